// Reading [fiber] from a scene: a good scene with a row of fibers and probes, and every bad
// input of the fiber solver with its error text.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <functional>

#include "config.hpp"
#include "system.hpp"

using namespace fiber;
using Catch::Matchers::Contains;

namespace {

std::filesystem::path write_scene(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / "fsi_test_fiber_config";
  std::filesystem::create_directories(dir);
  const auto p = dir / name;
  std::ofstream(p) << text;
  return p;
}

Config read(const std::string& name, const std::string& text) {
  fsi::Scene scene(write_scene(name, text));
  return read_config(scene.root().table("fiber"));
}

// a + b without the operator+ that GCC 12 misreports under -Wrestrict
std::string with(const std::string& a, const char* b) { return fmt::format("{}{}", a, b); }

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const fsi::InputError& e) {
    return e.what();
  }
  return "no error";
}

const char* kGlycocalyx = R"(
[fiber]
gravity = [0, -1]
substeps = 2
[fiber.repulsion]
stiffness = 1e-8
cutoff = 0.004
[[fiber.fiber]]
name = "strand"
length = 0.125
segments = 62
density = 0.1
bending = 1e-4
position = [0.03125, 0]
angle = 90
count = 16
spacing = [0.0625, 0]
[fiber.fiber.root]
kind = "clamped"
[[fiber.fiber]]
name = "cilium"
length = 0.2
segments = 20
density = 1
bending = 0
position = [0.5, 0.5]
angle = -90
[fiber.fiber.motion]
kind = "rotating"
center = [0.5, 0.5]
angular_velocity = 90
[[fiber.probe]]
name = "tip3"
fiber = "strand_3"
s = 0.125
)";

}  // namespace

TEST_CASE("a good [fiber] table: rows, clamped roots, prescribed motion, probes", "[fiber][config]") {
  const Config c = read("good.toml", kGlycocalyx);
  REQUIRE(c.fibers.size() == 17);
  CHECK(c.substeps == 2);
  CHECK(c.gravity.y() == -1.0);
  CHECK(c.repulsion.is_enabled);
  CHECK(c.repulsion.cutoff == 0.004);
  CHECK(c.fibers[3].name == "strand_3");
  CHECK(c.fibers[3].position.x() == Approx(0.03125 + 3 * 0.0625));
  CHECK(c.fibers[3].root.kind == EndKind::clamped);
  CHECK(c.fibers[3].root.angle == Approx(std::numbers::pi / 2));
  CHECK(c.fibers[3].angle == Approx(std::numbers::pi / 2));
  CHECK(c.fibers[16].motion.kind == MotionKind::rotating);
  CHECK(c.fibers[16].motion.angular_velocity == Approx(std::numbers::pi / 2));
  REQUIRE(c.probes.size() == 1);
  CHECK(c.probes[0].fiber == 3);
  FiberSystem sys(c);
  CHECK(sys.total_markers() == 16 * 63 + 21);
}

TEST_CASE("bad fiber input: each error names the key, the value and the file", "[fiber][config]") {
  const std::string base = R"(
[fiber]
[[fiber.fiber]]
name = "a"
density = 1
bending = 1
position = [0, 0]
)";
  // length <= 0
  auto e = error_of([&] { read("len.toml", with(base, "length = -1\nsegments = 8\n")); });
  CHECK_THAT(e, Contains("fiber.fiber[0].length must be > 0, got -1") && Contains("len.toml:8"));
  e = error_of([&] { read("len0.toml", with(base, "length = 0\nsegments = 8\n")); });
  CHECK_THAT(e, Contains("fiber.fiber[0].length must be > 0, got 0"));
  // fewer than 2 segments
  e = error_of([&] { read("seg.toml", with(base, "length = 1\nsegments = 1\n")); });
  CHECK_THAT(e, Contains("fiber.fiber[0].segments must be >= 2, got 1") && Contains("seg.toml:9"));
  // a typo
  e = error_of([&] { read("typo.toml", with(base, "length = 1\nsegments = 8\nbendng = 2\n")); });
  CHECK_THAT(e, Contains("unknown key 'fiber.fiber[0].bendng'") && Contains("did you mean 'bending'"));
  // no fiber at all: a scene without fibers, not an error
  CHECK(read("none.toml", "[fiber]\ngravity = [0, -1]\n").fibers.empty());
  CHECK_NOTHROW(FiberSystem(read("none.toml", "[fiber]\n")));
  // a probe on a fiber that does not exist
  e = error_of([&] {
    read("probe.toml", with(base, "length = 1\nsegments = 8\n[[fiber.probe]]\nname = \"p\"\nfiber = \"b\"\ns = 0.5\n"));
  });
  CHECK_THAT(e, Contains("fiber.probe[0].fiber") && Contains("names no fiber of the scene; fibers: a"));
  e = error_of([&] {
    read("probe_s.toml", with(base, "length = 1\nsegments = 8\n[[fiber.probe]]\nname = \"p\"\nfiber = \"a\"\ns = 2\n"));
  });
  CHECK_THAT(e, Contains("fiber.probe[0].s must be in [0, 1], got 2"));
}

