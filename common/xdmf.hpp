// XDMF side files: the light XML that lets ParaView open the heavy data of an .h5 file as a time
// series. One XdmfWriter describes one temporal collection of one kind of grid (a 2D
// structured grid, a triangle mesh, or a set of polylines); after each appended step the whole
// file is rewritten through a temporary and a rename, so it is valid at any moment of a run.
// Datasets are referenced by the .h5 path relative to the .xdmf file's folder.
//
//   H5File h5(out / "fluid.h5", H5File::Mode::truncate);
//   h5.write("/grid/nodes", rectilinear_nodes(xf, yf), {(ny + 1) * (nx + 1), 2});  // the faces
//   XdmfWriter xdmf(out / "fluid.xdmf", out / "fluid.h5",
//                   XdmfStructured{"/grid/nodes", nx + 1, ny + 1}, "fluid");
//   // each output step:
//   std::string g = h5_step_group(step);
//   h5.write_window(g + "/p", p, {ny + 2 * ng, nx + 2 * ng}, {ng, ng}, {ny, nx});
//   xdmf.add_step(t, {{"p", XdmfCenter::cell, g + "/p"}});
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "error.hpp"

namespace fsi {

// Where an attribute's values live: on the grid's nodes or on its cells (structured cells are
// the quadrilaterals between neighbouring nodes; mesh cells are triangles; polyline
// cells are segments).
enum class XdmfCenter { node, cell };

// One field of a step: `dataset` in the .h5 file (e.g. "/step_000012/p") of float64 values.
// Shape: scalar {ny, nx} on structured nodes, {ny-1, nx-1} on its cells, {n} on mesh or polyline
// nodes/cells. A vector has 3 components and shape {n_points, 3} (n_points = ny*nx on structured
// nodes ...): store (vx, vy, 0), because ParaView reads a 2-component "Vector" as if it had 3.
struct XdmfAttribute {
  std::string name;
  XdmfCenter center = XdmfCenter::node;
  std::string dataset;
  std::size_t components = 1;
};

// A 2D structured grid of nx x ny nodes: `nodes` is an {ny * nx, 2} float64 dataset of the node
// positions, x fastest (rectilinear_nodes() for a rectilinear grid). The caller chooses what the
// nodes are: cell faces (then cell-centred attributes are cell averages) or cell centres (then
// node-centred attributes are the values at the centres). A rectilinear grid is written this way,
// not as a 2DRectMesh with VXVY coordinates, because ParaView 5.11's three XDMF readers read such
// coordinates as arrays of nx * ny values and draw the grid as a line.
struct XdmfStructured {
  std::string nodes = {};
  std::size_t nx = 0;
  std::size_t ny = 0;
};

// The {ny * nx, 2} node positions (x fastest) of the rectilinear grid with coordinates x and y.
std::vector<double> rectilinear_nodes(std::span<const double> x, std::span<const double> y);

// A triangle mesh: `topology` is an int32 dataset {n_triangles, 3} of 0-based node indices,
// written once. Node positions are an {n_nodes, 2} float64 dataset, given per step or, for a
// mesh that does not move, once here as `geometry`.
struct XdmfTriangles {
  std::string topology;
  std::size_t n_triangles = 0;
  std::size_t n_nodes = 0;
  std::string geometry = {};  // optional fixed geometry
};

// A set of polylines (fibers), drawn as 2-node segments so that lines of different lengths share
// one topology: `segments` is an int32 dataset {n_segments, 2} (see polyline_segments()).
struct XdmfPolylines {
  std::string segments;
  std::size_t n_segments = 0;
  std::size_t n_nodes = 0;
  std::string geometry = {};  // optional fixed geometry
};

// Segment connectivity for polylines stored one after the other: line k has nodes_per_line[k]
// consecutive nodes. Returns {a0, b0, a1, b1, ...} (n_segments = sum(nodes - 1)).
std::vector<int> polyline_segments(std::span<const std::size_t> nodes_per_line);

class XdmfWriter {
 public:
  using Grid = std::variant<XdmfStructured, XdmfTriangles, XdmfPolylines>;

  // `xdmf` is the side file to (re)write, `h5` the data file it points into, `name` the
  // collection's name in ParaView. Nothing is written before the first step.
  XdmfWriter(std::filesystem::path xdmf, const std::filesystem::path& h5, Grid grid,
             std::string name = "grid");

  // Appends one time step and rewrites the file. `geometry` is the step's {n_nodes, 2} node
  // positions (meshes and polylines; empty = the fixed geometry; must be empty for structured).
  void add_step(double time, const std::vector<XdmfAttribute>& attributes,
                std::string_view geometry = {});

  // Restart: take back the steps of an existing side file at this path with time <= t_last
  // (none if there is no file) and rewrite it. Call before the first add_step.
  void resume(double t_last);

  std::size_t steps() const { return m_steps.size(); }
  const std::filesystem::path& path() const { return m_xdmf; }

 private:
  std::string data_item(std::string_view dataset, const std::vector<std::size_t>& dims,
                        bool is_int) const;
  void rewrite() const;

  std::filesystem::path m_xdmf;
  std::string m_h5_ref;  // the .h5 path relative to the side file's folder
  Grid m_grid;
  std::string m_name;
  struct Step {
    double time;
    std::string xml;
  };
  std::vector<Step> m_steps;
};

// Checks a side file against its data: every HDF5 DataItem must name an existing dataset whose
// shape equals its Dimensions and whose element type matches NumberType and Precision. Returns
// the problems found, one line each (empty when consistent). Meant for tests and `validate`.
std::vector<std::string> xdmf_check(const std::filesystem::path& xdmf);

}  // namespace fsi
