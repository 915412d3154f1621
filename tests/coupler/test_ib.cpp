// Feedback-IB transfers: the kernel's moment conditions, exact interpolation of linear fields
// (also across a periodic boundary), conservation of spread force, interpolation = spreading^T.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <random>

#include "fixtures.hpp"
#include "ib.hpp"

using namespace coupler;
using coupler::testing::grid;

namespace {

// Face positions of the two families (u: (x_face[i], y_centre[j]), v: (x_centre[i], y_face[j])).
void face_xy(const proto::GridInfo& g, int c, std::int32_t f, double& x, double& y) {
  const double hx = g.x_face[1] - g.x_face[0], hy = g.y_face[1] - g.y_face[0];
  const int ni = c == 0 ? (g.periodic_x ? g.nx : g.nx + 1) : g.nx;
  const int i = f % ni, j = f / ni;
  x = g.x_face[0] + (c == 0 ? i * hx : (i + 0.5) * hx);
  y = g.y_face[0] + (c == 0 ? (j + 0.5) * hy : j * hy);
}

// <f, u>_grid: the spread forces (per unit volume, times the cell's volume) against velocities
// u given on the sorted sample faces `faces`.
double grid_dot(const proto::FaceForce& f, const std::vector<std::int32_t>& faces,
                const std::vector<double>& u, double cell) {
  double s = 0;
  for (std::size_t k = 0; k < f.index.size(); ++k)
    s += f.force[k] * cell * u[std::lower_bound(faces.begin(), faces.end(), f.index[k]) - faces.begin()];
  return s;
}

// Random velocities u, v on the sample faces su, sv, stored, and U interpolated at markers x.
void sample_and_interpolate(FeedbackIB& ib, const std::vector<double>& x,
                            const std::vector<std::int32_t>& su,
                            const std::vector<std::int32_t>& sv, std::mt19937& rng,
                            std::vector<double>& u, std::vector<double>& v,
                            std::vector<double>& U) {
  std::uniform_real_distribution<double> r(-1, 1);
  u.resize(su.size()), v.resize(sv.size());
  for (auto& a : u) a = r(rng);
  for (auto& a : v) a = r(rng);
  ib.store_samples(su, u, sv, v);
  ib.interpolate(x, U);
}

}  // namespace

TEST_CASE("Peskin's 4-point kernel: partition of unity and zero first moment") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> r(-0.5, 0.5);
  for (int t = 0; t < 1000; ++t) {
    const double s = r(rng);
    double m0 = 0, m1 = 0;
    for (int i = -3; i <= 3; ++i) m0 += peskin4(s - i), m1 += (s - i) * peskin4(s - i);
    CHECK(std::abs(m0 - 1) <= 1e-15);
    CHECK(std::abs(m1) <= 1e-15);
  }
}

TEST_CASE("Peskin's 4-point weights with one square root equal the kernel at the four points") {
  for (int t = 0; t <= 1000; ++t) {
    const double r = t < 1000 ? t / 1000.0 : std::nextafter(1.0, 0.0);
    double w[4];
    peskin4_weights(r, w);
    for (int k = 0; k < 4; ++k) CHECK(std::abs(w[k] - peskin4(r + 1 - k)) <= 1e-15);
  }
}

TEST_CASE("interpolation is exact for linear fields and, across periodic boundaries, constants") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> r(0, 1);
  SECTION("linear field, markers anywhere at least 2 cells from the walls") {
    const auto g = grid(40, 30, 2.0, 1.5, false, false);
    FeedbackIB ib(g);
    std::vector<double> x;
    for (int m = 0; m < 50; ++m) x.push_back(0.2 + 1.6 * r(rng)), x.push_back(0.2 + 1.1 * r(rng));
    std::vector<std::int32_t> fu, fv;
    ib.stencil({x}, 0, fu, fv);
    auto lin_u = [](double px, double py) { return 0.3 + 1.7 * px - 0.9 * py; };
    auto lin_v = [](double px, double py) { return -1.1 + 0.4 * px + 2.2 * py; };
    std::vector<double> u(fu.size()), v(fv.size());
    for (std::size_t k = 0; k < fu.size(); ++k) {
      double px, py;
      face_xy(g, 0, fu[k], px, py);
      u[k] = lin_u(px, py);
    }
    for (std::size_t k = 0; k < fv.size(); ++k) {
      double px, py;
      face_xy(g, 1, fv[k], px, py);
      v[k] = lin_v(px, py);
    }
    ib.store_samples(fu, u, fv, v);
    std::vector<double> U;
    ib.interpolate(x, U);
    for (std::size_t m = 0; m < x.size(); m += 2) {
      CHECK(std::abs(U[m] - lin_u(x[m], x[m + 1])) <= 1e-13);
      CHECK(std::abs(U[m + 1] - lin_v(x[m], x[m + 1])) <= 1e-13);
    }
  }
  SECTION("constant field across the periodic boundaries") {
    const auto g = grid(32, 32, 1.0, 1.0, true, true);
    FeedbackIB ib(g);
    const std::vector<double> x = {0.001, 0.5, 0.999, 0.002, 0.98, 0.99, 0.5, 0.5};
    std::vector<std::int32_t> fu, fv;
    ib.stencil({x}, 1, fu, fv);
    ib.store_samples(fu, std::vector<double>(fu.size(), 0.7), fv, std::vector<double>(fv.size(), -0.2));
    std::vector<double> U;
    ib.interpolate(x, U);
    for (std::size_t m = 0; m < x.size(); m += 2) {
      CHECK(std::abs(U[m] - 0.7) <= 1e-14);
      CHECK(std::abs(U[m + 1] + 0.2) <= 1e-14);
    }
  }
  SECTION("a marker outside the sampled stencil is an error") {
    const auto g = grid(32, 32, 1.0, 1.0, true, true);
    FeedbackIB ib(g);
    std::vector<std::int32_t> fu, fv;
    ib.stencil({{0.5, 0.5}}, 0, fu, fv);
    ib.store_samples(fu, std::vector<double>(fu.size(), 1.0), fv, std::vector<double>(fv.size(), 1.0));
    std::vector<double> U;
    CHECK_THROWS_WITH(ib.interpolate({0.6, 0.5}, U), Catch::Contains("moved beyond the sampled stencil"));
  }
}

