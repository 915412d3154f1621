// Surface probes (surface.hpp): the wall shear stress from fluid samples outside a body, on
// analytic face fields: exact for a linear shear at any angle and across a periodic boundary,
// exact for a parabolic profile along a grid-aligned wall and first order or better tilted,
// zero for a rigid rotation (D = 0), and the input errors naming the key.
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <numbers>

#include "error.hpp"
#include "fixtures.hpp"
#include "surface.hpp"

using namespace coupler;
using Catch::Matchers::Contains;
using coupler::testing::grid;

namespace {

using Field = std::function<std::array<double, 2>(double, double)>;

// A rectangle W x H centred at (cx, cy), turned by theta: nodes counter-clockwise from the
// lower left, two triangles, surface edges with the body on the left.
proto::BodyMeshes block(double cx, double cy, double w, double h, double theta) {
  proto::BodyMesh b;
  b.name = "wall";
  b.kind = proto::BodyKind::rigid_fixed;
  const double c = std::cos(theta), s = std::sin(theta);
  for (auto [x, y] : {std::pair{-w / 2, -h / 2}, {w / 2, -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}})
    b.x_ref.push_back(cx + c * x - s * y), b.x_ref.push_back(cy + s * x + c * y);
  b.tri = {0, 1, 2, 0, 2, 3};
  b.edges = {0, 1, 1, 2, 2, 3, 3, 0};
  proto::BodyMeshes m;
  m.bodies.push_back(b);
  return m;
}

proto::SolidState state_of(const proto::BodyMeshes& m, const Field& body_velocity = nullptr) {
  proto::SolidState s;
  for (const auto& b : m.bodies) {
    s.x.push_back(b.x_ref);
    std::vector<double> v(b.x_ref.size(), 0.0);
    if (body_velocity)
      for (std::size_t k = 0; k + 1 < v.size(); k += 2) {
        const auto u = body_velocity(b.x_ref[k], b.x_ref[k + 1]);
        v[k] = u[0], v[k + 1] = u[1];
      }
    s.v.push_back(v);
  }
  return s;
}

using Scalar = std::function<double(double, double)>;

// The probe's row with the requested faces sampled from `field` (u at u-faces, v at v-faces)
// and the requested cells from `pressure` (at the cell centres; zero when not given).
std::vector<double> probe(const proto::GridInfo& g, const proto::BodyMeshes& m,
                          std::array<double, 2> point, double mu, const Field& field,
                          const Field& body_velocity = nullptr, const Scalar& pressure = nullptr) {
  SurfaceProbes sp(g, m, {{"P", "wall", point}}, mu, "test.toml");
  const auto st = state_of(m, body_velocity);
  std::vector<std::int32_t> uf, vf, pc;
  sp.add_requests(st, uf, vf, pc);
  std::vector<std::int32_t> uf2 = uf, vf2 = vf, pc2 = pc;
  sp.add_requests(st, uf2, vf2, pc2);
  CHECK(uf2 == uf);  // idempotent
  CHECK(vf2 == vf);
  CHECK(pc2 == pc);
  const int nu = g.periodic_x ? g.nx : g.nx + 1;
  std::vector<double> u, v;
  for (std::int32_t f : uf) {
    const int i = f % nu, j = f / nu;
    u.push_back(field(g.x_face[i], 0.5 * (g.y_face[j] + g.y_face[j + 1]))[0]);
  }
  for (std::int32_t f : vf) {
    const int i = f % g.nx, j = f / g.nx;
    v.push_back(field(0.5 * (g.x_face[i] + g.x_face[i + 1]), g.y_face[j])[1]);
  }
  std::vector<double> p;
  for (std::int32_t c : pc) {
    const int i = c % g.nx, j = c / g.nx;
    p.push_back(pressure ? pressure(0.5 * (g.x_face[i] + g.x_face[i + 1]),
                                    0.5 * (g.y_face[j] + g.y_face[j + 1]))
                         : 0.0);
  }
  std::vector<double> row;
  sp.evaluate(st, uf, u, vf, v, pc, p, row);
  REQUIRE(row.size() == SurfaceProbes::kColumns);
  return row;
}

}  // namespace

