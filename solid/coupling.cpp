// The coupling hook: body geometry for the coupler, surface points for fiber roots, and point
// loads (force + moment) turned into equivalent nodal forces on a surface edge.
#include "coupling.hpp"

#include <cmath>

#include "error.hpp"

namespace solid {

std::array<Vec2, 2> point_load_on_edge(const Vec2& xa, const Vec2& xb, double s, const Vec2& force,
                                       double moment) {
  const double ex = xb[0] - xa[0], ey = xb[1] - xa[1];
  const double l2 = ex * ex + ey * ey;
  // (xa - xb) x c = M with c perpendicular to the edge.
  const double k = -moment / l2;
  const Vec2 c{-k * ey, k * ex};
  return {Vec2{(1 - s) * force[0] + c[0], (1 - s) * force[1] + c[1]},
          Vec2{s * force[0] - c[0], s * force[1] - c[1]}};
}

BodyGeometry CouplingHook::geometry(int body) const {
  const Mesh& m = m_solver.mesh(body);
  BodyGeometry g;
  const auto& spec = m_solver.model().bodies.at(body);
  g.name = spec.name;
  g.kind = spec.kind;
  const auto& mo = spec.motion;
  g.moving =
      spec.kind == BodyKind::rigid &&
      (mo.velocity[0] != 0 || mo.velocity[1] != 0 || mo.omega != 0 ||
       ((mo.amplitude[0] != 0 || mo.amplitude[1] != 0 || mo.angle != 0) && mo.frequency != 0));
  g.x_ref = m.x;
  g.triangles = m.triangles;
  g.surface = m.surface;
  return g;
}

SurfacePoint CouplingHook::surface_point(int body, int edge, double s) const {
  if (body < 0 || body >= num_bodies()) fsi::fail("surface point: no body {}", body);
  const Mesh& m = m_solver.mesh(body);
  if (edge < 0 || edge >= static_cast<int>(m.surface.size()))
    fsi::fail("surface point: body '{}' has {} surface edges, asked for edge {}",
              m_solver.model().bodies[body].name, m.surface.size(), edge);
  if (!(s >= 0 && s <= 1)) fsi::fail("surface point: parameter {} is outside [0, 1]", s);
  const auto& e = m.surface[edge];
  const auto& x = m_solver.positions(body);
  const double ax = x[2 * e[0]], ay = x[2 * e[0] + 1];
  const double ex = x[2 * e[1]] - ax, ey = x[2 * e[1] + 1] - ay;
  const double l = std::hypot(ex, ey);
  SurfacePoint p;
  p.position = {ax + s * ex, ay + s * ey};
  p.normal = {ey / l, -ex / l};
  p.nodes = e;
  return p;
}

void CouplingHook::add_point_load(int body, int edge, double s, const Vec2& force, double moment,
                                  std::vector<double>& nodal) const {
  const SurfacePoint p = surface_point(body, edge, s);
  const auto& x = m_solver.positions(body);
  if (nodal.empty()) nodal.assign(x.size(), 0.0);
  if (nodal.size() != x.size())
    fsi::fail("point load: nodal force vector has {} values, expected {}", nodal.size(),
              x.size());
  const int a = p.nodes[0], b = p.nodes[1];
  const auto f =
      point_load_on_edge({x[2 * a], x[2 * a + 1]}, {x[2 * b], x[2 * b + 1]}, s, force, moment);
  for (int i = 0; i < 2; ++i) {
    nodal[2 * a + i] += f[0][i];
    nodal[2 * b + i] += f[1][i];
  }
}

}  // namespace solid
