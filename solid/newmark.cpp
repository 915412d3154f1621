// The Newmark step (paper Eq. 13-14; beta = 1/4, gamma = 1/2, the trapezoidal rule, unless the
// scene sets solid.newmark_gamma / newmark_beta): the predictor, Newton on the
// step's residual with contact (newton.cpp), the velocity and acceleration update; and the
// look-ahead factorisation of the next step's first matrix.
#include <cstdio>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

namespace {

// Failed attempts (of a step or of one of its parts) noted on stderr; later ones are not noted,
// the steps they cut are still counted (Solver::cut_steps).
constexpr long kCutbackNotes = 10;

}  // namespace

void Solver::keep_step_start() {
  for (auto& bp : m_bodies) {
    bp->u_old = bp->u;
    bp->v_old = bp->v;
  }
}

// The next step's first matrix, factorised while the fluid steps. Without active contact it is
// K_eff(x^n), which iteration 0 then solves with unassembled (m_ahead_fresh). With active
// contact iteration 0 assembles its matrix at x^n and adds the curvature of the slots active
// after its detection; the slots as the last step left them (its converged iterate is x^n) are
// those in most steps of a lasting contact, so their curvature is added here and the sum
// factorised: factorize_cached() then finds iteration 0's matrix factorised when its values
// agree bit for bit, and factorises it otherwise. Either way iteration 0 solves with the factor
// of its own matrix, so a step's result does not depend on the look-ahead. Curvature that
// would grow the pattern is left to the step: a slot first activated in an iteration that
// solved with a held factor (modified Newton adds no curvature there) may lack its entries, and
// the step then factorises at iteration 0.
void Solver::factorize_ahead(double dt) {
  m_ahead_fresh = false;
  if (m_bodies.empty() || m_neq == 0 || m_model.settings.analysis != Analysis::dynamic) return;
  const bool contact = any_contact_active();
  // The step starts with the factor it holds (newton.cpp, kKeepRatio): nothing to do ahead.
  if (m_keep_factor && m_factored_valid && m_contact.empty() && m_factored_c0 == newmark_c0(dt))
    return;
  keep_step_start();  // as advance() begins (the residual's inertia reads them)
  const auto inverted = assemble(newmark_c0(dt), dt, true, m_time + dt, nullptr);
  if (!m_residual.allFinite()) return;
  keep_ahead_residual(newmark_c0(dt), dt, m_time + dt, inverted);
  if (contact) {
    if (add_contact_curvature(newmark_c0(dt), dt, m_time + dt, nullptr, false))
      factorize_cached();
    return;
  }
  m_ahead_fresh = factorize_cached();
}

