// Bad input in the [fluid] table: each error names the key, the value and the file.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "config.hpp"
#include "error.hpp"
#include "grid.hpp"
#include "scene.hpp"

using Catch::Matchers::Contains;

namespace {

const char* kGood = R"(
[fluid]
density = 1.0
viscosity = 0.01
[fluid.grid]
cells = [32, 16]
size = [2.0, 1.0]
[fluid.boundary]
left = { type = "periodic" }
right = { type = "periodic" }
bottom = { type = "wall" }
top = { type = "wall" }
)";

// TEXT as a scene file, in the temporary folder: a run of this binary from a source tree leaves
// nothing there.
std::string scene_file(const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / "fluid_config_test.toml").string();
  std::ofstream(path) << text;
  return path;
}

fluid::Config read(const std::string& text, double dt = 1e-3) {
  fsi::Scene scene(scene_file(text));
  return fluid::read_config(scene.root().table("fluid"), dt);
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  REQUIRE(p != std::string::npos);
  return s.replace(p, from.size(), to);
}

}  // namespace

TEST_CASE("a good [fluid] table reads", "[fluid][config]") {
  const fluid::Config c = read(kGood);
  CHECK(c.x.cells == 32);
  CHECK(c.y.cells == 16);
  CHECK(c.bc[fluid::left].type == fluid::BcType::periodic);
  CHECK(c.bc[fluid::top].type == fluid::BcType::wall);
}

TEST_CASE("non-positive viscosity or density", "[fluid][config]") {
  CHECK_THROWS_WITH(read(replace(kGood, "viscosity = 0.01", "viscosity = -1")),
                    Contains("fluid.viscosity must be > 0, got -1") && Contains("fluid_config_test.toml"));
  CHECK_THROWS_WITH(read(replace(kGood, "density = 1.0", "density = 0")),
                    Contains("fluid.density must be > 0, got 0"));
}

TEST_CASE("grid too small for the stencil", "[fluid][config]") {
  CHECK_THROWS_WITH(read(replace(kGood, "cells = [32, 16]", "cells = [32, 2]")),
                    Contains("fluid.grid.cells must be >= 4"));
}

TEST_CASE("a stretched direction where a solve needs it uniform", "[fluid][config]") {
  // y stretched and periodic
  std::string s = replace(kGood, "size = [2.0, 1.0]", "size = [2.0, 1.0]\ny_stretch = 1.5");
  s = replace(s, "bottom = { type = \"wall\" }", "bottom = { type = \"periodic\" }");
  s = replace(s, "top = { type = \"wall\" }", "top = { type = \"periodic\" }");
  CHECK_THROWS_WITH(read(s), Contains("fluid.grid.y_stretch = 1.5 stretches a periodic direction"));
  // both directions stretched, y by tanh, x by the outlet sponge: read (y is then transformed by
  // its eigenvectors), except with the direct Crank-Nicolson solve
  std::string b = replace(kGood, "size = [2.0, 1.0]", "size = [2.0, 1.0]\ny_stretch = 1.5");
  b = replace(b, "left = { type = \"periodic\" }", "left = { type = \"inflow\", mean = 1.0 }");
  b = replace(b, "right = { type = \"periodic\" }", "right = { type = \"outflow\" }");
  b += "[fluid.sponge]\ncells = 8\nratio = 1.1\n";
  CHECK(read(b).x.sponge_cells == 8);
  b = replace(b, "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\"\nhelmholtz = \"direct\"");
  CHECK_THROWS_WITH(read(b), Contains("fluid.helmholtz = \"direct\" needs one uniform direction") &&
                                 Contains("fluid.grid.y_stretch = 1.5") && Contains("fluid.sponge"));
}

TEST_CASE("periodic on one side only, inflow on a periodic side", "[fluid][config]") {
  CHECK_THROWS_WITH(read(replace(kGood, "right = { type = \"periodic\" }", "right = { type = \"wall\" }")),
                    Contains("fluid.boundary.left is periodic but fluid.boundary.right is wall"));
  CHECK_THROWS_WITH(
      read(replace(kGood, "left = { type = \"periodic\" }", "left = { type = \"inflow\", mean = 1.0 }")),
      Contains("fluid.boundary.left: an inflow cannot face a periodic side"));
}

