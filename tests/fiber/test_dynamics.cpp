// Dynamics against exact references (short versions of the validation cases): cantilever
// frequencies (Euler-Bernoulli) and the period of a stiff hinged fiber (rigid rod pendulum).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "fixtures.hpp"

using namespace fiber;
using namespace fiber::test;

namespace {

// Frequency of cantilever mode k measured from the projection of the deflection on the mode.
double cantilever_frequency(int mode, int segments, double periods) {
  FiberSpec f = make_fiber(1.0, segments, 1.0, 1.0);
  f.shape = ShapeKind::points;
  f.points = cantilever_shape(mode, 5e-4, 1.0, segments);
  f.root.kind = EndKind::clamped;
  f.root.has_angle = true;  // clamped along x, not along the deflected first segment
  FiberSystem sys(one_fiber(f));
  const double omega = std::pow(cantilever_beta(mode), 2);
  const double t_end = periods * 2 * std::numbers::pi / omega;
  const double dt = 0.9 * bending_dt_limit(f);
  std::vector<double> t, q;
  while (sys.time() < t_end) {
    sys.advance(dt);
    const auto x = sys.positions(0);
    double p = 0;
    for (int i = 0; i <= segments; ++i)
      p += sys.marker_arclength(0, i) * x[2 * i + 1] * cantilever_mode(mode, i * f.ds(), 1.0);
    t.push_back(sys.time());
    q.push_back(p);
  }
  return 2 * std::numbers::pi / period_from_crossings(zero_crossings(t, q));
}

double elliptic_k(double k) {
  double a = 1, b = std::sqrt(1 - k * k);
  for (int i = 0; i < 30; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return std::numbers::pi / (2 * a);
}

}  // namespace

TEST_CASE("cantilever in vacuum: first two frequencies within 1 % of Euler-Bernoulli", "[fiber][dynamics]") {
  const double w1 = cantilever_frequency(1, 24, 3.2);
  const double w2 = cantilever_frequency(2, 24, 8.2);
  const double e1 = w1 / std::pow(cantilever_beta(1), 2) - 1;
  const double e2 = w2 / std::pow(cantilever_beta(2), 2) - 1;
  INFO("24 segments: omega_1 error " << e1 << ", omega_2 error " << e2);
  CHECK(std::abs(e1) < 0.01);
  CHECK(std::abs(e2) < 0.01);
  // The discretisation is second order: 12 segments have about 4 times the error.
  const double e1_coarse = cantilever_frequency(1, 12, 3.2) / std::pow(cantilever_beta(1), 2) - 1;
  INFO("12 segments: omega_1 error " << e1_coarse);
  CHECK(e1_coarse / e1 == Approx(4.0).epsilon(0.15));
}

TEST_CASE("stiff hinged fiber released at 60 degrees swings with the rigid pendulum's period",
          "[fiber][dynamics]") {
  const double g = 9.81, length = 1.0, theta0 = std::numbers::pi / 3;
  FiberSpec f = make_fiber(length, 10, 1.0, 50 * g, {0, 0}, -std::numbers::pi / 2 + theta0);
  f.root.kind = EndKind::hinged;
  Config c = one_fiber(f);
  c.gravity = {0, -g};
  FiberSystem sys(c);
  const double period = 4 * std::sqrt(2 * length / (3 * g)) * elliptic_k(std::sin(theta0 / 2));
  const double dt = 0.9 * bending_dt_limit(f);
  std::vector<double> t, th;
  while (sys.time() < 1.3 * period) {
    sys.advance(dt);
    const auto x = sys.positions(0);
    t.push_back(sys.time());
    th.push_back(std::atan2(x[20] - x[0], -(x[21] - x[1])));
  }
  const double measured = period_from_crossings(zero_crossings(t, th));
  INFO("period " << measured << ", rigid rod " << period);
  CHECK(measured == Approx(period).epsilon(0.01));
}
