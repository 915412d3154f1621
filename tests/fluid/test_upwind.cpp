// fluid.upwind_blend: the weight b of first-order upwind in the convective fluxes outside the
// sponge. The carried value is c + b (upwind - c), so the explicit terms are linear in b: checked
// against the central (b = 0) and the fully upwind (b = 1) terms on a random field, and the fully
// upwind terms against first-order upwind fluxes written out here.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "momentum.hpp"
#include "solver.hpp"

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

// fluid.convection = "upwind3": on a doubly periodic grid every flux carries Leonard's
// third-order upwind-biased value, written out here in its own form: for a > 0 across the face
// between l and r (m before l, p after r) (-m + 5 l + 2 r)/6, for a < 0 (2 l + 5 r - p)/6.
TEST_CASE("upwind3: third-order upwind-biased fluxes on a periodic grid", "[fluid][upwind]") {
  const int nx = 10, ny = 7;
  AxisSpec ax{nx, 1.0, 0.0}, ay{ny, 0.7, 0.0};
  ax.periodic = ay.periodic = true;
  const Grid g(ax, ay);
  const double hx = 1.0 / nx, hy = 0.7 / ny;
  // Periodic values, ghosts included (what fill_ghosts leaves).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<double> uv(nx * ny), vv(nx * ny);
  for (double& x : uv) x = d(rng);
  for (double& x : vv) x = d(rng);
  auto mod = [](int k, int n) { return ((k % n) + n) % n; };
  auto U = [&](int i, int j) { return uv[mod(i, nx) + nx * mod(j, ny)]; };
  auto V = [&](int i, int j) { return vv[mod(i, nx) + nx * mod(j, ny)]; };
  Field u(nx + 1, ny), v(nx, ny + 1);
  for (int j = -1; j <= ny; ++j)
    for (int i = -1; i <= nx + 1; ++i) u(i, j) = U(i, j);
  for (int j = -1; j <= ny + 1; ++j)
    for (int i = -1; i <= nx; ++i) v(i, j) = V(i, j);
  Field hu(nx + 1, ny), hv(nx, ny + 1);
  const SpongeWeights sw = sponge_weights(g, 0.0);
  momentum_terms(g, sw, u, v, 0.0, 0, 0, hu, hv, nullptr, nullptr);
  std::vector<double> work;
  upwind3_terms(g, sw, u, v, OuterRows{}, OuterRows{}, 0, 0, hu, hv, work);
  auto q3 = [](double a, double m, double l, double r, double p) {
    return a > 0 ? (-m + 5 * l + 2 * r) / 6 : (2 * l + 5 * r - p) / 6;
  };
  double err = 0, errv = 0, scale = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      // u face (i, j): x fluxes at the cells i - 1 and i, y fluxes at the corners j and j + 1.
      const double ue = 0.5 * (U(i, j) + U(i + 1, j)), uw = 0.5 * (U(i - 1, j) + U(i, j));
      const double fx = ue * q3(ue, U(i - 1, j), U(i, j), U(i + 1, j), U(i + 2, j)) -
                        uw * q3(uw, U(i - 2, j), U(i - 1, j), U(i, j), U(i + 1, j));
      const double vn = 0.5 * (V(i - 1, j + 1) + V(i, j + 1)), vs = 0.5 * (V(i - 1, j) + V(i, j));
      const double fy = vn * q3(vn, U(i, j - 1), U(i, j), U(i, j + 1), U(i, j + 2)) -
                        vs * q3(vs, U(i, j - 2), U(i, j - 1), U(i, j), U(i, j + 1));
      err = std::max(err, std::abs(hu(i, j) + fx / hx + fy / hy));
      scale = std::max(scale, std::abs(hu(i, j)));
      // v face (i, j): x fluxes at the corners i and i + 1, y fluxes at the cells j - 1 and j.
      const double ve = 0.5 * (U(i + 1, j - 1) + U(i + 1, j)), vw = 0.5 * (U(i, j - 1) + U(i, j));
      const double gx = ve * q3(ve, V(i - 1, j), V(i, j), V(i + 1, j), V(i + 2, j)) -
                        vw * q3(vw, V(i - 2, j), V(i - 1, j), V(i, j), V(i + 1, j));
      const double vnn = 0.5 * (V(i, j) + V(i, j + 1)), vss = 0.5 * (V(i, j - 1) + V(i, j));
      const double gy = vnn * q3(vnn, V(i, j - 1), V(i, j), V(i, j + 1), V(i, j + 2)) -
                        vss * q3(vss, V(i, j - 2), V(i, j - 1), V(i, j), V(i, j + 1));
      errv = std::max(errv, std::abs(hv(i, j) + gx / hx + gy / hy));
    }
  INFO("largest term " << scale);
  CHECK(scale > 1);
  CHECK(err < 1e-12 * scale);
  CHECK(errv < 1e-12 * scale);
}