TEST_CASE("dt above the explicit stability limit at start", "[fluid][config]") {
  // h = 1/16, nu = 0.01: limit 1 / (4 nu (256 + 256)) = 0.048828
  CHECK_THROWS_WITH(read(kGood, 0.1),
                    Contains("time.dt = 0.1 is above the explicit diffusion stability limit 0.0488281"));
  // Start-up CFL from a moving wall: u = 10, h = 1/16, dt = 0.01 -> CFL 1.6
  CHECK_THROWS_WITH(read(replace(kGood, "top = { type = \"wall\" }", "top = { type = \"wall\", velocity = 10.0 }"), 0.01),
                    Contains("start-up CFL number 1.6 above the limit"));
  // Implicit diffusion lifts the diffusion limit.
  CHECK_NOTHROW(read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\""), 0.06));
}

TEST_CASE("unknown keys are errors", "[fluid][config]") {
  CHECK_THROWS_WITH(read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\nviscocity = 2")),
                    Contains("viscocity"));
}


TEST_CASE("upwind_blend: read, and refused outside [0, 1]", "[fluid][config][upwind]") {
  CHECK(read(kGood).upwind_blend == 0.0);
  CHECK(read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\nupwind_blend = 0.2")).upwind_blend == 0.2);
  CHECK_THROWS_WITH(read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\nupwind_blend = 1.5")),
                    Contains("upwind_blend") && Contains("1.5"));
}

TEST_CASE("convection: central by default, upwind3, anything else refused",
          "[fluid][config][upwind]") {
  auto with = [](const std::string& keys) {
    return replace(kGood, "viscosity = 0.01", "viscosity = 0.01\n" + keys);
  };
  CHECK_FALSE(read(kGood).upwind3);
  CHECK_FALSE(read(with("convection = \"central\"")).upwind3);
  CHECK(read(with("convection = \"upwind3\"")).upwind3);
  CHECK_THROWS_WITH(read(with("convection = \"quick\"")),
                    Contains("convection") && Contains("quick") && Contains("upwind3"));
  // Sub-cycling aims at a CFL number below AB2's limit with these fluxes.
  const std::string up3 = with("convection = \"upwind3\"");
  CHECK_NOTHROW(read(up3 + "\n[fluid.substeps]\nmax = 4\ncfl = 0.5\n"));
  CHECK_THROWS_WITH(read(up3 + "\n[fluid.substeps]\nmax = 4\n"),
                    Contains("cfl") && Contains("0.8 (the default)") && Contains("upwind3"));
  CHECK_NOTHROW(read(std::string(kGood) + "\n[fluid.substeps]\nmax = 4\n"));
}

TEST_CASE("body_divergence: zero by default, solid, coupled_step only with substeps",
          "[fluid][config]") {
  using BD = fluid::Config::BodyDivergence;
  auto with = [](const std::string& keys) {
    return replace(kGood, "viscosity = 0.01", "viscosity = 0.01\n" + keys);
  };
  CHECK(read(kGood).body_divergence == BD::zero);
  CHECK(read(with("body_divergence = \"solid\"")).body_divergence == BD::solid);
  const std::string step = with("body_divergence = \"coupled_step\"");
  CHECK(read(step + "\n[fluid.substeps]\nmax = 2\n").body_divergence == BD::coupled_step);
  CHECK_THROWS_WITH(read(step), Contains("body_divergence") && Contains("coupled_step") &&
                                    Contains("[fluid.substeps]") && Contains("fluid_config_test.toml"));
  CHECK_THROWS_WITH(read(step + "\n[fluid.substeps]\nmax = 1\n"), Contains("body_divergence"));
  CHECK_THROWS_WITH(read(with("body_divergence = \"some\"")),
                    Contains("body_divergence") && Contains("some") && Contains("coupled_step"));
}

TEST_CASE("forcing_time: read with every diffusion and forcing, refused negative",
          "[fluid][config]") {
  auto with = [](const std::string& keys) {
    return replace(kGood, "viscosity = 0.01", "viscosity = 0.01\n" + keys);
  };
  CHECK(read(kGood).forcing_time < 0);  // not given: tau = dt
  CHECK(read(with("forcing_time = 2e-4")).forcing_time == 2e-4);
  CHECK(read(with("forcing_time = 0")).forcing_time == 0.0);
  const std::string after_solve = "diffusion = \"implicit\"\nimplicit_forcing = \"after_solve\"";
  CHECK(read(with(after_solve + "\nforcing_time = 1e-3")).forcing_time == 1e-3);
  // Crank-Nicolson's default forcing, inside its solve, blends by the same beta.
  CHECK(read(with("diffusion = \"implicit\"\nforcing_time = 1e-3")).forcing_time == 1e-3);
  CHECK_THROWS_WITH(read(with("forcing_time = -1e-3")),
                    Contains("forcing_time") && Contains("-0.001"));
  CHECK_THROWS_WITH(read(with("forcing_time = inf")), Contains("forcing_time") && Contains("inf"));
  CHECK(read(with("diffusion = \"implicit\"\nimplicit_forcing = \"increment\"\nforcing_time = 0"))
            .forcing_time == 0.0);
}

TEST_CASE("interface: volume by default, sharp with explicit diffusion only", "[fluid][config]") {
  auto with = [](const std::string& keys) {
    return replace(kGood, "viscosity = 0.01", "viscosity = 0.01\n" + keys);
  };
  CHECK_FALSE(read(kGood).sharp_interface);
  CHECK_FALSE(read(with("interface = \"volume\"")).sharp_interface);
  CHECK(read(with("interface = \"sharp\"")).sharp_interface);
  CHECK_THROWS_WITH(read(with("interface = \"sharp\"\ndiffusion = \"implicit\"")),
                    Contains("fluid.interface") && Contains("explicit diffusion") &&
                        Contains("fluid_config_test.toml"));
  CHECK_THROWS_WITH(read(with("interface = \"sharp\"\nforcing_time = 0.0")),
                    Contains("fluid.interface") && Contains("forcing_time") &&
                        Contains("fluid_config_test.toml"));
  CHECK_THROWS_WITH(read(with("interface = \"smooth\"")),
                    Contains("interface") && Contains("smooth") && Contains("sharp"));
}

TEST_CASE("implicit_forcing: read with Crank-Nicolson, refused without it or unknown",
          "[fluid][config][implicit]") {
  const std::string cn = replace(kGood, "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\"");
  CHECK(read(cn).forcing_in_increment);  // "increment" by default
  CHECK_FALSE(
      read(replace(cn, "viscosity = 0.01", "viscosity = 0.01\nimplicit_forcing = \"after_solve\""))
          .forcing_in_increment);
  CHECK_THROWS_WITH(
      read(replace(cn, "viscosity = 0.01", "viscosity = 0.01\nimplicit_forcing = \"inside\"")),
      Contains("implicit_forcing") && Contains("inside"));
  CHECK_THROWS_WITH(read(replace(kGood, "viscosity = 0.01",
                                 "viscosity = 0.01\nimplicit_forcing = \"increment\"")),
                    Contains("implicit_forcing") && Contains("increment") &&
                        Contains("Crank-Nicolson only"));
}

TEST_CASE("helmholtz: factored by default, direct with Crank-Nicolson, refused otherwise",
          "[fluid][config][implicit]") {
  const std::string cn = replace(kGood, "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\"");
  CHECK(read(cn).factored_helmholtz);
  CHECK_FALSE(read(replace(cn, "viscosity = 0.01", "viscosity = 0.01\nhelmholtz = \"direct\""))
                  .factored_helmholtz);
  CHECK_THROWS_WITH(read(replace(cn, "viscosity = 0.01", "viscosity = 0.01\nhelmholtz = \"adi\"")),
                    Contains("helmholtz") && Contains("adi"));
  CHECK_THROWS_WITH(
      read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\nhelmholtz = \"factored\"")),
      Contains("helmholtz") && Contains("factored") && Contains("Crank-Nicolson only"));
  // Walls across the transform direction (x): the direct solve holds for nu dt / h^2 < 2 only
  // (h = 1/16, nu = 0.01: dt < 0.78), the factored one at any dt.
  std::string walls = replace(replace(cn, "left = { type = \"periodic\" }", "left = { type = \"wall\" }"),
                              "right = { type = \"periodic\" }", "right = { type = \"wall\" }");
  CHECK_NOTHROW(read(walls, 1.0));
  CHECK_THROWS_WITH(
      read(replace(walls, "viscosity = 0.01", "viscosity = 0.01\nhelmholtz = \"direct\""), 1.0),
      Contains("time.dt = 1") && Contains("nu dt / h^2 < 2"));
  CHECK_NOTHROW(
      read(replace(walls, "viscosity = 0.01", "viscosity = 0.01\nhelmholtz = \"direct\""), 0.5));
}

