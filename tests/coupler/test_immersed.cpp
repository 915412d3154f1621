// The immersed solid transfers: volume fractions add up to the body's area, mean velocities are
// the exact means of linear fields, and the nodal reaction cancels the fluid forcing.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "clip.hpp"
#include "fixtures.hpp"
#include "immersed.hpp"
#include "sorted_marks.hpp"

using namespace coupler;
using coupler::testing::grid;

namespace {


// A w × h rectangle of m × n cells, each split into two triangles, rotated by theta about its
// centre and centred at c.
proto::BodyMesh rectangle(double w, double h, int m, int n, double theta, Vec2 c) {
  proto::BodyMesh b;
  b.name = "rect";
  const double ct = std::cos(theta), st = std::sin(theta);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= m; ++i) {
      const double x = w * i / m - w / 2, y = h * j / n - h / 2;
      b.x_ref.push_back(c.x + ct * x - st * y);
      b.x_ref.push_back(c.y + st * x + ct * y);
    }
  auto id = [&](int i, int j) { return i + (m + 1) * j; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i) {
      b.tri.insert(b.tri.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      b.tri.insert(b.tri.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return b;
}

// A polygonal disk: a centre node and `rings` rings of 6k nodes.
proto::BodyMesh disk(double r, int rings, Vec2 c, double* area) {
  proto::BodyMesh b;
  b.name = "disk";
  b.x_ref = {c.x, c.y};
  std::vector<int> first{0};
  for (int k = 1; k <= rings; ++k) {
    first.push_back(static_cast<int>(b.x_ref.size() / 2));
    for (int q = 0; q < 6 * k; ++q) {
      const double phi = 2 * M_PI * q / (6 * k);
      b.x_ref.push_back(c.x + r * k / rings * std::cos(phi));
      b.x_ref.push_back(c.y + r * k / rings * std::sin(phi));
    }
  }
  // Fan between ring k-1 and ring k by walking both rings in angle.
  for (int k = 1; k <= rings; ++k) {
    const int nin = k == 1 ? 1 : 6 * (k - 1), nout = 6 * k;
    int a = 0, o = 0;
    while (a < nin || o < nout) {
      const int in0 = first[k - 1] + (k == 1 ? 0 : a % nin);
      const int o0 = first[k] + o % nout, o1 = first[k] + (o + 1) % nout;
      const double ang_in = k == 1 ? 1e9 : (a + 1.0) / nin, ang_out = (o + 1.0) / nout;
      if (o < nout && (a >= nin || ang_out <= ang_in)) {
        b.tri.insert(b.tri.end(), {in0, o0, o1});
        ++o;
      } else {
        const int in1 = first[k - 1] + (a + 1) % nin;
        b.tri.insert(b.tri.end(), {in0, o0, in1});
        ++a;
      }
    }
  }
  *area = 0;
  for (std::size_t e = 0; e < b.tri.size(); e += 3) {
    const double* p = b.x_ref.data();
    const int i = b.tri[e], j = b.tri[e + 1], k = b.tri[e + 2];
    *area += 0.5 * ((p[2 * j] - p[2 * i]) * (p[2 * k + 1] - p[2 * i + 1]) -
                    (p[2 * k] - p[2 * i]) * (p[2 * j + 1] - p[2 * i + 1]));
  }
  return b;
}

proto::SolidState at_rest(const proto::BodyMeshes& m) {
  proto::SolidState s;
  for (const auto& b : m.bodies) {
    s.x.push_back(b.x_ref);
    s.v.emplace_back(b.x_ref.size(), 0.0);
  }
  return s;
}

double sum_alpha_volume(const FaceBoxes& boxes, const proto::FaceSolid& f) {
  double s = 0;
  for (std::size_t k = 0; k < f.index.size(); ++k)
    s += f.alpha[k] * boxes.volume(f.index[k] % boxes.ni, f.index[k] / boxes.ni);
  return s;
}

// Independent reference: a convex polygon clipped against a box, edge by edge (no triangles).
std::vector<Vec2> clip_convex(std::vector<Vec2> poly, double x0, double x1, double y0, double y1) {
  auto cut = [](const std::vector<Vec2>& in, auto inside, auto cross) {
    std::vector<Vec2> out;
    for (std::size_t k = 0; k < in.size(); ++k) {
      const Vec2 a = in[k], b = in[(k + 1) % in.size()];
      if (inside(a)) out.push_back(a);
      if (inside(a) != inside(b)) out.push_back(cross(a, b));
    }
    return out;
  };
  auto on_x = [](double c) {
    return [c](Vec2 a, Vec2 b) { return Vec2{c, a.y + (c - a.x) / (b.x - a.x) * (b.y - a.y)}; };
  };
  auto on_y = [](double c) {
    return [c](Vec2 a, Vec2 b) { return Vec2{a.x + (c - a.y) / (b.y - a.y) * (b.x - a.x), c}; };
  };
  poly = cut(poly, [&](Vec2 p) { return p.x >= x0; }, on_x(x0));
  if (poly.empty()) return poly;
  poly = cut(poly, [&](Vec2 p) { return p.x <= x1; }, on_x(x1));
  if (poly.empty()) return poly;
  poly = cut(poly, [&](Vec2 p) { return p.y >= y0; }, on_y(y0));
  if (poly.empty()) return poly;
  return cut(poly, [&](Vec2 p) { return p.y <= y1; }, on_y(y1));
}


// The control volume |CV| of face idx of family comp (0: u, 1: v) from the grid's faces alone,
// independently of FaceBoxes: a u-face's spans x between the centres of its two cells (across a
// periodic side, the last cell's and the first's) and y over its row; a v-face's the other way
// round. Interior faces and those of a periodic side only: a boundary face of another side, or
// an index outside the grid, throws.
double face_volume(const proto::GridInfo& g, int comp, std::int32_t idx) {
  auto width = [](const std::vector<double>& f, int k, bool periodic) {
    const int n = static_cast<int>(f.size()) - 1;
    if (periodic && k == -1) k = n - 1;  // the cell before the first, across the period
    if (k < 0 || k >= n) throw std::out_of_range("face_volume: a boundary face");
    return f[k + 1] - f[k];
  };
  const bool px = g.periodic_x != 0, py = g.periodic_y != 0;
  const int ni = comp == 0 && !px ? g.nx + 1 : g.nx;
  const int nj = comp == 1 && !py ? g.ny + 1 : g.ny;
  if (idx < 0 || idx >= ni * nj) throw std::out_of_range("face_volume: no such face");
  const int i = idx % ni, j = idx / ni;
  if (comp == 0)
    return 0.5 * (width(g.x_face, i - 1, px) + width(g.x_face, i, px)) * width(g.y_face, j, false);
  return width(g.x_face, i, false) * 0.5 * (width(g.y_face, j - 1, py) + width(g.y_face, j, py));
}

// The fluid's forcing f_s (random values on the faces the body touches) and its nodal reaction:
// Σ_CV f_s |CV| + Σ_a F_a per component, which must vanish, and Σ |f_s| |CV| for its scale
// (|CV| from face_volume, not from the FaceBoxes the reaction uses).
struct Balance {
  double fx = 0, fy = 0, scale = 0;
};
Balance action_plus_reaction(const proto::GridInfo& g, const ImmersedSolid& is,
                             const proto::FaceSolid& u, const proto::FaceSolid& v, std::mt19937& rng) {
  std::uniform_real_distribution<double> r(-1, 1);
  std::vector<double> fs_u(u.index.size()), fs_v(v.index.size());
  for (auto& x : fs_u) x = 1000 * r(rng);
  for (auto& x : fs_v) x = 1000 * r(rng);
  std::vector<std::vector<double>> F;
  is.reaction(fs_u, fs_v, F);
  Balance b;
  for (std::size_t k = 0; k < u.index.size(); ++k) {
    const double f = fs_u[k] * face_volume(g, 0, u.index[k]);
    b.fx += f, b.scale += std::abs(f);
  }
  for (std::size_t k = 0; k < v.index.size(); ++k) {
    const double f = fs_v[k] * face_volume(g, 1, v.index[k]);
    b.fy += f, b.scale += std::abs(f);
  }
  for (const auto& fb : F)
    for (std::size_t k = 0; k < fb.size(); k += 2) b.fx += fb[k], b.fy += fb[k + 1];
  return b;
}

}  // namespace

TEST_CASE("triangle-box clipping") {
  const Vec2 t[3] = {{0, 0}, {1, 0}, {0, 1}};
  Vec2 out[7];
  SECTION("triangle inside the box") {
    const int n = clip_triangle_box(t, -1, 2, -1, 2, out);
    CHECK(n == 3);
    CHECK(polygon_moments(out, n).area == Approx(0.5).epsilon(1e-15));
  }
  SECTION("box inside the triangle") {
    const int n = clip_triangle_box(t, 0.1, 0.2, 0.1, 0.3, out);
    CHECK(polygon_moments(out, n).area == Approx(0.02).epsilon(1e-13));
    CHECK(polygon_moments(out, n).centroid.x == Approx(0.15).epsilon(1e-13));
  }
  SECTION("box cutting a corner") {
    const int n = clip_triangle_box(t, 0.5, 2, -1, 2, out);
    CHECK(polygon_moments(out, n).area == Approx(0.125).epsilon(1e-14));
  }
  SECTION("disjoint") { CHECK(clip_triangle_box(t, 2, 3, 2, 3, out) == 0); }
}

namespace {

// Bodies on grids whose footprints must add up to the body's area.
struct AreaCase {
  std::string name;
  proto::GridInfo g;
  proto::BodyMesh body;
  double area;
};
std::vector<AreaCase> area_cases() {
  std::vector<AreaCase> cases;
  cases.push_back({"rotated square", grid(32, 24, 1.0, 0.75, false, false),
                   rectangle(0.3, 0.3, 7, 7, 0.37, {0.47, 0.39}), 0.09});
  double disk_area = 0;
  auto d = disk(0.17, 6, {0.52, 0.4}, &disk_area);
  cases.push_back({"disk", grid(40, 32, 1.0, 0.8, false, false), d, disk_area});
  cases.push_back({"across the periodic boundaries", grid(32, 32, 1.0, 1.0, true, true),
                   rectangle(0.4, 0.25, 9, 5, 0.2, {0.97, 0.02}), 0.1});
  cases.push_back({"travelled several periods", grid(32, 32, 1.0, 1.0, true, true),
                   rectangle(0.4, 0.25, 9, 5, 0.2, {0.97 + 2.0, 0.02 - 3.0}), 0.1});
  cases.push_back({"stretched grid", [] {
                     auto g = grid(30, 20, 1.0, 1.0, true, false);
                     for (int j = 0; j <= 20; ++j) g.y_face[j] = std::pow(j / 20.0, 1.5);
                     return g;
                   }(),
                   rectangle(0.5, 0.3, 10, 6, -0.6, {0.5, 0.5}), 0.15});
  return cases;
}

// The grid g with both directions stretched (the ends stay, so a periodic direction keeps its
// period). x: each face moved by s -> s + a s (s - 1) of the span, the spacing 1 + a (2s - 1)
// growing from one end to the other, so that across a periodic side the last cell is
// (1 + a)/(1 - a) times as wide as the first. y: s -> s + a sin(2 pi s) / (2 pi), the spacing
// 1 + a cos(2 pi s), finer in the middle and coarser towards the ends, as bands give. Both
// monotone for a < 1.
proto::GridInfo stretched_both(proto::GridInfo g) {
  auto warp = [](std::vector<double>& f, auto shift) {
    const double lo = f.front(), len = f.back() - f.front(), n = double(f.size() - 1);
    for (std::size_t k = 1; k + 1 < f.size(); ++k) {
      const double s = k / n;
      f[k] = lo + len * (s + shift(s));
    }
  };
  warp(g.x_face, [](double s) { return 0.45 * s * (s - 1); });
  warp(g.y_face, [](double s) { return 0.6 * std::sin(2 * M_PI * s) / (2 * M_PI); });
  return g;
}

}  // namespace

TEST_CASE("volume fractions add up to the body's area, for u- and v-cells separately") {
  for (auto& c : area_cases()) {
    SECTION(c.name) {
      proto::BodyMeshes m;
      m.bodies.push_back(c.body);
      ImmersedSolid is(c.g, m);
      proto::FaceSolid u, v;
      is.update(at_rest(m), u, v);
      CHECK(std::abs(sum_alpha_volume(FaceBoxes::u_faces(c.g), u) - c.area) <= 1e-12 * c.area);
      CHECK(std::abs(sum_alpha_volume(FaceBoxes::v_faces(c.g), v) - c.area) <= 1e-12 * c.area);
      for (double a : u.alpha) CHECK((a > 0 && a <= 1.0));
    }
  }
}

TEST_CASE("mean solid velocity is the exact mean over CV ∩ body of a linear field") {
  const auto uniform = grid(24, 20, 1.2, 1.0, false, false);
  const bool stretched = GENERATE(false, true);
  INFO((stretched ? "both directions stretched" : "uniform grid"));
  const auto g = stretched ? stretched_both(uniform) : uniform;
  const double theta = 0.41, w = 0.5, h = 0.35;
  const Vec2 c{0.61, 0.48};
  proto::BodyMeshes m;
  m.bodies.push_back(rectangle(w, h, 9, 6, theta, c));
  // The body's outline, for the independent reference.
  std::vector<Vec2> outline;
  for (auto [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const double x = sx * w / 2, y = sy * h / 2;
    outline.push_back({c.x + std::cos(theta) * x - std::sin(theta) * y,
                       c.y + std::sin(theta) * x + std::cos(theta) * y});
  }
  struct Field {
    const char* name;
    double a11, a12, a21, a22, b1, b2;
  };
  for (const Field f : {Field{"rigid rotation", 0, -2.5, 2.5, 0, 0.3, -0.1},
                        Field{"linear strain", 1.5, 0.7, -0.4, -1.1, 0, 0}}) {
    SECTION(f.name) {
      auto s = at_rest(m);
      for (std::size_t k = 0; k < s.x[0].size(); k += 2) {
        const double x = s.x[0][k], y = s.x[0][k + 1];
        s.v[0][k] = f.a11 * x + f.a12 * y + f.b1;
        s.v[0][k + 1] = f.a21 * x + f.a22 * y + f.b2;
      }
      ImmersedSolid is(g, m);
      proto::FaceSolid u, v;
      is.update(s, u, v);
      double worst = 0;
      for (int comp = 0; comp < 2; ++comp) {
        const auto boxes = comp == 0 ? FaceBoxes::u_faces(g) : FaceBoxes::v_faces(g);
        const auto& fs = comp == 0 ? u : v;
        REQUIRE(!fs.index.empty());
        // The control volumes from the grid's faces, independently of FaceBoxes: a u-face's
        // spans x between the centres of its two cells and y over its cell; a v-face's the other
        // way round (the body lies inside the grid, so every face is an interior one).
        const auto& xf = g.x_face;
        const auto& yf = g.y_face;
        auto mid = [](const std::vector<double>& f, int k) { return 0.5 * (f[k] + f[k + 1]); };
        for (std::size_t k = 0; k < fs.index.size(); ++k) {
          const int i = fs.index[k] % boxes.ni, j = fs.index[k] / boxes.ni;
          const double x0 = comp == 0 ? mid(xf, i - 1) : xf[i], x1 = comp == 0 ? mid(xf, i) : xf[i + 1];
          const double y0 = comp == 0 ? yf[j] : mid(yf, j - 1), y1 = comp == 0 ? yf[j + 1] : mid(yf, j);
          const auto p = clip_convex(outline, x0, x1, y0, y1);
          const auto mo = polygon_moments(p.data(), static_cast<int>(p.size()));
          const double exact = comp == 0 ? f.a11 * mo.centroid.x + f.a12 * mo.centroid.y + f.b1
                                         : f.a21 * mo.centroid.x + f.a22 * mo.centroid.y + f.b2;
          worst = std::max(worst, std::abs(fs.velocity[k] - exact));
          // The fraction agrees with the independent clipping as well (to round-off of a
          // polygon of small area).
          CHECK(std::abs(fs.alpha[k] * (x1 - x0) * (y1 - y0) - mo.area) <= 1e-14);
        }
      }
      CHECK(worst <= 1e-12);
    }
  }
}

TEST_CASE("the nodal reaction cancels the fluid forcing: action = reaction") {
  const auto uniform = grid(32, 32, 1.0, 1.0, true, false);
  const bool stretched = GENERATE(false, true);
  INFO((stretched ? "both directions stretched" : "uniform grid"));
  const auto g = stretched ? stretched_both(uniform) : uniform;
  proto::BodyMeshes m;
  m.bodies.push_back(rectangle(0.3, 0.2, 8, 5, 0.3, {0.1, 0.5}));  // crosses x = 0
  double area = 0;
  m.bodies.push_back(disk(0.12, 4, {0.6, 0.45}, &area));
  m.bodies[1].kind = fsi::proto::BodyKind::rigid_fixed;  // rigid fixed: clipped once, reused
  ImmersedSolid is(g, m);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> r(-1, 1);
  auto s = at_rest(m);
  for (int step = 0; step < 3; ++step) {
    for (double& x : s.x[0]) x += 0.01 * r(rng);  // the elastic body moves a little each step
    proto::FaceSolid u, v;
    is.update(s, u, v);
    const auto b = action_plus_reaction(g, is, u, v, rng);
    CHECK(std::abs(b.fx) <= 1e-12 * b.scale);
    CHECK(std::abs(b.fy) <= 1e-12 * b.scale);
  }
}

// A rigid fixed body is clipped once and handled per face afterwards; its transfers must be
// those of the same body clipped every step, to the bit: the faces, α, ū_s and the reaction,
// with the body at rest (its pieces then add nothing to ū_s) and moving (a state a fixed body
// does not send, summed all the same), through update() and update_velocities().
TEST_CASE("a fixed body's transfers are those of the same body clipped every step") {
  const auto g = grid(32, 32, 1.0, 1.0, true, false);
  proto::BodyMeshes clipped_each_step;
  double area = 0;
  // The disk first: its pieces then come first in both runs, so every sum runs in one order.
  clipped_each_step.bodies.push_back(disk(0.12, 4, {0.45, 0.45}, &area));
  clipped_each_step.bodies.push_back(rectangle(0.3, 0.2, 8, 5, 0.3, {0.62, 0.5}));  // overlaps it
  proto::BodyMeshes fixed = clipped_each_step;
  fixed.bodies[0].kind = fsi::proto::BodyKind::rigid_fixed;
  ImmersedSolid a(g, clipped_each_step), b(g, fixed);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> r(-1, 1);
  auto s = at_rest(clipped_each_step);
  auto same = [](const proto::FaceSolid& p, const proto::FaceSolid& q) {
    CHECK(p.index == q.index);
    CHECK(p.alpha == q.alpha);
    CHECK(p.velocity == q.velocity);
  };
  for (int step = 0; step < 3; ++step) {
    for (double& x : s.x[1]) x += 0.01 * r(rng);
    for (double& v : s.v[1]) v = r(rng);
    if (step == 2)
      for (double& v : s.v[0]) v = r(rng);
    proto::FaceSolid ua, va, ub, vb;
    a.update(s, ua, va);
    b.update(s, ub, vb);
    same(ua, ub);
    same(va, vb);
    for (double& v : s.v[0]) v = step == 1 ? r(rng) : 0.0;
    for (double& v : s.v[1]) v = r(rng);
    a.update_velocities(s, ua, va);
    b.update_velocities(s, ub, vb);
    same(ua, ub);
    same(va, vb);
    std::vector<double> fs_u(ua.index.size()), fs_v(va.index.size());
    for (auto& x : fs_u) x = 1000 * r(rng);
    for (auto& x : fs_v) x = 1000 * r(rng);
    std::vector<std::vector<double>> fa, fb;
    a.reaction(fs_u, fs_v, fa);
    b.reaction(fs_u, fs_v, fb);
    CHECK(fa == fb);
    CHECK(a.area_u() == b.area_u());
    CHECK(a.area_v() == b.area_v());
  }
}

// Two bodies that overlap (contact): on each face α = min(1, (|CV ∩ A| + |CV ∩ B|)/|CV|), so α
// is capped at 1 where the overlap would count twice; ū_s is the mean over both pieces, weighted
// by their areas; the reaction still cancels the forcing. The reference clips each body's
// outline against the box independently (no triangles).
TEST_CASE("overlapping bodies: alpha capped at 1, the mean velocity weighted by both pieces") {
  const auto g = grid(24, 20, 1.2, 1.0, false, false);
  struct Body {
    double w, h, theta;
    Vec2 c, vel;
  };
  const Body bodies[] = {{0.5, 0.4, 0.2, {0.45, 0.45}, {1.0, -0.5}},
                         {0.45, 0.35, -0.3, {0.7, 0.55}, {-2.0, 0.75}}};
  proto::BodyMeshes m;
  std::vector<std::vector<Vec2>> outline;
  for (const auto& b : bodies) {
    m.bodies.push_back(rectangle(b.w, b.h, 9, 7, b.theta, b.c));
    outline.emplace_back();
    for (auto [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      const double x = sx * b.w / 2, y = sy * b.h / 2;
      outline.back().push_back({b.c.x + std::cos(b.theta) * x - std::sin(b.theta) * y,
                                b.c.y + std::sin(b.theta) * x + std::cos(b.theta) * y});
    }
  }
  auto s = at_rest(m);
  for (int b = 0; b < 2; ++b)
    for (std::size_t k = 0; k < s.v[b].size(); k += 2) {
      s.v[b][k] = bodies[b].vel.x;
      s.v[b][k + 1] = bodies[b].vel.y;
    }
  ImmersedSolid is(g, m);
  proto::FaceSolid u, v;
  is.update(s, u, v);
  for (int comp = 0; comp < 2; ++comp) {
    const auto boxes = comp == 0 ? FaceBoxes::u_faces(g) : FaceBoxes::v_faces(g);
    const auto& fs = comp == 0 ? u : v;
    int capped = 0, shared = 0;
    for (std::size_t k = 0; k < fs.index.size(); ++k) {
      const int i = fs.index[k] % boxes.ni, j = fs.index[k] / boxes.ni;
      double area[2], sum_v = 0;
      for (int b = 0; b < 2; ++b) {
        const auto p = clip_convex(outline[b], boxes.ex[i], boxes.ex[i + 1], boxes.ey[j],
                                   boxes.ey[j + 1]);
        area[b] = p.empty() ? 0.0 : polygon_moments(p.data(), static_cast<int>(p.size())).area;
        sum_v += area[b] * (comp == 0 ? bodies[b].vel.x : bodies[b].vel.y);
      }
      const double vol = boxes.volume(i, j), both = area[0] + area[1];
      CHECK(std::abs(fs.alpha[k] - std::min(1.0, both / vol)) <= 1e-13);
      CHECK(fs.alpha[k] <= 1.0);
      CHECK(std::abs(fs.velocity[k] - sum_v / both) <= 1e-12);
      capped += both > vol * (1 + 1e-9);
      shared += area[0] > 0 && area[1] > 0;
      // The face's body (protocol version 9): -1 exactly where both outlines reach into the box,
      // else the one that does; a sliver below round-off may go either way.
      REQUIRE(fs.body.size() == fs.index.size());
      const double sliver = 1e-12 * vol;
      if (std::min(area[0], area[1]) > sliver) CHECK(fs.body[k] == -1);
      if (area[1] == 0) CHECK(fs.body[k] == 0);
      if (area[0] == 0) CHECK(fs.body[k] == 1);
    }
    CHECK(capped > 10);  // the overlap covers whole boxes twice: the cap is exercised
    CHECK(shared > capped);
  }
  // One body alone: no bodies are sent.
  proto::BodyMeshes one;
  one.bodies.push_back(m.bodies[0]);
  ImmersedSolid alone(g, one);
  proto::FaceSolid u1, v1;
  alone.update(at_rest(one), u1, v1);
  CHECK(!u1.index.empty());
  CHECK(u1.body.empty());
  CHECK(v1.body.empty());
  // The second body fixed (its faces' bodies found once, when it is first clipped), and the
  // velocities refilled for a coupled iteration: the same names.
  proto::BodyMeshes with_fixed = m;
  with_fixed.bodies[1].kind = proto::BodyKind::rigid_fixed;
  ImmersedSolid fixed_is(g, with_fixed);
  proto::FaceSolid uf, vf;
  const auto rest = at_rest(with_fixed);
  fixed_is.update(rest, uf, vf);
  CHECK(uf.body == u.body);
  CHECK(vf.body == v.body);
  fixed_is.update(rest, uf, vf);  // the fixed body's pieces kept from the first step
  CHECK(uf.body == u.body);
  fixed_is.update_velocities(rest, uf, vf);
  CHECK(vf.body == v.body);
  // Action = reaction with the overlap.
  std::mt19937 rng(5);
  const auto b = action_plus_reaction(g, is, u, v, rng);
  CHECK(std::abs(b.fx) <= 1e-12 * b.scale);
  CHECK(std::abs(b.fy) <= 1e-12 * b.scale);
}

// The elastic bodies' part of α (protocol version 8), where the fluid takes its viscosity out of
// the bodies: none sent while every body is elastic; with a rigid body (fixed, prescribed or
// free) that overlaps an elastic one, min(1, |CV ∩ elastic|/|CV|) on every face, the elastic body's exact
// outline clipped as reference, on faces of either body alone and of both.
TEST_CASE("the elastic part of alpha: empty when all bodies are elastic, else theirs alone") {
  const auto g = grid(24, 20, 1.2, 1.0, false, false);
  proto::BodyMeshes m;
  const double theta = 0.2, w = 0.5, h = 0.4;
  const Vec2 c{0.45, 0.45};
  m.bodies.push_back(rectangle(w, h, 9, 7, theta, c));
  m.bodies.push_back(rectangle(0.45, 0.35, 9, 7, 0.0, {0.7, 0.55}));
  std::vector<Vec2> elastic;  // the first body's outline
  for (auto [sx, sy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
    elastic.push_back({c.x + std::cos(theta) * sx * w / 2 - std::sin(theta) * sy * h / 2,
                       c.y + std::sin(theta) * sx * w / 2 + std::cos(theta) * sy * h / 2});
  const std::vector<Vec2> rigid = {{0.475, 0.375}, {0.925, 0.375}, {0.925, 0.725}, {0.475, 0.725}};
  const auto s = at_rest(m);
  {
    ImmersedSolid all_elastic(g, m);
    proto::FaceSolid u, v;
    all_elastic.update(s, u, v);
    CHECK(!u.index.empty());
    CHECK(u.elastic.empty());
    CHECK(v.elastic.empty());
  }
  // Fixed, prescribed, and free (kind 0, rigid = 1: solid_rigid's bodies).
  for (const auto& [kind, rigid_flag] :
       {std::pair{proto::BodyKind::rigid_fixed, 0}, std::pair{proto::BodyKind::rigid_moving, 0},
        std::pair{proto::BodyKind::elastic, 1}}) {
    m.bodies[1].kind = kind;
    m.bodies[1].rigid = rigid_flag;
    ImmersedSolid is(g, m);
    proto::FaceSolid u, v;
    is.update(s, u, v);
    for (int comp = 0; comp < 2; ++comp) {
      const auto boxes = comp == 0 ? FaceBoxes::u_faces(g) : FaceBoxes::v_faces(g);
      const auto& fs = comp == 0 ? u : v;
      REQUIRE(fs.elastic.size() == fs.index.size());
      int rigid_only = 0, elastic_only = 0, both = 0;
      for (std::size_t k = 0; k < fs.index.size(); ++k) {
        const int i = fs.index[k] % boxes.ni, j = fs.index[k] / boxes.ni;
        auto area = [&](const std::vector<Vec2>& outline) {
          const auto p = clip_convex(outline, boxes.ex[i], boxes.ex[i + 1], boxes.ey[j],
                                     boxes.ey[j + 1]);
          return p.empty() ? 0.0 : polygon_moments(p.data(), static_cast<int>(p.size())).area;
        };
        const double vol = boxes.volume(i, j), a_el = area(elastic), a_rigid = area(rigid);
        CHECK(std::abs(fs.elastic[k] - std::min(1.0, a_el / vol)) <= 1e-13);
        CHECK(fs.elastic[k] <= fs.alpha[k]);
        const bool e = a_el > 1e-12 * vol, r = a_rigid > 1e-12 * vol;
        both += e && r, rigid_only += r && !e, elastic_only += e && !r;
      }
      CHECK(rigid_only > 5);
      CHECK(elastic_only > 5);
      CHECK(both > 5);
    }
  }
}

// The smoothed footprint (`[coupler] footprint_smoothing = ε`): each face's weight is its box
// convolved with a box of width ε h, a partition of unity; ε = 1 on a uniform grid is the tent of
// width 2h.
namespace {

// ∫_{-1}^{d} (1 − |s|) ds: the fraction of a unit tent below d.
double tent_below(double d) {
  if (d <= -1) return 0;
  if (d >= 1) return 1;
  return d <= 0 ? 0.5 * (1 + d) * (1 + d) : 1 - 0.5 * (1 - d) * (1 - d);
}

// The fraction below d (in cells from the face) of the box of width 1 convolved with a box of
// width e: flat within (1 − e)/2 of the face, ramps of width e about ±1/2.
double smoothed_below(double d, double e) {
  auto ramp = [e](double x) {  // ∫_{-∞}^{x} of a ramp rising over [-e/2, e/2]: C¹
    if (x <= -e / 2) return 0.0;
    if (x >= e / 2) return x;
    return (x + e / 2) * (x + e / 2) / (2 * e);
  };
  return ramp(d + 0.5) - ramp(d - 0.5);
}

}  // namespace

TEST_CASE("smoothed footprint: the weights add up to the body's area, for u- and v-faces") {
  const auto cases = area_cases();
  for (const double eps : {0.5, 1.0}) {
    for (auto& c : cases) {
      SECTION(c.name + (eps == 1.0 ? ", eps 1" : ", eps 0.5")) {
        proto::BodyMeshes m;
        m.bodies.push_back(c.body);
        ImmersedSolid is(c.g, m, eps);
        proto::FaceSolid u, v;
        is.update(at_rest(m), u, v);
        CHECK(std::abs(sum_alpha_volume(FaceBoxes::u_faces(c.g), u) - c.area) <= 1e-12 * c.area);
        CHECK(std::abs(sum_alpha_volume(FaceBoxes::v_faces(c.g), v) - c.area) <= 1e-12 * c.area);
        CHECK(std::abs(is.area_u() - c.area) <= 1e-12 * c.area);
        CHECK(std::abs(is.area_v() - c.area) <= 1e-12 * c.area);
        for (double a : u.alpha) CHECK((a > 0 && a <= 1.0));
        // The weights reach a face further than its box does: more faces take part.
        ImmersedSolid box(c.g, m);
        proto::FaceSolid ub, vb;
        box.update(at_rest(m), ub, vb);
        CHECK(u.index.size() > ub.index.size());
      }
    }
  }
}

TEST_CASE("smoothed footprint: alpha at a straight edge is the weight's share below it") {
  // A block whose top edge y = y0 lies off the grid lines; faces well inside its x extent see
  // the half-plane y < y0.
  const auto g = grid(20, 20, 1.0, 1.0, false, false);
  const double h = 0.05, y0 = 0.5 + 0.37 * h;
  proto::BodyMeshes m;
  m.bodies.push_back(rectangle(0.6, 0.3, 12, 6, 0.0, {0.5, y0 - 0.15}));
  for (const double eps : {0.3, 1.0}) {
    ImmersedSolid is(g, m, eps);
    proto::FaceSolid u, v;
    is.update(at_rest(m), u, v);
    int checked = 0;
    for (int comp = 0; comp < 2; ++comp) {
      const auto faces = comp == 0 ? FaceBoxes::u_faces(g) : FaceBoxes::v_faces(g);
      const auto& fs = comp == 0 ? u : v;
      for (std::size_t k = 0; k < fs.index.size(); ++k) {
        const int i = fs.index[k] % faces.ni, j = fs.index[k] / faces.ni;
        const double xf = comp == 0 ? i * h : (i + 0.5) * h, yf = comp == 0 ? (j + 0.5) * h : j * h;
        if (xf < 0.3 || xf > 0.7 || yf < y0 - 2 * h) continue;
        const double d = (y0 - yf) / h;
        CHECK(std::abs(fs.alpha[k] - smoothed_below(d, eps)) <= 1e-13);
        if (eps == 1.0) CHECK(std::abs(fs.alpha[k] - tent_below(d)) <= 1e-13);
        ++checked;
      }
    }
    CHECK(checked >= 4 * 8);  // two rows of u-faces and two of v-faces meet the edge
  }
}

TEST_CASE("smoothed footprint: alpha at a straight edge on a stretched grid and across a seam") {
  // The weight of face j along y, from its box edges e (FaceBoxes, the box footprint's) alone:
  // 1 inside, linear ramps of half-width r_k = ε/2 min(adjacent widths) about each edge, so
  // α_j = [R(y0; e_j, r_j) − R(y0; e_{j+1}, r_{j+1})] / (e_{j+1} − e_j), R the integral of a ramp
  // from 0 to 1 over [e − r, e + r] up to y0. `wrap`: a periodic direction of length 1.
  auto expected = [](const std::vector<double>& e, int j, double y0, double eps, bool wrap) {
    const int n = static_cast<int>(e.size()) - 1;
    auto width = [&](int k) {  // box k's width, k taken around the period
      const int m = ((k % n) + n) % n;
      return e[m + 1] - e[m];
    };
    auto edge = [&](int k) {  // edge k, k in [0, n]; around the period: shifted by 1
      const int m = ((k % n) + n) % n;
      return e[m] + (k - m) / n;
    };
    auto r = [&](int k) {
      if (!wrap && (k == 0 || k == n)) return 0.0;
      return 0.5 * eps * std::min(width(k - 1), width(k));
    };
    auto R = [](double y, double c, double h) {
      if (h <= 0) return std::max(0.0, y - c);
      if (y <= c - h) return 0.0;
      if (y >= c + h) return y - c;
      return (y - c + h) * (y - c + h) / (4 * h);
    };
    // The edge nearest y0 among the copies of the face's box (a seam: y0 may lie a period away).
    double best = 0, shift = 0, dist = 1e9;
    for (double sh : wrap ? std::vector<double>{-1.0, 0.0, 1.0} : std::vector<double>{0.0}) {
      const double d = std::abs(0.5 * (edge(j) + edge(j + 1)) + sh - y0);
      if (d < dist) dist = d, shift = sh;
    }
    best = (R(y0 - shift, edge(j), r(j)) - R(y0 - shift, edge(j + 1), r(j + 1))) / width(j);
    return best;
  };
  struct Case {
    const char* name;
    proto::GridInfo g;
    double y0, y_bottom;
    bool wrap;
  };
  auto stretched = grid(20, 20, 1.0, 1.0, false, false);
  for (int j = 0; j <= 20; ++j) stretched.y_face[j] = std::pow(j / 20.0, 1.3);
  const Case cases[] = {{"stretched", stretched, 0.5531, 0.3, false},
                        {"periodic seam", grid(20, 20, 1.0, 1.0, false, true), 1.0185, 0.7, true}};
  for (const auto& c : cases) {
    SECTION(c.name) {
      proto::BodyMeshes m;
      m.bodies.push_back(rectangle(0.6, c.y0 - c.y_bottom, 12, 8, 0.0, {0.5, 0.5 * (c.y0 + c.y_bottom)}));
      const double eps = 0.7;
      ImmersedSolid is(c.g, m, eps);
      proto::FaceSolid u, v;
      is.update(at_rest(m), u, v);
      int checked = 0;
      for (int comp = 0; comp < 2; ++comp) {
        const auto faces = comp == 0 ? FaceBoxes::u_faces(c.g) : FaceBoxes::v_faces(c.g);
        const auto& fs = comp == 0 ? u : v;
        for (std::size_t k = 0; k < fs.index.size(); ++k) {
          const int i = fs.index[k] % faces.ni, j = fs.index[k] / faces.ni;
          const double xf = comp == 0 ? c.g.x_face[i] : 0.5 * (c.g.x_face[i] + c.g.x_face[i + 1]);
          if (xf < 0.3 || xf > 0.7) continue;  // whole along x: its x weight integrates to 1
          const double centre = 0.5 * (faces.ey[j] + faces.ey[j + 1]);
          double off = centre - c.y0;  // from the top edge (around the period when periodic)
          if (c.wrap) off -= std::round(off);
          if (std::abs(off) > 0.15) continue;
          INFO("face " << comp << " (" << i << ", " << j << ")");
          CHECK(std::abs(fs.alpha[k] - expected(faces.ey, j, c.y0, eps, c.wrap)) <= 1e-12);
          ++checked;
        }
      }
      CHECK(checked >= 4 * 8);
    }
  }
}

TEST_CASE("smoothed footprint: alpha is continuously differentiable as a body crosses the grid") {
  // A block slides up by h/100 per step across two cells; the second difference of a face's α
  // is at most (δ/h)²/ε (the weight's α'' is at most 1/(ε h²)), while the box's α has kinks
  // where the edge meets a box edge (a second difference of δ/h).
  const auto g = grid(20, 20, 1.0, 1.0, false, false);
  const double h = 0.05, delta = h / 100;
  proto::BodyMeshes m;
  m.bodies.push_back(rectangle(0.6, 0.3, 12, 6, 0.0, {0.5, 0.35}));
  auto alpha_of = [&](double eps, double shift, int comp) {
    auto s = at_rest(m);
    for (std::size_t k = 1; k < s.x[0].size(); k += 2) s.x[0][k] += shift;
    ImmersedSolid is(g, m, eps);
    proto::FaceSolid u, v;
    is.update(s, u, v);
    const auto faces = comp == 0 ? FaceBoxes::u_faces(g) : FaceBoxes::v_faces(g);
    const auto& fs = comp == 0 ? u : v;
    for (std::size_t k = 0; k < fs.index.size(); ++k)
      if (fs.index[k] == 10 + faces.ni * 10) return fs.alpha[k];  // the face at or near (0.5, 0.5)
    return 0.0;
  };
  for (int comp = 0; comp < 2; ++comp) {
    for (const double eps : {0.0, 0.5, 1.0}) {
      double worst = 0;
      for (int n = 1; n < 200; ++n)
        worst = std::max(worst, std::abs(alpha_of(eps, (n + 1) * delta, comp) -
                                         2 * alpha_of(eps, n * delta, comp) +
                                         alpha_of(eps, (n - 1) * delta, comp)));
      if (eps == 0.0)
        CHECK(worst >= 0.4 * delta / h);
      else
        CHECK(worst <= 1.0001 * (delta / h) * (delta / h) / eps);
    }
  }
}

TEST_CASE("smoothed footprint: the mean velocity of a linear field and action = reaction") {
  const auto g = grid(24, 20, 1.2, 1.0, false, false);
  const double h = 0.05;
  proto::BodyMeshes m;
  m.bodies.push_back(rectangle(0.5, 0.35, 9, 6, 0.41, {0.61, 0.48}));
  auto s = at_rest(m);
  const double a11 = 1.5, a12 = 0.7, a21 = -0.4, a22 = -1.1, b1 = 0.3, b2 = -0.1;
  for (std::size_t k = 0; k < s.x[0].size(); k += 2) {
    const double x = s.x[0][k], y = s.x[0][k + 1];
    s.v[0][k] = a11 * x + a12 * y + b1;
    s.v[0][k + 1] = a21 * x + a22 * y + b2;
  }
  for (const double eps : {0.5, 1.0}) {
    ImmersedSolid is(g, m, eps);
    proto::FaceSolid u, v;
    is.update(s, u, v);
    // A face whose whole weight lies in the body: the weight is symmetric about the face, so the
    // mean of a linear field over it is the field at the face.
    int inside = 0;
    for (int comp = 0; comp < 2; ++comp) {
      const auto faces = comp == 0 ? FaceBoxes::u_faces(g) : FaceBoxes::v_faces(g);
      const auto& fs = comp == 0 ? u : v;
      for (std::size_t k = 0; k < fs.index.size(); ++k) {
        if (fs.alpha[k] < 1 - 1e-12) continue;
        const int i = fs.index[k] % faces.ni, j = fs.index[k] / faces.ni;
        const double x = comp == 0 ? i * h : (i + 0.5) * h, y = comp == 0 ? (j + 0.5) * h : j * h;
        const double exact = comp == 0 ? a11 * x + a12 * y + b1 : a21 * x + a22 * y + b2;
        CHECK(std::abs(fs.velocity[k] - exact) <= 1e-12);
        ++inside;
      }
    }
    CHECK(inside > 20);
    std::mt19937 rng(3);
    const auto bal = action_plus_reaction(g, is, u, v, rng);
    CHECK(std::abs(bal.fx) <= 1e-12 * bal.scale);
    CHECK(std::abs(bal.fy) <= 1e-12 * bal.scale);
  }
}

// The faces a footprint touches are listed in index order whatever their spread: a band read off
// the marks, or a radix sort when the marks are far apart (two bodies on opposite walls).
TEST_CASE("sort_marked lists the marked faces in order, dense or spread", "[immersed]") {
  std::mt19937 rng(7);
  // (2000 and 40: one radix pass; 70000: two; 5 million: three)
  for (const int range : {50, 2000, 3000, 70000, 5000000}) {
    for (const int count : {1, 40, 2000}) {
      if (count > range) continue;
      std::vector<char> mark(static_cast<std::size_t>(range), 0);
      std::vector<std::int32_t> list;
      const std::int32_t lo = 17;
      std::uniform_int_distribution<std::int32_t> pick(0, range - 1);
      while (static_cast<int>(list.size()) < count) {
        const std::int32_t k = pick(rng);
        if (!mark[k]) mark[k] = 1, list.push_back(lo + k);
      }
      std::vector<std::int32_t> expected = list;
      std::sort(expected.begin(), expected.end());
      const std::int32_t hi = expected.back();
      sort_marked(list, expected.front(), hi, [&](std::int32_t k) { return mark[k - lo] != 0; });
      INFO("range " << range << ", " << count << " marks");
      CHECK(list == expected);
    }
  }
}
