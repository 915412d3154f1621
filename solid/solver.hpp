// The solid solver: total-Lagrangian linear triangles for every elastic body, Newmark
// (beta = 1/4, gamma = 1/2) with Newton-Raphson each step or load-stepped statics, constraints
// (fixed, prescribed, periodic), gravity and external nodal loads, frictionless node-to-segment
// contact with Lagrange multipliers, rigid bodies with prescribed motion, eigenmodes.
// One sparse system holds every elastic body (contact couples them); its symbolic analysis is
// done once. Not thread-safe; no MPI.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "contact.hpp"
#include "error.hpp"
#include "element.hpp"
#include "linear_solver.hpp"
#include "model.hpp"

namespace solid {

// What one step (or one load step) did.
struct StepReport {
  int iterations = 0;             // Newton iterations (linear solves)
  std::vector<double> residuals;  // ||R|| at each iteration, first one before any solve
  double tolerance = 0;           // the residual target of this step
  bool converged = false;
  int active_contacts = 0;
  double assembly_seconds = 0, factor_seconds = 0, solve_seconds = 0;
  int substeps = 1;  // Newmark steps the step took (more than one after a cutback)
  int held_from = 0;  // the iteration from which a cycle held the contacts' features (0: none)
};

// A step the solver could not take: Newton did not converge, an element turned inside out, the
// state or the residual is not finite. advance() redoes such a step from x^n when it started
// from the predicted iterate (Settings::predictor), then in halves (Settings::step_cutbacks),
// before it gives up.
class StepFailed : public fsi::Error {
 public:
  using fsi::Error::Error;
};

template <class... Args>
[[noreturn]] void step_failed(fmt::format_string<Args...> f, Args&&... args) {
  throw StepFailed(fmt::format(f, std::forward<Args>(args)...));
}

// Eigenmodes of K phi = omega^2 M phi about the reference state (paper Eq. 28).
struct Modes {
  std::vector<double> omega;  // angular frequencies, ascending [rad / time]
  std::vector<std::vector<std::vector<double>>>
      shapes;  // [mode][body] nodal (x0, y0, ...), M-normalised
};

// The state a step starts from, for coupled iterations that redo a step: every body's
// displacements, velocities, M a, positions and contact forces, the contact slots (active set,
// multipliers), the clock. Opaque outside the solver.
struct StepState {
  std::vector<std::vector<double>> u, v, ma, x, contact;
  std::vector<std::vector<double>> root_mass_tangent;  // the root masses the tangent takes
  std::vector<ContactSlot> slots;
  double time = 0;
  long step = 0;
  double contact_force_factor = 1;
};

// The factor a dynamic step keeps for the next (checkpoints): the matrix values it was computed
// from, their inertia factor c0 (newmark_c0) and the round-off floor's matrix part at that time.
struct KeptFactor {
  std::vector<double> values;  // empty: none kept
  double c0 = 0;
  double matrix_floor = 0;
};

class Solver {
 public:
  // Validates the model (throws fsi::InputError for bad input), numbers the equations, builds
  // the sparse pattern and its symbolic factorisation, and sets the initial state (reference
  // configuration, initial velocities).
  explicit Solver(Model model, LinearSolver::Backend backend = LinearSolver::Backend::automatic);
  ~Solver();

  const Model& model() const { return m_model; }
  int num_bodies() const { return static_cast<int>(m_bodies.size()); }
  int body_index(const std::string& name) const;  // -1 when absent
  int num_equations() const { return m_neq; }
  double time() const { return m_time; }
  long step() const { return m_step; }
  std::string linear_backend() const { return m_linear.backend(); }

