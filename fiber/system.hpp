// The fiber solver: every fiber of a scene as a chain of Lagrangian markers at uniform arclength
// ds, advanced by the explicit scheme of Huang, Shin & Sung (JCP 226, 2007) with the tension from
// the discrete pseudo-Poisson equation (paper Eq. 17), bending, repulsion (Eq. 11-12), gravity,
// external forces and every end condition. This header is also the coupling hook the coupler uses.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "cell_list.hpp"
#include "h5.hpp"
#include "spec.hpp"

namespace fiber {

// Pose of a supported end: position and unit direction X_s (pointing into the fiber at the root).
struct EndPose {
  Vec2 position = Vec2::Zero();
  Vec2 direction = Vec2::UnitX();
};

// Load a fiber exerts ON ITS SUPPORT at one end: force and moment (counter-clockwise positive)
// about the end marker. Zero at a free end. At a supported root also the force's linear response
// to the root's acceleration a, force ~ force_0 - mass a (the fiber's inertia that the support
// carries: about the whole fiber's mass along a straight fiber, the end marker's across it),
// and the acceleration a this force was taken at; a support that moves by its own equations can
// take the inertia implicitly (common/PROTOCOL.md, "Fiber roots").
struct EndLoad {
  Vec2 force = Vec2::Zero();
  double moment = 0;
  Eigen::Matrix2d mass = Eigen::Matrix2d::Zero();
  Vec2 accel = Vec2::Zero();
};

// Wall time spent in each phase of a step, accumulated since construction [s].
struct PhaseTimes {
  double forces = 0;   // bending, gravity, external forces, repulsion, predictor
  double tension = 0;  // the tension equation (Newton on |X_s| = 1)
  double update = 0;   // position update, end loads, health checks
  long steps = 0;
  long tension_solves = 0;  // tridiagonal solves (Newton steps), summed over fibers and sub-steps
};

// Explicit bending limit of one fiber: the scheme (bending at X* = 2X^n - X^(n-1)) is stable for
// dt^2 lambda_max <= 4/3 and lambda_max <= 16 gamma / (rho' ds^4), so dt <= ds^2 sqrt(rho'/(12 gamma)).
// Infinite without bending or for a prescribed fiber.
double bending_dt_limit(const FiberSpec& f);

// Empty when dt / substeps is within every fiber's bending limit; otherwise the message (it
// states the limit and the fix).
std::string time_step_problem(const Config& config, double dt);

class FiberSystem {
 public:
  // Lays out the markers of every fiber. Throws fsi::InputError for fibers that start
  // overlapping or a `points` shape that is not at uniform arclength.
  explicit FiberSystem(Config config);

  // ---- layout (fixed for the run) ----------------------------------------------------------
  const Config& config() const { return m_config; }
  int fiber_count() const { return static_cast<int>(m_fibers.size()); }
  int marker_count(int k) const { return m_fibers[k].segments + 1; }
  std::size_t total_markers() const { return m_mass.size(); }
  // Index of fiber k's first marker in the flat arrays that hold all fibers one after another.
  std::size_t marker_offset(int k) const { return m_fibers[k].offset; }
  double ds(int k) const { return m_fibers[k].ds; }
  EndKind root_kind(int k) const { return m_config.fibers[k].root.kind; }
  EndKind tip_kind(int k) const { return m_config.fibers[k].tip.kind; }
  // Arclength a marker stands for: ds, and ds/2 at the two end markers. The coupler spreads a
  // marker's force per unit length with this weight so that action = reaction.
  double marker_arclength(int k, int i) const;

  // ---- state -----------------------------------------------------------------------------------
  double time() const { return m_time; }
  long step_count() const { return m_steps; }
  // X^n of fiber k (or of all fibers), flattened x0, y0, x1, y1, ...
  std::span<const double> positions(int k) const;
  std::span<const double> positions() const { return m_x; }
  // X^(n-1): the positions one time step of the scene (not one sub-step) earlier.
  std::span<const double> previous_positions(int k) const;
  std::span<const double> previous_positions() const { return m_x_step_old; }
  // Tension T on fiber k's segments (segment j joins markers j and j+1) from the last step [force].
  std::span<const double> segment_tension(int k) const;

