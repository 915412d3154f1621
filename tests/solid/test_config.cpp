// Reading [solid] from a scene: a complete scene, and each kind of bad input with its error text
// (key, value and file named).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "config.hpp"
#include "error.hpp"
#include "scene.hpp"
#include "solver.hpp"

using namespace solid;

namespace {

const std::filesystem::path source_dir = FSI_SOURCE_DIR;

std::filesystem::path write(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::current_path() / name;
  std::ofstream(p) << text;
  return p;
}

Config read(const std::string& name, const std::string& text, double rho_f = 0) {
  fsi::Scene scene(write(name, text));
  return read_config(scene.root().table("solid"), rho_f);
}

const std::string block = R"(
[[solid.body]]
name = "block"
[solid.body.rectangle]
size = [1, 0.5]
cells = [4, 2]
[[solid.body.material]]
model = "neo-hookean"
density = 10
youngs_modulus = 1e4
poisson_ratio = 0.3
)";

std::string with_material(const std::string& lines) {
  return R"(
[solid]
[[solid.body]]
name = "block"
[solid.body.rectangle]
size = [1, 0.5]
cells = [4, 2]
[[solid.body.material]]
model = "saint-venant-kirchhoff"
)" + lines;
}

}  // namespace

TEST_CASE("a complete solid scene is read", "[config]") {
  const std::string geo = (source_dir / "runs/turek-hron-csm/bar.geo").string();
  const Config c = read("full.toml", R"(
[solid]
analysis = "static"
gravity = [0, -2]
newton_tolerance = 1e-9

[[solid.body]]
name = "bar"
mesh = ")" + geo + R"("
mesh_parameters = "nx = 20, ny = 2"
[[solid.body.material]]
region = "bar"
model = "saint-venant-kirchhoff"
density = 1000
shear_modulus = 0.5e6
poisson_ratio = 0.4
[[solid.body.constraint]]
boundary = "clamp"
type = "fixed"
[[solid.body.probe]]
name = "A"
point = [0.6, 0.2]

[[solid.body]]
name = "floor"
kind = "rigid"
[solid.body.rectangle]
origin = [0, 0]
size = [1, 0.1]
cells = [2, 1]
[solid.body.motion]
velocity = [0.1, 0]

[[solid.contact]]
bodies = ["floor", "bar"]
)",
                        0.0);
  REQUIRE(c.model.bodies.size() == 2);
  const BodySpec& bar = c.model.bodies[0];
  CHECK(c.model.settings.analysis == Analysis::statics);
  CHECK(c.model.settings.gravity[1] == -2);
  CHECK(bar.mesh.num_nodes() == 63);
  CHECK(bar.materials[0].mu == Approx(0.5e6));
  CHECK(bar.materials[0].lambda == Approx(2 * 0.5e6 * 0.4 / (1 - 0.8)));
  CHECK(bar.constraints.size() == 1);
  REQUIRE(c.probes.size() == 1);
  CHECK(c.probes[0].name == "A");
  CHECK(c.model.bodies[1].kind == BodyKind::rigid);
  CHECK(c.model.bodies[1].motion.velocity[0] == 0.1);
  REQUIRE(c.model.contacts.size() == 1);
  CHECK(c.model.contacts[0].slave == 0);  // the rigid body is always the master
  CHECK(c.quality[0].min_quality > 0.1);
  Solver s(c.model);
  CHECK(s.num_equations() > 0);
}

TEST_CASE("step_cutbacks: the default, a value, and out of range", "[config][input]") {
  const std::string mat = "density = 1\nyoungs_modulus = 1\npoisson_ratio = 0.3\n";
  CHECK(read("cut_default.toml", with_material(mat)).model.settings.step_cutbacks == 3);
  std::string text = with_material(mat);
  text.replace(text.find("[solid]\n"), 8, "[solid]\nstep_cutbacks = 0\n");
  CHECK(read("cut_zero.toml", text).model.settings.step_cutbacks == 0);
  text.replace(text.find("step_cutbacks = 0"), 17, "step_cutbacks = 21");
  CHECK_THROWS_WITH(read("cut_many.toml", text), Catch::Contains("solid.step_cutbacks") &&
                                                     Catch::Contains("got 21") &&
                                                     Catch::Contains("cut_many.toml"));
  text.replace(text.find("step_cutbacks = 21"), 18, "step_cutbacks = -1");
  CHECK_THROWS_WITH(read("cut_negative.toml", text),
                    Catch::Contains("solid.step_cutbacks") && Catch::Contains("got -1"));
}

