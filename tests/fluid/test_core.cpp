// Exactness of the fast Poisson solve and the projection, Taylor-Green convergence order and
// exact plane Poiseuille flow on the MAC grid.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "diagnostics.hpp"
#include "solver.hpp"

using namespace fluid;

namespace {

Config channel(int nx, int ny, BcType x_bc, BcType y_bc) {
  Config c;
  c.density = 1;
  c.viscosity = 0.1;
  c.x = {nx, 2.0, 0.0};
  c.y = {ny, 1.0, 0.0};
  c.bc[left].type = c.bc[right].type = x_bc;
  c.bc[bottom].type = c.bc[top].type = y_bc;
  c.cfl_max = 1e9;
  return c;
}

// A random field made discretely compatible, projected: the divergence must vanish to round-off.
double projected_divergence(Config c) {
  Solver s(c, 1e-4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> d(-1, 1);
  for (int j = 0; j < s.grid().ny(); ++j)
    for (int i = s.i0(); i < s.grid().nx(); ++i) s.u()(i, j) = d(rng);
  for (int j = s.j0(); j < s.grid().ny(); ++j)
    for (int i = 0; i < s.grid().nx(); ++i) s.v()(i, j) = d(rng);
  s.project_initial();
  return max_divergence(s).value;
}

}  // namespace

TEST_CASE("projection leaves a divergence at round-off", "[fluid][projection]") {
  CHECK(projected_divergence(channel(32, 24, BcType::periodic, BcType::periodic)) < 1e-11);
  CHECK(projected_divergence(channel(32, 24, BcType::periodic, BcType::wall)) < 1e-11);
  CHECK(projected_divergence(channel(30, 20, BcType::wall, BcType::wall)) < 1e-11);
  CHECK(projected_divergence(channel(30, 20, BcType::wall, BcType::periodic)) < 1e-11);
  Config st = channel(32, 24, BcType::periodic, BcType::wall);
  st.y.tanh_beta = 1.5;
  CHECK(projected_divergence(st) < 1e-10);
  Config sp = channel(32, 24, BcType::wall, BcType::wall);
  sp.bc[right].type = BcType::outflow;
  sp.x.sponge_cells = 8;
  sp.x.sponge_ratio = 1.2;
  CHECK(projected_divergence(sp) < 1e-10);
  Config bb = channel(30, 20, BcType::wall, BcType::wall);  // banded in x and in y
  bb.x.band_from = 0.5, bb.x.band_to = 1.0, bb.x.band_cells = 12;
  bb.y.band_from = 0.3, bb.y.band_to = 0.5, bb.y.band_cells = 6;
  CHECK(projected_divergence(bb) < 1e-10);
}

TEST_CASE("fast solver inverts the discrete operator exactly", "[fluid][poisson]") {
  // Manufactured discrete solution: x random, r = (L - sigma) x by the 1D stencils, solve. At
  // nt = 101, an odd prime below 173, FFTW 3.3 (FFTW_ESTIMATE) has only its generic O(n^2) code;
  // the solver's transforms are then matrix products (DenseTransform) where the machine
  // vectorises them.
  for (const int nt : {12, 101}) {
    for (auto [lo, hi] : {std::pair{Closure::periodic, Closure::periodic},
                          {Closure::neumann_half, Closure::neumann_half},
                          {Closure::dirichlet_half, Closure::dirichlet_half},
                          {Closure::dirichlet_half, Closure::neumann_half},
                          {Closure::neumann_half, Closure::dirichlet_half},
                          {Closure::dirichlet_node, Closure::dirichlet_node}}) {
      INFO("nt = " << nt << ", closures " << int(lo) << ", " << int(hi));
      const int ns = 9;
      const double h = 0.3, sigma = 2.5;
      Operator1D t{nt, lo, hi, h, {}, {}, {}, false};
      // A stretched tridiagonal direction with Dirichlet-like ends.
      Operator1D s;
      s.n = ns;
      s.a.resize(ns);
      s.b.resize(ns);
      s.c.resize(ns);
      for (int j = 0; j < ns; ++j) {
        s.a[j] = j > 0 ? 1.0 + 0.1 * j : 0.0;
        s.c[j] = j < ns - 1 ? 1.2 - 0.05 * j : 0.0;
        s.b[j] = -(2.3 + 0.1 * j);
      }
      FastSolver fs(t, s, sigma);
      const TransformPair kt = transform_pair(nt, lo, hi);
      CHECK(fs.dense() ==
            (DenseTransform::preferred(kt.fwd, nt) || DenseTransform::preferred(kt.bwd, nt)));
      if (nt == 101) CHECK(fs.dense() == DenseTransform::vectorised());
      std::mt19937 rng(3);
      std::uniform_real_distribution<double> d(-1, 1);
      std::vector<double> x(nt * ns), r(nt * ns);
      for (auto& q : x) q = d(rng);
      auto X = [&](int k, int j) -> double {
        if (j < 0 || j >= ns) return 0.0;
        if (k < 0 || k >= nt) {
          const bool low = k < 0;
          const Closure cl = low ? lo : hi;
          const int kk = low ? 0 : nt - 1;
          switch (cl) {
            case Closure::periodic:
              return x[((k + nt) % nt) + nt * j];
            case Closure::neumann_half:
              return x[kk + nt * j];
            case Closure::dirichlet_half:
              return -x[kk + nt * j];
            case Closure::dirichlet_node:
              return 0.0;
          }
        }
        return x[k + nt * j];
      };
      for (int j = 0; j < ns; ++j)
        for (int k = 0; k < nt; ++k)
          r[k + nt * j] = (X(k + 1, j) - 2 * X(k, j) + X(k - 1, j)) / (h * h) +
                          s.a[j] * X(k, j - 1) + s.b[j] * X(k, j) + s.c[j] * X(k, j + 1) -
                          sigma * X(k, j);
      std::copy(r.begin(), r.end(), fs.data());
      fs.solve();
      double err = 0;
      for (int q = 0; q < nt * ns; ++q) err = std::max(err, std::abs(fs.data()[q] - x[q]));
      CHECK(err < 1e-12);
    }
  }
}

TEST_CASE("a stretched transform direction is diagonalised by its eigenvectors", "[fluid][poisson]") {
  // The rows of a stretched direction (widths w growing by up to 1.3) as the transform direction:
  // pressure rows (zero-gradient ends) and normal-velocity rows (values beyond the ends), against
  // a stretched s. F B = I, L = B diag(lambda) F, and the solve inverts (L_t + L_s - sigma).
  const int nt = 23, ns = 9;
  std::vector<double> w(nt + 1);
  for (int k = 0; k <= nt; ++k) w[k] = 0.1 * (1.0 + 0.3 * std::sin(0.7 * k) * std::sin(0.7 * k));
  for (const bool pressure : {true, false}) {
    Operator1D t;
    t.n = pressure ? nt : nt - 1;
    t.a.assign(t.n, 0.0), t.b.assign(t.n, 0.0), t.c.assign(t.n, 0.0);
    for (int k = 0; k < t.n; ++k) {
      if (pressure) {  // cell k of width w[k], centres d apart
        const double dl = k > 0 ? 0.5 * (w[k - 1] + w[k]) : 0.0;
        const double dr = k < nt - 1 ? 0.5 * (w[k] + w[k + 1]) : 0.0;
        t.a[k] = k > 0 ? 1.0 / (dl * w[k]) : 0.0;
        t.c[k] = k < nt - 1 ? 1.0 / (dr * w[k]) : 0.0;
        t.b[k] = -(t.a[k] + t.c[k]);
      } else {  // face k + 1 between cells k and k + 1
        const double d = 0.5 * (w[k] + w[k + 1]);
        t.a[k] = 1.0 / (w[k] * d);
        t.c[k] = 1.0 / (w[k + 1] * d);
        t.b[k] = -(t.a[k] + t.c[k]);
        if (k == 0) t.a[k] = 0;
        if (k == t.n - 1) t.c[k] = 0;
      }
    }
    t.singular = pressure;
    const EigenTransform e = eigen_transform(t);
    const int n = t.n;
    double id_err = 0, l_err = 0, lmax = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        double fb = 0, l = 0;
        for (int m = 0; m < n; ++m) {
          fb += e.fwd[i * n + m] * e.bwd[m * n + j];
          l += e.bwd[i * n + m] * e.lambda[m] * e.fwd[m * n + j];
        }
        const double lij = j == i - 1 ? t.a[i] : j == i ? t.b[i] : j == i + 1 ? t.c[i] : 0.0;
        id_err = std::max(id_err, std::abs(fb - (i == j ? 1.0 : 0.0)));
        l_err = std::max(l_err, std::abs(l - lij));
        lmax = std::max(lmax, std::abs(lij));
      }
    INFO((pressure ? "pressure" : "normal velocity") << " rows: |FB - I| " << id_err
                                                      << ", |B diag F - L| / |L| " << l_err / lmax);
    CHECK(id_err < 1e-12);
    CHECK(l_err < 1e-12 * lmax);
    CHECK(std::count(e.lambda.begin(), e.lambda.end(), 0.0) == (pressure ? 1 : 0));

    Operator1D s;
    s.n = ns;
    s.a.resize(ns), s.b.resize(ns), s.c.resize(ns);
    for (int j = 0; j < ns; ++j) {
      s.a[j] = j > 0 ? 1.0 + 0.1 * j : 0.0;
      s.c[j] = j < ns - 1 ? 1.2 - 0.05 * j : 0.0;
      s.b[j] = -(2.3 + 0.1 * j);
    }
    const double sigma = 2.5;
    FastSolver fs(t, s, sigma);
    CHECK(fs.dense());
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> d(-1, 1);
    std::vector<double> x(std::size_t(n) * ns);
    for (auto& q : x) q = d(rng);
    auto X = [&](int k, int j) { return (k < 0 || k >= n || j < 0 || j >= ns) ? 0.0 : x[k + n * j]; };
    for (int j = 0; j < ns; ++j)
      for (int k = 0; k < n; ++k)
        fs.data()[k + n * j] = t.a[k] * X(k - 1, j) + t.b[k] * X(k, j) + t.c[k] * X(k + 1, j) +
                               s.a[j] * X(k, j - 1) + s.b[j] * X(k, j) + s.c[j] * X(k, j + 1) -
                               sigma * X(k, j);
    fs.solve();
    double err = 0;
    for (int q = 0; q < n * ns; ++q) err = std::max(err, std::abs(fs.data()[q] - x[q]));
    CHECK(err < 1e-11);
  }
}

