// The solver core without scenes: patch tests (uniform stretch and shear exact for both
// materials), quadratic Newton convergence, energy conservation of the trapezoidal rule,
// zero excess mass, gravity and reactions, periodic pairs.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "solver.hpp"

using namespace solid;

namespace {

Material svk() {
  return Material::from_young(MaterialModel::saint_venant_kirchhoff, 1.0e3, 0.3, 2.0);
}
Material neo() {
  return Material::from_young(MaterialModel::neo_hookean, 1.0e3, 0.3, 2.0);
}

// A 4 x 3 rectangle, 6 x 5 cells, interior nodes moved at random (an irregular patch).
Mesh irregular_patch(Diagonals d) {
  Mesh m = rectangle_mesh(0, 0, 4, 3, 6, 5, d);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  std::vector<bool> on_boundary(m.num_nodes(), false);
  for (const auto& e : m.surface) on_boundary[e[0]] = on_boundary[e[1]] = true;
  for (int n = 0; n < m.num_nodes(); ++n)
    if (!on_boundary[n]) {
      m.x[2 * n] += u(rng) * 4.0 / 6;
      m.x[2 * n + 1] += u(rng) * 3.0 / 5;
    }
  finalize_mesh(m);
  return m;
}

Constraint fix(const std::string& b, bool x, bool y) {
  Constraint c;
  c.boundary = b;
  c.x = x;
  c.y = y;
  return c;
}

double max_error_against(const Solver& s, const Eigen::Matrix2d& F0) {
  const Mesh& m = s.mesh(0);
  double err = 0;
  for (int n = 0; n < m.num_nodes(); ++n)
    for (int i = 0; i < 2; ++i) {
      const double exact = F0(i, 0) * m.x[2 * n] + F0(i, 1) * m.x[2 * n + 1];
      err = std::max(err, std::abs(s.positions(0)[2 * n + i] - exact));
    }
  return err;
}

}  // namespace

TEST_CASE("patch test: uniform stretch and simple shear under exact tractions", "[patch]") {
  // F0 is reproduced exactly when the boundary carries P N with P = F0 S(F0) and only rigid
  // motions are held (node (0,0) fixed, node (4,0) fixed in y).
  Eigen::Matrix2d stretch, shear;
  stretch << 1.3, 0, 0, 0.8;
  shear << 1, 0.4, 0, 1;
  for (const Material mat : {svk(), neo()})
    for (const auto& F0 : {stretch, shear})
      for (Diagonals d : {Diagonals::criss_cross, Diagonals::right, Diagonals::union_jack}) {
        Model model;
        model.settings.analysis = Analysis::statics;
        model.settings.load_steps = 3;
        model.settings.newton_tolerance = 1e-14;
        BodySpec b;
        b.name = "patch";
        b.mesh = irregular_patch(d);
        b.mesh.node_sets["origin"] = {0};
        b.mesh.node_sets["corner"] = {6};
        b.materials = {mat};
        b.constraints = {fix("origin", true, true), fix("corner", false, true)};
        Eigen::Vector3d Sv;
        evaluate_material(mat, F0 - Eigen::Matrix2d::Identity(), &Sv, nullptr);
        Eigen::Matrix2d S;
        S << Sv(0), Sv(2), Sv(2), Sv(1);
        const Eigen::Matrix2d P = F0 * S;
        const std::pair<std::string, Eigen::Vector2d> sides[] = {
            {"left", {-1, 0}}, {"right", {1, 0}}, {"bottom", {0, -1}}, {"top", {0, 1}}};
        for (const auto& [name, N] : sides) {
          Load l;
          l.boundary = name;
          const Eigen::Vector2d t = P * N;
          l.value = {t(0), t(1)};
          b.loads.push_back(l);
        }
        model.bodies.push_back(b);
        Solver s(model);
        s.solve_static();
        INFO(material_model_name(mat.model) << " F0 = " << F0);
        CHECK(max_error_against(s, F0) <= 1e-12);
      }
}