// One step t^n -> t^(n+1) = t^n + dt:
//   R(x) = F(t^(n+1)) - Q(x) - c0 M (x - x^n - dt v^n) + w_a (M a)^n + w_c F_c,
// (c0, w_a, w_c = 4/dt^2, 1, 2 in the trapezoidal rule; 1/(beta dt^2), (1/2 - beta)/beta,
// 1/(2 beta) otherwise), R(x^(n+1)) + B^T lambda = 0 with the contact conditions, then the
// velocity update (update_velocity).
// A step that fails (StepFailed) from the predicted iterate is taken again from x^n; one that
// fails from x^n is taken again from its start as two steps of dt/2 with the same external
// forces, each of which may be halved again, settings.step_cutbacks times at most
// (newmark_span); the step then ends at t^(n+1) as one step does.
StepReport Solver::advance(double dt, const std::vector<std::vector<double>>* external,
                           const std::vector<std::vector<double>>* iteration_velocity,
                           const std::vector<std::vector<double>>* root_mass) {
  m_failed_start_kept = false;
  m_predictor_off = false;
  if (!(dt > 0)) fsi::fail("time step must be > 0, got {}", dt);
  if (m_bodies.empty()) {  // a scene without bodies: only the clock moves
    m_time += dt;
    m_step++;
    StepReport none;
    none.converged = true;
    return none;
  }
  if (m_model.settings.analysis != Analysis::dynamic)
    fsi::fail("advance() needs a dynamic analysis");
  const double t1 = m_time + dt;
  const std::string when = fmt::format("step {} (t = {:.6g})", m_step + 1, t1);
  if (m_step == 0 && m_time == 0) initial_acceleration(dt);
  // Coupled iterations: the fluid's reaction is linearised about the coupler's velocity
  // (assembly.cpp); without a fluid there is no reaction to linearise.
  m_iteration_velocity = m_model.settings.fluid_density > 0 ? iteration_velocity : nullptr;
  m_root_mass = root_mass;
  if (!m_model.settings.trapezoidal()) {
    // The linearised reaction of coupled iterations and the fibers' root inertia are written for
    // the trapezoidal rule's velocity (assembly.cpp, Body::step_velocity).
    const bool root_masses = any_root_mass(root_mass);
    if (m_iteration_velocity || root_masses) {
      m_iteration_velocity = nullptr;
      m_root_mass = nullptr;
      fsi::fail("solid.newmark_gamma = {}, newmark_beta = {}: {} need the trapezoidal rule "
                "(newmark_gamma = 0.5, newmark_beta = 0.25)",
                m_model.settings.newmark_gamma, m_model.settings.newmark_beta,
                root_masses ? "fibers rooted on an elastic body" : "coupled iterations");
    }
  }
  StepReport rep;
  m_keep_allowed = m_model.settings.keep_factor && m_keep_permitted;
  if (!m_keep_allowed) m_keep_factor = false;
  // The linearised reaction of coupled iterations is about the velocity at t^(n+1): a step that
  // carries it is not cut.
  const int cutbacks = m_iteration_velocity ? 0 : m_model.settings.step_cutbacks;
  try {
    rep = newmark_span(dt, external, when, cutbacks, 1);
  } catch (...) {
    m_iteration_velocity = nullptr;
    m_root_mass = nullptr;
    m_keep_allowed = false;
    m_predictor_off = false;
    throw;
  }
  m_iteration_velocity = nullptr;
  m_root_mass = nullptr;
  m_keep_allowed = false;
  m_time = t1;
  m_step++;
  if (rep.substeps > 1) m_cut_steps++;
  return rep;
}

// One Newmark step of dt from the current state, or, when it fails and `cutbacks` > 0, two
// steps of dt/2 from the same start (each a span with one cutback less). `parts`: how many such
// steps the caller's step is cut into at this depth (1 for the whole step), for the messages.
// A step that failed from the predicted iterate (settings.predictor) is first taken again from
// x^n at the same dt: the predictor changes where Newton starts, not what the step solves, so a
// start it makes worse (a node predicted into a closing contact, an active set that cycles from
// there) must not cost the run a cutback, nor the run itself where no cutback is left.
// The contact forces left on the bodies are the mean over the span's steps: each is the force
// over its own step (Newmark: 2 beta lambda acts over the step, Eq. 13-14), so the mean has the
// span's impulse.
StepReport Solver::newmark_span(double dt, const std::vector<std::vector<double>>* external,
                                const std::string& when, int cutbacks, int parts) {
  StepState start;
  const bool may_predict = m_model.settings.predictor == Predictor::acceleration;
  if (cutbacks > 0 || may_predict) save_state(start);
  const std::string here =
      parts == 1 ? when : fmt::format("{}, cut into steps of dt/{} (this one from t = {:.9g})",
                                      when, parts, m_time);
  // Notes of retries from x^n and of cutbacks are limited separately: a run with the predictor
  // may retry often, and the cutbacks' notes are the ones that point at a problem.
  auto note = [&](const StepFailed& e, bool retry) {
    if ((retry ? m_retry_notes : m_cutback_notes)++ >= kCutbackNotes) return;
    const std::string what = e.what();
    const std::string then =
        retry ? std::string("taken again from the step's start without the predictor "
                            "(solid.predictor)")
              : fmt::format("taken again as two steps of dt/{}", 2 * parts);
    std::fprintf(stderr, "[solid] note: %s; %s\n", what.substr(0, what.find('\n')).c_str(),
                 then.c_str());
  };
  bool predicted = false;
  try {
    return newmark_step(dt, external, here);
  } catch (const StepFailed& e) {
    predicted = m_predictor_moved;
    if (!predicted && cutbacks == 0) throw;
    note(e, predicted);
  }
  if (predicted) {
    restore_state(start);
    // The failed attempt's last factor is not the matrix at x^n: iteration 0 must not keep it
    // (restore_state already drops a look-ahead of another state).
    m_keep_factor = false;
    m_predictor_off = true;  // advance() resets it should the retry throw anything else
    try {
      StepReport rep = newmark_step(dt, external, here);
      m_predictor_off = false;
      ++m_unpredicted_retries;
      return rep;
    } catch (const StepFailed& e) {
      m_predictor_off = false;
      if (cutbacks == 0) throw;
      note(e, false);
    }
  }
  restore_state(start);
  StepReport first, rep;
  std::vector<std::vector<double>> contact;
  std::vector<Vec2> contact_bodies;
  try {
    first = newmark_span(dt / 2, external, when, cutbacks - 1, 2 * parts);
    for (const auto& b : m_bodies) {
      contact.push_back(b->contact);
      contact_bodies.push_back(b->contact_bodies);
    }
    rep = newmark_span(dt / 2, external, when, cutbacks - 1, 2 * parts);
  } catch (const StepFailed&) {
    if (parts == 1) {  // the whole step failed: keep where it started (failed_step_start)
      m_failed_start = std::move(start);
      m_failed_start_kept = true;
    }
    throw;
  }
  for (std::size_t b = 0; b < m_bodies.size(); ++b) {
    for (std::size_t d = 0; d < contact[b].size(); ++d)
      m_bodies[b]->contact[d] = 0.5 * (contact[b][d] + m_bodies[b]->contact[d]);
    for (int i = 0; i < 2; ++i)
      m_bodies[b]->contact_bodies[i] = 0.5 * (contact_bodies[b][i] + m_bodies[b]->contact_bodies[i]);
  }
  rep.iterations += first.iterations;
  rep.assembly_seconds += first.assembly_seconds;
  rep.factor_seconds += first.factor_seconds;
  rep.solve_seconds += first.solve_seconds;
  rep.substeps += first.substeps;
  return rep;
}

