// serve(): the solver side of the step sequence (see driver.hpp and common/PROTOCOL.md).
#include "driver.hpp"

#include "checkpoint.hpp"
#include "progress.hpp"
#include "summary.hpp"

#include <chrono>
#include <cmath>
#include <fstream>

namespace fsi {

// A step is an output step when it is the first of a new output interval; times within this
// fraction of an interval below a multiple count as that multiple (round-off of n dt).
constexpr double kIntervalTolerance = 1e-9;

namespace {
// Whether t^n is the first step time of a new multiple of `interval`.
bool crosses(const CommonSettings& s, double interval, long n) {
  const double k_now = std::floor(step_time(s, n) / interval + kIntervalTolerance);
  const double k_before = std::floor(step_time(s, n - 1) / interval + kIntervalTolerance);
  return k_now > k_before;
}
}  // namespace

bool is_output_step(const CommonSettings& s, long n) {
  if (s.output_interval <= 0) return false;
  if (n == 0 || n == s.steps) return true;
  return crosses(s, s.output_interval, n);
}

bool is_checkpoint_step(const CommonSettings& s, long n) {
  if (s.checkpoint_interval <= 0 || n <= 0) return false;
  return n == s.steps || crosses(s, s.checkpoint_interval, n);
}

void SolverPort::save(H5File&) const { fail("this program cannot write checkpoints"); }
void SolverPort::load(const H5File&) { fail("this program cannot restart from a checkpoint"); }

void write_summary(const Runtime& rt, const nlohmann::json& summary) {
  write_file_atomically(rt.out_dir() / "summary.json", summary.dump(2) + "\n");
}

namespace {

// Adds the wall time of f() to `seconds`.
template <class F>
void timed(double& seconds, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json base_summary(const Runtime& rt, long steps) {
  nlohmann::json j;
  j["scene"] = rt.settings().name;
  j["scene_file"] = rt.scene().file().string();
  j["protocol_version"] = proto::kVersion;
  j["steps"] = steps;
  j["time"] = step_time(rt.settings(), steps);
  j["dt"] = rt.settings().dt;
  return j;
}

// Standalone: this solver is the clock; coupling inputs stay empty.
template <class Port, class Advance>
void run_alone(Runtime& rt, Port& port, Advance advance) {
  const auto& s = rt.settings();
  // On several ranks (the fluid's), rank 0 writes the run's files and prints its progress.
  if (rt.is_root())
    write_file_atomically(rt.out_dir() / "scene.effective.toml", rt.scene().effective_toml());
  const long first = rt.first_step();
  if (!rt.restart_step()) port.output(0, 0.0, is_output_step(s, 0));
  Progress::Options po;
  po.every_steps = s.progress_every;
  po.first_step = first;
  po.first_time = step_time(s, first);
  po.is_enabled = rt.is_root();
  Progress progress(fmt::format("[{}]", rt.name()), s.steps, step_time(s, s.steps), po);
  long n = first;
  while (n < s.steps) {
    rt.check_fault(n);
    const proto::StepBegin sb{n, step_time(s, n), s.dt, proto::Action::step};
    advance(sb);
    ++n;
    port.output(n, step_time(s, n), is_output_step(s, n));
    progress.update(n, step_time(s, n), s.dt, [&] { return port.status(); });
    const bool stop = rt.stop_requested();
    if (stop || is_checkpoint_step(s, n))
      write_checkpoint(rt, n, [&](H5File& h5) { port.save(h5); }, [&] { port.save_ranks(); });
    if (stop) break;
  }
  nlohmann::json j = base_summary(rt, n);
  j["wall_time"][rt.name()] = rt.wall_seconds();
  j[rt.name()] = port.report();
  if (rt.program_size() > 1) j[rt.name()]["ranks"] = rt.program_size();
  if (rt.is_root()) write_summary(rt, j);
  progress.finish(n, step_time(s, n), fmt::format("output in {}", rt.out_dir().string()));
}

// Coupled: follow the coupler's step_begin messages until it says stop. A step is committed,
// and its output written, once answered when it cannot be repeated (may_repeat = 0), else when
// the next step begins with iteration 0 or the run stops: an iteration k > 0 repeats the step
// just done (PROTOCOL.md, "Coupled iterations").
template <class Port, class Advance>
void follow(Runtime& rt, Port& port, Advance advance) {
  Link& c = rt.coupler_link();
  c.send(proto::Text{proto::Tag::effective_scene, rt.scene().effective_toml()});
  const auto& s = rt.settings();
  if (!rt.restart_step()) port.output(0, 0.0, is_output_step(s, 0));
  long steps = rt.first_step(), repeats = 0;
  // Wall time inside the port's step (its whole computation between receiving its input and
  // sending its answer): the coupler's time for this solver's phase minus this is the messages'.
  // And the work done ahead of the input (begin, prepare_next), outside that phase.
  double port_seconds = 0, ahead_seconds = 0;
  bool pending = false;  // step `steps` - 1 is done but not yet committed
  bool pending_checkpoint = false;  // ... and its state is to be checkpointed once committed
  double t_done = 0;
  // The committed step `steps` (state at t_done): its output, and its checkpoint when asked.
  auto commit_step = [&](bool checkpoint) {
    port.output(steps, t_done, is_output_step(s, steps));
    if (checkpoint)
      write_checkpoint(rt, steps, [&](H5File& h5) { port.save(h5); }, [&] { port.save_ranks(); });
    pending = false;
  };
  for (;;) {
    proto::StepBegin sb;
    c.recv(sb);
    const bool commit = sb.action == proto::Action::stop || sb.iteration == 0;
    if (pending && commit) commit_step(pending_checkpoint);
    if (sb.action == proto::Action::stop) break;
    const long expected = sb.iteration == 0 ? steps : steps - 1;
    if (sb.step != expected || sb.iteration < 0 || (sb.iteration > 0 && !pending))
      fail("protocol error: the coupler began step {} iteration {} after step {} was done",
           sb.step, sb.iteration, steps - 1);
    if (sb.iteration == 0) {
      rt.check_fault(sb.step);
      if (s.work_ahead) timed(ahead_seconds, [&] { port.begin(sb); });
    } else {
      ++repeats;
    }
    advance(sb, port_seconds);
    steps = sb.step + 1;
    t_done = sb.time + sb.dt;
    pending = true;
    pending_checkpoint = sb.checkpoint != 0;
    if (sb.may_repeat == 0) {
      // A step that cannot be repeated is final once answered: commit it now, then work ahead
      // (not after a checkpoint: the coupler may stop the run there).
      commit_step(pending_checkpoint);
      if (s.work_ahead && steps < s.steps && !sb.checkpoint)
        timed(ahead_seconds, [&] { port.prepare_next(sb); });
    }
  }
  nlohmann::json j = port.report();
  j["wall_time"] = rt.wall_seconds();
  j["port_seconds"] = port_seconds;
  j["ahead_seconds"] = ahead_seconds;
  j["steps"] = steps;
  if (repeats > 0) j["repeated_steps"] = repeats;
  j["bytes_sent"] = c.bytes_sent();
  j["bytes_received"] = c.bytes_received();
  c.send(proto::Text{proto::Tag::final_report, j.dump()});
}

// The per-step exchange of a solver that reports its state (solid, fiber): its input from the
// coupler, the step, its new state back.
template <class Port, class In, class State>
void follow_state(Runtime& rt, Port& port, In& in, State& st, bool can_iterate) {
  Link& c = rt.coupler_link();
  follow(rt, port, [&](const proto::StepBegin& sb, double& seconds) {
    if (sb.iteration > 0 && !can_iterate)
      fail("protocol error: the coupler asked the {} to repeat step {}, which it cannot",
           rt.name(), sb.step);
    c.recv(in);
    timed(seconds, [&] {
      port.advance(sb, in);
      port.state(st);
    });
    c.send(st, sb.step);
  });
}

}  // namespace

void serve(Runtime& rt, FluidPort& port) {
  if (rt.restart_step()) port.load(open_restart(rt));
  proto::FluidInput in;
  proto::FluidOutput out;
  if (!rt.coupled()) return run_alone(rt, port, [&](const proto::StepBegin& sb) {
    port.advance(sb, in, out);
  });
  proto::GridInfo grid = port.grid_info();
  grid.can_iterate = port.can_iterate();
  rt.coupler_link().send(grid);
  follow(rt, port, [&](const proto::StepBegin& sb, double& seconds) {
    if (sb.iteration > 0 && !port.can_iterate())
      fail("protocol error: the coupler asked the fluid to repeat step {}, which it cannot", sb.step);
    rt.coupler_link().recv(in);
    timed(seconds, [&] { port.advance(sb, in, out); });
    rt.coupler_link().send(out, sb.step);
  });
}

void serve(Runtime& rt, SolidPort& port) {
  if (rt.restart_step()) port.load(open_restart(rt));
  proto::SolidInput in;
  proto::SolidState st;
  if (!rt.coupled()) return run_alone(rt, port, [&](const proto::StepBegin& sb) {
    port.advance(sb, in);
  });
  Link& c = rt.coupler_link();
  proto::BodyMeshes meshes = port.meshes();
  meshes.can_iterate = port.can_iterate();
  c.send(meshes);
  port.state(st);
  c.send(st);
  follow_state(rt, port, in, st, port.can_iterate());
}

void serve(Runtime& rt, FiberPort& port) {
  if (rt.restart_step()) port.load(open_restart(rt));
  proto::FiberInput in;
  proto::FiberState st;
  if (!rt.coupled()) return run_alone(rt, port, [&](const proto::StepBegin& sb) {
    port.advance(sb, in);
  });
  Link& c = rt.coupler_link();
  c.send(port.layout());
  c.recv(in);  // root poses at t^0
  port.set_initial_roots(in.root_pose);
  port.state(st);
  c.send(st);
  follow_state(rt, port, in, st, false);
}

}  // namespace fsi