TEST_CASE("patch test: uniform stretch under prescribed displacements", "[patch]") {
  for (const Material mat : {svk(), neo()}) {
    Model model;
    model.settings.analysis = Analysis::statics;
    model.settings.load_steps = 2;
    model.settings.newton_tolerance = 1e-14;
    BodySpec b;
    b.name = "patch";
    b.mesh = irregular_patch(Diagonals::criss_cross);
    b.materials = {mat};
    Constraint right = fix("right", true, false), top = fix("top", false, true);
    right.type = top.type = Constraint::Type::displacement;
    right.displacement = {0.4 * 4, 0};  // stretch 1.4 in x
    top.displacement = {0, -0.25 * 3};  // 0.75 in y
    b.constraints = {fix("left", true, false), fix("bottom", false, true), right, top};
    model.bodies.push_back(b);
    Solver s(model);
    s.solve_static();
    Eigen::Matrix2d F0;
    F0 << 1.4, 0, 0, 0.75;
    INFO(material_model_name(mat.model));
    CHECK(max_error_against(s, F0) <= 1e-12);
    // The support reactions balance: left and right carry equal and opposite x forces.
    const Vec2 rl = s.reaction(0, "left"), rr = s.reaction(0, "right");
    CHECK(rl[0] + rr[0] == Approx(0).margin(1e-9 * std::abs(rr[0])));
    CHECK(std::abs(rr[0]) > 0);
  }
}

TEST_CASE("Newton converges quadratically on a large-deflection cantilever", "[newton]") {
  for (const Material mat : {svk(), neo()}) {
    Model model;
    model.settings.analysis = Analysis::statics;
    model.settings.load_steps = 1;
    model.settings.newton_tolerance = 1e-13;
    BodySpec b;
    b.name = "beam";
    b.mesh = rectangle_mesh(0, 0, 10, 1, 20, 2, Diagonals::criss_cross);
    b.materials = {mat};
    b.constraints = {fix("left", true, true)};
    Load l;
    l.boundary = "right";
    l.value = {0, -1.0};  // tip deflection of roughly a fifth of the length
    b.loads = {l};
    model.bodies.push_back(b);
    Solver s(model);
    const auto rep = s.solve_static();
    REQUIRE(rep.size() == 1);
    const auto& r = rep[0].residuals;
    std::string seq;
    for (double v : r) seq += fmt::format("{:.3e} ", v);
    INFO(material_model_name(mat.model) << " residuals: " << seq);
    WARN(material_model_name(mat.model) << " Newton residuals: " << seq);
    REQUIRE(rep[0].converged);
    const double tip = s.displacements(0)[2 * 62 + 1];
    CHECK(tip < -1.0);
    // Orders p_k = log(r_k+1 / r_k) / log(r_k / r_k-1) over the iterations above round-off.
    double best = 0;
    for (std::size_t k = 1; k + 1 < r.size(); ++k)
      if (r[k + 1] > 1e-12 * r[0])
        best = std::max(best, std::log(r[k + 1] / r[k]) / std::log(r[k] / r[k - 1]));
    CHECK(best >= 1.8);
    CHECK(rep[0].iterations <= 12);
  }
}

TEST_CASE("trapezoidal Newmark keeps the energy of a free linear-regime vibration", "[energy]") {
  Model model;
  model.settings.newton_tolerance = 1e-13;
  BodySpec b;
  b.name = "beam";
  b.mesh = rectangle_mesh(0, 0, 2, 0.2, 20, 2, Diagonals::criss_cross);
  b.materials = {svk()};
  b.constraints = {fix("left", true, true)};
  model.bodies.push_back(b);
  Solver s(model);
  // Initial velocity growing along the beam (amplitude 1e-5 of the length per period).
  std::vector<double> v(2 * s.mesh(0).num_nodes(), 0.0);
  for (int n = 0; n < s.mesh(0).num_nodes(); ++n) {
    const double X = s.mesh(0).x[2 * n] / 2;
    v[2 * n + 1] = 1e-4 * X * X;
  }
  s.set_velocity(0, v);
  const double e0 = s.kinetic_energy() + s.strain_energy();
  REQUIRE(e0 > 0);
  double worst = 0;
  for (int k = 0; k < 1000; ++k) {
    s.advance(2e-3);
    const double e = s.kinetic_energy() + s.strain_energy();
    worst = std::max(worst, std::abs(e - e0) / e0);
  }
  INFO("largest relative energy change " << worst);
  CHECK(worst <= 1e-6);
  CHECK(s.strain_energy() > 0);
}