TEST_CASE("pressure Poisson problem solved exactly on a stretched grid", "[fluid][poisson]") {
  // p random; r = D G p with zero-flux walls; the solve returns p up to a constant. Stretched in
  // y (transform in x), then banded in x and y (walls all round: the transform in y by its
  // eigenvectors, the zero mode of both directions), the y band off and on the channel's centre.
  for (int variant = 0; variant < 3; ++variant) {
  Config c = channel(16, 12, BcType::periodic, BcType::wall);
  c.y.tanh_beta = 2.0;
  if (variant >= 1) {
    c = channel(24, 16, BcType::wall, BcType::wall);
    c.x.band_from = 0.5, c.x.band_to = 1.0, c.x.band_cells = 8;
    c.y.band_from = 0.3, c.y.band_to = 0.5, c.y.band_cells = 4;
  }
  if (variant == 2)  // centred: y's eigenvectors even and odd to round-off, used whole
    c.y.band_from = 0.4, c.y.band_to = 0.6;
  INFO("variant " << variant);
  Solver s(c, 1e-4);
  const Grid& g = s.grid();
  const int nx = g.nx(), ny = g.ny();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  Field p(nx, ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) p(i, j) = d(rng);
  s.boundaries().fill_scalar(p);
  FastSolver& ps = s.poisson();
  CHECK(s.transform_axis() == std::min(variant, 1));
  auto at = [&](int i, int j) { return variant == 0 ? i + nx * j : j + ny * i; };
  const double *xwi = g.x().wi(), *xdi = g.x().di(), *ywi = g.y().wi(), *ydi = g.y().di();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double gn = j < ny - 1 ? (p(i, j + 1) - p(i, j)) * ydi[j + 1] : 0.0;
      const double gs = j > 0 ? (p(i, j) - p(i, j - 1)) * ydi[j] : 0.0;
      const double lx = ((p(i + 1, j) - p(i, j)) * xdi[i + 1] - (p(i, j) - p(i - 1, j)) * xdi[i]) * xwi[i];
      ps.data()[at(i, j)] = lx + (gn - gs) * ywi[j];
    }
  ps.solve();
  const double shift = ps.data()[0] - p(0, 0);
  double err = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) err = std::max(err, std::abs(ps.data()[at(i, j)] - shift - p(i, j)));
  CHECK(err < 1e-11);
  }
}