  // One Newmark step of size dt. external[b] (may be null or empty per body) holds nodal forces
  // on body b, layout (f0x, f0y, f1x, ...), force ON the solid, held over the step; they are
  // added to gravity and the scene's loads at t + dt. Throws fsi::Error when Newton fails, an
  // element inverts (det F <= 0) or a value is not finite; the message names body, element or
  // node, step and time.
  //
  // Coupled iterations: iteration_velocity[b] (may be null or empty per body) is the velocity
  // w at t + dt whose footprint the fluid's forcing used for `external`. When the scene has a
  // fluid (settings.fluid_density > 0) the step linearises the reaction about it (assembly.cpp):
  // a term that vanishes when the step returns v^(n+1) = w. Trapezoidal rule only: with other
  // Newmark parameters a step with these (or with root masses, below) throws.
  //
  // Fiber roots: root_mass[b] (may be null or empty per body) holds the fibers' root inertia,
  // a 2 x 2 block (m_xx, m_xy, m_yy) per node; the node then carries -m a^(n+1) with its own
  // acceleration over the step (assembly.cpp, add_root_mass).
  // Whether root masses (advance()'s root_mass, may be null) hold a non-zero value.
  static bool any_root_mass(const std::vector<std::vector<double>>* root_mass) {
    if (root_mass)
      for (const auto& m : *root_mass)
        for (double v : m)
          if (v != 0) return true;
    return false;
  }
  StepReport advance(double dt, const std::vector<std::vector<double>>* external = nullptr,
                     const std::vector<std::vector<double>>* iteration_velocity = nullptr,
                     const std::vector<std::vector<double>>* root_mass = nullptr);
  // Look-ahead: the first Newton matrix of the next dynamic step of size dt (at the current
  // state; forces enter only the residual), factorised now, while a coupled solid waits for its
  // forces. The step finds the factor done: a factorisation is skipped when the matrix equals
  // the last one factorised bit for bit (factorize()), so results do not change. A singular
  // matrix is left for the step to report.
  void factorize_ahead(double dt);
  long factor_reuses() const { return m_factor_reuses; }
  // Steps that failed whole and were taken in halves (settings.step_cutbacks).
  long cut_steps() const { return m_cut_steps; }
  // Steps (or parts) that failed from the predicted iterate and converged from x^n, since the
  // solver was made (not kept in checkpoints).
  long unpredicted_retries() const { return m_unpredicted_retries; }
  // Newton solves (steps or their parts) that cycled and held their contacts' features.
  long feature_holds() const { return m_feature_holds; }
  // ... whose converged state detection without the hold then refused (newton.cpp).
  long feature_holds_refused() const { return m_feature_holds_refused; }
  long factorizations() const { return m_factorizations; }
  // Times a contact working set grew within an iteration (solve_contact): a candidate the free
  // step left open was taken through by the constrained one.
  long contact_working_set_growths() const { return m_working_set_growths; }
  // Checkpoints: the values of the matrix whose factor the next step starts with, when it keeps
  // one (empty otherwise); a resumed run factorises them again, so it continues bit for bit.
  KeptFactor kept_factor() const;
  void restore_kept_factor(const KeptFactor& k);
  // Checkpoints: the entries contact added to the sparse pattern (pairs of equations). A resumed
  // run builds the same pattern, so its factor's ordering, and its round-off, are the same.
  // Restore them before the kept factor (a new pattern forgets the factor).
  std::vector<std::int64_t> contact_entries() const;
  void restore_contact_entries(const std::vector<std::int64_t>& pairs);
  // A step that the coupler may repeat (coupled iterations) starts from a fresh factor, so that a
  // repeat with the same forces gives the same bits (the kept factor is not part of StepState).
  void allow_kept_factor(bool allow) { m_keep_permitted = allow; }

  // Coupled iterations: keep the current state / go back to a kept one (then advance() redoes
  // the step from it and gives bit for bit what it gave the first time with the same forces).
  void save_state(StepState& s) const;
  void restore_state(const StepState& s);
  // After advance() failed with cutbacks: the state the failed step started from (the last
  // converged one), for the output of a stopped run; nullptr otherwise (no cutbacks: none kept).
  const StepState* failed_step_start() const { return m_failed_start_kept ? &m_failed_start : nullptr; }