namespace {
// A 0.4 x 0.2 neo-Hookean block without supports or loads.
Model free_block(Predictor predictor) {
  Model model;
  model.settings.predictor = predictor;
  BodySpec b;
  b.name = "block";
  b.mesh = rectangle_mesh(0, 0, 0.4, 0.2, 8, 4, Diagonals::criss_cross);
  b.materials = {neo()};
  model.bodies = {b};
  return model;
}
// F_c = M g' in y: the consistent mass's row sums (rho A / 3 per element node) times g', the
// force that gives a free body the uniform acceleration g'.
std::vector<double> uniform_push(const Mesh& mesh, double rho, double g) {
  std::vector<double> f(2 * mesh.num_nodes(), 0.0);
  const double* x = mesh.x.data();
  for (const auto& t : mesh.triangles) {
    const double area = 0.5 * std::abs((x[2 * t[1]] - x[2 * t[0]]) * (x[2 * t[2] + 1] - x[2 * t[0] + 1]) -
                                       (x[2 * t[2]] - x[2 * t[0]]) * (x[2 * t[1] + 1] - x[2 * t[0] + 1]));
    for (int a = 0; a < 3; ++a) f[2 * t[a] + 1] += rho * area / 3 * g;
  }
  return f;
}
}  // namespace

// The predictor (newmark.cpp, Solver::predict) is the trapezoidal step with the start's forces:
// for a free body under gravity, a rigid translation with F - Q constant, it is the step itself,
// so Newton's first residual meets the tolerance and no solve is made; starting at x^n, every
// step solves. Either way the fall is the exact y = -g t^2 / 2 (trapezoidal rule, constant a).
TEST_CASE("the predictor takes a free fall as the step: no Newton solve", "[newton]") {
  for (Predictor predictor : {Predictor::none, Predictor::acceleration}) {
    Model model = free_block(predictor);
    model.settings.gravity = {0, -10};
    Solver s(model);
    const double dt = 1e-3;
    const int steps = 20;
    long solves = 0;
    for (int k = 0; k < steps; ++k) solves += s.advance(dt).iterations;
    const double t = steps * dt;
    const std::vector<double> u = s.displacements(0);
    double worst = 0;
    for (std::size_t d = 0; d < u.size(); ++d)
      worst = std::max(worst, std::abs(u[d] - (d % 2 ? -5.0 * t * t : 0.0)));
    INFO("predictor " << (predictor == Predictor::acceleration ? "acceleration" : "none")
                      << ", Newton solves " << solves << ", largest error " << worst);
    CHECK(worst <= 1e-12);
    if (predictor == Predictor::acceleration)
      CHECK(solves == 0);
    else
      CHECK(solves >= steps);
  }
}

// The coupling force in the predictor: a free body without gravity pushed by F_c = M g' (the
// consistent mass's row sums times a uniform g') falls as under gravity g' (the force acts
// over each step, entering the residual twice): with the predictor no solve, y = g' t^2 / 2.
TEST_CASE("the predictor takes the coupling force's step: no Newton solve", "[newton]") {
  Solver s(free_block(Predictor::acceleration));
  const Mesh& mesh = s.mesh(0);
  const double g = -3.0;
  const std::vector<std::vector<double>> f{uniform_push(mesh, neo().density, g)};
  const double dt = 1e-3;
  const int steps = 20;
  long solves = 0;
  for (int k = 0; k < steps; ++k) solves += s.advance(dt, &f).iterations;
  const double t = steps * dt;
  const std::vector<double> u = s.displacements(0);
  double worst = 0;
  for (std::size_t d = 0; d < u.size(); ++d)
    worst = std::max(worst, std::abs(u[d] - (d % 2 ? 0.5 * g * t * t : 0.0)));
  INFO("Newton solves " << solves << ", largest error " << worst);
  CHECK(worst <= 1e-12);
  CHECK(solves == 0);
}

