// What the current state gives for output: energies, per-element det F and von Mises stress,
// the contact forces and pressure, the support reactions.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

double Solver::kinetic_energy() const {
  double k = 0;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
      const auto& t = B.spec.mesh.triangles[e];
      double me[3][3];
      element_mass(B.geo[e].area, me);
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c)
          for (int i = 0; i < 2; ++i)
            k += 0.5 * B.rho_inertia[e] * me[a][c] * B.v[2 * t[a] + i] * B.v[2 * t[c] + i];
    }
  }
  return k;
}

double Solver::strain_energy() const {
  double w = 0;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
      const auto& t = B.spec.mesh.triangles[e];
      const Eigen::Matrix2d H =
          displacement_gradient(B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]], &B.u[2 * t[2]]);
      w += B.geo[e].area * evaluate_material(B.spec.materials[B.material[e]], H, nullptr, nullptr);
    }
  }
  return w;
}

bool Solver::massless(int b, std::size_t d) const {
  const Body& B = *m_bodies[b];
  return B.is_elastic() && d < B.mass_row.size() && !(B.mass_row[d] > 0);
}

double Solver::load_potential() const {
  double p = 0;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    const auto f =
        scene_loads(B.index, m_model.settings.analysis == Analysis::statics ? 1.0 : m_time);
    for (std::size_t d = 0; d < f.size(); ++d) p -= f[d] * B.u[d];
  }
  return p;
}

std::vector<double> Solver::element_det_f(int b) const {
  const Body& B = *m_bodies[b];
  std::vector<double> out(B.spec.mesh.num_triangles(), 1.0);
  if (!B.is_elastic()) return out;
  for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
    const auto& t = B.spec.mesh.triangles[e];
    const Eigen::Matrix2d H =
        displacement_gradient(B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]], &B.u[2 * t[2]]);
    out[e] = 1 + H.trace() + H.determinant();
  }
  return out;
}

std::vector<double> Solver::element_von_mises(int b) const {
  const Body& B = *m_bodies[b];
  std::vector<double> out(B.spec.mesh.num_triangles(), 0.0);
  if (!B.is_elastic()) return out;
  for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
    const auto& t = B.spec.mesh.triangles[e];
    const Eigen::Matrix2d H =
        displacement_gradient(B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]], &B.u[2 * t[2]]);
    out[e] = von_mises(cauchy_stress(B.spec.materials[B.material[e]], H));
  }
  return out;
}

const std::vector<double>& Solver::contact_forces(int b) const {
  return m_bodies[b]->contact;
}

std::vector<double> Solver::contact_pressure(int b) const {
  const Body& B = *m_bodies[b];
  const Mesh& mesh = B.spec.mesh;
  std::vector<double> length(mesh.num_nodes(), 0.0), p(mesh.num_nodes(), 0.0);
  for (const auto& e : mesh.surface) {
    const double l =
        std::hypot(B.x[2 * e[1]] - B.x[2 * e[0]], B.x[2 * e[1] + 1] - B.x[2 * e[0] + 1]);
    length[e[0]] += l / 2;
    length[e[1]] += l / 2;
  }
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (length[n] > 0) p[n] = std::hypot(B.contact[2 * n], B.contact[2 * n + 1]) / length[n];
  return p;
}

Vec2 Solver::total_contact_force(int b) const {
  Vec2 f{0, 0};
  const auto& c = m_bodies[b]->contact;
  for (std::size_t d = 0; d < c.size(); ++d) f[d % 2] += c[d];
  return f;
}

Vec2 Solver::contact_force_from_bodies(int b) const { return m_bodies[b]->contact_bodies; }

double Solver::min_contact_gap() const {
  double g = std::numeric_limits<double>::infinity();
  for (const auto& s : m_contact.slots()) g = std::min(g, s.gap);
  return g;
}

Vec2 Solver::reaction(int b, const std::string& boundary) const {
  const Body& B = *m_bodies[b];
  if (!B.spec.mesh.has_boundary(boundary))
    fsi::fail("body '{}' has no boundary '{}'", B.spec.name, boundary);
  Vec2 f{0, 0};
  for (int n : B.spec.mesh.boundary_nodes(boundary))
    for (int i = 0; i < 2; ++i)
      if (B.eq[2 * n + i] < 0) f[i] -= B.r[2 * n + i] + B.contact[2 * n + i];
  return f;
}

}  // namespace solid
