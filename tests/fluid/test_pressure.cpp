// The pressure boundary (fluid.boundary.<side>.type = "pressure"): a channel driven by the
// pressure difference between its ends against the exact plane solutions: the steady parabola
// (to round-off, on uniform and stretched grids), the start-up from rest (second order in space
// at a fixed diffusion number) and the oscillating pressure (Womersley's solution).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "diagnostics.hpp"
#include "solver.hpp"

using namespace fluid;

namespace {

constexpr double kPi = std::numbers::pi;

// A channel [0, L] x [0, 1] between walls, pressure p_in(t) at x = 0 and 0 at x = L.
Config pressure_channel(int nx, int ny, double L, double p_in) {
  Config c;
  c.density = 1;
  c.viscosity = 1;
  c.x = {nx, L, 0.0};
  c.y = {ny, 1.0, 0.0};
  c.bc[left].type = c.bc[right].type = BcType::pressure;
  c.bc[left].value = p_in;
  c.bc[bottom].type = c.bc[top].type = BcType::wall;
  c.cfl_max = 1e9;
  return c;
}

// Largest |u - exact(y)| over every u face, the boundary faces included.
template <class F>
double max_u_error(const Solver& s, F exact) {
  double e = 0;
  for (int j = 0; j < s.grid().ny(); ++j) {
    const double y = s.grid().y().centre(j);
    for (int i = 0; i <= s.grid().nx(); ++i) e = std::max(e, std::abs(s.u()(i, j) - exact(y)));
  }
  return e;
}

// Start-up of plane Poiseuille flow from rest under the gradient G (H = 1, rho = 1):
//   u = G/(2 mu) y (1 - y) - sum_{n odd} 4 G / (mu pi^3 n^3) sin(n pi y) exp(-n^2 pi^2 nu t).
double startup(double y, double t, double G, double mu) {
  double u = 0.5 * G / mu * y * (1 - y);
  for (int n = 1; n < 400; n += 2)
    u -= 4 * G / (mu * kPi * kPi * kPi * n * n * n) * std::sin(n * kPi * y) *
         std::exp(-n * n * kPi * kPi * mu * t);
  return u;
}

}  // namespace

TEST_CASE("pressure boundaries drive the exact Poiseuille parabola", "[fluid][pressure]") {
  // -dp/dx = G = p_in / L = 2: u = y (1 - y), p = p_in (1 - x / L).
  for (int variant = 0; variant < 6; ++variant) {
    const double L = 2.0;
    Config c = pressure_channel(variant >= 4 ? 16 : 8, 16, L, 4.0);
    if (variant == 1) c.y.tanh_beta = 1.2;  // transform in x (Dirichlet on both ends), y stretched
    if (variant == 2) {                     // a sponge: x stretched, solved by the tridiagonal sweeps
      c.x.sponge_cells = 4;
      c.x.sponge_ratio = 1.3;
    }
    if (variant == 3) {  // a band in y: 4 of the 16 rows over [0.3, 0.5], the others growing
      c.y.band_from = 0.3, c.y.band_to = 0.5, c.y.band_cells = 4;
    }
    if (variant >= 4) {  // a band in x: transform in y, x by the tridiagonal sweeps
      c.x.band_from = 0.6, c.x.band_to = 1.0, c.x.band_cells = 4;
    }
    if (variant == 5) {  // and one in y: y transformed by its eigenvectors
      c.y.band_from = 0.3, c.y.band_to = 0.5, c.y.band_cells = 4;
    }
    Solver s(c, 0.25 * explicit_diffusion_limit(c));
    set_initial(s);
    const double dt = 0.25 * explicit_diffusion_limit(c);
    for (long k = 0; k < std::lround(3.0 / dt); ++k) s.step(dt);
    // The pressure: linear, p_in on the inlet face and 0 on the outlet face (x_end: the sponge
    // lengthens the channel, G = p_in / x_end); u = G / (2 mu) y (1 - y).
    const double x_end = s.grid().x().face(s.grid().nx());
    const double G = 4.0 / x_end;
    const double err = max_u_error(s, [&](double y) { return 0.5 * G * y * (1 - y); });
    double perr = 0;
    for (int j = 0; j < s.grid().ny(); ++j)
      for (int i = 0; i < s.grid().nx(); ++i)
        perr = std::max(perr, std::abs(s.p()(i, j) - 4.0 * (1 - s.grid().x().centre(i) / x_end)));
    double verr = 0;
    for (int j = 0; j <= s.grid().ny(); ++j)
      for (int i = 0; i < s.grid().nx(); ++i) verr = std::max(verr, std::abs(s.v()(i, j)));
    INFO("variant " << variant << ": max u error " << err << ", p error " << perr << ", |v| " << verr);
    CHECK(err < 1e-10);
    CHECK(perr < 1e-9);
    CHECK(verr < 1e-12);
  }
}

TEST_CASE("start-up from rest under a pressure difference: second order", "[fluid][pressure]") {
  // G = 8, t = 0.05 (the slowest mode at 61 % of its start): the error at fixed nu dt / h^2.
  const double G = 8, t_end = 0.05;
  double prev = 0;
  for (int ny : {16, 32, 64}) {
    Config c = pressure_channel(4, ny, 0.5, G * 0.5);
    const double h = 1.0 / ny;
    const double dt = t_end / std::ceil(t_end / (0.1 * h * h));
    Solver s(c, dt);
    set_initial(s);
    for (long k = 0; k < std::lround(t_end / dt); ++k) s.step(dt);
    const double err = max_u_error(s, [&](double y) { return startup(y, t_end, G, 1.0); });
    const double peak = startup(0.5, t_end, G, 1.0);
    INFO("ny " << ny << ": max error " << err << " of the centreline speed " << peak);
    // Measured 2.1e-3 of the centreline speed at 16 cells (order 1.85, 1.93): the bound guards the
    // size (a wrong face pressure is off at O(1)), the order below the scheme.
    CHECK(err < 1e-2 * peak * (16.0 / ny) * (16.0 / ny));
    if (prev > 0) {
      const double order = std::log2(prev / err);
      INFO("order " << order);
      CHECK(order > 1.8);
    }
    prev = err;
  }
}

