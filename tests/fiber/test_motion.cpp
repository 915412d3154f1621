// Prescribed-motion fibers (fixed, translating, rotating, beating), many fibers in one system,
// and the library's own input checks (overlap, lengths, the explicit bending limit).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "error.hpp"
#include "fixtures.hpp"

using namespace fiber;
using namespace fiber::test;
using Catch::Matchers::Contains;

TEST_CASE("rotating fiber follows the rigid rotation; its driver feels the centripetal load", "[fiber][motion]") {
  FiberSpec f = make_fiber(1.0, 10, 2.0, 0.0, {1, 0}, 0.0);
  f.motion.kind = MotionKind::rotating;
  f.motion.center = {0, 0};
  f.motion.angular_velocity = 3.0;
  FiberSystem sys(one_fiber(f));
  const double dt = 1e-3;
  for (int n = 0; n < 500; ++n) sys.advance(dt);
  const double a = 3.0 * sys.time();
  const auto x = sys.positions(0);
  for (int i = 0; i <= 10; ++i) {
    const double r = 1.0 + 0.1 * i;
    CHECK(x[2 * i] == Approx(r * std::cos(a)).margin(1e-12));
    CHECK(x[2 * i + 1] == Approx(r * std::sin(a)).margin(1e-12));
  }
  // load on the driver = sum m omega^2 (X - c) = rho' L omega^2 r_centroid, r_centroid = 1.5
  const Vec2 load = sys.root_load(0).force;
  CHECK(load.norm() == Approx(2.0 * 1.0 * 9.0 * 1.5).epsilon(1e-6));
  // the load of the step t^n -> t^(n+1) is the one at t^n (explicit forces)
  const double an = 3.0 * (sys.time() - dt);
  CHECK(load.normalized().dot(Vec2(std::cos(an), std::sin(an))) == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("translating and fixed fibers: the driver carries the applied loads", "[fiber][motion]") {
  Config c;
  FiberSpec a = make_fiber(1.0, 8, 1.5, 0.0, {0, 0}, 0.0);
  a.motion.kind = MotionKind::fixed;
  FiberSpec b = make_fiber(0.5, 4, 1.0, 0.0, {0, 1}, std::numbers::pi / 2);
  b.name = std::string("b");
  b.key = std::string("fiber.fiber[1]");
  b.motion.kind = MotionKind::translating;
  b.motion.velocity = {0.2, -0.1};
  c.fibers = {a, b};
  c.gravity = {0, -2};
  FiberSystem sys(c);
  std::vector<double> ext(2 * (9 + 5), 0.0);
  for (int i = 0; i < 9; ++i) ext[2 * i] = 1.0;  // 1 per unit length along x on fiber a
  for (int n = 0; n < 10; ++n) sys.advance(0.01, ext);
  CHECK(sys.root_load(0).force.x() == Approx(1.0).epsilon(1e-12));
  CHECK(sys.root_load(0).force.y() == Approx(-2 * 1.5).epsilon(1e-12));
  CHECK(sys.root_load(0).moment == Approx(-2 * 1.5 * 0.5).epsilon(1e-12));  // weight at x = 1/2
  CHECK(sys.root_load(1).force.y() == Approx(-2 * 0.5).epsilon(1e-9));
  CHECK(sys.positions(1)[0] == Approx(0.2 * sys.time()).margin(1e-12));
  CHECK(sys.positions(1)[1] == Approx(1 - 0.1 * sys.time()).margin(1e-12));
}

TEST_CASE("beating fiber keeps every segment at length ds", "[fiber][motion]") {
  FiberSpec f = make_fiber(1.0, 30, 1.0, 0.0, {0, 0}, std::numbers::pi / 2);
  f.motion.kind = MotionKind::beating;
  f.motion.amplitude = 0.6;
  f.motion.frequency = 2.0;
  f.motion.wavelength = 0.7;
  FiberSystem sys(one_fiber(f));
  double worst = 0, tip_min = 1, tip_max = -1;
  for (int n = 0; n < 600; ++n) {
    sys.advance(1e-3);
    worst = std::max(worst, sys.max_stretch());
    tip_min = std::min(tip_min, sys.positions(0)[60]);
    tip_max = std::max(tip_max, sys.positions(0)[60]);
  }
  CHECK(worst < 1e-13);
  CHECK(tip_max - tip_min > 0.2);  // it beats
  CHECK(sys.positions(0)[0] == 0.0);
}

TEST_CASE("many fibers: a row of identical clamped fibers moves identically", "[fiber][motion]") {
  Config c;
  for (int k = 0; k < 16; ++k) {
    FiberSpec f = make_fiber(0.125, 62, 0.1, 1e-4, {k / 16.0, 0}, std::numbers::pi / 2);
    f.name = fmt::format("g{}", k);
    f.key = std::string("fiber.fiber[0]");
    f.root.kind = EndKind::clamped;
    c.fibers.push_back(f);
  }
  c.gravity = {1, 0};
  c.repulsion = {true, 1e-9, 0.5 / 128};
  c.substeps = 3;
  FiberSystem sys(c);
  const double dt = 2.5 * bending_dt_limit(c.fibers[0]);
  for (int n = 0; n < 200; ++n) sys.advance(dt);
  const auto x0 = sys.positions(0);
  CHECK(x0[2 * 62] > 1e-4);  // bent by the load
  for (int k = 1; k < 16; ++k) {
    const auto x = sys.positions(k);
    for (int i = 0; i <= 62; ++i) {
      CHECK(x[2 * i] - k / 16.0 == Approx(x0[2 * i]).margin(1e-12));
      CHECK(x[2 * i + 1] == Approx(x0[2 * i + 1]).margin(1e-12));
    }
  }
}

TEST_CASE("library input checks: overlap, sizes, the bending limit", "[fiber][input]") {
  FiberSpec a = make_fiber(1.0, 10, 1.0, 1.0);
  FiberSpec b = make_fiber(1.0, 10, 1.0, 1.0, {0.5, 0.001}, 0.0);
  b.name = std::string("b");
  b.key = std::string("fiber.fiber[1]");
  Config c;
  c.fibers = {a, b};
  c.repulsion = {true, 1e-6, 0.01};
  c.file = "scene.toml";
  CHECK_THROWS_WITH(FiberSystem(c), Contains("start overlapping") && Contains("fiber.fiber[1]") &&
                                        Contains("fiber.repulsion.cutoff = 0.01") && Contains("in scene.toml"));
  c.repulsion.is_enabled = false;
  c.fibers[1].position = {0.5, 0};
  CHECK_THROWS_WITH(FiberSystem(c), Contains("start overlapping") && Contains("coincide"));
  c.fibers[1].position = {0.5, 0.5};
  CHECK_NOTHROW(FiberSystem(c));

  Config d = one_fiber(make_fiber(-1.0, 10, 1.0, 1.0));
  CHECK_THROWS_WITH(FiberSystem(d), Contains("fiber.fiber[0].length must be > 0, got -1"));
  d = one_fiber(make_fiber(1.0, 1, 1.0, 1.0));
  CHECK_THROWS_WITH(FiberSystem(d), Contains("fiber.fiber[0].segments must be >= 2, got 1"));

  // dt above the explicit bending limit: the message states the limit.
  d = one_fiber(make_fiber(1.0, 10, 1.0, 1.0));
  const double limit = 0.01 * std::sqrt(1.0 / 12);
  CHECK(bending_dt_limit(d.fibers[0]) == Approx(limit));
  CHECK(time_step_problem(d, 0.99 * limit).empty());
  const std::string msg = time_step_problem(d, 1e-2);
  CHECK_THAT(msg, Contains("time.dt = 0.01") && Contains("bending stability limit") &&
                      Contains(fmt::format("{:.6g}", limit)) && Contains("fiber.substeps >= 4"));
  FiberSystem sys(d);
  CHECK_THROWS_WITH(sys.advance(1e-2), Contains("bending stability limit"));
  d.substeps = 4;
  CHECK(time_step_problem(d, 1e-2).empty());
}
