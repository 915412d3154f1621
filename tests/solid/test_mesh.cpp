// Meshes: built-in rectangles, Gmsh .geo/.msh import with physical groups, quality checks and
// the errors for missing, non-Gmsh, inverted and degenerate meshes.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "error.hpp"
#include "gmsh_mesh.hpp"
#include "mesh.hpp"

using namespace solid;

namespace {

const std::filesystem::path source_dir = FSI_SOURCE_DIR;

std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::current_path() / name;
  std::ofstream(p) << text;
  return p;
}

const char* msh_header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";

}  // namespace

TEST_CASE("built-in rectangles: counts, area, boundaries, orientation", "[mesh]") {
  for (Diagonals d :
       {Diagonals::criss_cross, Diagonals::right, Diagonals::left, Diagonals::union_jack}) {
    const Mesh m = rectangle_mesh(1, 2, 3, 0.5, 6, 2, d);
    const bool jack = d == Diagonals::union_jack;
    CHECK(m.num_nodes() == 7 * 3 + (jack ? 12 : 0));
    CHECK(m.num_triangles() == 12 * (jack ? 4 : 2));
    CHECK(m.area() == Approx(1.5).epsilon(1e-14));
    CHECK(m.surface.size() == 16);
    CHECK(m.boundaries.at("left").size() == 2);
    CHECK(m.boundaries.at("top").size() == 6);
    CHECK(m.boundary_nodes("right").size() == 3);
    // Surface edges have the body on their left: the outward normal of the bottom is -y.
    for (const auto& e : m.boundaries.at("bottom")) CHECK(m.x[2 * e[1]] > m.x[2 * e[0]]);
  }
}

TEST_CASE("criss-cross alternates the diagonals cell by cell", "[mesh]") {
  const Mesh m = rectangle_mesh(0, 0, 2, 2, 2, 2, Diagonals::criss_cross);
  // Cell (0,0) holds the diagonal 0-4, cell (1,0) the diagonal 2-4 (nodes numbered row by row).
  auto has_edge = [&](int a, int b) {
    for (const auto& t : m.triangles)
      for (int k = 0; k < 3; ++k)
        if ((t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a)) return true;
    return false;
  };
  CHECK(has_edge(0, 4));
  CHECK(has_edge(2, 4));
  CHECK_FALSE(has_edge(1, 3));
}

TEST_CASE("a .geo file is meshed through Gmsh with its physical groups", "[mesh][gmsh]") {
  GmshOptions opt;
  opt.parameters = {{"ny", 2}, {"nx", 10}};
  const Mesh m = read_gmsh(source_dir / "runs/turek-hron-csm/bar.geo", opt);
  CHECK(m.num_nodes() == 33);
  CHECK(m.num_triangles() == 40);
  REQUIRE(m.region_names.size() == 1);
  CHECK(m.region_names[0] == "bar");
  CHECK(m.boundaries.at("clamp").size() == 2);
  CHECK(m.boundaries.at("tip").size() == 2);
  // Area: the rectangle to x = 0.6 minus the circular segment cut by the cylinder, which the
  // straight edges of the clamped end approximate by two chords.
  const double x0 = 0.2 + std::sqrt(0.05 * 0.05 - 0.01 * 0.01);
  const double chord_area = 0.02 * (0.6 - x0) - 0.5 * 0.02 * (0.25 - x0);
  CHECK(m.area() == Approx(chord_area).epsilon(1e-12));
  for (const auto& t : m.triangles) {
    const double* p = &m.x[2 * t[0]];
    const double* q = &m.x[2 * t[1]];
    const double* r = &m.x[2 * t[2]];
    CHECK((q[0] - p[0]) * (r[1] - p[1]) - (r[0] - p[0]) * (q[1] - p[1]) > 0);
  }
  opt.refine = 1;
  const Mesh fine = read_gmsh(source_dir / "runs/turek-hron-csm/bar.geo", opt);
  CHECK(fine.num_triangles() == 160);
}