// Newmark's damped members keep a uniform acceleration exact (Eq. 13-14 integrate a constant a
// exactly for any beta, gamma): a free body under gravity g and pushed by a coupling force
// F_c = M g' (an impulse over each step) moves as y = (g + g') t^2 / 2, v = (g + g') t, which
// needs the residual's weights of (M a)^n and F_c and the velocity update's M^-1 terms.
TEST_CASE("Newmark with gamma > 1/2 keeps a uniform acceleration exact", "[newton]") {
  for (const double gamma : {0.6, 0.9}) {
    Model model = free_block(Predictor::none);
    model.settings.gravity = {0, -10};
    model.settings.newmark_gamma = gamma;
    model.settings.newmark_beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
    model.settings.newton_tolerance = 1e-13;
    Solver s(model);
    const Mesh& mesh = s.mesh(0);
    const double g = -3.0;
    const std::vector<std::vector<double>> f{uniform_push(mesh, neo().density, g)};
    const double dt = 1e-3;
    const int steps = 20;
    for (int k = 0; k < steps; ++k) s.advance(dt, &f);
    const double t = steps * dt, a = -10 + g;
    const std::vector<double> u = s.displacements(0), v = s.velocities(0);
    double worst_u = 0, worst_v = 0;
    for (std::size_t d = 0; d < u.size(); ++d) {
      worst_u = std::max(worst_u, std::abs(u[d] - (d % 2 ? 0.5 * a * t * t : 0.0)));
      worst_v = std::max(worst_v, std::abs(v[d] - (d % 2 ? a * t : 0.0)));
    }
    INFO("gamma " << gamma << ": largest error in u " << worst_u << ", in v " << worst_v);
    CHECK(worst_u <= 1e-12);
    CHECK(worst_v <= 1e-10);
  }
}

TEST_CASE("a body with rho_s = rho_f has no FE mass and still solves quasi-statically", "[mass]") {
  Model model;
  model.settings.fluid_density = 2.0;  // equal to the solid density
  model.settings.gravity = {0, -9.81};
  BodySpec b;
  b.name = "neutral";
  b.mesh = rectangle_mesh(0, 0, 2, 0.2, 10, 2, Diagonals::criss_cross);
  b.materials = {svk()};
  b.constraints = {fix("left", true, true)};
  Load l;
  l.boundary = "right";
  l.value = {0, -0.5};
  b.loads = {l};
  model.bodies.push_back(b);
  Solver s(model);
  s.advance(1e-3);
  const auto u1 = s.displacements(0);
  s.advance(1e-3);
  const auto u2 = s.displacements(0);
  CHECK(s.kinetic_energy() == 0);
  // No inertia: both steps are the static equilibrium under the traction (gravity has zero
  // excess weight), so they agree and the velocity is zero after the first step.
  double diff = 0, mag = 0;
  for (std::size_t d = 0; d < u1.size(); ++d) {
    diff = std::max(diff, std::abs(u2[d] - u1[d]));
    mag = std::max(mag, std::abs(u1[d]));
  }
  CHECK(mag > 1e-4);
  CHECK(diff <= 1e-10 * mag);
  for (double vv : s.velocities(0)) CHECK(std::abs(vv) <= 1e-6 * mag);

  Model st = model;
  st.settings.analysis = Analysis::statics;
  Solver ss(st);
  ss.solve_static();
  const auto us = ss.displacements(0);
  for (std::size_t d = 0; d < u1.size(); ++d) CHECK(u1[d] == Approx(us[d]).margin(1e-10 * mag));
}

