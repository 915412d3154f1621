// The coupler's clock and its step (the paper's Sec. 3.3; message order in common/PROTOCOL.md):
// one step is the list of named steps in step(); the coupled iterations that repeat some of them
// live beside it.
#include "coupler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "checkpoint.hpp"
#include "driver.hpp"

namespace coupler {

using fsi::Role;

namespace {

// The residual's floor, as a fraction of the fluid's fastest speed at every node: a body at rest
// in a moving fluid keeps an attainable target instead of one at round-off.
constexpr double kResidualFloor = 0.01;
// Steps whose unconverged iterations are warned about one by one; later ones are only counted.
constexpr long kWarnedSteps = 20;
// The loop's wall time for the rates in summary.json is at least this: a run of no steps divides
// by it, not by zero.
constexpr double kMinLoopSeconds = 1e-9;

}  // namespace

void Coupler::run() {
  setup();
  if (m_rt.restart_step()) load(fsi::open_restart(m_rt));
  const auto& s = m_rt.settings();
  const long first = m_rt.first_step();
  fsi::Progress::Options po;
  po.every_steps = s.progress_every;
  po.first_step = first;
  po.first_time = fsi::step_time(s, first);
  m_progress =
      std::make_unique<fsi::Progress>("[coupler]", s.steps, fsi::step_time(s, s.steps), po);
  m_t_start = m_rt.wall_seconds();
  // Asked to stop (a signal, the time limit): the next step is checkpointed and is the last.
  long n = first;
  while (n < s.steps) {
    m_stopping = m_stopping || m_rt.stop_requested();
    step(n++);
    if (m_stopping) break;
  }
  finish(n, first);
}

// One step t^n -> t^(n+1). With coupler.iterations.max = 1 the explicit staggered step; with
// max > 1 iterate() repeats footprint() to solid() within it (README.md, "Coupled iterations").
void Coupler::step(long n) {
  begin_step(n);        // 1: step_begin to the fluid and the fiber; the bodies' state at t^n
  feedback_forces();    // the fibers' feedback force F_f from U(X^n), its spread f_f
  footprint();          // the bodies' footprint: α and ū_s on the control volumes they touch
  begin_solid_step(n);  // 1: step_begin to the solid, once the footprint is done
  fluid(n);             // 2-3: α, ū_s, f_f to the fluid; its step; f_s and u^(n+1) samples back
  reaction();           // 4: the nodal forces on the solid: F_s, the reaction of f_s; root loads
  solid(n);             // 4-5: the solid step; x^(n+1), v^(n+1) back
  iterate(n);           // coupled iterations: 1-5 again until v^(n+1) agrees
  commit(n);            // the accepted step: exchange log, samples, force probes, growth check
  fibers(n);            // 6-7: root poses at t^(n+1) to the fiber; its step; root loads back
  report(n);
  if (m_sb.checkpoint) fsi::write_checkpoint(m_rt, n + 1, [&](fsi::H5File& h5) { save(h5); });
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

// The solid's step_begin waits for the footprint (begin_solid_step): the solid's work ahead of
// its forces (a factorisation) then runs beside the fluid's step, not beside the clipping and the
// fluid's own work ahead of its input.
void Coupler::begin_step(long n) {
  const auto& s = m_rt.settings();
  m_sb =
      proto::StepBegin{n, fsi::step_time(s, n), s.dt, proto::Action::step, 0, iterates() ? 1 : 0};
  m_sb.checkpoint = m_stopping || fsi::is_checkpoint_step(s, n + 1);
  for (Role r : {Role::fluid, Role::fiber})
    if (has(r))
      for (auto& l : m_rt.links(r)) l->send(m_sb, n);
  m_rt.check_fault(n);
  m_start = m_solid;  // the bodies' state at t^n
  if (!iterates()) return;
  // The first estimate of v^(n+1): the linear extrapolation 2 v^n - v^(n-1) (v^n on the first
  // step), an O(dt^2) guess instead of O(dt) for smooth motion; the converged step does not
  // depend on it. The explicit step takes v^n.
  m_guess = m_start;
  if (m_v_before.size() == m_start.v.size())
    for (std::size_t b = 0; b < m_guess.v.size(); ++b)
      if (m_meshes.bodies[b].kind == proto::BodyKind::elastic &&
          m_v_before[b].size() == m_guess.v[b].size())
        for (std::size_t d = 0; d < m_guess.v[b].size(); ++d)
          m_guess.v[b][d] = 2 * m_start.v[b][d] - m_v_before[b][d];
  m_v_before = m_start.v;
  m_accel->begin_step();
}

// α = |V ∩ body| / |V| and ū_s, the mean of the FE velocity over V ∩ body, on every control
// volume V the bodies touch (ImmersedSolid::update), from x^n and the velocity estimate. The
// footprint of x^n is clipped once per step; an iteration only averages its new velocities.
void Coupler::footprint() {
  if (!m_immersed) return;
  m_phases.start("footprint");
  if (m_sb.iteration == 0)
    m_immersed->update(footprint_state(), m_fluid_in.solid_u, m_fluid_in.solid_v);
  else
    m_immersed->update_velocities(footprint_state(), m_fluid_in.solid_u, m_fluid_in.solid_v);
  m_phases.stop("footprint");
}

void Coupler::begin_solid_step(long n) {
  if (has(Role::solid)) m_rt.link(Role::solid).send(m_sb, n);
}

// The fluid's step (or, in iteration k > 0, its forcing f_s = ρ_f α (ū_s − ũ)/Δt and projection
// again from the same predictor ũ).
void Coupler::fluid(long n) {
  if (m_surface && m_sb.iteration == 0) request_surface_samples();
  if (!has(Role::fluid)) return;
  if (!m_fluid_ranks) return exchange(Role::fluid, m_fluid_in, m_fluid_out, n);
  // Several fluid ranks: each gets the part of the input on its rows; all answer.
  m_phases.start("fluid");
  m_fluid_ranks->split(m_fluid_in);
  auto& links = m_rt.links(Role::fluid);
  for (int r = 0; r < m_fluid_ranks->ranks(); ++r) links[r]->send(m_fluid_ranks->part(r), n);
  for (int r = 0; r < m_fluid_ranks->ranks(); ++r) links[r]->recv(m_fluid_ranks->answer(r));
  m_fluid_ranks->merge(m_fluid_out);
  m_phases.stop("fluid");
}

// The nodal forces on the solid: the exact reaction of f_s (ImmersedSolid::reaction),
//   F_a = − Σ_V f_s(V) |V| ∫_{V∩body} N_a dA / Σ_bodies |V ∩ body|,
// kept whole for the probes and the log; rigid bodies move by their law, so theirs is only
// measured, not sent. Then the fibers' root loads of step n − 1 as nodal forces (roots.cpp).
void Coupler::reaction() {
  if (m_immersed) {
    m_phases.start("reaction");
    m_immersed->reaction(m_fluid_out.fs_u, m_fluid_out.fs_v, m_solid_in.force);
    m_phases.stop("reaction");
  }
  m_reaction = m_solid_in.force;
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) m_solid_in.force[b].clear();
  // With iterations the solid also gets the velocities this pass's forcing used (protocol
  // version 3): the reaction's linearisation dF/dv ~ -M_f/dt is about them.
  if (iterates()) {
    m_solid_in.velocity = footprint_state().v;
    for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
      if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) m_solid_in.velocity[b].clear();
  }
  add_root_loads(m_start);
}

