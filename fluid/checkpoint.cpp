// The fluid's part of a checkpoint: the state a step starts from (solver.hpp, Solver::save).
#include "checkpoint.hpp"

#include "solver.hpp"

namespace fluid {

namespace {

// The whole grid's values of f (ghosts included, the one-rank layout) into the rows it stores.
void load_field(const fsi::H5File& h5, const std::string& name, Field& f) {
  std::vector<double> a = h5.read_doubles(name);
  const std::size_t whole = std::size_t(f.sx) * (f.nj + 2);
  if (a.size() != whole)
    fsi::fail("checkpoint {}: {} has {} values, the grid {} (another grid?)", h5.path().string(), name,
              a.size(), whole);
  if (f.a.size() == whole) {
    f.a = std::move(a);
    return;
  }
  std::copy(a.begin() + std::size_t(f.jlo) * f.sx, a.begin() + std::size_t(f.jlo) * f.sx + f.a.size(),
            f.a.begin());
}

}  // namespace

// The fields with their ghosts; H^n, which the next step's AB2 predictor weighs against H^(n+1)
// (after a step it is in m_hu_old, m_hv_old); dt of the last step (AB2's dt') and the clock as
// the steps accumulated it (not n dt, so that the sums stay bit for bit).
void Solver::save(fsi::H5File* h5) const {
  if (m_phase == Phase::begun) fsi::fail("fluid::Solver::save: a step is under way");
  const std::pair<const char*, const Field*> fields[] = {
      {"fluid/u", &m_u},       {"fluid/v", &m_v},        {"fluid/p", &m_p},
      {"fluid/hu", &m_hu_old}, {"fluid/hv", &m_hv_old},
      // overwritten by the next step; kept for exactness
      {"fluid/hu_spare", &m_hu}, {"fluid/hv_spare", &m_hv}};
  for (const auto& [name, f] : fields) {
    if (m_dec.serial()) {
      h5->write(name, f->a);
      continue;
    }
    const std::vector<double> all = m_dec.gather_field(*f);
    if (h5) h5->write(name, all);
  }
  m_bnd.save(h5, "fluid/boundaries");
  if (!h5) return;
  h5->write("fluid/clock", std::vector<double>{m_t, m_dt_prev});
  h5->write("fluid/step", std::vector<std::int64_t>{m_step});
  // whether the last step's footprint had elastic faces (the next step keeps uⁿ for
  // body_viscosity)
  h5->write("fluid/body_faces", std::vector<std::int64_t>{m_body_faces ? 1 : 0});
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
  // (absent in a checkpoint written before it was kept: uⁿ is kept at the first step)
  if (h5.exists("fluid/body_faces")) m_body_faces = h5.read_int64s("fluid/body_faces").at(0) != 0;
  m_bnd.load(h5, "fluid/boundaries");
  m_phase = Phase::between_steps;
}

// An outflow's last interior line per side: along a left or right side the rows' values of
// every rank, along a bottom or top side that of the rank holding it; the whole side's in the
// file.
void Boundaries::save(fsi::H5File* h5, const std::string& group) const {
  std::vector<std::vector<double>> prev(m_prev.begin(), m_prev.end());
  // A checkpoint follows a step, which set the line of every outflow side: on several ranks the
  // whole side's line from the ranks' parts (collective, the same sides on every rank).
  if (!m_d.serial())
    for (int s = 0; s < 4; ++s) {
      if (m_bc[s].type != BcType::outflow) continue;
      m_mine = m_prev[s];
      prev[s] = whole_side(s);
    }
  if (!h5) return;
  fsi::write_vectors(*h5, group + "/previous", prev);
  h5->write(group + "/speed", std::vector<double>(m_speed.begin(), m_speed.end()));
}

void Boundaries::load(const fsi::H5File& h5, const std::string& group) {
  const auto prev = fsi::read_vectors(h5, group + "/previous");
  const auto speed = h5.read_doubles(group + "/speed");
  if (prev.size() != m_prev.size() || speed.size() != m_speed.size())
    fsi::fail("checkpoint {}: {} is not of four sides", h5.path().string(), group);
  for (std::size_t s = 0; s < m_prev.size(); ++s) {
    m_speed[s] = speed[s];
    if (m_d.serial() || prev[s].empty()) {
      m_prev[s] = prev[s];
      continue;
    }
    // This rank's part of the whole side's line.
    if (s < 2)
      m_prev[s].assign(prev[s].begin() + row_lo(), prev[s].begin() + row_hi());
    else
      m_prev[s] = holds(int(s)) ? prev[s] : std::vector<double>{};
  }
}

}  // namespace fluid
