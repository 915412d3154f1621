// Checkpoints: which keys a restart may change, which checkpoint a restart takes, lists of vectors.
#include <catch2/catch.hpp>
#include <fstream>

#include "checkpoint.hpp"

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

TEST_CASE("a key recorded since its default changed: absent counts as its old value", "[checkpoint]") {
  using fsi::changed_physics_key;
  // A checkpoint from before fluid.body_viscosity was recorded ran the bodies as Kelvin-Voigt
  // solids: the same explicitly continues it, the new default does not.
  const auto with = [&](const char* v) {
    return replaced(kScene, "viscosity = 0.01", std::string("viscosity = 0.01\nbody_viscosity = ") + v);
  };
  CHECK(changed_physics_key(kScene, with("\"kelvin-voigt\"")).empty());
  CHECK(changed_physics_key(kScene, with("'kelvin-voigt'")).empty());
  CHECK(changed_physics_key(kScene, with("\"none\"")) == "fluid.body_viscosity");
  CHECK(changed_physics_key(with("\"none\""), with("\"kelvin-voigt\"")) == "fluid.body_viscosity");
  CHECK(changed_physics_key(with("\"kelvin-voigt\""), kScene) == "fluid.body_viscosity");
  // Crank-Nicolson's forcing, recorded since its default became "increment".
  const auto forcing = [&](const char* v) {
    return replaced(kScene, "viscosity = 0.01",
                    std::string("viscosity = 0.01\nimplicit_forcing = ") + v);
  };
  CHECK(changed_physics_key(kScene, forcing("\"after_solve\"")).empty());
  CHECK(changed_physics_key(kScene, forcing("\"increment\"")) == "fluid.implicit_forcing");
  // Any other key added at a restart still counts.
  CHECK(changed_physics_key(kScene, replaced(kScene, "viscosity = 0.01", "viscosity = 0.01\nforcing_time = 0.0")) ==
        "fluid.forcing_time");
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
