// The solver side of a run, written once for every solver: a solver implements the port of its
// role and serve() drives it, either following the coupler's clock through the per-step message
// sequence of common/PROTOCOL.md, or alone (a scene with that one physics) on its own clock with
// empty coupling inputs. Replacing a solver means implementing one of these ports.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "h5.hpp"
#include "protocol.hpp"
#include "runtime.hpp"

namespace fsi {

// What every solver offers the driver besides its physics. Not called inside a step's loops.
class SolverPort {
 public:
  virtual ~SolverPort() = default;
  // After step `step` reached time t (also called once with step 0 at t = 0): write probes
  // (cheap, every step) and fields when `fields` is true (the scene's output interval).
  virtual void output(long step, double t, bool fields) = 0;
  // Extra fields for the progress line of a standalone run ("CFL 0.31  div 1e-15").
  virtual std::string status() const { return {}; }
  // This solver's part of summary.json (phases, iterations, metrics).
  virtual nlohmann::json report() const { return nlohmann::json::object(); }
  // Work ahead of the input, done while this solver would otherwise wait for it (the coupler is
  // meanwhile running the other solvers or its own transfers); advance() must give the same
  // result with or without it. prepare_next(): after the answer to step `done` was sent, when
  // that step cannot be repeated (done.may_repeat == 0) and another follows; that step is then
  // committed (output() was called), so the port may change its state. begin(): on receiving
  // step_begin for a new step (iteration 0), after the previous step's output, before its input.
  virtual void prepare_next(const proto::StepBegin& done) { (void)done; }
  virtual void begin(const proto::StepBegin& s) { (void)s; }
  // Checkpoint and restart (common/checkpoint.hpp). save(): after a committed step and its
  // output, everything the next step reads (fields, histories, states of the outputs) into `h5`.
  // load(): in a restarted run, before anything is sent or written, the same back; the port has
  // already reopened its output files to continue them (their rows up to the restart time kept).
  // A run stopped and restarted gives the same results bit for bit. The default refuses.
  // A program on several ranks: rank 0 calls save(), the others save_ranks() at the same
  // point (collective gathers without a file; the default does nothing); load() on every rank.
  virtual void save(H5File& h5) const;
  virtual void save_ranks() const {}
  virtual void load(const H5File& h5);
};

// Coupled iterations (common/PROTOCOL.md, "Coupled iterations"): a fluid or solid port that
// returns true from can_iterate() must accept advance() with s.iteration > 0, meaning "redo the
// step s.step that the previous advance() did, from the state at its start, with this input".
// Output is asked for only once a step is committed. A port that returns false (the default)
// is never asked to repeat a step: the coupler refuses a scene with iterations for it.
class FluidPort : public SolverPort {
 public:
  virtual proto::GridInfo grid_info() const = 0;
  // One fluid step t^n -> t^n + dt with the coupler's sparse input; fills `out` (f_s on the
  // solid faces, samples of u^(n+1), diagnostics). With s.iteration > 0: the same step again
  // from the same predictor (and p^n), with new solid velocities: redo the immersed forcing
  // and the projection (and a solve that took the forcing, fluid/README.md); the fibers' force
  // is the same as in iteration 0. Only a step
  // whose iteration 0 came with s.may_repeat = 1 is ever repeated: a port keeps what a redo
  // needs only then.
  virtual void advance(const proto::StepBegin& s, const proto::FluidInput& in,
                       proto::FluidOutput& out) = 0;
  virtual bool can_iterate() const { return false; }
};

class SolidPort : public SolverPort {
 public:
  virtual proto::BodyMeshes meshes() const = 0;
  virtual void state(proto::SolidState& s) const = 0;  // current x, v of every body
  // One solid step with nodal forces on the solid (empty vectors: no coupling force). With
  // s.iteration > 0: the same step again from the state saved at its start (iteration 0).
  virtual void advance(const proto::StepBegin& s, const proto::SolidInput& in) = 0;
  virtual bool can_iterate() const { return false; }
};

class FiberPort : public SolverPort {
 public:
  virtual proto::FiberLayout layout() const = 0;
  // Root poses of attached fibers at t^0, before the initial state is taken (coupled runs).
  virtual void set_initial_roots(const std::vector<std::vector<double>>& root_pose) = 0;
  virtual void state(proto::FiberState& s) const = 0;  // X^n, X^(n-1), root loads
  virtual void advance(const proto::StepBegin& s, const proto::FiberInput& in) = 0;
};

// Run the solver to the end of the scene (coupled or standalone), write summary.json and the
// effective scene in a standalone run. Collective over the job.
void serve(Runtime& rt, FluidPort& port);
void serve(Runtime& rt, SolidPort& port);
void serve(Runtime& rt, FiberPort& port);

// The time of step n: t^n = n dt (no accumulated round-off).
inline double step_time(const CommonSettings& s, long n) { return static_cast<double>(n) * s.dt; }

// Whether fields are written after step n: at every multiple of the output interval (and at the
// last step); never when the interval is 0.
bool is_output_step(const CommonSettings& s, long n);
// Whether a checkpoint is written after step n: at every multiple of output.checkpoint_interval
// and at the last step; never when the interval is 0.
bool is_checkpoint_step(const CommonSettings& s, long n);

// Write out_dir/summary.json (atomically).
void write_summary(const Runtime& rt, const nlohmann::json& summary);

}  // namespace fsi