  // ---- the step ----------------------------------------------------------------------------
  // Advance t^n -> t^n + dt in config().substeps fiber steps.
  // external_force: per unit length ON THE FIBER at every marker of every fiber, flattened like
  //   positions() (2 per marker), held constant over the step; empty for none.
  // root_poses: one per fiber, the pose at t^(n+1) of attached roots (entries of other fibers are
  //   ignored); may be empty when no fiber is attached.
  // Throws fsi::Error when a fiber stretches beyond config().stretch_limit or a value is NaN.
  void advance(double dt, std::span<const double> external_force = {},
               std::span<const EndPose> root_poses = {});
  // Load on the support of fiber k's root (s = 0) and tip (s = L), averaged over the last step:
  // the force and moment the fiber exerts on what holds it. For a prescribed fiber the root load
  // is the load on its driver, about the root marker.
  EndLoad root_load(int k) const { return m_fibers[k].root_load; }
  EndLoad tip_load(int k) const { return m_fibers[k].tip_load; }
  // Set-up only (before the first step): lay an attached fiber out straight from its root pose.
  void place_root(int k, const EndPose& pose);

  // ---- diagnostics -----------------------------------------------------------------------
  double dt_limit(int k) const { return bending_dt_limit(m_config.fibers[k]); }
  // max over segments of | |X_{j+1} - X_j| / ds - 1 |, over fiber k or all fibers.
  double max_stretch(int k) const;
  double max_stretch() const;
  // Per marker of fiber k: tension (mean of the adjacent segments; 0 at a free end) and signed
  // curvature (turning angle per ds; at a clamped end from the ghost marker).
  void marker_tension(int k, std::vector<double>& out) const;
  void marker_curvature(int k, std::vector<double>& out) const;
  // Newton iterations of fiber k's tension equation in the last sub-step.
  int tension_iterations(int k) const { return m_fibers[k].tension_iterations; }
  // Kinetic energy of fiber k from the last step's velocity (X^n - X^(n-1)) / h.
  double kinetic_energy(int k) const;
  const PhaseTimes& phase_times() const { return m_times; }
  void reset_phase_times() { m_times = PhaseTimes{}; }
  // Checkpoints (checkpoint.cpp), between steps: positions X^n, X^(n-1) and the sub-steps' own
  // history, tensions (the next tension solve starts from them), root poses and loads, clock.
  void save(fsi::H5File& h5) const;
  void load(const fsi::H5File& h5);

 private:
  struct Fiber {
    int segments = 0;
    double ds = 0;
    std::size_t offset = 0;      // first marker
    std::size_t seg_offset = 0;  // first segment
    bool is_prescribed = false;
    bool is_root_fixed = false, is_tip_fixed = false;
    EndPose root_pose_old, root_pose_new;  // attached roots: pose at t^n and t^(n+1)
    EndLoad root_load, tip_load;
    double root_moment = 0, tip_moment = 0;  // bending moment on clamped supports, this sub-step
    int tension_iterations = 0;
  };

  void substep(double h, double t_new, double pose_weight, std::span<const double> external_force);
  void predict(int k, double h, double theta, double t_new, double pose_weight,
               std::span<const double> external_force);
  void solve_tension(int k);
  void end_loads(int k, double h);
  Eigen::Matrix2d root_mass(int k, double h) const;
  void prescribed_load(int k, double h, std::span<const double> external_force);
  void prescribe(int k, double t, std::span<double> x) const;
  EndPose end_pose(int k, bool is_root, double t, double pose_weight) const;
  void repulsion_forces();
  void check_health() const;

  Config m_config;
  std::vector<Fiber> m_fibers;
  double m_time = 0;
  long m_steps = 0;
  long m_substeps_done = 0;
  double m_last_h = 0;
  double m_sub_time = 0;

  // Flat over all markers (2 per marker) or all segments (1 per segment).
  std::vector<double> m_x, m_x_old, m_x_new, m_x_star, m_x_step_old, m_x_initial;
  std::vector<double> m_force;      // forces on the markers in this step [force]
  std::vector<double> m_repulsion;  // repulsion per unit length at the markers
  std::vector<double> m_mass;       // lumped marker mass rho' ds w_i
  std::vector<double> m_weight;     // arclength of each marker ds w_i
  std::vector<int> m_owner;         // fiber of each marker
  std::vector<double> m_tension;    // per segment
  std::vector<double> m_coef;       // per marker: theta h^2 / (m_i ds), 0 for law-driven markers
  std::vector<double> m_ref;        // per segment: reference direction d^n (2 per segment)
  std::vector<double> m_lo, m_di, m_up, m_rhs;  // tridiagonal work, per segment
  std::vector<EndLoad> m_root_acc, m_tip_acc;  // loads summed over the sub-steps of a step
  CellList m_cells;
  PhaseTimes m_times;
};

}  // namespace fiber
