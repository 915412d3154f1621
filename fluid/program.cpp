// FluidPort implementation: runs the solver step by step, writes fields, probes and wall shear
// stress, and stops a run that goes unhealthy with a message saying what, where and when.
#include "program.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "checkpoint.hpp"
#include "diagnostics.hpp"

namespace fluid {

FluidProgram::FluidProgram(fsi::Runtime& rt)
    : m_rt(rt),
      m_cfg(read_config(rt.root().table("fluid"), rt.settings().dt)),
      m_solver(std::make_unique<Solver>(m_cfg, rt.settings().dt, rt.program_comm())) {
  if (rt.is_root() && m_cfg.ranks > 0 && m_cfg.ranks != rt.program_size())
    std::fprintf(stderr,
                 "[fluid] warning: fluid.ranks = %d in %s, but the job launched the fluid on %d "
                 "rank(s): running on %d (the job's count decides)\n",
                 m_cfg.ranks, rt.scene().file().string().c_str(), rt.program_size(),
                 rt.program_size());
  set_initial(*m_solver);
  const Grid& g = m_solver->grid();
  // Rank 0 writes the files; the diagnostics below are collective over the fluid's ranks.
  const bool root = rt.is_root();
  std::vector<double> xf(g.nx() + 1), yf(g.ny() + 1);
  for (int i = 0; i <= g.nx(); ++i) xf[i] = g.x().face(i);
  for (int j = 0; j <= g.ny(); ++j) yf[j] = g.y().face(j);
  if (root) {
    m_h5.emplace(fsi::output_h5(rt, rt.out_dir() / "fluid.h5"));
    m_h5->create_group("grid");
    m_h5->write("grid/x_face", xf);
    m_h5->write("grid/y_face", yf);
    m_h5->write("grid/nodes", fsi::rectilinear_nodes(xf, yf), {yf.size() * xf.size(), 2});
    m_h5->set_attribute("grid", "density", m_cfg.density);
    m_h5->set_attribute("grid", "viscosity", m_cfg.viscosity);
  }
  for (Side s : m_cfg.wall_shear) {
    std::vector<double> pos;
    wall_shear(*m_solver, s, &pos);
    if (root) m_h5->write(fmt::format("grid/tau_{}_position", kSideNames[s]), pos);
  }
  if (root) {
    m_xdmf.emplace(rt.out_dir() / "fluid.xdmf", rt.out_dir() / "fluid.h5",
                   fsi::XdmfStructured{"/grid/nodes", xf.size(), yf.size()}, "fluid");
    if (rt.restart_step()) m_xdmf->resume(fsi::restart_fields_time(rt));
  }
  if (!m_cfg.probes.empty()) {
    std::vector<std::string> names;
    for (const Probe& p : m_cfg.probes) names.push_back(p.name);
    if (root)
      m_probes.emplace(fsi::output_csv(rt, rt.out_dir() / "fluid_probes.csv",
                                       fsi::probe_columns(names, {"ux", "uy", "p"})));
    m_row.resize(3 * names.size());
  }
  if (!m_cfg.flow_rate.empty()) {
    std::vector<std::string> cols;
    for (std::size_t k = 0; k < m_cfg.flow_rate.size(); ++k) {
      m_flow_columns.push_back(nearest_u_column(*m_solver, m_cfg.flow_rate[k]));
      cols.push_back(fmt::format("Q{}", k));
    }
    if (root) m_flow.emplace(fsi::output_csv(rt, rt.out_dir() / "fluid_flow_rate.csv", cols));
    m_flow_row.resize(cols.size());
  }
}

fsi::proto::GridInfo FluidProgram::grid_info() const {
  const Grid& g = m_solver->grid();
  fsi::proto::GridInfo gi;
  gi.nx = g.nx();
  gi.ny = g.ny();
  gi.periodic_x = g.x().periodic();
  gi.periodic_y = g.y().periodic();
  for (int i = 0; i <= g.nx(); ++i) gi.x_face.push_back(g.x().face(i));
  for (int j = 0; j <= g.ny(); ++j) gi.y_face.push_back(g.y().face(j));
  gi.density = m_cfg.density;
  return gi;
}

// The step's first part (explicit terms, boundary values, the predictor; with Crank-Nicolson its
// right-hand side, the solve waiting for the forces) needs no coupling input. After a final step
// it starts at once (the next step has the same dt: the coupler's clock is uniform), else on
// step_begin. With sub-cycling it is the first substep's.
void FluidProgram::prepare_next(const fsi::proto::StepBegin& done) {
  m_solver->begin_step(done.dt / substeps(done.dt));
}

void FluidProgram::begin(const fsi::proto::StepBegin& s) {
  if (!m_solver->is_begun()) m_solver->begin_step(s.dt / substeps(s.dt));
}

// Sub-cycling ([fluid.substeps]). C = max |u| dt / h is the CFL number of the coupled step over
// the velocity u^n it starts from; the count follows it as substep_count() says, falling by one
// and with a margin so that a CFL number near cfl x m does not change the fluid's step length
// back and forth. The health check after a step finds the next step's count (m_substeps); the
// first step of a run finds it here. A checkpoint keeps it (it depends on the counts before),
// so a restart repeats the run.
int FluidProgram::substeps(double dt) {
  if (m_cfg.substeps_max == 1) return 1;
  if (m_substeps == 0)
    m_substeps = substep_count(0, cfl(*m_solver, dt).value, m_cfg.substeps_max, m_cfg.substeps_cfl);
  return m_substeps;
}

int substep_count(int now, double c, int max, double cfl) {
  if (max == 1 || !std::isfinite(c)) return 1;
  now = std::max(1, now);
  if (c > cfl * now) return int(std::min<double>(max, std::ceil(c / cfl)));
  if (now > 1 && c <= kSubstepsFall * cfl * (now - 1)) return now - 1;
  return now;
}

void FluidProgram::advance(const fsi::proto::StepBegin& s, const fsi::proto::FluidInput& in,
                           fsi::proto::FluidOutput& out) {
  CouplingIn c;
  c.solid_u_index = in.solid_u.index;
  c.solid_u_alpha = in.solid_u.alpha;
  c.solid_u_velocity = in.solid_u.velocity;
  c.solid_v_index = in.solid_v.index;
  c.solid_v_alpha = in.solid_v.alpha;
  c.solid_v_velocity = in.solid_v.velocity;
  c.solid_u_elastic = in.solid_u.elastic;
  c.solid_v_elastic = in.solid_v.elastic;
  c.solid_u_body = in.solid_u.body;
  c.solid_v_body = in.solid_v.body;
  c.fiber_u_index = in.force_u.index;
  c.fiber_u_force = in.force_u.force;
  c.fiber_v_index = in.force_v.index;
  c.fiber_v_force = in.force_v.force;
  c.sample_u_index = in.sample_u;
  c.sample_v_index = in.sample_v;
  c.sample_p_index = in.sample_p;
  if (s.iteration == 0) {
    m_solver->set_keep_for_redo(s.may_repeat != 0);
    begin(s);
    m_substeps_done = substeps(s.dt);
    m_solver->end_substeps(s.dt, m_substeps_done, c, m_out);
    if (m_substeps_done > 1) ++m_substepped, m_substeps_taken += m_substeps_done;
  } else {
    m_solver->redo_step(s.dt, c, m_out);
  }
  out.fs_u = m_out.solid_u_force;
  out.fs_v = m_out.solid_v_force;
  out.u_sample = m_out.sample_u;
  out.v_sample = m_out.sample_v;
  out.p_sample = m_out.sample_p;
  check_health(s.step + 1, s.time + s.dt, s.dt);
  out.cfl = m_cfl;
  out.max_div = m_div;
  out.kinetic_energy = m_energy;
}

void FluidProgram::check_health(long step, double t, double dt) {
  // The CFL number of the next step's own (sub)step: that of dt over the substeps it will take.
  const Extremum c = cfl(*m_solver, dt);
  const int m = substep_count(m_substeps, c.value, m_cfg.substeps_max, m_cfg.substeps_cfl);
  if (m_cfg.substeps_max > 1) m_substeps = m;
  m_cfl = c.value / m;
  std::string what;
  if (!std::isfinite(c.value)) {
    what = "the velocity is not finite (NaN or Inf)" + fsi::extreme_constants_hint();
  } else if (m_cfl > m_cfg.cfl_max) {
    what = fmt::format(
        "CFL number {:.4g} above fluid.health.cfl_max = {:g} in cell ({}, {}) at "
        "(x, y) = ({:.6g}, {:.6g}){}; lower time.dt{}{}",
        m_cfl, m_cfg.cfl_max, c.i, c.j, c.x, c.y,
        m > 1 ? fmt::format(" with {} substeps (fluid.substeps.max)", m) : "",
        m > 1 ? " or raise fluid.substeps.max" : "", fsi::extreme_constants_hint());
  } else if (step % m_cfg.health_every == 0) {
    const Extremum d = max_divergence(*m_solver);
    m_div = d.value;
    m_energy = kinetic_energy(*m_solver);
    if (m_div_first < 0) m_div_first = d.value;
    // Round-off grows slowly with the field; a jump by orders of magnitude is a failure.
    // The fluid's own step: dt over the substeps it took.
    const double own = dt / m_substeps_done;
    if (d.value * own > m_cfg.divergence_max) {
      what = fmt::format(
          "divergence |div u| dt = {:.3g} above fluid.health.divergence_max = {:g} "
          "in cell ({}, {}) at (x, y) = ({:.6g}, {:.6g})",
          d.value * own, m_cfg.divergence_max, d.i, d.j, d.x, d.y);
    }
  }
  if (what.empty()) return;
  write_fields(step, t);
  throw fsi::Error(
      fmt::format("fluid unhealthy at step {}, t = {:.6g}: {} (last state written to {})", step, t,
                  what, (m_rt.out_dir() / "fluid.h5").string()));
}

// Collective over the fluid's ranks: each gives its rows, rank 0 writes the whole grid's.
void FluidProgram::write_fields(long step, double t) {
  if (step == m_written_step) return;
  m_written_step = step;
  const Solver& s = *m_solver;
  const Grid& g = s.grid();
  const Decomposition& d = s.decomposition();
  const int nx = g.nx(), ny = g.ny(), lo = d.lo(), rows = d.hi() - d.lo();
  const bool root = m_rt.is_root();
  const std::string grp = fsi::h5_step_group(step);
  if (root) {
    m_h5->create_group(grp);
    m_h5->set_attribute(grp, "time", t);
  }
  const fsi::H5Shape shape{std::size_t(ny), std::size_t(nx)};
  std::vector<double> all(root ? std::size_t(nx + 1) * (ny + 1) : 0);
  // This rank's rows of one field (n per row, `extra` rows more on the last rank) to rank 0,
  // written there as `name`.
  auto write = [&](const std::string& name, const std::vector<double>& mine, int n, int extra,
                   fsi::H5Shape sh) {
    d.gather_rows(mine.data(), n, int(mine.size() / std::max(1, n)), all.data(), extra);
    if (root) m_h5->write(name, std::vector<double>(all.begin(), all.begin() + sh[0] * sh[1]), sh);
  };
  centred_velocity(s, m_w1, m_w2);
  write(grp + "/u", m_w1, nx, 0, shape);
  write(grp + "/v", m_w2, nx, 0, shape);
  m_w1.resize(std::size_t(nx) * rows);
  for (int j = lo; j < d.hi(); ++j)
    for (int i = 0; i < nx; ++i) m_w1[i + std::size_t(nx) * (j - lo)] = s.p()(i, j);
  write(grp + "/p", m_w1, nx, 0, shape);
  vorticity(s, m_w1);
  write(grp + "/vorticity", m_w1, nx, 0, shape);
  // The staggered fields themselves, for exact post-processing.
  const int vrows = d.v_hi() - lo;
  std::vector<double> uf(std::size_t(nx + 1) * rows), vf(std::size_t(nx) * vrows);
  for (int j = lo; j < d.hi(); ++j)
    for (int i = 0; i <= nx; ++i) uf[i + std::size_t(nx + 1) * (j - lo)] = s.u()(i, j);
  for (int j = lo; j < d.v_hi(); ++j)
    for (int i = 0; i < nx; ++i) vf[i + std::size_t(nx) * (j - lo)] = s.v()(i, j);
  write(grp + "/u_face", uf, nx + 1, 0, {std::size_t(ny), std::size_t(nx + 1)});
  write(grp + "/v_face", vf, nx, 1, {std::size_t(ny + 1), std::size_t(nx)});
  for (Side side : m_cfg.wall_shear) {
    const std::vector<double> tau = wall_shear(s, side);
    if (root) m_h5->write(fmt::format("{}/tau_{}", grp, kSideNames[side]), tau);
  }
  if (!root) return;
  std::vector<fsi::XdmfAttribute> at;
  for (const char* q : {"u", "v", "p", "vorticity"}) {
    at.push_back({q, fsi::XdmfCenter::cell, grp + "/" + q, 1});
  }
  m_xdmf->add_step(t, at);
}

void FluidProgram::output(long step, double t, bool fields) {
  if (!m_cfg.probes.empty()) {
    for (std::size_t k = 0; k < m_cfg.probes.size(); ++k) {
      const auto& at = m_cfg.probes[k].at;
      for (int q = 0; q < 3; ++q) m_row[3 * k + q] = sample(*m_solver, q, at[0], at[1]);
    }
    if (m_probes) m_probes->write(t, m_row);
  }
  if (!m_flow_columns.empty()) write_flow_rate(t);
  if (fields) write_fields(step, t);
}

// One row of fluid_flow_rate.csv: Q_k = sum_j u(i_k, j) w_y(j) at each section's face column.
void FluidProgram::write_flow_rate(double t) {
  for (std::size_t k = 0; k < m_flow_columns.size(); ++k)
    m_flow_row[k] = flow_rate(*m_solver, m_flow_columns[k]);
  if (!m_flow) return;  // not rank 0
  m_flow->write(t, m_flow_row);
  m_flow_times.push_back(t);
  m_flow_values.insert(m_flow_values.end(), m_flow_row.begin(), m_flow_row.end());
}

// Per section: where it is measured, and over this run's steps (since the start or the restart)
// the mean, min, max and the fluctuation amplitude (max - min) / 2; with an oscillating forcing
// also the amplitude over the last forcing period (the periodic state's, start-up excluded).
nlohmann::json FluidProgram::flow_rate_report() const {
  nlohmann::json out = nlohmann::json::array();
  const std::size_t n = m_flow_columns.size(), steps = m_flow_times.size();
  const bool oscillating =
      m_cfg.period > 0 && (m_cfg.oscillating[0] != 0 || m_cfg.oscillating[1] != 0);
  for (std::size_t k = 0; k < n; ++k) {
    nlohmann::json j;
    j["x"] = m_cfg.flow_rate[k];
    j["face_column"] = m_flow_columns[k];
    j["face_x"] = m_solver->grid().x().face(m_flow_columns[k]);
    if (steps > 0) {
      double lo = m_flow_values[k], hi = lo, sum = 0, plo = lo, phi = lo;
      bool any_period = false;
      const double t_from = m_flow_times.back() - m_cfg.period;
      for (std::size_t s = 0; s < steps; ++s) {
        const double q = m_flow_values[s * n + k];
        lo = std::min(lo, q), hi = std::max(hi, q), sum += q;
        if (oscillating && m_flow_times[s] >= t_from) {
          if (!any_period) plo = phi = q, any_period = true;
          plo = std::min(plo, q), phi = std::max(phi, q);
        }
      }
      j["mean"] = sum / double(steps);
      j["min"] = lo;
      j["max"] = hi;
      j["amplitude"] = 0.5 * (hi - lo);
      if (oscillating && m_flow_times.back() - m_flow_times.front() >= m_cfg.period)
        j["amplitude_last_period"] = 0.5 * (phi - plo);
    }
    out.push_back(j);
  }
  return out;
}

// The solver's state, and the health check's (the diagnostics the coupler is sent).
void FluidProgram::save(fsi::H5File& h5) const {
  m_solver->save(&h5);
  h5.write("health", std::vector<double>{m_cfl, m_div, m_div_first, m_energy});
  if (m_cfg.substeps_max > 1) h5.write("substeps", std::vector<double>{double(m_substeps)});
}

// The other ranks' part of a checkpoint: the solver's gathers, no file.
void FluidProgram::save_ranks() const { m_solver->save(nullptr); }

void FluidProgram::load(const fsi::H5File& h5) {
  m_solver->load(h5);
  const auto h = h5.read_doubles("health");
  m_cfl = h.at(0), m_div = h.at(1), m_div_first = h.at(2), m_energy = h.at(3);
  m_substeps = 0;
  if (m_cfg.substeps_max > 1 && h5.exists("substeps")) {
    const double m = h5.read_doubles("substeps").at(0);
    if (!(m >= 0 && m <= m_cfg.substeps_max && m == std::floor(m)))
      fsi::fail("fluid checkpoint: substep count {} outside 0..fluid.substeps.max = {}", m,
                m_cfg.substeps_max);
    m_substeps = int(m);
  }
}

std::string FluidProgram::status() const {
  return fmt::format("CFL {:.3f}  div {:.1e}", m_cfl, m_div);
}

nlohmann::json FluidProgram::report() const {
  const Timings& tm = m_solver->timings();
  const double cells = double(m_solver->grid().nx()) * m_solver->grid().ny();
  const double steps = std::max<long>(tm.steps, 1);
  const double total = tm.predictor + tm.boundaries + tm.poisson + tm.projection;
  nlohmann::json j;
  j["grid"] = {m_solver->grid().nx(), m_solver->grid().ny()};
  j["steps"] = tm.steps;
  if (tm.repeats > 0) j["repeated_steps"] = tm.repeats;
  // Sub-cycling: the coupled steps sub-cycled, their substeps, and all the fluid's own steps.
  if (m_cfg.substeps_max > 1)
    j["substeps"] = {{"max", m_cfg.substeps_max}, {"cfl", m_cfg.substeps_cfl},
                     {"coupled_steps_subcycled", m_substepped},
                     {"their_substeps", m_substeps_taken}, {"fluid_steps", tm.steps}};
  j["phases"] = {{"predictor", tm.predictor},
                 {"boundaries", tm.boundaries},
                 {"poisson", tm.poisson},
                 {"projection", tm.projection}};
  j["phases_cpu_seconds"] = tm.cpu;  // the phases' CPU time, without descheduled time
  j["ns_per_cell_step"] = 1e9 * total / (cells * steps);
  // On several ranks: this rank's rows and what its exchanges cost (inside the phases above).
  const Decomposition& d = m_solver->decomposition();
  if (!d.serial()) {
    const auto& tr = d.traffic();
    const auto tt = m_solver->transpose_traffic();
    j["rows"] = {d.lo(), d.hi()};
    j["communication"] = {{"halo_seconds", tr.halo_seconds},
                          {"halos", tr.halos},
                          {"halo_bytes", tr.halo_bytes},
                          {"collective_seconds", tr.collective_seconds},
                          {"collectives", tr.collectives},
                          {"transpose_seconds", tt.seconds},
                          {"transposes", tt.count},
                          {"transpose_bytes", tt.bytes}};
  }
  j["max_divergence"] = max_divergence(*m_solver).value;
  j["kinetic_energy"] = kinetic_energy(*m_solver);
  if (m_flow) j["flow_rate"] = flow_rate_report();
  return j;
}

}  // namespace fluid
