// An oscillating wall: the channel between a fixed bottom wall and a top wall moving with
// V0 sin(ω t) has the exact periodic solution u = Im[V0 e^{iωt} sinh(k y) / sinh(k H)],
// k = sqrt(iω/ν) (the fluid-only limit of the two-layer channel of Sugiyama et al. 2011).
#include <catch2/catch.hpp>

#include <cmath>
#include <complex>
#include <numbers>

#include "diagnostics.hpp"
#include "solver.hpp"

using namespace fluid;

namespace {

// Max error against the periodic solution after 6 periods (start-up decays as e^(−π² ν t / H²)).
double oscillating_wall_error(int ny, bool implicit) {
  Config c;
  c.density = 1;
  c.viscosity = 1;
  c.x = {4, 0.25, 0.0};
  c.y = {ny, 1.0, 0.0};
  c.bc[left].type = c.bc[right].type = BcType::periodic;
  c.bc[bottom].type = c.bc[top].type = BcType::wall;
  c.bc[top].amplitude = 1.0;
  c.bc[top].omega = std::numbers::pi;
  c.implicit = implicit;
  c.cfl_max = 1e9;
  const double h = 1.0 / ny;
  const double dt = implicit ? 0.5 * h : 0.1 * h * h;  // time error below the space error
  Solver s(c, dt);
  set_initial(s);
  const long steps = std::lround(12.0 / dt);
  for (long k = 0; k < steps; ++k) s.step(dt);
  const double t = s.time();
  const std::complex<double> I(0, 1), k = std::sqrt(I * c.bc[top].omega / c.viscosity);
  double err = 0;
  for (int j = 0; j < ny; ++j) {
    const double y = s.grid().y().centre(j);
    const double exact = std::imag(std::exp(I * c.bc[top].omega * t) * std::sinh(k * y) / std::sinh(k));
    for (int i = 0; i < s.grid().nx(); ++i) err = std::max(err, std::abs(s.u()(i, j) - exact));
  }
  return err;
}

}  // namespace

TEST_CASE("an oscillating wall drives the exact periodic channel flow", "[fluid][wall]") {
  for (bool implicit : {false, true}) {
    const double e16 = oscillating_wall_error(16, implicit), e32 = oscillating_wall_error(32, implicit);
    const double order = std::log2(e16 / e32);
    INFO((implicit ? "Crank-Nicolson" : "explicit") << ": max error " << e16 << " (16 cells), " << e32
                                                    << " (32 cells), order " << order);
    CHECK(e32 < 2e-3);
    CHECK(order > 1.8);
  }
}