  // Static analysis: the loads and prescribed displacements scaled by k / load_steps,
  // k = 1 ... load_steps, each solved by Newton. Returns the report of every load step.
  std::vector<StepReport> solve_static();
  // One static equilibrium at load factor `factor` from the current state.
  StepReport solve_static_step(double factor);

  // Current state of body b, layout (x0, y0, x1, y1, ...).
  const std::vector<double>& positions(int b) const;
  const std::vector<double>& velocities(int b) const;
  std::vector<double> displacements(int b) const;
  const Mesh& mesh(int b) const;
  BodyKind kind(int b) const;

  // Sets the velocity of body b (elastic: free dofs only, e.g. an initial mode shape).
  void set_velocity(int b, const std::vector<double>& v);
  // Sets the positions of body b (elastic; prescribed dofs keep their values).
  void set_positions(int b, const std::vector<double>& x);

  // Energies of the current state: kinetic 1/2 v^T M v (inertial density rho_s - rho_f),
  // strain sum A0 W, and the potential of gravity and the constant scene loads -F^T u.
  double kinetic_energy() const;
  double strain_energy() const;
  double load_potential() const;
  // Whether dof d (layout as positions) of elastic body b has no inertia (rho_s = rho_f): its
  // step is quasi-static, the coupling and contact forces balance the internal ones at t^(n+1).
  bool massless(int b, std::size_t d) const;

  // Per-element det F, von Mises stress (plane-strain Cauchy stress) of body b.
  std::vector<double> element_det_f(int b) const;
  std::vector<double> element_von_mises(int b) const;

  // Contact: the multiplier force on each surface node of body b (layout as positions; force ON
  // body b) and the normal contact pressure per node (force / tributary current length).
  const std::vector<double>& contact_forces(int b) const;
  std::vector<double> contact_pressure(int b) const;
  Vec2 total_contact_force(int b) const;
  // ... its part from the other bodies (contact pairs; not the planes, not self-contact)
  Vec2 contact_force_from_bodies(int b) const;
  double min_contact_gap()
      const;  // smallest signed gap over every contact candidate (+inf if none)

  // Support reaction on the prescribed nodes of boundary `name` of body b: the force the
  // support exerts on the body (sum over its constrained nodes).
  Vec2 reaction(int b, const std::string& boundary) const;

  // Lowest `count` eigenpairs of the linearised problem about the reference configuration
  // (stiffness at the reference state, constraints applied), by Spectra shift-invert about
  // `shift` (rad^2 / time^2). Needs a non-zero inertial density on every elastic element.
  Modes modes(int count, double shift = 0) const;

  // Nodal forces of body b from the scene's loads (gravity, tractions, point loads) at load
  // factor or time t; used by tests and diagnostics.
  std::vector<double> scene_loads(int b, double t) const;

