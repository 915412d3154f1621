// Surface probes: wall shear stress at material points of the bodies' surfaces from fluid
// samples taken outside the body (the method: surface.hpp).
#include "surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "error.hpp"

namespace coupler {

namespace {

// A probe's point is on the surface when it lies within this fraction of the nearest edge's
// length (as a fiber root, roots.cpp).
constexpr double kOnSurface = 1e-3;

// Index k0 of the node at or below x and the weight w of node k0 + 1 (k1, wrapped on a periodic
// axis); outside a bounded axis the end node (w = 0): a point within half a cell of a domain
// wall takes the nearest row's value.
void bracket(const std::vector<double>& c, double period, double x, int& k0, int& k1, double& w) {
  const int m = static_cast<int>(c.size());
  if (period > 0) {
    x = c[0] + std::fmod(std::fmod(x - c[0], period) + period, period);
    auto it = std::upper_bound(c.begin(), c.end(), x);
    k0 = static_cast<int>(it - c.begin()) - 1;
    k1 = (k0 + 1) % m;
    const double next = k0 + 1 < m ? c[k0 + 1] : c[0] + period;
    w = (x - c[k0]) / (next - c[k0]);
    return;
  }
  if (x <= c[0]) {
    k0 = k1 = 0, w = 0;
    return;
  }
  if (x >= c[m - 1]) {
    k0 = k1 = m - 1, w = 0;
    return;
  }
  auto it = std::upper_bound(c.begin(), c.end(), x);
  k0 = static_cast<int>(it - c.begin()) - 1;
  k1 = k0 + 1;
  w = (x - c[k0]) / (c[k1] - c[k0]);
}

// The width of the cell of `faces` that holds x (the end cell outside).
double local_width(const std::vector<double>& faces, double period, double x) {
  const int n = static_cast<int>(faces.size()) - 1;
  if (period > 0) x = faces[0] + std::fmod(std::fmod(x - faces[0], period) + period, period);
  auto it = std::upper_bound(faces.begin(), faces.end(), x);
  const int i = std::clamp(static_cast<int>(it - faces.begin()) - 1, 0, n - 1);
  return faces[i + 1] - faces[i];
}

}  // namespace

SurfaceProbes::SurfaceProbes(const proto::GridInfo& g, const proto::BodyMeshes& meshes,
                             std::vector<SurfaceProbeSpec> specs, double viscosity,
                             const std::string& source)
    : m_mu(viscosity), m_xf(g.x_face), m_yf(g.y_face) {
  const auto& bodies = meshes.bodies;
  std::vector<std::string> names;
  for (const auto& b : bodies) names.push_back(b.name);
  const std::string known = names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
  for (std::size_t k = 0; k < specs.size(); ++k) {
    const auto& sp = specs[k];
    const std::string key = fmt::format("coupler.surface_probe[{}] (name '{}')", k, sp.name);
    for (std::size_t q = 0; q < k; ++q)
      if (specs[q].name == sp.name)
        throw fsi::InputError(fmt::format("{}: the name is used by coupler.surface_probe[{}] too "
                                          "(in {})", key, q, source));
    int only = -1;
    if (!sp.body.empty()) {
      auto it = std::find(names.begin(), names.end(), sp.body);
      if (it == names.end())
        throw fsi::InputError(fmt::format("{}: body = '{}' is not a body of the scene (bodies: "
                                          "{}) (in {})", key, sp.body, known, source));
      only = static_cast<int>(it - names.begin());
    }
    Probe p{sp};
    double best = std::numeric_limits<double>::infinity(), best_len = 0, bx = 0, by = 0;
    for (std::size_t bi = 0; bi < bodies.size(); ++bi) {
      if (only >= 0 && static_cast<int>(bi) != only) continue;
      const auto& b = bodies[bi];
      for (std::size_t e = 0; e + 1 < b.edges.size(); e += 2) {
        const int a = b.edges[e], c = b.edges[e + 1];
        const double ax = b.x_ref[2 * a], ay = b.x_ref[2 * a + 1];
        const double dx = b.x_ref[2 * c] - ax, dy = b.x_ref[2 * c + 1] - ay;
        const double len2 = dx * dx + dy * dy;
        const double s =
            std::clamp(((sp.point[0] - ax) * dx + (sp.point[1] - ay) * dy) / len2, 0.0, 1.0);
        const double d = std::hypot(ax + s * dx - sp.point[0], ay + s * dy - sp.point[1]);
        if (d < best)
          best = d, best_len = std::sqrt(len2), p.body = static_cast<int>(bi), p.a = a, p.b = c,
          p.s = s, bx = ax + s * dx, by = ay + s * dy;
      }
    }
    if (!std::isfinite(best))
      throw fsi::InputError(fmt::format("{}: the scene has no body surface to put it on (bodies: "
                                        "{}) (in {})", key, known, source));
    if (best > kOnSurface * best_len)
      throw fsi::InputError(fmt::format(
          "{}: point = [{}, {}] is not on the surface of {} '{}' (its nearest surface point "
          "({:.6g}, {:.6g}) is {:.3g} away; the tolerance is {:g} of that edge's length, {:.3g}) "
          "(in {})",
          key, sp.point[0], sp.point[1], only >= 0 ? "body" : "any body: the nearest is",
          names[p.body], bx, by, best, kOnSurface, kOnSurface * best_len, source));
    m_probes.push_back(p);
  }
  // u-faces at (x_face[i], y_centre[j]), v-faces at (x_centre[i], y_face[j]); a periodic
  // direction has nx (ny) faces and wraps with the domain's length.
  const double lx = g.x_face.back() - g.x_face.front(), ly = g.y_face.back() - g.y_face.front();
  std::vector<double> xc, yc;
  for (int i = 0; i < g.nx; ++i) xc.push_back(0.5 * (g.x_face[i] + g.x_face[i + 1]));
  for (int j = 0; j < g.ny; ++j) yc.push_back(0.5 * (g.y_face[j] + g.y_face[j + 1]));
  m_u.x.c.assign(g.x_face.begin(), g.x_face.end() - (g.periodic_x ? 1 : 0));
  m_u.y.c = yc;
  m_v.x.c = xc;
  m_v.y.c.assign(g.y_face.begin(), g.y_face.end() - (g.periodic_y ? 1 : 0));
  m_p.x.c = xc;  // cells: i + nx j, at (x_centre[i], y_centre[j])
  m_p.y.c = yc;
  for (Family* f : {&m_u, &m_v, &m_p}) {
    f->x.period = g.periodic_x ? lx : 0;
    f->y.period = g.periodic_y ? ly : 0;
    f->value.assign(f->x.c.size() * f->y.c.size(), 0.0);
    f->has.assign(f->value.size(), 0);
  }
}

std::vector<std::string> SurfaceProbes::columns() const {
  std::vector<std::string> cols;
  for (const auto& p : m_probes)
    for (const char* q : {"x", "y", "nx", "ny", "tau", "slip", "p"})
      cols.push_back(fmt::format("{}.{}", p.spec.name, q));
  return cols;
}

SurfaceProbes::Frame SurfaceProbes::frame(const Probe& p, const proto::SolidState& st) const {
  const auto& x = st.x[p.body];
  const auto& v = st.v[p.body];
  const double ax = x[2 * p.a], ay = x[2 * p.a + 1], bx = x[2 * p.b], by = x[2 * p.b + 1];
  const double len = std::hypot(bx - ax, by - ay);
  const double ex = (bx - ax) / len, ey = (by - ay) / len;
  Frame f;
  f.px = ax + p.s * (bx - ax), f.py = ay + p.s * (by - ay);
  f.nx = ey, f.ny = -ex;  // outward: the body lies on the left of a -> b
  const double tx = f.ny, ty = -f.nx;
  const double lx = m_u.x.period, ly = m_v.y.period;
  f.h = std::max(local_width(m_xf, lx, f.px), local_width(m_yf, ly, f.py));
  double vx = 0, vy = 0, dvx = 0, dvy = 0;
  if (!v.empty()) {
    vx = (1 - p.s) * v[2 * p.a] + p.s * v[2 * p.b];
    vy = (1 - p.s) * v[2 * p.a + 1] + p.s * v[2 * p.b + 1];
    dvx = v[2 * p.b] - v[2 * p.a], dvy = v[2 * p.b + 1] - v[2 * p.a + 1];
  }
  f.vt = vx * tx + vy * ty;
  // d/dt = −d/de along the edge (t = −e): the linear FE velocity's derivative.
  f.dvn_dt = -(dvx * f.nx + dvy * f.ny) / len;
  return f;
}

void SurfaceProbes::stencil(const Family& f, double x, double y, std::int32_t idx[4],
                            double w[4]) const {
  int i0, i1, j0, j1;
  double wx, wy;
  bracket(f.x.c, f.x.period, x, i0, i1, wx);
  bracket(f.y.c, f.y.period, y, j0, j1, wy);
  const int ni = static_cast<int>(f.x.c.size());
  idx[0] = i0 + ni * j0, w[0] = (1 - wx) * (1 - wy);
  idx[1] = i1 + ni * j0, w[1] = wx * (1 - wy);
  idx[2] = i0 + ni * j1, w[2] = (1 - wx) * wy;
  idx[3] = i1 + ni * j1, w[3] = wx * wy;
}

double SurfaceProbes::interpolate(const Family& f, double x, double y) const {
  std::int32_t idx[4];
  double w[4];
  stencil(f, x, y, idx, w);
  double s = 0;
  for (int k = 0; k < 4; ++k) {
    if (w[k] == 0) continue;
    if (!f.has[idx[k]])
      fsi::fail("surface probe: face or cell {} of its stencil at ({}, {}) was not sampled by "
                "the fluid (internal: the request was not sent)",
                idx[k], x, y);
    s += w[k] * f.value[idx[k]];
  }
  return s;
}

void SurfaceProbes::add_requests(const proto::SolidState& st, std::vector<std::int32_t>& u_faces,
                                 std::vector<std::int32_t>& v_faces,
                                 std::vector<std::int32_t>& p_cells) {
  for (auto [f, out] :
       {std::pair{&m_u, &u_faces}, std::pair{&m_v, &v_faces}, std::pair{&m_p, &p_cells}}) {
    m_scratch.clear();
    const int points = f == &m_p ? 2 : kPoints;
    for (const auto& p : m_probes) {
      const Frame fr = frame(p, st);
      for (int k = 0; k < points; ++k) {
        const double d = (kFirst + k) * fr.h;
        std::int32_t idx[4];
        double w[4];
        stencil(*f, fr.px + d * fr.nx, fr.py + d * fr.ny, idx, w);
        m_scratch.insert(m_scratch.end(), idx, idx + 4);
      }
    }
    std::sort(m_scratch.begin(), m_scratch.end());
    std::vector<std::int32_t> merged;
    std::set_union(out->begin(), out->end(), m_scratch.begin(), m_scratch.end(),
                   std::back_inserter(merged));
    merged.erase(std::unique(merged.begin(), merged.end()), merged.end());
    *out = std::move(merged);
  }
}

void SurfaceProbes::evaluate(const proto::SolidState& st, const std::vector<std::int32_t>& u_faces,
                             const std::vector<double>& u,
                             const std::vector<std::int32_t>& v_faces,
                             const std::vector<double>& v,
                             const std::vector<std::int32_t>& p_cells,
                             const std::vector<double>& p, std::vector<double>& row) {
  for (auto [f, idx, val] : {std::tuple{&m_u, &u_faces, &u}, std::tuple{&m_v, &v_faces, &v},
                             std::tuple{&m_p, &p_cells, &p}}) {
    if (idx->size() != val->size())
      fsi::fail("protocol error: {} samples for {} faces or cells", val->size(), idx->size());
    std::fill(f->has.begin(), f->has.end(), 0);
    for (std::size_t k = 0; k < idx->size(); ++k) {
      f->value[(*idx)[k]] = (*val)[k];
      f->has[(*idx)[k]] = 1;
    }
  }
  row.resize(kColumns * m_probes.size());
  for (std::size_t q = 0; q < m_probes.size(); ++q) {
    const Frame fr = frame(m_probes[q], st);
    const double tx = fr.ny, ty = -fr.nx;
    // The parabola through (d_k, f_k), d_k = (kFirst + k) h: its value and slope at d = 0 are
    // sum_k L_k(0) f_k and sum_k L_k'(0) f_k (Lagrange basis of the nodes d_k).
    double d[kPoints], fk[kPoints];
    for (int k = 0; k < kPoints; ++k) {
      d[k] = (kFirst + k) * fr.h;
      const double x = fr.px + d[k] * fr.nx, y = fr.py + d[k] * fr.ny;
      fk[k] = interpolate(m_u, x, y) * tx + interpolate(m_v, x, y) * ty;
    }
    double value = 0, slope = 0;
    for (int k = 0; k < kPoints; ++k) {
      double l = 1, dl = 0, denom = 1;
      for (int m = 0; m < kPoints; ++m) {
        if (m == k) continue;
        denom *= d[k] - d[m];
        l *= -d[m];
      }
      for (int m = 0; m < kPoints; ++m) {  // L_k'(0) = sum_m prod_{r != k, m} (−d_r) / denom
        if (m == k) continue;
        double prod = 1;
        for (int r = 0; r < kPoints; ++r)
          if (r != k && r != m) prod *= -d[r];
        dl += prod;
      }
      value += l / denom * fk[k];
      slope += dl / denom * fk[k];
    }
    double* out = &row[kColumns * q];
    out[0] = fr.px, out[1] = fr.py, out[2] = fr.nx, out[3] = fr.ny;
    out[4] = m_mu * (slope + fr.dvn_dt);
    out[5] = value - fr.vt;
    const double p0 = interpolate(m_p, fr.px + d[0] * fr.nx, fr.py + d[0] * fr.ny);
    const double p1 = interpolate(m_p, fr.px + d[1] * fr.nx, fr.py + d[1] * fr.ny);
    out[6] = (d[1] * p0 - d[0] * p1) / (d[1] - d[0]);
  }
}

}  // namespace coupler
