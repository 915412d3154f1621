// XDMF side files: after every step they are complete files whose DataItems name existing
// datasets of the declared shape and type (checked by fsi::xdmf_check and, when python3 with h5py
// is present, by an independent ElementTree + h5py script); restart keeps earlier steps.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "h5.hpp"
#include "xdmf.hpp"

namespace fs = std::filesystem;
using fsi::H5File;
using fsi::XdmfAttribute;
using fsi::XdmfCenter;
using fsi::XdmfWriter;

namespace {
fs::path fresh_dir(const std::string& name) {
  fs::path dir = fs::current_path() / "output_xdmf_files" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

// The independent Python check; skipped (with a warning) where python3 or h5py is missing.
void python_check(const fs::path& xdmf, std::size_t steps) {
  if (std::system("/usr/bin/python3 -c 'import h5py' > /dev/null 2>&1") != 0) {
    WARN("python3 with h5py not found: independent XDMF check skipped");
    return;
  }
  std::string command = "/usr/bin/python3 " + std::string(OUTPUT_TEST_SOURCE_DIR) + "/check_xdmf.py '" +
                        xdmf.string() + "' " + std::to_string(steps);
  CHECK(std::system(command.c_str()) == 0);
}

// A rectilinear fluid-like output: face coordinates, p cell-centred, u node-centred, a vector.
void write_fluid_step(H5File& h5, XdmfWriter& xdmf, long step, std::size_t nx, std::size_t ny) {
  std::string g = fsi::h5_step_group(step);
  std::vector<double> p((nx - 1) * (ny - 1), 1.0 * step), u(nx * ny, 2.0 * step), uv(nx * ny * 3, 0.5);
  h5.write(g + "/p", p, {ny - 1, nx - 1});
  h5.write(g + "/u", u, {ny, nx});
  h5.write(g + "/velocity", uv, {nx * ny, 3});
  xdmf.add_step(0.1 * step, {XdmfAttribute{"p", XdmfCenter::cell, g + "/p"},
                             XdmfAttribute{"u", XdmfCenter::node, g + "/u"},
                             XdmfAttribute{"velocity", XdmfCenter::node, g + "/velocity", 3}});
}
}  // namespace

TEST_CASE("rectilinear grid: valid after every step, relative references", "[xdmf]") {
  fs::path dir = fresh_dir("rectilinear");
  const std::size_t nx = 5, ny = 4;
  H5File h5(dir / "fluid.h5", H5File::Mode::truncate);
  const std::vector<double> x{0, 0.25, 0.5, 0.75, 1.0}, y{0, 0.1, 0.2, 0.3};
  h5.write("/grid/nodes", fsi::rectilinear_nodes(x, y), {ny * nx, 2});
  XdmfWriter xdmf(dir / "fluid.xdmf", dir / "fluid.h5", fsi::XdmfStructured{"/grid/nodes", nx, ny}, "fluid");
  CHECK_FALSE(fs::exists(dir / "fluid.xdmf"));
  for (long step = 0; step < 3; ++step) {
    write_fluid_step(h5, xdmf, step, nx, ny);
    INFO(joined(fsi::xdmf_check(dir / "fluid.xdmf")));
    CHECK(fsi::xdmf_check(dir / "fluid.xdmf").empty());
    CHECK(count(read_text(dir / "fluid.xdmf"), "<Time ") == std::size_t(step + 1));
  }
  std::string text = read_text(dir / "fluid.xdmf");
  CHECK(text.find(">fluid.h5:/step_000002/p</DataItem>") != std::string::npos);
  CHECK(text.find("TopologyType=\"2DSMesh\" Dimensions=\"4 5\"") != std::string::npos);
  CHECK(text.find("Dimensions=\"20 2\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">fluid.h5:/grid/nodes<") != std::string::npos);
  CHECK(text.find("Dimensions=\"3 4\"") != std::string::npos);   // cells
  CHECK(text.find("Dimensions=\"20 3\"") != std::string::npos);  // a vector per node
  CHECK(xdmf.steps() == 3);
  python_check(dir / "fluid.xdmf", 3);
  // No temporary left beside the file.
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 2);
}

TEST_CASE("rectilinear_nodes: the node positions of a rectilinear grid, x fastest", "[xdmf]") {
  const std::vector<double> x{0, 0.5, 2}, y{-1, 1};
  CHECK(fsi::rectilinear_nodes(x, y) == std::vector<double>{0, -1, 0.5, -1, 2, -1, 0, 1, 0.5, 1, 2, 1});
}

TEST_CASE("the data file may sit in another folder", "[xdmf]") {
  fs::path dir = fresh_dir("subfolder");
  fs::create_directories(dir / "data");
  H5File h5(dir / "data" / "fluid.h5", H5File::Mode::truncate);
  h5.write("nodes", fsi::rectilinear_nodes(std::vector<double>{0, 1}, std::vector<double>{0, 1, 2}),
           {6, 2});
  XdmfWriter xdmf(dir / "fluid.xdmf", dir / "data" / "fluid.h5", fsi::XdmfStructured{"nodes", 2, 3});
  h5.write("/step_000000/p", std::vector<double>{1, 2}, {2, 1});
  xdmf.add_step(0.0, {{"p", XdmfCenter::cell, "/step_000000/p"}});
  CHECK(read_text(dir / "fluid.xdmf").find(">data/fluid.h5:/step_000000/p<") != std::string::npos);
  CHECK(fsi::xdmf_check(dir / "fluid.xdmf").empty());
}

TEST_CASE("triangle mesh: topology once, geometry per step, node and cell attributes", "[xdmf]") {
  fs::path dir = fresh_dir("triangles");
  H5File h5(dir / "solid.h5", H5File::Mode::truncate);
  h5.write("/mesh/triangles", std::vector<int>{0, 1, 2, 0, 2, 3}, {2, 3});
  XdmfWriter xdmf(dir / "solid.xdmf", dir / "solid.h5", fsi::XdmfTriangles{"/mesh/triangles", 2, 4}, "solid");
  for (long step = 0; step < 4; ++step) {
    std::string g = fsi::h5_step_group(step);
    double s = 0.01 * step;
    h5.write(g + "/xy", std::vector<double>{0, 0, 1 + s, 0, 1 + s, 1, 0, 1}, {4, 2});
    h5.write(g + "/displacement", std::vector<double>{0, 0, 0, s, 0, 0, s, 0, 0, 0, 0, 0}, {4, 3});
    h5.write(g + "/stress", std::vector<double>{s, 2 * s});
    xdmf.add_step(0.5 * step,
                  {{"displacement", XdmfCenter::node, g + "/displacement", 3}, {"stress", XdmfCenter::cell, g + "/stress"}},
                  g + "/xy");
  }
  INFO(joined(fsi::xdmf_check(dir / "solid.xdmf")));
  CHECK(fsi::xdmf_check(dir / "solid.xdmf").empty());
  std::string text = read_text(dir / "solid.xdmf");
  CHECK(count(text, "TopologyType=\"Triangle\" NumberOfElements=\"2\" NodesPerElement=\"3\"") == 4);
  CHECK(count(text, ">solid.h5:/mesh/triangles<") == 4);
  CHECK(text.find(">solid.h5:/step_000003/xy<") != std::string::npos);
  python_check(dir / "solid.xdmf", 4);

  // A step without geometry on a mesh without fixed geometry is refused.
  CHECK_THROWS_AS(xdmf.add_step(9.0, {}), fsi::Error);
}

TEST_CASE("polylines: segment connectivity for lines of different lengths", "[xdmf]") {
  std::vector<std::size_t> nodes = {3, 2, 1, 4};
  std::vector<int> seg = fsi::polyline_segments(nodes);
  CHECK(seg == std::vector<int>{0, 1, 1, 2, 3, 4, 6, 7, 7, 8, 8, 9});

  fs::path dir = fresh_dir("polylines");
  H5File h5(dir / "fiber.h5", H5File::Mode::truncate);
  h5.write("/fibers/segments", seg, {seg.size() / 2, 2});
  std::vector<double> xy(2 * 10);
  for (std::size_t k = 0; k < 10; ++k) xy[2 * k] = double(k);
  h5.write("/fibers/reference_xy", xy, {10, 2});
  XdmfWriter xdmf(dir / "fiber.xdmf", dir / "fiber.h5",
                  fsi::XdmfPolylines{"/fibers/segments", 6, 10, "/fibers/reference_xy"}, "fibers");
  h5.write("/step_000000/tension", std::vector<double>(10, 1.0));
  h5.write("/step_000001/tension", std::vector<double>(10, 2.0));
  h5.write("/step_000001/xy", xy, {10, 2});
  xdmf.add_step(0.0, {{"tension", XdmfCenter::node, "/step_000000/tension"}});  // fixed geometry
  xdmf.add_step(1.0, {{"tension", XdmfCenter::node, "/step_000001/tension"}}, "/step_000001/xy");
  INFO(joined(fsi::xdmf_check(dir / "fiber.xdmf")));
  CHECK(fsi::xdmf_check(dir / "fiber.xdmf").empty());
  std::string text = read_text(dir / "fiber.xdmf");
  CHECK(count(text, "TopologyType=\"Polyline\" NumberOfElements=\"6\" NodesPerElement=\"2\"") == 2);
  CHECK(text.find(">fiber.h5:/fibers/reference_xy<") != std::string::npos);
  python_check(dir / "fiber.xdmf", 2);
}

TEST_CASE("xdmf_check reports missing datasets, wrong shapes and wrong types", "[xdmf]") {
  fs::path dir = fresh_dir("bad");
  H5File h5(dir / "f.h5", H5File::Mode::truncate);
  h5.write("nodes", fsi::rectilinear_nodes(std::vector<double>{0, 1, 2}, std::vector<double>{0, 1}),
           {6, 2});
  h5.write("/s0/p", std::vector<double>{1, 2, 3}, {1, 3});  // node shape {2, 3} was meant
  h5.write("/s0/q", std::vector<int>{1, 2}, {1, 2});        // right shape, int instead of float64
  XdmfWriter xdmf(dir / "f.xdmf", dir / "f.h5", fsi::XdmfStructured{"nodes", 3, 2});
  xdmf.add_step(0.0, {{"p", XdmfCenter::node, "/s0/p"}, {"q", XdmfCenter::cell, "/s0/q"},
                      {"r", XdmfCenter::cell, "/s0/r"}});
  std::vector<std::string> problems = fsi::xdmf_check(dir / "f.xdmf");
  INFO(joined(problems));
  REQUIRE(problems.size() == 3);
  CHECK_THAT(problems[0], Catch::Contains("/s0/p") && Catch::Contains("shape 1 3"));
  CHECK_THAT(problems[1], Catch::Contains("/s0/q") && Catch::Contains("int32"));
  CHECK_THAT(problems[2], Catch::Contains("/s0/r") && Catch::Contains("no such dataset"));
  CHECK(fsi::xdmf_check(dir / "none.xdmf").size() == 1);
  CHECK_THROWS_AS(XdmfWriter(dir / "g.xdmf", dir / "f.h5", fsi::XdmfStructured{"nodes", 1, 2}), fsi::Error);
  CHECK_THROWS_AS(xdmf.add_step(1.0, {}, "/s0/p"), fsi::Error);  // rectilinear takes no geometry
  CHECK_THROWS_WITH(xdmf.add_step(1.0, {{"v", XdmfCenter::node, "/s0/v", 2}}), Catch::Contains("(vx, vy, 0)"));
  CHECK(xdmf.steps() == 1);
}

TEST_CASE("resume keeps the steps up to the restart time", "[xdmf]") {
  fs::path dir = fresh_dir("resume");
  const std::size_t nx = 3, ny = 3;
  {
    H5File h5(dir / "fluid.h5", H5File::Mode::truncate);
    h5.write("/grid/nodes", fsi::rectilinear_nodes(std::vector<double>{0, 1, 2}, std::vector<double>{0, 1, 2}),
             {9, 2});
    XdmfWriter xdmf(dir / "fluid.xdmf", dir / "fluid.h5", fsi::XdmfStructured{"/grid/nodes", nx, ny});
    for (long step = 0; step < 5; ++step) write_fluid_step(h5, xdmf, step, nx, ny);  // t = 0 ... 0.4
  }
  H5File h5(dir / "fluid.h5", H5File::Mode::read_write);
  XdmfWriter xdmf(dir / "fluid.xdmf", dir / "fluid.h5", fsi::XdmfStructured{"/grid/nodes", nx, ny});
  xdmf.resume(0.2);
  CHECK(xdmf.steps() == 3);
  CHECK(count(read_text(dir / "fluid.xdmf"), "<Time ") == 3);
  write_fluid_step(h5, xdmf, 3, nx, ny);
  std::string text = read_text(dir / "fluid.xdmf");
  CHECK(count(text, "<Time ") == 4);
  CHECK(text.find("<Time Value=\"0.4\"/>") == std::string::npos);
  CHECK(fsi::xdmf_check(dir / "fluid.xdmf").empty());
  python_check(dir / "fluid.xdmf", 4);

  XdmfWriter fresh(dir / "other.xdmf", dir / "fluid.h5", fsi::XdmfStructured{"/grid/nodes", nx, ny});
  fresh.resume(1.0);  // no file yet: starts empty
  CHECK(fresh.steps() == 0);
}