TEST_CASE("newmark_gamma and newmark_beta: the default, the derived beta, out of range",
          "[config][input]") {
  const std::string mat = "density = 1\nyoungs_modulus = 1\npoisson_ratio = 0.3\n";
  auto with = [&](const std::string& keys) {
    std::string text = with_material(mat);
    text.replace(text.find("[solid]\n"), 8, "[solid]\n" + keys + "\n");
    return text;
  };
  const Settings plain = read("newmark_default.toml", with_material(mat)).model.settings;
  CHECK(plain.trapezoidal());
  const Settings damped = read("newmark_gamma.toml", with("newmark_gamma = 0.6")).model.settings;
  CHECK(damped.newmark_gamma == 0.6);
  CHECK(damped.newmark_beta == Approx(0.3025).epsilon(1e-15));
  CHECK_THROWS_WITH(read("newmark_low.toml", with("newmark_gamma = 0.4")),
                    Catch::Contains("solid.newmark_gamma") && Catch::Contains("0.4") &&
                        Catch::Contains("newmark_low.toml"));
  CHECK_THROWS_WITH(read("newmark_beta.toml", with("newmark_gamma = 0.8\nnewmark_beta = 0.3")),
                    Catch::Contains("solid.newmark_beta") && Catch::Contains("0.3") &&
                        Catch::Contains("at least newmark_gamma / 2") &&
                        Catch::Contains("newmark_beta.toml"));
}

TEST_CASE("bad elastic constants name the key, the value and the file", "[config][input]") {
  CHECK_THROWS_WITH(
      read("nu_half.toml", with_material("density = 1\nyoungs_modulus = 1\npoisson_ratio = 0.5\n")),
      Catch::Contains("solid.body[0].material[0].poisson_ratio") && Catch::Contains("got 0.5") &&
          Catch::Contains("nu_half.toml"));
  CHECK_THROWS_WITH(
      read("nu_low.toml", with_material("density = 1\nyoungs_modulus = 1\npoisson_ratio = -1\n")),
      Catch::Contains("poisson_ratio") && Catch::Contains("got -1"));
  CHECK_THROWS_WITH(
      read("e_neg.toml", with_material("density = 1\nyoungs_modulus = -3\npoisson_ratio = 0.3\n")),
      Catch::Contains("solid.body[0].material[0].youngs_modulus") && Catch::Contains("-3") &&
          Catch::Contains("e_neg.toml"));
  CHECK_THROWS_WITH(
      read("g_zero.toml", with_material("density = 1\nshear_modulus = 0\nbulk_modulus = 3\n")),
      Catch::Contains("shear_modulus") && Catch::Contains("got 0"));
  CHECK_THROWS_WITH(
      read("rho_zero.toml",
           with_material("density = 0\nyoungs_modulus = 1\npoisson_ratio = 0.3\n")),
      Catch::Contains("solid.body[0].material[0].density") && Catch::Contains("got 0"));
  CHECK_THROWS_WITH(read("pair.toml", with_material("density = 1\nyoungs_modulus = 1\n")),
                    Catch::Contains("one pair"));
}

TEST_CASE("missing or non-Gmsh mesh files", "[config][input]") {
  const std::string head = "[solid]\n[[solid.body]]\nname = \"b\"\n";
  CHECK_THROWS_WITH(read("missing.toml", head + "mesh = \"nowhere.geo\"\n"),
                    Catch::Contains("solid.body[0].mesh") && Catch::Contains("nowhere.geo") &&
                        Catch::Contains("does not exist") && Catch::Contains("missing.toml"));
  write("plain.msh", "just text\n");
  CHECK_THROWS_WITH(read("notgmsh.toml", head + "mesh = \"plain.msh\"\n"),
                    Catch::Contains("solid.body[0].mesh") && Catch::Contains("plain.msh") &&
                        Catch::Contains("not a Gmsh mesh"));
  write("shape.stl", "solid x\n");
  CHECK_THROWS_WITH(read("stl.toml", head + "mesh = \"shape.stl\"\n"),
                    Catch::Contains("not a Gmsh file"));
}

