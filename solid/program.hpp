// The `solid` program's side of a run: the solid solver behind the driver's SolidPort, alone (a
// pure-solid scene) or as the solid role of a coupled job. Output: HDF5 + XDMF per body
// (displacement, velocity, von Mises stress, det F, contact pressure), probe CSV at material
// points, a history CSV (energies, contact, Newton iterations), eigenmodes; health checks stop
// the run with a message naming body, element or node, step and time, after writing the state.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "config.hpp"
#include "driver.hpp"
#include "h5.hpp"
#include "probes.hpp"
#include "solver.hpp"
#include "xdmf.hpp"

namespace solid {

class SolidProgram : public fsi::SolidPort {
 public:
  explicit SolidProgram(fsi::Runtime& rt);
  fsi::proto::BodyMeshes meshes() const override;
  void state(fsi::proto::SolidState& s) const override;
  void advance(const fsi::proto::StepBegin& s, const fsi::proto::SolidInput& in) override;
  // Coupled iterations linearise the fluid's reaction with the trapezoidal rule's velocity.
  bool can_iterate() const override { return m_cfg.model.settings.trapezoidal(); }
  void begin(const fsi::proto::StepBegin& s) override;
  void output(long step, double t, bool fields) override;
  std::string status() const override;
  nlohmann::json report() const override;
  void save(fsi::H5File& h5) const override;  // checkpoint.cpp
  void load(const fsi::H5File& h5) override;

 private:
  void write_modes();
  void write_fields(long step, double t);
  void add_step_work();

  fsi::Runtime& m_rt;
  Config m_cfg;
  std::unique_ptr<Solver> m_solver;
  fsi::H5File m_h5;
  std::vector<fsi::XdmfWriter> m_xdmf;  // one per body
  std::optional<fsi::ProbeCsv> m_probes, m_history;
  std::vector<MeshPoint> m_probe_points;
  std::vector<double> m_row;
  std::vector<std::vector<double>> m_external;
  // The energy balance (solid_history.csv): the work done on the elastic bodies since t = 0 by
  // the coupling forces and by contact, and what a step needs for it: the positions and both
  // forces at the step's start (t^n) and the coupling forces of the last step taken.
  double m_coupling_work = 0, m_contact_work = 0, m_work_start[2] = {0, 0};
  std::vector<std::vector<double>> m_x_n, m_contact_n, m_external_n, m_external_used;
  Modes m_modes;
  StepReport m_last;
  StepState m_start;  // the state the current step started from (coupled iterations)
  long m_start_step = -1;  // the step m_start belongs to (-1: none kept)
  long m_newton_total = 0, m_newton_max = 0, m_steps = 0, m_repeats = 0, m_written_step = -1;
  long m_cut_steps = 0;  // steps taken in parts after a failure (step_cutbacks)
  double m_assembly = 0, m_factor = 0, m_solve = 0;
};

}  // namespace solid
