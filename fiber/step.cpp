// One time step of the fiber system (Huang, Shin & Sung 2007, as in the paper's Sec. 3.1.3):
// repulsion at X^n, explicit forces and the predictor, the tension equation (tension.cpp), the
// position update, the loads on the supports, and the health checks. Sub-steps split a scene
// time step when the explicit bending limit asks for it.
#include <fmt/format.h>

#include <Eigen/Eigenvalues>

#include <chrono>
#include <cmath>

#include "error.hpp"
#include "system.hpp"

namespace fiber {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Vec2 at(std::span<const double> x, std::size_t i) { return {x[2 * i], x[2 * i + 1]}; }

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

void FiberSystem::advance(double dt, std::span<const double> external_force,
                          std::span<const EndPose> root_poses) {
  if (!(dt > 0)) fsi::fail("FiberSystem::advance() needs dt > 0, got {}", dt);
  if (!external_force.empty() && external_force.size() != m_x.size())
    fsi::fail("FiberSystem::advance(): the external force has {} values, expected 2 per marker = {}", external_force.size(),
              m_x.size());
  if (const std::string problem = time_step_problem(m_config, dt); !problem.empty())
    throw fsi::Error(problem);
  for (int k = 0; k < fiber_count(); ++k) {
    if (m_config.fibers[k].root.kind != EndKind::attached) continue;
    Fiber& s = m_fibers[k];
    if (root_poses.empty()) {
      s.root_pose_new = s.root_pose_old;
      continue;
    }
    if (static_cast<int>(root_poses.size()) != fiber_count())
      fsi::fail("FiberSystem::advance(): {} root poses handed in, expected one per fiber ({})", root_poses.size(), fiber_count());
    const EndPose& p = root_poses[k];
    const double len = p.direction.norm();
    if (!(len > 0) || !std::isfinite(len) || !p.position.allFinite())
      fsi::fail("fiber '{}': invalid root pose ({}, {}) direction ({}, {}) at t = {}", m_config.fibers[k].name,
                p.position.x(), p.position.y(), p.direction.x(), p.direction.y(), m_time + dt);
    s.root_pose_new = {p.position, p.direction / len};
  }

  std::copy(m_x.begin(), m_x.end(), m_x_step_old.begin());
  for (auto& l : m_root_acc) l = EndLoad{};
  for (auto& l : m_tip_acc) l = EndLoad{};
  const int m = m_config.substeps;
  const double h = dt / m;
  for (int q = 0; q < m; ++q) substep(h, m_time + (q + 1) * h, double(q + 1) / m, external_force);

  for (int k = 0; k < fiber_count(); ++k) {
    Fiber& s = m_fibers[k];
    s.root_load = {m_root_acc[k].force / m, m_root_acc[k].moment / m, m_root_acc[k].mass / m,
                   m_root_acc[k].accel / m};
    s.tip_load = {m_tip_acc[k].force / m, m_tip_acc[k].moment / m};
    s.root_pose_old = s.root_pose_new;
  }
  m_time += dt;
  ++m_steps;
  ++m_times.steps;
}

void FiberSystem::substep(double h, double t_new, double pose_weight, std::span<const double> external_force) {
  auto t0 = Clock::now();
  // The first step starts from rest: X^(-1) = X^0 for markers that follow the equation of
  // motion, and theta = 1/2 makes X^1 = X^0 + h^2/2 a^0. Law-driven markers get X^(-1) from
  // their law, so their acceleration (which enters the end loads) is right from the start.
  const bool is_first = m_substeps_done == 0;
  const double theta = is_first ? 0.5 : 1.0;
  if (is_first) {
    const double t_old = t_new - 2 * h;
    for (int k = 0; k < fiber_count(); ++k) {
      const Fiber& s = m_fibers[k];
      if (s.is_prescribed) {
        prescribe(k, t_old, std::span<double>(m_x_old.data() + 2 * s.offset, 2 * (s.segments + 1)));
        continue;
      }
      for (int e = 0; e < 2; ++e) {
        const EndLaw& law = e == 0 ? m_config.fibers[k].root : m_config.fibers[k].tip;
        if (law.kind != EndKind::clamped && law.kind != EndKind::hinged) continue;
        const std::size_t i = s.offset + (e == 0 ? 0 : s.segments);
        const Vec2 p = law.position_at(t_old);
        m_x_old[2 * i] = p.x();
        m_x_old[2 * i + 1] = p.y();
      }
    }
  }

  repulsion_forces();
  for (int k = 0; k < fiber_count(); ++k) {
    const Fiber& s = m_fibers[k];
    if (s.is_prescribed)
      prescribe(k, t_new, std::span<double>(m_x_new.data() + 2 * s.offset, 2 * (s.segments + 1)));
    else
      predict(k, h, theta, t_new, pose_weight, external_force);
  }
  m_times.forces += seconds_since(t0);

  t0 = Clock::now();
  for (int k = 0; k < fiber_count(); ++k)
    if (!m_fibers[k].is_prescribed) solve_tension(k);
  m_times.tension += seconds_since(t0);

  t0 = Clock::now();
  for (int k = 0; k < fiber_count(); ++k) {
    if (m_fibers[k].is_prescribed)
      prescribed_load(k, h, external_force);
    else
      end_loads(k, h);
  }
  // X^(n-1) <- X^n <- X^(n+1)
  m_x_old.swap(m_x);
  m_x.swap(m_x_new);
  m_last_h = h;
  ++m_substeps_done;
  m_sub_time = t_new;
  check_health();
  m_times.update += seconds_since(t0);
}

// Explicit forces on fiber k's markers and the predictor. With X* = 2 X^n - X^(n-1) (Huang et
// al. 2007) and the lumped marker mass m_i = rho' ds w_i (w_i = 1/2 at the end markers):
//   f_i = m_i g + (F_i + F_r,i) ds w_i - c ds w_i (X^n_i - X^(n-1)_i)/h - dE_b/dX_i (X*),
//   E_b = gamma ds / 2 sum_i w_i |kappa_i|^2,  kappa_i = (X_{i+1} - 2 X_i + X_{i-1}) / ds^2,
// where a clamped end adds kappa_0 = 2 (X_1 - X_0 - ds tau) / ds^2 (the ghost marker
// X_{-1} = X_1 - 2 ds tau, weight 1/2) and a free or hinged end has kappa = 0 (X_ss = 0). For
// interior markers -dE_b/dX = -gamma D4 X ds, the (gamma X_ss)_ss of Eq. 9; at a free end it
// reproduces the ghost-point conditions X_ss = 0, X_sss = 0. The predictor is
//   Xhat_i = 2 X^n_i - X^(n-1)_i + theta h^2 f_i / m_i,
// and law-driven end markers take their position at t^(n+1).
void FiberSystem::predict(int k, double h, double theta, double t_new, double pose_weight,
                          std::span<const double> external_force) {
  const FiberSpec& f = m_config.fibers[k];
  Fiber& s = m_fibers[k];
  const int n = s.segments;
  const std::size_t o = s.offset;
  const double ds = s.ds;
  double* xs = m_x_star.data() + 2 * o;
  const double* x = m_x.data() + 2 * o;
  const double* xo = m_x_old.data() + 2 * o;
  double* fo = m_force.data() + 2 * o;
  const double* rep = m_repulsion.data() + 2 * o;
  const double* ext = external_force.empty() ? nullptr : external_force.data() + 2 * o;
  const double* mass = m_mass.data() + o;
  const double* wds = m_weight.data() + o;

  for (int i = 0; i <= n; ++i) {
    xs[2 * i] = 2 * x[2 * i] - xo[2 * i];
    xs[2 * i + 1] = 2 * x[2 * i + 1] - xo[2 * i + 1];
  }
  EndPose root, tip;
  if (s.is_root_fixed) {
    root = end_pose(k, true, t_new, pose_weight);
    xs[0] = root.position.x();
    xs[1] = root.position.y();
  }
  if (s.is_tip_fixed) {
    tip = end_pose(k, false, t_new, pose_weight);
    xs[2 * n] = tip.position.x();
    xs[2 * n + 1] = tip.position.y();
  }

  const double gx = m_config.gravity.x(), gy = m_config.gravity.y();
  const double c = f.damping / h;
  for (int i = 0; i <= n; ++i) {
    double fx = mass[i] * gx + wds[i] * (rep[2 * i] - c * (x[2 * i] - xo[2 * i]));
    double fy = mass[i] * gy + wds[i] * (rep[2 * i + 1] - c * (x[2 * i + 1] - xo[2 * i + 1]));
    if (ext) {
      fx += wds[i] * ext[2 * i];
      fy += wds[i] * ext[2 * i + 1];
    }
    fo[2 * i] = fx;
    fo[2 * i + 1] = fy;
  }

  s.root_moment = 0;
  s.tip_moment = 0;
  if (f.bending > 0) {
    const double inv_ds2 = 1.0 / (ds * ds);
    const double g_ds = f.bending / ds;
    for (int i = 1; i < n; ++i) {
      const double bx = g_ds * (xs[2 * i + 2] - 2 * xs[2 * i] + xs[2 * i - 2]) * inv_ds2;
      const double by = g_ds * (xs[2 * i + 3] - 2 * xs[2 * i + 1] + xs[2 * i - 1]) * inv_ds2;
      fo[2 * i - 2] -= bx;
      fo[2 * i - 1] -= by;
      fo[2 * i] += 2 * bx;
      fo[2 * i + 1] += 2 * by;
      fo[2 * i + 2] -= bx;
      fo[2 * i + 3] -= by;
    }
    // Clamped ends: moment on the support M = sigma gamma kappa_end . tau_perp (sigma = +1 at
    // the root, -1 at the tip), the generalised force -dE_b/dtheta of the support's rotation.
    const EndKind rk = f.root.kind, tk = f.tip.kind;
    if (rk == EndKind::clamped || rk == EndKind::attached) {
      const Vec2 kap = 2 * inv_ds2 * (Vec2(xs[2], xs[3]) - Vec2(xs[0], xs[1]) - ds * root.direction);
      fo[2] -= g_ds * kap.x();
      fo[3] -= g_ds * kap.y();
      fo[0] += g_ds * kap.x();
      fo[1] += g_ds * kap.y();
      s.root_moment = f.bending * cross(root.direction, kap);
    }
    if (tk == EndKind::clamped) {
      const Vec2 kap = 2 * inv_ds2 *
                       (Vec2(xs[2 * n - 2], xs[2 * n - 1]) - Vec2(xs[2 * n], xs[2 * n + 1]) + ds * tip.direction);
      fo[2 * n - 2] -= g_ds * kap.x();
      fo[2 * n - 1] -= g_ds * kap.y();
      fo[2 * n] += g_ds * kap.x();
      fo[2 * n + 1] += g_ds * kap.y();
      s.tip_moment = -f.bending * cross(tip.direction, kap);
    }
  }

  // Predictor; m_coef holds theta h^2 / (m_i ds), the factor of the tension force.
  double* xn = m_x_new.data() + 2 * o;
  double* coef = m_coef.data() + o;
  const double th2 = theta * h * h;
  for (int i = 0; i <= n; ++i) {
    const double a = th2 / mass[i];
    xn[2 * i] = 2 * x[2 * i] - xo[2 * i] + a * fo[2 * i];
    xn[2 * i + 1] = 2 * x[2 * i + 1] - xo[2 * i + 1] + a * fo[2 * i + 1];
    coef[i] = a / ds;
  }
  if (s.is_root_fixed) {
    xn[0] = root.position.x();
    xn[1] = root.position.y();
    coef[0] = 0;
  }
  if (s.is_tip_fixed) {
    xn[2 * n] = tip.position.x();
    xn[2 * n + 1] = tip.position.y();
    coef[n] = 0;
  }
}

// Load on the supports of fiber k, from the balance of each supported end marker e:
//   m_e a_e = f_e + t_e + R_e,  a_e = (X^(n+1)_e - 2 X^n_e + X^(n-1)_e) / h^2,
// with t_e the tension force of the adjacent segment (T r / ds); the load on the support is
// -R_e = f_e + t_e - m_e a_e. Internal forces cancel in the sum over markers, so the loads on
// the supports plus the external forces equal the rate of change of the fiber's momentum.
void FiberSystem::end_loads(int k, double h) {
  const Fiber& s = m_fibers[k];
  const int n = s.segments;
  const double inv_h2 = 1.0 / (h * h);
  const auto load_at = [&](std::size_t i, std::size_t seg, double sign) {
    const Vec2 a = (at(m_x_new, i) - 2 * at(m_x, i) + at(m_x_old, i)) * inv_h2;
    const Vec2 t = sign * m_tension[seg] / s.ds * at(m_ref, seg);
    return Vec2(at(m_force, i) + t - m_mass[i] * a);
  };
  if (s.is_root_fixed) {
    m_root_acc[k].force += load_at(s.offset, s.seg_offset, 1.0);
    m_root_acc[k].moment += s.root_moment;
    m_root_acc[k].mass += root_mass(k, h);
    m_root_acc[k].accel += (at(m_x_new, s.offset) - 2 * at(m_x, s.offset) + at(m_x_old, s.offset)) * inv_h2;
  }
  if (s.is_tip_fixed) {
    m_tip_acc[k].force += load_at(s.offset + n, s.seg_offset + n - 1, -1.0);
    m_tip_acc[k].moment += s.tip_moment;
  }
}

// The root load's response to the root's acceleration, -d(load)/d(a_0), with the tension solved
// again. Moving the root marker's X^(n+1)_0 by delta (a_0 by delta / h^2) changes only the
// constraint of segment 0, dg_0 = -2 d_0.delta (d_j = X^(n+1)_{j+1} - X^(n+1)_j), so the tensions
// change by dT = J^-1 e_0 (2 d_0.delta) (J the tension equation's tridiagonal Jacobian at the
// solution, which solve_tension leaves in m_lo, m_di, m_up), and the load -R_0 = f_0 + T_0 r_0 / ds
// - m_0 a_0 by (2 z / ds) r_0 d_0^T delta - m_0 delta / h^2, z = (J^-1)_00. Hence
//   mass = m_0 I - (2 h^2 z / ds) r_0 d_0^T,
// symmetrised (r_0 = d_0 up to the step's rotation of the first segment). z is the inverse of
// the first pivot of J eliminated from the last row upwards (its Schur complement). The bending
// forces' dependence on the root (a stiffness, O(h^2) against the inertia) is left out. For a
// straight fiber, J^-1 makes the whole chain follow the root along its axis: mass ~ the fiber's
// mass along it, m_0 across. A first segment that turns fast within the sub-step (by more than
// about sqrt(2 / markers) rad) would make the symmetrised block indefinite; its eigenvalues are
// kept >= m_0, the end marker's own mass, so that the support always receives a positive mass.
// On the very first sub-step c holds theta = 1/2 (the start from rest), which doubles the mass
// along the fiber for that step only.
Eigen::Matrix2d FiberSystem::root_mass(int k, double h) const {
  const Fiber& s = m_fibers[k];
  const int n = s.segments;
  const std::size_t o = s.seg_offset;
  double pivot = m_di[o + n - 1];
  for (int j = n - 2; j >= 0; --j) pivot = m_di[o + j] - m_up[o + j] * m_lo[o + j + 1] / pivot;
  const Vec2 r0 = at(m_ref, o);
  const Vec2 d0 = at(m_x_new, s.offset + 1) - at(m_x_new, s.offset);
  const double m0 = m_mass[s.offset];
  Eigen::Matrix2d m = m0 * Eigen::Matrix2d::Identity() -
                      (2 * h * h / (pivot * s.ds)) * (r0 * d0.transpose());
  m = 0.5 * (m + m.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(m);
  if (eig.eigenvalues()(0) < m0) {
    const Eigen::Vector2d lam = eig.eigenvalues().cwiseMax(m0);
    m = eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
  }
  return m;
}

// Load on the driver of a prescribed fiber: sum_i (f_i - m_i a_i) with f_i = m_i g +
// (F_i + F_r,i) ds w_i, and its moment about the root marker X^(n+1)_0.
void FiberSystem::prescribed_load(int k, double h, std::span<const double> external_force) {
  const Fiber& s = m_fibers[k];
  const double inv_h2 = 1.0 / (h * h);
  Vec2 force = Vec2::Zero();
  double moment = 0;
  const Vec2 x0 = at(m_x_new, s.offset);
  for (int q = 0; q <= s.segments; ++q) {
    const std::size_t i = s.offset + q;
    Vec2 f = m_mass[i] * m_config.gravity + m_weight[i] * at(m_repulsion, i);
    if (!external_force.empty()) f += m_weight[i] * at(external_force, i);
    const Vec2 a = (at(m_x_new, i) - 2 * at(m_x, i) + at(m_x_old, i)) * inv_h2;
    const Vec2 l = f - m_mass[i] * a;
    force += l;
    moment += cross(at(m_x_new, i) - x0, l);
  }
  m_root_acc[k].force += force;
  m_root_acc[k].moment += moment;
}

// Fiber-fiber repulsion at X^n (paper Eq. 11-12). Between markers i and j of different fibers
// closer than the cut-off, W_r = k / (2 |X_i - X_j|^2) gives the force per unit length
//   F_r,i = k (X_i - X_j) / |X_i - X_j|^4  (= -dW_r/dX_i),
// summed over j. On the markers it acts as the force F_r,i sqrt(l_i l_j) (l = ds w, the marker's
// arclength) and -F_r,i sqrt(l_i l_j) on j: the per-unit-length force of Eq. 11 between interior
// markers of equal ds, with action = reaction for every pair (ends and unequal ds included).
// Stored per unit length of marker i: F_r,i sqrt(l_j / l_i).
void FiberSystem::repulsion_forces() {
  const auto& rep = m_config.repulsion;
  if (!rep.is_enabled) return;
  std::fill(m_repulsion.begin(), m_repulsion.end(), 0.0);
  m_cells.build(m_x, rep.cutoff);
  const double kr = rep.stiffness;
  const auto fiber_end = [&](std::size_t i) {
    const Fiber& s = m_fibers[m_owner[i]];
    return s.offset + s.segments + 1;
  };
  m_cells.for_each_pair(m_x, rep.cutoff, fiber_end, [&](std::size_t i, std::size_t j, double dx, double dy, double r2) {
    const double c = kr / (r2 * r2);
    const double ci = c * std::sqrt(m_weight[j] / m_weight[i]);
    const double cj = c * std::sqrt(m_weight[i] / m_weight[j]);
    m_repulsion[2 * i] += ci * dx;
    m_repulsion[2 * i + 1] += ci * dy;
    m_repulsion[2 * j] -= cj * dx;
    m_repulsion[2 * j + 1] -= cj * dy;
  });
}

// NaN and stretch, every sub-step: O(markers).
void FiberSystem::check_health() const {
  for (int k = 0; k < fiber_count(); ++k) {
    const Fiber& s = m_fibers[k];
    const FiberSpec& f = m_config.fibers[k];
    double worst = 0;
    int at_seg = 0;
    for (int j = 0; j < s.segments; ++j) {
      const std::size_t i = s.offset + j;
      const double dx = m_x[2 * i + 2] - m_x[2 * i], dy = m_x[2 * i + 3] - m_x[2 * i + 1];
      const double e = std::abs(std::sqrt(dx * dx + dy * dy) / s.ds - 1);
      if (!(e <= worst)) {  // also catches NaN
        worst = e;
        at_seg = j;
        if (std::isnan(e)) break;
      }
    }
    if (std::isnan(worst))
      throw fsi::Error(fmt::format("fiber '{}' ({}): NaN position near marker {} at t = {:.9g} (step {})", f.name,
                                   f.key, at_seg, m_sub_time, m_steps + 1));
    if (!s.is_prescribed && worst > m_config.stretch_limit)
      throw fsi::Error(fmt::format(
          "fiber '{}' ({}): stretch | |X_s| - 1 | = {:.3g} at segment {} (s = {:.6g}) is above "
          "fiber.stretch_limit = {:.3g} at t = {:.9g} (step {}); the tension equation did not hold the "
          "length: lower the time step or raise fiber.tension_iterations",
          f.name, f.key, worst, at_seg, (at_seg + 0.5) * s.ds, m_config.stretch_limit, m_sub_time, m_steps + 1));
  }
}

}  // namespace fiber
