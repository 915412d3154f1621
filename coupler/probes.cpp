// Force probes ([[coupler.force]], coupler_forces.csv): the hydrodynamic force on named groups of
// bodies, every step.
#include <algorithm>
#include <cmath>

#include "checkpoint.hpp"
#include "coupler.hpp"
#include "driver.hpp"

namespace coupler {

namespace {

// ρ_f ∫ v dA over a body in its current configuration (v linear on each triangle), both
// components in one pass. A rigid fixed body does not move: zero without a pass.
std::array<double, 2> body_momentum(const proto::BodyMesh& b, const std::vector<double>& x,
                                    const std::vector<double>& v, double rho) {
  std::array<double, 2> p{0.0, 0.0};
  if (b.kind == proto::BodyKind::rigid_fixed) return p;
  for (std::size_t e = 0; e + 2 < b.tri.size(); e += 3) {
    const int i = b.tri[e], j = b.tri[e + 1], k = b.tri[e + 2];
    const double area = 0.5 * std::abs((x[2 * j] - x[2 * i]) * (x[2 * k + 1] - x[2 * i + 1]) -
                                       (x[2 * k] - x[2 * i]) * (x[2 * j + 1] - x[2 * i + 1]));
    for (int c = 0; c < 2; ++c) p[c] += area * (v[2 * i + c] + v[2 * j + c] + v[2 * k + c]) / 3.0;
  }
  return {rho * p[0], rho * p[1]};
}

}  // namespace

// The scene's groups, or one per body; their bodies by name; the CSV; the bodies' momentum at t^0.
void Coupler::setup_force_probes() {
  const auto& bodies = m_meshes.bodies;
  if (m_force_groups.empty())
    for (const auto& b : bodies) m_force_groups.push_back({b.name, {b.name}, {}});
  for (std::size_t g = 0; g < m_force_groups.size(); ++g) {
    for (const auto& name : m_force_groups[g].body_names) {
      auto it =
          std::find_if(bodies.begin(), bodies.end(), [&](const auto& b) { return b.name == name; });
      if (it == bodies.end())
        throw fsi::InputError(fmt::format(
            "coupler.force[{}].bodies names body '{}', which the scene does not have (bodies: {}) "
            "(in {})",
            g, name, body_names(), m_rt.scene().file().string()));
      m_force_groups[g].bodies.push_back(static_cast<int>(it - bodies.begin()));
    }
  }
  if (!m_force_groups.empty()) {
    std::vector<std::string> cols;
    for (const auto& g : m_force_groups)
      cols.push_back(g.name + ".fx"), cols.push_back(g.name + ".fy");
    m_probes = std::make_unique<fsi::ProbeCsv>(
        fsi::output_csv(m_rt, m_rt.out_dir() / "coupler_forces.csv", cols));
    m_probe_row.assign(cols.size(), 0.0);
  }
  m_momentum.resize(bodies.size());
  for (std::size_t b = 0; b < bodies.size(); ++b)
    m_momentum[b] = body_momentum(bodies[b], m_solid.x[b], m_solid.v[b], m_grid.density);
}

// The hydrodynamic force on each group: F = Σ_a F_a + d/dt (ρ_f ∫ v dA). The first term is the
// reaction of f_s of this step (before any fiber root load is added); the second restores the
// inertia of the fluid the forcing carries inside the body (the fluid's momentum over the body:
// ∫ f_s = ρ_f V a_s − traction), from the bodies' momentum change over the previous step (the
// state at t^n is the newest the coupler holds when the reaction is known).
void Coupler::write_force_probes(long n, const proto::SolidState& start,
                                 const std::vector<std::vector<double>>& reaction) {
  if (!m_probes) return;
  const auto& bodies = m_meshes.bodies;
  const double dt = m_rt.settings().dt;
  // Per body, once: the reaction's resultant plus the rate of the carried fluid momentum.
  m_body_force.assign(bodies.size(), {0.0, 0.0});
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    const auto p = body_momentum(bodies[b], start.x[b], start.v[b], m_grid.density);
    const auto& f = reaction[b];
    for (std::size_t k = 0; k < f.size(); ++k) m_body_force[b][k % 2] += f[k];
    for (int c = 0; c < 2; ++c) m_body_force[b][c] += (p[c] - m_momentum[b][c]) / dt;
    m_momentum[b] = p;
  }
  std::fill(m_probe_row.begin(), m_probe_row.end(), 0.0);
  for (std::size_t g = 0; g < m_force_groups.size(); ++g)
    for (int b : m_force_groups[g].bodies)
      for (int c = 0; c < 2; ++c) m_probe_row[2 * g + c] += m_body_force[b][c];
  m_probes->write(fsi::step_time(m_rt.settings(), n + 1), m_probe_row);
}

}  // namespace coupler