// The solid's step (or the same step again from its state at t^n).
void Coupler::solid(long n) {
  if (!has(Role::solid)) return;
  exchange(Role::solid, m_solid_in, m_solid, n);
  if (m_immersed) check_bodies_in_domain(n + 1);
}

// The coupled iterations of step n: the fixed point v = H(v) of one pass footprint -> fluid ->
// reaction -> solid, v the elastic bodies' nodal velocities at t^(n+1). The pass of step() is
// iteration 0; each further one takes the accelerated estimate (IQN-ILS, acceleration.hpp), until
// residual() <= coupler.iterations.tolerance or coupler.iterations.max passes.
void Coupler::iterate(long n) {
  if (!iterates()) return;
  for (int k = 0;; ++k) {
    m_phases.start("iterations");
    m_res = residual();
    if (k == 0) m_res_first = m_res;
    m_its = k + 1;
    m_converged = m_res <= m_iter.tolerance;
    if (m_converged || k + 1 >= m_iter.max) {
      m_phases.stop("iterations");
      break;
    }
    next_estimate();
    m_phases.stop("iterations");
    m_sb.iteration = k + 1;
    for (Role r : {Role::fluid, Role::solid})
      if (has(r))
        for (auto& l : m_rt.links(r)) l->send(m_sb, n);
    footprint();
    fluid(n);
    reaction();
    solid(n);
  }
  count_iterations(n);
}