// Whether the effective scene of TEXT records fluid.implicit_forcing (a restart and the case
// scripts tell the defaults of a run by it: common/checkpoint.cpp, runs/lib/job.py).
bool records_implicit_forcing(const std::string& text) {
  fsi::Scene scene(scene_file(text));
  fluid::read_config(scene.root().table("fluid"), 1e-3);
  return scene.effective_toml().find("implicit_forcing = \"increment\"") != std::string::npos;
}

TEST_CASE("implicit_forcing: its default recorded with Crank-Nicolson only", "[fluid][config]") {
  CHECK(records_implicit_forcing(
      replace(kGood, "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\"")));
  CHECK_FALSE(records_implicit_forcing(kGood));
}

TEST_CASE("body_viscosity: none by default, kelvin-voigt, refused when unknown",
          "[fluid][config]") {
  CHECK(read(kGood).bodies_inviscid);
  CHECK(read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\nbody_viscosity = \"none\""))
            .bodies_inviscid);
  CHECK_FALSE(read(replace(kGood, "viscosity = 0.01",
                           "viscosity = 0.01\nbody_viscosity = \"kelvin-voigt\""))
                  .bodies_inviscid);
  CHECK_THROWS_WITH(
      read(replace(kGood, "viscosity = 0.01", "viscosity = 0.01\nbody_viscosity = \"elastic\"")),
      Contains("body_viscosity") && Contains("elastic"));
}

