// Triangle meshes of the solid bodies: reference nodes, linear triangles (counter-clockwise),
// named material regions, named boundary edge sets and node sets, and the surface edges.
// Built-in structured rectangles live here; Gmsh import is in gmsh_mesh.hpp.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

namespace solid {

struct Mesh {
  std::vector<double> x;                      // reference coordinates x0, y0, x1, y1, ...
  std::vector<std::array<int, 3>> triangles;  // node indices, counter-clockwise
  std::vector<int> triangle_region;           // index into region_names, one per triangle
  std::vector<std::string> region_names;
  // Named edge sets (Gmsh physical curves, or left/right/bottom/top of a built-in rectangle).
  // Edges on the surface are oriented like `surface`.
  std::map<std::string, std::vector<std::array<int, 2>>> boundaries;
  // Named node sets (Gmsh physical points).
  std::map<std::string, std::vector<int>> node_sets;
  // Every boundary edge (an edge of exactly one triangle), oriented with the body on its left:
  // for an edge a -> b the outward normal is (dy, -dx) / |b - a|.
  std::vector<std::array<int, 2>> surface;
  std::string source;  // file name or description, for messages

  int num_nodes() const { return static_cast<int>(x.size() / 2); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
  bool has_boundary(const std::string& name) const;
  // Sorted nodes of a boundary edge set or node set.
  std::vector<int> boundary_nodes(const std::string& name) const;
  // All boundary and node set names, sorted.
  std::vector<std::string> boundary_names() const;
  int region_index(const std::string& name) const;  // -1 when absent
  double area() const;
};

struct MeshQuality {
  double min_area = 0;     // smallest triangle area
  double min_quality = 0;  // smallest 4 sqrt(3) A / (l1^2 + l2^2 + l3^2): 1 equilateral, 0 flat
  int worst_triangle = -1;
  double min_edge = 0, max_edge = 0;
};

// Completes a mesh whose triangles have a consistent orientation within each group (a Gmsh
// surface; all one group for built-in meshes): flips a clockwise group, rejects an element whose
// orientation differs from its group's (inverted) or whose area is below 1e-12 of its longest
// edge squared (degenerate), rejects edges shared by more than two triangles, builds the surface
// edges and orients the boundary edges. Throws fsi::InputError naming mesh.source and element.
MeshQuality finalize_mesh(Mesh& mesh, const std::vector<int>& orientation_group = {});

enum class Diagonals { criss_cross, right, left, union_jack };
Diagonals diagonals_from_name(const std::string& name);  // throws std::invalid_argument

// Structured mesh of [x0, x0 + lx] x [y0, y0 + ly] with nx x ny cells. Diagonals: criss_cross
// alternates the two diagonals cell by cell (checkerboard), right runs every diagonal from
// bottom-left to top-right, left from bottom-right to top-left, union_jack splits each cell in
// four around a centre node. Boundaries "left", "right", "bottom", "top"; one region `region`.
Mesh rectangle_mesh(double x0, double y0, double lx, double ly, int nx, int ny, Diagonals d,
                    const std::string& region = "body");

// Element containing reference point p and its barycentric coordinates; the element with the
// largest smallest coordinate wins (points on edges, or within `tol` relative outside).
struct MeshPoint {
  int triangle = -1;
  std::array<double, 3> weights{};
};
MeshPoint locate(const Mesh& mesh, double px, double py, double tol = 1e-9);

}  // namespace solid