TEST_CASE("surface probe: a linear shear along a wall at any angle gives mu times its rate",
          "[coupler][surface]") {
  const auto g = grid(40, 40, 1.0, 1.0, false, false);
  const double mu = 0.3, gamma = 2.0, cx = 0.5, cy = 0.3, hb = 0.2;
  for (double deg : {0.0, 7.0, 30.0, 45.0, 60.0, 90.0, 137.0}) {
    const double th = deg * std::numbers::pi / 180;
    const auto m = block(cx, cy, 0.4, hb, th);
    // The top edge's outward normal n and t = (n_y, -n_x); a point on the edge, off its middle.
    const double nx = -std::sin(th), ny = std::cos(th), tx = ny, ty = -nx;
    const double px = cx + 0.1 * tx + 0.5 * hb * nx, py = cy + 0.1 * ty + 0.5 * hb * ny;
    // u = (U0 + gamma d) t, d the distance from the wall: D's shear part is gamma / 2.
    const Field f = [&](double x, double y) {
      const double d = (x - px) * nx + (y - py) * ny, s = 0.7 + gamma * d;
      return std::array<double, 2>{s * tx, s * ty};
    };
    const auto body = [&](double, double) { return std::array<double, 2>{0.7 * tx, 0.7 * ty}; };
    const auto row = probe(g, m, {px, py}, mu, f, body);
    INFO("wall at " << deg << " degrees");
    CHECK(row[0] == Approx(px).margin(1e-12));
    CHECK(row[1] == Approx(py).margin(1e-12));
    CHECK(row[2] == Approx(nx).margin(1e-12));
    CHECK(row[3] == Approx(ny).margin(1e-12));
    CHECK(row[4] == Approx(mu * gamma).epsilon(1e-10));
    CHECK(std::abs(row[5]) < 1e-10);  // no slip
  }
}

TEST_CASE("surface probe: the stencil wraps across a periodic boundary", "[coupler][surface]") {
  const auto g = grid(16, 32, 0.5, 1.0, true, false);
  const auto m = block(0.02, 0.3, 0.2, 0.2, 0.0);  // sticks out of x = 0 (clipped with images)
  const Field f = [](double, double y) { return std::array<double, 2>{-1.5 * (y - 0.4), 0.0}; };
  const auto row = probe(g, m, {-0.05, 0.4}, 2.0, f);
  CHECK(row[4] == Approx(-3.0).epsilon(1e-12));
}

TEST_CASE("surface probe: a parabolic profile is exact on an aligned wall, first order tilted",
          "[coupler][surface]") {
  // u = G/(2 mu) d (H - d) t over a wall at angle theta (the Poiseuille channel's profile),
  // tau = G H / 2 at the wall.
  const double mu = 0.5, G = 3.0, H = 0.5, exact = G * H / 2;
  auto error = [&](int n, double deg, double shift) {
    const auto g = grid(n, n, 1.0, 1.0, false, false);
    const double th = deg * std::numbers::pi / 180;
    const double nx = -std::sin(th), ny = std::cos(th), tx = ny, ty = -nx;
    const double cx = 0.5, cy = 0.2 + shift / n, hb = 0.2;
    const auto m = block(cx, cy, 0.4, hb, th);
    const double px = cx + 0.5 * hb * nx, py = cy + 0.5 * hb * ny;
    const Field f = [&](double x, double y) {
      const double d = (x - px) * nx + (y - py) * ny, s = G / (2 * mu) * d * (H - d);
      return std::array<double, 2>{s * tx, s * ty};
    };
    return std::abs(probe(g, m, {px, py}, mu, f)[4] - exact) / exact;
  };
  for (double shift : {0.0, 0.37})
    for (int n : {20, 40, 80}) CHECK(error(n, 0.0, shift) < 1e-10);
  // Tilted, the bilinear interpolation's error e_k <= h^2 |f''| / 8 differs from point to point;
  // the parabola's slope weights 14 / h in all (|L_k'(0)| at d = 2.5, 3.5, 4.5 h: 4, 7, 3), so
  // |tau error| / tau <= 14 (h / 8) (G / mu) / (G H / (2 mu)) = 3.5 h / H: first order, bounded,
  // not monotone (measured 0.026, 0.0071, 4.7e-5, 5.7e-4 on n = 20 ... 160).
  const double e20 = error(20, 27.0, 0.37);
  for (int n : {20, 40, 80, 160}) {
    const double e = error(n, 27.0, 0.37);
    INFO("n = " << n << ": relative error " << e);
    CHECK(e <= 3.5 * (1.0 / n) / H);
    CHECK(e <= e20 * 20.0 / n);
  }
}