TEST_CASE("an oscillating inlet pressure gives Womersley's flow", "[fluid][pressure]") {
  // p_in = A sin(omega t), p_out = 0 over L: -dp/dx = (A / L) sin(omega t). Periodic state
  //   u = Im{ (A / (L i omega rho)) [1 - cosh(k (y - 1/2)) / cosh(k / 2)] e^{i omega t} },
  //   k = sqrt(i omega / nu); here the Womersley number sqrt(omega / nu) / 2 = 2.5.
  const double A = 5, L = 1, omega = 25, period = 2 * kPi / omega;
  Config c = pressure_channel(4, 32, L, 0.0);
  c.bc[left].amplitude = A;
  c.bc[left].omega = omega;
  const double h = 1.0 / 32, dt = period / std::ceil(period / (0.1 * h * h));
  Solver s(c, dt);
  set_initial(s);
  const std::complex<double> I(0, 1), k = std::sqrt(I * omega);
  auto exact = [&](double y, double t) {
    const std::complex<double> shape = 1.0 - std::cosh(k * (y - 0.5)) / std::cosh(0.5 * k);
    return std::imag(A / (L * I * omega) * shape * std::exp(I * omega * t));
  };
  const long per = std::lround(period / dt);
  double err = 0, amp = 0;
  for (long n = 1; n <= 6 * per; ++n) {
    s.step(dt);
    if (n > 5 * per && n % (per / 8) == 0) {  // eight times in the sixth period
      const double t = n * dt;
      err = std::max(err, max_u_error(s, [&](double y) { return exact(y, t); }));
      amp = std::max(amp, std::abs(exact(0.5, t)));
    }
  }
  INFO("max error over the sixth period " << err << " of the centreline amplitude " << amp);
  CHECK(err < 5e-3 * amp);
}

TEST_CASE("a total-pressure face: Bernoulli's speed between free-slip walls", "[fluid][pressure]") {
  // Free-slip walls, no shear: the flow from a face whose entering fluid has total pressure P to
  // a face at static pressure 0 settles to the plug u = sqrt(2 P / rho), the static pressure 0
  // everywhere (P - rho u^2 / 2 on the entering face). Both directions: entering on the left, and
  // on the right (a backflow into an outlet).
  for (int side : {int(left), int(right)}) {
    const double P = 2.0, rho = 1.5;
    Config c = pressure_channel(16, 8, 1.0, 0.0);
    c.density = rho;
    c.viscosity = 0.05;
    c.bc[bottom].type = c.bc[top].type = BcType::slip;
    c.bc[side].value = P;
    c.bc[side].total = true;
    const double dt = 0.2 * explicit_diffusion_limit(c);
    Solver s(c, dt);
    set_initial(s);
    for (long k = 0; k < std::lround(20.0 / dt); ++k) s.step(dt);
    const double expect = (side == left ? 1.0 : -1.0) * std::sqrt(2 * P / rho);
    const double err = max_u_error(s, [&](double) { return expect; });
    double pmax = 0;
    for (int j = 0; j < s.grid().ny(); ++j)
      for (int i = 0; i < s.grid().nx(); ++i) pmax = std::max(pmax, std::abs(s.p()(i, j)));
    INFO("entering on side " << side << ": max |u - " << expect << "| = " << err << ", max |p| = " << pmax);
    CHECK(err < 1e-8);
    CHECK(pmax < 1e-8);
  }
}

TEST_CASE("a varying face pressure keeps the divergence at round-off", "[fluid][pressure]") {
  // phi_b != 0 in every step (a ramp, then an oscillation): the Dirichlet rows and their
  // right-hand side 2 phi_b / w^2 must be D G exactly, on the tridiagonal rows of a stretched x
  // (a sponge before a pressure outlet) and in the transform direction with one pressure side
  // (an inflow on the left: the mixed real transforms), and with a total-pressure face.
  for (int variant = 0; variant < 3; ++variant) {
    Config c = pressure_channel(24, 12, 2.0, 3.0);
    c.viscosity = 0.02;
    c.bc[left].ramp = Ramp::cosine;
    c.bc[left].ramp_time = 0.2;
    c.bc[right].amplitude = 0.5;
    c.bc[right].omega = 20;
    if (variant == 0) {
      c.x.sponge_cells = 6;
      c.x.sponge_ratio = 1.2;
    }
    if (variant == 1) {
      c.bc[left] = SideBc{};
      c.bc[left].type = BcType::inflow;
      c.bc[left].mean = 1.0;
    }
    if (variant == 2) c.bc[right].total = true, c.bc[left].total = true;
    const double dt = 0.2 * explicit_diffusion_limit(c);
    Solver s(c, dt);
    set_initial(s);
    double worst = 0;
    for (int k = 0; k < 200; ++k) {
      s.step(dt);
      worst = std::max(worst, max_divergence(s).value);
    }
    double umax = 0;
    for (double u : s.u().a) umax = std::max(umax, std::abs(u));
    INFO("variant " << variant << ": max |div u| " << worst << ", max |u| " << umax);
    CHECK(worst < 1e-10);
    CHECK(umax > 0.1);  // the flow moved
  }
}
