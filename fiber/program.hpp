// The `fiber` program's side of a run: the fiber system behind the driver's FiberPort (alone in
// vacuum, or as the fiber role of a coupled job), with its output: marker positions, tension and
// curvature in HDF5 + XDMF polylines, probes at arclength positions, and the loads on supports.
#pragma once

#include <optional>
#include <vector>

#include "config.hpp"
#include "driver.hpp"
#include "h5.hpp"
#include "probes.hpp"
#include "system.hpp"
#include "xdmf.hpp"

namespace fiber {

class FiberProgram : public fsi::FiberPort {
 public:
  explicit FiberProgram(fsi::Runtime& rt);
  fsi::proto::FiberLayout layout() const override;
  void set_initial_roots(const std::vector<std::vector<double>>& root_pose) override;
  void state(fsi::proto::FiberState& s) const override;
  void advance(const fsi::proto::StepBegin& s, const fsi::proto::FiberInput& in) override;
  void output(long step, double t, bool fields) override;
  std::string status() const override;
  nlohmann::json report() const override;
  void save(fsi::H5File& h5) const override { m_system->save(h5); }
  void load(const fsi::H5File& h5) override { m_system->load(h5); }

  const FiberSystem& system() const { return *m_system; }

 private:
  void write_fields(long step, double t);

  fsi::Runtime& m_rt;
  std::optional<FiberSystem> m_system;
  fsi::H5File m_h5;
  std::optional<fsi::XdmfWriter> m_xdmf;
  std::optional<fsi::ProbeCsv> m_probes, m_loads;
  std::vector<int> m_load_ends;  // 2k: root of fiber k, 2k+1: its tip
  std::vector<double> m_row, m_ext, m_geometry, m_tension, m_curvature, m_work;
  std::vector<EndPose> m_poses;
  double m_max_stretch = 0;
  double m_next_probe_time = 0;
  long m_written_step = -1;
};

}  // namespace fiber
