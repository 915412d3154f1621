// Assembly: the scene's loads, the internal force and its consistent tangent (material and
// geometric stiffness of every element, element.hpp), the Newmark inertia, the coupling force and
// the coupled iterations' linearised fluid reaction, into the residual on the free equations and
// the effective matrix in its fixed pattern.
#include <algorithm>
#include <cmath>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

std::vector<double> Solver::scene_loads(int b, double t) const {
  std::vector<double> f(m_bodies[b]->X.size(), 0.0);
  add_scene_loads(*m_bodies[b], t, f);
  return f;
}

// F(t) = (gravity + sum_k f_k(t) load_k), or factor * (gravity + sum_k load_k) in statics.
void Solver::add_scene_loads(const Body& B, double t, std::vector<double>& f) const {
  if (!B.is_elastic()) return;
  const bool statics = m_model.settings.analysis == Analysis::statics;
  const double scale = statics ? t : 1.0;
  for (std::size_t d = 0; d < f.size(); ++d) f[d] += scale * B.gravity[d];
  for (std::size_t k = 0; k < B.load_dofs.size(); ++k) {
    const double s = statics ? t : B.spec.loads[k].time(t);
    for (const auto& [dof, c] : B.load_dofs[k]) f[dof] += s * c;
  }
}

// Residual on the free equations, for Newmark (c0 = 1 / (beta dt^2), 4 / dt^2 in the
// trapezoidal rule) or statics (c0 = 0):
//   R = F(t) - Q(x) - c0 M (x - x^n - dt v^n) + (1/2 - beta) / beta (M a)^n + F_c / (2 beta),
// with Q_a = sum_e A0 F S dN_a/dX (element.hpp) and, when with_matrix,
//   K_eff = dQ/dx + c0 M  (material + geometric stiffness plus the Newmark mass term).
// `time_or_factor` is t^(n+1) in dynamics and the load factor in statics. The coupling force
// enters last (finish_residual): R = R_0 + F_c / (2 beta), R_0 every other term, so that a step's
// first residual may be the look-ahead's R_0 at the same state plus the step's F_c
// (take_ahead_residual) with the bits of an assembly.
std::pair<int, int> Solver::assemble(double c0, double dt, bool with_matrix, double time_or_factor,
                                     const std::vector<std::vector<double>>* external) {
  std::pair<int, int> inverted{-1, -1};
  if (with_matrix) {
    std::fill_n(m_matrix.valuePtr(), m_matrix.nonZeros(), 0.0);
    m_matrix_c0 = c0;
    m_matrix_curved = false;
  }
  m_ahead_residual.valid = false;  // its R_0 is overwritten below
  double* values = m_matrix.valuePtr();
  const bool dynamic = c0 > 0;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    const Mesh& mesh = B.spec.mesh;
    std::fill(B.f_ext.begin(), B.f_ext.end(), 0.0);
    add_scene_loads(B, time_or_factor, B.f_ext);
    set_coupling_force(B, external);
    std::fill(B.q.begin(), B.q.end(), 0.0);
    const std::vector<double>* iter_w = nullptr;
    if (dynamic && m_iteration_velocity &&
        static_cast<int>(m_iteration_velocity->size()) > B.index &&
        !(*m_iteration_velocity)[B.index].empty()) {
      iter_w = &(*m_iteration_velocity)[B.index];
      if (iter_w->size() != B.u.size())
        fsi::fail("iteration velocities for body '{}' have {} values, expected {}",
                  B.spec.name, iter_w->size(), B.u.size());
    }
    std::vector<double>& r = B.r_0;
    // The coupling force is the reaction of the fluid's velocity correction over this step: an
    // impulse F_c dt within the step, like the contact acceleration of the paper's Eq. 13-14
    // (x^(n+1) = ... + dt^2/2 a_c, v^(n+1) = ... + dt a_c). In the trapezoidal residual
    // (4/dt^2) M (x^(n+1) - x^n - dt v^n) - M a^n = F^(n+1) - Q^(n+1) + 2 F_c it enters twice,
    // and it stays out of the stored M a (the next step does not average it in again): the
    // solid receives the whole impulse in the step the fluid lost it, so momentum balances step
    // by step. Averaging it over two steps delays the reaction and pumps energy into the solid's
    // element-scale modes. Massless dofs (rho_s = rho_f) are quasi-static: F - Q + F_c = 0.
    // With other Newmark parameters (M a)^n enters with (1/2 - beta) / beta and F_c with
    // 1 / (2 beta) (Eq. 13 solved for a^(n+1)); both are exact in the trapezoidal rule (1, 2).
    const double w_ma = newmark_ma_weight();
    for (std::size_t d = 0; d < r.size(); ++d) r[d] = B.f_ext[d] + (dynamic ? w_ma * B.ma[d] : 0.0);
    // Scales of R: |element forces| (absq); the inertia's and root masses' round-off floor
    // (absm); |K| |u| with the matrix (absk).
    std::vector<double>& absq = B.abs_q;
    std::vector<double>& absm = B.abs_floor;
    std::vector<double>& absk = B.abs_ku;
    std::fill(absq.begin(), absq.end(), 0.0);
    std::fill(absm.begin(), absm.end(), 0.0);
    if (with_matrix) std::fill(absk.begin(), absk.end(), 0.0);
    for (int e = 0; e < mesh.num_triangles(); ++e) {
      const auto& t = mesh.triangles[e];
      double fe[6], ke[36];
      double J = 1;
      element_internal(B.spec.materials[B.material[e]], B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]],
                       &B.u[2 * t[2]], fe, with_matrix ? ke : nullptr, &J, false);
      B.det_f[e] = J;
      if (!(J > 0) && inverted.first < 0) inverted = {B.index, e};
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 2; ++i) {
          const int d = 2 * t[a] + i;
          B.q[d] += fe[2 * a + i];
          absq[d] += std::abs(fe[2 * a + i]);
        }
      // The element's mass matrix (unit density), for the inertia and the coupled iterations'
      // term; each removes scale(k) * (M vec)_k from the residual and adds scale(k) * (M |vec|)_k
      // to its round-off floor, k = 2a + i.
      double me[3][3] = {};
      if (dynamic && (B.rho_inertia[e] > 0 || iter_w)) element_mass(B.geo[e].area, me);
      auto mass_terms = [&](const double* vec, const double* vec_abs, auto scale) {
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < 2; ++i) {
            double m = 0, mabs = 0;
            for (int c = 0; c < 3; ++c) {
              m += me[a][c] * vec[2 * c + i];
              mabs += me[a][c] * vec_abs[2 * c + i];
            }
            r[2 * t[a] + i] -= scale(2 * a + i) * m;
            absm[2 * t[a] + i] += scale(2 * a + i) * mabs;
          }
      };
      if (dynamic && B.rho_inertia[e] > 0) {
        const double rho = B.rho_inertia[e];
        double w[6], wabs[6];
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < 2; ++i) {
            const int d = 2 * t[a] + i;
            w[2 * a + i] = B.u[d] - B.u_old[d] - dt * B.v_old[d];
            wabs[2 * a + i] = std::abs(B.u[d]) + std::abs(B.u_old[d]) + dt * std::abs(B.v_old[d]);
          }
        mass_terms(w, wabs, [&](int) { return c0 * rho; });
        if (with_matrix)
          for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c)
              for (int i = 0; i < 2; ++i) ke[6 * (2 * a + i) + 2 * c + i] += c0 * rho * me[a][c];
      }
      if (iter_w) {
        // Coupled iterations: the reaction F_c the coupler sent was computed from the
        // velocity w it gave the fluid; about w it is F_c(v) ~ F_c - M_f (v - w) / dt, M_f the
        // mass matrix of density rho_f (the fluid inside the body, which the forcing makes
        // follow v). In the residual F_c enters with the weight s_d (2 on dofs with mass, 1 on
        // massless ones, as above) and v_c^(n+1) = s_c (x_c^(n+1) - x_c^n) / dt - [mass] v_c^n,
        // so
        //   r_d -= s_d / dt sum_c M_f,dc (v_c - w_c),   K_dc += s_d s_c / dt^2 M_f,dc.
        // The term vanishes when the step returns v^(n+1) = w (a converged iteration), and it
        // gives a body without excess mass (rho_s = rho_f) the inertia rho_f it otherwise lacks
        // within the step: a free neutrally buoyant body has a regular matrix.
        const double rf = m_model.settings.fluid_density;
        double sw[6], dv[6], vabs[6];  // vabs: |v| + |w|, the scale of the terms that cancel
        for (int c = 0; c < 6; ++c) {
          const int d = 2 * t[c / 2] + c % 2;
          sw[c] = B.impulse_weight(d);
          const double v = B.step_velocity(d, dt);
          dv[c] = v - (*iter_w)[d];
          vabs[c] = std::abs(v) + std::abs((*iter_w)[d]);
        }
        mass_terms(dv, vabs, [&](int k) { return sw[k] * rf / dt; });
        if (with_matrix)
          for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c)
              for (int i = 0; i < 2; ++i)
                ke[6 * (2 * a + i) + 2 * c + i] +=
                    sw[2 * a + i] * sw[2 * c + i] * rf / (dt * dt) * me[a][c];
      }
      if (with_matrix && m_dirichlet_pending) {
        double dp[6];
        bool moved = false;
        for (int c = 0; c < 6; ++c) {
          dp[c] = B.dirichlet_step[2 * t[c / 2] + c % 2];
          moved = moved || dp[c] != 0;
        }
        if (moved)
          for (int rr = 0; rr < 6; ++rr) {
            double f = 0;
            for (int c = 0; c < 6; ++c) f += ke[6 * rr + c] * dp[c];
            r[2 * t[rr / 2] + rr % 2] -= f;
          }
      }
      if (with_matrix) {
        // Round-off floor of the residual: |K| |u| (a residual cannot be resolved below eps of
        // the element forces that cancel in it).
        for (int rr = 0; rr < 6; ++rr) {
          double f = 0;
          for (int c = 0; c < 6; ++c)
            f += std::abs(ke[6 * rr + c]) * std::abs(B.u[2 * t[c / 2] + c % 2]);
          absk[2 * t[rr / 2] + rr % 2] += f;
        }
        const auto& map = B.kmap[e];
        for (int k = 0; k < 36; ++k)
          if (map[k] >= 0) values[map[k]] += ke[k];
      }
    }
    if (dynamic) add_root_mass(B, dt, with_matrix, r, absm);
    for (std::size_t d = 0; d < r.size(); ++d) r[d] -= B.q[d];
  }
  finish_residual(dynamic, with_matrix);
  return inverted;
}

