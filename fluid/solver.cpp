// The fluid's time step as the paper's procedure (Sec. 3.3, step 4 of common/PROTOCOL.md):
// predictor, immersed-solid forcing, projection, samples; and the set-up of its operators. The
// steps themselves are in predictor.cpp, forcing.cpp and projection.cpp.
#include "solver.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "error.hpp"
#include "timer.hpp"

namespace fluid {
namespace {

enum class Loc { pressure, normal, tangential };

// The 1D operator along axis `ax` for a quantity at location `loc`, bounded by sides lo/hi; as a
// uniform transform direction without its rows.
//   pressure (cell centres, finite volume, zero normal gradient at walls):
//     row k: [(x_{k+1}-x_k)/d_{k+1} - (x_k-x_{k-1})/d_k] / w_k
//   normal velocity (faces 1..n-1, boundary faces given):
//     row f: [(x_{f+1}-x_f)/w_f - (x_f-x_{f-1})/w_{f-1}] / d_f
//   tangential velocity (cell centres, finite difference, ghost rule at the ends):
//     row k: [(x_{k+1}-x_k)/d_{k+1} - (x_k-x_{k-1})/d_k] * 2 / (c_{k+1} - c_{k-1})
Operator1D make_operator(const Axis& ax, Loc loc, bool transform, const Boundaries& b,
                         int side_lo) {
  Operator1D op;
  const int n = ax.n();
  op.h = ax.h();
  if (ax.periodic()) {
    op.n = n;
    op.lo = op.hi = Closure::periodic;
    return op;
  }
  const double *wi = ax.wi(), *di = ax.di(), *ci = ax.ci();
  if (loc == Loc::normal) {
    op.n = n - 1;
    op.lo = op.hi = Closure::dirichlet_node;
    if (transform && ax.uniform()) return op;
    op.a.resize(n - 1);
    op.b.resize(n - 1);
    op.c.resize(n - 1);
    for (int f = 1; f < n; ++f) {
      op.a[f - 1] = wi[f - 1] * di[f];
      op.c[f - 1] = wi[f] * di[f];
      op.b[f - 1] = -(op.a[f - 1] + op.c[f - 1]);
    }
    op.a[0] = 0;
    op.c[n - 2] = 0;
    return op;
  }
  op.n = n;
  op.a.resize(n);
  op.b.resize(n);
  op.c.resize(n);
  for (int k = 0; k < n; ++k) {
    const double s = loc == Loc::pressure ? wi[k] : ci[k];
    op.a[k] = di[k] * s;
    op.c[k] = di[k + 1] * s;
    op.b[k] = -(op.a[k] + op.c[k]);
  }
  if (loc == Loc::pressure) {
    // Zero normal gradient, or on a pressure side the value on the face: the ghost is
    // 2 phi_b - phi_0, its phi_b part on the right-hand side (Solver::project).
    const bool dlo = b.is_pressure(side_lo), dhi = b.is_pressure(side_lo + 1);
    op.lo = dlo ? Closure::dirichlet_half : Closure::neumann_half;
    op.hi = dhi ? Closure::dirichlet_half : Closure::neumann_half;
    op.b[0] = dlo ? -(op.c[0] + 2 * op.a[0]) : -op.c[0];
    op.b[n - 1] = dhi ? -(op.a[n - 1] + 2 * op.c[n - 1]) : -op.a[n - 1];
    op.singular = !dlo && !dhi;
  } else {
    for (int e = 0; e < 2; ++e) {
      const int side = side_lo + e;
      const bool slip = b.side(side).type == BcType::slip;
      (e == 0 ? op.lo : op.hi) = slip ? Closure::neumann_half : Closure::dirichlet_half;
      // Fold the ghost rule g = ga q0 + gb q1 (+ data, on the right-hand side) into the row.
      const GhostRule& r = b.rule(side);
      const int k = e == 0 ? 0 : n - 1, k1 = e == 0 ? 1 : n - 2;
      double& gcoef = e == 0 ? op.a[0] : op.c[n - 1];
      op.b[k] += gcoef * (r.is_data ? 0.0 : r.ga);
      (k1 > k ? op.c[k] : op.a[k]) += gcoef * (r.is_data ? 0.0 : r.gb);
      gcoef = 0;
    }
  }
  if (transform && ax.uniform()) {  // a stretched transform direction keeps its rows
    op.a.clear();
    op.b.clear();
    op.c.clear();
  }
  return op;
}

// The same operator as tridiagonal rows in any direction (the factored Helmholtz solve): a
// periodic direction (uniform) gets rows whose a[0] and c[n-1] wrap around.
Operator1D tridiagonal_operator(const Axis& ax, Loc loc, const Boundaries& b, int side_lo) {
  Operator1D op = make_operator(ax, loc, false, b, side_lo);
  if (op.lo != Closure::periodic) return op;
  const double k = 1.0 / (op.h * op.h);
  op.a.assign(op.n, k);
  op.c.assign(op.n, k);
  op.b.assign(op.n, -2 * k);
  return op;
}

}  // namespace

Solver::Solver(const Config& c, double dt, MPI_Comm comm)
    : m_cfg(c),
      m_grid(
          [&] {
            AxisSpec x = c.x;
            x.periodic = c.bc[left].type == BcType::periodic;
            return x;
          }(),
          [&] {
            AxisSpec y = c.y;
            y.periodic = c.bc[bottom].type == BcType::periodic;
            return y;
          }()),
      m_dec(comm, m_grid.ny(), m_grid.y().periodic(),
            fmt::format("fluid.grid.cells = [{}, {}] (in {}): its", c.x.cells, c.y.cells,
                        c.source)),
      m_bnd(m_grid, c.bc, m_dec),
      m_sponge(sponge_weights(m_grid, c.upwind_blend)) {
  validate(c, dt);
  if (c.sharp_interface && !m_dec.serial())
    throw fsi::InputError(fmt::format(
        "fluid.interface = \"sharp\" runs on one fluid rank, the job gives the fluid {}: set "
        "fluid.ranks = 1 or interface = \"volume\" (in {})",
        m_dec.ranks(), c.source));
  m_dilation_share = dilation_share(1);
  m_nu = c.viscosity / c.density;
  const int nx = m_grid.nx(), ny = m_grid.ny();
  // The transform axis: x where it is uniform, else y (stretched too: its eigenvectors).
  m_t_axis = m_grid.x().uniform() ? 0 : 1;
  m_i0 = m_grid.x().periodic() ? 0 : 1;
  m_j0 = m_grid.y().periodic() ? 0 : 1;
  m_iu0 = m_bnd.is_pressure(left) ? 0 : m_i0;
  m_iu1 = m_bnd.is_pressure(right) ? nx + 1 : nx;
  const int lo = m_dec.lo(), hi = m_dec.hi(), vhi = m_dec.v_hi();
  m_u = Field(nx + 1, ny, lo, hi);
  m_v = Field(nx, ny + 1, lo, vhi);
  m_p = Field(nx, ny, lo, hi);
  m_phi = Field(nx, ny, lo, hi);
  m_hu = m_hu_old = Field(nx + 1, ny, lo, hi);
  m_hv = m_hv_old = Field(nx, ny + 1, lo, vhi);

  const Axis& T = m_grid.axis(m_t_axis);
  const Axis& S = m_grid.axis(1 - m_t_axis);
  const int side_t = 2 * m_t_axis, side_s = 2 * (1 - m_t_axis);
  const Operator1D pt = make_operator(T, Loc::pressure, true, m_bnd, side_t);
  const Operator1D ps = make_operator(S, Loc::pressure, false, m_bnd, side_s);
  std::vector<double> w(S.n());
  for (int j = 0; j < S.n(); ++j) w[j] = S.width(j);
  if (m_dec.serial()) {
    m_poisson = std::make_unique<FastSolver>(pt, ps, 0.0);
    m_poisson->set_mean_weights(w);
  } else {
    m_slab_poisson = std::make_unique<SlabSolver>(pt, ps, 0.0, m_t_axis, ny, 0, comm);
    m_slab_poisson->set_mean_weights(w);
  }
  // u^n: body_viscosity = "none" has begin_step copy it once the footprint has faces of an
  // elastic body, and the α fields are made at the first such faces (body_viscosity.cpp), so a
  // run without elastic bodies has none.
  if (c.implicit) {
    m_un = Field(nx + 1, ny, lo, hi);
    m_vn = Field(nx, ny + 1, lo, vhi);
    m_lu = Field(nx + 1, ny, lo, hi);
    m_lv = Field(nx, ny + 1, lo, vhi);
    build_implicit(dt);
  }
  m_bnd.fill_ghosts(m_u, m_v);
  for (int s : {int(left), int(right)})
    if (m_bnd.is_pressure(s)) m_face_p[s].assign(ny, 0.0), m_phi_b[s].assign(ny, 0.0);
  face_pressure(m_t);
  m_bnd.fill_scalar(m_p, m_face_p);
}

Solver::~Solver() = default;

// p_b(t) per row; with `total`, p_b(t) - rho u^2 / 2 on the rows where u enters (u > 0 on the
// left face, u < 0 on the right), u the face's current normal velocity.
void Solver::face_pressure(double t) {
  const int nx = m_grid.nx();
  for (int s : {int(left), int(right)}) {
    if (!m_bnd.is_pressure(s)) continue;
    const SideBc& b = m_bnd.side(s);
    const double pb = b.boundary_pressure(t);
    const int i = s == left ? 0 : nx;
    const double inward = s == left ? 1.0 : -1.0;
    std::vector<double>& v = m_face_p[s];
    for (int j = row_lo(); j < row_hi(); ++j) {
      const double un = inward * m_u(i, j);
      v[j] = b.total && un > 0 ? pb - 0.5 * m_cfg.density * un * un : pb;
    }
  }
}

// Helmholtz operators of Crank-Nicolson: (L - 2/(nu dt)) for u and for v, solved exactly
// (FastSolver, SlabSolver) or factored along the grid lines (helmholtz = "factored"; in the
// same layout, the transform axis contiguous).
void Solver::build_implicit(double dt) {
  const double sigma = 2.0 / (m_nu * dt);
  const Axis& T = m_grid.axis(m_t_axis);
  const Axis& S = m_grid.axis(1 - m_t_axis);
  const int side_t = 2 * m_t_axis, side_s = 2 * (1 - m_t_axis);
  for (int comp = 0; comp < 2; ++comp) {
    const Loc lt = comp == m_t_axis ? Loc::normal : Loc::tangential;
    const Loc ls = comp == m_t_axis ? Loc::tangential : Loc::normal;
    if (m_cfg.factored_helmholtz) {
      auto& f = comp == 0 ? m_fact_u : m_fact_v;
      if (m_dec.serial()) {
        f = std::make_unique<FactoredSolver>(tridiagonal_operator(T, lt, m_bnd, side_t),
                                             tridiagonal_operator(S, ls, m_bnd, side_s), sigma);
      } else {
        // The slabs' layout: x contiguous whatever the transform axis; a padded row 0 for the v
        // faces between walls.
        const Loc lx = comp == 0 ? Loc::normal : Loc::tangential;
        const Loc ly = comp == 0 ? Loc::tangential : Loc::normal;
        f = std::make_unique<FactoredSolver>(
            tridiagonal_operator(m_grid.x(), lx, m_bnd, 0),
            tridiagonal_operator(m_grid.y(), ly, m_bnd, 2), sigma, m_dec.comm(), m_dec.lo(),
            m_dec.hi(), comp == 1 ? m_j0 : 0);
      }
      continue;
    }
    const Operator1D ot = make_operator(T, lt, true, m_bnd, side_t);
    const Operator1D os = make_operator(S, ls, false, m_bnd, side_s);
    if (m_dec.serial()) {
      (comp == 0 ? m_helm_u : m_helm_v) = std::make_unique<FastSolver>(ot, os, sigma);
    } else {
      // The v faces between walls have one unknown row fewer than the cells: a padded row 0.
      const int pad = comp == 1 ? m_j0 : 0;
      (comp == 0 ? m_slab_u : m_slab_v) = std::make_unique<SlabSolver>(
          ot, os, sigma, m_t_axis, m_grid.ny(), pad, m_dec.comm());
    }
  }
  m_dt_implicit = dt;
}

std::array<double, 2> Solver::body_acceleration(double t) const {
  const double s =
      m_cfg.period > 0 ? std::sin(2 * std::numbers::pi * t / m_cfg.period + m_cfg.phase) : 0.0;
  std::array<double, 2> a;
  for (int d = 0; d < 2; ++d) {
    a[d] = (m_cfg.body[d] + m_cfg.oscillating[d] * s) / m_cfg.density + m_cfg.gravity[d];
  }
  return a;
}

double* Solver::solve_data(int which) {
  if (which < 2 && m_fact_u) return (which == 0 ? *m_fact_u : *m_fact_v).data();
  if (m_dec.serial()) return (which == 0 ? *m_helm_u : which == 1 ? *m_helm_v : *m_poisson).data();
  return (which == 0 ? *m_slab_u : which == 1 ? *m_slab_v : *m_slab_poisson).data();
}

int Solver::solve_nt(int which) const {
  if (which < 2 && m_fact_u) return (which == 0 ? *m_fact_u : *m_fact_v).nt();
  if (m_dec.serial()) return (which == 0 ? *m_helm_u : which == 1 ? *m_helm_v : *m_poisson).nt();
  return (which == 0 ? *m_slab_u : which == 1 ? *m_slab_v : *m_slab_poisson).row_length();
}

std::size_t Solver::solve_size(int which) const {
  if (which < 2 && m_fact_u) return (which == 0 ? *m_fact_u : *m_fact_v).size();
  if (m_dec.serial()) {
    const FastSolver& f = which == 0 ? *m_helm_u : which == 1 ? *m_helm_v : *m_poisson;
    return std::size_t(f.nt()) * f.ns();
  }
  const SlabSolver& f = which == 0 ? *m_slab_u : which == 1 ? *m_slab_v : *m_slab_poisson;
  return std::size_t(f.row_length()) * (f.split().hi - f.split().lo);
}

Solver::TransposeTraffic Solver::transpose_traffic() const {
  TransposeTraffic t;
  for (const auto* s : {m_slab_poisson.get(), m_slab_u.get(), m_slab_v.get()}) {
    if (!s) continue;
    t.count += s->transposes();
    t.seconds += s->transpose_seconds();
    t.bytes += s->transpose_bytes();
  }
  return t;
}

void Solver::solve(int which) {
  if (which < 2 && m_fact_u) return (which == 0 ? *m_fact_u : *m_fact_v).solve();
  if (m_dec.serial()) return (which == 0 ? *m_helm_u : which == 1 ? *m_helm_v : *m_poisson).solve();
  (which == 0 ? *m_slab_u : which == 1 ? *m_slab_v : *m_slab_poisson).solve();
}

void Solver::step(double dt) {
  static const CouplingIn none{};
  CouplingOut out;
  step(dt, none, out);
}

void Solver::step(double dt, const CouplingIn& in, CouplingOut& out) {
  begin_step(dt);
  end_step(dt, in, out);
}

// The step's first part, which needs no coupling input: the explicit terms H(u^n), the boundary
// values at t^(n+1), and the predictor u~ without the fibers' force (Crank-Nicolson: its
// right-hand side B).
void Solver::begin_step(double dt) {
  if (!(dt > 0)) fsi::fail("fluid::Solver::step: dt must be > 0, got {}", dt);
  if (m_phase == Phase::begun)
    fsi::fail("fluid::Solver: a step was begun (begin_step) and not ended");
  {
    const PhaseTimer t(m_time.predictor, m_time.cpu);
    explicit_terms();
  }
  // u^n with t^n's boundary values and ghosts (predictor_implicit; remove_body_viscosity, while
  // the footprint has elastic faces: a scene without elastic bodies does not pay for the copy)
  m_un_kept = m_cfg.implicit || (m_cfg.bodies_inviscid && m_body_faces);
  if (m_un_kept) {
    const PhaseTimer t(m_time.predictor, m_time.cpu);
    m_un = m_u;
    m_vn = m_v;
  }
  {
    const PhaseTimer t(m_time.boundaries, m_time.cpu);
    m_bnd.advance_normal(m_u, m_v, m_t + dt, dt);
    if (m_cfg.implicit) m_bnd.fill_ghosts(m_u, m_v);  // Crank-Nicolson: ghosts of the new wall data
  }
  const PhaseTimer t(m_time.predictor, m_time.cpu);
  if (m_step == 0) m_dt_prev = dt;
  if (m_cfg.implicit) {
    if (dt != m_dt_implicit) build_implicit(dt);
    predictor_implicit(dt, m_t + 0.5 * dt);
  } else {
    predictor(dt, m_t + 0.5 * dt);
  }
  m_phase = Phase::begun;
  m_begun_dt = dt;
}

// The step's second part: the fibers' force f_f into the predictor (Crank-Nicolson: then its
// solve, with implicit_forcing = "increment" the forcing on its explicit prediction), u~ kept for
// a redo, then forcing, projection and samples.
void Solver::end_step(double dt, const CouplingIn& in, CouplingOut& out) {
  if (m_phase != Phase::begun || m_begun_dt != dt)
    fsi::fail("fluid::Solver::end_step: no step of this dt begun");
  {
    const PhaseTimer t(m_time.predictor, m_time.cpu);
    add_fiber_force(dt, in);
    remove_body_viscosity(dt, in);
    // implicit_forcing = "increment" keeps u^ before its solve, which a redo takes again with the
    // iteration's alpha and u_s; the forcing after the solve keeps u~.
    if (solve_in_redo()) keep_predictor();
    if (m_cfg.implicit) solve_implicit(in);
    if (!solve_in_redo()) keep_predictor();
  }
  correct(dt, in, out);
  ++m_time.steps;
}

// The solid's force of a sub-cycled step is the mean (1/m) sum_k f_k of its m steps: the
// impulse (dt/m) sum_k f_k the fluid received over the coupled step, divided by dt.
void Solver::end_substeps(double dt, int m, const CouplingIn& in, CouplingOut& out) {
  if (m == 1) return end_step(dt, in, out);
  if (m < 1) fsi::fail("fluid::Solver::end_substeps: {} substeps", m);
  // body_divergence = "coupled_step": the share of the bodies' divergence for m substeps, back to
  // a plain step's when they are done (also when one throws).
  struct Share {
    double& w;
    double plain;
    ~Share() { w = plain; }
  } share{m_dilation_share, dilation_share(1)};
  m_dilation_share = dilation_share(m);
  const double h = dt / m;
  m_force_sum[0].assign(in.solid_u_index.size(), 0.0);
  m_force_sum[1].assign(in.solid_v_index.size(), 0.0);
  for (int k = 0; k < m; ++k) {
    if (k > 0) begin_step(h);
    end_step(h, in, out);
    for (std::size_t q = 0; q < m_force_sum[0].size(); ++q)
      m_force_sum[0][q] += out.solid_u_force[q];
    for (std::size_t q = 0; q < m_force_sum[1].size(); ++q)
      m_force_sum[1][q] += out.solid_v_force[q];
  }
  for (std::size_t q = 0; q < m_force_sum[0].size(); ++q)
    out.solid_u_force[q] = m_force_sum[0][q] / m;
  for (std::size_t q = 0; q < m_force_sum[1].size(); ++q)
    out.solid_v_force[q] = m_force_sum[1][q] / m;
}

void Solver::redo_step(double dt, const CouplingIn& in, CouplingOut& out) {
  if (m_phase != Phase::redoable || dt != m_dt_prev)
    fsi::fail("fluid::Solver::redo_step: no step of this dt kept for a redo");
  restore_predictor();
  if (solve_in_redo()) {
    const PhaseTimer t(m_time.predictor, m_time.cpu);
    solve_implicit(in);
  }
  correct(dt, in, out);
  ++m_time.repeats;
}

// u~ (u^ before the increment's solve), p^n and the clock at the end of the predictor, for
// coupled iterations (redo_step).
void Solver::keep_predictor() {
  m_phase = m_keep_for_redo ? Phase::redoable : Phase::between_steps;
  if (m_keep_for_redo) {
    m_u_pred = m_u;
    m_v_pred = m_v;
    m_p_start = m_p;
  }
  m_t_start = m_t;
  m_dt_prev_start = m_dt_prev;
}

// Back to the end of the predictor: u~, p^n, the explicit terms in their step-n slots, t^n.
void Solver::restore_predictor() {
  m_u = m_u_pred;
  m_v = m_v_pred;
  m_p = m_p_start;
  std::swap(m_hu, m_hu_old);
  std::swap(m_hv, m_hv_old);
  m_t = m_t_start;
  m_dt_prev = m_dt_prev_start;
  --m_step;
}

// The step from u~ on: immersed forcing, projection, boundary ghosts, samples of u^(n+1); then
// t^n -> t^(n+1) (the explicit terms H^n become H^(n-1)).
void Solver::correct(double dt, const CouplingIn& in, CouplingOut& out) {
  {
    const PhaseTimer t(m_time.predictor, m_time.cpu);
    immersed_forcing(dt, in, out);
    dilating_cells(in);
  }
  project(dt, m_t + dt);
  {
    const PhaseTimer t(m_time.boundaries, m_time.cpu);
    m_bnd.fill_ghosts(m_u, m_v);
    sample(in, out);
  }
  std::swap(m_hu, m_hu_old);
  std::swap(m_hv, m_hv_old);
  m_dt_prev = dt;
  m_t += dt;
  ++m_step;
}

// u^(n+1) on the faces the coupler asked for (the fibers' and surface probes' stencils) and
// p^(n+1) in its cells, in its order.
void Solver::sample(const CouplingIn& in, CouplingOut& out) const {
  out.sample_p.resize(in.sample_p_index.size());
  for (std::size_t q = 0; q < in.sample_p_index.size(); ++q) {
    const std::int32_t c = in.sample_p_index[q];
    out.sample_p[q] = m_p(c % m_grid.nx(), owned(c / m_grid.nx(), 2));
  }
  out.sample_u.resize(in.sample_u_index.size());
  out.sample_v.resize(in.sample_v_index.size());
  for (std::size_t q = 0; q < in.sample_u_index.size(); ++q) {
    const auto [i, j] = face_of(0, in.sample_u_index[q]);
    out.sample_u[q] = m_u(i, owned(j, 0));
  }
  for (std::size_t q = 0; q < in.sample_v_index.size(); ++q) {
    const auto [i, j] = face_of(1, in.sample_v_index[q]);
    out.sample_v[q] = m_v(i, owned(j, 1));
  }
}

int Solver::owned(int j, int comp) const {
  if (m_dec.serial() || (comp == 1 ? m_dec.owns_v_row(j) : m_dec.owns_row(j))) return j;
  fsi::fail("fluid rank {}: the coupling input names a face or cell of row {}, which rank {} holds "
            "(this rank holds rows [{}, {}))",
            m_dec.rank(), j, m_dec.owner(j), m_dec.lo(), comp == 1 ? m_dec.v_hi() : m_dec.hi());
}

}  // namespace fluid
