// The coupler's side of the surface probes ([[coupler.surface_probe]], coupler_surface.csv):
// their set-up, the fluid samples they ask for, one row per accepted step (surface.hpp).
#include <sstream>
#include <toml.hpp>

#include "checkpoint.hpp"
#include "coupler.hpp"
#include "driver.hpp"

namespace coupler {

// The probes on their bodies, the fluid's viscosity (from the scene as the fluid read it), the
// CSV. Checked here: a fluid and bodies to probe.
void Coupler::setup_surface_probes() {
  if (m_surface_specs.empty()) return;
  const std::string file = m_rt.scene().file().string();
  if (!has(fsi::Role::fluid))
    throw fsi::InputError(fmt::format(
        "coupler.surface_probe: surface probes sample the fluid, and the scene has no [fluid] "
        "(in {})",
        file));
  std::istringstream is(m_effective.at("fluid"));
  const auto doc = toml::parse<toml::discard_comments, std::map, std::vector>(is, "fluid");
  const double mu = toml::get<double>(doc.at("fluid").at("viscosity"));
  m_surface = std::make_unique<SurfaceProbes>(m_grid, m_meshes, m_surface_specs, mu, file);
  m_surface_csv = std::make_unique<fsi::ProbeCsv>(
      fsi::output_csv(m_rt, m_rt.out_dir() / "coupler_surface.csv", m_surface->columns()));
}

// Before the fluid's step (iteration 0): the faces and cells of the probes' stencils in the footprint's
// configuration x^n join the step's sample request (the fibers' stencil, when there are fibers).
void Coupler::request_surface_samples() {
  // Without fibers the request is the probes' alone (the last step's faces are not kept).
  if (!m_ib) m_fluid_in.sample_u.clear(), m_fluid_in.sample_v.clear();
  m_fluid_in.sample_p.clear();
  m_surface->add_requests(footprint_state(), m_fluid_in.sample_u, m_fluid_in.sample_v,
                          m_fluid_in.sample_p);
}

// The accepted step n: tau and the slip at t^(n+1) from the fluid's u^(n+1), on the surface in
// the configuration the fluid's forcing of this step used (x^n, footprint_state()).
void Coupler::write_surface_probes(long n) {
  if (!m_surface) return;
  m_surface->evaluate(footprint_state(), m_fluid_in.sample_u, m_fluid_out.u_sample,
                      m_fluid_in.sample_v, m_fluid_out.v_sample, m_fluid_in.sample_p,
                      m_fluid_out.p_sample, m_surface_row);
  m_surface_csv->write(fsi::step_time(m_rt.settings(), n + 1), m_surface_row);
}

}  // namespace coupler