TEST_CASE("pressure boundaries: where they are allowed", "[fluid][config][pressure]") {
  std::string open = replace(kGood, "left = { type = \"periodic\" }",
                             "left = { type = \"pressure\", value = 2.0, ramp = \"cosine\", ramp_time = 0.5 }");
  open = replace(open, "right = { type = \"periodic\" }", "right = { type = \"pressure\" }");
  const fluid::Config c = read(open);
  CHECK(c.bc[fluid::left].type == fluid::BcType::pressure);
  CHECK(c.bc[fluid::left].boundary_pressure(0.25) == Approx(1.0));
  CHECK(c.bc[fluid::right].boundary_pressure(3.0) == 0.0);
  // With a sponge on the right: allowed.
  CHECK_NOTHROW(read(open + "[fluid.sponge]\ncells = 4\nratio = 1.1\n"));
  CHECK_THROWS_WITH(read(replace(open, "right = { type = \"pressure\" }", "right = { type = \"outflow\" }")),
                    Contains("fluid.boundary.left = pressure with fluid.boundary.right = outflow") &&
                        Contains("fluid_config_test.toml"));
  CHECK_THROWS_WITH(read(replace(open, "bottom = { type = \"wall\" }", "bottom = { type = \"pressure\" }")),
                    Contains("fluid.boundary.bottom = pressure") && Contains("left and right sides only"));
  CHECK_THROWS_WITH(read(replace(open, "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\"")),
                    Contains("fluid.boundary.left = pressure needs fluid.diffusion = \"explicit\""));
  CHECK_THROWS_WITH(read(replace(open, "value = 2.0", "value = \"high\"")), Contains("value"));
  CHECK(read(replace(open, "right = { type = \"pressure\" }",
                     "right = { type = \"pressure\", entering = \"total\" }")).bc[fluid::right].total);
  CHECK_THROWS_WITH(read(replace(open, "right = { type = \"pressure\" }",
                                 "right = { type = \"pressure\", entering = \"dynamic\" }")),
                    Contains("entering"));
}

TEST_CASE("a band of even cells with smooth growth outside it", "[fluid][config][band]") {
  const std::string walls =
      replace(replace(kGood, "left = { type = \"periodic\" }", "left = { type = \"wall\" }"),
              "right = { type = \"periodic\" }", "right = { type = \"wall\" }");
  const fluid::Config c =
      read(replace(walls, "size = [2.0, 1.0]",
                   "size = [2.0, 1.0]\ny_band = { from = 0.4, to = 0.6, cells = 4 }"));
  REQUIRE(c.y.band_cells == 4);
  const fluid::Axis y(c.y);
  CHECK_FALSE(y.uniform());
  CHECK(y.lo() == 0.0);
  CHECK(y.hi() == 1.0);
  const fluid::BandLayout l = fluid::band_layout(c.y);
  CHECK(l.below + l.above == 12);
  CHECK(l.below == 6);  // the band sits in the middle: the split is symmetric
  // Even in the band, its edges on faces; outside, each cell wider than the one nearer the band
  // by the same ratio, the first by that ratio over the band's spacing.
  CHECK(y.face(l.below) == 0.4);
  CHECK(y.face(l.below + 4) == 0.6);
  for (int j = l.below; j < l.below + 4; ++j) CHECK(y.width(j) == Approx(0.05).epsilon(1e-12));
  for (int j = 0; j < l.below; ++j)
    CHECK(y.width(j) / y.width(j + 1) == Approx(l.growth_below).epsilon(1e-9));
  for (int j = l.below + 4; j < 16; ++j)
    CHECK(y.width(j) / y.width(j - 1) == Approx(l.growth_above).epsilon(1e-9));
  CHECK(l.worst() <= 1.2);
  CHECK(l.growth_below > 1.0);

  // The same band in x (the transform then runs along y, which must stay uniform).
  const fluid::Config cx =
      read(replace(walls, "size = [2.0, 1.0]",
                   "size = [2.0, 1.0]\nx_band = { from = 0.5, to = 1.0, cells = 8 }"));
  const fluid::Axis x(cx.x);
  CHECK_FALSE(x.uniform());
  CHECK(x.hi() == 2.0);
}

