// SolidPort implementation: one Newmark step (or one load step of a static analysis) per driver
// step, output of fields, probes and history, eigenmodes at the start, and the run's report.
#include "program.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "checkpoint.hpp"
#include "coupling.hpp"

namespace solid {

namespace {

constexpr double two_pi = 6.283185307179586;

double fluid_density_of(const fsi::Runtime& rt) {
  const auto root = rt.root();
  return root.has("fluid") ? root.table("fluid").positive("density") : 0.0;
}

std::string body_group(const std::string& name) {
  return "/body_" + name;
}

}  // namespace

SolidProgram::SolidProgram(fsi::Runtime& rt)
    : m_rt(rt),
      m_cfg(read_config(rt.root().table("solid"), fluid_density_of(rt))),
      m_h5(fsi::output_h5(rt, rt.out_dir() / "solid.h5")) {
  try {
    m_solver = std::make_unique<Solver>(m_cfg.model);
  } catch (const fsi::InputError& e) {  // the model's checks know no file: name it
    throw fsi::InputError(fmt::format("{} (in {})", e.what(), rt.scene().file().string()));
  }
  const Solver& s = *m_solver;
  for (int b = 0; b < s.num_bodies(); ++b) {
    const Mesh& m = s.mesh(b);
    const std::string g = body_group(m_cfg.model.bodies[b].name);
    m_h5.create_group(g);
    std::vector<int> tri;
    for (const auto& t : m.triangles) tri.insert(tri.end(), t.begin(), t.end());
    m_h5.write(g + "/triangles", tri, {m.triangles.size(), 3});
    m_h5.write(g + "/x_ref", m.x, {std::size_t(m.num_nodes()), 2});
    std::vector<int> region(m.triangle_region.begin(), m.triangle_region.end());
    m_h5.write(g + "/region", region);
    m_h5.set_attribute(g, "kind", s.kind(b) == BodyKind::rigid ? "rigid" : "elastic");
    m_h5.set_attribute(g, "min_quality", m_cfg.quality[b].min_quality);
    m_xdmf.emplace_back(
        rt.out_dir() / fmt::format("solid_{}.xdmf", m_cfg.model.bodies[b].name),
        rt.out_dir() / "solid.h5",
        fsi::XdmfTriangles{g + "/triangles", m.triangles.size(), std::size_t(m.num_nodes())},
        m_cfg.model.bodies[b].name);
    if (rt.restart_step()) m_xdmf.back().resume(fsi::restart_fields_time(rt));
    if (m_cfg.quality[b].min_quality < 0.1)
      fmt::print(
          stderr,
          "[solid] warning: body '{}' has a poor element {} (quality {:.3g}, 1 = equilateral)\n",
          m_cfg.model.bodies[b].name, m_cfg.quality[b].worst_triangle,
          m_cfg.quality[b].min_quality);
  }
  if (m_cfg.modes > 0) write_modes();
  if (m_cfg.initial_mode > 0) {
    const auto& shape = m_modes.shapes.at(m_cfg.initial_mode - 1);
    double peak = 0;
    for (const auto& body : shape)
      for (double c : body) peak = std::max(peak, std::abs(c));
    for (int b = 0; b < s.num_bodies(); ++b) {
      std::vector<double> v = shape[b];
      for (double& c : v) c *= m_cfg.initial_mode_speed / peak;
      if (s.kind(b) == BodyKind::elastic) m_solver->set_velocity(b, v);
    }
  }
  if (!m_cfg.probes.empty()) {
    std::vector<std::string> names;
    for (const auto& p : m_cfg.probes) {
      names.push_back(p.name);
      m_probe_points.push_back(locate(s.mesh(p.body), p.point[0], p.point[1], kProbeLocateTolerance));
    }
    m_probes.emplace(fsi::output_csv(rt, rt.out_dir() / "solid_probes.csv",
                                     fsi::probe_columns(names, {"x", "y", "ux", "uy", "vx", "vy"})));
  }
  std::vector<std::string> cols{"kinetic",        "strain",  "load_potential",
                                "total_energy",   "min_gap", "newton_iterations",
                                "active_contacts"};
  for (const auto& b : m_cfg.model.bodies) {
    cols.push_back(b.name + ".contact_fx");
    cols.push_back(b.name + ".contact_fy");
  }
  cols.push_back("coupling_work");
  cols.push_back("contact_work");
  for (const auto& b : m_cfg.model.bodies) {
    cols.push_back(b.name + ".contact_bodies_fx");
    cols.push_back(b.name + ".contact_bodies_fy");
  }
  m_history.emplace(fsi::output_csv(rt, rt.out_dir() / "solid_history.csv", cols));
  m_external.resize(s.num_bodies());
}

void SolidProgram::write_modes() {
  m_modes = m_solver->modes(m_cfg.modes);
  m_h5.create_group("/modes");
  std::vector<double> f;
  for (double w : m_modes.omega) f.push_back(w / two_pi);
  m_h5.write("/modes/omega", m_modes.omega);
  m_h5.write("/modes/frequency", f);
  for (std::size_t k = 0; k < m_modes.shapes.size(); ++k)
    for (int b = 0; b < m_solver->num_bodies(); ++b) {
      const auto& sh = m_modes.shapes[k][b];
      std::vector<double> v3;
      for (std::size_t n = 0; n < sh.size() / 2; ++n)
        v3.insert(v3.end(), {sh[2 * n], sh[2 * n + 1], 0.0});
      m_h5.write(fmt::format("{}/mode_{}", body_group(m_cfg.model.bodies[b].name), k + 1), v3,
                 {sh.size() / 2, 3});
    }
  // One side file per body that shows the modes as a series whose "time" is the frequency.
  for (int b = 0; b < m_solver->num_bodies(); ++b) {
    if (m_solver->kind(b) != BodyKind::elastic) continue;
    const std::string& name = m_cfg.model.bodies[b].name;
    const std::string g = body_group(name);
    const Mesh& m = m_solver->mesh(b);
    fsi::XdmfWriter x(m_rt.out_dir() / fmt::format("solid_{}_modes.xdmf", name),
                      m_rt.out_dir() / "solid.h5",
                      fsi::XdmfTriangles{g + "/triangles", m.triangles.size(),
                                         std::size_t(m.num_nodes()), g + "/x_ref"},
                      name + " modes");
    for (std::size_t k = 0; k < f.size(); ++k)
      x.add_step(f[k],
                 {{"mode_shape", fsi::XdmfCenter::node, fmt::format("{}/mode_{}", g, k + 1), 3}});
  }
  for (std::size_t k = 0; k < f.size(); ++k)
    fmt::print("[solid] mode {}: omega = {:.8g}, f = {:.8g}\n", k + 1, m_modes.omega[k], f[k]);
}

fsi::proto::BodyMeshes SolidProgram::meshes() const {
  fsi::proto::BodyMeshes out;
  CouplingHook hook(*m_solver);
  for (int b = 0; b < hook.num_bodies(); ++b) {
    const BodyGeometry g = hook.geometry(b);
    fsi::proto::BodyMesh m;
    m.name = g.name;
    m.kind = g.kind == BodyKind::elastic ? fsi::proto::BodyKind::elastic
             : g.moving                    ? fsi::proto::BodyKind::rigid_moving
                                           : fsi::proto::BodyKind::rigid_fixed;
    m.rigid = g.kind == BodyKind::elastic ? 0 : 1;
    m.x_ref = g.x_ref;
    for (const auto& t : g.triangles) m.tri.insert(m.tri.end(), t.begin(), t.end());
    for (const auto& e : g.surface) m.edges.insert(m.edges.end(), e.begin(), e.end());
    out.bodies.push_back(std::move(m));
  }
  return out;
}

void SolidProgram::state(fsi::proto::SolidState& st) const {
  st.time = m_solver->time();
  st.x.resize(m_solver->num_bodies());
  st.v.resize(m_solver->num_bodies());
  for (int b = 0; b < m_solver->num_bodies(); ++b) {
    st.x[b] = m_solver->positions(b);
    st.v[b] = m_solver->velocities(b);
  }
}

// While the fluid steps, the solid factorises the first Newton matrix of its coming step (it
// needs no forces); the step then reuses that factor. Not with coupled iterations, whose matrix
// has the fluid's linearised reaction in it.
void SolidProgram::begin(const fsi::proto::StepBegin& s) {
  if (s.may_repeat == 0 && m_cfg.model.settings.analysis == Analysis::dynamic)
    m_solver->factorize_ahead(s.dt);
}

void SolidProgram::advance(const fsi::proto::StepBegin& sb, const fsi::proto::SolidInput& in) {
  for (int b = 0; b < m_solver->num_bodies(); ++b) {
    m_external[b].clear();
    if (b < static_cast<int>(in.force.size()) && m_solver->kind(b) == BodyKind::elastic)
      m_external[b] = in.force[b];
  }
  // Coupled iterations: iteration 0 keeps the state the step starts from when the step may be
  // repeated (sb.may_repeat), a repeat goes back to it.
  if (sb.iteration == 0) {
    m_start_step = -1;
    m_work_start[0] = m_coupling_work, m_work_start[1] = m_contact_work;
    m_x_n.resize(m_solver->num_bodies());
    m_contact_n.resize(m_solver->num_bodies());
    for (int b = 0; b < m_solver->num_bodies(); ++b) {
      m_x_n[b] = m_solver->positions(b);
      m_contact_n[b] = m_solver->contact_forces(b);
    }
    m_external_n = m_external_used;
    if (sb.may_repeat != 0) {
      m_solver->save_state(m_start);
      m_start_step = sb.step;
    }
  } else {
    if (m_start_step != sb.step)
      fsi::fail("protocol error: the coupler asked the solid to repeat step {}, whose start it "
                "was not told to keep (may_repeat = 0)", sb.step);
    m_solver->restore_state(m_start);
  }
  if (!m_cfg.model.settings.trapezoidal() && Solver::any_root_mass(&in.root_mass))
    throw fsi::InputError(fmt::format(
        "solid.newmark_gamma = {}, newmark_beta = {}: a fiber is rooted on an elastic body, "
        "whose root inertia is written for the trapezoidal rule; remove both keys (in {})",
        m_cfg.model.settings.newmark_gamma, m_cfg.model.settings.newmark_beta,
        m_rt.scene().file().string()));
  try {
    if (m_cfg.model.settings.analysis == Analysis::statics) {
      // A static analysis walks the load factor t / t_end over the scene's steps.
      const auto& s = m_rt.settings();
      m_last = m_solver->solve_static_step(std::min(1.0, (sb.time + sb.dt) / s.t_end));
    } else {
      m_solver->allow_kept_factor(sb.may_repeat == 0);
      m_last = m_solver->advance(sb.dt, &m_external, in.velocity.empty() ? nullptr : &in.velocity,
                                 in.root_mass.empty() ? nullptr : &in.root_mass);
    }
  } catch (const fsi::Error&) {
    // For a look at what went wrong: the state the failed step started from (t^n, the last
    // converged one), kept by the step's cutbacks or by coupled iterations, then the failed
    // attempt's last iterate (of the step or of a part of it), no solution, as the step's end.
    // Best effort: an error while writing these leaves the step's own error to report.
    const StepState* start = m_solver->failed_step_start();
    if (!start && m_start_step == sb.step) start = &m_start;
    if (start) {
      StepState failed;
      m_solver->save_state(failed);
      try {
        m_solver->restore_state(*start);
        write_fields(sb.step, sb.time);
        std::fprintf(stderr, "[solid] the state the failed step started from (t = %.9g) and its "
                     "last iterate (no solution) are the last two outputs\n", sb.time);
      } catch (const std::exception&) {
      }
      m_solver->restore_state(failed);
    }
    write_fields(sb.step + 1, sb.time + sb.dt);
    throw;
  }
  add_step_work();
  if (sb.iteration == 0)
    m_steps++;
  else
    m_repeats++;
  if (m_last.substeps > 1) m_cut_steps++;
  m_newton_total += m_last.iterations;
  m_newton_max = std::max<long>(m_newton_max, m_last.iterations);
  m_assembly += m_last.assembly_seconds;
  m_factor += m_last.factor_seconds;
  m_solve += m_last.solve_seconds;
}

// The work done on the elastic bodies over the step just taken (or taken again), from the
// step's start. The coupling force F_c and the contact force (2 beta lambda) act over the step as
// impulses (assembly.cpp, newmark.cpp): with the trapezoidal rule (gamma = 1/2, beta = 1/4)
//   M (v^(n+1) - v^n) = dt (1/2 (f^n + f^(n+1)) + F_c + F_k),   x^(n+1) - x^n = dt/2 (v^n + v^(n+1)),
// f = F - Q the scene's loads less the internal force, so the kinetic energy changes by
// (x^(n+1) - x^n) . (1/2 (f^n + f^(n+1)) + F_c + F_k), and for a linear elastic body the strain
// energy and the load potential by exactly the f part:
//   W += (F_c^(n+1) + F_k^(n+1)) . (x^(n+1) - x^n)
// on a dof with mass. A massless dof (rho_s = rho_f) is quasi-static, Q = F + F_c + F_k at each
// end of the step, and its strain energy changes by the trapezoid 1/2 (F^n + F^(n+1)) . dx of
// those forces (F^n of the last step taken, zero before the first). So kinetic + strain + load
// potential − the two works is what the time stepping gained (positive) or lost (negative)
// since t = 0: Newmark's damping (gamma > 1/2), a nonlinear material's share, the contact
// force's change between a cut step's parts, or energy that nothing supplied.
void SolidProgram::add_step_work() {
  double w[2] = {0, 0};
  for (int b = 0; b < m_solver->num_bodies(); ++b) {
    if (m_solver->kind(b) != BodyKind::elastic || b >= static_cast<int>(m_x_n.size())) continue;
    const std::vector<double>& x = m_solver->positions(b);
    const std::vector<double>& contact = m_solver->contact_forces(b);
    const auto at = [](const std::vector<std::vector<double>>& f, int b, std::size_t d) {
      return b < static_cast<int>(f.size()) && d < f[b].size() ? f[b][d] : 0.0;
    };
    for (std::size_t d = 0; d < x.size(); ++d) {
      const double dx = x[d] - m_x_n[b][d];
      const double fc = at(m_external, b, d), fk = d < contact.size() ? contact[d] : 0.0;
      if (m_solver->massless(b, d)) {
        w[0] += 0.5 * (at(m_external_n, b, d) + fc) * dx;
        w[1] += 0.5 * (at(m_contact_n, b, d) + fk) * dx;
      } else {
        w[0] += fc * dx;
        w[1] += fk * dx;
      }
    }
  }
  m_coupling_work = m_work_start[0] + w[0];
  m_contact_work = m_work_start[1] + w[1];
  m_external_used = m_external;
}

void SolidProgram::write_fields(long step, double t) {
  if (step == m_written_step) return;
  m_written_step = step;
  const Solver& s = *m_solver;
  const std::string grp = fsi::h5_step_group(step);
  m_h5.create_group(grp);
  m_h5.set_attribute(grp, "time", t);
  for (int b = 0; b < s.num_bodies(); ++b) {
    const std::string g = grp + body_group(m_cfg.model.bodies[b].name);
    m_h5.create_group(g);
    const std::size_t nn = s.mesh(b).num_nodes(), nt = s.mesh(b).num_triangles();
    m_h5.write(g + "/position", s.positions(b), {nn, 2});
    auto vec3 = [&](const std::vector<double>& v) {
      std::vector<double> out(3 * nn);
      for (std::size_t n = 0; n < nn; ++n) {
        out[3 * n] = v[2 * n];
        out[3 * n + 1] = v[2 * n + 1];
        out[3 * n + 2] = 0;
      }
      return out;
    };
    m_h5.write(g + "/displacement", vec3(s.displacements(b)), {nn, 3});
    m_h5.write(g + "/velocity", vec3(s.velocities(b)), {nn, 3});
    std::vector<fsi::XdmfAttribute> at{
        {"displacement", fsi::XdmfCenter::node, g + "/displacement", 3},
        {"velocity", fsi::XdmfCenter::node, g + "/velocity", 3}};
    if (s.kind(b) == BodyKind::elastic) {
      m_h5.write(g + "/von_mises", s.element_von_mises(b), {nt});
      m_h5.write(g + "/det_f", s.element_det_f(b), {nt});
      m_h5.write(g + "/contact_pressure", s.contact_pressure(b), {nn});
      at.push_back({"von_mises", fsi::XdmfCenter::cell, g + "/von_mises", 1});
      at.push_back({"det_f", fsi::XdmfCenter::cell, g + "/det_f", 1});
      at.push_back({"contact_pressure", fsi::XdmfCenter::node, g + "/contact_pressure", 1});
    }
    m_xdmf[b].add_step(t, at, g + "/position");
  }
  m_h5.flush();
}

void SolidProgram::output(long step, double t, bool fields) {
  const Solver& s = *m_solver;
  if (m_probes) {
    m_row.clear();
    for (std::size_t k = 0; k < m_cfg.probes.size(); ++k) {
      const int b = m_cfg.probes[k].body;
      const auto& tri = s.mesh(b).triangles[m_probe_points[k].triangle];
      double q[6] = {0, 0, 0, 0, 0, 0};
      const auto& x = s.positions(b);
      const auto& v = s.velocities(b);
      const auto u = s.displacements(b);
      for (int a = 0; a < 3; ++a) {
        const double w = m_probe_points[k].weights[a];
        for (int i = 0; i < 2; ++i) {
          q[i] += w * x[2 * tri[a] + i];
          q[2 + i] += w * u[2 * tri[a] + i];
          q[4 + i] += w * v[2 * tri[a] + i];
        }
      }
      m_row.insert(m_row.end(), q, q + 6);
    }
    m_probes->write(t, m_row);
  }
  const double kin = s.kinetic_energy(), str = s.strain_energy(), pot = s.load_potential();
  std::vector<double> h{kin,
                        str,
                        pot,
                        kin + str + pot,
                        std::isfinite(s.min_contact_gap()) ? s.min_contact_gap() : 0.0,
                        double(m_last.iterations),
                        double(m_last.active_contacts)};
  for (int b = 0; b < s.num_bodies(); ++b) {
    const Vec2 f = s.total_contact_force(b);
    h.push_back(f[0]);
    h.push_back(f[1]);
  }
  h.push_back(m_coupling_work);
  h.push_back(m_contact_work);
  for (int b = 0; b < s.num_bodies(); ++b) {
    const Vec2 f = s.contact_force_from_bodies(b);
    h.push_back(f[0]);
    h.push_back(f[1]);
  }
  m_history->write(t, h);
  if (fields) write_fields(step, t);
}

std::string SolidProgram::status() const {
  std::string st = fmt::format("Newton {}", m_last.iterations);
  if (!m_last.residuals.empty()) st += fmt::format("  |R| {:.1e}", m_last.residuals.back());
  if (m_last.active_contacts > 0) st += fmt::format("  contacts {}", m_last.active_contacts);
  return st;
}

nlohmann::json SolidProgram::report() const {
  const Solver& s = *m_solver;
  nlohmann::json j;
  j["analysis"] = m_cfg.model.settings.analysis == Analysis::statics ? "static" : "dynamic";
  j["equations"] = s.num_equations();
  j["steps"] = m_steps;
  if (m_repeats > 0) j["repeated_steps"] = m_repeats;
  j["cut_steps"] = m_cut_steps;  // failed whole, taken in parts (step_cutbacks)
  // Steps (or parts) that failed from the predicted iterate and converged from x^n, since this
  // process started.
  if (m_cfg.model.settings.predictor == Predictor::acceleration)
    j["unpredicted_retries"] = s.unpredicted_retries();
  // Newton solves that came back to an earlier residual and held their contacts' features
  // (solid/README.md, Contact), since this process started.
  if (s.feature_holds() > 0) {
    j["contact_feature_holds"] = s.feature_holds();
    j["contact_feature_holds_refused"] = s.feature_holds_refused();
  }
  j["newton_iterations"] = m_newton_total;
  j["newton_iterations_max"] = m_newton_max;
  j["phases"] = {{"assembly", m_assembly}, {"factorization", m_factor}, {"solve", m_solve}};
  j["factorizations_reused"] = s.factor_reuses();  // done ahead (begin) or unchanged matrix
  j["factorizations"] = s.factorizations();  // done, ahead or in a step
  j["energy"] = {{"kinetic", s.kinetic_energy()},
                 {"strain", s.strain_energy()},
                 {"load_potential", s.load_potential()},
                 {"coupling_work", m_coupling_work},
                 {"contact_work", m_contact_work}};
  nlohmann::json bodies = nlohmann::json::array();
  for (int b = 0; b < s.num_bodies(); ++b) {
    const auto& spec = m_cfg.model.bodies[b];
    nlohmann::json jb;
    jb["name"] = spec.name;
    jb["nodes"] = s.mesh(b).num_nodes();
    jb["triangles"] = s.mesh(b).num_triangles();
    jb["min_quality"] = m_cfg.quality[b].min_quality;
    const Vec2 fc = s.total_contact_force(b);
    jb["contact_force"] = {fc[0], fc[1]};
    nlohmann::json reactions = nlohmann::json::object();
    if (spec.kind == BodyKind::elastic)
      for (const auto& c : spec.constraints)
        if (c.type != Constraint::Type::periodic) {
          const Vec2 r = s.reaction(b, c.boundary);
          reactions[c.boundary] = {r[0], r[1]};
        }
    jb["reactions"] = reactions;
    bodies.push_back(jb);
  }
  j["bodies"] = bodies;
  if (std::isfinite(s.min_contact_gap())) j["min_contact_gap"] = s.min_contact_gap();
  if (!m_modes.omega.empty()) {
    nlohmann::json f = nlohmann::json::array();
    for (double w : m_modes.omega) f.push_back(w / two_pi);
    j["mode_frequencies"] = f;
  }
  if (!m_cfg.probes.empty()) {
    nlohmann::json p = nlohmann::json::object();
    for (std::size_t k = 0; k < m_cfg.probes.size(); ++k) {
      const int b = m_cfg.probes[k].body;
      const auto& tri = s.mesh(b).triangles[m_probe_points[k].triangle];
      const auto u = s.displacements(b);
      double ux = 0, uy = 0;
      for (int a = 0; a < 3; ++a) {
        ux += m_probe_points[k].weights[a] * u[2 * tri[a]];
        uy += m_probe_points[k].weights[a] * u[2 * tri[a] + 1];
      }
      p[m_cfg.probes[k].name] = {{"ux", ux}, {"uy", uy}};
    }
    j["probes"] = p;
  }
  return j;
}

}  // namespace solid
