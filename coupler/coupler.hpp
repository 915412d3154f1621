// The coupler: the clock of a coupled run and every Euler-Lagrange transfer between the fluid,
// the solids and the fibers (the paper's Sec. 3.2 and 3.3). It knows the fluid only through the
// grid the fluid describes at set-up, and the solids and fibers only through their meshes and
// markers.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "acceleration.hpp"
#include "exchange_log.hpp"
#include "fluid_ranks.hpp"
#include "ib.hpp"
#include "immersed.hpp"
#include "probes.hpp"
#include "progress.hpp"
#include "protocol.hpp"
#include "runtime.hpp"
#include "summary.hpp"
#include "surface.hpp"

namespace coupler {

namespace proto = fsi::proto;

// Larger than any length or distance of a scene: the start of a search for the smallest one.
inline constexpr double kFar = 1e300;

class Coupler {
 public:
  // Reads the [coupler] table of the scene (setup.cpp).
  explicit Coupler(fsi::Runtime& rt);
  // Set-up exchange, every step of the scene, then the end of the run and summary.json.
  // Collective over the job.
  void run();

 private:
  // The clock and the step (coupler.cpp).
  void step(long n);
  void begin_step(long n);
  void footprint();
  void begin_solid_step(long n);
  void fluid(long n);
  void reaction();
  void solid(long n);
  void iterate(long n);
  double residual();
  void next_estimate();
  void count_iterations(long n);
  void commit(long n);
  void fibers(long n);
  void report(long n);
  // The end of the run after `steps` steps (computed from step `first` on).
  void finish(long steps, long first);
  // Checkpoint and restart (checkpoint.cpp): what the next step reads beyond the solvers' states.
  void save(fsi::H5File& h5) const;
  void load(const fsi::H5File& h5);
  bool has(fsi::Role r) const { return m_rt.roles()[r]; }
  bool iterates() const { return m_accel && m_immersed; }
  // The state the footprint is taken from: x^n with v^n (explicit step) or with the current
  // estimate of v^(n+1) (coupled iterations).
  const proto::SolidState& footprint_state() const { return iterates() ? m_guess : m_start; }
  void gather_velocities(const proto::SolidState& s, std::vector<double>& x) const;
  void scatter_velocities(const std::vector<double>& x, proto::SolidState& s) const;
  template <class In, class Out>
  void exchange(fsi::Role r, const In& in, Out& out, long n);
  // Set-up and input (setup.cpp).
  void setup();
  void read_iterations(const fsi::SceneTable& t);
  void check_can_iterate() const;
  void check_immersed_forcing_keys() const;  // fluid.forcing_time, fluid.interface
  void write_effective_scene() const;
  std::string body_names() const;
  // The fibers' feedback force (feedback.cpp).
  void default_kappa();
  void feedback_forces();
  // Health checks (health.cpp).
  const char* outside(double x, double y) const;
  void check_bodies_in_domain(long step) const;
  void check_fibers_in_domain(long step) const;
  void check_growth(long step);
  void warn_element_sizes() const;
  void warn_marker_spacing() const;
  // Fiber roots on bodies (roots.cpp).
  void resolve_roots();
  void root_poses(const proto::SolidState& state, std::vector<std::vector<double>>& poses) const;
  void add_root_loads(const proto::SolidState& state);
  std::vector<double> root_loads_without_inertia() const;
  // Force probes (probes.cpp).
  void setup_force_probes();
  void write_force_probes(long step, const proto::SolidState& start,
                          const std::vector<std::vector<double>>& reaction);
  // Surface probes (surface_probes.cpp; the method in surface.hpp).
  void setup_surface_probes();
  void request_surface_samples();
  void write_surface_probes(long step);

  // Where an attached fiber's root sits: surface edge `edge` (node a -> node b) of body `body`, at
  // parameter s along it. body < 0: the fiber is not attached to a body.
  struct Root {
    int body = -1;
    int a = 0, b = 0;
    double s = 0;
  };

