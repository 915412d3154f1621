// The projection of the fractional step: the pressure Poisson equation and the velocity
// correction that makes u^(n+1) discretely divergence-free.
#include <algorithm>

#include "solver.hpp"
#include "timer.hpp"

namespace fluid {

// Projection: L phi = (rho / dt) D u~ (Neumann at walls, inflows and outflows; on a pressure
// side phi = phi_b = p_b(t^{n+1}) - p_b(t^n) on the face), then
//   u^{n+1} = u~ - (dt / rho) G phi,   p^{n+1} = p^n + phi.
// D G is exactly the operator the fast solver inverts, so D u^{n+1} = 0 to round-off. On a
// pressure side the first cell's row reads [(phi_1 - phi_0) d_1 - 2 (phi_0 - phi_b) / w_0] / w_0:
// the solver's operator holds the phi_0 part, -2 phi_b / w_0^2 moves to the right-hand side.
//
// A compressible elastic body ([fluid] body_divergence). The forcing holds the fluid on a
// body's faces at the body's velocity ū_s, whose divergence inside the body is the solid's own
// volume change. A projection that made the fluid divergence-free there too would answer it with
// the increment (ρ/Δt) L⁻¹ D ū_s, and the incremental projection keeps every increment in p:
// inside the body p grows as (ρ/Δt²) L⁻¹ D of the body's displacement since the start, a penalty
// on the body's gradient (dilatational) motion of stiffness ρ_f/Δt² per unit volume at any
// wavelength. The body receives it through the reaction of the next step's forcing, which
// cancels the predictor's −∇pⁿ on the body's faces. A stiffness κ acting one step late feeds the
// motion it resists (about κ Δt/2 of negative damping); with m substeps of Δt/m each projection
// adds (ρ m/Δt) L⁻¹ D ū_s again for the same ū_s, so κ grows as m² (what it did to the vocal
// folds: fluid/README.md, runs/vocal-folds/README.md).
//
// body_divergence = "solid" lets the fluid in an elastic body take the body's divergence, as
// immersed methods for compressible solids have div u = J̇/J in the solid (Heltai & Costanzo
// 2012). The fluid then follows all of the body's motion a step late (the explicit coupling's
// lagged added mass ρ_f, which "zero" replaced by the damping ρ_f/Δt for the gradient motion),
// so it is for bodies much heavier than the fluid (fluid/README.md). In cell c
//   D u^(n+1) = S_c,   S_c = φ_c (D ū_s,c − d̄),   d̄ = Σ_c φ_c D ū_s,c |c| / Σ_c φ_c |c|,
// φ_c the smallest elastic α of the cell's four faces (1 inside a body, 0 in the fluid, between
// at the surface, continuous as the body moves: the body's share of the cell), D ū_s,c the
// divergence of the four faces' mean solid velocities (all four are solid faces where φ_c > 0),
// whatever the forcing made of them (Crank-Nicolson's solve moves the faces it forced), |c| the
// cell's area. With a pressure side the fluid outside takes the bodies' net volume change
// through it, and d̄ = 0. Without one (walls, periodic sides, inflows, outflows
// whose flux is set) the Poisson problem is singular and compatible only with Σ (D ũ − S) |c| =
// the boundary's net inflow, so d̄ takes the bodies' net volume change out (Σ S_c |c| = 0): in a
// closed box an incompressible fluid keeps the bodies' total volume, as it would physically. Then
//   L φ = (ρ/Δt) (D ũ − S)   (the right-hand side less k S_c in those cells).
// Rigid bodies keep the constraint (their ū_s is divergence-free on covered cells anyway), and so
// do the cells by a wall (its faces carry no α). This step's cells and φ_c are listed here, from
// the coupling input; project() uses and then forgets them.
//
// body_divergence = "coupled_step" keeps "zero"'s pressure per coupled step under sub-cycling.
// With m substeps of h = Δt/m and the fluid taking the share w of the divergence,
//   S_c = w φ_c (D ū_s,c − d̄),
// each projection adds (ρ/h)(1 − w) L⁻¹ φ D ū_s and the m of them (ρ m² (1 − w)/Δt) L⁻¹ φ D ū_s,
// which is one plain step's (ρ/Δt) L⁻¹ φ D ū_s for w = 1 − 1/m²: the penalty on the body's
// volume change stays ρ_f/Δt² whatever m, and m = 1 is "zero" itself. "solid" is w = 1.
double Solver::dilation_share(int substeps) const {
  switch (m_cfg.body_divergence) {
    case Config::BodyDivergence::solid: return 1.0;
    case Config::BodyDivergence::coupled_step: return 1.0 - 1.0 / (double(substeps) * substeps);
    case Config::BodyDivergence::zero: break;
  }
  return 0.0;
}

void Solver::dilating_cells(const CouplingIn& in) {
  m_dilating.clear();
  m_dilate_step = false;
  if (!(m_dilation_share > 0)) return;
  const std::span<const std::int32_t> idx[2] = {in.solid_u_index, in.solid_v_index};
  const std::span<const double> vel[2] = {in.solid_u_velocity, in.solid_v_velocity};
  const bool mixed[2] = {!in.solid_u_elastic.empty(), !in.solid_v_elastic.empty()};
  const std::span<const double> alpha[2] = {mixed[0] ? in.solid_u_elastic : in.solid_u_alpha,
                                            mixed[1] ? in.solid_v_elastic : in.solid_v_alpha};
  bool here = false;
  for (int c = 0; c < 2 && !here; ++c)
    here = std::any_of(alpha[c].begin(), alpha[c].end(), [](double a) { return a > 0; });
  // The halos below are collective: every rank goes on when any has elastic faces.
  if (!(m_dec.serial() ? here : m_dec.sum(here ? 1.0 : 0.0) > 0)) return;
  m_dilate_step = true;
  const int nx = m_grid.nx(), ny = m_grid.ny();
  const int lo = row_lo(), hi = row_hi();
  const double *xwi = m_grid.x().wi(), *ywi = m_grid.y().wi();
  // Per family the faces' elastic α and ū_s, zero where there is none.
  if (m_dil_alpha[0].a.empty())
    for (int c = 0; c < 2; ++c) {
      m_dil_alpha[c] = Field(nx + 1 - c, ny + c, lo, hi);
      m_dil_us[c] = Field(nx + 1 - c, ny + c, lo, hi);
      m_dil_body[c] = Field(nx + 1 - c, ny + c, lo, hi);
    }
  // With several bodies, a cell takes a divergence only when its four faces name one body: a
  // face that pieces of two cover carries their mean velocity, and a cell whose faces name two
  // bodies spans the gap between them; either way D ū_s there is the bodies' approach, not a
  // volume change (taken as one, it made a sink at the vocal folds' closing glottis:
  // fluid/README.md). m_dil_body holds body + 1 (0: several).
  const std::span<const std::int32_t> body[2] = {in.solid_u_body, in.solid_v_body};
  // (Whether the scene has several: a rank without faces has no list, and the halo below is
  // collective.)
  bool bodies = !body[0].empty() || !body[1].empty();
  if (!m_dec.serial()) bodies = m_dec.sum(bodies ? 1.0 : 0.0) > 0;
  for (int c = 0; c < 2; ++c)
    for (std::size_t q = 0; q < idx[c].size(); ++q)
      if (alpha[c][q] > 0) {
        const auto [i, j] = face_of(c, idx[c][q]);
        m_dil_alpha[c](i, j) = std::min(1.0, alpha[c][q]);
        m_dil_us[c](i, j) = vel[c][q];
        if (!body[c].empty()) m_dil_body[c](i, j) = body[c][q] + 1.0;
      }
  Field &au = m_dil_alpha[0], &av = m_dil_alpha[1], &us = m_dil_us[0], &vs = m_dil_us[1];
  Field &bu = m_dil_body[0], &bv = m_dil_body[1];
  // The v faces of row hi (the next slab's first, or across a periodic y); the duplicate faces
  // of a periodic direction carry face 0's values.
  if (!m_dec.serial()) {
    m_dec.halo(av), m_dec.halo(vs);
    if (bodies) m_dec.halo(bv);
  }
  if (m_grid.x().periodic())
    for (int j = lo; j < hi; ++j) au(nx, j) = au(0, j), us(nx, j) = us(0, j), bu(nx, j) = bu(0, j);
  if (m_grid.y().periodic() && m_dec.serial())
    for (int i = 0; i < nx; ++i) av(i, ny) = av(i, 0), vs(i, ny) = vs(i, 0), bv(i, ny) = bv(i, 0);
  // Each cell with φ > 0 has its west u face among the solid faces; D ū_s from its four faces.
  for (std::size_t q = 0; q < idx[0].size(); ++q) {
    const auto [i, j] = face_of(0, idx[0][q]);
    if (i >= nx || !(alpha[0][q] > 0)) continue;
    if (bodies) {
      const double b = bu(i, j);
      if (!(b > 0 && bu(i + 1, j) == b && bv(i, j) == b && bv(i, j + 1) == b)) continue;
    }
    const double phi = std::min(std::min(au(i, j), au(i + 1, j)), std::min(av(i, j), av(i, j + 1)));
    if (phi > 0)
      m_dilating.push_back(
          {i, j, phi, (us(i + 1, j) - us(i, j)) * xwi[i] + (vs(i, j + 1) - vs(i, j)) * ywi[j]});
  }
  // Back to zero for the next step: the faces written, the copies, the halo rows.
  for (int c = 0; c < 2; ++c)
    for (std::size_t q = 0; q < idx[c].size(); ++q) {
      const auto [i, j] = face_of(c, idx[c][q]);
      m_dil_alpha[c](i, j) = m_dil_us[c](i, j) = m_dil_body[c](i, j) = 0;
    }
  for (int j = lo; j < hi; ++j) au(nx, j) = us(nx, j) = bu(nx, j) = 0;
  for (int i = -1; i <= nx; ++i)
    av(i, hi) = av(i, lo - 1) = vs(i, hi) = vs(i, lo - 1) = bv(i, hi) = bv(i, lo - 1) = 0;
  // In row order, so that the sums below do not depend on the input's order or the ranks.
  std::sort(m_dilating.begin(), m_dilating.end(), [](const DilatingCell& x, const DilatingCell& y) {
    return x.j != y.j ? x.j < y.j : x.i < y.i;
  });
}

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
  // body_divergence = "solid", and "coupled_step" in a sub-cycled step: the cells inside elastic
  // bodies keep S_c, the share w of it (dilating_cells above), d̄ summed row by row in row order
  // (the same bits on any number of ranks).
  if (m_div_allowed.a.empty() && m_dilate_step) m_div_allowed = Field(nx, ny, lo, hi);
  for (const DilatingCell& c : m_dilated) m_div_allowed(c.i, c.j) = 0;
  if (m_dilate_step) {
    bool open = false;
    for (int side : {int(left), int(right), int(bottom), int(top)}) open |= m_bnd.is_pressure(side);
    double mean = 0;
    if (!open) {
      std::vector<double>& rows = m_dil_rows;
      rows.assign(std::size_t(3) * ny, 0.0);  // per row: Σ φ D ū_s |c|, Σ φ |c|; scratch
      for (const DilatingCell& c : m_dilating) {
        const double area = 1 / (xwi[c.i] * ywi[c.j]);
        rows[c.j] += c.phi * c.div * area;
        rows[ny + c.j] += c.phi * area;
      }
      if (!m_dec.serial())
        for (int q = 0; q < 2; ++q) {
          std::copy(rows.begin() + q * ny + lo, rows.begin() + q * ny + hi, rows.begin() + 2 * ny);
          m_dec.gather_all_rows(rows.data() + 2 * ny, rows.data() + q * ny);
        }
      double sums[2] = {0, 0};
      for (int j = 0; j < ny; ++j) sums[0] += rows[j], sums[1] += rows[ny + j];
      if (sums[1] > 0) mean = sums[0] / sums[1];
    }
    for (const DilatingCell& c : m_dilating) {
      const double allowed = m_dilation_share * c.phi * (c.div - mean);
      m_div_allowed(c.i, c.j) = allowed;
      buf[buf_index(c.i, c.j, 0, 0, nt)] -= k * allowed;
    }
  }
  m_dilated.swap(m_dilating);
  m_dilating.clear();
  m_dilate_step = false;
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
  m_sharp_kept.resize(m_sharp_sealed.size());
  for (std::size_t q = 0; q < m_sharp_sealed.size(); ++q)
    m_sharp_kept[q] = m_p(m_sharp_sealed[q] % nx, m_sharp_sealed[q] / nx);
  for (int j = lo; j < hi; ++j) {
    double* phi = m_phi.row(j);
    double* p = m_p.row(j);
    for (int i = 0; i < nx; ++i) {
      phi[i] = buf[buf_index(i, j, 0, 0, nt)];
      p[i] += phi[i];
    }
  }
  // interface = "sharp": the cells walled in by faces set whole keep p^n (sealed_cells()).
  for (std::size_t q = 0; q < m_sharp_sealed.size(); ++q)
    m_p(m_sharp_sealed[q] % nx, m_sharp_sealed[q] / nx) = m_sharp_kept[q];
  m_sharp_sealed.clear();
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