TEST_CASE("bands that cannot be laid out are refused with the key", "[fluid][config][band]") {
  const std::string walls =
      replace(replace(kGood, "left = { type = \"periodic\" }", "left = { type = \"wall\" }"),
              "right = { type = \"periodic\" }", "right = { type = \"wall\" }");
  auto with = [&](const std::string& keys) {
    return read(replace(walls, "size = [2.0, 1.0]", "size = [2.0, 1.0]\n" + keys));
  };
  CHECK_THROWS_WITH(with("y_band = { from = 0.4, to = 1.2, cells = 8 }"),
                    Contains("fluid.grid.y_band") && Contains("within [0, 1]"));
  CHECK_THROWS_WITH(with("y_band = { from = 0.45, to = 0.55, cells = 14 }"),
                    Contains("fluid.grid.y_band") && Contains("change width by a factor") &&
                        Contains("fluid_config_test.toml"));
  CHECK_THROWS_WITH(with("y_band = { from = 0.4, to = 0.6, cells = 20 }"),
                    Contains("cells") && Contains("more than the direction's 16 cells"));
  CHECK_THROWS_WITH(with("y_band = { from = 0.4, to = 0.6, cells = 4 }\ny_stretch = 1.2"),
                    Contains("fluid.grid.y_band with fluid.grid.y_stretch"));
  // Bands in both directions are read (the transform then runs along y by its eigenvectors, on
  // any number of ranks), but the direct Crank-Nicolson solve needs one uniform direction.
  const std::string both =
      "y_band = { from = 0.4, to = 0.6, cells = 4 }\nx_band = { from = 0.5, to = 1.0, cells = 8 }";
  CHECK(with(both).x.band_cells == 8);
  CHECK(read(replace(replace(walls, "size = [2.0, 1.0]", "size = [2.0, 1.0]\n" + both),
                     "viscosity = 0.01", "viscosity = 0.01\nranks = 2"))
            .ranks == 2);
  CHECK_THROWS_WITH(
      read(replace(replace(walls, "size = [2.0, 1.0]", "size = [2.0, 1.0]\n" + both),
                   "viscosity = 0.01", "viscosity = 0.01\ndiffusion = \"implicit\"\nhelmholtz = \"direct\"")),
      Contains("fluid.helmholtz = \"direct\" needs one uniform direction") &&
          Contains("fluid.grid.y_band") && Contains("fluid.grid.x_band"));
  CHECK_THROWS_WITH(with("y_band = { from = 0.4, to = 0.6, cells = 8, step = 2 }"),
                    Contains("step"));
  // A band along a periodic direction.
  CHECK_THROWS_WITH(
      read(replace(kGood, "size = [2.0, 1.0]",
                   "size = [2.0, 1.0]\nx_band = { from = 0.5, to = 1.0, cells = 8 }")),
      Contains("fluid.grid.x_band stretches x, which is periodic"));
}

TEST_CASE("a band at a wall, and one over the whole direction", "[fluid][config][band]") {
  fluid::AxisSpec a;
  a.cells = 16, a.length = 1.0, a.origin = 0.0;
  a.band_from = 0.0, a.band_to = 0.25, a.band_cells = 8;  // at the bottom wall
  const fluid::BandLayout l = fluid::band_layout(a);
  CHECK(l.below == 0);
  CHECK(l.above == 8);
  const fluid::Axis y(a);
  for (int j = 0; j < 8; ++j) CHECK(y.width(j) == Approx(1.0 / 32).epsilon(1e-12));
  CHECK(y.hi() == 1.0);
  // An edge within round-off of the end counts as the end: no cell is squeezed beyond it.
  a.origin = 0.1, a.length = 0.2, a.band_from = 0.1, a.band_to = 0.3, a.band_cells = 16;
  CHECK(fluid::band_layout(a).worst() == 1.0);
  // A band over the whole direction needs all its cells.
  a.band_cells = 8;
  CHECK_THROWS_WITH(fluid::band_layout(a), Contains("covers the whole direction"));
}
