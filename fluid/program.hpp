// The `fluid` program's side of a run: the fluid solver behind the driver's FluidPort, with its
// output (HDF5 + XDMF fields, probe CSV, wall shear stress), health checks and report.
#pragma once

#include <memory>
#include <optional>

#include "driver.hpp"
#include "h5.hpp"
#include "probes.hpp"
#include "solver.hpp"
#include "xdmf.hpp"

namespace fluid {

// Sub-cycling: the substep count falls by one only when the CFL number over one substep fewer
// would be at most this fraction of [fluid.substeps] cfl.
inline constexpr double kSubstepsFall = 0.8;

// The substeps of the next coupled step, from `now` (those of the last; 0: none yet) and c, the
// CFL number of the coupled step's dt over the velocity it starts from, under [fluid.substeps]
// max and cfl: ceil(c / cfl) (at most max) once c / now > cfl; now - 1 once
// c / (now - 1) <= kSubstepsFall cfl; else now. 1 for a c that is not finite.
int substep_count(int now, double c, int max, double cfl);

class FluidProgram : public fsi::FluidPort {
 public:
  explicit FluidProgram(fsi::Runtime& rt);
  fsi::proto::GridInfo grid_info() const override;
  void advance(const fsi::proto::StepBegin& s, const fsi::proto::FluidInput& in,
               fsi::proto::FluidOutput& out) override;
  // A sub-cycling fluid cannot redo a step (the coupler refuses coupled iterations at set-up).
  bool can_iterate() const override { return m_cfg.substeps_max == 1; }
  void prepare_next(const fsi::proto::StepBegin& done) override;
  void begin(const fsi::proto::StepBegin& s) override;
  void output(long step, double t, bool fields) override;
  std::string status() const override;
  nlohmann::json report() const override;
  void save(fsi::H5File& h5) const override;
  void save_ranks() const override;
  void load(const fsi::H5File& h5) override;

 private:
  void write_fields(long step, double t);
  void write_flow_rate(double t);
  nlohmann::json flow_rate_report() const;
  // Health: NaN/Inf, CFL above its limit, divergence growth. Writes the state, then throws.
  void check_health(long step, double t, double dt);
  // Sub-cycling: the substeps of the coming step of dt.
  int substeps(double dt);

  fsi::Runtime& m_rt;
  Config m_cfg;
  std::unique_ptr<Solver> m_solver;
  std::optional<fsi::H5File> m_h5;  // the files: on the fluid's rank 0 only
  std::optional<fsi::XdmfWriter> m_xdmf;
  std::optional<fsi::ProbeCsv> m_probes;
  std::vector<double> m_row, m_w1, m_w2;
  // Flow-rate sections ([fluid.diagnostics] flow_rate): their u-face columns, the CSV, and the
  // times and values of this run's steps (for the report's mean and fluctuation amplitude).
  std::vector<int> m_flow_columns;
  std::optional<fsi::ProbeCsv> m_flow;
  std::vector<double> m_flow_row, m_flow_times, m_flow_values;
  CouplingOut m_out;
  double m_cfl = 0, m_div = 0, m_div_first = -1;
  double m_energy = 0;  // kinetic energy, refreshed with the divergence every health.every steps
  long m_written_step = -1;
  int m_substeps = 0;  // substeps of the next step (0: not known yet)
  int m_substeps_done = 1;  // substeps of the step just taken
  long m_substepped = 0, m_substeps_taken = 0;  // steps sub-cycled in this run, their substeps
};

}  // namespace fluid