// On a bounded grid with a sponge: the carried value is (1 - beta) q3 + beta q_up, so the terms
// are (1 - b) T3 + b T1 outside the sponge (T3 the upwind3 terms at b = 0, T1 fully upwind), the
// first-order upwind terms inside it, and the faces next to a wall, an inflow or an outflow
// keep their two-point fluxes (the same rule holds there with T3 = the central terms).
TEST_CASE("upwind3: the blend and the sponge weights, bounded sides", "[fluid][upwind]") {
  const int nx = 14, ny = 9;
  AxisSpec ax{nx, 1.4, 0.0}, ay{ny, 0.9, 0.0};
  ax.sponge_cells = 4;
  ax.sponge_ratio = 1.2;
  const Grid g(ax, ay);
  const int n = g.nx();
  Field u(n + 1, ny), v(n, ny + 1);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-1, 1);
  for (double& x : u.a) x = d(rng);
  for (double& x : v.a) x = d(rng);
  auto terms = [&](double b, bool up3, bool full) {
    Field hu(n + 1, ny), hv(n, ny + 1);
    SpongeWeights sw = sponge_weights(g, b);
    if (full) {
      std::fill(sw.centre.begin(), sw.centre.end(), 1.0);
      std::fill(sw.face.begin(), sw.face.end(), 1.0);
    }
    momentum_terms(g, sw, u, v, 0.0, 1, 1, hu, hv, nullptr, nullptr);
    std::vector<double> work;
    if (up3) upwind3_terms(g, sw, u, v, OuterRows{}, OuterRows{}, 1, 1, hu, hv, work);
    return std::pair{hu, hv};
  };
  const double b = 0.3;
  const auto [t3, s3] = terms(0.0, true, false);
  const auto [t1, s1] = terms(0.0, false, true);
  const auto [tb, sb] = terms(b, true, false);
  const auto [tc, sc] = terms(0.0, false, false);
  const int start = g.x().sponge_start();
  double dev = 0, act = 0, wall = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 1; i < n; ++i) {
      // u face i reads the cells i - 1 and i and its own column's weight.
      const double want = i - 1 >= start ? t1(i, j)
                          : i < start    ? (1 - b) * t3(i, j) + b * t1(i, j)
                                         : tb(i, j);
      dev = std::max(dev, std::abs(tb(i, j) - want));
      act = std::max(act, std::abs(t3(i, j) - tc(i, j)));
    }
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < n; ++i) {
      const double want = i - 1 >= start  ? s1(i, j)
                          : i + 1 < start ? (1 - b) * s3(i, j) + b * s1(i, j)
                                          : sb(i, j);
      dev = std::max(dev, std::abs(sb(i, j) - want));
    }
  // The first u row above the bottom wall: its y fluxes keep two points (the corner below row 1
  // would need row -1), so only the x fluxes differ from the central terms.
  for (int i = 2; i + 2 < start; ++i) {
    const double cx = [&] {
      auto flux = [&](int c) {
        const double a = 0.5 * (u(c, 0) + u(c + 1, 0));
        const double m = u(c - 1, 0), l = u(c, 0), r = u(c + 1, 0), p = u(c + 2, 0);
        const double q = a > 0 ? (-m + 5 * l + 2 * r) / 6 : (2 * l + 5 * r - p) / 6;
        return a * (q - 0.5 * (l + r));
      };
      return -(flux(i) - flux(i - 1)) / 0.1;
    }();
    wall = std::max(wall, std::abs(t3(i, 0) - (tc(i, 0) + cx)));
  }
  INFO("upwind3 against central " << act);
  CHECK(act > 0.1);
  CHECK(dev < 1e-12);
  CHECK(wall < 1e-12);
}