TEST_CASE("spreading conserves force and is the transpose of interpolation") {
  const auto g = grid(48, 40, 1.2, 1.0, true, false);
  FeedbackIB ib(g);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> r(-1, 1);
  // A fiber that crosses the periodic boundary x = 0.
  std::vector<double> x, F;
  for (int m = 0; m < 40; ++m) {
    x.push_back(std::fmod(1.1 + 0.004 * m * 1.0 + 1.2, 1.2));
    x.push_back(0.3 + 0.01 * m);
    F.push_back(r(rng)), F.push_back(r(rng));
  }
  const double ds = 0.01;
  ib.spread(x, F, ds);
  std::vector<std::int32_t> su, sv;
  ib.stencil({x}, 0, su, sv);
  proto::FaceForce fu, fv;
  ib.take_spread(su, sv, fu, fv);
  const double cell = ib.hx() * ib.hy();
  double sx = 0, sy = 0, tx = 0, ty = 0, scale = 0;
  for (double f : fu.force) sx += f * cell, scale += std::abs(f * cell);
  for (double f : fv.force) sy += f * cell;
  // Marker arclengths: ds inside, ds/2 at the ends.
  auto w = [&](std::size_t m) { return m / 2 == 0 || m / 2 == F.size() / 2 - 1 ? 0.5 * ds : ds; };
  for (std::size_t m = 0; m < F.size(); m += 2) tx += F[m] * w(m), ty += F[m + 1] * w(m);
  CHECK(std::abs(sx + tx) <= 1e-12 * scale);
  CHECK(std::abs(sy + ty) <= 1e-12 * scale);

  // <spread(F), u>_grid = −<F, interp(u)>_markers for an arbitrary velocity u.
  std::vector<double> u, v, U;
  sample_and_interpolate(ib, x, su, sv, rng, u, v, U);
  double marker_side = 0;
  for (std::size_t m = 0; m < F.size(); ++m) marker_side += F[m] * U[m] * w(m);
  const double grid_side = grid_dot(fu, su, u, cell) + grid_dot(fv, sv, v, cell);
  CHECK(std::abs(grid_side + marker_side) <= 1e-12 * std::abs(marker_side));
}

TEST_CASE("a stretched grid is refused for fibers") {
  auto g = grid(8, 8, 1.0, 1.0, false, false);
  g.y_face[3] += 0.01;
  CHECK_THROWS_WITH(FeedbackIB(g), Catch::Contains("fibers need a uniform fluid grid"));
}

