// The coupler's part of a checkpoint: what its next step reads that no solver sends again at a
// restart (each solver sends its restored state at set-up, as at the start of a run).
#include "checkpoint.hpp"

#include "coupler.hpp"

namespace coupler {

namespace {

std::vector<std::vector<double>> pairs_to_vectors(const std::vector<std::array<double, 2>>& a) {
  std::vector<std::vector<double>> v;
  for (const auto& p : a) v.push_back({p[0], p[1]});
  return v;
}

}  // namespace

// The bodies' carried momentum at the last force probe (the probe's rate term), the growth
// check's history, the fluid's velocity samples around the markers (U(X^n) of the next step),
// the accelerator's kept secant pairs and v^(n-1), and the iteration statistics.
void Coupler::save(fsi::H5File& h5) const {
  fsi::write_vectors(h5, "probes/momentum", pairs_to_vectors(m_momentum));
  h5.write("growth/energy", m_energy);
  fsi::write_vectors(h5, "growth/velocity", m_velocity);
  std::vector<std::int64_t> growing(m_growing.begin(), m_growing.end());
  h5.write("growth/growing", growing);
  h5.write("samples/have", std::vector<std::int64_t>{m_have_samples ? 1 : 0});
  if (m_have_samples) {
    const std::vector<std::int64_t> iu(m_fluid_in.sample_u.begin(), m_fluid_in.sample_u.end());
    const std::vector<std::int64_t> iv(m_fluid_in.sample_v.begin(), m_fluid_in.sample_v.end());
    h5.write("samples/u_index", iu);
    h5.write("samples/v_index", iv);
    h5.write("samples/u", m_fluid_out.u_sample);
    h5.write("samples/v", m_fluid_out.v_sample);
  }
  if (m_accel) {
    m_accel->save(h5, "iterations/pairs");
    fsi::write_vectors(h5, "iterations/v_before", m_v_before);
    h5.write("iterations/counts", std::vector<std::int64_t>{m_iter_total, m_iter_max, m_not_converged});
    h5.write("iterations/largest_final_residual", std::vector<double>{m_residual_max});
  }
}

void Coupler::load(const fsi::H5File& h5) {
  const auto momentum = fsi::read_vectors(h5, "probes/momentum");
  if (momentum.size() != m_momentum.size())
    fsi::fail("checkpoint {} holds {} bodies, the scene {}", h5.path().string(), momentum.size(),
              m_momentum.size());
  for (std::size_t b = 0; b < momentum.size(); ++b) m_momentum[b] = {momentum[b].at(0), momentum[b].at(1)};
  m_energy = h5.read_doubles("growth/energy");
  m_velocity = fsi::read_vectors(h5, "growth/velocity");
  const auto growing = h5.read_int64s("growth/growing");
  m_growing.assign(growing.begin(), growing.end());
  m_have_samples = h5.read_int64s("samples/have").at(0) != 0;
  if (m_have_samples) {
    if (!m_ib) fsi::fail("checkpoint {} holds fluid samples for fibers the scene does not have", h5.path().string());
    const auto iu = h5.read_int64s("samples/u_index"), iv = h5.read_int64s("samples/v_index");
    m_fluid_in.sample_u.assign(iu.begin(), iu.end());
    m_fluid_in.sample_v.assign(iv.begin(), iv.end());
    m_fluid_out.u_sample = h5.read_doubles("samples/u");
    m_fluid_out.v_sample = h5.read_doubles("samples/v");
    m_ib->store_samples(m_fluid_in.sample_u, m_fluid_out.u_sample, m_fluid_in.sample_v,
                        m_fluid_out.v_sample);
  }
  if (m_accel) {
    m_accel->load(h5, "iterations/pairs");
    m_v_before = fsi::read_vectors(h5, "iterations/v_before");
    const auto counts = h5.read_int64s("iterations/counts");
    m_iter_total = counts.at(0), m_iter_max = counts.at(1), m_not_converged = counts.at(2);
    m_residual_max = h5.read_doubles("iterations/largest_final_residual").at(0);
  }
}

}  // namespace coupler