TEST_CASE("a physical group the mesh lacks", "[config][input]") {
  const std::string geo = (source_dir / "runs/turek-hron-csm/bar.geo").string();
  const std::string head = "[solid]\n[[solid.body]]\nname = \"bar\"\nmesh = \"" + geo +
                           "\"\nmesh_parameters = \"nx = 10, ny = 2\"\n";
  const std::string mat =
      "[[solid.body.material]]\nmodel = \"neo-hookean\"\ndensity = 1\n"
      "youngs_modulus = 1\npoisson_ratio = 0.3\n";
  CHECK_THROWS_WITH(
      read("noboundary.toml",
           head + mat + "[[solid.body.constraint]]\ntype = \"fixed\"\nboundary = \"clmap\"\n"),
      Catch::Contains("solid.body[0].constraint[0].boundary") && Catch::Contains("\"clmap\"") &&
          Catch::Contains("lacks") && Catch::Contains("clamp") &&
          Catch::Contains("noboundary.toml"));
  CHECK_THROWS_WITH(
      read("noregion.toml",
           head + "[[solid.body.material]]\nregion = \"cover\"\nmodel = \"neo-hookean\"\n"
                  "density = 1\nyoungs_modulus = 1\npoisson_ratio = 0.3\n"),
      Catch::Contains("solid.body[0].material[0].region") && Catch::Contains("\"cover\"") &&
          Catch::Contains("its regions: bar"));
}

TEST_CASE("an inverted or degenerate element in the mesh file", "[config][input]") {
  write("flip.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
        "5 0.5 0.5 0\n$EndNodes\n$Elements\n4\n1 2 2 1 1 1 2 5\n2 2 2 1 1 2 3 5\n"
        "3 2 2 1 1 3 4 5\n4 2 2 1 1 5 1 4\n$EndElements\n");
  CHECK_THROWS_WITH(
      read("flip.toml", "[solid]\n[[solid.body]]\nname = \"b\"\nmesh = \"flip.msh\"\n"),
      Catch::Contains("flip.msh") && Catch::Contains("element 3") && Catch::Contains("inverted"));
  write("flat.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 2 0 0\n"
        "$EndNodes\n$Elements\n2\n1 2 2 1 1 1 2 3\n2 2 2 1 1 1 2 4\n$EndElements\n");
  CHECK_THROWS_WITH(
      read("flat.toml", "[solid]\n[[solid.body]]\nname = \"b\"\nmesh = \"flat.msh\"\n"),
      Catch::Contains("flat.msh") && Catch::Contains("element 1") && Catch::Contains("degenerate"));
}

TEST_CASE("a body without constraint in a static solve", "[config][input]") {
  CHECK_THROWS_WITH(read("free.toml", "[solid]\nanalysis = \"static\"\n" + block),
                    Catch::Contains("[solid.body[0]]") &&
                        Catch::Contains("\"block\" has no fixed or displacement constraint") &&
                        Catch::Contains("singular") && Catch::Contains("free.toml"));
  // Held in x only: the solver's own check names the missing direction.
  const Config c = read(
      "half.toml",
      "[solid]\nanalysis = \"static\"\n" + block +
          "[[solid.body.constraint]]\ntype = \"fixed\"\nboundary = \"left\"\ncomponents = \"x\"\n");
  CHECK_THROWS_WITH(Solver(c.model),
                    Catch::Contains("body 'block' has no constraint that holds it in y"));
}

