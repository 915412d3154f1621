// Tension equation: inextensibility under a strong flapping motion, the exact tension of a
// hanging chain at rest, and the pull-back of a drifted length.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "error.hpp"
#include "fixtures.hpp"

using namespace fiber;
using namespace fiber::test;

namespace {

// A clamped fiber whose root direction flaps by +-45 degrees at a frequency near its first mode,
// under gravity: large, fast deformation.
Config flapping(int iterations) {
  FiberSpec f = make_fiber(1.0, 32, 1.0, 0.01);
  f.root.kind = EndKind::clamped;
  f.root.angle_amplitude = std::numbers::pi / 4;
  f.root.frequency = 0.5;
  Config c = one_fiber(f);
  c.gravity = {0, -1};
  c.tension_iterations = iterations;
  return c;
}

}  // namespace

TEST_CASE("inextensibility: |X_s| = 1 within 1e-6 after 1e4 steps of flapping", "[fiber][tension]") {
  Config c = flapping(8);
  const double dt = 0.9 * bending_dt_limit(c.fibers[0]);
  FiberSystem sys(c);
  double worst = 0;
  for (int n = 0; n < 10000; ++n) {
    sys.advance(dt);
    worst = std::max(worst, sys.max_stretch());
  }
  // The fiber really moved: the tip swept a large arc.
  const auto x = sys.positions(0);
  INFO("tip at " << x[64] << ", " << x[65] << ", t = " << sys.time());
  CHECK(std::abs(x[65]) > 0.05);
  CHECK(worst <= 1e-6);
  CHECK(worst <= 1e-10);  // Newton to 1e-12 in |d|^2/ds^2
}

TEST_CASE("a single linear tension solve per step keeps the length through its pull-back term",
          "[fiber][tension]") {
  Config c = flapping(1);
  c.stretch_limit = 1e-2;
  const double dt = 0.9 * bending_dt_limit(c.fibers[0]);
  FiberSystem sys(c);
  double worst = 0, typical = 0;
  int above = 0;
  for (int n = 0; n < 10000; ++n) {
    sys.advance(dt);
    worst = std::max(worst, sys.max_stretch());
    if (sys.max_stretch() > 1e-6) ++above;
  }
  typical = sys.max_stretch();
  INFO("one solve per step: max stretch " << worst << ", steps above 1e-6: " << above << ", final " << typical);
  // The O(h^4) remainder of one linear solve does not accumulate: the next step's right-hand
  // side contains ds^2 - |d^n|^2 and pulls a drifted length back. Violent moments (the tension
  // jumps when the flapping root whips the fiber) leave short excursions, which the Newton
  // iteration of the default settings removes.
  CHECK(worst < 1e-3);
  CHECK(typical < 1e-6);
}

TEST_CASE("a bending-free chain hanging from a hinge stays at rest with T = rho' g (L - s)",
          "[fiber][tension]") {
  FiberSpec f = make_fiber(2.0, 20, 0.3, 0.0, {0, 0}, -std::numbers::pi / 2);
  f.root.kind = EndKind::hinged;
  Config c = one_fiber(f);
  c.gravity = {0, -9.81};
  FiberSystem sys(c);
  const std::vector<double> x0(sys.positions(0).begin(), sys.positions(0).end());
  for (int n = 0; n < 2000; ++n) sys.advance(1e-3);
  const auto x = sys.positions(0);
  double moved = 0;
  for (std::size_t i = 0; i < x.size(); ++i) moved = std::max(moved, std::abs(x[i] - x0[i]));
  CHECK(moved < 1e-12);
  const auto T = sys.segment_tension(0);
  for (int j = 0; j < 20; ++j) {
    const double s = (j + 0.5) * 0.1;
    CHECK(T[j] == Approx(0.3 * 9.81 * (2.0 - s)).epsilon(1e-7));
  }
  // The hinge carries the weight, without moment.
  CHECK(sys.root_load(0).force.y() == Approx(-0.3 * 2.0 * 9.81).epsilon(1e-7));
  CHECK(std::abs(sys.root_load(0).force.x()) < 1e-12);
  CHECK(sys.root_load(0).moment == 0.0);
}

TEST_CASE("a free fiber falls with exactly g and carries no tension", "[fiber][tension]") {
  FiberSpec f = make_fiber(1.0, 8, 2.0, 0.5, {0, 0}, 0.3);
  Config c = one_fiber(f);
  c.gravity = {0.5, -2.0};
  FiberSystem sys(c);
  const std::vector<double> x0(sys.positions(0).begin(), sys.positions(0).end());
  const double dt = 0.5 * bending_dt_limit(f);
  for (int n = 0; n < 500; ++n) sys.advance(dt);
  const double t = sys.time();
  const auto x = sys.positions(0);
  for (int i = 0; i <= 8; ++i) {
    CHECK(x[2 * i] == Approx(x0[2 * i] + 0.5 * 0.5 * t * t).margin(1e-11));
    CHECK(x[2 * i + 1] == Approx(x0[2 * i + 1] - 0.5 * 2.0 * t * t).margin(1e-11));
  }
  for (double T : sys.segment_tension(0)) CHECK(std::abs(T) < 1e-9);
}

TEST_CASE("health: supports pulled apart beyond the fiber's length stop the run with the stretch",
          "[fiber][tension]") {
  // A slack chain between two hinges whose tip support moves away: once the supports are
  // farther apart than the length, no tension can hold it.
  FiberSpec f = make_fiber(1.0, 16, 1.0, 0.0, {0, 0}, -0.6);
  f.shape = ShapeKind::arc;
  f.curvature = 1.2;
  f.root.kind = EndKind::hinged;
  f.tip.kind = EndKind::hinged;
  f.tip.velocity = {0.5, 0.0};
  Config c = one_fiber(f);
  FiberSystem sys(c);
  const auto x = sys.positions(0);
  const double chord = std::hypot(x[32] - x[0], x[33] - x[1]);
  REQUIRE(chord < 1.0);
  const double dt = 1e-3;
  std::string message;
  try {
    for (int n = 0; n < 20000; ++n) sys.advance(dt);
  } catch (const fsi::Error& e) {
    message = e.what();
  }
  INFO("stopped at t = " << sys.time() << " with: " << message);
  CHECK_THAT(message, Catch::Matchers::Contains("stretch") && Catch::Matchers::Contains("fiber.stretch_limit"));
  // it stopped once the supports were about a length apart, not before
  CHECK(chord + 0.5 * sys.time() > 0.99);
}
