// The fluid's part of a checkpoint: the state a step starts from (solver.hpp, Solver::save).
#include "checkpoint.hpp"

#include "solver.hpp"

namespace fluid {

namespace {

void load_field(const fsi::H5File& h5, const std::string& name, Field& f) {
  std::vector<double> a = h5.read_doubles(name);
  if (a.size() != f.a.size())
    fsi::fail("checkpoint {}: {} has {} values, the grid {} (another grid?)", h5.path().string(), name,
              a.size(), f.a.size());
  f.a = std::move(a);
}

}  // namespace

// The fields with their ghosts; H^n, which the next step's AB2 predictor weighs against H^(n+1)
// (after a step it is in m_hu_old, m_hv_old); dt of the last step (AB2's dt') and the clock as
// the steps accumulated it (not n dt, so that the sums stay bit for bit).
void Solver::save(fsi::H5File& h5) const {
  if (m_phase == Phase::begun) fsi::fail("fluid::Solver::save: a step is under way");
  h5.write("fluid/u", m_u.a);
  h5.write("fluid/v", m_v.a);
  h5.write("fluid/p", m_p.a);
  h5.write("fluid/hu", m_hu_old.a);
  h5.write("fluid/hv", m_hv_old.a);
  h5.write("fluid/hu_spare", m_hu.a);  // overwritten by the next step; kept for exactness
  h5.write("fluid/hv_spare", m_hv.a);
  h5.write("fluid/clock", std::vector<double>{m_t, m_dt_prev});
  h5.write("fluid/step", std::vector<std::int64_t>{m_step});
  m_bnd.save(h5, "fluid/boundaries");
}

void Solver::load(const fsi::H5File& h5) {
  load_field(h5, "fluid/u", m_u);
  load_field(h5, "fluid/v", m_v);
  load_field(h5, "fluid/p", m_p);
  load_field(h5, "fluid/hu", m_hu_old);
  load_field(h5, "fluid/hv", m_hv_old);
  load_field(h5, "fluid/hu_spare", m_hu);
  load_field(h5, "fluid/hv_spare", m_hv);
  const auto clock = h5.read_doubles("fluid/clock");
  m_t = clock.at(0), m_dt_prev = clock.at(1);
  m_step = h5.read_int64s("fluid/step").at(0);
  m_bnd.load(h5, "fluid/boundaries");
  m_phase = Phase::between_steps;
}

void Boundaries::save(fsi::H5File& h5, const std::string& group) const {
  fsi::write_vectors(h5, group + "/previous", {m_prev.begin(), m_prev.end()});
  h5.write(group + "/speed", std::vector<double>(m_speed.begin(), m_speed.end()));
}

void Boundaries::load(const fsi::H5File& h5, const std::string& group) {
  const auto prev = fsi::read_vectors(h5, group + "/previous");
  const auto speed = h5.read_doubles(group + "/speed");
  if (prev.size() != m_prev.size() || speed.size() != m_speed.size())
    fsi::fail("checkpoint {}: {} is not of four sides", h5.path().string(), group);
  for (std::size_t s = 0; s < m_prev.size(); ++s) m_prev[s] = prev[s], m_speed[s] = speed[s];
}

}  // namespace fluid
