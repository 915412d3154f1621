// fluid.upwind_blend: the weight b of first-order upwind in the convective fluxes outside the
// sponge. The carried value is c + b (upwind - c), so the explicit terms are linear in b: checked
// against the central (b = 0) and the fully upwind (b = 1) terms on a random field, and the fully
// upwind terms against first-order upwind fluxes written out here.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "momentum.hpp"

using namespace fluid;

TEST_CASE("upwind blend: linear in the weight, fully upwind at 1", "[fluid][upwind]") {
  const int nx = 12, ny = 9;
  AxisSpec ax{nx, 1.2, 0.0}, ay{ny, 0.9, 0.0};
  ax.periodic = ay.periodic = true;
  const Grid g(ax, ay);
  Field u(nx + 1, ny), v(nx, ny + 1);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-1, 1);
  for (double& x : u.a) x = d(rng);
  for (double& x : v.a) x = d(rng);
  auto terms = [&](double b) {
    Field hu(nx + 1, ny), hv(nx, ny + 1);
    momentum_terms(g, sponge_weights(g, b), u, v, 0.0, 1, 1, hu, hv, nullptr, nullptr);
    return std::pair{hu, hv};
  };
  const auto [h0, v0] = terms(0.0);
  const auto [h1, v1] = terms(1.0);
  const auto [hb, vb] = terms(0.3);
  double dev = 0, diff = 0, devv = 0, diffv = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 1; i < nx; ++i) {
      dev = std::max(dev, std::abs(hb(i, j) - (0.7 * h0(i, j) + 0.3 * h1(i, j))));
      diff = std::max(diff, std::abs(h1(i, j) - h0(i, j)));
    }
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      devv = std::max(devv, std::abs(vb(i, j) - (0.7 * v0(i, j) + 0.3 * v1(i, j))));
      diffv = std::max(diffv, std::abs(v1(i, j) - v0(i, j)));
    }
  CHECK(dev < 1e-13);
  CHECK(devv < 1e-13);
  CHECK(diff > 0.1);  // the weight acts
  CHECK(diffv > 0.1);
  // b = 1: the x flux of u written out, -(U_e q_e - U_w q_w) / dx with q the upwind neighbour,
  // plus the y flux with the corner velocity V and the upwind row.
  const double hx = 1.2 / nx, hy = 0.9 / ny;
  double err = 0;
  for (int j = 1; j < ny - 1; ++j)
    for (int i = 1; i < nx; ++i) {
      const double ue = 0.5 * (u(i, j) + u(i + 1, j)), uw = 0.5 * (u(i - 1, j) + u(i, j));
      const double fx = ue * (ue > 0 ? u(i, j) : u(i + 1, j)) - uw * (uw > 0 ? u(i - 1, j) : u(i, j));
      const double vn = 0.5 * (v(i - 1, j + 1) + v(i, j + 1)), vs = 0.5 * (v(i - 1, j) + v(i, j));
      const double fy = vn * (vn > 0 ? u(i, j) : u(i, j + 1)) - vs * (vs > 0 ? u(i, j - 1) : u(i, j));
      err = std::max(err, std::abs(h1(i, j) - (-(fx / hx + fy / hy))));
    }
  CHECK(err < 1e-12);
  // The same for v: -(U q_e - U q_w) / dx with U the corner velocity, plus the y flux of v.
  double errv = 0;
  for (int j = 1; j < ny; ++j)
    for (int i = 1; i < nx - 1; ++i) {
      const double ue = 0.5 * (u(i + 1, j - 1) + u(i + 1, j)), uw = 0.5 * (u(i, j - 1) + u(i, j));
      const double fx = ue * (ue > 0 ? v(i, j) : v(i + 1, j)) - uw * (uw > 0 ? v(i - 1, j) : v(i, j));
      const double vn = 0.5 * (v(i, j) + v(i, j + 1)), vs = 0.5 * (v(i, j - 1) + v(i, j));
      const double fy = vn * (vn > 0 ? v(i, j) : v(i, j + 1)) - vs * (vs > 0 ? v(i, j - 1) : v(i, j));
      errv = std::max(errv, std::abs(v1(i, j) - (-(fx / hx + fy / hy))));
    }
  CHECK(errv < 1e-12);
}
