// The coupler's step sequence (DESIGN.md §3; message order in common/PROTOCOL.md).
#include "coupler.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <toml.hpp>

#include "driver.hpp"

namespace coupler {

using fsi::Role;

Coupler::Coupler(fsi::Runtime& rt) : m_rt(rt) {
  if (const auto c = rt.root().optional_table("coupler")) c->finish();
}

void Coupler::run() {
  setup();
  m_t_start = m_rt.wall_seconds();
  for (long n = 0; n < m_rt.settings().steps; ++n) step(n);
  finish();
}

// Set-up, once: grid from the fluid; meshes and initial state from the solid; layout from the
// fiber, then the fibers' root poses at t^0 and their initial state; each solver's effective
// scene.
void Coupler::setup() {
  if (has(Role::fluid)) {
    auto& l = m_rt.link(Role::fluid);
    l.recv(m_grid);
    proto::Text t{proto::Tag::effective_scene, {}};
    l.recv(t);
    m_effective["fluid"] = t.text;
  }
  if (has(Role::solid)) {
    auto& l = m_rt.link(Role::solid);
    l.recv(m_meshes);
    l.recv(m_solid);
    proto::Text t{proto::Tag::effective_scene, {}};
    l.recv(t);
    m_effective["solid"] = t.text;
  }
  if (has(Role::fiber)) {
    auto& l = m_rt.link(Role::fiber);
    l.recv(m_layout);
    m_fiber_in.force.assign(m_layout.fibers.size(), {});
    m_fiber_in.root_pose.assign(m_layout.fibers.size(), {});
    for (std::size_t k = 0; k < m_layout.fibers.size(); ++k)
      if (m_layout.fibers[k].root == 1)
        fsi::fail("fiber '{}' is attached to body '{}': fibers rooted on bodies are not coupled yet",
                  m_layout.fibers[k].name, m_layout.fibers[k].body);
    l.send(m_fiber_in);
    l.recv(m_fiber);
    proto::Text t{proto::Tag::effective_scene, {}};
    l.recv(t);
    m_effective["fiber"] = t.text;
  }
  if (!m_meshes.bodies.empty())
    fsi::fail("the scene has {} solid bodies: the immersed-solid coupling is not available yet",
              m_meshes.bodies.size());
  m_solid_in.force.assign(m_meshes.bodies.size(), {});

  // The effective scene: the coupler's own reading, each solver's table from that solver.
  std::istringstream own(m_rt.scene().effective_toml());
  auto doc = toml::parse<toml::discard_comments, std::map, std::vector>(
      own, "effective");
  for (const auto& [role, text] : m_effective) {
    std::istringstream is(text);
    const auto part = toml::parse<toml::discard_comments, std::map, std::vector>(is, role);
    if (part.contains(role)) doc.as_table()[role] = part.at(role);
  }
  std::ofstream(m_rt.out_dir() / "scene.effective.toml") << toml::format(doc);
}

// One step t^n -> t^(n+1), DESIGN.md §3.
void Coupler::step(long n) {
  const auto& s = m_rt.settings();
  const proto::StepBegin sb{n, fsi::step_time(s, n), s.dt, proto::Action::step};
  for (Role r : {Role::fluid, Role::solid, Role::fiber})
    if (has(r)) m_rt.link(r).send(sb, n);
  m_rt.check_fault(n);

  if (has(Role::fluid)) {
    auto& l = m_rt.link(Role::fluid);
    l.send(m_fluid_in, n);
    l.recv(m_fluid_out);
  }
  if (has(Role::solid)) {
    auto& l = m_rt.link(Role::solid);
    l.send(m_solid_in, n);
    l.recv(m_solid);
  }
  if (has(Role::fiber)) {
    auto& l = m_rt.link(Role::fiber);
    l.send(m_fiber_in, n);
    l.recv(m_fiber);
  }

  const double wall = m_rt.wall_seconds() - m_t_start;
  static double last_print = 0;
  if (wall - last_print > 2.0 || n + 1 == s.steps) {
    const double rate = (n + 1) / std::max(wall, 1e-9);
    std::fprintf(stderr, "[coupler] step %ld/%ld  t=%.6g  dt=%.3g  CFL %.3g  %.1f steps/s  ETA %.0f s\n",
                 n + 1, s.steps, fsi::step_time(s, n + 1), s.dt, m_fluid_out.cfl, rate,
                 (s.steps - n - 1) / rate);
    last_print = wall;
  }
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
  const double steps_per_s = s.steps / std::max(m_rt.wall_seconds() - m_t_start, 1e-9);
  j["wall_time"]["coupler"] = m_rt.wall_seconds();
  j["coupler"]["steps_per_second"] = steps_per_s;
  j["coupler"]["us_per_step"] = 1e6 / steps_per_s;
  fsi::write_summary(m_rt, j);
  std::fprintf(stderr, "[coupler] done: %ld steps in %.2f s; output in %s\n", s.steps,
               m_rt.wall_seconds(), m_rt.out_dir().string().c_str());
}

}  // namespace coupler
