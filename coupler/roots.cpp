// Fibers rooted on bodies (paper Sec. 3.2.3): where each root sits on its body's surface, the
// root pose the fiber is clamped to, and the fiber's root load carried to the body's nodes.
#include <algorithm>
#include <cmath>

#include "coupler.hpp"

namespace coupler {

namespace {

// A root is on the surface when it lies within this fraction of the nearest edge's length.
constexpr double kOnSurface = 1e-3;

}  // namespace

// Attached fibers: the body by name, and the surface edge nearest to the root's reference point.
void Coupler::resolve_roots() {
  const auto& bodies = m_meshes.bodies;
  m_roots.assign(m_layout.fibers.size(), Root{});
  for (std::size_t k = 0; k < m_layout.fibers.size(); ++k) {
    const auto& f = m_layout.fibers[k];
    if (f.root != 1) continue;
    auto it =
        std::find_if(bodies.begin(), bodies.end(), [&](const auto& b) { return b.name == f.body; });
    if (it == bodies.end())
      throw fsi::InputError(fmt::format(
          "fiber '{}' is rooted on body '{}', which the scene does not have (bodies: {}) (in {})",
          f.name, f.body, body_names(), m_rt.scene().file().string()));
    const auto& b = *it;
    Root r;
    r.body = static_cast<int>(it - bodies.begin());
    double best = kFar, best_len = 0;
    for (std::size_t e = 0; e + 1 < b.edges.size(); e += 2) {
      const int a = b.edges[e], c = b.edges[e + 1];
      const double ax = b.x_ref[2 * a], ay = b.x_ref[2 * a + 1];
      const double dx = b.x_ref[2 * c] - ax, dy = b.x_ref[2 * c + 1] - ay;
      const double len2 = dx * dx + dy * dy;
      const double s = std::clamp(((f.root_x - ax) * dx + (f.root_y - ay) * dy) / len2, 0.0, 1.0);
      const double d = std::hypot(ax + s * dx - f.root_x, ay + s * dy - f.root_y);
      if (d < best) best = d, best_len = std::sqrt(len2), r.a = a, r.b = c, r.s = s;
    }
    if (b.edges.empty() || best > kOnSurface * best_len)
      throw fsi::InputError(fmt::format(
          "fiber '{}': its root ({}, {}) is not on the surface of body '{}' (nearest surface point "
          "{:.3g} away) (in {})",
          f.name, f.root_x, f.root_y, f.body, best, m_rt.scene().file().string()));
    m_roots[k] = r;
  }
}

// Root pose of each attached fiber from a solid state: the material point at s along its edge,
// and the edge's outward normal (the body lies on the left of a -> b):
//   p = x_a + s (x_b − x_a),  d = (t_y, −t_x),  t = (x_b − x_a) / |x_b − x_a|.
void Coupler::root_poses(const proto::SolidState& state,
                         std::vector<std::vector<double>>& poses) const {
  poses.assign(m_layout.fibers.size(), {});
  for (std::size_t k = 0; k < m_roots.size(); ++k) {
    const Root& r = m_roots[k];
    if (r.body < 0) continue;
    const auto& x = state.x[r.body];
    const double ax = x[2 * r.a], ay = x[2 * r.a + 1], dx = x[2 * r.b] - ax,
                 dy = x[2 * r.b + 1] - ay;
    const double len = std::hypot(dx, dy);
    poses[k] = {ax + r.s * dx, ay + r.s * dy, dy / len, -dx / len};
  }
}

// The fiber's load on its support (force F, moment M at the root point p) as equivalent nodal
// forces on the edge a -> b that holds it (paper Sec. 3.2.3, Fig. 2):
//   f_a = (1 − s) F' − q n,  f_b = s F' + q n,  n = (−t_y, t_x), q = M / L,
// with t the edge's unit tangent and L its length: the resultant is F', and the moment about p is
// (1 − s)(x_a − p) × F' + s (x_b − p) × F' + q (x_b − x_a) × n = 0 + q L = M, exactly.
// The fiber's inertia goes to the solid implicitly: the fiber reports its load's response to the
// root's acceleration, F ~ F_0 − m a (m = root_mass), and the acceleration a* it took F at. The
// solid gets F' = F + m a* (the load without that inertia) and the root mass lumped on the edge's
// nodes, (1 − s) m at a and s m at b, to which it adds −m a^(n+1) with its own acceleration of the
// step (PROTOCOL.md, "Fiber roots"). Sent one step late, the inertia −m a* alone is stable only
// while m is small against the nodes' mass (the root's acceleration grows by −m / m_node per step).
void Coupler::add_root_loads(const proto::SolidState& state) {
  for (auto& m : m_solid_in.root_mass) m.clear();
  const std::vector<double> load = root_loads_without_inertia();
  for (std::size_t k = 0; k < m_roots.size(); ++k) {
    const Root& r = m_roots[k];
    if (r.body < 0 || load.size() < 3 * (k + 1)) continue;
    if (m_meshes.bodies[r.body].kind != proto::BodyKind::elastic) continue;
    const double fx = load[3 * k], fy = load[3 * k + 1], M = load[3 * k + 2];
    const auto& x = state.x[r.body];
    const double dx = x[2 * r.b] - x[2 * r.a], dy = x[2 * r.b + 1] - x[2 * r.a + 1];
    const double len = std::hypot(dx, dy);
    const double q = M / len, nx = -dy / len, ny = dx / len;
    auto& f = m_solid_in.force[r.body];
    if (f.empty()) f.assign(x.size(), 0.0);
    f[2 * r.a] += (1 - r.s) * fx - q * nx;
    f[2 * r.a + 1] += (1 - r.s) * fy - q * ny;
    f[2 * r.b] += r.s * fx + q * nx;
    f[2 * r.b + 1] += r.s * fy + q * ny;
    if (m_fiber.root_mass.size() < 3 * (k + 1)) continue;
    if (m_solid_in.root_mass.size() < m_meshes.bodies.size())
      m_solid_in.root_mass.resize(m_meshes.bodies.size());
    auto& m = m_solid_in.root_mass[r.body];
    if (m.empty()) m.assign(3 * (x.size() / 2), 0.0);
    for (const auto& [node, w] : {std::pair{r.a, 1 - r.s}, std::pair{r.b, r.s}})
      for (int i = 0; i < 3; ++i) m[3 * node + i] += w * m_fiber.root_mass[3 * k + i];
  }
}

// F' = F + m a* per fiber (3 values: force, moment), F the fiber's root load; F where the fiber
// sent no root mass.
std::vector<double> Coupler::root_loads_without_inertia() const {
  std::vector<double> load = m_fiber.root_load;
  const auto& m = m_fiber.root_mass;
  const auto& a = m_fiber.root_accel;
  for (std::size_t k = 0; 3 * k + 2 < load.size(); ++k) {
    if (m.size() < 3 * (k + 1) || a.size() < 2 * (k + 1)) continue;
    load[3 * k] += m[3 * k] * a[2 * k] + m[3 * k + 1] * a[2 * k + 1];
    load[3 * k + 1] += m[3 * k + 1] * a[2 * k] + m[3 * k + 2] * a[2 * k + 1];
  }
  return load;
}

}  // namespace coupler