// One Newmark step of dt from the current state, the clock moved to its end.
StepReport Solver::newmark_step(double dt, const std::vector<std::vector<double>>* external,
                                const std::string& when) {
  const double t1 = m_time + dt;
  predict(t1, dt, external);
  // Physical contact force per multiplier: the multiplier balances the residual, in which a
  // force acting over the step enters with the weight 1 / (2 beta) (as the coupling force does,
  // assembly.cpp): the force on the bodies is 2 beta lambda (lambda / 2 in the trapezoidal rule).
  m_contact_force_factor = 2 * m_model.settings.newmark_beta;
  StepReport rep = newton(newmark_c0(dt), dt, t1, external, when);
  // The next step's tangent (and its look-ahead factorisation) takes this step's root masses.
  m_root_mass_tangent = m_root_mass ? *m_root_mass : std::vector<std::vector<double>>{};
  update_velocity(dt);
  m_time = t1;
  check_finite(when);
  check_inverted(when);
  return rep;
}

// (M a)^0 = F^0 - Q(x^0) on the dofs that carry mass: the initial state starts in dynamic
// balance with the scene's loads.
void Solver::initial_acceleration(double dt) {
  assemble(0, dt, false, 0.0, nullptr);
  for (auto& bp : m_bodies)
    for (std::size_t d = 0; d < bp->ma.size(); ++d)
      bp->ma[d] = bp->is_elastic() && bp->mass_row[d] > 0 && bp->eq[d] >= 0
                      ? bp->f_ext[d] - bp->q[d]
                      : 0.0;
}