  // A named set of bodies whose total hydrodynamic force is a probe ([[coupler.force]]).
  struct ForceGroup {
    std::string name;
    std::vector<std::string> body_names;
    std::vector<int> bodies;
  };

  fsi::Runtime& m_rt;
  // What the solvers described at set-up.
  proto::GridInfo m_grid;
  proto::BodyMeshes m_meshes;
  proto::FiberLayout m_layout;
  // Latest states and the messages of a step (kept to reuse their storage).
  proto::StepBegin m_sb;
  proto::SolidState m_solid;
  proto::FiberState m_fiber;
  proto::FluidInput m_fluid_in;
  proto::FluidOutput m_fluid_out;
  // The fluid on several ranks: the split of its input and the merge of its answers.
  std::unique_ptr<FluidRanks> m_fluid_ranks;
  proto::SolidInput m_solid_in;
  proto::FiberInput m_fiber_in;
  std::map<std::string, std::string> m_effective;  // role -> its effective scene (TOML)
  std::unique_ptr<ImmersedSolid> m_immersed;
  double m_footprint_smoothing = 0.0;  // [coupler] footprint_smoothing (SmoothBoxes)
  std::unique_ptr<FeedbackIB> m_ib;
  double m_kappa = 0;         // feedback stiffness (force per length per length), coupler.kappa
  double m_kappa_gain = 0.5;  // the default rule's one-step gain, see default_kappa()
  bool m_kappa_given = false;
  bool m_have_samples = false;  // fluid velocity samples around the markers are stored
  std::vector<Root> m_roots;
  std::vector<ForceGroup> m_force_groups;
  std::vector<std::array<double, 2>> m_momentum;    // per body: ρ_f ∫ v dA at the last probe
  std::vector<std::array<double, 2>> m_body_force;  // per body: hydrodynamic force of this step
  std::unique_ptr<fsi::ProbeCsv> m_probes;
  std::vector<double> m_probe_row;
  // [[coupler.surface_probe]]: as read, the probes on their bodies (null without), the CSV.
  std::vector<SurfaceProbeSpec> m_surface_specs;
  std::unique_ptr<SurfaceProbes> m_surface;
  std::unique_ptr<fsi::ProbeCsv> m_surface_csv;
  std::vector<double> m_surface_row;
  std::unique_ptr<fsi::Progress> m_progress;
  // [coupler.diagnostics]: the exchange log (null when off) and its settings.
  std::unique_ptr<ExchangeLog> m_log;
  bool m_log_csv = false;
  long m_dump_every = 0;
  std::vector<std::vector<double>> m_log_poses;  // scratch: root poses at t^n for the log
  // Growth check of the explicit coupling (check_growth): per body, the kinetic energy per unit
  // density and the node velocities of the previous step, and how many growth steps in a row.
  double m_growth_factor = 2.0;
  long m_growth_steps = 3;
  std::vector<double> m_energy;
  std::vector<std::vector<double>> m_velocity;
  std::vector<long> m_growing;
  fsi::PhaseTimer m_phases;
  double m_t_start = 0;
  double m_h_min = 0;  // smallest grid spacing (element sizes; the iterations' tolerance floor)
  // Coupled iterations: settings, the state of step n (and v^(n-1)), the state the footprint is
  // taken from (x^n with the current estimate of v^(n+1)), the stacked velocities of one
  // iteration (input, output, next input), the reaction of the last iteration, statistics.
  IterationSettings m_iter;
  std::unique_ptr<Acceleration> m_accel;
  proto::SolidState m_start, m_guess;
  std::vector<std::vector<double>> m_v_before, m_reaction;
  std::vector<double> m_x_in, m_x_out, m_x_next;
  long m_its = 1;  // this step: iterations, first and last residual, converged
  double m_res_first = 0, m_res = 0;
  bool m_converged = true;
  long m_iter_total = 0, m_iter_max = 0, m_not_converged = 0;
  double m_residual_max = 0;
  std::unique_ptr<fsi::ProbeCsv> m_iter_csv;
  bool m_stopping = false;  // asked to stop: the step under way is checkpointed and is the last
};

}  // namespace coupler
