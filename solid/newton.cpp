// Newton-Raphson for one Newmark step or one static load step, with the contact conditions
// linearised in every iteration (contact_solve.cpp): assemble the residual and tangent at the
// iterate, add the contact terms, test convergence, factorise and solve, update the iterate.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <limits>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

namespace {

// Halvings of a Newton step whose iterate leaves the material's domain (neo-Hookean J <= 0):
// 2^-12 of the step is well inside the last valid iterate's neighbourhood; beyond that the
// step is hopeless and the run stops.
constexpr int kMaxStepHalvings = 12;
// A residual that fell by less than this factor in one iteration no longer converges
// quadratically: it has reached its floor.
constexpr double kStallRatio = 0.5;
// The round-off floor of the residual relative to the terms that cancel in it (|F| + |Q| +
// |inertia| + |K| |u|): some thousand machine epsilons, the rounding a sum of many such terms
// accumulates.
constexpr double kRoundoffFloor = 1e-12;
// Contacts a failed step names (the active and penetrating ones, in slot order).
constexpr int kContactsNamed = 8;
// Residuals of the last iterations a failed step shows.
constexpr std::size_t kResidualsNamed = 5;
// A later iteration of a step solves with the factor of an earlier one (modified Newton) while
// the residual falls by at least this factor per iteration: the tangent then changes too little
// within the step to matter (a step of a body whose inertia term 4M/dt^2 dominates its
// stiffness); a slower fall factorises the current tangent. In contact too: the contact
// conditions are linearised afresh in every iteration (the gaps, B, the complementarity problem
// through the held factor), so only the tangent is an earlier one, its contact curvature that of
// the slots active when it was factorised; the contraction test covers both. Once such a reuse
// in contact has not contracted, the step's later iterations in contact factorise: the held
// tangent had sent the active set back to an earlier state, and reusing it again after the next
// fresh factor did the same (a Newton cycle of period three: residuals 6.3e6, 1.3e6, 7.5e3,
// 6.3e6, ... in the vocal folds at h = 0).
constexpr double kReuseRatio = 1e-2;
// A dynamic step starts with the factor the last step solved with (kept across steps) when that
// step's first solve cut the residual by at least this factor: the matrix of a body whose
// inertia 4M/dt^2 dominates its stiffness changes too little over a step to matter, and a kept
// factor saves the look-ahead factorisation. At this contraction a step needs at most about
// four solves (a residual 1e11 above its tolerance); a slower one factorises ahead again.
constexpr double kKeepRatio = 1e-3;

// A Newton solve whose residual comes back, within this relative difference, to its value two
// to kCyclePeriod iterations before cycles: detection's discrete choices (an edge or its
// neighbour, a vertex zone or its edge, a joined pair or two slots) send the iterate back and
// forth. From then on each contact keeps its feature (ContactSet::hold_features). Seen: a fold's
// node at a creased vertex, 2 % of an edge from it (the zone's border), the pseudo-normal and
// the edge's normal 52 degrees apart, a cycle of period four (residuals 1.8e4, 8.1e2, 1.4e1,
// 2.0e4, 1.8e4, ...) through every cutback (vocal folds at h = 0 with the predictor, t = 6.94).
constexpr double kCycleMatch = 1e-3;
constexpr std::size_t kCyclePeriod = 4;
// A state converged with held features may have a node this far (relative to its smallest
// surface edge) through a surface by detection without the hold: twice the vertex zone's radius
// (contact.cpp, kVertexZone), the most a joined pair's gap is off the distance (a zone's
// gap, to the plane through its vertex, is off it by up to 1.4 radii of that vertex's zone).
constexpr double kHeldGapSlack = 0.02;
// Holds noted on stderr; later ones are only counted (contact_feature_holds).
constexpr long kHoldNotes = 10;

// Whether the last residual repeats one of 2 to kCyclePeriod iterations before.
bool revisits(const std::vector<double>& r) {
  const std::size_t n = r.size();
  for (std::size_t p = 2; p <= kCyclePeriod && p < n; ++p)
    if (std::abs(r[n - 1] - r[n - 1 - p]) <= kCycleMatch * r[n - 1]) return true;
  return false;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

// Newton-Raphson on R(x) + B^T lambda = 0 with the contact conditions g(x) >= 0, lambda >= 0,
// lambda g = 0 (paper Eq. 3-5). Each iteration linearises both:
//   K_eff dx = R + B^T lambda,  g + B dx >= 0,  lambda >= 0,  lambda (g + B dx) = 0,
// solved through the factorised K_eff: y0 = K^-1 R, Y = K^-1 B^T, the complementarity problem
// for lambda with S = B Y, q = g + B y0 (solve_contact), then dx = y0 + Y lambda. The active
// set is the lambda > 0 of the last iteration. Converged when ||R + B^T lambda|| <= tol, no slot
// penetrates and every active gap is closed, both within the contact tolerance. Iterations after
// the first keep the factor while Newton contracts fast without it (kReuseRatio).
StepReport Solver::newton(double c0, double dt, double time_or_factor,
                          const std::vector<std::vector<double>>* external,
                          const std::string& when) {
  using clock = std::chrono::steady_clock;
  const auto& st = m_model.settings;
  StepReport rep;
  const double gap_tol = contact_gap_tolerance();
  Eigen::VectorXd dx(m_neq);
  double previous = std::numeric_limits<double>::infinity();
  bool contact_active_or_open = false;  // the last iteration had contact candidates
  const bool had_increment = m_dirichlet_pending;
  // The look-ahead factorised the matrix at the step's start x^n (factorize_ahead): iteration 0
  // solves with it and assembles the residual only. That matrix is the first iteration's when
  // the predictor moved no elastic node, no coupled iteration's velocities enter it, and every
  // body's root masses in it are the last step's (add_root_mass), which the look-ahead had too.
  // From a predicted iterate the factor is x^n's (modified Newton): over one step the tangent
  // changes by far less than its inertia part 4M/dt^2, and the contraction test below
  // (kReuseRatio) factorises afresh when it does not.
  const bool ahead = m_ahead_fresh && !m_iteration_velocity && root_mass_tangent_lagged();
  m_ahead_fresh = false;
  bool reused_in_contact = false;   // the last iteration solved with a held factor, in contact
  bool contact_reuse_failed = false;  // and its residual did not contract: no more reuse in contact
  // Features are held within this solve only (revisits below), however it ends.
  m_contact.hold_features(false);
  struct Release {
    ContactSet& set;
    ~Release() { set.hold_features(false); }
  } release{m_contact};

  for (int it = 0;; ++it) {
    auto t0 = clock::now();
    m_tangent_root_mass_now = it > 0;  // add_root_mass: the first tangent takes the last step's
    // The held factor serves this iteration (modified Newton) when it is valid, no prescribed
    // increment needs the matrix in the residual, and either this is a later iteration (kept
    // while it contracts fast, below, with or without contact), or a dynamic step's first
    // iteration without contact curvature in the factor's matrix or in this one (no slot active:
    // detection releases slots, only the complementarity problem activates them) with the
    // look-ahead's factor of this very matrix, or one after a step whose first solve contracted
    // by kKeepRatio. Such an iteration assembles the residual only; if the contraction then says
    // "factorise", the matrix and its contact curvature are assembled at the same iterate.
    const bool plain_factor = m_factored_valid && !m_factored_curved && !any_contact_active();
    const bool may_reuse =
        m_factored_valid && !m_dirichlet_pending &&
        (it > 0 ? plain_factor || !contact_reuse_failed
                : plain_factor && m_factored_c0 == c0 &&
                      (ahead || (m_keep_allowed && m_keep_factor && m_contact.empty())));
    // The first iteration without the matrix takes the look-ahead's residual when it is of this
    // state (take_ahead_residual), else assembles it.
    if (!(it == 0 && may_reuse && take_ahead_residual(c0, dt, time_or_factor, external, when)))
      assemble_iterate(c0, dt, time_or_factor, external, it > 0, dx, when, !may_reuse);
    rep.assembly_seconds += seconds_since(t0);
#ifndef NDEBUG
    if (it == 0 && may_reuse && ahead && !m_predictor_moved)
      check_ahead_matrix(c0, dt, time_or_factor, external);
#endif
    ContactLinearisation contact =
        linearise_contact(c0, dt, time_or_factor, external, !may_reuse);

    double rn = contact.residual.norm();
    rep.tolerance = st.newton_tolerance * m_force_scale;
    bool converged = is_converged(it, rn, previous, rep.tolerance, contact.worst_gap, gap_tol);
    if (converged && m_contact.holds_features() && !held_state_admissible(gap_tol)) {
      // Detection without the hold finds a node through the surface: Newton goes on from the
      // same iterate with that detection (the matrix keeps the held curvature).
      contact = linearise_contact(c0, dt, time_or_factor, external, false);
      rn = contact.residual.norm();
      converged = false;
      ++m_feature_holds_refused;
    }
    rep.residuals.push_back(rn);
    rep.active_contacts = contact.active;
    contact_active_or_open = !contact.candidates.empty();
    if (converged) {
      rep.converged = true;
      break;
    }
    if (it >= st.newton_max_iterations) break;
    // Once per solve: a hold whose state detection then refused goes on unheld.
    if (contact_active_or_open && rep.held_from == 0 && revisits(rep.residuals)) {
      m_contact.hold_features(true);
      rep.held_from = it + 1;
      if (++m_feature_holds <= kHoldNotes)
        std::fprintf(stderr,
                     "[solid] note: Newton came back to an earlier residual at %s in iteration "
                     "%d (%.3e): a cycle of contact choices; the contacts' features are held for "
                     "the rest of this solve%s\n",
                     when.c_str(), it, rn,
                     m_feature_holds == kHoldNotes ? " (further holds only counted in summary.json)"
                                                   : "");
    }
    // A first iteration that may reuse had no slot active, and detection activates none.
    FSI_ASSERT(!may_reuse || it > 0 || contact.active == 0);
    if (reused_in_contact && !(rn <= kReuseRatio * previous)) contact_reuse_failed = true;
    const bool reuse = may_reuse && (it == 0 || rn <= kReuseRatio * previous);
    reused_in_contact = reuse && !plain_factor;
    if (!reuse && may_reuse) {
      t0 = clock::now();
      assemble(c0, dt, true, time_or_factor, external);
      if (contact.active > 0) add_contact_curvature(c0, dt, time_or_factor, external);
      rep.assembly_seconds += seconds_since(t0);
    }
    previous = rn;

    t0 = clock::now();
    if (reuse)
      ++m_factor_reuses;
    else
      factorize(when);
    rep.factor_seconds += seconds_since(t0);
    t0 = clock::now();
    dx = m_linear.solve(m_residual);
    if (!contact.candidates.empty()) solve_contact(contact, gap_tol, dx);
    rep.solve_seconds += seconds_since(t0);
    apply_newton_step(dx);
    rep.iterations++;
  }
  // The next dynamic step keeps this step's last factor if its first solve contracted enough;
  // not after a step with a prescribed increment (the next one has one too, and its first matrix
  // is the look-ahead's to factorise), nor with contact (whose entries grow the pattern).
  const auto& r = rep.residuals;
  if (m_keep_allowed && r.size() >= 2)
    m_keep_factor = r[1] <= kKeepRatio * r[0] && !had_increment && m_contact.empty();

  m_tangent_root_mass_now = false;
  store_contact_forces();
  if (!rep.converged && contact_active_or_open) fail_contact_not_converged(rep, when, gap_tol);
  if (!rep.converged) fail_not_converged(rep, when);
  return rep;
}

// A state that converged with held features (hold_features) is taken when detection without the
// hold finds no node through a surface deeper than kHeldGapSlack of the smallest surface edge of
// the node's body or of the body it touches, the larger (the accepted gap, if larger still): the
// two detections differ at the border between features, where a held vertex zone's gap (a joined
// pair's: up to the zone's radius, a fraction of the master's edge; detect_self, detect_slot) and
// an edge's are two models of one contact. Taken, the slots keep the held features the state was
// solved with (its multipliers act along their normals); refused, they have the new detection
// and the hold is released.
bool Solver::held_state_admissible(double gap_tol) {
  std::vector<ContactSlot> held = m_contact.slots();
  m_contact.hold_features(false);
  detect_contacts();
  for (const auto& s : m_contact.slots()) {
    double edge = m_bodies[s.slave_body]->min_edge;
    if (s.master_body >= 0) edge = std::max(edge, m_bodies[s.master_body]->min_edge);
    const double slack = std::max(gap_tol, kHeldGapSlack * edge);
    if (s.gap < -slack) return false;
  }
  m_contact.slots() = std::move(held);
  return true;
}

// A step with contact that does not converge: which contacts (slave body and node, master body
// and feature, gap, multiplier), the residual history's tail, and what to change.
void Solver::fail_contact_not_converged(const StepReport& rep, const std::string& when,
                                        double gap_tol) const {
  std::string list;
  int shown = 0;
  for (const auto& s : m_contact.slots()) {
    if (!s.active && !(s.gap < 0)) continue;
    if (shown++ >= kContactsNamed) continue;
    const std::string master =
        s.master_body < 0 ? fmt::format("plane {}", s.plane)
        : s.m1 < 0 ? fmt::format("body '{}' node {}", m_bodies[s.master_body]->spec.name, s.m0)
                   : fmt::format("body '{}' edge ({}, {}) at {:.3g}",
                                 m_bodies[s.master_body]->spec.name, s.m0, s.m1, s.xi);
    list += fmt::format("\n  body '{}' node {} against {}: gap {:.3e}, multiplier {:.3e}{}",
                        m_bodies[s.slave_body]->spec.name, s.slave_node, master, s.gap,
                        s.lambda, s.active ? "" : " (inactive, penetrating)");
  }
  std::string history;
  const auto& r = rep.residuals;
  for (std::size_t k = r.size() > kResidualsNamed ? r.size() - kResidualsNamed : 0; k < r.size(); ++k)
    history += fmt::format("{}{:.3e}", history.empty() ? "" : ", ", r[k]);
  step_failed(
      "Newton did not converge in {} iterations at {} with contact: residual {:.3e} (the last "
      "iterations: {}), tolerance {:.3e}, accepted gap {:.3e}{}; {} active "
      "and penetrating contacts{}{}\nChange: solid.newton_max_iterations (now {}), "
      "solid.contact_tolerance (now {:g}, relative to the smallest surface edge), or a smaller "
      "[time] dt",
      rep.iterations, when, r.back(), history, rep.tolerance, gap_tol,
      rep.held_from > 0
          ? fmt::format("; a cycle: the contacts' features held from iteration {} on", rep.held_from)
          : "",
      shown, list,
      shown > kContactsNamed ? fmt::format("\n  ... and {} more", shown - kContactsNamed) : "",
      m_model.settings.newton_max_iterations, m_model.settings.contact_tolerance);
}

// The residual and tangent at the iterate. An iterate that leaves the material's domain
// (neo-Hookean J <= 0, a non-finite residual) is pulled back by halving the last step dx:
// x <- x - dx/2, x - 3 dx/4, ...; a residual still not finite stops the run.
void Solver::assemble_iterate(double c0, double dt, double time_or_factor,
                              const std::vector<std::vector<double>>* external, bool have_step,
                              Eigen::VectorXd& dx, const std::string& when, bool with_matrix) {
  auto inverted = assemble(c0, dt, with_matrix, time_or_factor, external);
  for (int halving = 0; have_step && !m_residual.allFinite() && halving < kMaxStepHalvings;
       ++halving) {
    dx *= 0.5;
    for (auto& bp : m_bodies) {
      Body& B = *bp;
      if (!B.is_elastic()) continue;
      for (std::size_t d = 0; d < B.u.size(); ++d)
        if (B.eq[d] >= 0) B.u[d] -= dx[B.eq[d]];
      B.sync_positions();
    }
    inverted = assemble(c0, dt, with_matrix, time_or_factor, external);
  }
  if (!m_residual.allFinite()) fail_non_finite_residual(inverted, when);
}

// Converged: ||R + B^T lambda|| below the tolerance, or stalled at its round-off floor after at
// least one solve; and no slot penetrates, every active gap is closed, no prescribed increment
// is still pending.
bool Solver::is_converged(int it, double rn, double previous, double tolerance, double worst_gap,
                          double gap_tol) const {
  const bool small = rn <= tolerance;
  const bool stalled =
      it > 0 && rn > kStallRatio * previous && rn <= kRoundoffFloor * m_roundoff_scale;
  return (small || stalled) && worst_gap <= gap_tol && !m_dirichlet_pending;
}

// x <- x + dx on the free equations; a pending prescribed increment is applied with the first.
void Solver::apply_newton_step(const Eigen::VectorXd& dx) {
  if (m_dirichlet_pending) apply_prescribed_step();
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (std::size_t d = 0; d < B.u.size(); ++d)
      if (B.eq[d] >= 0) B.u[d] += dx[B.eq[d]];
    B.sync_positions();
  }
}

// Every body given root masses this step has the last step's too: the first tangent takes those
// (add_root_mass), as the look-ahead, which has no current ones, did.
bool Solver::root_mass_tangent_lagged() const {
  if (!m_root_mass) return true;
  for (std::size_t b = 0; b < m_root_mass->size(); ++b)
    if (!(*m_root_mass)[b].empty() &&
        (m_root_mass_tangent.size() <= b || m_root_mass_tangent[b].empty()))
      return false;
  return true;
}

#ifndef NDEBUG
// Debug builds: the matrix iteration 0 would assemble is the look-ahead's bit for bit.
void Solver::check_ahead_matrix(double c0, double dt, double time_or_factor,
                                const std::vector<std::vector<double>>* external) {
  const Eigen::VectorXd residual = m_residual;
  const double force = m_force_scale, roundoff = m_roundoff_scale, floor = m_matrix_floor;
  assemble(c0, dt, true, time_or_factor, external);
  m_residual = residual;  // the same values; kept so that the check changes nothing
  m_force_scale = force, m_roundoff_scale = roundoff, m_matrix_floor = floor;
  const auto nnz = static_cast<std::size_t>(m_matrix.nonZeros());
  FSI_ASSERT(m_factored.size() == nnz &&
             std::memcmp(m_matrix.valuePtr(), m_factored.data(), nnz * sizeof(double)) == 0);
}
#endif

}  // namespace solid