TEST_CASE("a .msh file with regions, boundaries and a clockwise surface", "[mesh][gmsh]") {
  // Two triangles listed clockwise: the surface is flipped as a whole, not rejected.
  const auto p = write_file(
      "cw.msh",
      std::string(msh_header) +
          "$PhysicalNames\n2\n1 7 \"base\"\n2 1 \"soft\"\n$EndPhysicalNames\n"
          "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n"
          "$Elements\n3\n1 1 2 7 1 1 2\n2 2 2 1 1 1 3 2\n3 2 2 1 1 1 4 3\n$EndElements\n");
  const Mesh m = read_gmsh(p);
  CHECK(m.num_triangles() == 2);
  CHECK(m.area() == Approx(1.0));
  CHECK(m.region_names == std::vector<std::string>{"soft"});
  REQUIRE(m.boundaries.count("base") == 1);
  CHECK(m.boundaries.at("base").size() == 1);
  CHECK(m.surface.size() == 4);
}

TEST_CASE("bad meshes are rejected with the file and the element named", "[mesh][input]") {
  CHECK_THROWS_AS(read_gmsh("no/such/bar.geo", {}, "solid.body[0].mesh"), fsi::InputError);
  CHECK_THROWS_WITH(read_gmsh("no/such/bar.geo", {}, "solid.body[0].mesh"),
                    Catch::Contains("solid.body[0].mesh") && Catch::Contains("no/such/bar.geo") &&
                        Catch::Contains("does not exist"));
  const auto txt = write_file("notes.txt", "hello\n");
  CHECK_THROWS_WITH(read_gmsh(txt), Catch::Contains("is not a Gmsh file"));
  const auto garbage = write_file("garbage.msh", "this is not a mesh\n1 2 3\n");
  CHECK_THROWS_WITH(read_gmsh(garbage), Catch::Contains("is not a Gmsh mesh"));
  const auto empty_geo = write_file("empty.geo", "Point(1) = {0, 0, 0};\n");
  CHECK_THROWS_WITH(read_gmsh(empty_geo), Catch::Contains("holds no triangles"));

  const auto inverted = write_file(
      "inverted.msh", std::string(msh_header) +
                          "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0.5 0.5 0\n$EndNodes\n"
                          "$Elements\n4\n1 2 2 1 1 1 2 5\n2 2 2 1 1 2 3 5\n3 2 2 1 1 3 4 5\n"
                          "4 2 2 1 1 5 1 4\n$EndElements\n");
  CHECK_THROWS_AS(read_gmsh(inverted), fsi::InputError);
  CHECK_THROWS_WITH(read_gmsh(inverted), Catch::Contains("inverted.msh") &&
                                             Catch::Contains("element 3") &&
                                             Catch::Contains("is inverted"));

  const auto degenerate = write_file(
      "degenerate.msh", std::string(msh_header) +
                            "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 2 0 0\n$EndNodes\n"
                            "$Elements\n2\n1 2 2 1 1 1 2 3\n2 2 2 1 1 1 2 4\n$EndElements\n");
  CHECK_THROWS_WITH(read_gmsh(degenerate), Catch::Contains("degenerate.msh") &&
                                               Catch::Contains("element 1") &&
                                               Catch::Contains("degenerate"));
}

TEST_CASE("locating a reference point gives its element and barycentric weights", "[mesh]") {
  const Mesh m = rectangle_mesh(0, 0, 2, 1, 4, 2, Diagonals::criss_cross);
  const MeshPoint p = locate(m, 1.3, 0.7);
  REQUIRE(p.triangle >= 0);
  double x = 0, y = 0;
  for (int a = 0; a < 3; ++a) {
    x += p.weights[a] * m.x[2 * m.triangles[p.triangle][a]];
    y += p.weights[a] * m.x[2 * m.triangles[p.triangle][a] + 1];
  }
  CHECK(x == Approx(1.3));
  CHECK(y == Approx(0.7));
  CHECK(locate(m, 3, 0.5).triangle == -1);
}