// On a bounded grid with weights that differ at every position, the correction alone (terms
// from zero) against the correction written out here with global indices: each flux's
// (1 - w) a (q3 - (l + r)/2), w the centre weight of its cell (fluxes through cells) or the face
// weight of its column (fluxes through corners), and zero where the four values would include a
// ghost. Every ghost holds NaN, so reading one shows.
TEST_CASE("upwind3: weights per position, no ghost read on bounded sides", "[fluid][upwind]") {
  const int nx = 11, ny = 9;
  const double hx = 0.1, hy = 0.12;
  const Grid g(AxisSpec{nx, nx * hx, 0.0}, AxisSpec{ny, ny * hy, 0.0});
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> d(-1, 1), w01(0, 1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Field u(nx + 1, ny), v(nx, ny + 1);
  for (double& x : u.a) x = nan;
  for (double& x : v.a) x = nan;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i <= nx; ++i) u(i, j) = d(rng);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i < nx; ++i) v(i, j) = d(rng);
  SpongeWeights sw = sponge_weights(g, 0.0);
  for (double& x : sw.centre) x = w01(rng);
  for (double& x : sw.face) x = w01(rng);
  auto wc = [&](int c) { return sw.centre[c + 1]; };
  auto wf = [&](int i) { return sw.face[i + 1]; };
  auto corr = [](double w, double a, double m, double l, double r, double p) {
    const double q = a > 0 ? (-m + 5 * l + 2 * r) / 6 : (2 * l + 5 * r - p) / 6;
    return (1 - w) * a * (q - 0.5 * (l + r));
  };
  Field hu(nx + 1, ny), hv(nx, ny + 1);
  std::vector<double> work;
  upwind3_terms(g, sw, u, v, OuterRows{}, OuterRows{}, 1, 1, hu, hv, work);
  double err = 0, edge = 0;
  bool finite = true;
  for (int j = 0; j < ny; ++j)
    for (int i = 1; i < nx; ++i) {
      auto fx = [&](int c) {  // through cell c, u faces c - 1 .. c + 2
        if (c < 1 || c > nx - 2) return 0.0;
        const double a = 0.5 * (u(c, j) + u(c + 1, j));
        return corr(wc(c), a, u(c - 1, j), u(c, j), u(c + 1, j), u(c + 2, j));
      };
      auto fy = [&](int k) {  // through the corner below row k, rows k - 2 .. k + 1
        if (k < 2 || k > ny - 2) return 0.0;
        const double a = 0.5 * (v(i - 1, k) + v(i, k));
        return corr(wf(i), a, u(i, k - 2), u(i, k - 1), u(i, k), u(i, k + 1));
      };
      const double want = -(fx(i) - fx(i - 1)) / hx - (fy(j + 1) - fy(j)) / hy;
      finite = finite && std::isfinite(hu(i, j));
      err = std::max(err, std::abs(hu(i, j) - want));
      if (j == 0 || j == ny - 1 || i == 1 || i == nx - 1) edge = std::max(edge, std::abs(want));
    }
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      auto fx = [&](int k) {  // through the corner left of cell k, cells k - 2 .. k + 1
        if (k < 2 || k > nx - 2) return 0.0;
        const double a = 0.5 * (u(k, j - 1) + u(k, j));
        return corr(wf(k), a, v(k - 2, j), v(k - 1, j), v(k, j), v(k + 1, j));
      };
      auto fy = [&](int c) {  // through cell c, v faces c - 1 .. c + 2
        if (c < 1 || c > ny - 2) return 0.0;
        const double a = 0.5 * (v(i, c) + v(i, c + 1));
        return corr(wc(i), a, v(i, c - 1), v(i, c), v(i, c + 1), v(i, c + 2));
      };
      const double want = -(fx(i + 1) - fx(i)) / hx - (fy(j) - fy(j - 1)) / hy;
      finite = finite && std::isfinite(hv(i, j));
      err = std::max(err, std::abs(hv(i, j) - want));
      if (j == 1 || j == ny - 1 || i == 0 || i == nx - 1) edge = std::max(edge, std::abs(want));
    }
  CHECK(finite);
  CHECK(err < 1e-12);
  CHECK(edge > 0.01);  // the faces beside the sides take the corrections they can
}