namespace {

// L2 velocity error of the Taylor-Green vortex at time t_end on n x n cells of [0, 2 pi]^2.
double taylor_green_error(int n, bool implicit, double dt, double t_end) {
  Config c;
  c.density = 1;
  c.viscosity = 0.05;
  const double L = 2 * std::numbers::pi;
  c.x = {n, L, 0.0};
  c.y = {n, L, 0.0};
  for (auto& b : c.bc) b.type = BcType::periodic;
  c.implicit = implicit;
  c.initial.type = InitialType::taylor_green;
  c.initial.amplitude = 1;
  Solver s(c, dt);
  set_initial(s);
  const long steps = std::lround(t_end / dt);
  for (long k = 0; k < steps; ++k) s.step(dt);
  const double decay = std::exp(-2 * c.viscosity * s.time());
  const Grid& g = s.grid();
  double e = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double ue = -std::cos(g.x().face(i)) * std::sin(g.y().centre(j)) * decay;
      const double ve = std::sin(g.x().centre(i)) * std::cos(g.y().face(j)) * decay;
      e += (std::pow(s.u()(i, j) - ue, 2) + std::pow(s.v()(i, j) - ve, 2)) * g.x().h() * g.y().h();
    }
  return std::sqrt(e / (2 * L * L));
}

}  // namespace