// F_c of body B: the external forces given for it, else zero.
void Solver::set_coupling_force(Body& B, const std::vector<std::vector<double>>* external) {
  if (external && static_cast<int>(external->size()) > B.index && !(*external)[B.index].empty()) {
    const auto& fe = (*external)[B.index];
    if (fe.size() != B.f_cpl.size())
      fsi::fail("external forces for body '{}' have {} values, expected {}", B.spec.name,
                fe.size(), B.f_cpl.size());
    std::copy(fe.begin(), fe.end(), B.f_cpl.begin());
  } else {
    std::fill(B.f_cpl.begin(), B.f_cpl.end(), 0.0);
  }
}

// From every body's R_0 (B.r_0) and F_c: r = R_0 + w F_c (w = 1 / (2 beta) on a dof with mass in
// dynamics, 1 otherwise), the residual on the free equations, its force scale (the norm of the
// terms that enter it) and its round-off floor (with |K| |u| when the matrix was assembled).
void Solver::finish_residual(bool dynamic, bool with_matrix) {
  m_residual.setZero();
  double scale2 = 0, floor2 = 0;
  const double w_ma = newmark_ma_weight(), w_impulse = newmark_impulse_weight();
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (std::size_t d = 0; d < B.r.size(); ++d) {
      // The coupling force counts as it enters r: 1 / (2 beta) with mass, once on a massless
      // dof.
      const double w_cpl = dynamic && B.mass_row[d] > 0 ? w_impulse : 1.0;
      B.r[d] = B.r_0[d] + w_cpl * B.f_cpl[d];
      if (B.eq[d] >= 0) {
        m_residual[B.eq[d]] += B.r[d];
        const double s = std::abs(B.f_ext[d]) + w_cpl * std::abs(B.f_cpl[d]) + B.abs_q[d] +
                         (dynamic ? std::abs(w_ma * B.ma[d]) : 0.0);
        const double f = s + B.abs_floor[d] + (with_matrix ? B.abs_ku[d] : 0.0);
        scale2 += s * s;
        floor2 += f * f;
      }
    }
  }
  m_force_scale = std::sqrt(scale2);
  // Without the matrix the floor lacks |K| |u|: the last matrix assembly's floor stands in.
  m_roundoff_scale = std::sqrt(floor2);
  if (with_matrix)
    m_matrix_floor = m_roundoff_scale;
  else
    m_roundoff_scale = std::max(m_roundoff_scale, m_matrix_floor);
}

