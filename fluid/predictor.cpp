// The predictor u~ of the fractional step: the explicit terms, the explicit (AB2) predictor, the
// Crank-Nicolson one (its right-hand side and its solve), and the fibers' force in either.
#include <algorithm>

#include "solver.hpp"

namespace fluid {

// H(u^n) into m_hu, m_hv: -div(u u) + nu lap(u) (explicit diffusion) or -div(u u) with L u^n into
// m_lu, m_lv (Crank-Nicolson).
void Solver::explicit_terms() {
  const bool imp = m_cfg.implicit;
  momentum_terms(m_grid, m_sponge, m_u, m_v, imp ? 0.0 : m_nu, m_i0, m_j0, m_hu, m_hv,
                 imp ? &m_lu : nullptr, imp ? &m_lv : nullptr);
  if (m_cfg.upwind3) {
    m_dec.outer_rows(m_u, m_outer_u);
    m_dec.outer_rows(m_v, m_outer_v);
    upwind3_terms(m_grid, m_sponge, m_u, m_v, m_outer_u, m_outer_v, m_i0, m_j0, m_hu, m_hv,
                  m_upwind3_work);
  }
}

// Explicit predictor (AB2 for convection and diffusion, Euler on the first step):
//   u~ = u^n + dt [ (1 + dt/(2 dt')) H^n - dt/(2 dt') H^{n-1} - G p^n / rho + f(t^{n+1/2}) / rho
//                   + f_f / rho ],   H = -div(u u) + nu lap(u)
// without the fibers' f_f / rho, which add_fiber_force() adds on their faces.
void Solver::predictor(double dt, double t_half) {
  const double c1 = m_step == 0 ? 1.0 : 1.0 + 0.5 * dt / m_dt_prev;
  const double c0 = m_step == 0 ? 0.0 : -0.5 * dt / m_dt_prev;
  const auto acc = body_acceleration(t_half);
  const double ri = 1.0 / m_cfg.density;
  const int nx = m_grid.nx();
  const double* xdi = m_grid.x().di();
  const double* ydi = m_grid.y().di();
  for (int j = row_lo(); j < row_hi(); ++j) {
    double* u = m_u.row(j);
    const double* h = m_hu.row(j);
    const double* ho = m_hu_old.row(j);
    const double* p = m_p.row(j);
    for (int i = m_i0; i < nx; ++i) {
      u[i] += dt * (c1 * h[i] + c0 * ho[i] + acc[0] - ri * (p[i] - p[i - 1]) * xdi[i]);
    }
    // A pressure side's boundary face: the explicit terms of its interior neighbour, the
    // gradient to the face pressure p_b(t^n) (the ghost p_{-1} = 2 p_b - p_0: xdi = 1 / w_0).
    if (m_bnd.is_pressure(left))
      u[0] += dt * (c1 * h[1] + c0 * ho[1] + acc[0] - ri * (p[0] - p[-1]) * xdi[0]);
    if (m_bnd.is_pressure(right))
      u[nx] += dt * (c1 * h[nx - 1] + c0 * ho[nx - 1] + acc[0] - ri * (p[nx] - p[nx - 1]) * xdi[nx]);
  }
  for (int j = v_row_lo(); j < row_hi(); ++j) {
    double* v = m_v.row(j);
    const double* h = m_hv.row(j);
    const double* ho = m_hv_old.row(j);
    const double* p = m_p.row(j);
    const double* ps = m_p.row(j - 1);
    const double gy = ri * ydi[j];
    for (int i = 0; i < nx; ++i) {
      v[i] += dt * (c1 * h[i] + c0 * ho[i] + acc[1] - gy * (p[i] - ps[i]));
    }
  }
}

// u~ += dt f_f / rho on the fibers' faces (the explicit predictor's last term; Crank-Nicolson:
// on its explicit prediction u^, before the solve).
void Solver::add_fiber_force(double dt, const CouplingIn& in) {
  const double ri = 1.0 / m_cfg.density;
  const int ny = m_grid.ny();
  for (std::size_t q = 0; q < in.fiber_u_index.size(); ++q) {
    const auto [i, j] = face_of(0, in.fiber_u_index[q]);
    if (i >= m_iu0 && i < m_iu1) m_u(i, owned(j, 0)) += dt * ri * in.fiber_u_force[q];
  }
  for (std::size_t q = 0; q < in.fiber_v_index.size(); ++q) {
    const auto [i, j] = face_of(1, in.fiber_v_index[q]);
    if (j >= m_j0 && owned(j, 1) < ny) m_v(i, j) += dt * ri * in.fiber_v_force[q];
  }
}

// Crank-Nicolson predictor in increment form, theta = nu dt / 2. The classical step
//   (I - theta L0) u~ = u^n + dt R + theta L(u^n; b^n) + theta L(u^n; b^(n+1)) - theta L0 u^n,
//   R = AB2(-div(u u)) - G p^n / rho + f / rho + f_f / rho,
// (L0: the fast solver's operator, which differs from L only in the transform direction next to
// a wall or an outflow, where it takes the nearest closure a real transform diagonalises, the
// difference carried explicitly with u^n; stable for nu dt / h_t^2 < 2, checked by validate()) is,
// with u~ = u^n + Y, the same as
//   u^ = u^n + dt R + 2 theta L(u^n; b^n)                  (an explicit prediction)
//   (I - theta L0) Y = u^ - u^n + theta [L(u^n; b^(n+1)) - L(u^n; b^n)].
// The immersed solid's forcing with implicit_forcing = "increment" acts on u^ before the solve,
// u^_f = u^ + alpha (u_s - u^) (beta with forcing_time, forcing.cpp): the solve takes u^_f - u^n
// in place of u^ - u^n, and u~ = u^n + Y; every face keeps the solve's value (forcing.cpp: why
// the covered ones too). In a steady state with u^_f = u^n (the explicit scheme's balance) Y = 0
// and u~ = u^n: the wall sits where the explicit scheme puts it, at any lambda = nu dt / h^2; and
// as u~ - u^n is always a solve's result, the explicit diffusion in u^ never reaches u~ undamped
// (forcing a cut face after the solve as well would leave alpha (1 - alpha) of it there, unstable
// from lambda of about 0.5). The reaction is what the forcing put in: rho alpha (u_s - u^) / dt
// (beta with forcing_time). The solve's faces are the interior ones: Crank-Nicolson has no
// pressure sides (config.cpp). Without a body the step is the classical one; "after_solve" forces
// u~ after the solve as the explicit scheme does (the solve then acts on the unforced prediction
// inside the body, and the wall leaks).
//
// This part runs before the coupling input: u^ into the fields' unknowns (the boundary faces and
// ghosts hold t^(n+1)'s values), and the boundary increment theta [L(u^n; b^(n+1)) - L(u^n; b^n)]
// (coefficient times the change of the value beyond the boundary row, from m_un, m_vn) into
// m_rhs in the solver's layout. add_fiber_force() adds f_f to u^; solve_implicit() does the rest.
void Solver::predictor_implicit(double dt, double t_half) {
  const double c1 = m_step == 0 ? 1.0 : 1.0 + 0.5 * dt / m_dt_prev;
  const double c0 = m_step == 0 ? 0.0 : -0.5 * dt / m_dt_prev;
  const auto acc = body_acceleration(t_half);
  const double ri = 1.0 / m_cfg.density;
  const double theta = 0.5 * m_nu * dt;
  const int nx = m_grid.nx();
  const Axis& X = m_grid.x();
  const Axis& Y = m_grid.y();

  for (int comp = 0; comp < 2; ++comp) {
    Field& F = comp == 0 ? m_u : m_v;
    const Field& Fn = comp == 0 ? m_un : m_vn;
    const Field& H = comp == 0 ? m_hu : m_hv;
    const Field& Ho = comp == 0 ? m_hu_old : m_hv_old;
    const Field& L = comp == 0 ? m_lu : m_lv;
    const int ib = comp == 0 ? m_i0 : 0, jb = comp == 0 ? 0 : m_j0;
    const int nt = solve_nt(comp);
    // Rows of the unknowns on this rank: [jr, row_hi()) (one rank: [jb, ny)).
    const int jr = std::max(jb, row_lo());
    std::vector<double>& buf = m_rhs[comp];
    buf.assign(solve_size(comp), 0.0);
    const double* gd = comp == 0 ? X.di() : Y.di();
    for (int j = jr; j < row_hi(); ++j) {
      double* f = F.row(j);
      const double* h = H.row(j);
      const double* ho = Ho.row(j);
      const double* l = L.row(j);
      const double* p = m_p.row(j);
      const double* pm = comp == 0 ? p - 1 : m_p.row(j - 1);  // p at the face's low side
      for (int i = ib; i < nx; ++i) {
        const double gp = (p[i] - pm[i]) * (comp == 0 ? gd[i] : gd[j]);
        f[i] += dt * (c1 * h[i] + c0 * ho[i] + acc[comp] - ri * gp) + 2 * theta * l[i];
      }
    }
    // Boundary rows: theta * coef * (the value beyond the row at t^(n+1) - at t^n).
    for (int s = 0; s < 4; ++s) {
      const SideBc& bc = m_bnd.side(s);
      if (bc.type == BcType::periodic) continue;
      const int a = s / 2;
      const bool hi = s % 2;
      const Axis& ax = m_grid.axis(a);
      const int n = ax.n();
      // Range along the side on this rank: its rows (left, right) or, when it holds the side,
      // the columns (bottom, top).
      const bool here = a == 0 || (hi ? m_dec.has_top() : m_dec.has_bottom());
      const int kb = a == 0 ? jr : ib, ke = a == 0 ? row_hi() : here ? nx : ib;
      auto change = [&](int nidx, int k) {
        return a == 0 ? F(nidx, k) - Fn(nidx, k) : F(k, nidx) - Fn(k, nidx);
      };
      auto add = [&](int nidx, int k, double x) {
        const int i = a == 0 ? nidx : k, j = a == 0 ? k : nidx;
        buf[buf_index(i, j, ib, jb, nt)] += theta * x;
      };
      if (a == comp) {  // normal component: boundary face value
        const int b = hi ? n : 0, f = hi ? n - 1 : 1;
        const double coef = hi ? ax.wi()[n - 1] * ax.di()[n - 1] : ax.wi()[0] * ax.di()[1];
        for (int k = kb; k < ke; ++k) add(f, k, coef * change(b, k));
      } else {  // tangential component: ghost value
        const int g = hi ? n : -1, q0 = hi ? n - 1 : 0;
        const double coef = hi ? ax.di()[n] * ax.ci()[n - 1] : ax.di()[0] * ax.ci()[0];
        for (int k = kb; k < ke; ++k) add(q0, k, coef * change(g, k));
      }
    }
  }
}

// The Crank-Nicolson solve of the step (predictor_implicit): the forcing alpha (u_s - u^) on u^
// (beta with forcing_time; kept in m_pull for the reaction),
// (I - theta L0) Y = u^_f - u^n + boundary increment, u~ = u^n + Y. A coupled iteration's redo
// takes u^ again and solves with its alpha and u_s (forcing.cpp: why the faces keep the solve's
// values).
void Solver::solve_implicit(const CouplingIn& in) {
  const int nx = m_grid.nx(), ny = m_grid.ny();
  const double scale = -1.0 / (0.5 * m_nu * m_begun_dt);  // the Helmholtz solver's B / -theta
  for (int comp = 0; comp < 2; ++comp) {
    Field& F = comp == 0 ? m_u : m_v;
    const Field& Fn = comp == 0 ? m_un : m_vn;
    const int ib = comp == 0 ? m_i0 : 0, jb = comp == 0 ? 0 : m_j0;
    const int nt = solve_nt(comp);
    const std::vector<double>& rhs = m_rhs[comp];
    double* buf = solve_data(comp);
    const int jr = std::max(jb, row_lo());
    for (int j = jr; j < row_hi(); ++j) {
      const double* f = F.row(j);
      const double* fn = Fn.row(j);
      for (int i = ib; i < nx; ++i) {
        const int k = buf_index(i, j, ib, jb, nt);
        buf[k] = scale * (f[i] - fn[i] + rhs[k]);
      }
    }
    // implicit_forcing = "increment": the forcing on u^, alpha (u_s - u^) (beta with
    // forcing_time, forcing.cpp), into the solve and kept for the reaction (immersed_forcing).
    if (m_cfg.forcing_in_increment) {
      const auto& idx = comp == 0 ? in.solid_u_index : in.solid_v_index;
      const auto& alpha = comp == 0 ? in.solid_u_alpha : in.solid_v_alpha;
      const auto& us = comp == 0 ? in.solid_u_velocity : in.solid_v_velocity;
      std::vector<double>& pull = m_pull[comp];
      pull.assign(idx.size(), 0.0);
      for (std::size_t q = 0; q < idx.size(); ++q) {
        const auto [i, j] = face_of(comp, idx[q]);
        if (i < ib || i >= nx || j < jb || owned(j, comp) >= ny) continue;
        pull[q] = forcing_fraction(alpha[q], m_begun_dt) * (us[q] - F(i, j));
        buf[buf_index(i, j, ib, jb, nt)] += scale * pull[q];
      }
    }
    solve(comp);
    for (int j = jr; j < row_hi(); ++j) {
      double* f = F.row(j);
      const double* fn = Fn.row(j);
      for (int i = ib; i < nx; ++i) f[i] = fn[i] + buf[buf_index(i, j, ib, jb, nt)];
    }
  }
}

}  // namespace fluid