TEST_CASE("gravity uses the excess density and the supports carry the weight", "[loads]") {
  Model model;
  model.settings.analysis = Analysis::statics;
  model.settings.gravity = {0, -2};
  model.settings.fluid_density = 0.5;
  BodySpec b;
  b.name = "block";
  b.mesh = rectangle_mesh(0, 0, 1, 0.5, 4, 2, Diagonals::right);
  b.materials = {svk()};
  b.constraints = {fix("bottom", true, true)};
  model.bodies.push_back(b);
  Solver s(model);
  s.solve_static();
  const double weight = (2.0 - 0.5) * 0.5 * 2;
  const Vec2 r = s.reaction(0, "bottom");
  CHECK(r[1] == Approx(weight).epsilon(1e-10));
  CHECK(r[0] == Approx(0).margin(1e-10));
}

TEST_CASE("periodic pairs: a strip sheared with periodic ends stays uniform", "[periodic]") {
  Model model;
  model.settings.analysis = Analysis::statics;
  model.settings.newton_tolerance = 1e-14;
  BodySpec b;
  b.name = "layer";
  b.mesh = rectangle_mesh(0, 0, 3, 1, 9, 4, Diagonals::criss_cross);
  b.materials = {neo()};
  Constraint top = fix("top", true, true);
  top.type = Constraint::Type::displacement;
  top.displacement = {0.3, 0};
  Constraint per;
  per.type = Constraint::Type::periodic;
  per.boundary = "right";
  per.partner = "left";
  b.constraints = {fix("bottom", true, true), top, per};
  model.bodies.push_back(b);
  Solver s(model);
  s.solve_static();
  // Simple shear of a neo-Hookean layer: u_x = 0.3 y exactly; u_y = 0 by symmetry of the
  // periodic strip.
  const auto u = s.displacements(0);
  double err = 0;
  for (int n = 0; n < s.mesh(0).num_nodes(); ++n) {
    err = std::max(err, std::abs(u[2 * n] - 0.3 * s.mesh(0).x[2 * n + 1]));
    err = std::max(err, std::abs(u[2 * n + 1]));
  }
  CHECK(err <= 1e-12);
}

TEST_CASE("a periodic massless layer starting from rest converges under a force of 1e-14",
          "[periodic][newton]") {
  // The first step of a coupled run from rest: the fluid's force on the layer is ~1e-14, so the
  // Newton tolerance (relative to it) is ~1e-24. The residual must reach it, on the free dofs,
  // the periodic pairs and the top row alike.
  Model model;
  model.settings.fluid_density = 1.0;  // rho_s = rho_f: no FE mass
  BodySpec b;
  b.name = "layer";
  b.mesh = rectangle_mesh(0, 0, 0.25, 0.5, 4, 16, Diagonals::criss_cross);
  b.materials = {Material{}};
  b.materials[0].model = MaterialModel::neo_hookean;
  b.materials[0].mu = 5;
  b.materials[0].bulk = 500;
  b.materials[0].density = 1;
  Constraint per;
  per.type = Constraint::Type::periodic;
  per.boundary = "left";
  per.partner = "right";
  b.constraints = {fix("bottom", true, true), per};
  model.bodies.push_back(b);
  Solver s(model);
  const Mesh& m = s.mesh(0);
  for (double level : {1e-14, 1e-8, 1e-3}) {
    INFO("force level " << level);
    // A shear force on the top row, growing towards the top, as the fluid's drag.
    std::vector<std::vector<double>> f(1, std::vector<double>(2 * m.num_nodes(), 0.0));
    for (int n = 0; n < m.num_nodes(); ++n) f[0][2 * n] = level * m.x[2 * n + 1] * m.x[2 * n + 1];
    const StepReport r = s.advance(5e-4, &f);
    CHECK(r.converged);
    CHECK(r.iterations <= 4);
    CHECK(r.residuals.back() <= r.tolerance);
  }
}

TEST_CASE("a static body without supports is rejected", "[input]") {
  Model model;
  model.settings.analysis = Analysis::statics;
  BodySpec b;
  b.name = "loose";
  b.mesh = rectangle_mesh(0, 0, 1, 1, 2, 2, Diagonals::criss_cross);
  b.materials = {svk()};
  b.constraints = {fix("left", true, false)};
  model.bodies.push_back(b);
  CHECK_THROWS_WITH(Solver(model),
                    Catch::Contains("body 'loose' has no constraint that holds it in y") &&
                        Catch::Contains("static solve is singular"));
}