// The look-ahead's assembly at x^n (factorize_ahead, F_c = 0) kept for the step from x^n: its
// R_0 (B.r_0) and the state it was assembled at.
void Solver::keep_ahead_residual(double c0, double dt, double time, std::pair<int, int> inverted) {
  AheadResidual& a = m_ahead_residual;
  a.c0 = c0, a.dt = dt, a.time = time, a.inverted = inverted;
  a.u.resize(m_bodies.size()), a.v.resize(m_bodies.size()), a.ma.resize(m_bodies.size());
  for (std::size_t b = 0; b < m_bodies.size(); ++b) {
    const Body& B = *m_bodies[b];
    if (!B.is_elastic()) continue;
    a.u[b] = B.u, a.v[b] = B.v_old, a.ma[b] = B.ma;
  }
  a.valid = true;
}

// A step's first residual from the look-ahead's R_0 plus this step's F_c, when R_0 is that of
// this very assembly: the same c0, dt and time; the iterate, x^n, v^n and (M a)^n the ones it was
// assembled at (compared value for value: anything that moved the state between them, a
// restored checkpoint, a set velocity, a predictor, refuses it); no prescribed increment,
// coupled iterations' velocities or fibers' root masses (terms the look-ahead had not). Then the
// residual is bit for bit the residual-only assembly's, one element pass less on the step's
// critical path. Returns false (nothing changed) otherwise.
bool Solver::take_ahead_residual(double c0, double dt, double time,
                                 const std::vector<std::vector<double>>* external,
                                 const std::string& when) {
  AheadResidual& a = m_ahead_residual;
  if (!a.valid || a.c0 != c0 || a.dt != dt || a.time != time || m_dirichlet_pending ||
      m_iteration_velocity || any_root_mass(m_root_mass))
    return false;
  for (std::size_t b = 0; b < m_bodies.size(); ++b) {
    const Body& B = *m_bodies[b];
    if (B.is_elastic() &&
        (B.u != a.u[b] || B.u_old != a.u[b] || B.v_old != a.v[b] || B.ma != a.ma[b]))
      return false;
  }
  for (auto& bp : m_bodies)
    if (bp->is_elastic()) set_coupling_force(*bp, external);
  finish_residual(c0 > 0, false);
  a.valid = false;
  if (!m_residual.allFinite()) fail_non_finite_residual(a.inverted, when);
  return true;
}

