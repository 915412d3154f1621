// Time accuracy and stability of both diffusion options on the Taylor-Green vortex.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "solver.hpp"

using namespace fluid;

namespace {
// Error of u against a reference run with dt_ref on the same grid (isolates the time error).
double run(int n, bool implicit, double nu, double dt, double t_end, std::vector<double>* keep,
           bool factored = false) {
  Config c;
  c.density = 1;
  c.viscosity = nu;
  const double L = 2 * std::numbers::pi;
  c.x = {n, L, 0.0};
  c.y = {n, L, 0.0};
  for (auto& b : c.bc) b.type = BcType::periodic;
  c.implicit = implicit;
  c.factored_helmholtz = factored;
  c.initial.type = InitialType::taylor_green;
  c.initial.amplitude = 1;
  c.cfl_max = 10;
  Solver s(c, dt);
  set_initial(s);
  const long steps = std::lround(t_end / dt);
  for (long k = 0; k < steps; ++k) s.step(dt);
  std::vector<double> u(s.u().a);
  if (keep) *keep = u;
  return std::isfinite(u[u.size() / 2]) ? 0.0 : 1.0;
}
double diff(const std::vector<double>& a, const std::vector<double>& b) {
  double e = 0;
  for (std::size_t q = 0; q < a.size(); ++q) e = std::max(e, std::abs(a[q] - b[q]));
  return e;
}
}  // namespace

TEST_CASE("Taylor-Green: second order in time for both diffusion options", "[fluid][tg]") {
  // explicit, Crank-Nicolson with the direct and with the factored Helmholtz solve
  for (int variant = 0; variant < 3; ++variant) {
    const bool implicit = variant > 0, factored = variant == 2;
    std::vector<double> ref, a, b;
    const int n = 32;
    const double nu = 0.05;
    run(n, implicit, nu, 0.0025, 1.0, &ref, factored);
    run(n, implicit, nu, 0.04, 1.0, &a, factored);
    run(n, implicit, nu, 0.02, 1.0, &b, factored);
    const double ea = diff(a, ref), eb = diff(b, ref);
    const double order = std::log2(ea / eb);
    INFO("variant " << variant << " e(0.04) " << ea << " e(0.02) " << eb << " order " << order);
    CHECK(order >= 1.9);
  }
}

TEST_CASE("implicit diffusion is stable at 4x the explicit limit", "[fluid][tg]") {
  // nu large so that diffusion, not convection, limits dt.
  const int n = 32;
  const double nu = 2.0, h = 2 * std::numbers::pi / n;
  const double limit = 1.0 / (4 * nu * 2 / (h * h));
  std::vector<double> u;
  run(n, true, nu, 4 * limit, 200 * limit, &u);
  double m = 0;
  for (double q : u) m = std::max(m, std::abs(q));
  CHECK(std::isfinite(m));
  CHECK(m < 1.0);  // decays: amplitude exp(-2 nu t) of an initial 1
}
