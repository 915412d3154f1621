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

// Each program's checkpoint holds its own effective scene; the scene.effective.toml a run writes
// also holds the defaults the other programs filled in. Resumed with it, a program passes over
// the keys only one side has that it does not read, and still refuses those it reads.
TEST_CASE("a key only one side has counts only for the program that reads it", "[checkpoint]") {
  using fsi::changed_physics_key;
  const std::string merged = kScene + "[coupler]\nfootprint_smoothing = 0.0\n";
  const auto fluid_reads = [](const std::string& table, const std::string& key) {
    return table.starts_with("fluid") || (table.empty() && key == "fluid");
  };
  const auto coupler_reads = [](const std::string& table, const std::string& key) {
    return table == "coupler" || (table.empty() && key == "coupler");
  };
  CHECK(changed_physics_key(kScene, merged, fluid_reads).empty());
  CHECK(changed_physics_key(merged, kScene, fluid_reads).empty());
  CHECK(changed_physics_key(kScene, merged, coupler_reads) == "coupler");
  CHECK(changed_physics_key(kScene, merged) == "coupler");
  const std::string denser = replaced(kScene, "viscosity = 0.01", "viscosity = 0.01\ndensity = 2.0");
  CHECK(changed_physics_key(kScene, denser, fluid_reads) == "fluid.density");
  CHECK(changed_physics_key(kScene, denser, coupler_reads).empty());
  // A value both sides hold is compared whoever reads it.
  CHECK(changed_physics_key(merged, replaced(merged, "smoothing = 0.0", "smoothing = 0.5"), fluid_reads) ==
        "coupler.footprint_smoothing");
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
