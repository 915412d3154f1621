// Checkpoints: which keys a restart may change, which checkpoint a restart takes, lists of vectors.
#include <catch2/catch.hpp>
#include <fstream>

#include "checkpoint.hpp"
#include "scene.hpp"

namespace {

const std::string kScene = R"(
[scene]
name = "a"
description = "first"
[time]
dt = 0.01
t_end = 1.0
[output]
interval = 0.1
[fluid]
viscosity = 0.01
[fluid.grid]
cells = [32, 16]
)";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("a restart may change t_end, [output] and the description, nothing else", "[checkpoint]") {
  using fsi::changed_physics_key;
  CHECK(changed_physics_key(kScene, kScene).empty());
  CHECK(changed_physics_key(kScene, replaced(kScene, "t_end = 1.0", "t_end = 2.0")).empty());
  CHECK(changed_physics_key(kScene, replaced(kScene, "interval = 0.1", "interval = 0.2\ncheckpoint_interval = 0.5")).empty());
  CHECK(changed_physics_key(kScene, replaced(kScene, "\"first\"", "\"second\"")).empty());
  CHECK(changed_physics_key(kScene, replaced(kScene, "viscosity = 0.01", "viscosity = 0.02")) == "fluid.viscosity");
  CHECK(changed_physics_key(kScene, replaced(kScene, "dt = 0.01", "dt = 0.02")) == "time.dt");
  CHECK(changed_physics_key(kScene, replaced(kScene, "[32, 16]", "[32, 17]")) == "fluid.grid.cells[1]");
  CHECK(changed_physics_key(kScene, replaced(kScene, "viscosity = 0.01", "viscosity = 0.01\ndensity = 2.0")) ==
        "fluid.density");
  CHECK(changed_physics_key(replaced(kScene, "viscosity = 0.01", "viscosity = 0.01\ndensity = 2.0"), kScene) ==
        "fluid.density");
}

TEST_CASE("a key the checkpoint's scene lacks, or holds and the scene lacks, counts as changed",
          "[checkpoint]") {
  using fsi::changed_physics_key;
  // Keys whose default changed (fluid.body_viscosity, fluid.implicit_forcing) are recorded in the
  // effective scene since; a checkpoint without them predates protocol version 8 and is refused
  // on its version before its scene is compared (check_checkpoint_version).
  const auto with = [&](const char* v) {
    return replaced(kScene, "viscosity = 0.01", std::string("viscosity = 0.01\nbody_viscosity = ") + v);
  };
  CHECK(changed_physics_key(kScene, with("\"kelvin-voigt\"")) == "fluid.body_viscosity");
  CHECK(changed_physics_key(kScene, with("\"none\"")) == "fluid.body_viscosity");
  CHECK(changed_physics_key(with("\"none\""), with("\"kelvin-voigt\"")) == "fluid.body_viscosity");
  CHECK(changed_physics_key(with("\"kelvin-voigt\""), kScene) == "fluid.body_viscosity");
  CHECK(changed_physics_key(with("\"none\""), with("\"none\"")).empty());
  CHECK(changed_physics_key(kScene, replaced(kScene, "viscosity = 0.01", "viscosity = 0.01\nforcing_time = 0.0")) ==
        "fluid.forcing_time");
}

namespace {
// Two programs reading a scene file as programs do: every one skips the others' top-level
// tables; "fluid" reads fluid.viscosity, fluid.density with a default (filled into its effective
// scene) and fluid.upwind_blend only when given; "solid" reads each [[solid.body]]'s name and its
// density with a default. The scene as the program read it.
enum class Reader { fluid, solid };
fsi::Scene read_as(Reader who, const std::string& text) {
  const auto file = std::filesystem::temp_directory_path() / "fsi_test_checkpoint_scene.toml";
  std::ofstream(file) << text;
  fsi::Scene scene(file);
  const fsi::SceneTable root = scene.root();
  for (const char* k : {"scene", "time", "fluid", "solid", "coupler"}) root.skip(k);
  if (who == Reader::fluid) {
    const fsi::SceneTable f = root.table("fluid");
    f.number("viscosity");
    f.number("density", 1.0);
    if (f.has("upwind_blend")) f.number("upwind_blend");
  } else {
    for (const fsi::SceneTable& b : root.table("solid").tables("body")) {
      b.string("name");
      b.number("density", 1.0);
    }
  }
  std::filesystem::remove(file);
  return scene;
}

// changed_physics_key as open_restart calls it: the checkpoint's effective scene (the program's
// reading of the run's scene) against the program's reading of the resumed scene.
std::string resumed(Reader who, const std::string& run, const std::string& resume, int* side = nullptr) {
  const fsi::Scene before = read_as(who, run);
  const fsi::Scene now = read_as(who, resume);
  return fsi::changed_physics_key(
      before.effective_toml(), now.effective_toml(),
      [&](const std::string& t, const std::string& k) { return now.reads(t, k); }, side);
}

const std::string kRun = R"(
[time]
dt = 0.01
t_end = 1.0
[fluid]
viscosity = 0.01
upwind_blend = 0.2
[solid]
[[solid.body]]
name = "a"
[coupler]
gain = 0.5
)";
}  // namespace