TEST_CASE("unknown keys and wrong choices", "[config][input]") {
  CHECK_THROWS_WITH(
      read("typo.toml", "[solid]\ngravty = [0, -1]\n" + block),
      Catch::Contains("gravty") && Catch::Contains("did you mean") && Catch::Contains("gravity"));
  std::string hooke = with_material("density = 1\nyoungs_modulus = 1\npoisson_ratio = 0.3\n");
  hooke.replace(hooke.find("saint-venant-kirchhoff"), 22, "saint-venant-kirchoff");
  CHECK_THROWS_WITH(read("model.toml", hooke),
                    Catch::Contains("solid.body[0].material[0].model") &&
                        Catch::Contains("did you mean 'saint-venant-kirchhoff'"));
  CHECK_THROWS_WITH(read("contact.toml", "[solid]\n" + block +
                                             "[[solid.contact]]\nbodies = [\"block\", \"lid\"]\n"),
                    Catch::Contains("solid.contact[0].bodies") && Catch::Contains("\"lid\""));
  // A body named twice is a self-contact: read as one pair; two_way has no meaning there.
  const Config self = read("self.toml", "[solid]\n" + block +
                                            "[[solid.contact]]\nbodies = [\"block\", \"block\"]\n");
  REQUIRE(self.model.contacts.size() == 1);
  CHECK(self.model.contacts[0].slave == 0);
  CHECK(self.model.contacts[0].master == 0);
  CHECK_THROWS_WITH(read("self_two_way.toml",
                         "[solid]\n" + block +
                             "[[solid.contact]]\nbodies = [\"block\", \"block\"]\ntwo_way = true\n"),
                    Catch::Contains("solid.contact[0].two_way") &&
                        Catch::Contains("self-contact") && Catch::Contains("self_two_way.toml"));
  // A pair named twice (in either order, when the first takes both directions): an error.
  std::string lid = block;
  lid.replace(lid.find("\"block\""), 7, "\"lid\"");
  const std::string pair = "[[solid.contact]]\nbodies = [\"block\", \"lid\"]\n";
  CHECK_THROWS_WITH(
      read("twice.toml", "[solid]\n" + block + lid + pair +
                             "[[solid.contact]]\nbodies = [\"lid\", \"block\"]\n"),
      Catch::Contains("solid.contact[1].bodies") && Catch::Contains("repeats the contact") &&
          Catch::Contains("twice.toml"));
  CHECK_THROWS_WITH(read("self_twice.toml", "[solid]\n" + block +
                                                "[[solid.contact]]\nbodies = [\"block\", \"block\"]\n"
                                                "[[solid.contact]]\nbodies = [\"block\", \"block\"]\n"),
                    Catch::Contains("solid.contact[1].bodies") &&
                        Catch::Contains("repeats the contact"));
  // One way each, opposite directions: both directions once, as one two-way pair.
  const Config both = read("both.toml", "[solid]\n" + block + lid +
                                            "[[solid.contact]]\nbodies = [\"block\", \"lid\"]\n"
                                            "two_way = false\n"
                                            "[[solid.contact]]\nbodies = [\"lid\", \"block\"]\n"
                                            "two_way = false\n");
  CHECK(both.model.contacts.size() == 2);
  CHECK(read("pair.toml", "[solid]\n" + block + lid + pair).model.contacts.size() == 1);
  CHECK_THROWS_WITH(
      read("probe.toml",
           "[solid]\n" + block + "[[solid.body.probe]]\nname = \"P\"\npoint = [3, 3]\n"),
      Catch::Contains("solid.body[0].probe[0].point") && Catch::Contains("outside body"));
  // Options that served a study and were removed: a scene that still sets them is told so.
  CHECK_THROWS_WITH(read("lumped.toml", "[solid]\nmass = \"lumped\"\n" + block),
                    Catch::Contains("unknown key") && Catch::Contains("mass"));
  CHECK_THROWS_WITH(read("fluid_mass.toml", "[solid]\niteration_fluid_mass = false\n" + block),
                    Catch::Contains("unknown key") && Catch::Contains("iteration_fluid_mass"));
  const Config light = read("buoyant.toml", "[solid]\n" + block, 20.0);
  CHECK_THROWS_WITH(Solver(light.model), Catch::Contains("below the fluid density"));
}
