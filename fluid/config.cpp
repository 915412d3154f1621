// Reading and checking the [fluid] table of a scene.
#include "config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.hpp"
#include "scene.hpp"

namespace fluid {
namespace {

const char* type_name(BcType t) {
  switch (t) {
    case BcType::periodic: return "periodic";
    case BcType::wall: return "wall";
    case BcType::slip: return "slip";
    case BcType::inflow: return "inflow";
    case BcType::outflow: return "outflow";
    case BcType::pressure: return "pressure";
  }
  return "?";
}

// The largest width ratio of neighbouring cells outside a band.
constexpr double kMaxBandGrowth = 1.2;

[[noreturn]] void bad(const Config& c, const std::string& msg) {
  throw fsi::InputError(c.source.empty() ? msg : fmt::format("{} (in {})", msg, c.source));
}

double min_width(const AxisSpec& a) {
  if (a.band_cells > 0) {
    const Axis ax(a);
    double w = ax.width(0);
    for (int i = 1; i < a.cells; ++i) w = std::min(w, ax.width(i));
    return w;
  }
  // tanh clustering: the first cell is the smallest.
  if (a.tanh_beta > 0) {
    const double x1 = 0.5 * a.length *
                      (1.0 + std::tanh(a.tanh_beta * (2.0 / a.cells - 1)) / std::tanh(a.tanh_beta));
    return x1;
  }
  return a.length / a.cells;
}

}  // namespace

double explicit_diffusion_limit(const Config& c) {
  const double nu = c.viscosity / c.density;
  const double hx = min_width(c.x), hy = min_width(c.y);
  return 1.0 / (4.0 * nu * (1.0 / (hx * hx) + 1.0 / (hy * hy)));
}

void validate(const Config& c, double dt) {
  if (!(c.density > 0)) bad(c, fmt::format("fluid.density must be > 0, got {}", c.density));
  if (!(c.viscosity > 0)) bad(c, fmt::format("fluid.viscosity must be > 0, got {}", c.viscosity));
  constexpr int kMinCells = 4;
  if (c.x.cells < kMinCells || c.y.cells < kMinCells) {
    bad(c, fmt::format("fluid.grid.cells must be >= {} in each direction for the stencil, got [{}, {}]",
                       kMinCells, c.x.cells, c.y.cells));
  }
  if (!(c.x.length > 0) || !(c.y.length > 0)) {
    bad(c, fmt::format("fluid.grid.size must be > 0 in each direction, got [{}, {}]", c.x.length,
                       c.y.length));
  }
  for (int a = 0; a < 2; ++a) {
    const SideBc& lo = c.bc[2 * a];
    const SideBc& hi = c.bc[2 * a + 1];
    const bool plo = lo.type == BcType::periodic, phi = hi.type == BcType::periodic;
    if (plo != phi) {
      const int per = plo ? 2 * a : 2 * a + 1, other = plo ? 2 * a + 1 : 2 * a;
      if (c.bc[other].type == BcType::inflow) {
        bad(c, fmt::format("fluid.boundary.{}: an inflow cannot face a periodic side "
                           "(fluid.boundary.{} is periodic); make both sides periodic or neither",
                           kSideNames[other], kSideNames[per]));
      }
      bad(c, fmt::format("fluid.boundary.{} is periodic but fluid.boundary.{} is {}: periodic must "
                         "be set on both sides of a direction",
                         kSideNames[per], kSideNames[other], type_name(c.bc[other].type)));
    }
  }
  for (int s = 0; s < 4; ++s) {
    const SideBc& b = c.bc[s];
    if ((b.type == BcType::inflow || b.type == BcType::pressure) && b.ramp != Ramp::none &&
        !(b.ramp_time > 0)) {
      bad(c, fmt::format("fluid.boundary.{}.ramp_time must be > 0 with a ramp, got {}", kSideNames[s],
                         b.ramp_time));
    }
  }
  // A pressure side: its u faces are stepped by the momentum equation and corrected by the
  // projection with the pressure given on the face (boundary.hpp). Only on the x sides, with the
  // explicit predictor, and not beside a convective outflow, whose flux is fixed by convection
  // alone (the flow through the pressure side could then never start).
  for (int s = 0; s < 4; ++s) {
    if (c.bc[s].type != BcType::pressure) continue;
    if (s == bottom || s == top)
      bad(c, fmt::format("fluid.boundary.{} = pressure: a pressure boundary is available on the left "
                         "and right sides only", kSideNames[s]));
    if (c.implicit)
      bad(c, fmt::format("fluid.boundary.{} = pressure needs fluid.diffusion = \"explicit\" (the "
                         "Crank-Nicolson predictor takes the boundary faces as given)", kSideNames[s]));
    for (int o = 0; o < 4; ++o) {
      if (c.bc[o].type == BcType::outflow)
        bad(c, fmt::format("fluid.boundary.{} = pressure with fluid.boundary.{} = outflow: a convective "
                           "outflow fixes the flux through it by convection alone, so no flow "
                           "through the pressure side could start; make the outlet a pressure "
                           "boundary too (type = \"pressure\", value = 0)",
                           kSideNames[s], kSideNames[o]));
    }
  }
  const bool px = c.bc[left].type == BcType::periodic, py = c.bc[bottom].type == BcType::periodic;
  const bool x_sponge = c.x.sponge_cells > 0 && c.x.sponge_ratio != 1.0;
  const bool x_stretched = x_sponge || c.x.band_cells > 0;
  const bool y_stretched = c.y.tanh_beta > 0 || c.y.band_cells > 0;
  // Bands: where they fit, and a growth outside them smooth enough for the stencils (a width
  // ratio of neighbouring cells far from 1 costs the interpolations their second order).
  for (const auto& [a, name] : {std::pair{&c.x, "x_band"}, std::pair{&c.y, "y_band"}}) {
    if (a->band_cells == 0) continue;
    BandLayout l;
    try {
      l = band_layout(*a);
    } catch (const fsi::Error& e) {
      bad(c, fmt::format("fluid.grid.{}: {}", name, e.what()));
    }
    if (l.worst() > kMaxBandGrowth)
      bad(c, fmt::format("fluid.grid.{} = {{ from = {:g}, to = {:g}, cells = {} }}: the {} cells "
                         "outside it would change width by a factor {} from cell to cell (at "
                         "most {:g}); give the direction more cells, the band fewer, or widen it",
                         name, a->band_from, a->band_to, a->band_cells, a->cells - a->band_cells,
                         std::isfinite(l.worst()) ? fmt::format("{:.3g}", l.worst())
                                                  : std::string("of more than 10"),
                         kMaxBandGrowth));
  }
  if (c.x.band_cells > 0 && x_sponge)
    bad(c,
        "fluid.grid.x_band with an outlet sponge: the sponge stretches x already; use a "
        "y_band, or no sponge");
  if (c.y.band_cells > 0 && c.y.tanh_beta > 0)
    bad(c, fmt::format("fluid.grid.y_band with fluid.grid.y_stretch = {}: one or the other",
                       c.y.tanh_beta));
  if (c.x.band_cells > 0 && px)
    bad(c,
        "fluid.grid.x_band stretches x, which is periodic; the fast Poisson solver transforms "
        "periodic directions, which must be uniform");
  if (c.y.band_cells > 0 && py)
    bad(c,
        "fluid.grid.y_band stretches y, which is periodic; the fast Poisson solver transforms "
        "periodic directions, which must be uniform");
  if (c.x.sponge_cells > 0 && c.bc[right].type != BcType::outflow &&
      c.bc[right].type != BcType::pressure) {
    bad(c, fmt::format("fluid.sponge needs an outflow or a pressure boundary on the right side, got "
                       "fluid.boundary.right = {}",
                       type_name(c.bc[right].type)));
  }
  if (c.y.tanh_beta > 0 && py) {
    bad(c, fmt::format("fluid.grid.y_stretch = {} stretches a periodic direction; the fast Poisson "
                       "solver transforms periodic directions, which must be uniform",
                       c.y.tanh_beta));
  }
  if (x_stretched && y_stretched) {
    // What stretches y, and x, for the messages.
    const std::string ys = c.y.band_cells > 0 ? std::string("fluid.grid.y_band")
                                              : fmt::format("fluid.grid.y_stretch = {}", c.y.tanh_beta);
    const char* xs = x_sponge ? "fluid.sponge" : "fluid.grid.x_band";
    if (c.implicit && !c.factored_helmholtz)
      bad(c, fmt::format("fluid.helmholtz = \"direct\" needs one uniform direction; {} and a "
                         "stretched x ({}) stretch both: use helmholtz = \"factored\" (the default)",
                         ys, xs));
  }
  if (x_sponge && px) bad(c, "fluid.sponge: the sponge stretches x, which is periodic");
  if (!(dt > 0)) bad(c, fmt::format("time.dt must be > 0, got {}", dt));
  const double nu = c.viscosity / c.density;
  {
    // The diffusion number d = nu dt / h_min^2. A step adds d times the stencil's Laplacian to
    // u^n; once d eps exceeds sqrt(eps) (d > 1 / sqrt(eps) = 6.7e7) fewer than half of double
    // precision's digits of u^n survive the step, and soon nu dt / h^2 overflows: the flow is
    // no longer stepped, whichever diffusion scheme. Refused as the viscosity's fault.
    const double hmin = std::min(min_width(c.x), min_width(c.y));
    const double d = nu * dt / (hmin * hmin);
    const double d_max = 1.0 / std::sqrt(std::numeric_limits<double>::epsilon());
    if (!std::isfinite(nu) || !(d <= d_max))
      bad(c, fmt::format("fluid.viscosity = {:g} (with fluid.density = {:g}: nu = {:g}) is beyond what "
                         "double precision can step: the diffusion number nu dt / h^2 = {:.3g} "
                         "(time.dt = {:g}, h = {:.3g}) exceeds 1/sqrt(machine epsilon) = {:.3g}",
                         c.viscosity, c.density, nu, d, dt, hmin, d_max));
  }
  if (!c.implicit) {
    const double lim = explicit_diffusion_limit(c);
    if (dt > lim) {
      bad(c, fmt::format("time.dt = {:g} is above the explicit diffusion stability limit {:.6g} "
                         "(1 / (4 nu (1/dx^2 + 1/dy^2)), nu = {:g}); lower dt or set "
                         "fluid.diffusion = \"implicit\"",
                         dt, lim, nu));
    }
  } else {
    // Crank-Nicolson with a wall or outflow across the transform direction (see predictor_implicit).
    const int t = x_stretched ? 1 : 0;
    // The factored solve has the boundary rows in both directions: no such limit.
    const bool closure_mismatch = !(t == 0 ? px : py) && !c.factored_helmholtz;
    const double h = t == 0 ? c.x.length / c.x.cells : c.y.length / c.y.cells;
    if (closure_mismatch && nu * dt / (h * h) >= 2.0) {
      bad(c, fmt::format("time.dt = {:g} is above the limit {:.6g} of implicit diffusion with walls "
                         "across the {} direction (nu dt / h^2 < 2); lower dt",
                         dt, 2.0 * h * h / nu, t == 0 ? "x" : "y"));
    }
  }
  // Start-up CFL from the initial field and the inflow speeds.
  double umax = std::hypot(c.initial.velocity[0], c.initial.velocity[1]);
  if (c.initial.type == InitialType::taylor_green || c.initial.type == InitialType::vortex) {
    umax += std::abs(c.initial.amplitude) * std::max(1.0, c.x.length / c.y.length);
  }
  for (int s = 0; s < 4; ++s) {
    const SideBc& b = c.bc[s];
    if (b.type == BcType::inflow) umax = std::max(umax, std::abs(b.mean) * (b.profile == Profile::parabolic ? 1.5 : 1.0));
    if (b.type == BcType::wall) umax = std::max(umax, std::abs(b.velocity) + std::abs(b.amplitude));
  }
  const double hmin = std::min(min_width(c.x), min_width(c.y));
  // With substeps, the fluid's own step may be as short as dt / substeps_max.
  const double cfl = umax * dt / hmin / c.substeps_max;
  if (cfl > c.cfl_max) {
    bad(c, fmt::format("time.dt = {:g} gives a start-up CFL number {:.4g} above the limit "
                       "fluid.health.cfl_max = {:g} (speed {:g}, smallest cell {:g}{}); the "
                       "largest stable dt is {:.6g}",
                       dt, cfl, c.cfl_max, umax, hmin,
                       c.substeps_max > 1
                           ? fmt::format(", {} substeps (fluid.substeps.max)", c.substeps_max)
                           : std::string(),
                       c.cfl_max * hmin / umax * c.substeps_max));
  }
}

namespace {

// The optional oscillation amplitude sin(omega t + phase) of a wall's speed or a face pressure.
void read_oscillation(const fsi::SceneTable& t, SideBc& b) {
  b.amplitude = t.number("amplitude", 0.0);
  b.omega = t.number("omega", 0.0);
  b.phase_angle = t.number("phase", 0.0);
}

SideBc read_side(const fsi::SceneTable& t) {
  SideBc b;
  const std::string type =
      t.choice("type", {"periodic", "wall", "slip", "inflow", "outflow", "pressure"});
  if (type == "periodic") b.type = BcType::periodic;
  if (type == "wall") {
    b.type = BcType::wall;
    b.velocity = t.number("velocity", 0.0);
    read_oscillation(t, b);
  }
  if (type == "slip") b.type = BcType::slip;
  if (type == "inflow") {
    b.type = BcType::inflow;
    b.profile = t.choice("profile", {"parabolic", "uniform"}, "parabolic") == "uniform"
                    ? Profile::uniform
                    : Profile::parabolic;
    b.mean = t.number("mean");
  }
  if (type == "inflow" || type == "pressure") {
    const std::string ramp = t.choice("ramp", {"none", "cosine", "linear"}, "none");
    b.ramp = ramp == "cosine" ? Ramp::cosine : ramp == "linear" ? Ramp::linear : Ramp::none;
    b.ramp_time = b.ramp == Ramp::none ? 0.0 : t.positive("ramp_time");
  }
  if (type == "pressure") {
    b.type = BcType::pressure;
    b.value = t.number("value", 0.0);
    read_oscillation(t, b);
    b.total = t.choice("entering", {"static", "total"}, "static") == "total";
  }
  if (type == "outflow") {
    b.type = BcType::outflow;
    b.phase = t.choice("phase", {"bulk", "orlanski"}, "bulk") == "orlanski" ? Phase::orlanski : Phase::bulk;
  }
  t.finish();
  return b;
}

}  // namespace

Config read_config(const fsi::SceneTable& f, double dt) {
  Config c;
  c.source = f.file().string();
  c.density = f.positive("density");
  c.viscosity = f.positive("viscosity");
  c.implicit = f.choice("diffusion", {"explicit", "implicit"}, "explicit") == "implicit";
  // Crank-Nicolson's forcing, "increment" by default (recorded in the effective scene: the
  // default was "after_solve" before, common/checkpoint.cpp).
  if (c.implicit || f.has("implicit_forcing")) {
    c.forcing_in_increment =
        f.choice("implicit_forcing", {"after_solve", "increment"}, "increment") == "increment";
    if (!c.implicit)
      f.fail("implicit_forcing",
             fmt::format("= \"{}\" applies to Crank-Nicolson only: set diffusion = \"implicit\" "
                         "or remove the key",
                         c.forcing_in_increment ? "increment" : "after_solve"));
  }
  if (f.has("helmholtz")) {
    c.factored_helmholtz = f.choice("helmholtz", {"factored", "direct"}, "factored") == "factored";
    if (!c.implicit)
      f.fail("helmholtz", fmt::format("= \"{}\" applies to Crank-Nicolson only: set diffusion = "
                                      "\"implicit\" or remove the key",
                                      c.factored_helmholtz ? "factored" : "direct"));
  }
  c.bodies_inviscid = f.choice("body_viscosity", {"none", "kelvin-voigt"}, "none") == "none";
  // Only when given: a scene without it keeps its effective scene (and its checkpoints) as before.
  if (f.has("body_divergence")) {
    const std::string d = f.choice("body_divergence", {"zero", "solid", "coupled_step"}, "zero");
    c.body_divergence = d == "solid"          ? Config::BodyDivergence::solid
                        : d == "coupled_step" ? Config::BodyDivergence::coupled_step
                                              : Config::BodyDivergence::zero;
  }
  if (f.has("forcing_time")) c.forcing_time = f.non_negative("forcing_time");
  // Only when given: a scene without it keeps its effective scene as it was.
  if (f.has("interface")) {
    c.sharp_interface = f.choice("interface", {"volume", "sharp"}, "volume") == "sharp";
    if (c.sharp_interface && c.implicit)
      f.fail("interface", "= \"sharp\" applies to explicit diffusion only: set diffusion = "
                          "\"explicit\" or interface = \"volume\"");
    if (c.sharp_interface && f.has("forcing_time"))
      f.fail("interface", "= \"sharp\" places the wall itself and takes no forcing_time: remove "
                          "fluid.forcing_time or set interface = \"volume\"");
  }
  // Only when given: a scene without it keeps its effective scene as it was.
  if (f.has("upwind_blend")) c.upwind_blend = f.in_range("upwind_blend", 0.0, 1.0, false, 0.0);
  if (f.has("convection"))
    c.upwind3 = f.choice("convection", {"central", "upwind3"}, "central") == "upwind3";
  // The launcher's: how many ranks ./fsi gives the fluid (the job's own count decides).
  if (f.has("ranks")) c.ranks = int(f.positive_integer("ranks"));

  const fsi::SceneTable g = f.table("grid");
  const std::vector<double> cells = g.numbers("cells");
  if (cells.size() != 2) g.fail("cells", fmt::format("must be [nx, ny], got {} numbers", cells.size()));
  for (double n : cells) {
    if (n != std::floor(n)) g.fail("cells", fmt::format("must be integers, got {}", n));
    if (n < 4) g.fail("cells", fmt::format("must be >= 4 in each direction for the stencil, got {}", n));
  }
  // About 50 doubles a cell (velocity, pressure, predictor, explicit terms, forcing, volume
  // fractions, the Poisson solver's transforms): less than the fluid takes.
  constexpr double kBytesPerCell = 50 * 8;
  fsi::check_memory(g, "cells", cells[0] * cells[1] * kBytesPerCell,
               fmt::format("{:g} x {:g} = {:.3g} grid cells", cells[0], cells[1], cells[0] * cells[1]));
  if (cells[0] > 1e9 || cells[1] > 1e9)
    g.fail("cells", fmt::format("must be at most 1e9 in each direction, got [{:g}, {:g}]", cells[0], cells[1]));
  const auto size = g.vec2("size");
  if (!(size[0] > 0 && size[1] > 0)) g.fail("size", fmt::format("must be > 0, got [{}, {}]", size[0], size[1]));
  const auto origin = g.vec2("origin", {0.0, 0.0});
  c.x = {int(cells[0]), size[0], origin[0]};
  c.y = {int(cells[1]), size[1], origin[1]};
  c.y.tanh_beta = g.non_negative("y_stretch", 0.0);
  for (const auto& [a, name] : {std::pair{&c.x, "x_band"}, std::pair{&c.y, "y_band"}}) {
    const auto band = g.optional_table(name);
    if (!band) continue;
    a->band_from = band->number("from");
    a->band_to = band->number("to");
    const long cells_in = band->positive_integer("cells");
    if (cells_in > a->cells)
      band->fail("cells", fmt::format("= {} is more than the direction's {} cells "
                                      "(fluid.grid.cells)",
                                      cells_in, a->cells));
    a->band_cells = int(cells_in);
    band->finish();
  }
  g.finish();

  const fsi::SceneTable b = f.table("boundary");
  for (int s = 0; s < 4; ++s) c.bc[s] = read_side(b.table(kSideNames[s]));
  b.finish();
  c.x.periodic = c.bc[left].type == BcType::periodic;
  c.y.periodic = c.bc[bottom].type == BcType::periodic;

  if (auto sp = f.optional_table("sponge")) {
    c.x.sponge_cells = int(sp->positive_integer("cells"));
    c.x.sponge_ratio = sp->in_range("ratio", 1.0, 1.5, false, 1.05);
    sp->finish();
  }
  if (auto fo = f.optional_table("forcing")) {
    c.body = fo->vec2("body", {0.0, 0.0});
    c.oscillating = fo->vec2("oscillating", {0.0, 0.0});
    c.gravity = fo->vec2("gravity", {0.0, 0.0});
    const bool osc = c.oscillating[0] != 0 || c.oscillating[1] != 0;
    c.period = osc ? fo->positive("period") : fo->positive("period", 1.0);
    c.phase = fo->number("phase", 0.0);
    fo->finish();
  }
  if (auto in = f.optional_table("initial")) {
    const std::string t = in->choice("type", {"rest", "uniform", "taylor-green", "vortex"}, "rest");
    c.initial.type = t == "uniform"        ? InitialType::uniform
                     : t == "taylor-green" ? InitialType::taylor_green
                     : t == "vortex"       ? InitialType::vortex
                                           : InitialType::rest;
    if (t == "uniform" || t == "vortex") c.initial.velocity = in->vec2("velocity", {0.0, 0.0});
    if (t == "taylor-green" || t == "vortex") c.initial.amplitude = in->number("amplitude");
    if (t == "vortex") {
      c.initial.centre = in->vec2("centre");
      c.initial.radius = in->positive("radius");
    }
    in->finish();
  }
  for (const fsi::SceneTable& p : f.tables("probes")) {
    c.probes.push_back({p.string("name"), p.vec2("at")});
    p.finish();
  }
  if (auto d = f.optional_table("diagnostics")) {
    const std::string ws = d->choice("wall_shear", {"none", "left", "right", "bottom", "top", "both_y", "both_x"}, "none");
    if (ws == "both_y") c.wall_shear = {bottom, top};
    else if (ws == "both_x") c.wall_shear = {left, right};
    else if (ws != "none") {
      for (int s = 0; s < 4; ++s)
        if (ws == kSideNames[s]) c.wall_shear = {Side(s)};
    }
    // Only when given: a scene without it keeps its effective scene as it was.
    if (d->has("flow_rate")) {
      c.flow_rate = d->numbers("flow_rate");
      const double lo = c.x.origin, hi = c.x.origin + c.x.length;
      for (std::size_t k = 0; k < c.flow_rate.size(); ++k)
        if (!(c.flow_rate[k] >= lo && c.flow_rate[k] <= hi))
          d->fail("flow_rate", fmt::format("section {} at x = {} is outside the domain's x range "
                                           "[{}, {}]", k, c.flow_rate[k], lo, hi));
    }
    d->finish();
  }
  if (auto h = f.optional_table("health")) {
    c.cfl_max = h->positive("cfl_max", 1.0);
    c.divergence_max = h->positive("divergence_max", 1e-6);
    c.health_every = h->positive_integer("every", 10);
    h->finish();
  }
  if (auto s = f.optional_table("substeps")) {
    const long m = s->positive_integer("max", 1);
    if (m > kMaxSubsteps)
      s->fail("max", fmt::format("{} substeps per step: at most {}; lower time.dt instead", m,
                                 kMaxSubsteps));
    c.substeps_max = int(m);
    c.substeps_cfl = s->positive("cfl", 0.8);
    if (c.substeps_cfl > c.cfl_max)
      s->fail("cfl", fmt::format("{:g}{} is above fluid.health.cfl_max = {:g}: the substeps "
                                 "would aim above the number that stops the run",
                                 c.substeps_cfl, s->has("cfl") ? "" : " (the default)",
                                 c.cfl_max));
    // AB2 with third-order upwind fluxes: stable to |u| dt/h = 0.58 (1D von Neumann).
    constexpr double kUpwind3Cfl = 0.58;
    if (c.upwind3 && c.substeps_cfl > kUpwind3Cfl)
      s->fail("cfl", fmt::format("{:g}{} is above {:g}, where AB2 with convection = \"upwind3\" "
                                 "turns unstable: set cfl = 0.5",
                                 c.substeps_cfl, s->has("cfl") ? "" : " (the default)",
                                 kUpwind3Cfl));
    s->finish();
  }
  // "coupled_step" differs from "zero" in sub-cycled steps only: without substeps it would be a
  // choice that does nothing.
  if (c.body_divergence == Config::BodyDivergence::coupled_step && c.substeps_max == 1)
    f.fail("body_divergence",
           "= \"coupled_step\" changes only the steps the fluid sub-cycles, and this scene does not "
           "sub-cycle it ([fluid.substeps] max > 1): set body_divergence = \"zero\" (the same "
           "steps) or add [fluid.substeps]");
  for (Side s : c.wall_shear) {
    if (c.bc[s].type != BcType::wall) {
      f.fail("diagnostics", fmt::format("wall_shear on side {} which is not a wall", kSideNames[s]));
    }
  }
  f.finish();
  validate(c, dt);
  return c;
}

}  // namespace fluid
