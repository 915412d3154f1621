// Scene reading: good files read with defaults filled in; every bad case names key, value, file.
#include <catch2/catch.hpp>
#include <fstream>

#include "runtime.hpp"
#include "scene.hpp"

namespace {

std::filesystem::path write_scene(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "fsi_test_scene";
  std::filesystem::create_directories(dir);
  const auto p = dir / name;
  std::ofstream(p) << text;
  return p;
}

const char* kGood = R"(
[scene]
name = "good"
[time]
dt = 1e-3
t_end = 0.5
[output]
interval = 0.1
[fluid]
density = 2
cells = [16, 8]
)";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const fsi::InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("a good scene is read with defaults filled in") {
  const auto file = write_scene("good.toml", kGood);
  fsi::Scene scene(file);
  const auto root = scene.root();
  const auto s = fsi::read_common(root);
  CHECK(s.name == "good");
  CHECK(s.dt == 1e-3);
  CHECK(s.steps == 500);
  CHECK(s.output_interval == 0.1);
  const auto fluid = root.table("fluid");
  CHECK(fluid.positive("density") == 2.0);
  CHECK(fluid.positive("viscosity", 0.25) == 0.25);
  CHECK(fluid.numbers("cells") == std::vector<double>{16, 8});
  CHECK(fluid.choice("diffusion", {"explicit", "implicit"}, std::string("implicit")) == "implicit");
  fluid.finish();
  const std::string eff = scene.effective_toml();
  CHECK(eff.find("viscosity") != std::string::npos);
  CHECK(eff.find("0.25") != std::string::npos);
  CHECK(eff.find("diffusion") != std::string::npos);
  // The effective scene is itself a valid scene with the same values.
  const auto again = write_scene("again.toml", eff);
  fsi::Scene s2(again);
  CHECK(s2.root().table("fluid").number("viscosity") == 0.25);
  CHECK(fsi::roles_needed(root).names() == "fluid");
}

TEST_CASE("t_end not a multiple of dt rounds the step count up") {
  const auto file = write_scene("steps.toml", "[time]\ndt = 0.3\nt_end = 1.0\n[fluid]\n");
  fsi::Scene scene(file);
  CHECK(fsi::read_common(scene.root()).steps == 4);
}

