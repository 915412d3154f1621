// What the coupler exchanges, written down for checking ([coupler.diagnostics], README.md):
// per step the sums that must balance (coupler_exchange.csv), and every so many steps the
// exchanged quantities themselves (coupler_exchange.h5), so that a script can compare them with
// values it computes on its own. Off by default; costs nothing when off.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "h5.hpp"
#include "ib.hpp"
#include "probes.hpp"
#include "protocol.hpp"

namespace coupler {

namespace proto = fsi::proto;

class ExchangeLog {
 public:
  // `csv`: write coupler_exchange.csv; `dump_every` > 0: write coupler_exchange.h5 every so many
  // steps (0: never). The grid, meshes and layout must outlive the log.
  ExchangeLog(const std::filesystem::path& out_dir, const proto::GridInfo& grid,
              const proto::BodyMeshes& meshes, const proto::FiberLayout& layout, double dt,
              bool csv, long dump_every);

  // The hooks of one step n, in the order the coupler calls them (coupler.cpp, step()):
  // what goes to the fluid (α, ū_s, f_f) with the states it came from and the markers'
  // interpolated velocity U(Xⁿ) (`ib` null or `have_samples` false: none yet) ...
  void inputs(long n, double t, const proto::SolidState& solid, const proto::FiberState& fiber,
              const proto::FluidInput& fluid_in, const proto::FiberInput& fiber_in,
              const FeedbackIB* ib, bool have_samples);
  // ... the fluid's answer and the nodal reaction of f_s on every body (before rigid bodies'
  // forces are dropped) ...
  void reaction(const proto::FluidInput& fluid_in, const proto::FluidOutput& fluid_out,
                const std::vector<std::vector<double>>& force);
  // ... the nodal forces just before and just after the fibers' root loads are added, the root
  // loads and the root poses (x, y, dx, dy per attached fiber, empty otherwise) at tⁿ ...
  void before_root_loads(const std::vector<std::vector<double>>& force);
  // (and the fibers' root masses, lumped on the nodes as the solid gets them)
  void root_loads(const std::vector<std::vector<double>>& force,
                  const std::vector<double>& root_load,
                  const std::vector<std::vector<double>>& poses,
                  const std::vector<double>& root_mass,
                  const std::vector<std::vector<double>>& nodal_root_mass);
  // ... and the end of the step: one CSV row, the dump when due.
  void end_step();

 private:
  struct FaceBox {  // volume of each face's control volume, per family
    std::vector<double> u, v;
  };
  void dump();

  const proto::GridInfo& m_grid;
  const proto::BodyMeshes& m_meshes;
  const proto::FiberLayout& m_layout;
  long m_dump_every;
  FaceBox m_volume;
  double m_cell = 0;  // hx hy of a uniform grid (the fibers' spreading volume), 0 otherwise
  std::unique_ptr<fsi::ProbeCsv> m_csv;
  std::unique_ptr<fsi::H5File> m_h5;

  // The step being recorded (copies: the coupler reuses its messages' storage).
  long m_step = 0;
  double m_time = 0;
  proto::SolidState m_solid;
  proto::FiberState m_fiber;
  proto::FluidInput m_in;
  proto::FluidOutput m_out;
  std::vector<std::vector<double>> m_u_markers, m_fiber_force, m_reaction, m_root_nodal, m_poses;
  std::vector<double> m_root_load, m_root_mass;
  std::vector<std::vector<double>> m_nodal_root_mass;
  std::vector<std::int32_t> m_sample_u, m_sample_v, m_prev_sample_u, m_prev_sample_v;
  std::vector<double> m_value_u, m_value_v, m_prev_value_u, m_prev_value_v;
  std::vector<double> m_row;
};

}  // namespace coupler
