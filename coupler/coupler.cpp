// The coupler's step sequence (the paper's Sec. 3.3; message order in common/PROTOCOL.md).
#include "coupler.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <toml.hpp>

#include "driver.hpp"

namespace coupler {

using fsi::Role;

Coupler::Coupler(fsi::Runtime& rt) : m_rt(rt) {
  if (const auto c = rt.root().optional_table("coupler")) {
    for (const auto& f : c->tables("force")) {
      ForceGroup g;
      g.name = f.string("name");
      g.body_names = f.strings("bodies");
      f.finish();
      m_force_groups.push_back(g);
    }
    m_kappa_given = c->has("kappa");
    if (m_kappa_given) m_kappa = c->positive("kappa");
    m_kappa_gain = c->in_range("kappa_gain", 0.0, 2.0, true, 0.5);
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

void Coupler::read_iterations(const fsi::SceneTable& t) {
  m_iter.max = static_cast<int>(t.positive_integer("max", 1));
  if (m_iter.max > 1000) t.fail("max", fmt::format("must be <= 1000, got {}", m_iter.max));
  m_iter.tolerance = t.in_range("tolerance", 0.0, 1.0, true, 1e-6);
  // IQN-ILS is the one method: the key is still accepted so that scenes naming it keep running.
  t.choice("acceleration", {"iqn-ils"}, "iqn-ils");
  m_iter.relaxation = t.in_range("relaxation", 0.0, 1.0, false, 0.5);
  if (!(m_iter.relaxation > 0)) t.fail("relaxation", "must be in (0, 1], got 0");
  const long reuse = t.integer("reuse", 0);
  if (reuse < 0 || reuse > 100) t.fail("reuse", fmt::format("must be in [0, 100], got {}", reuse));
  m_iter.reuse = static_cast<int>(reuse);
  t.finish();
}

// Sub-iterations need a fluid and a solid that can repeat a step (their ports say so at set-up).
void Coupler::check_can_iterate() const {
  if (m_iter.max <= 1) return;
  auto refuse = [&](const char* program) {
    throw fsi::InputError(fmt::format(
        "coupler.iterations.max = {} asks every step to be repeated, but the {} program cannot "
        "repeat a step (its port does not implement coupled iterations); set max = 1 (in {})",
        m_iter.max, program, m_rt.scene().file().string()));
  };
  if (has(Role::fluid) && !m_grid.can_iterate) refuse("fluid");
  if (has(Role::solid) && !m_meshes.can_iterate) refuse("solid");
}

void Coupler::run() {
  setup();
  const auto& s = m_rt.settings();
  fsi::Progress::Options po;
  po.every_steps = s.progress_every;
  m_progress = std::make_unique<fsi::Progress>("[coupler]", s.steps, fsi::step_time(s, s.steps), po);
  m_t_start = m_rt.wall_seconds();
  for (long n = 0; n < s.steps; ++n) step(n);
  finish();
}

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

// Set-up, once: grid from the fluid; meshes and initial state from the solid; layout from the
// fiber, then the fibers' root poses at t^0 and their initial state; each solver's effective
// scene.
void Coupler::setup() {
  auto effective = [&](fsi::Link& l, const char* role) {
    proto::Text t{proto::Tag::effective_scene, {}};
    l.recv(t);
    m_effective[role] = t.text;
  };
  if (has(Role::fluid)) {
    auto& l = m_rt.link(Role::fluid);
    l.recv(m_grid);
    effective(l, "fluid");
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
    m_ib = std::make_unique<FeedbackIB>(m_grid);
    if (!m_kappa_given) {
      // Default κ: the feedback acts as a spring between a marker and where the fluid carries it,
      // applied explicitly. Over one step it closes the fraction
      //   g = κ Δt² (1/m' + 1/m_f)
      // of the gap, with m' the fiber's line density (∞ for prescribed motion) and m_f = ρ_f h
      // a lower bound of the fluid mass per unit length the delta function reaches. g < 2 is the
      // explicit stability bound of that spring; the default takes g = coupler.kappa_gain (0.5)
      // for the lightest fiber.
      const double h = std::min(m_ib->hx(), m_ib->hy());
      const double dt = m_rt.settings().dt;
      double inv_mass = 1.0 / (m_grid.density * h);
      double lightest = 0;
      for (const auto& f : m_layout.fibers)
        if (f.line_density > 0) lightest = std::max(lightest, 1.0 / f.line_density);
      inv_mass += lightest;
      m_kappa = m_kappa_gain / (dt * dt * inv_mass);
      std::fprintf(stderr, "[coupler] feedback stiffness kappa = %.4g (gain %.2g at dt = %.3g)\n",
                   m_kappa, m_kappa_gain, dt);
    }
  }
  check_can_iterate();
  m_h_min = 1e300;
  for (std::size_t i = 0; i + 1 < m_grid.x_face.size(); ++i)
    m_h_min = std::min(m_h_min, m_grid.x_face[i + 1] - m_grid.x_face[i]);
  for (std::size_t j = 0; j + 1 < m_grid.y_face.size(); ++j)
    m_h_min = std::min(m_h_min, m_grid.y_face[j + 1] - m_grid.y_face[j]);
  const auto& bodies = m_meshes.bodies;
  if (!bodies.empty()) {
    if (!has(Role::fluid))
      fsi::fail("the scene has solid bodies and fibers but no fluid: nothing couples them");
    m_immersed = std::make_unique<ImmersedSolid>(m_grid, m_meshes);
    check_bodies_in_domain(0);
    warn_element_sizes();
  }
  m_solid_in.force.assign(bodies.size(), {});
  if (m_ib)
    for (const auto& f : m_layout.fibers)
      if (f.ds > 2 * std::max(m_ib->hx(), m_ib->hy()))
        std::fprintf(stderr,
                     "[coupler] WARNING: fiber '%s' has markers %.3g apart, more than twice the grid "
                     "spacing: the fluid leaks between them\n",
                     f.name.c_str(), f.ds);

  // Force probes: the scene's groups, or one per body.
  if (m_force_groups.empty())
    for (const auto& b : bodies) m_force_groups.push_back({b.name, {b.name}, {}});
  for (std::size_t g = 0; g < m_force_groups.size(); ++g) {
    for (const auto& name : m_force_groups[g].body_names) {
      auto it = std::find_if(bodies.begin(), bodies.end(), [&](const auto& b) { return b.name == name; });
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
    for (const auto& g : m_force_groups) cols.push_back(g.name + ".fx"), cols.push_back(g.name + ".fy");
    m_probes = std::make_unique<fsi::ProbeCsv>(m_rt.out_dir() / "coupler_forces.csv", cols);
    m_probe_row.assign(cols.size(), 0.0);
  }
  if (m_accel)
    m_iter_csv = std::make_unique<fsi::ProbeCsv>(
        m_rt.out_dir() / "coupler_iterations.csv",
        std::vector<std::string>{"step", "iterations", "residual_first", "residual", "converged",
                                 "omega", "columns"});
  if (m_log_csv || m_dump_every > 0)
    m_log = std::make_unique<ExchangeLog>(m_rt.out_dir(), m_grid, m_meshes, m_layout,
                                          m_rt.settings().dt, m_log_csv, m_dump_every);
  if (m_ib) check_fibers_in_domain(0);
  m_energy.assign(bodies.size(), 0.0);
  m_growing.assign(bodies.size(), 0);
  m_velocity.assign(bodies.size(), {});
  check_growth(0);
  m_momentum.resize(bodies.size());
  for (std::size_t b = 0; b < bodies.size(); ++b)
    m_momentum[b] = body_momentum(bodies[b], m_solid.x[b], m_solid.v[b], m_grid.density);

  // The effective scene: the coupler's own reading, each solver's table from that solver.
  std::istringstream own(m_rt.scene().effective_toml());
  auto doc = toml::parse<toml::discard_comments, std::map, std::vector>(own, "effective");
  for (const auto& [role, text] : m_effective) {
    std::istringstream is(text);
    const auto part = toml::parse<toml::discard_comments, std::map, std::vector>(is, role);
    if (part.contains(role)) doc.as_table()[role] = part.at(role);
  }
  fsi::write_file_atomically(m_rt.out_dir() / "scene.effective.toml", toml::format(doc));
}

// The non-periodic boundary a point (x, y) is beyond, or nullptr when it is inside the domain.
const char* Coupler::outside(double x, double y) const {
  if (!m_grid.periodic_x && x < m_grid.x_face.front()) return "left";
  if (!m_grid.periodic_x && x > m_grid.x_face.back()) return "right";
  if (!m_grid.periodic_y && y < m_grid.y_face.front()) return "bottom";
  if (!m_grid.periodic_y && y > m_grid.y_face.back()) return "top";
  return nullptr;
}

// A body must stay inside the fluid domain, except across a periodic boundary.
void Coupler::check_bodies_in_domain(long step) const {
  const double x0 = m_grid.x_face.front(), x1 = m_grid.x_face.back();
  const double y0 = m_grid.y_face.front(), y1 = m_grid.y_face.back();
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b) {
    const auto& x = m_solid.x[b];
    for (std::size_t k = 0; k + 1 < x.size(); k += 2) {
      if (const char* side = outside(x[k], x[k + 1])) {
        // Thrown out by the explicit coupling's instability before check_growth() could count
        // growth_steps steps of it: say so, it is the cause to fix.
        const long grew = b < m_growing.size() ? m_growing[b] : 0;
        const std::string cause =
            grew > 0 ? fmt::format("; its motion grew and reversed in the {} step(s) before: the "
                                   "explicit coupling cannot hold this body at this density "
                                   "ratio (make it heavier, or turn on coupled iterations, "
                                   "[coupler.iterations] max > 1)",
                                   grew)
                     : std::string();
        fsi::fail("body '{}' is outside the fluid domain [{}, {}] x [{}, {}] through its {} "
                  "boundary at step {}: node {} at ({}, {}){}",
                  m_meshes.bodies[b].name, x0, x1, y0, y1, side, step, k / 2, x[k], x[k + 1],
                  cause);
      }
    }
  }
}

// A fiber must stay inside the fluid domain, except across a periodic boundary: outside, its
// markers would neither feel the fluid nor act on it.
void Coupler::check_fibers_in_domain(long step) const {
  const double x0 = m_grid.x_face.front(), x1 = m_grid.x_face.back();
  const double y0 = m_grid.y_face.front(), y1 = m_grid.y_face.back();
  for (std::size_t k = 0; k < m_fiber.x.size() && k < m_layout.fibers.size(); ++k) {
    const auto& x = m_fiber.x[k];
    for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
      if (const char* side = outside(x[m], x[m + 1]))
        fsi::fail("fiber '{}' left the fluid domain [{}, {}] x [{}, {}] through its {} boundary "
                  "at step {}: marker {} at ({:.6g}, {:.6g})",
                  m_layout.fibers[k].name, x0, x1, y0, y1, side, step, m / 2, x[m], x[m + 1]);
    }
  }
}

// The explicit coupling of a body light against the fluid can be unstable at a given Δt: the
// fluid's reaction overshoots the body's own inertia, the motion reverses and grows every step
// (an amplification factor below −1), and the solid or the fluid fails a few steps later far
// from the cause. Caught here from each elastic body's velocity v (linear on each triangle T,
// integrals exact with ∫_T N_a N_b dA = |T| (1 + δ_ab)/12):
//   E = ½ ∫ |v|² dA = Σ_T |T|/24 (Σ_a |v_a|² + |Σ_a v_a|²)          (kinetic energy / density)
//   C = ∫ vⁿ⁺¹·vⁿ dA = Σ_T |T|/12 (Σ_a vⁿ⁺¹_a·vⁿ_a + Σ_a vⁿ⁺¹_a · Σ_a vⁿ_a)
// A step with E grown by more than coupler.health.growth_factor and C < 0 (the velocity field
// reversed) is a growth step; growth_steps of them in a row stop the run. Physical motion does
// not reverse at every step of the time discretisation while it grows.
void Coupler::check_growth(long step) {
  for (std::size_t b = 0; b < m_meshes.bodies.size() && b < m_solid.x.size(); ++b) {
    const auto& body = m_meshes.bodies[b];
    if (body.kind != proto::BodyKind::elastic) continue;
    const auto& x = m_solid.x[b];
    const auto& v = m_solid.v[b];
    auto& vo = m_velocity[b];
    const bool has_old = vo.size() == v.size();
    double e = 0, c = 0;
    for (std::size_t t = 0; t + 2 < body.tri.size(); t += 3) {
      const int i = body.tri[t], j = body.tri[t + 1], k = body.tri[t + 2];
      const double area = 0.5 * std::abs((x[2 * j] - x[2 * i]) * (x[2 * k + 1] - x[2 * i + 1]) -
                                         (x[2 * k] - x[2 * i]) * (x[2 * j + 1] - x[2 * i + 1]));
      double sq = 0, cr = 0;
      for (int d = 0; d < 2; ++d) {
        const double a = v[2 * i + d], bb = v[2 * j + d], cc = v[2 * k + d];
        sq += a * a + bb * bb + cc * cc + (a + bb + cc) * (a + bb + cc);
        if (has_old) {
          const double ao = vo[2 * i + d], bo = vo[2 * j + d], co = vo[2 * k + d];
          cr += a * ao + bb * bo + cc * co + (a + bb + cc) * (ao + bo + co);
        }
      }
      e += area / 24.0 * sq;
      c += area / 12.0 * cr;
    }
    const double before = m_energy[b];
    const bool grew = has_old && before > 0 && e > m_growth_factor * before && c < 0;
    m_growing[b] = grew ? m_growing[b] + 1 : 0;
    m_energy[b] = e;
    vo = v;
    if (m_growing[b] >= m_growth_steps)
      fsi::fail("body '{}' is unstable at step {}: its kinetic energy per unit density "
                "1/2 int |v|^2 dA = {:.3g} grew by more than a factor {} and its velocity "
                "reversed in each of the last {} steps: the explicit coupling cannot hold this "
                "time.dt = {} (lower it, make the body heavier, or turn on coupled iterations, "
                "[coupler.iterations] max > 1)",
                body.name, step, e, m_growth_factor, m_growth_steps, m_rt.settings().dt);
  }
}

// Elements much larger than the grid spacing are clipped exactly but forced at the grid's
// resolution; much smaller ones cost clipping work for nothing.
void Coupler::warn_element_sizes() const {
  double hmin = 1e300;
  for (std::size_t i = 0; i + 1 < m_grid.x_face.size(); ++i)
    hmin = std::min(hmin, m_grid.x_face[i + 1] - m_grid.x_face[i]);
  for (std::size_t j = 0; j + 1 < m_grid.y_face.size(); ++j)
    hmin = std::min(hmin, m_grid.y_face[j + 1] - m_grid.y_face[j]);
  for (const auto& b : m_meshes.bodies) {
    if (b.tri.empty()) continue;
    double sum = 0;
    for (std::size_t e = 0; e + 2 < b.tri.size(); e += 3)
      for (int k = 0; k < 3; ++k) {
        const int i = b.tri[e + k], j = b.tri[e + (k + 1) % 3];
        sum += std::hypot(b.x_ref[2 * j] - b.x_ref[2 * i], b.x_ref[2 * j + 1] - b.x_ref[2 * i + 1]);
      }
    const double h = sum / static_cast<double>(b.tri.size());
    if (h > 4 * hmin)
      std::fprintf(stderr,
                   "[coupler] WARNING: body '%s' has elements (mean edge %.3g) much larger than the "
                   "grid spacing (%.3g): the volume fractions are still exact, but the forcing "
                   "only resolves the grid\n",
                   b.name.c_str(), h, hmin);
    if (h < hmin / 8)
      std::fprintf(stderr,
                   "[coupler] WARNING: body '%s' has elements (mean edge %.3g) tiny against the "
                   "grid spacing (%.3g): clipping costs grow with no gain in the forcing\n",
                   b.name.c_str(), h, hmin);
  }
}

// Send `in` to a solver and wait for its answer, timed as that solver's phase.
template <class In, class Out>
void Coupler::exchange(Role r, const In& in, Out& out, long n) {
  m_phases.start(fsi::role_name(r));
  auto& l = m_rt.link(r);
  l.send(in, n);
  l.recv(out);
  m_phases.stop(fsi::role_name(r));
}

// One step t^n -> t^(n+1) (common/PROTOCOL.md), with coupled iterations when
// coupler.iterations.max > 1 (README.md): messages 1-5 are repeated, the fluid redoing its forcing
// and projection from the same predictor u~ and the solid its step from the state at t^n,
// until the solid's velocities stop changing; then the step is committed and the fibers follow.
// With max = 1 this is the explicit staggered step, every operation in the same order.
void Coupler::step(long n) {
  const auto& s = m_rt.settings();
  const bool iterate = m_accel && m_immersed;
  proto::StepBegin sb{n, fsi::step_time(s, n), s.dt, proto::Action::step, 0, iterate ? 1 : 0};
  // The solid's step_begin waits until the footprint is done: the solid's work ahead of its
  // forces (a factorisation) then runs beside the fluid's step, not beside the clipping and the
  // fluid's own work ahead of its input.
  for (Role r : {Role::fluid, Role::fiber})
    if (has(r)) m_rt.link(r).send(sb, n);
  m_rt.check_fault(n);
  m_start = m_solid;  // the bodies' state at t^n

  // The footprint's state: x^n, and the first estimate of the velocities at t^(n+1). The
  // explicit step takes v^n. Iterations start from the linear extrapolation 2 v^n - v^(n-1)
  // (v^n on the first step): an O(dt^2) guess instead of O(dt) for smooth motion, so fewer
  // iterations; the converged step does not depend on it.
  const proto::SolidState* footprint = &m_start;
  if (iterate) {
    m_guess = m_start;
    if (m_v_before.size() == m_start.v.size())
      for (std::size_t b = 0; b < m_guess.v.size(); ++b)
        if (m_meshes.bodies[b].kind == proto::BodyKind::elastic && m_v_before[b].size() == m_guess.v[b].size())
          for (std::size_t d = 0; d < m_guess.v[b].size(); ++d)
            m_guess.v[b][d] = 2 * m_start.v[b][d] - m_v_before[b][d];
    m_v_before = m_start.v;
    footprint = &m_guess;
    m_accel->begin_step();
  }
  // 2: the fibers' feedback force from U(X^n), its spread, and the faces to sample next
  // (once per step: the fibers' step follows the converged solid).
  if (m_ib) {
    m_phases.start("fibers");
    feedback_forces();
    m_phases.stop("fibers");
  }
  const bool had_samples = m_have_samples;

  int k = 0;
  bool converged = !iterate;
  double res_first = 0, res = 0;
  for (;; ++k) {
    if (k > 0) {
      sb.iteration = k;
      for (Role r : {Role::fluid, Role::solid})
        if (has(r)) m_rt.link(r).send(sb, n);
    }
    // 2: the bodies' footprint, α and ū_s, from x^n and the velocity estimate (the footprint of
    // x^n is clipped once per step; an iteration only averages its new velocities).
    if (m_immersed) {
      m_phases.start("footprint");
      if (k == 0) m_immersed->update(*footprint, m_fluid_in.solid_u, m_fluid_in.solid_v);
      else m_immersed->update_velocities(*footprint, m_fluid_in.solid_u, m_fluid_in.solid_v);
      m_phases.stop("footprint");
    }
    if (k == 0 && has(Role::solid)) m_rt.link(Role::solid).send(sb, n);
    // 3-4: the fluid step (or its forcing and projection again).
    if (has(Role::fluid)) exchange(Role::fluid, m_fluid_in, m_fluid_out, n);
    // 5-6: the exact reaction of f_s on the bodies' nodes.
    if (m_immersed) {
      m_phases.start("reaction");
      m_immersed->reaction(m_fluid_out.fs_u, m_fluid_out.fs_v, m_solid_in.force);
      m_phases.stop("reaction");
    }
    m_reaction = m_solid_in.force;
    // Rigid bodies move by their law: their reaction is only measured, not sent.
    for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
      if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) m_solid_in.force[b].clear();
    // With iterations the solid also gets the velocities this pass's forcing used (protocol
    // version 3): the reaction's linearisation dF/dv ~ -M_f/dt is about them.
    if (iterate) {
      m_solid_in.velocity = footprint->v;
      for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
        if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) m_solid_in.velocity[b].clear();
    }
    add_root_loads(m_start);
    // 7: the solid step (or the same step again from its state at t^n).
    if (has(Role::solid)) {
      exchange(Role::solid, m_solid_in, m_solid, n);
      if (m_immersed) check_bodies_in_domain(n + 1);
    }
    if (!iterate) break;
    // Residual of the fixed point v = H(v) over every elastic body's nodes, against |v^(k+1)|
    // with a floor: 1 % of the fluid's fastest speed at every node, U = CFL h_min / dt (a lower
    // bound of max |u| from the fluid's CFL number). A body at rest in a moving fluid (a steady
    // state, a start from rest) then keeps an attainable target instead of one at round-off.
    m_phases.start("iterations");
    gather_velocities(*footprint, m_x_in);
    gather_velocities(m_solid, m_x_out);
    double r2 = 0, v2 = 0;
    for (std::size_t i = 0; i < m_x_in.size(); ++i) {
      const double d = m_x_out[i] - m_x_in[i];
      r2 += d * d, v2 += m_x_out[i] * m_x_out[i];
    }
    const double u_fluid = m_fluid_out.cfl * m_h_min / s.dt;
    const double floor = 0.01 * u_fluid * std::sqrt(static_cast<double>(m_x_in.size()));
    const double scale = std::max(std::sqrt(v2), floor);
    res = scale > 0 ? std::sqrt(r2) / scale : (r2 > 0 ? 1.0 : 0.0);
    if (k == 0) res_first = res;
    converged = res <= m_iter.tolerance;
    if (converged || k + 1 >= m_iter.max) {
      m_phases.stop("iterations");
      break;
    }
    m_accel->update(m_x_in, m_x_out, m_x_next);
    if (footprint != &m_guess) m_guess = m_start;
    scatter_velocities(m_x_next, m_guess);
    // Rigid bodies: their velocity at t^(n+1), as the solid just reported it.
    for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
      if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) m_guess.v[b] = m_solid.v[b];
    footprint = &m_guess;
    m_phases.stop("iterations");
  }
  if (iterate) {
    const long its = k + 1;
    m_accel->end_step(converged);
    m_iter_total += its;
    m_iter_max = std::max(m_iter_max, its);
    m_residual_max = std::max(m_residual_max, res);
    if (!converged) {
      ++m_not_converged;
      if (m_not_converged <= 20)
        std::fprintf(stderr,
                     "[coupler] WARNING: step %ld (t = %.6g): the coupled iterations did not "
                     "converge in coupler.iterations.max = %d: residual %.3e, tolerance %.1e%s\n",
                     n, sb.time, m_iter.max, res, m_iter.tolerance,
                     m_not_converged == 20 ? " (further warnings only counted in summary.json)"
                                           : "");
    }
    m_iter_csv->write(fsi::step_time(s, n + 1),
                      {double(n), double(its), res_first, res, converged ? 1.0 : 0.0,
                       m_accel->omega(), double(m_accel->columns())});
  }

  // The committed step: the exchange log, the fibers' samples of u^(n+1), the force probes, the
  // growth check, as for the explicit step.
  if (m_log) {
    m_log->inputs(n, sb.time, *footprint, m_fiber, m_fluid_in, m_fiber_in, m_ib.get(), had_samples);
  }
  if (m_ib && has(Role::fluid)) {
    m_ib->store_samples(m_fluid_in.sample_u, m_fluid_out.u_sample, m_fluid_in.sample_v,
                        m_fluid_out.v_sample);
    m_have_samples = true;
  }
  if (m_log) {
    m_log->reaction(m_fluid_in, m_fluid_out, m_reaction);
    auto before = m_reaction;
    for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
      if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) before[b].clear();
    m_log->before_root_loads(before);
    root_poses(m_start, m_log_poses);
    m_log->root_loads(m_solid_in.force, m_fiber.root_load, m_log_poses);
  }
  write_force_probes(n, m_start, m_reaction);
  if (has(Role::solid)) check_growth(n + 1);
  // 8-9: the fiber step, with the root poses from the solid's new state.
  if (has(Role::fiber)) {
    root_poses(m_solid, m_fiber_in.root_pose);
    exchange(Role::fiber, m_fiber_in, m_fiber, n);
    if (m_ib) check_fibers_in_domain(n + 1);
  }
  if (m_log) m_log->end_step();
  m_progress->update(n + 1, fsi::step_time(s, n + 1), s.dt, [&] {
    std::string st = fmt::format("CFL {:.3g}  div {:.1e}", m_fluid_out.cfl, m_fluid_out.max_div);
    if (iterate) st += fmt::format("  iter {}  res {:.1e}", k + 1, res);
    return st;
  });
}