 private:
  struct Body;
  void setup_body(int index);
  void number_equations();
  void build_pattern();
  int matrix_index(int row, int col) const;  // position in m_matrix's values, -1 if absent
  void update_prescribed(double t);
  bool prepare_prescribed(double t);
  void apply_prescribed_step();
  void update_rigid(double t);
  void add_scene_loads(const Body& body, double t, std::vector<double>& f) const;
  // Assembles R (free equations) and, when with_matrix, K_eff = K_T + c0 M into m_matrix.
  // Returns the first inverted element as (body, element) or (-1, -1).
  std::pair<int, int> assemble(double c0, double dt, bool with_matrix, double load_factor,
                               const std::vector<std::vector<double>>* external);
  void add_root_mass(Body& B, double dt, bool with_matrix, std::vector<double>& r,
                     std::vector<double>& absm);
  void set_coupling_force(Body& B, const std::vector<std::vector<double>>* external);
  void finish_residual(bool dynamic, bool with_matrix);
  void keep_ahead_residual(double c0, double dt, double time, std::pair<int, int> inverted);
  bool take_ahead_residual(double c0, double dt, double time,
                           const std::vector<std::vector<double>>* external,
                           const std::string& when);
  void check_initial_overlap();
  // Newton on the step's residual with contact (newton.cpp) and its parts.
  StepReport newton(double c0, double dt, double load_factor,
                    const std::vector<std::vector<double>>* external, const std::string& when);
  void assemble_iterate(double c0, double dt, double time_or_factor,
                        const std::vector<std::vector<double>>* external, bool have_step,
                        Eigen::VectorXd& dx, const std::string& when, bool with_matrix);
  bool is_converged(int it, double rn, double previous, double tolerance, double worst_gap,
                    double gap_tol) const;
  void apply_newton_step(const Eigen::VectorXd& dx);
  // The contact solve of a Newton iteration (contact_solve.cpp).
  struct ContactLinearisation;
  double contact_gap_tolerance() const;
  void detect_contacts();
  ContactLinearisation linearise_contact(double c0, double dt, double time_or_factor,
                                         const std::vector<std::vector<double>>* external,
                                         bool with_curvature);
  bool add_contact_curvature(double c0, double dt, double time_or_factor,
                             const std::vector<std::vector<double>>* external,
                             bool may_grow = true);
  void solve_contact(const ContactLinearisation& con, double gap_tol, Eigen::VectorXd& dx);
  void store_contact_forces();
  bool any_contact_active() const;
  bool root_mass_tangent_lagged() const;
#ifndef NDEBUG
  void check_ahead_matrix(double c0, double dt, double time_or_factor,
                          const std::vector<std::vector<double>>* external);
#endif
  void factorize(const std::string& when);
  bool factorize_cached();
  // The Newmark step's parts (newmark.cpp).
  void initial_acceleration(double dt);
  void predict(double t1, double dt, const std::vector<std::vector<double>>* external);
  void remember_fronts();
  bool factorize_mass();
  void add_mass(Eigen::SparseMatrix<double>& M) const;
  StepReport newmark_span(double dt, const std::vector<std::vector<double>>* external,
                          const std::string& when, int cutbacks, int parts);
  StepReport newmark_step(double dt, const std::vector<std::vector<double>>* external,
                          const std::string& when);
  void update_velocity(double dt);
  // u_old, v_old := u, v: the state the coming step starts from.
  void keep_step_start();
  // The Newmark inertia factor of the effective matrix, c0 = 1 / (beta dt^2) (4 / dt^2 in the
  // trapezoidal rule): one expression for advance() and factorize_ahead(), whose matrices must
  // agree bit for bit.
  double newmark_c0(double dt) const {
    return m_model.settings.trapezoidal() ? 4 / (dt * dt)
                                          : 1 / (m_model.settings.newmark_beta * dt * dt);
  }
  // The weights of (M a)^n and of a force acting as an impulse over the step (coupling,
  // contact) in the Newmark residual of a dof with mass (assembly.cpp): (1/2 - beta) / beta and
  // 1 / (2 beta), 1 and 2 in the trapezoidal rule.
  double newmark_ma_weight() const {
    const double b = m_model.settings.newmark_beta;
    return (0.5 - b) / b;
  }
  double newmark_impulse_weight() const { return 0.5 / m_model.settings.newmark_beta; }
  [[noreturn]] void fail_health(const std::string& what, int body, int element,
                                const std::string& when) const;
  void check_finite(const std::string& when) const;
  void check_inverted(const std::string& when) const;
  [[noreturn]] void fail_non_finite_residual(std::pair<int, int> inverted,
                                             const std::string& when) const;
  [[noreturn]] void fail_not_converged(const StepReport& rep, const std::string& when) const;
  bool held_state_admissible(double gap_tol);
  [[noreturn]] void fail_contact_not_converged(const StepReport& rep, const std::string& when,
                                               double gap_tol) const;

