// The projection of the fractional step: the pressure Poisson equation and the velocity
// correction that makes u^(n+1) discretely divergence-free.
#include "solver.hpp"
#include "timer.hpp"

namespace fluid {

// Projection: L phi = (rho / dt) D u~ (Neumann at walls, inflows and outflows; on a pressure
// side phi = phi_b = p_b(t^{n+1}) - p_b(t^n) on the face), then
//   u^{n+1} = u~ - (dt / rho) G phi,   p^{n+1} = p^n + phi.
// D G is exactly the operator the fast solver inverts, so D u^{n+1} = 0 to round-off. On a
// pressure side the first cell's row reads [(phi_1 - phi_0) d_1 - 2 (phi_0 - phi_b) / w_0] / w_0:
// the solver's operator holds the phi_0 part, -2 phi_b / w_0^2 moves to the right-hand side.
void Solver::project(double dt, double t_new) {
  const int nx = m_grid.nx(), ny = m_grid.ny();
  const int lo = row_lo(), hi = row_hi();
  const double *xwi = m_grid.x().wi(), *ywi = m_grid.y().wi();
  const double *xdi = m_grid.x().di(), *ydi = m_grid.y().di();
  double* buf = solve_data(2);
  const int nt = solve_nt(2);
  const double k = m_cfg.density / dt;
  // The duplicate face of a periodic direction carries the value of face 0. On several ranks
  // the v faces above the slab (row hi) come from the neighbour, which also covers a periodic y.
  if (m_grid.x().periodic())
    for (int j = lo; j < hi; ++j) m_u(nx, j) = m_u(0, j);
  if (m_dec.serial()) {
    if (m_grid.y().periodic())
      for (int i = 0; i < nx; ++i) m_v(i, ny) = m_v(i, 0);
  } else {
    m_dec.halo(m_v);
  }
  // The right-hand side in the solver's layout: rows of x (FastSolver along x, or any slab).
  const bool by_rows = m_t_axis == 0 || !m_dec.serial();
  for (int j = lo; j < hi; ++j) {
    const double* u = m_u.row(j);
    const double* v = m_v.row(j);
    const double* vn = m_v.row(j + 1);
    const double wy = ywi[j];
    if (by_rows) {
      double* b = buf + std::size_t(nt) * (j - lo);
      for (int i = 0; i < nx; ++i) b[i] = k * ((u[i + 1] - u[i]) * xwi[i] + (vn[i] - v[i]) * wy);
    } else {
      for (int i = 0; i < nx; ++i) {
        buf[j + std::size_t(nt) * i] = k * ((u[i + 1] - u[i]) * xwi[i] + (vn[i] - v[i]) * wy);
      }
    }
  }
  // The face pressure of p^(n+1) (from u~ where it depends on the velocity), and of p^n as its
  // ghost holds it: phi_b is their difference, row by row.
  face_pressure(t_new);
  for (int s : {int(left), int(right)}) {
    if (!m_bnd.is_pressure(s)) continue;
    const int i = s == left ? 0 : nx - 1, g = s == left ? -1 : nx;
    const double coef = 2.0 * xwi[i] * xwi[i];
    for (int j = lo; j < hi; ++j) {
      m_phi_b[s][j] = m_face_p[s][j] - 0.5 * (m_p(g, j) + m_p(i, j));
      buf[buf_index(i, j, 0, 0, nt)] -= coef * m_phi_b[s][j];
    }
  }
  {
    const PhaseTimer t(m_time.poisson, m_time.cpu);
    solve(2);
  }
  const PhaseTimer t(m_time.projection, m_time.cpu);
  for (int j = lo; j < hi; ++j) {
    double* phi = m_phi.row(j);
    double* p = m_p.row(j);
    for (int i = 0; i < nx; ++i) {
      phi[i] = buf[buf_index(i, j, 0, 0, nt)];
      p[i] += phi[i];
    }
  }
  m_bnd.fill_scalar(m_phi, m_phi_b);
  m_bnd.fill_scalar(m_p, m_face_p);
  const double c = dt / m_cfg.density;
  for (int j = lo; j < hi; ++j) {
    double* u = m_u.row(j);
    const double* phi = m_phi.row(j);
    for (int i = m_iu0; i < m_iu1; ++i) u[i] -= c * (phi[i] - phi[i - 1]) * xdi[i];
  }
  for (int j = v_row_lo(); j < hi; ++j) {
    double* v = m_v.row(j);
    const double* phi = m_phi.row(j);
    const double* phs = m_phi.row(j - 1);
    const double cy = c * ydi[j];
    for (int i = 0; i < nx; ++i) v[i] -= cy * (phi[i] - phs[i]);
  }
}

void Solver::project_initial() {
  m_bnd.advance_normal(m_u, m_v, m_t, 0.0);
  // The face pressures of the current u in the ghosts first (a total-pressure face depends on
  // it): the projection then moves no face pressure (phi_b = 0).
  face_pressure(m_t);
  m_bnd.fill_scalar(m_p, m_face_p);
  const Field p = m_p;
  project(1.0, m_t);
  m_p = p;
  face_pressure(m_t);
  m_bnd.fill_scalar(m_p, m_face_p);
  m_bnd.fill_ghosts(m_u, m_v);
}

}  // namespace fluid