// Near a bounded side the kernel reaches faces beyond the wall, which hold no velocity and take
// no force: interpolation is the sum over the faces inside, spreading drops the rest, and the two
// stay each other's transpose.
TEST_CASE("next to a wall: interpolation over the faces inside, spreading its transpose") {
  const auto g = grid(32, 20, 1.6, 1.0, false, false);  // h = 0.05, walls all round
  FeedbackIB ib(g);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> r(-1, 1);
  std::vector<double> x, F;  // within a cell and a half of the bottom and left walls
  for (int m = 0; m < 30; ++m) {
    x.push_back(0.01 + 0.002 * m), x.push_back(0.012 + 0.002 * m);
    F.push_back(r(rng)), F.push_back(r(rng));
  }
  std::vector<std::int32_t> su, sv;
  ib.stencil({x}, 1, su, sv);
  std::vector<double> u, v, U;
  sample_and_interpolate(ib, x, su, sv, rng, u, v, U);
  // The same sum written out with the kernel over the faces inside the grid.
  for (std::size_t m = 0; m < x.size(); m += 2)
    for (int c = 0; c < 2; ++c) {
      const auto& faces = c == 0 ? su : sv;
      const auto& val = c == 0 ? u : v;
      double s = 0;
      for (std::size_t k = 0; k < faces.size(); ++k) {
        double fx = 0, fy = 0;
        face_xy(g, c, faces[k], fx, fy);
        s += val[k] * peskin4((fx - x[m]) / 0.05) * peskin4((fy - x[m + 1]) / 0.05);
      }
      CHECK(U[m + c] == Approx(s).margin(1e-13));
    }
  const double ds = 0.002;
  ib.spread(x, F, ds);
  proto::FaceForce fu, fv;
  ib.take_spread(su, sv, fu, fv);
  const double cell = ib.hx() * ib.hy();
  auto w = [&](std::size_t m) { return m / 2 == 0 || m / 2 == F.size() / 2 - 1 ? 0.5 * ds : ds; };
  double marker_side = 0;
  for (std::size_t m = 0; m < F.size(); ++m) marker_side += F[m] * U[m] * w(m);
  const double grid_side = grid_dot(fu, su, u, cell) + grid_dot(fv, sv, v, cell);
  CHECK(std::abs(grid_side + marker_side) <= 1e-12 * std::abs(marker_side));
  // The next take finds nothing left over.
  ib.take_spread(su, sv, fu, fv);
  CHECK(fu.index.empty());
  CHECK(fv.index.empty());
}

// The stencil is kept while every marker stays in its cell; it must equal a fresh one's after a
// sub-cell move, after a marker crosses into another cell, and with another margin or fiber count.
TEST_CASE("the kept sample stencil equals a fresh one") {
  const auto g = grid(48, 40, 1.2, 1.0, true, false);
  FeedbackIB kept(g);
  std::vector<std::vector<double>> fibers(3);
  auto place = [&](double shift) {
    for (std::size_t k = 0; k < fibers.size(); ++k) {
      fibers[k].clear();
      for (int m = 0; m < 20; ++m)
        fibers[k].push_back(std::fmod(0.1 + 0.4 * k + shift + 0.001 * m + 1.2, 1.2)),
            fibers[k].push_back(0.3 + 0.008 * m);
    }
  };
  auto same_as_fresh = [&](int margin) {
    std::vector<std::int32_t> ku, kv, fu, fv;
    kept.stencil(fibers, margin, ku, kv);
    FeedbackIB fresh(g);
    fresh.stencil(fibers, margin, fu, fv);
    CHECK(ku == fu);
    CHECK(kv == fv);
  };
  place(0.0);
  same_as_fresh(1);
  place(1e-4);  // within the cells
  same_as_fresh(1);
  place(0.013);  // about half a cell: some markers change cell
  same_as_fresh(1);
  same_as_fresh(0);
  fibers.pop_back();
  same_as_fresh(0);
  place(-0.2);  // across the periodic side
  same_as_fresh(1);
}

// The one-pass feedback (what the coupler runs each step) against its parts: U interpolated,
// F = kappa (dt U - (X - X_old)), F spread. The same sums in the same order, so the forces and the
// spread field agree bit for bit; on a bounded grid with markers next to a wall and across the
// middle, and with old positions of another length refused.
TEST_CASE("feedback in one pass equals interpolate, force and spread") {
  const auto g = grid(32, 20, 1.6, 1.0, false, false);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> r(-1, 1);
  std::vector<double> x, x_old;
  for (int m = 0; m < 60; ++m) {
    x.push_back(0.01 + 0.02 * m), x.push_back(0.02 + 0.015 * m);  // from the corner inwards
    x_old.push_back(x[2 * m] - 1e-3 * r(rng)), x_old.push_back(x[2 * m + 1] - 1e-3 * r(rng));
  }
  const double kappa = 2e3, dt = 1e-3, ds = 0.02;
  FeedbackIB a(g), b(g);
  std::vector<std::int32_t> su, sv;
  a.stencil({x}, 1, su, sv);
  std::vector<double> u, v, U;
  sample_and_interpolate(a, x, su, sv, rng, u, v, U);
  b.store_samples(su, u, sv, v);
  // a: the parts.
  std::vector<double> F(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) F[k] = kappa * (dt * U[k] - (x[k] - x_old[k]));
  a.spread(x, F, ds);
  proto::FaceForce fu_a, fv_a, fu_b, fv_b;
  a.take_spread(su, sv, fu_a, fv_a);
  // b: one pass.
  std::vector<double> G;
  b.feedback(x, x_old, kappa, dt, ds, G);
  b.take_spread(su, sv, fu_b, fv_b);
  CHECK(G == F);
  CHECK(fu_a.index == fu_b.index);
  CHECK(fu_a.force == fu_b.force);
  CHECK(fv_a.index == fv_b.index);
  CHECK(fv_a.force == fv_b.force);
  CHECK_FALSE(fu_b.index.empty());
  x_old.pop_back();
  CHECK_THROWS_WITH(b.feedback(x, x_old, kappa, dt, ds, G), Catch::Contains("marker coordinates"));
}