// The predictor. The step's start is kept (x^n, v^n), the rigid bodies are moved to t^(n+1), the
// prescribed displacements at t^(n+1) wait as an increment for the first solve, and the
// self-contact remembers what each node faces at x^n. Then, with settings.predictor =
// "acceleration", the elastic bodies' free dofs with mass move to the Newmark step taken with
// the forces of the step's start (a^(n+1) = a^n): in the residual (assembly.cpp) put
// (F - Q)^(n+1) = (F - Q)^n = (M a)^n and keep this step's coupling force F_c; no contact (no
// slot is active at the start). Eq. 13 with a^(n+1) = a^n gives, for any beta,
//   x = x^n + dt v^n + (dt^2 / 2) M^-1 ((M a)^n + F_c)
// (in the trapezoidal residual: (4/dt^2) M (x - x^n - dt v^n) = 2 ((M a)^n + F_c)),
// M the consistent mass on the free equations (factorize_mass; a lumped one leaves the rough
// part of the fluid's force in the first residual). Newton's first residual is then the change
// of F - Q over the step, not the step's whole inertia M v^n / (beta dt) (solid/README.md, "The
// predictor"). Dofs that share an equation (periodic partners) move together; massless ones
// (rho_s = rho_f: quasi-static) start at x^n. Not when a contact slot is active at the start
// (the contact force is the one part that changes sign within a step: a predicted node would be
// driven into the surface that stopped it), not in a step with a prescribed increment (a motion
// the Newmark step does not know of: the first solve applies it), not with fibers' root
// masses (the step's mass there is M + m_root, which M^-1 leaves out), nor when a term is not
// finite (Newton's first residual then names the cause). The coupled iterations' linearised
// reaction is left out (it vanishes at a converged iteration). Where the look-ahead's factor
// serves the step, the first iteration solves with the matrix at x^n (modified Newton), and a
// step without a fresh look-ahead makes that factor here, so that its bits do not depend on
// whether the look-ahead ran (a resumed run's first step).
void Solver::predict(double t1, double dt, const std::vector<std::vector<double>>* external) {
  m_predictor_moved = false;
  keep_step_start();
  update_rigid(t1);
  const bool prescribed_increment = prepare_prescribed(t1);
  remember_fronts();
  const bool root_masses = any_root_mass(m_root_mass);
  if (m_model.settings.predictor != Predictor::acceleration || m_predictor_off ||
      any_contact_active() ||
      prescribed_increment || root_masses)
    return;
  if (!m_ahead_fresh && !m_iteration_velocity && root_mass_tangent_lagged()) factorize_ahead(dt);
  if (!factorize_mass()) return;
  Eigen::VectorXd force = Eigen::VectorXd::Zero(m_neq), velocity = force;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    const std::vector<double>* fc = nullptr;
    if (external && static_cast<int>(external->size()) > B.index &&
        (*external)[B.index].size() == B.u.size())
      fc = &(*external)[B.index];
    for (std::size_t d = 0; d < B.u.size(); ++d) {
      const int e = B.eq[d];
      if (e < 0 || !(B.mass_row[d] > 0)) continue;
      force[e] += B.ma[d] + (fc ? (*fc)[d] : 0.0);
      velocity[e] = B.v_old[d];
    }
  }
  if (!force.allFinite()) return;
  // A massless equation has no velocity or force here and a decoupled row in M: it stays.
  const Eigen::VectorXd du = dt * velocity + 0.5 * dt * dt * m_mass_solver.solve(force);
  if (!du.allFinite() || du.isZero(0.0)) return;
  apply_newton_step(du);  // no prescribed increment is pending (above)
  m_predictor_moved = true;
}

// The mass matrix of the inertia (density rho_s - rho_f, as in the residual) on the free
// equations, its lower triangle factorised once (when the solver is built, for the predictor
// and for the velocity update of Newmark parameters other than the trapezoidal rule's, whose
// runs stop when it fails). An equation without mass
// (rho_s = rho_f) gets the mean diagonal of the others (no force: it does not move). False, with
// a note, when it cannot be factorised.
bool Solver::factorize_mass() {
  if (m_mass_state != 0) return m_mass_state > 0;
  Eigen::SparseMatrix<double> mass = m_matrix;
  std::fill_n(mass.valuePtr(), mass.nonZeros(), 0.0);
  add_mass(mass);
  double diagonal = 0;
  int count = 0;
  for (int e = 0; e < m_neq; ++e)
    if (const double d = mass.valuePtr()[matrix_index(e, e)]; d > 0) diagonal += d, ++count;
  const double placeholder = count > 0 ? diagonal / count : 1.0;
  for (int e = 0; e < m_neq; ++e)
    if (double& d = mass.valuePtr()[matrix_index(e, e)]; !(d > 0)) d = placeholder;
  m_mass_solver.analyze(mass);
  m_mass_state = m_mass_solver.factorize(mass) ? 1 : -1;
  if (m_mass_state < 0 && m_model.settings.predictor == Predictor::acceleration)
    std::fprintf(stderr, "[solid] note: the mass matrix is singular: solid.predictor = "
                         "\"acceleration\" is off for this run\n");
  return m_mass_state > 0;
}

