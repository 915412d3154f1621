// FiberPort implementation: set-up checks (attached roots, the explicit bending limit), the
// step with the coupler's forces and root poses, output and the run report. A health failure of
// the fiber system writes the last state before the error goes on to the runtime.
#include "program.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "checkpoint.hpp"

namespace fiber {

namespace {

Config read_checked(fsi::Runtime& rt) {
  const auto table = rt.root().table("fiber");
  Config c = read_config(table);
  check_attachments(c, table, rt.roles()[fsi::Role::solid]);
  check_time_step(c, rt.settings().dt);
  return c;
}

}  // namespace

FiberProgram::FiberProgram(fsi::Runtime& rt)
    : m_rt(rt), m_h5(fsi::output_h5(rt, rt.out_dir() / "fiber.h5")) {
  m_system.emplace(read_checked(rt));
  const FiberSystem& sys = *m_system;
  const Config& cfg = sys.config();
  if (sys.fiber_count() == 0) std::fprintf(stderr, "[fiber] note: the scene defines no fiber ([[fiber.fiber]])\n");

  // Layout: one polyline per fiber, drawn as 2-node segments.
  std::vector<std::size_t> nodes;
  std::vector<double> ds;
  for (int k = 0; k < sys.fiber_count(); ++k) {
    nodes.push_back(sys.marker_count(k));
    ds.push_back(sys.ds(k));
  }
  const std::vector<int> seg = fsi::polyline_segments(nodes);
  m_h5.create_group("layout");
  m_h5.write("layout/segments", seg, {seg.size() / 2, 2});
  m_h5.write("layout/ds", ds);
  std::vector<int> counts(nodes.begin(), nodes.end());
  m_h5.write("layout/markers", counts);
  std::string names;
  for (const auto& f : cfg.fibers) names += (names.empty() ? "" : ",") + f.name;
  m_h5.set_attribute("layout", "names", names);
  m_xdmf.emplace(rt.out_dir() / "fiber.xdmf", rt.out_dir() / "fiber.h5",
                 fsi::XdmfPolylines{"/layout/segments", seg.size() / 2, sys.total_markers()}, "fibers");
  if (rt.restart_step()) m_xdmf->resume(fsi::restart_fields_time(rt));

  if (!cfg.probes.empty()) {
    std::vector<std::string> pn;
    for (const auto& p : cfg.probes) pn.push_back(p.name);
    m_probes.emplace(fsi::output_csv(rt, rt.out_dir() / "fiber_probes.csv",
                                     fsi::probe_columns(pn, {"x", "y", "tension", "curvature"})));
  }
  // Loads on supports: one column group per supported end.
  std::vector<std::string> ln;
  for (int k = 0; k < sys.fiber_count(); ++k) {
    const FiberSpec& f = cfg.fibers[k];
    if (f.root.is_supported() || f.is_prescribed()) {
      m_load_ends.push_back(2 * k);
      ln.push_back(f.name);
    }
    if (f.tip.is_supported()) {
      m_load_ends.push_back(2 * k + 1);
      ln.push_back(f.name + "_tip");
    }
  }
  if (!ln.empty())
    m_loads.emplace(fsi::output_csv(rt, rt.out_dir() / "fiber_loads.csv",
                                    fsi::probe_columns(ln, {"fx", "fy", "moment"})));
  m_ext.assign(2 * sys.total_markers(), 0.0);
  m_poses.resize(sys.fiber_count());
}

fsi::proto::FiberLayout FiberProgram::layout() const {
  const FiberSystem& sys = *m_system;
  fsi::proto::FiberLayout l;
  for (int k = 0; k < sys.fiber_count(); ++k) {
    const FiberSpec& f = sys.config().fibers[k];
    fsi::proto::FiberLayout1 one;
    one.name = f.name;
    one.markers = sys.marker_count(k);
    one.ds = sys.ds(k);
    one.root = f.root.kind == EndKind::attached ? 1 : 0;
    one.body = f.root.body;
    one.edge = -1;  // the fiber knows the surface point, not the body's edges: the coupler resolves it
    one.edge_s = 0;
    one.root_x = f.root.point.x();
    one.root_y = f.root.point.y();
    one.line_density = f.is_prescribed() ? 0.0 : f.density;
    one.root_x = f.root.point.x();
    one.root_y = f.root.point.y();
    one.line_density = f.is_prescribed() ? 0.0 : f.density;
    l.fibers.push_back(one);
  }
  return l;
}

void FiberProgram::set_initial_roots(const std::vector<std::vector<double>>& root_pose) {
  if (m_rt.restart_step()) return;  // the roots are where the checkpoint has them
  FiberSystem& sys = *m_system;
  for (int k = 0; k < sys.fiber_count() && k < static_cast<int>(root_pose.size()); ++k) {
    if (sys.root_kind(k) != EndKind::attached) continue;
    const auto& p = root_pose[k];
    if (p.size() != 4) fsi::fail("fiber '{}': initial root pose has {} values, expected 4", sys.config().fibers[k].name, p.size());
    sys.place_root(k, {Vec2(p[0], p[1]), Vec2(p[2], p[3])});
  }
}

void FiberProgram::state(fsi::proto::FiberState& s) const {
  const FiberSystem& sys = *m_system;
  s.time = sys.time();
  s.x.resize(sys.fiber_count());
  s.x_old.resize(sys.fiber_count());
  s.root_load.resize(3 * sys.fiber_count());
  s.root_mass.resize(3 * sys.fiber_count());
  s.root_accel.resize(2 * sys.fiber_count());
  for (int k = 0; k < sys.fiber_count(); ++k) {
    const auto x = sys.positions(k), xo = sys.previous_positions(k);
    s.x[k].assign(x.begin(), x.end());
    s.x_old[k].assign(xo.begin(), xo.end());
    const EndLoad l = sys.root_load(k);
    s.root_load[3 * k] = l.force.x();
    s.root_load[3 * k + 1] = l.force.y();
    s.root_load[3 * k + 2] = l.moment;
    s.root_mass[3 * k] = l.mass(0, 0);
    s.root_mass[3 * k + 1] = l.mass(0, 1);
    s.root_mass[3 * k + 2] = l.mass(1, 1);
    s.root_accel[2 * k] = l.accel.x();
    s.root_accel[2 * k + 1] = l.accel.y();
  }
}

void FiberProgram::advance(const fsi::proto::StepBegin& s, const fsi::proto::FiberInput& in) {
  FiberSystem& sys = *m_system;
  const bool has_force = !in.force.empty();
  if (has_force) {
    if (static_cast<int>(in.force.size()) != sys.fiber_count())
      fsi::fail("fiber_input has forces for {} fibers, expected {}", in.force.size(), sys.fiber_count());
    for (int k = 0; k < sys.fiber_count(); ++k) {
      const auto& f = in.force[k];
      const std::size_t o = 2 * sys.marker_offset(k);
      if (f.empty()) {
        std::fill(m_ext.begin() + o, m_ext.begin() + o + 2 * sys.marker_count(k), 0.0);
        continue;
      }
      if (f.size() != 2 * static_cast<std::size_t>(sys.marker_count(k)))
        fsi::fail("fiber '{}': fiber_input force has {} values, expected {}", sys.config().fibers[k].name, f.size(),
                  2 * sys.marker_count(k));
      std::copy(f.begin(), f.end(), m_ext.begin() + o);
    }
  }
  bool has_pose = false;
  for (int k = 0; k < sys.fiber_count() && k < static_cast<int>(in.root_pose.size()); ++k) {
    const auto& p = in.root_pose[k];
    if (p.size() != 4) continue;
    m_poses[k] = {Vec2(p[0], p[1]), Vec2(p[2], p[3])};
    has_pose = true;
  }
  try {
    sys.advance(s.dt, has_force ? std::span<const double>(m_ext) : std::span<const double>(),
                has_pose ? std::span<const EndPose>(m_poses) : std::span<const EndPose>());
  } catch (const fsi::Error& e) {
    write_fields(s.step + 1, s.time + s.dt);
    throw fsi::Error(fmt::format("{} (last state written to {})", e.what(), (m_rt.out_dir() / "fiber.h5").string()));
  }
  m_max_stretch = std::max(m_max_stretch, sys.max_stretch());
}

// Value of marker quantity q at arclength s, linear between markers.
static double along(const std::vector<double>& q, double s, double ds) {
  const int n = static_cast<int>(q.size()) - 1;
  const int i = std::clamp(static_cast<int>(s / ds), 0, n - 1);
  const double w = s / ds - i;
  return (1 - w) * q[i] + w * q[i + 1];
}

void FiberProgram::output(long step, double t, bool fields) {
  const FiberSystem& sys = *m_system;
  const Config& cfg = sys.config();
  const bool is_last = step == m_rt.settings().steps;
  const bool is_probe_step = t >= m_next_probe_time * (1 - 1e-12) || is_last;
  if (is_probe_step) m_next_probe_time = t + cfg.probe_interval;
  if (m_probes && is_probe_step) {
    m_row.clear();
    for (const auto& p : cfg.probes) {
      const auto x = sys.positions(p.fiber);
      m_work.resize(sys.marker_count(p.fiber));
      const double ds = sys.ds(p.fiber);
      for (int c = 0; c < 2; ++c) {
        for (int i = 0; i < sys.marker_count(p.fiber); ++i) m_work[i] = x[2 * i + c];
        m_row.push_back(along(m_work, p.s, ds));
      }
      sys.marker_tension(p.fiber, m_tension);
      m_row.push_back(along(m_tension, p.s, ds));
      sys.marker_curvature(p.fiber, m_curvature);
      m_row.push_back(along(m_curvature, p.s, ds));
    }
    m_probes->write(t, m_row);
  }
  if (m_loads && is_probe_step) {
    m_row.clear();
    for (int e : m_load_ends) {
      const EndLoad l = e % 2 == 0 ? sys.root_load(e / 2) : sys.tip_load(e / 2);
      m_row.insert(m_row.end(), {l.force.x(), l.force.y(), l.moment});
    }
    m_loads->write(t, m_row);
  }
  if (fields) write_fields(step, t);
}

void FiberProgram::write_fields(long step, double t) {
  if (step == m_written_step) return;
  m_written_step = step;
  const FiberSystem& sys = *m_system;
  const std::string grp = fsi::h5_step_group(step);
  m_h5.create_group(grp);
  m_h5.set_attribute(grp, "time", t);
  const std::size_t n = sys.total_markers();
  m_h5.write(grp + "/X", sys.positions(), {n, 2});
  std::vector<double> tension, curvature, fiber_id;
  for (int k = 0; k < sys.fiber_count(); ++k) {
    sys.marker_tension(k, m_tension);
    sys.marker_curvature(k, m_curvature);
    tension.insert(tension.end(), m_tension.begin(), m_tension.end());
    curvature.insert(curvature.end(), m_curvature.begin(), m_curvature.end());
    fiber_id.insert(fiber_id.end(), sys.marker_count(k), double(k));
  }
  m_h5.write(grp + "/tension", tension);
  m_h5.write(grp + "/curvature", curvature);
  m_h5.write(grp + "/fiber", fiber_id);
  m_xdmf->add_step(t,
                   {{"tension", fsi::XdmfCenter::node, grp + "/tension", 1},
                    {"curvature", fsi::XdmfCenter::node, grp + "/curvature", 1},
                    {"fiber", fsi::XdmfCenter::node, grp + "/fiber", 1}},
                   grp + "/X");
}

std::string FiberProgram::status() const {
  const FiberSystem& sys = *m_system;
  int it = 0;
  for (int k = 0; k < sys.fiber_count(); ++k) it = std::max(it, sys.tension_iterations(k));
  return fmt::format("stretch {:.1e}  tension iterations {}", sys.max_stretch(), it);
}

nlohmann::json FiberProgram::report() const {
  const FiberSystem& sys = *m_system;
  const PhaseTimes& tm = sys.phase_times();
  const double steps = std::max<long>(tm.steps, 1);
  nlohmann::json j;
  j["fibers"] = sys.fiber_count();
  j["markers"] = sys.total_markers();
  j["substeps"] = sys.config().substeps;
  j["steps"] = tm.steps;
  j["phases"] = {{"forces", tm.forces}, {"tension", tm.tension}, {"update", tm.update}};
  j["us_per_step"] = 1e6 * (tm.forces + tm.tension + tm.update) / steps;
  j["ns_per_marker_step"] = 1e9 * (tm.forces + tm.tension + tm.update) / (steps * sys.total_markers());
  j["max_stretch"] = m_max_stretch;
  nlohmann::json loads = nlohmann::json::object();
  for (int k = 0; k < sys.fiber_count(); ++k) {
    const EndLoad l = sys.root_load(k);
    loads[sys.config().fibers[k].name] = {l.force.x(), l.force.y(), l.moment};
  }
  j["root_loads"] = loads;
  return j;
}

}  // namespace fiber