TEST_CASE("surface probe: the pressure is exact for a linear field, second order for a smooth one",
          "[coupler][surface]") {
  // p = a + b.x: the line through the two nearest fluid points is the field, at any angle and
  // across a periodic boundary. p = cos(k . x): the error of the bilinear interpolation and of
  // the extrapolation, O(h^2).
  const Field still = [](double, double) { return std::array<double, 2>{0.0, 0.0}; };
  for (bool periodic : {false, true})
    for (double deg : {0.0, 21.0, 90.0, 160.0}) {
      const auto g = grid(40, 40, 1.0, 1.0, periodic, false);
      const double th = deg * std::numbers::pi / 180;
      const auto m = block(periodic ? 0.05 : 0.5, 0.4, 0.4, 0.2, th);
      const double nx = -std::sin(th), ny = std::cos(th);
      const double px = (periodic ? 0.05 : 0.5) + 0.1 * nx, py = 0.4 + 0.1 * ny;
      const Scalar lin = [&](double x, double y) {
        // periodic in x: no x-gradient (a periodic linear field would jump)
        return 2.0 + (periodic ? 0.0 : -1.3 * x) + 0.7 * y;
      };
      const auto row = probe(g, m, {px, py}, 1.0, still, nullptr, lin);
      INFO("wall at " << deg << " degrees, periodic " << periodic);
      CHECK(row[6] == Approx(lin(px, py)).epsilon(1e-12));
    }
  // The bound: the line's extrapolation error |p_nn| d_0 d_1 / 2 = 4.375 h^2 |p_nn| plus the
  // bilinear errors h^2 / 8 (|p_xx| + |p_yy|) at the two points, weighted 3.5 and 2.5: with
  // |p''| <= 13 for this p, 66.6 h^2. The two parts change sign independently from grid to grid
  // (the point's place in its cells), so the error is bounded, not monotone.
  for (int n : {40, 80, 160, 320}) {
    const auto g = grid(n, n, 1.0, 1.0, false, false);
    const auto m = block(0.5, 0.3, 0.4, 0.2, 0.3);
    const double nx = -std::sin(0.3), ny = std::cos(0.3);
    const double px = 0.5 + 0.1 * nx, py = 0.3 + 0.1 * ny;
    const Scalar wave = [](double x, double y) { return std::cos(3 * x + 2 * y); };
    const double e = std::abs(probe(g, m, {px, py}, 1.0, still, nullptr, wave)[6] - wave(px, py));
    const double h = 1.0 / n;
    INFO("n = " << n << ": error " << e << ", bound " << 66.6 * h * h);
    CHECK(e <= 66.6 * h * h);
  }
}

TEST_CASE("surface probe: a rigid rotation has no shear stress", "[coupler][surface]") {
  // u = omega x (r - c) everywhere, fluid and body: D = 0, tau = 0; d(u.t)/dn alone is
  // -omega, and the body's d(v.n)/dt along the surface cancels it.
  const auto g = grid(50, 50, 1.0, 1.0, false, false);
  const double omega = 1.7, ox = 0.45, oy = 0.35;
  const Field f = [&](double x, double y) {
    return std::array<double, 2>{-omega * (y - oy), omega * (x - ox)};
  };
  for (double deg : {0.0, 33.0}) {
    const double th = deg * std::numbers::pi / 180;
    const auto m = block(0.5, 0.3, 0.4, 0.2, th);
    const double nx = -std::sin(th), ny = std::cos(th);
    const auto row = probe(g, m, {0.5 + 0.1 * nx, 0.3 + 0.1 * ny}, 1.0, f, f);
    INFO("wall at " << deg << " degrees");
    CHECK(std::abs(row[4]) < 1e-10);
    CHECK(std::abs(row[5]) < 1e-10);
  }
}

TEST_CASE("surface probe: bad input names the key, the probe, the body and the distance",
          "[coupler][surface]") {
  const auto g = grid(20, 20, 1.0, 1.0, false, false);
  const auto m = block(0.5, 0.3, 0.4, 0.2, 0.0);  // top edge at y = 0.4
  auto make = [&](std::vector<SurfaceProbeSpec> s) { SurfaceProbes sp(g, m, s, 1.0, "x.toml"); };
  CHECK_NOTHROW(make({{"A", "", {0.5, 0.4}}}));  // body by nearest surface
  CHECK_THROWS_WITH(make({{"A", "wall", {0.5, 0.45}}}),
                    Contains("coupler.surface_probe[0] (name 'A')") &&
                        Contains("point = [0.5, 0.45] is not on the surface of body 'wall'") &&
                        Contains("0.05 away") && Contains("x.toml"));
  CHECK_THROWS_WITH(make({{"A", "", {0.5, 0.45}}}),
                    Contains("any body: the nearest is 'wall'") && Contains("0.05 away"));
  CHECK_THROWS_WITH(make({{"A", "cylinder", {0.5, 0.4}}}),
                    Contains("body = 'cylinder' is not a body of the scene (bodies: wall)"));
  CHECK_THROWS_WITH(make({{"A", "", {0.5, 0.4}}, {"A", "", {0.6, 0.4}}}),
                    Contains("coupler.surface_probe[1] (name 'A'): the name is used by "
                             "coupler.surface_probe[0]"));
  proto::BodyMeshes none;
  CHECK_THROWS_WITH(SurfaceProbes(g, none, {{"A", "", {0.5, 0.4}}}, 1.0, "x.toml"),
                    Contains("no body surface"));
}
