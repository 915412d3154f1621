// Prescribed motion: the time profiles of loads and constraints, the prescribed displacements
// (set at once, or as the pending increment the first Newton iteration carries), and the
// positions and velocities of rigid bodies.
#include <algorithm>
#include <cmath>

#include "solver_body.hpp"

namespace solid {

namespace {

constexpr double kTwoPi = 6.283185307179586;

}  // namespace

double TimeFunction::operator()(double t) const {
  switch (kind) {
    case Kind::constant:
      return 1.0;
    case Kind::ramp:
      return ramp_time > 0 ? std::clamp(t / ramp_time, 0.0, 1.0) : 1.0;
    case Kind::sine:
      return std::sin(kTwoPi * frequency * t + phase);
  }
  return 1.0;
}

void Solver::update_prescribed(double t) {
  const bool statics = m_model.settings.analysis == Analysis::statics;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (const auto& p : B.prescribed) {
      if (p.constraint < 0) continue;
      const auto& con = B.spec.constraints[p.constraint];
      double u = 0;
      if (con.type == Constraint::Type::displacement)
        u = con.displacement[p.component] * (statics ? t : con.time(t));
      B.u[p.dof] = u;
    }
    for (const auto& p : B.prescribed)
      if (p.follow >= 0) B.u[p.dof] = B.u[p.follow];
    B.sync_positions();
  }
}

// The prescribed displacements at t (or load factor) become a pending increment: the first
// Newton iteration carries it through the linearised system, K_ff du_f = R_f - K_fp du_p, so
// that the free nodes follow the moved boundary instead of meeting it as a jump (which can
// invert the elements next to it).
bool Solver::prepare_prescribed(double t) {
  const bool statics = m_model.settings.analysis == Analysis::statics;
  bool any = false;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    B.dirichlet_step.assign(B.u.size(), 0.0);
    if (!B.is_elastic()) continue;
    std::vector<double> target(B.u);
    for (const auto& p : B.prescribed) {
      if (p.constraint < 0) continue;
      const auto& con = B.spec.constraints[p.constraint];
      target[p.dof] = con.type == Constraint::Type::displacement
                          ? con.displacement[p.component] * (statics ? t : con.time(t))
                          : 0.0;
    }
    for (const auto& p : B.prescribed)
      if (p.follow >= 0) target[p.dof] = target[p.follow];
    for (const auto& p : B.prescribed) {
      B.dirichlet_step[p.dof] = target[p.dof] - B.u[p.dof];
      if (B.dirichlet_step[p.dof] != 0) any = true;
    }
  }
  m_dirichlet_pending = any;
  return any;
}

void Solver::apply_prescribed_step() {
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (const auto& p : B.prescribed) B.u[p.dof] += B.dirichlet_step[p.dof];
    B.sync_positions();
  }
  m_dirichlet_pending = false;
}

void Solver::update_rigid(double t) {
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (B.is_elastic()) continue;
    const RigidMotion& m = B.spec.motion;
    const double w = kTwoPi * m.frequency;
    const double s = std::sin(w * t + m.phase), c = std::cos(w * t + m.phase);
    const double theta = m.omega * t + m.angle * s;
    const double dtheta = m.omega + m.angle * w * c;
    const double ct = std::cos(theta), st = std::sin(theta);
    for (int n = 0; n < B.spec.mesh.num_nodes(); ++n) {
      const double rx = B.X[2 * n] - m.center[0], ry = B.X[2 * n + 1] - m.center[1];
      const double qx = ct * rx - st * ry, qy = st * rx + ct * ry;
      B.x[2 * n] = m.center[0] + m.velocity[0] * t + m.amplitude[0] * s + qx;
      B.x[2 * n + 1] = m.center[1] + m.velocity[1] * t + m.amplitude[1] * s + qy;
      B.v[2 * n] = m.velocity[0] + m.amplitude[0] * w * c - dtheta * qy;
      B.v[2 * n + 1] = m.velocity[1] + m.amplitude[1] * w * c + dtheta * qx;
      B.u[2 * n] = B.x[2 * n] - B.X[2 * n];
      B.u[2 * n + 1] = B.x[2 * n + 1] - B.X[2 * n + 1];
    }
  }
}

}  // namespace solid