TEST_CASE("bad fiber input: attached roots", "[fiber][config]") {
  const std::string base = R"(
[fiber]
[[fiber.fiber]]
name = "a"
length = 1
segments = 8
density = 1
bending = 1
angle = 90
[fiber.fiber.root]
kind = "attached"
)";
  // a body that cannot exist: the scene has no solid
  const auto path = write_scene("nosolid.toml", with(base, "body = \"wall\"\npoint = [0.5, 0.1]\n"));
  fsi::Scene scene(path);
  const auto table = scene.root().table("fiber");
  const Config c = read_config(table);
  CHECK(c.fibers[0].position.x() == 0.5);
  CHECK(c.fibers[0].root.body == "wall");
  const auto e = error_of([&] { check_attachments(c, table, false); });
  CHECK_THAT(e, Contains("fiber.fiber[0].root.body") && Contains("\"wall\"") &&
                    Contains("the scene has no [solid] section") && Contains("nosolid.toml:12"));
  CHECK(error_of([&] { check_attachments(c, table, true); }) == "no error");
  // no surface point, an empty body name, a position besides the point
  CHECK_THAT(error_of([&] { read("nopoint.toml", with(base, "body = \"wall\"\n")); }),
             Contains("fiber.fiber[0].root.point"));
  CHECK_THAT(error_of([&] { read("nobody.toml", with(base, "body = \"\"\npoint = [0, 0]\n")); }),
             Contains("fiber.fiber[0].root.body must name the solid body"));
  CHECK_THAT(error_of([&] { read("tip.toml", R"(
[fiber]
[[fiber.fiber]]
name = "a"
length = 1
segments = 8
density = 1
bending = 1
position = [0, 0]
[fiber.fiber.tip]
kind = "attached"
)"); }),
             Contains("fiber.fiber[0].tip.kind must be one of free, clamped, hinged"));
}

TEST_CASE("bad fiber input: markers that start overlapping", "[fiber][config]") {
  const std::string text = R"(
[fiber]
[fiber.repulsion]
stiffness = 1e-6
cutoff = 0.02
[[fiber.fiber]]
name = "row"
length = 1
segments = 10
density = 1
bending = 1
position = [0, 0]
angle = 90
count = 3
spacing = [0.01, 0]
)";
  const Config c = read("overlap.toml", text);
  const auto e = error_of([&] { FiberSystem sys(c); });
  CHECK_THAT(e, Contains("fibers 'row_0' (fiber.fiber[0] (fiber 0 of the row)) and 'row_1'") &&
                    Contains("start overlapping") && Contains("0.01 apart") &&
                    Contains("fiber.repulsion.cutoff = 0.02") && Contains("overlap.toml"));
}

TEST_CASE("bad fiber input: time step above the explicit bending limit", "[fiber][config]") {
  const Config c = read("dt.toml", R"(
[fiber]
[[fiber.fiber]]
name = "beam"
length = 1
segments = 20
density = 1
bending = 1
position = [0, 0]
[fiber.fiber.root]
kind = "clamped"
)");
  const double limit = 0.05 * 0.05 * std::sqrt(1.0 / 12);
  CHECK(error_of([&] { check_time_step(c, 0.99 * limit); }) == "no error");
  const auto e = error_of([&] { check_time_step(c, 1e-3); });
  CHECK_THAT(e, Contains("time.dt = 0.001 is above the explicit bending stability limit of fiber 'beam'") &&
                    Contains(fmt::format("= {:.6g}", limit)) && Contains("fiber.substeps >= 2") &&
                    Contains("dt.toml"));
}