  Model m_model;
  std::vector<std::unique_ptr<Body>> m_bodies;
  int m_neq = 0;
  double m_time = 0;
  long m_step = 0;
  double m_force_scale = 0;              // norm of |F_ext| + |Q| + |inertia| from the last assembly
  double m_roundoff_scale = 0;           // the same with the terms of c0 M u: the round-off floor
  double m_matrix_floor = 0;  // the floor's |K| |u| part is known from matrix assemblies only
  Eigen::SparseMatrix<double> m_matrix;  // lower triangle of K_eff on the free equations
  std::set<std::pair<int, int>> m_contact_entries;  // extra (row, col) entries contact needs
  Eigen::VectorXd m_residual;
  LinearSolver m_linear;
  std::vector<double> m_factored;  // values of the matrix m_linear holds the factor of
  bool m_factored_valid = false;
  long m_factor_reuses = 0;
  long m_factorizations = 0;
  long m_working_set_growths = 0;
  long m_cut_steps = 0, m_cutback_notes = 0;  // advance(): steps cut back, notes printed
  long m_retry_notes = 0;                      // notes printed of steps taken again from x^n
  StepState m_failed_start;  // failed_step_start()
  bool m_failed_start_kept = false;
  // A dynamic step may start with the factor the last one solved with (newton.cpp, kKeepRatio):
  // allowed during advance(), earned by the last step's first contraction.
  bool m_keep_allowed = false;
  bool m_keep_factor = false;
  bool m_keep_permitted = true;  // allow_kept_factor
  double m_matrix_c0 = 0;        // the inertia factor c0 (newmark_c0) of the last matrix
  double m_factored_c0 = 0;      // ... and of the matrix factorised
  bool m_matrix_curved = false;    // the matrix holds contact curvature (add_contact_curvature)
  bool m_factored_curved = false;  // ... and the matrix factorised
  // factorize_ahead() factorised (or found factorised) this step's first matrix: the state the
  // step starts from, its c0, no active contact. Read and cleared by the step's newton().
  bool m_ahead_fresh = false;
  // The look-ahead's residual without the coupling force and the state it is of
  // (keep_ahead_residual, take_ahead_residual); any other assembly overwrites it.
  struct AheadResidual {
    bool valid = false;
    double c0 = 0, dt = 0, time = 0;
    std::pair<int, int> inverted{-1, -1};
    std::vector<std::vector<double>> u, v, ma;  // per body: x^n - X, v^n, (M a)^n
  } m_ahead_residual;
  bool m_predictor_moved = false;  // predict() moved an elastic node off x^n this step
  bool m_predictor_off = false;    // newmark_span(): a failed predicted step taken from x^n
  long m_unpredicted_retries = 0;  // steps that failed predicted and converged from x^n
  long m_feature_holds = 0;         // Newton solves that held their contacts' features
  long m_feature_holds_refused = 0;  // ... and whose held state was refused
  LinearSolver m_mass_solver;      // the mass matrix on the free equations (factorize_mass)
  int m_mass_state = 0;            // 0: not factorised yet, 1: factorised, -1: singular
  ContactSet m_contact;
  double m_contact_force_factor = 1;  // physical contact force / multiplier (2 beta in Newmark)
  bool m_dirichlet_pending = false;   // a prescribed increment awaits the first Newton solve
  const std::vector<std::vector<double>>* m_iteration_velocity = nullptr;  // during advance()
  const std::vector<std::vector<double>>* m_root_mass = nullptr;            // during advance()
  // The root masses in the tangent: those of the previous step (assembly.cpp, add_root_mass).
  std::vector<std::vector<double>> m_root_mass_tangent;
  bool m_tangent_root_mass_now = false;  // later Newton iterations: the tangent takes the current
};

}  // namespace solid
