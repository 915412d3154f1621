// Eigenmodes (paper Eq. 28) of a slender clamped-free beam against Euler-Bernoulli with the
// plane-strain modulus, and the same frequency from a free-vibration time run.
#include <catch2/catch.hpp>
#include <cmath>
#include <utility>

#include "solver.hpp"

using namespace solid;

namespace {

const double beta_l[3] = {1.875104, 4.694091, 7.854757};
constexpr double pi = 3.141592653589793;

// Cantilever L = 1, h = 0.02 (slender: shear and rotary inertia below 0.5 % on mode 3),
// E = 1e6, nu = 0.3, rho = 1, clamped at x = 0.
Model cantilever(int ny) {
  Model model;
  BodySpec b;
  b.name = "beam";
  b.mesh = rectangle_mesh(0, 0, 1, 0.02, 50 * ny, ny, Diagonals::criss_cross);
  b.materials = {Material::from_young(MaterialModel::saint_venant_kirchhoff, 1e6, 0.3, 1)};
  Constraint c;
  c.boundary = "left";
  b.constraints = {c};
  model.bodies = {b};
  return model;
}

double euler_bernoulli(int k) {
  const double E = 1e6 / (1 - 0.09), I = 0.02 * 0.02 * 0.02 / 12, m = 0.02;
  return beta_l[k] * beta_l[k] * std::sqrt(E * I / m);
}

}  // namespace

TEST_CASE("cantilever eigenfrequencies within 2 % of Euler-Bernoulli (8 elements across)",
          "[modes]") {
  Solver s(cantilever(8));
  const Modes m = s.modes(3);
  REQUIRE(m.omega.size() == 3);
  for (int k = 0; k < 3; ++k) {
    const double err = m.omega[k] / euler_bernoulli(k) - 1;
    INFO("mode " << k + 1 << ": omega " << m.omega[k] << ", Euler-Bernoulli " << euler_bernoulli(k)
                 << ", error " << 100 * err << " %");
    CHECK(std::abs(err) <= 0.02);
  }
  // Mode shapes are M-orthonormal: kinetic energy of a unit modal velocity is 1/2.
  s.set_velocity(0, m.shapes[0][0]);
  CHECK(s.kinetic_energy() == Approx(0.5).epsilon(1e-8));
}

TEST_CASE("a free vibration from the first mode shape has the modal frequency",
          "[modes][dynamic]") {
  Solver s(cantilever(4));
  const Modes m = s.modes(1);
  const double omega = m.omega[0];
  const double period = 2 * pi / omega;
  const int steps_per_period = 100;
  const double dt = period / steps_per_period;
  // Small amplitude: tip displacement about 1e-6 of the length.
  std::vector<double> v = m.shapes[0][0];
  const Mesh& mesh = s.mesh(0);
  int tip = 0;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (std::abs(mesh.x[2 * n] - 1) < 1e-12 && std::abs(mesh.x[2 * n + 1] - 0.01) < 1e-12) tip = n;
  const double scale = 1e-6 * omega / std::abs(v[2 * tip + 1]);
  for (double& c : v) c *= scale;
  s.set_velocity(0, v);
  std::vector<double> crossings;
  double prev = 0;
  for (int k = 1; k <= 2 * steps_per_period + 10 && crossings.size() < 3; ++k) {
    s.advance(dt);
    const double uy = s.displacements(0)[2 * tip + 1];
    if (k > 1 && (uy > 0) != (prev > 0)) crossings.push_back(s.time() - dt * uy / (uy - prev));
    prev = uy;
  }
  REQUIRE(crossings.size() == 3);
  const double measured = crossings[2] - crossings[0];
  INFO("modal period " << period << ", time run " << measured);
  // Trapezoidal Newmark lengthens the period by (omega dt)^2 / 12 = 3.3e-4 at 100 steps.
  CHECK(measured / period - 1 == Approx(std::pow(2 * pi / steps_per_period, 2) / 12).margin(1e-4));
}

TEST_CASE("modes need inertia", "[modes][input]") {
  Model model = cantilever(2);
  model.settings.fluid_density = 1;  // rho_s - rho_f = 0
  Solver s(model);
  CHECK_THROWS_WITH(s.modes(2),
                    Catch::Contains("positive inertial density") && Catch::Contains("'beam'"));
}

// Newmark's damped members (gamma > 1/2, beta = (gamma + 1/2)^2 / 4): a free vibration from the
// first mode shape is a one-dof oscillator x'' + omega^2 x = 0 in the mode's coordinate, so its
// energy after k steps is the one of the one-dof Newmark recurrence (Eq. 13-14 with
// a = -omega^2 x) from the same start, which the step must follow to round-off and the
// linearisation of the small amplitude.
TEST_CASE("Newmark with gamma > 1/2 damps a modal vibration as the one-dof recurrence does",
          "[modes][dynamic]") {
  // (1/2, 0.3): the general velocity update without damping; then two damped members.
  for (const auto& [gamma, beta] : {std::pair{0.5, 0.3}, std::pair{0.6, 0.3025},
                                    std::pair{0.8, 0.4225}}) {
    Model model = cantilever(4);
    model.settings.newmark_gamma = gamma;
    model.settings.newmark_beta = beta;
    model.settings.newton_tolerance = 1e-13;
    Solver s(model);
    const Modes m = s.modes(1);
    const double omega = m.omega[0];
    const int steps_per_period = 10;
    const double dt = 2 * pi / omega / steps_per_period;
    // Unit modal velocity scaled to a tip speed of 1e-6 omega (the linear regime).
    std::vector<double> v = m.shapes[0][0];
    double vmax = 0;
    for (double c : v) vmax = std::max(vmax, std::abs(c));
    const double scale = 1e-6 * omega / vmax;
    for (double& c : v) c *= scale;
    s.set_velocity(0, v);
    const double e0 = s.kinetic_energy() + s.strain_energy();
    // The one-dof recurrence in the mode's coordinate q (unit modal mass).
    double q = 0, qd = scale, qdd = 0;
    const double w2 = omega * omega;
    double worst = 0, ratio = 1;
    for (int k = 0; k < 3 * steps_per_period; ++k) {
      s.advance(dt);
      const double q1 = (q + dt * qd + dt * dt * (0.5 - beta) * qdd) / (1 + beta * dt * dt * w2);
      const double qdd1 = -w2 * q1;
      qd += dt * ((1 - gamma) * qdd + gamma * qdd1);
      q = q1, qdd = qdd1;
      const double expected = 0.5 * (qd * qd + w2 * q * q);
      ratio = expected / e0;
      const double e = s.kinetic_energy() + s.strain_energy();
      worst = std::max(worst, std::abs(e / expected - 1));
    }
    INFO("gamma " << gamma << ", beta " << beta << ": energy after 3 periods " << ratio
                  << " of the start in the recurrence, largest relative difference " << worst);
    // The recurrence itself: gamma = 1/2 keeps the amplitude, the others damp (so the case
    // compares a decay, not a constant).
    if (gamma == 0.5)
      CHECK(std::abs(ratio - 1) <= 0.05);
    else
      CHECK(ratio < 0.9);
    CHECK(worst <= 1e-6);
  }
}