// The stacked velocities of the elastic bodies (the unknowns of the coupled iterations).
void Coupler::gather_velocities(const proto::SolidState& s, std::vector<double>& x) const {
  x.clear();
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind == proto::BodyKind::elastic) x.insert(x.end(), s.v[b].begin(), s.v[b].end());
}

void Coupler::scatter_velocities(const std::vector<double>& x, proto::SolidState& s) const {
  std::size_t i = 0;
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind == proto::BodyKind::elastic)
      for (double& v : s.v[b]) v = x[i++];
}

// "bar, cylinder", or "none": the bodies' names for error messages.
std::string Coupler::body_names() const {
  std::vector<std::string> names;
  for (const auto& b : m_meshes.bodies) names.push_back(b.name);
  return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

// Attached fibers: the body by name, and the surface edge nearest to the root's reference point
// (it must lie on the surface: within a thousandth of the edge's length).
void Coupler::resolve_roots() {
  const auto& bodies = m_meshes.bodies;
  m_roots.assign(m_layout.fibers.size(), Root{});
  for (std::size_t k = 0; k < m_layout.fibers.size(); ++k) {
    const auto& f = m_layout.fibers[k];
    if (f.root != 1) continue;
    auto it = std::find_if(bodies.begin(), bodies.end(), [&](const auto& b) { return b.name == f.body; });
    if (it == bodies.end())
      throw fsi::InputError(fmt::format(
          "fiber '{}' is rooted on body '{}', which the scene does not have (bodies: {}) (in {})",
          f.name, f.body, body_names(), m_rt.scene().file().string()));
    const auto& b = *it;
    Root r;
    r.body = static_cast<int>(it - bodies.begin());
    double best = 1e300, best_len = 0;
    for (std::size_t e = 0; e + 1 < b.edges.size(); e += 2) {
      const int a = b.edges[e], c = b.edges[e + 1];
      const double ax = b.x_ref[2 * a], ay = b.x_ref[2 * a + 1];
      const double dx = b.x_ref[2 * c] - ax, dy = b.x_ref[2 * c + 1] - ay;
      const double len2 = dx * dx + dy * dy;
      const double s = std::clamp(((f.root_x - ax) * dx + (f.root_y - ay) * dy) / len2, 0.0, 1.0);
      const double d = std::hypot(ax + s * dx - f.root_x, ay + s * dy - f.root_y);
      if (d < best) best = d, best_len = std::sqrt(len2), r.a = a, r.b = c, r.s = s;
    }
    if (b.edges.empty() || best > 1e-3 * best_len)
      throw fsi::InputError(fmt::format(
          "fiber '{}': its root ({}, {}) is not on the surface of body '{}' (nearest surface point "
          "{:.3g} away) (in {})",
          f.name, f.root_x, f.root_y, f.body, best, m_rt.scene().file().string()));
    m_roots[k] = r;
  }
}

// Root pose of each attached fiber from the current solid state: the material point of its edge,
// and the edge's outward normal (the body lies on the left of a -> b).
void Coupler::root_poses(const proto::SolidState& state,
                         std::vector<std::vector<double>>& poses) const {
  poses.assign(m_layout.fibers.size(), {});
  for (std::size_t k = 0; k < m_roots.size(); ++k) {
    const Root& r = m_roots[k];
    if (r.body < 0) continue;
    const auto& x = state.x[r.body];
    const double ax = x[2 * r.a], ay = x[2 * r.a + 1], dx = x[2 * r.b] - ax, dy = x[2 * r.b + 1] - ay;
    const double len = std::hypot(dx, dy);
    poses[k] = {ax + r.s * dx, ay + r.s * dy, dy / len, -dx / len};
  }
}

// The fiber's load on its support (force F, moment M at the root point p) as equivalent nodal
// forces on the edge a -> b that holds it (paper Sec. 3.2.3, Fig. 2):
//   f_a = (1 − s) F − q n,  f_b = s F + q n,  n = (−t_y, t_x), q = M / L,
// with t the edge's unit tangent and L its length: the resultant is F, and the moment about p is
// (1 − s)(x_a − p) × F + s (x_b − p) × F + q (x_b − x_a) × n = 0 + q L = M, exactly.
void Coupler::add_root_loads(const proto::SolidState& state) {
  for (std::size_t k = 0; k < m_roots.size(); ++k) {
    const Root& r = m_roots[k];
    if (r.body < 0 || m_fiber.root_load.size() < 3 * (k + 1)) continue;
    const double fx = m_fiber.root_load[3 * k], fy = m_fiber.root_load[3 * k + 1];
    const double M = m_fiber.root_load[3 * k + 2];
    const auto& x = state.x[r.body];
    const double dx = x[2 * r.b] - x[2 * r.a], dy = x[2 * r.b + 1] - x[2 * r.a + 1];
    const double len = std::hypot(dx, dy);
    const double q = M / len, nx = -dy / len, ny = dx / len;
    auto& f = m_solid_in.force[r.body];
    if (f.empty()) f.assign(x.size(), 0.0);
    f[2 * r.a] += (1 - r.s) * fx - q * nx;
    f[2 * r.a + 1] += (1 - r.s) * fy - q * ny;
    f[2 * r.b] += r.s * fx + q * nx;
    f[2 * r.b + 1] += r.s * fy + q * ny;
  }
}

// Feedback force on each fiber's markers (paper Eq. 23-24, force per unit length on the fiber):
//   F = κ (X_ib − 2Xⁿ + X^(n−1)),  X_ib = Xⁿ + Δt U(Xⁿ),
// i.e. κ Δt (U(Xⁿ) − (Xⁿ − X^(n−1))/Δt): it pulls each marker towards the fluid's velocity. The
// fluid receives the opposite, spread with the same delta function (Eq. 25). U(Xⁿ) comes from
// the fluid's samples of uⁿ taken after the previous step; on the very first step there are none
// and the feedback starts one step later. The faces to sample for the next step are the kernels
// of Xⁿ widened by one cell (a marker moves less than a cell per step).
void Coupler::feedback_forces() {
  const double dt = m_rt.settings().dt;
  for (std::size_t k = 0; k < m_layout.fibers.size(); ++k) {
    const auto& X = m_fiber.x[k];
    const auto& Xo = m_fiber.x_old[k];
    auto& F = m_fiber_in.force[k];
    F.assign(X.size(), 0.0);
    if (!m_have_samples) continue;
    m_ib->interpolate(X, m_u_markers);
    for (std::size_t m = 0; m < X.size(); ++m) F[m] = m_kappa * (dt * m_u_markers[m] - (X[m] - Xo[m]));
    m_ib->spread(X, F, m_layout.fibers[k].ds);
  }
  m_ib->take_spread(m_fluid_in.force_u, m_fluid_in.force_v);
  m_ib->stencil(m_fiber.x, 1, m_fluid_in.sample_u, m_fluid_in.sample_v);
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

void Coupler::finish() {
  const auto& s = m_rt.settings();
  const proto::StepBegin stop{s.steps, fsi::step_time(s, s.steps), s.dt, proto::Action::stop};
  nlohmann::json j;
  j["scene"] = s.name;
  j["scene_file"] = m_rt.scene().file().string();
  j["steps"] = s.steps;
  j["time"] = fsi::step_time(s, s.steps);
  j["dt"] = s.dt;
  for (Role r : {Role::fluid, Role::solid, Role::fiber}) {
    if (!has(r)) continue;
    auto& l = m_rt.link(r);
    l.send(stop, s.steps);
    proto::Text report{proto::Tag::final_report, {}};
    l.recv(report);
    auto part = nlohmann::json::parse(report.text);
    j["wall_time"][fsi::role_name(r)] = part["wall_time"];
    j[fsi::role_name(r)] = part;
  }
  const double loop = std::max(m_rt.wall_seconds() - m_t_start, 1e-9);
  j["wall_time"]["coupler"] = m_rt.wall_seconds();
  j["coupler"]["steps_per_second"] = s.steps / loop;
  j["coupler"]["us_per_step"] = 1e6 * loop / s.steps;
  j["coupler"]["phases"] = nlohmann::json::parse(m_phases.to_json().dump());
  if (m_accel) {
    j["coupler"]["iterations"] = {
        {"max", m_iter.max},
        {"tolerance", m_iter.tolerance},
        {"relaxation", m_iter.relaxation},
        {"reuse", m_iter.reuse},
        {"total", m_iter_total},
        {"mean_per_step", s.steps > 0 ? double(m_iter_total) / double(s.steps) : 0.0},
        {"max_per_step", m_iter_max},
        {"not_converged_steps", m_not_converged},
        {"largest_final_residual", m_residual_max}};
  }
  fsi::write_summary(m_rt, j);
  m_progress->finish(s.steps, fsi::step_time(s, s.steps),
                     fmt::format("output in {}", m_rt.out_dir().string()));
}

}  // namespace coupler