// Self-contact: what each node faces at the step's start, and where (contact.cpp).
void Solver::remember_fronts() {
  std::vector<const std::vector<double>*> xs;
  for (const auto& b : m_bodies) xs.push_back(&b->x);
  m_contact.remember_fronts(xs, contact_gap_tolerance());
}

// Newmark velocity from the positions and (M a)^(n+1) = F - Q: the acceleration without the
// contact part (Eq. 13-16). With a = M^-1 (F - Q) and the step's impulse forces
// a_c = M^-1 (F_con + F_c) (contact and coupling: dt^2/2 a_c in x, dt a_c in v), Eq. 13 gives
//   dt^2 beta a^(n+1) = x^(n+1) - x^n - dt v^n - dt^2 (1/2 - beta) a^n - dt^2/2 a_c,
// and Eq. 14 with it
//   v^(n+1) = gamma / (beta dt) (x^(n+1) - x^n) + (1 - gamma / beta) v^n
//             + dt (1 - gamma / (2 beta)) M^-1 ((M a)^n + F_con + F_c),
// the trapezoidal rule's v^(n+1) = 2 (x^(n+1) - x^n) / dt - v^n when gamma = 2 beta = 1/2 (no
// solve). Otherwise M^-1 is the consistent mass on the free equations (factorize_mass), and a
// prescribed dof's a^n is taken as 0 (its M a is not kept): the positions stay those of Eq. 13
// (the error this leaves in the free velocities, M_ff^-1 M_fp a_p, and in the prescribed ones
// cancels in the residual), while the velocities next to a prescribed motion that accelerates
// are off by about dt a_p (beta / gamma - 1/2).
// Massless dofs (rho_s = rho_f) are quasi-static: v = (x^(n+1) - x^n) / dt, (M a) = 0.
void Solver::update_velocity(double dt) {
  const Settings& st = m_model.settings;
  Eigen::VectorXd accel;
  if (!st.trapezoidal()) {
    if (!factorize_mass())
      fsi::fail("solid.newmark_gamma = {}, newmark_beta = {}: the velocity update needs the mass "
                "matrix, which is singular; remove both keys (the trapezoidal rule)",
                st.newmark_gamma, st.newmark_beta);
    Eigen::VectorXd force = Eigen::VectorXd::Zero(m_neq);
    for (const auto& bp : m_bodies) {
      const Body& B = *bp;
      if (!B.is_elastic()) continue;
      for (std::size_t d = 0; d < B.u.size(); ++d)
        if (B.eq[d] >= 0 && B.mass_row[d] > 0)
          force[B.eq[d]] += B.ma[d] + B.contact[d] + B.f_cpl[d];
    }
    accel = m_mass_solver.solve(force);
  }
  const double cx = st.newmark_gamma / (st.newmark_beta * dt);
  const double cv = 1 - st.newmark_gamma / st.newmark_beta;
  const double ca = dt * (1 - st.newmark_gamma / (2 * st.newmark_beta));
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (std::size_t d = 0; d < B.u.size(); ++d) {
      if (B.mass_row[d] > 0) {
        if (st.trapezoidal())
          B.v[d] = 2 * (B.u[d] - B.u_old[d]) / dt - B.v_old[d];
        else
          B.v[d] = cx * (B.u[d] - B.u_old[d]) + cv * B.v_old[d] +
                   (B.eq[d] >= 0 ? ca * accel[B.eq[d]] : 0.0);
        B.ma[d] = B.eq[d] >= 0 ? B.f_ext[d] - B.q[d] : 0.0;
      } else {
        B.v[d] = (B.u[d] - B.u_old[d]) / dt;
        B.ma[d] = 0;
      }
    }
  }
}

}  // namespace solid