namespace {
// Steps small enough that the time integrator's own amplitude error (below) stays under 1e-4.
constexpr double kWaveDt = 5e-4;
constexpr int kWaveSteps = 2000;
// A wave v = A sin(k x) carried by u = c through a periodic 32 x 4 grid of unit length for one
// time unit: the amplitude left after it, measured by projection on sin and cos.
double wave_left(bool up3, double blend, double c, int cells_per_wave) {
  Config cfg;
  cfg.density = 1;
  cfg.viscosity = 1e-12;
  const int n = 32;
  cfg.x = {n, 1.0, 0.0};
  cfg.y = {4, 0.125, 0.0};
  for (auto& b : cfg.bc) b.type = BcType::periodic;
  cfg.upwind3 = up3;
  cfg.upwind_blend = blend;
  Solver s(cfg, kWaveDt);
  const double k = 2 * std::numbers::pi * n / cells_per_wave;
  for (double& x : s.u().a) x = c;
  Field& v = s.v();
  for (int j = v.jlo - 1; j <= v.jhi; ++j)
    for (int i = -1; i <= n; ++i) v(i, j) = std::sin(k * (i + 0.5) / n);
  for (int step = 0; step < kWaveSteps; ++step) s.step(kWaveDt);
  double a = 0, b = 0;
  for (int i = 0; i < n; ++i) {
    a += s.v()(i, 2) * std::sin(k * (i + 0.5) / n);
    b += s.v()(i, 2) * std::cos(k * (i + 0.5) / n);
  }
  return 2.0 / n * std::hypot(a, b);
}
}  // namespace

// Through the whole solver: the third-order scheme damps a wave of kh = theta at the rate of
// its fourth difference, (4/3) sin^4(theta/2) |c| / h, in either direction of the flow; with
// the central fluxes it keeps its amplitude (but for the time integrator's growth); the upwind
// blend b damps at b 2 sin^2(theta/2) |c| / h, far more on the longer wave.
TEST_CASE("upwind3: a carried wave decays at the scheme's rate", "[fluid][upwind]") {
  const double h = 1.0 / 32;
  for (int cells : {8, 16}) {
    const double th = 2 * std::numbers::pi / cells, s2 = std::pow(std::sin(th / 2), 2);
    const double rate3 = 4.0 / 3.0 * s2 * s2 / h, rate_b = 0.2 * 2 * s2 / h;
    for (double c : {1.0, -1.0}) {
      const double left = wave_left(true, 0.0, c, cells);
      INFO(cells << " cells a wave, c = " << c << ": left " << left << " against "
                 << std::exp(-rate3));
      CHECK(std::abs(std::log(left) + rate3) < 0.01 * rate3);
    }
    const double central = wave_left(false, 0.0, 1.0, cells);
    const double blend = wave_left(false, 0.2, 1.0, cells);
    INFO(cells << " cells a wave: central " << central << ", blend 0.2 " << blend << " against "
               << std::exp(-rate_b));
    // Central fluxes: no damping; the growth is the time integrator's on an imaginary rate
    // i y / dt, y = sin(theta) |c| dt / h: Euler's first step |1 + i y| ~ 1 + y^2/2, then AB2's
    // 1 + y^4/4 per step.
    const double y = std::sin(th) * kWaveDt / h;
    const double growth = (1 + y * y / 2) * std::pow(1 + std::pow(y, 4) / 4, kWaveSteps - 1);
    CHECK(std::abs(central - growth) < 1e-5);
    CHECK(std::abs(std::log(blend) + rate_b) < 0.01 * rate_b);
  }
}
