// The flow-rate diagnostic ([fluid.diagnostics] flow_rate): the volume flux through a vertical
// section, sum_j u(i, j) w_y(j) at the nearest u-face column, against the exact plane Poiseuille
// flux Q = G H^3 / (12 mu) and against the midpoint sum of the discrete steady profile.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include "config.hpp"
#include "diagnostics.hpp"
#include "error.hpp"
#include "scene.hpp"
#include "solver.hpp"

using namespace fluid;
using Catch::Matchers::Contains;

namespace {

constexpr double kG = 2.0;   // driving force per unit volume, -dp/dx
constexpr double kMu = 0.5;  // dynamic viscosity (rho = 1)
constexpr double kH = 1.0;   // channel height

Config channel(int ny) {
  Config c;
  c.density = 1;
  c.viscosity = kMu;
  c.x = {4, 0.5, 0.25};  // x in [0.25, 0.75]
  c.y = {ny, kH, 0.0};
  c.bc[left].type = c.bc[right].type = BcType::periodic;
  c.bc[bottom].type = c.bc[top].type = BcType::wall;
  c.body = {kG, 0.0};
  c.cfl_max = 1e9;
  return c;
}

// The steady flux of a channel of ny cells, run from rest for 3 diffusion times H^2/nu (the
// slowest mode decays by exp(-3 pi^2) ~ 1e-13), at every u-face column.
std::vector<double> steady_flux(int ny) {
  const Config c = channel(ny);
  const double h = kH / ny, dt = 0.1 * h * h / kMu;
  Solver s(c, dt);
  set_initial(s);
  const long steps = std::lround(3.0 * kH * kH / kMu / dt);
  for (long k = 0; k < steps; ++k) s.step(dt);
  std::vector<double> q;
  for (int i = 0; i < s.grid().nu(); ++i) q.push_back(flow_rate(s, i));
  return q;
}

}  // namespace

TEST_CASE("the flow rate of a steady Poiseuille channel is exact on the MAC grid",
          "[fluid][flow_rate]") {
  const double exact = kG * kH * kH * kH / (12 * kMu);
  double err_prev = 0;
  for (int ny : {8, 16, 32}) {
    const std::vector<double> q = steady_flux(ny);
    const double h = kH / ny;
    // The discrete steady profile is the parabola at the u-face centres (quadratic ghost), so
    // the flux is its midpoint sum: exact + h^2 G H / (24 mu).
    const double midpoint = exact + h * h * kG * kH / (24 * kMu);
    const double err = std::abs(q[0] - exact);
    INFO("ny = " << ny << ": Q = " << q[0] << ", exact " << exact << ", midpoint sum " << midpoint);
    for (double qi : q) CHECK(std::abs(qi - q[0]) <= 1e-12 * exact);  // the same in every column
    CHECK(std::abs(q[0] - midpoint) <= 1e-9 * exact);
    if (err_prev > 0) CHECK(std::log2(err_prev / err) == Approx(2.0).margin(1e-6));
    err_prev = err;
  }
}

TEST_CASE("a flow-rate section is measured at the nearest u-face column", "[fluid][flow_rate]") {
  Config c = channel(8);
  Solver s(c, 1e-3);  // faces at x = 0.25, 0.375, 0.5, 0.625, 0.75 (= 0.25, periodic)
  CHECK(nearest_u_column(s, 0.25) == 0);
  CHECK(nearest_u_column(s, 0.43) == 1);
  CHECK(nearest_u_column(s, 0.44) == 2);
  CHECK(nearest_u_column(s, 0.6) == 3);
  CHECK(nearest_u_column(s, 0.75) == 0);  // the domain's end is face 0 on a periodic x
  // A uniform u = 3 through a height of 1.
  for (int j = 0; j < s.grid().ny(); ++j)
    for (int i = 0; i < s.grid().nu(); ++i) s.u()(i, j) = 3.0;
  CHECK(flow_rate(s, 2) == Approx(3.0).epsilon(1e-14));
}

TEST_CASE("flow_rate sections are read and checked", "[fluid][flow_rate][config]") {
  const std::string head = R"(
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
[fluid.diagnostics]
)";
  auto read = [](const std::string& text) {
    const std::string path = "fluid_flow_rate_test.toml";
    std::ofstream(path) << text;
    fsi::Scene scene(path);
    return read_config(scene.root().table("fluid"), 1e-3);
  };
  CHECK(read(head + "flow_rate = [0.5, 1.5]\n").flow_rate == std::vector<double>{0.5, 1.5});
  CHECK(read(head).flow_rate.empty());
  CHECK_THROWS_WITH(read(head + "flow_rate = [0.5, 2.5]\n"),
                    Contains("flow_rate") && Contains("section 1 at x = 2.5") &&
                        Contains("[0, 2]") && Contains("fluid_flow_rate_test.toml"));
  CHECK_THROWS_WITH(read(head + "flow_rate = \"left\"\n"), Contains("flow_rate"));
}
