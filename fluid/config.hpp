// Settings of the fluid solver, read from the scene's [fluid] table (read_config) or filled in
// directly by tests and drivers. fluid/README.md documents every key with an example scene.
#pragma once

#include <cmath>
#include <numbers>

#include <array>
#include <string>
#include <vector>

#include "grid.hpp"

namespace fsi {
class SceneTable;
}

namespace fluid {

enum Side : int { left = 0, right = 1, bottom = 2, top = 3 };
inline constexpr const char* kSideNames[4] = {"left", "right", "bottom", "top"};
// The most fluid steps per coupled step ([fluid.substeps] max).
inline constexpr long kMaxSubsteps = 64;

enum class BcType { periodic, wall, slip, inflow, outflow, pressure };
enum class Profile { uniform, parabolic };
enum class Ramp { none, cosine, linear };
enum class Phase { bulk, orlanski };

struct SideBc {
  BcType type = BcType::wall;
  double velocity = 0;  // wall: tangential speed along +x (bottom/top) or +y (left/right) ...
  double amplitude = 0;  // ... plus amplitude sin(omega t + phase_angle): an oscillating wall
  double omega = 0;      //     (pressure: the same oscillation added to the pressure)
  double phase_angle = 0;
  double wall_speed(double t) const { return velocity + amplitude * std::sin(omega * t + phase_angle); }
  Profile profile = Profile::parabolic;  // inflow: profile shape ...
  double mean = 0;                       // ... mean speed into the domain ...
  Ramp ramp = Ramp::none;                // ... and its start-up in time (inflow, pressure):
  double ramp_time = 0;  // cosine: (1 - cos(pi t / T)) / 2 for t < T (Turek-Hron Eq. 26)
  double ramp_factor(double t) const {
    if (ramp == Ramp::cosine && t < ramp_time) return 0.5 * (1 - std::cos(std::numbers::pi * t / ramp_time));
    if (ramp == Ramp::linear && t < ramp_time) return t / ramp_time;
    return 1.0;
  }
  // pressure: p_b(t) = ramp(t) value + amplitude sin(omega t + phase_angle) on the boundary face;
  // with `total`, where the flow enters through the face p_b is its total pressure p + rho u^2 / 2
  // (fluid drawn from a reservoir at rest; at an outlet, what a backflow sees)
  double value = 0;
  bool total = false;
  double boundary_pressure(double t) const {
    return ramp_factor(t) * value + amplitude * std::sin(omega * t + phase_angle);
  }
  Phase phase = Phase::bulk;  // outflow: convection speed, the bulk outlet velocity or Orlanski's
};

enum class InitialType { rest, uniform, taylor_green, vortex };
struct Initial {
  InitialType type = InitialType::rest;
  std::array<double, 2> velocity{0, 0};  // uniform part (uniform, vortex)
  double amplitude = 1;                  // taylor_green: U0; vortex: peak swirl speed
  std::array<double, 2> centre{0, 0};    // vortex centre
  double radius = 0.1;                   // vortex core radius (Gaussian, Lamb-Oseen like)
};

struct Probe {
  std::string name;
  std::array<double, 2> at{0, 0};
};

struct Config {
  double density = 1;    // rho_f > 0
  double viscosity = 0;  // dynamic, mu_f > 0
  AxisSpec x, y;
  std::array<SideBc, 4> bc;  // left, right, bottom, top
  bool implicit = false;     // Crank-Nicolson diffusion (else explicit AB2)
  // Crank-Nicolson's immersed forcing: on the explicit prediction before the solve ("increment",
  // the default; predictor.cpp, forcing.cpp: the explicit scheme's wall at any lambda), or all of
  // it after the solve ("after_solve", the default before: the wall leaks into the body at large
  // lambda; fluid/README.md).
  bool forcing_in_increment = true;  // fluid.implicit_forcing, default "increment"
  // Crank-Nicolson's Helmholtz solves: approximately factored along the grid lines ("factored",
  // the default; factored_solver.hpp: second order, no transform) or exact by transforms
  // ("direct").
  bool factored_helmholtz = true;  // fluid.helmholtz
  // fluid.body_viscosity = "none" (the default): the fluid's viscous stress weighted by 1 − φ
  // (φ the elastic bodies' volume fraction), so that bodies are purely elastic; rigid bodies
  // keep it, which changes nothing inside them (body_viscosity.cpp);
  // "kelvin-voigt": the fluid's viscosity everywhere, bodies are Kelvin-Voigt with μ_s = μ_f.
  bool bodies_inviscid = true;
  // fluid.body_divergence = "zero" (the default, the paper's): the fluid divergence-free
  // everywhere, inside bodies too; "solid": the projection holds the fluid inside an elastic
  // body at the body's own divergence (its volume change), so that a compressible body is not
  // held incompressible by the fluid it carries (projection.cpp, dilating_cells; for bodies much
  // heavier than the fluid: fluid/README.md); "coupled_step": "zero" in a step of one substep,
  // and in a step of m substeps the share 1 − 1/m² of the body's divergence, so that the body's
  // volume change meets the pressure of one coupled step whatever m (projection.cpp).
  enum class BodyDivergence { zero, solid, coupled_step };
  BodyDivergence body_divergence = BodyDivergence::zero;
  // fluid.forcing_time tau >= 0: the immersed forcing's relaxation time (forcing.cpp). A face of
  // volume fraction alpha is blended by beta = alpha dt / ((1 - alpha) tau + alpha dt), so a
  // steady flow's slip in a cut face is (1 - alpha)/alpha tau R whatever dt; < 0 (not given):
  // tau = dt, beta = alpha (paper Eq. 21 as written).
  double forcing_time = -1;
  // fluid.interface = "volume" (the default, paper Eq. 21): a cut face blended by its volume
  // fraction; "sharp": a cut face whose centre lies outside the body takes the value on the line
  // from the wall (placed from the face's volume fraction) to the next face out, one whose centre
  // lies inside the body is extrapolated as a ghost (forcing.cpp, sharp_targets); the walls of
  // fixed bodies (elastic bodies' faces keep Eq. 21; the coupler refuses moving rigid bodies).
  // Explicit diffusion, one fluid rank, without forcing_time.
  bool sharp_interface = false;
  // Weight of first-order upwind in the convective fluxes outside the sponge (0: central).
  double upwind_blend = 0;
  // fluid.convection = "upwind3": third-order upwind-biased carried values outside the sponge
  // (momentum.hpp, upwind3_terms); "central" (the default): the two-point average.
  bool upwind3 = false;
  int ranks = 0;  // [fluid] ranks: the ranks ./fsi launches the fluid on (0: not given)
  // Body force per unit volume f(t) = body + oscillating sin(2 pi t / period + phase) (Eq. 29
  // with body = 0), plus rho g.
  std::array<double, 2> body{0, 0}, oscillating{0, 0}, gravity{0, 0};
  double period = 0, phase = 0;
  Initial initial;
  std::vector<Probe> probes;
  std::vector<Side> wall_shear;  // sides along which tau_w (Eq. 30) is written
  std::vector<double> flow_rate;  // x of the vertical sections whose volume flux is written
  double cfl_max = 1.0;          // health: stop above this CFL number
  // [fluid.substeps]: within a coupled step of dt the fluid takes m equal steps dt / m, the
  // fewest (at most substeps_max) whose CFL number, from the step's start velocity, is at most
  // substeps_cfl (fluid/program.cpp). substeps_max = 1: one step of dt, no sub-cycling.
  int substeps_max = 1;
  double substeps_cfl = 0.8;
  double divergence_max = 1e-6;  // health: stop when max |div u| dt exceeds this (after growth)
  long health_every = 10;        // steps between divergence checks
  std::string source;            // scene file, for error messages
};

// Read [fluid] strictly (unknown keys are errors). dt is the scene's time step: the explicit
// stability limits are checked against it.
Config read_config(const fsi::SceneTable& fluid, double dt);

// Structural checks shared by read_config and the Solver (throws fsi::InputError naming the
// key): grid too small, periodic on one side only, inflow on a periodic side, stretched
// transform direction, dt above the explicit diffusion limit.
void validate(const Config& c, double dt);

// Largest dt of explicit AB2 diffusion: 1 / (4 nu (1/dx_min^2 + 1/dy_min^2)).
double explicit_diffusion_limit(const Config& c);

}  // namespace fluid