TEST_CASE("bad scenes give errors naming key, value and file") {
  SECTION("missing file") {
    const auto msg = error_of([] { fsi::Scene s("/nonexistent/dir/scene.toml"); });
    CHECK_THAT(msg, Catch::Contains("scene file '/nonexistent/dir/scene.toml' does not exist"));
  }
  SECTION("TOML syntax error") {
    const auto f = write_scene("syntax.toml", "[time]\ndt = = 1\n");
    const auto msg = error_of([&] { fsi::Scene s(f); });
    CHECK_THAT(msg, Catch::Contains("TOML syntax error"));
    CHECK_THAT(msg, Catch::Contains("syntax.toml"));
  }
  SECTION("unknown key with a suggestion") {
    const auto f = write_scene("unknown.toml", "[time]\ndt = 0.1\nt_end = 1\n[output]\ninterval = 0.1\nprogres = 1\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::read_common(s.root()); });
    CHECK_THAT(msg, Catch::Contains("unknown key 'output.progres'"));
    CHECK_THAT(msg, Catch::Contains("unknown.toml:6"));
    CHECK_THAT(msg, Catch::Contains("did you mean 'progress'?"));
  }
  SECTION("a misspelt required key") {
    const auto f = write_scene("typo.toml", "[time]\ndt = 0.1\ntend = 1\n[fluid]\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::read_common(s.root()); });
    CHECK_THAT(msg, Catch::Contains("missing required key 'time.t_end'"));
    CHECK_THAT(msg, Catch::Contains("did you mean 't_end' instead of 'tend'"));
  }
  SECTION("unknown top-level table") {
    const auto f = write_scene("top.toml", "[time]\ndt = 0.1\nt_end = 1\n[fluidd]\n[fluid]\n");
    fsi::Scene s(f);
    const auto root = s.root();
    fsi::read_common(root);
    for (const char* k : {"fluid", "solid", "fiber", "coupler"}) root.skip(k);
    const auto msg = error_of([&] { root.finish(); });
    CHECK_THAT(msg, Catch::Contains("unknown key 'fluidd'"));
    CHECK_THAT(msg, Catch::Contains("did you mean 'fluid'?"));
  }
  SECTION("wrong type") {
    const auto f = write_scene("type.toml", "[time]\ndt = \"small\"\nt_end = 1\n[fluid]\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::read_common(s.root()); });
    CHECK_THAT(msg, Catch::Contains("time.dt must be a number, got \"small\" (string)"));
    CHECK_THAT(msg, Catch::Contains("type.toml:2"));
  }
  SECTION("dt <= 0") {
    const auto f = write_scene("dt.toml", "[time]\ndt = -1e-3\nt_end = 1\n[fluid]\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::read_common(s.root()); });
    CHECK_THAT(msg, Catch::Contains("time.dt must be > 0, got -0.001"));
    CHECK_THAT(msg, Catch::Contains("dt.toml:2"));
  }
  SECTION("t_end <= 0") {
    const auto f = write_scene("tend.toml", "[time]\ndt = 1e-3\nt_end = 0\n[fluid]\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::read_common(s.root()); });
    CHECK_THAT(msg, Catch::Contains("time.t_end must be > 0, got 0"));
  }
  SECTION("missing [time]") {
    const auto f = write_scene("notime.toml", "[fluid]\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::read_common(s.root()); });
    CHECK_THAT(msg, Catch::Contains("missing required table [time]"));
  }
  SECTION("a file that does not exist") {
    const auto f = write_scene("mesh.toml", "[solid]\nmesh = \"no-such-mesh.msh\"\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { s.root().table("solid").existing_file("mesh"); });
    CHECK_THAT(msg, Catch::Contains("solid.mesh names file"));
    CHECK_THAT(msg, Catch::Contains("no-such-mesh.msh', which does not exist"));
  }
  SECTION("a choice outside its set") {
    const auto f = write_scene("choice.toml", "[fluid]\ndiffusion = \"implict\"\n");
    fsi::Scene s(f);
    const auto msg =
        error_of([&] { s.root().table("fluid").choice("diffusion", {"explicit", "implicit"}); });
    CHECK_THAT(msg, Catch::Contains("must be one of explicit, implicit, got \"implict\""));
    CHECK_THAT(msg, Catch::Contains("did you mean 'implicit'?"));
  }
  SECTION("integers where an integer is needed") {
    const auto f = write_scene("int.toml", "[fluid]\ncells = 1.5\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { s.root().table("fluid").positive_integer("cells"); });
    CHECK_THAT(msg, Catch::Contains("fluid.cells must be an integer, got 1.5 (float)"));
  }
  SECTION("a scene with no solver") {
    const auto f = write_scene("none.toml", "[time]\ndt = 1\nt_end = 1\n");
    fsi::Scene s(f);
    const auto msg = error_of([&] { fsi::roles_needed(s.root()); });
    CHECK_THAT(msg, Catch::Contains("nothing to run"));
  }
}

TEST_CASE("edit distance") {
  CHECK(fsi::edit_distance("viscosity", "viscocity") == 1);
  CHECK(fsi::edit_distance("", "abc") == 3);
  CHECK(fsi::edit_distance("dt", "dt") == 0);
}

TEST_CASE("output folders are never silently overwritten") {
  const auto root = std::filesystem::temp_directory_path() / "fsi_test_out";
  std::filesystem::remove_all(root);
  const auto a = fsi::choose_out_dir(root, "case", false);
  std::ofstream(a / "keep.txt") << "data";
  const auto b = fsi::choose_out_dir(root, "case", false);
  CHECK(a.filename() == "case");
  CHECK(b.filename() == "case-2");
  CHECK(std::filesystem::exists(a / "keep.txt"));
  // --overwrite: the same folder (emptied by run_program once it holds the folder's lock).
  const auto c = fsi::choose_out_dir(root, "case", true);
  CHECK(c == a);
}