TEST_CASE("Taylor-Green vortex converges at second order in space and time", "[fluid][tg]") {
  for (bool implicit : {false, true}) {
    // Space: dt small and refined with h^2 so that the spatial error dominates.
    const double e16 = taylor_green_error(16, implicit, 0.02, 1.0);
    const double e32 = taylor_green_error(32, implicit, 0.005, 1.0);
    const double order = std::log2(e16 / e32);
    INFO("implicit " << implicit << " e16 " << e16 << " e32 " << e32 << " order " << order);
    CHECK(order >= 1.9);
  }
}

TEST_CASE("plane Poiseuille flow reaches the exact parabola", "[fluid][poiseuille]") {
  for (int variant = 0; variant < 3; ++variant) {
    Config c = channel(8, 16, BcType::periodic, BcType::wall);
    c.viscosity = 1;
    c.body = {2.0, 0.0};  // -dp/dx = G = 2: u = G / (2 mu) y (H - y)
    if (variant == 1) c.y.tanh_beta = 1.2;
    double dt = 0.25 * explicit_diffusion_limit(c);
    if (variant == 2) {
      c.implicit = true;
      c.factored_helmholtz = false;  // the direct solve (test_factored.cpp: the factored one)
      dt = 0.01;
    }
    Solver s(c, dt);
    set_initial(s);
    const long steps = std::lround(3.0 / dt);  // ~30 decay times of the slowest mode
    for (long k = 0; k < steps; ++k) s.step(dt);
    double err = 0;
    for (int j = 0; j < s.grid().ny(); ++j) {
      const double y = s.grid().y().centre(j);
      for (int i = 0; i < s.grid().nx(); ++i) err = std::max(err, std::abs(s.u()(i, j) - y * (1 - y)));
    }
    INFO("variant " << variant << " max error " << err);
    CHECK(err < 1e-10);
  }
}

TEST_CASE("Crank-Nicolson with walls across the transform direction keeps the exact steady state",
          "[fluid][poiseuille]") {
  // Walls at x = 0, 2 (the transform direction), periodic in y, force along y.
  Config c = channel(16, 8, BcType::wall, BcType::periodic);
  c.viscosity = 1;
  c.body = {0.0, 2.0};
  c.implicit = true;
  c.factored_helmholtz = false;  // the direct solve's closure in the transform direction
  const double h = 2.0 / 16;
  const double dt = 1.5 * h * h;  // nu dt / h^2 = 1.5: 12x the explicit limit
  Solver s(c, dt);
  set_initial(s);
  for (long k = 0; k < std::lround(12.0 / dt); ++k) s.step(dt);
  double err = 0;
  for (int j = 0; j < s.grid().ny(); ++j)
    for (int i = 0; i < s.grid().nx(); ++i) {
      const double x = s.grid().x().centre(i);
      err = std::max(err, std::abs(s.v()(i, j) - x * (2 - x)));
    }
  CHECK(err < 1e-10);
}