// |v̂ − v| / max(|v̂|, kResidualFloor √N U) over the stacked nodal velocities of every elastic
// body (N values), v the input of the pass and v̂ the solid's answer; U = CFL h_min / Δt, a lower
// bound of the fluid's fastest speed from its CFL number.
double Coupler::residual() {
  gather_velocities(footprint_state(), m_x_in);
  gather_velocities(m_solid, m_x_out);
  double r2 = 0, v2 = 0;
  for (std::size_t i = 0; i < m_x_in.size(); ++i) {
    const double d = m_x_out[i] - m_x_in[i];
    r2 += d * d, v2 += m_x_out[i] * m_x_out[i];
  }
  const double u_fluid = m_fluid_out.cfl * m_h_min / m_rt.settings().dt;
  const double floor = kResidualFloor * u_fluid * std::sqrt(static_cast<double>(m_x_in.size()));
  const double scale = std::max(std::sqrt(v2), floor);
  return scale > 0 ? std::sqrt(r2) / scale : (r2 > 0 ? 1.0 : 0.0);
}

// The next input: the accelerated estimate for the elastic bodies; rigid bodies take their
// velocity at t^(n+1), as the solid just reported it.
void Coupler::next_estimate() {
  m_accel->update(m_x_in, m_x_out, m_x_next);
  scatter_velocities(m_x_next, m_guess);
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind != proto::BodyKind::elastic) m_guess.v[b] = m_solid.v[b];
}

// The step's iterations into the statistics, the warning of a step that did not converge, and
// its row of coupler_iterations.csv.
void Coupler::count_iterations(long n) {
  m_accel->end_step(m_converged);
  m_iter_total += m_its;
  m_iter_max = std::max(m_iter_max, m_its);
  m_residual_max = std::max(m_residual_max, m_res);
  if (!m_converged) {
    ++m_not_converged;
    if (m_not_converged <= kWarnedSteps)
      std::fprintf(stderr,
                   "[coupler] WARNING: step %ld (t = %.6g): the coupled iterations did not "
                   "converge in coupler.iterations.max = %d: residual %.3e, tolerance %.1e%s\n",
                   n, m_sb.time, m_iter.max, m_res, m_iter.tolerance,
                   m_not_converged == kWarnedSteps
                       ? " (further warnings only counted in summary.json)"
                       : "");
  }
  m_iter_csv->write(fsi::step_time(m_rt.settings(), n + 1),
                    {double(n), double(m_its), m_res_first, m_res, m_converged ? 1.0 : 0.0,
                     m_accel->omega(), double(m_accel->columns())});
}

// The accepted step (the last iteration): the exchange log, the fibers' samples of u^(n+1) for
// the next step, the force probes, the growth check.
void Coupler::commit(long n) {
  if (m_log)
    m_log->inputs(n, m_sb.time, footprint_state(), m_fiber, m_fluid_in, m_fiber_in, m_ib.get(),
                  m_have_samples);
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
    m_log->root_loads(m_solid_in.force, root_loads_without_inertia(), m_log_poses,
                      m_fiber.root_mass, m_solid_in.root_mass);
  }
  write_force_probes(n, m_start, m_reaction);
  write_surface_probes(n);
  if (has(Role::solid)) check_growth(n + 1);
}

// The fiber step, once per step after the accepted solid step: the root poses from the solid's
// state at t^(n+1) (roots.cpp) go with F_f; X^(n+1) and the root loads come back.
void Coupler::fibers(long n) {
  if (!has(Role::fiber)) return;
  root_poses(m_solid, m_fiber_in.root_pose);
  exchange(Role::fiber, m_fiber_in, m_fiber, n);
  if (m_ib) check_fibers_in_domain(n + 1);
}