// The fibers' root inertia (the coupler's root_mass: a 2 x 2 block m per node of the edges that
// hold roots): the root loads in the coupling force come without it, and the node carries
// -m a^(n+1), with a^(n+1) = (v^(n+1) - v^n) / dt the node's acceleration over the step, as an
// impulse like the coupling force (weight s_d, 2 on dofs with mass; the trapezoidal rule only:
// advance() refuses root masses with other Newmark parameters). With
// v_c^(n+1) = s_c (x_c^(n+1) - x_c^n) / dt - [mass] v_c^n,
//   r_d -= s_d / dt sum_c m_dc (v_c^(n+1) - v_c^n),   K_dc += s_d s_c / dt^2 m'_dc
// (c over the node's two dofs): on a dof with mass exactly the Newmark inertia of a point mass m.
// The first iteration's tangent takes m' = the previous step's root masses (the current ones on a
// first step): its matrix then depends on the state at the step's start only, so the look-ahead
// factorisation (factorize_ahead) serves it. A later iteration that factorises takes the current
// m (m_tangent_root_mass_now): with a root mass far from the last step's (a fiber's first load)
// the lagged tangent would not converge.
void Solver::add_root_mass(Body& B, double dt, bool with_matrix, std::vector<double>& r,
                           std::vector<double>& absm) {
  const std::size_t nodes = B.u.size() / 2;
  auto of = [&](const std::vector<std::vector<double>>* list) -> const std::vector<double>* {
    if (!list || static_cast<int>(list->size()) <= B.index) return nullptr;
    const auto& m = (*list)[B.index];
    if (m.empty()) return nullptr;
    if (m.size() != 3 * nodes)
      fsi::fail("root masses for body '{}' have {} values, expected 3 per node = {}", B.spec.name,
                m.size(), 3 * nodes);
    return &m;
  };
  const std::vector<double>* now = of(m_root_mass);
  const std::vector<double>* tangent = m_tangent_root_mass_now ? now : of(&m_root_mass_tangent);
  if (!tangent) tangent = now;
  double* values = m_matrix.valuePtr();
  for (std::size_t a = 0; a < nodes; ++a) {
    double sw[2];
    for (int i = 0; i < 2; ++i) sw[i] = B.impulse_weight(2 * a + i);
    if (now && ((*now)[3 * a] != 0 || (*now)[3 * a + 1] != 0 || (*now)[3 * a + 2] != 0)) {
      const double* m = &(*now)[3 * a];
      const double block[2][2] = {{m[0], m[1]}, {m[1], m[2]}};
      double dv[2], vabs[2];
      for (int i = 0; i < 2; ++i) {
        const std::size_t d = 2 * a + i;
        const double v = B.step_velocity(d, dt);
        dv[i] = v - B.v_old[d];
        vabs[i] = std::abs(v) + std::abs(B.v_old[d]);
      }
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
          r[2 * a + i] -= sw[i] / dt * block[i][j] * dv[j];
          absm[2 * a + i] += sw[i] / dt * std::abs(block[i][j]) * vabs[j];
        }
    }
    if (!with_matrix || !tangent) continue;
    const double* m = &(*tangent)[3 * a];
    if (m[0] == 0 && m[1] == 0 && m[2] == 0) continue;
    const double block[2][2] = {{m[0], m[1]}, {m[1], m[2]}};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        const int er = B.eq[2 * a + i], ec = B.eq[2 * a + j];
        if (er < 0 || ec < 0 || er < ec) continue;
        const int k = matrix_index(er, ec);
        FSI_ASSERT(k >= 0);
        values[k] += sw[i] * sw[j] / (dt * dt) * block[i][j];
      }
  }
}

}  // namespace solid