TEST_CASE("factored Crank-Nicolson reaches the exact parabola at any diffusion number",
          "[fluid][factored]") {
  // Plane Poiseuille flow along x (walls in y, the uniform and stretched cases) and along y (walls
  // at x = 0, 2, across the contiguous direction, where the direct solve is limited to
  // nu dt / h^2 < 2), at nu dt / h^2 = 5.
  for (int variant = 0; variant < 3; ++variant) {
    Config c = variant < 2 ? channel(8, 16, BcType::periodic, BcType::wall)
                           : channel(16, 8, BcType::wall, BcType::periodic);
    c.viscosity = 1;
    c.implicit = true;
    c.factored_helmholtz = true;
    if (variant == 1) c.y.tanh_beta = 1.2;
    const int a = variant < 2 ? 0 : 1;
    c.body[a] = 2.0;
    const double h = variant < 2 ? 1.0 / 16 : 2.0 / 16;
    const double dt = 5 * h * h;
    Solver s(c, dt);
    set_initial(s);
    for (long k = 0; k < std::lround(20.0 / dt); ++k) s.step(dt);
    double err = 0;
    for (int j = 0; j < s.grid().ny(); ++j)
      for (int i = 0; i < s.grid().nx(); ++i) {
        if (variant < 2) {
          const double y = s.grid().y().centre(j);
          err = std::max(err, std::abs(s.u()(i, j) - y * (1 - y)));
        } else {
          const double x = s.grid().x().centre(i);
          err = std::max(err, std::abs(s.v()(i, j) - x * (2 - x)));
        }
      }
    INFO("variant " << variant << " max error " << err);
    CHECK(err < 1e-10);
  }
}

TEST_CASE("two runs are bit-identical", "[fluid][determinism]") {
  Config c = channel(24, 16, BcType::inflow, BcType::wall);
  c.bc[left].mean = 1.0;
  c.bc[right].type = BcType::outflow;
  c.x.sponge_cells = 6;
  c.x.sponge_ratio = 1.1;
  c.viscosity = 0.01;
  c.implicit = true;
  auto run = [&] {
    Solver s(c, 0.01);
    set_initial(s);
    for (int k = 0; k < 20; ++k) s.step(0.01);
    return std::pair{s.u().a, s.p().a};
  };
  const auto a = run(), b = run();
  CHECK(a.first == b.first);
  CHECK(a.second == b.second);
}

// The CFL number against a loop written from its definition, on a random field and on one whose
// largest value sits in a known cell; a NaN or an infinity anywhere makes it NaN.
TEST_CASE("CFL number: value, cell and non-finite fields", "[fluid][health]") {
  Config c = channel(37, 23, BcType::periodic, BcType::wall);
  c.y.tanh_beta = 1.2;  // uneven rows: the row width enters
  Solver s(c, 1e-4);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  const Grid& g = s.grid();
  for (int j = 0; j < g.ny(); ++j)
    for (int i = 0; i <= g.nx(); ++i) s.u()(i, j) = d(rng);
  for (int j = 0; j <= g.ny(); ++j)
    for (int i = 0; i < g.nx(); ++i) s.v()(i, j) = d(rng);
  auto reference = [&] {
    Extremum e;
    for (int j = 0; j < g.ny(); ++j)
      for (int i = 0; i < g.nx(); ++i) {
        const double v = std::max(std::abs(s.u()(i, j)), std::abs(s.u()(i + 1, j))) * g.x().wi()[i] +
                         std::max(std::abs(s.v()(i, j)), std::abs(s.v()(i, j + 1))) * g.y().wi()[j];
        if (v > e.value) e = {v, i, j, 0, 0};
      }
    e.value *= 0.5;
    return e;
  };
  const Extremum r = reference(), e = cfl(s, 0.5);
  CHECK(e.value == r.value);
  CHECK(e.i == r.i);
  CHECK(e.j == r.j);
  s.u()(17, 9) = -40;  // the largest, in cell (16, 9) (face 17 is its right face) and (17, 9)
  const Extremum e2 = cfl(s, 0.5);
  CHECK(e2.value == reference().value);
  CHECK(e2.j == 9);
  CHECK((e2.i == 16 || e2.i == 17));
  CHECK(e2.x == g.x().centre(e2.i));
  CHECK(e2.y == g.y().centre(9));
  s.v()(3, 20) = std::numeric_limits<double>::infinity();
  CHECK(std::isnan(cfl(s, 0.5).value));
  s.v()(3, 20) = std::numeric_limits<double>::quiet_NaN();
  CHECK(std::isnan(cfl(s, 0.5).value));
  s.v()(3, 20) = 0;
  CHECK(std::isfinite(cfl(s, 0.5).value));
  // On the last face of a row or column (the second argument of each max).
  s.u()(g.nx(), 5) = std::numeric_limits<double>::quiet_NaN();
  CHECK(std::isnan(cfl(s, 0.5).value));
  s.u()(g.nx(), 5) = 0;
  s.v()(2, g.ny()) = std::numeric_limits<double>::quiet_NaN();
  CHECK(std::isnan(cfl(s, 0.5).value));
}