void Coupler::report(long n) {
  if (m_log) m_log->end_step();
  const auto& s = m_rt.settings();
  m_progress->update(n + 1, fsi::step_time(s, n + 1), s.dt, [&] {
    std::string st = fmt::format("CFL {:.3g}  div {:.1e}", m_fluid_out.cfl, m_fluid_out.max_div);
    if (iterates()) st += fmt::format("  iter {}  res {:.1e}", m_its, m_res);
    return st;
  });
}

// The stacked velocities of the elastic bodies (the unknowns of the coupled iterations).
void Coupler::gather_velocities(const proto::SolidState& s, std::vector<double>& x) const {
  x.clear();
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind == proto::BodyKind::elastic)
      x.insert(x.end(), s.v[b].begin(), s.v[b].end());
}

void Coupler::scatter_velocities(const std::vector<double>& x, proto::SolidState& s) const {
  std::size_t i = 0;
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind == proto::BodyKind::elastic)
      for (double& v : s.v[b]) v = x[i++];
}

// The end of the run: stop to every solver, their final reports into summary.json.
void Coupler::finish(long steps, long first) {
  const auto& s = m_rt.settings();
  const proto::StepBegin stop{steps, fsi::step_time(s, steps), s.dt, proto::Action::stop};
  nlohmann::json j;
  j["scene"] = s.name;
  j["scene_file"] = m_rt.scene().file().string();
  j["protocol_version"] = proto::kVersion;
  j["steps"] = steps;
  j["time"] = fsi::step_time(s, steps);
  j["dt"] = s.dt;
  if (m_rt.restart_step()) j["restarted_from_step"] = first;
  if (steps < s.steps) j["stopped_at_step"] = steps;
  for (Role r : {Role::fluid, Role::solid, Role::fiber}) {
    if (!has(r)) continue;
    // Every rank of the solver is stopped and reports; its rank 0's report stands for it (the
    // fluid's diagnostics are the whole grid's on every rank), with the count of ranks.
    auto& links = m_rt.links(r);
    for (auto& l : links) l->send(stop, steps);
    nlohmann::json traffic = nlohmann::json::array();
    for (std::size_t k = 0; k < links.size(); ++k) {
      proto::Text report{proto::Tag::final_report, {}};
      links[k]->recv(report);
      auto part = nlohmann::json::parse(report.text);
      // Per rank: the bytes it received from and sent to the coupler (its share of the traffic).
      traffic.push_back({{"received", part["bytes_received"]}, {"sent", part["bytes_sent"]}});
      if (k > 0) continue;
      j["wall_time"][fsi::role_name(r)] = part["wall_time"];
      j[fsi::role_name(r)] = part;
    }
    if (links.size() > 1) {
      j[fsi::role_name(r)]["ranks"] = links.size();
      j[fsi::role_name(r)]["bytes_per_rank"] = traffic;
    }
  }
  const double loop = std::max(m_rt.wall_seconds() - m_t_start, kMinLoopSeconds);
  j["wall_time"]["coupler"] = m_rt.wall_seconds();
  const double computed = std::max<long>(steps - first, 1);
  j["coupler"]["steps_per_second"] = computed / loop;
  j["coupler"]["us_per_step"] = 1e6 * loop / computed;
  j["coupler"]["phases"] = nlohmann::json::parse(m_phases.to_json().dump());
  if (m_accel) {
    j["coupler"]["iterations"] = {
        {"max", m_iter.max},
        {"tolerance", m_iter.tolerance},
        {"relaxation", m_iter.relaxation},
        {"reuse", m_iter.reuse},
        {"total", m_iter_total},
        {"mean_per_step", steps > 0 ? double(m_iter_total) / double(steps) : 0.0},
        {"max_per_step", m_iter_max},
        {"not_converged_steps", m_not_converged},
        {"largest_final_residual", m_residual_max}};
  }
  fsi::write_summary(m_rt, j);
  m_progress->finish(steps, fsi::step_time(s, steps),
                     fmt::format("output in {}", m_rt.out_dir().string()));
}

}  // namespace coupler