// Each program's checkpoint holds its own effective scene; the scene.effective.toml a run writes
// holds every program's defaults. Resumed with it, a program passes over the keys only one side
// has that it neither reads nor checks for, and refuses those it does.
TEST_CASE("a key only one side has counts only for the program that reads it", "[checkpoint]") {
  // The run's effective scene: both programs' defaults in it.
  const std::string merged = replaced(replaced(kRun, "upwind_blend = 0.2", "upwind_blend = 0.2\ndensity = 1.0"),
                                      "name = \"a\"", "name = \"a\"\ndensity = 1.0");
  CHECK(resumed(Reader::fluid, kRun, merged).empty());
  CHECK(resumed(Reader::solid, kRun, merged).empty());
  // ... and back from a run resumed with it to the scene it started from.
  CHECK(resumed(Reader::fluid, merged, kRun).empty());
  CHECK(resumed(Reader::solid, merged, kRun).empty());
  // A key read only when given, removed or added: the program that checks for it refuses, and
  // says on which side it is set.
  int side = -1;
  const std::string without = replaced(kRun, "upwind_blend = 0.2\n", "");
  CHECK(resumed(Reader::fluid, kRun, without, &side) == "fluid.upwind_blend");
  CHECK(side == 1);
  CHECK(resumed(Reader::fluid, without, kRun, &side) == "fluid.upwind_blend");
  CHECK(side == 2);
  CHECK(resumed(Reader::solid, kRun, without).empty());
  // A default a program fills in, given another value: a value that differs, for that program.
  const std::string denser = replaced(kRun, "name = \"a\"", "name = \"a\"\ndensity = 2.0");
  CHECK(resumed(Reader::solid, kRun, denser, &side) == "solid.body[0].density");
  CHECK(side == 0);
  CHECK(resumed(Reader::fluid, kRun, denser).empty());
  // A key no program here reads, in a table both sides have: compared by every program.
  CHECK(resumed(Reader::fluid, kRun, replaced(kRun, "gain = 0.5", "gain = 0.6")) == "coupler.gain");
  // Without `reads` (every key counts) the merged scene is refused.
  CHECK(fsi::changed_physics_key(read_as(Reader::fluid, kRun).effective_toml(),
                                 read_as(Reader::fluid, merged).effective_toml()) == "solid.body[0].density");
}

TEST_CASE("the restart takes the newest step every program completed", "[checkpoint]") {
  const auto out = std::filesystem::temp_directory_path() / "fsi_test_checkpoint";
  std::filesystem::remove_all(out);
  fsi::RoleSet fluid_solid;
  fluid_solid.need[static_cast<int>(fsi::Role::fluid)] = true;
  fluid_solid.need[static_cast<int>(fsi::Role::solid)] = true;
  CHECK_FALSE(fsi::newest_checkpoint(out, fluid_solid).has_value());
  auto touch = [&](long step, fsi::Role r, const char* suffix = "") {
    const auto p = fsi::checkpoint_file(out, step, r).string() + suffix;
    std::filesystem::create_directories(std::filesystem::path(p).parent_path());
    std::ofstream(p) << "x";
  };
  touch(100, fsi::Role::fluid), touch(100, fsi::Role::solid);
  touch(200, fsi::Role::fluid), touch(200, fsi::Role::solid);
  touch(300, fsi::Role::fluid), touch(300, fsi::Role::solid, ".tmp");  // the solid's was cut short
  touch(400, fsi::Role::solid);
  std::filesystem::create_directories(out / "checkpoint" / "step_junk");
  CHECK(fsi::newest_checkpoint(out, fluid_solid) == 200);
  fsi::RoleSet fluid_only;
  fluid_only.need[static_cast<int>(fsi::Role::fluid)] = true;
  CHECK(fsi::newest_checkpoint(out, fluid_only) == 300);
  std::filesystem::remove_all(out);
}

TEST_CASE("lists of vectors come back as they were, empty ones too", "[checkpoint]") {
  const auto path = std::filesystem::temp_directory_path() / "fsi_test_vectors.h5";
  const std::vector<std::vector<double>> v{{1.0, 2.5}, {}, {-3.0, 1e300, 4.0}};
  {
    fsi::H5File h5(path, fsi::H5File::Mode::truncate);
    fsi::write_vectors(h5, "a", v);
    fsi::write_vectors(h5, "none", {});
  }
  fsi::H5File h5(path, fsi::H5File::Mode::read_only);
  CHECK(fsi::read_vectors(h5, "a") == v);
  CHECK(fsi::read_vectors(h5, "none").empty());
}

TEST_CASE("a checkpoint of another protocol version is refused, naming both", "[checkpoint]") {
  const auto out = std::filesystem::temp_directory_path() / "fsi_test_checkpoint_version";
  std::filesystem::remove_all(out);
  const auto file = fsi::checkpoint_file(out, 100, fsi::Role::solid);
  std::filesystem::create_directories(file.parent_path());
  auto write = [&](std::int64_t version) {
    fsi::H5File h5(file, fsi::H5File::Mode::truncate);
    if (version >= 0) h5.set_attribute("/", "protocol_version", version);
  };
  write(fsi::proto::kVersion);
  CHECK_NOTHROW(fsi::check_checkpoint_version(out, 100, fsi::Role::solid, "s.toml"));
  write(7);
  CHECK_THROWS_WITH(fsi::check_checkpoint_version(out, 100, fsi::Role::solid, "s.toml"),
                    Catch::Contains("protocol version 7, this build speaks " +
                                    std::to_string(fsi::proto::kVersion)));
  write(-1);  // no attribute: written before the version was recorded
  CHECK_THROWS_WITH(fsi::check_checkpoint_version(out, 100, fsi::Role::solid, "s.toml"),
                    Catch::Contains("protocol version none recorded"));
  std::filesystem::remove_all(out);
}
