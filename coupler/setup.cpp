// The coupler's set-up: its [coupler] table, the set-up messages (common/PROTOCOL.md, S1-S9),
// the transfers' construction, the checks at t^0, and the effective scene.
#include <algorithm>
#include <sstream>
#include <toml.hpp>

#include "checkpoint.hpp"
#include "coupler.hpp"

namespace coupler {

using fsi::Role;

namespace {

// Upper bound of coupler.kappa_gain: the explicit spring between a marker and the fluid is stable
// for a one-step gain g < 2 (feedback.cpp).
constexpr double kMaxKappaGain = 2.0;
// Caps of [coupler.iterations] max and reuse: far above what a converging scene needs, so a
// larger value is a typing error rather than a setting.
constexpr long kMaxIterations = 1000;
constexpr long kMaxReuse = 100;

}  // namespace

Coupler::Coupler(fsi::Runtime& rt) : m_rt(rt) {
  if (const auto c = rt.root().optional_table("coupler")) {
    for (const auto& f : c->tables("force")) {
      ForceGroup g;
      g.name = f.string("name");
      g.body_names = f.strings("bodies");
      f.finish();
      m_force_groups.push_back(g);
    }
    for (const auto& f : c->tables("surface_probe")) {
      SurfaceProbeSpec sp;
      sp.name = f.string("name");
      sp.body = f.string("body", "");
      sp.point = f.vec2("point");
      f.finish();
      m_surface_specs.push_back(sp);
    }
    m_kappa_given = c->has("kappa");
    if (m_kappa_given) m_kappa = c->positive("kappa");
    m_kappa_gain = c->in_range("kappa_gain", 0.0, kMaxKappaGain, true, m_kappa_gain);
    m_footprint_smoothing = c->in_range("footprint_smoothing", 0.0, 1.0, false, m_footprint_smoothing);
    if (const auto d = c->optional_table("diagnostics")) {
      m_log_csv = d->boolean("exchange", false);
      m_dump_every = d->integer("dump_every", 0);
      if (m_dump_every < 0)
        d->fail("dump_every", fmt::format("must be >= 0 (0: no dump), got {}", m_dump_every));
      d->finish();
    }
    if (const auto h = c->optional_table("health")) {
      m_growth_factor = h->number("growth_factor", m_growth_factor);
      if (!(m_growth_factor > 1))
        h->fail("growth_factor", fmt::format("must be > 1, got {}", m_growth_factor));
      m_growth_steps = h->positive_integer("growth_steps", m_growth_steps);
      h->finish();
    }
    if (const auto it = c->optional_table("iterations")) read_iterations(*it);
    c->finish();
  }
  if (m_iter.max > 1) m_accel = std::make_unique<Acceleration>(m_iter);
}

// [coupler.iterations] (IQN-ILS, acceleration.hpp).
void Coupler::read_iterations(const fsi::SceneTable& t) {
  m_iter.max = static_cast<int>(t.positive_integer("max", 1));
  if (m_iter.max > kMaxIterations)
    t.fail("max", fmt::format("must be <= {}, got {}", kMaxIterations, m_iter.max));
  m_iter.tolerance = t.in_range("tolerance", 0.0, 1.0, true, m_iter.tolerance);
  m_iter.relaxation = t.in_range("relaxation", 0.0, 1.0, false, m_iter.relaxation);
  if (!(m_iter.relaxation > 0)) t.fail("relaxation", "must be in (0, 1], got 0");
  const long reuse = t.integer("reuse", 0);
  if (reuse < 0 || reuse > kMaxReuse)
    t.fail("reuse", fmt::format("must be in [0, {}], got {}", kMaxReuse, reuse));
  m_iter.reuse = static_cast<int>(reuse);
  t.finish();
}

// Sub-iterations need a fluid and a solid that can repeat a step (their ports say so at set-up).
void Coupler::check_can_iterate() const {
  if (m_iter.max <= 1) return;
  auto refuse = [&](const char* program) {
    throw fsi::InputError(fmt::format(
        "coupler.iterations.max = {} asks every step to be repeated, but the {} program cannot "
        "repeat a step (its port does not implement coupled iterations, a fluid takes "
        "substeps: fluid.substeps.max > 1, or the solid's Newmark step is not the trapezoidal "
        "rule: solid.newmark_gamma, newmark_beta); set max = 1 (in {})",
        m_iter.max, program, m_rt.scene().file().string()));
  };
  if (has(Role::fluid) && !m_grid.can_iterate) refuse("fluid");
  if (has(Role::solid) && !m_meshes.can_iterate) refuse("solid");
}

// The immersed forcing's keys against the scene's bodies.
//
// fluid.forcing_time blends a cut face by beta, not by the volume fraction alpha (fluid/forcing.cpp),
// while a body that moves under its load takes the fluid inside it as its own volume times
// rho_f (Eq. 21's alpha): its inertia would gain sum (beta - alpha) |V| rho_f, and the coupled
// iterations' linearisation would be off by beta/alpha. So the key is for scenes whose bodies
// take no load (fixed or prescribed; solid-rigid's free bodies come as elastic ones). Steady
// FSI1 with forcing_time = 0 gave u_y(A) +52 % against +12 % (runs/turek-hron-fsi): the held
// cut faces over the bent bar, not the inertia, which a steady state does not see.
//
// fluid.interface = "sharp" places the walls of fixed bodies; an elastic body's faces keep
// Eq. 21, known to the fluid by FaceSolid::elastic (fluid/forcing.cpp). A free rigid body takes
// load but is not elastic there, and a body with a prescribed motion is held by lines that
// switch as it crosses the cells, each switch a spike in its force (fluid/README.md): both are
// refused. So is a scene without a fixed body (the key would change nothing), and the smoothed
// footprint, whose alpha is not a box's area fraction, from which the line places the wall.
void Coupler::check_immersed_forcing_keys() const {
  if (!has(Role::fluid)) return;
  const auto fluid = m_rt.root().optional_table("fluid");  // (the fluid checked the keys)
  if (!fluid) return;
  const std::string file = m_rt.scene().file().string();
  if (has(Role::solid) && fluid->has("forcing_time")) {
    const double tau = fluid->number("forcing_time");
    for (const auto& b : m_meshes.bodies)
      if (b.kind == proto::BodyKind::elastic)
        throw fsi::InputError(fmt::format(
            "fluid.forcing_time = {} is for bodies that take no load (rigid bodies, fixed or with "
            "a prescribed motion): body '{}' moves under the fluid's load, and its reaction "
            "assumes the forcing of Eq. 21; remove fluid.forcing_time (in {})",
            tau, b.name, file));
  }
  if (!fluid->has("interface") || fluid->string("interface") != "sharp") return;
  if (m_footprint_smoothing > 0)
    throw fsi::InputError(fmt::format(
        "fluid.interface = \"sharp\" places the wall from each face's area fraction, and "
        "coupler.footprint_smoothing = {} smooths it; remove one of the two keys (in {})",
        m_footprint_smoothing, file));
  bool any = false;
  for (const auto& b : m_meshes.bodies) {
    if (b.kind == proto::BodyKind::elastic && b.rigid != 0)
      throw fsi::InputError(fmt::format(
          "fluid.interface = \"sharp\" places the walls of fixed bodies: body '{}' is a free "
          "rigid body, which moves under the fluid's load; remove fluid.interface (in {})",
          b.name, file));
    if (b.kind == proto::BodyKind::rigid_moving)
      throw fsi::InputError(fmt::format(
          "fluid.interface = \"sharp\" places the walls of fixed bodies: body '{}' moves "
          "([solid.body.motion]), and the faces switching as it crosses the cells put spikes "
          "into its force (fluid/README.md); remove fluid.interface (in {})",
          b.name, file));
    any |= b.kind == proto::BodyKind::rigid_fixed;
  }
  if (!any)
    throw fsi::InputError(fmt::format(
        "fluid.interface = \"sharp\" places the walls of fixed bodies, and this scene has none "
        "(an elastic body's faces keep Eq. 21); remove fluid.interface (in {})",
        file));
}

// Set-up, once: grid from the fluid; meshes and initial state from the solid; layout from the
// fiber, then the fibers' root poses at t^0 and their initial state; each solver's effective
// scene. Then the transfers, the checks at t^0, the probes and logs.
void Coupler::setup() {
  auto effective = [&](fsi::Link& l, const char* role) {
    proto::Text t{proto::Tag::effective_scene, {}};
    l.recv(t);
    m_effective[role] = t.text;
  };
  if (has(Role::fluid)) {
    // Every fluid rank sends the grid and its scene (the same); on several ranks the input of
    // each step is split by their rows (fluid_ranks.hpp).
    auto& links = m_rt.links(Role::fluid);
    for (std::size_t k = 0; k < links.size(); ++k) {
      proto::GridInfo g;
      links[k]->recv(k == 0 ? m_grid : g);
      if (k > 0 && (g.nx != m_grid.nx || g.ny != m_grid.ny))
        fsi::fail("fluid rank {} sent a {} x {} grid, rank 0 a {} x {} grid", k, g.nx, g.ny,
                  m_grid.nx, m_grid.ny);
      effective(*links[k], "fluid");
    }
    if (links.size() > 1) m_fluid_ranks = std::make_unique<FluidRanks>(m_grid, int(links.size()));
  }
  if (has(Role::solid)) {
    auto& l = m_rt.link(Role::solid);
    l.recv(m_meshes);
    l.recv(m_solid);
    effective(l, "solid");
  }
  if (has(Role::fiber)) {
    auto& l = m_rt.link(Role::fiber);
    l.recv(m_layout);
    m_fiber_in.force.assign(m_layout.fibers.size(), {});
    resolve_roots();
    root_poses(m_solid, m_fiber_in.root_pose);
    l.send(m_fiber_in);
    l.recv(m_fiber);
    effective(l, "fiber");
  }

  if (!m_layout.fibers.empty() && has(Role::fluid)) {
    if (!FeedbackIB::uniform_grid(m_grid))  // the scene's fault: named by its keys
      throw fsi::InputError(fmt::format(
          "fibers need a uniform fluid grid (the delta function's moment conditions hold on a "
          "uniform grid only): the scene has fibers ([fiber]), and fluid.grid.x_band, y_band, "
          "y_stretch or fluid.sponge stretches the fluid grid; give the fibers a uniform grid "
          "(in {})",
          m_rt.scene().file().string()));
    m_ib = std::make_unique<FeedbackIB>(m_grid);
    if (!m_kappa_given) default_kappa();
  }
  check_can_iterate();
  check_immersed_forcing_keys();
  m_h_min = kFar;
  for (std::size_t i = 0; i + 1 < m_grid.x_face.size(); ++i)
    m_h_min = std::min(m_h_min, m_grid.x_face[i + 1] - m_grid.x_face[i]);
  for (std::size_t j = 0; j + 1 < m_grid.y_face.size(); ++j)
    m_h_min = std::min(m_h_min, m_grid.y_face[j + 1] - m_grid.y_face[j]);
  const auto& bodies = m_meshes.bodies;
  if (!bodies.empty()) {
    if (!has(Role::fluid))
      fsi::fail("the scene has solid bodies and fibers but no fluid: nothing couples them");
    m_immersed = std::make_unique<ImmersedSolid>(m_grid, m_meshes, m_footprint_smoothing);
    check_bodies_in_domain(0);
    warn_element_sizes();
  }
  m_solid_in.force.assign(bodies.size(), {});
  if (m_ib) warn_marker_spacing();
  setup_force_probes();
  setup_surface_probes();
  if (m_accel)
    m_iter_csv = std::make_unique<fsi::ProbeCsv>(fsi::output_csv(
        m_rt, m_rt.out_dir() / "coupler_iterations.csv",
        std::vector<std::string>{"step", "iterations", "residual_first", "residual", "converged",
                                 "omega", "columns"}));
  if ((m_log_csv || m_dump_every > 0) && m_rt.restart_step())
    throw fsi::InputError(fmt::format(
        "coupler.diagnostics: the exchange log cannot continue a restarted run; turn exchange "
        "and dump_every off for the restart (in {})",
        m_rt.scene().file().string()));
  if (m_log_csv || m_dump_every > 0)
    m_log = std::make_unique<ExchangeLog>(m_rt.out_dir(), m_grid, m_meshes, m_layout,
                                          m_rt.settings().dt, m_log_csv, m_dump_every);
  if (m_ib) check_fibers_in_domain(0);
  m_energy.assign(bodies.size(), 0.0);
  m_growing.assign(bodies.size(), 0);
  m_velocity.assign(bodies.size(), {});
  check_growth(0);
  write_effective_scene();
}

// scene.effective.toml: the coupler's own reading, each solver's table from that solver.
void Coupler::write_effective_scene() const {
  std::istringstream own(m_rt.scene().effective_toml());
  auto doc = toml::parse<toml::discard_comments, std::map, std::vector>(own, "effective");
  for (const auto& [role, text] : m_effective) {
    std::istringstream is(text);
    const auto part = toml::parse<toml::discard_comments, std::map, std::vector>(is, role);
    if (part.contains(role)) doc.as_table()[role] = part.at(role);
  }
  fsi::write_file_atomically(m_rt.out_dir() / "scene.effective.toml", toml::format(doc));
}

// "bar, cylinder", or "none": the bodies' names for error messages.
std::string Coupler::body_names() const {
  std::vector<std::string> names;
  for (const auto& b : m_meshes.bodies) names.push_back(b.name);
  return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace coupler
