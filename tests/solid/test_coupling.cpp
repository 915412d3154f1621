// The coupling hook: geometry, surface points and normals, point force + moment as nodal forces
// (resultant and moment exact), advance with external nodal forces.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "coupling.hpp"

using namespace solid;

namespace {

Model bar(double fluid_density) {
  Model model;
  model.settings.fluid_density = fluid_density;
  model.settings.newton_tolerance = 1e-12;
  BodySpec b;
  b.name = "bar";
  b.mesh = rectangle_mesh(0, 0, 1, 0.1, 20, 2, Diagonals::criss_cross);
  b.materials = {Material::from_young(MaterialModel::saint_venant_kirchhoff, 1e5, 0.3, 1)};
  Constraint c;
  c.boundary = "left";
  b.constraints = {c};
  BodySpec wall;
  wall.name = "wall";
  wall.kind = BodyKind::rigid;
  wall.mesh = rectangle_mesh(-0.2, -0.5, 0.2, 1.1, 1, 2, Diagonals::right);
  model.bodies = {b, wall};
  return model;
}

}  // namespace

TEST_CASE("a point force and moment become nodal forces with the same resultant and moment",
          "[coupling]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 50; ++k) {
    const Vec2 a{u(rng), u(rng)}, b{u(rng) + 2, u(rng)};
    const double s = 0.5 * (u(rng) + 1);
    const Vec2 F{u(rng), u(rng)};
    const double M = u(rng);
    const auto f = point_load_on_edge(a, b, s, F, M);
    const Vec2 p{(1 - s) * a[0] + s * b[0], (1 - s) * a[1] + s * b[1]};
    CHECK(f[0][0] + f[1][0] == Approx(F[0]).margin(1e-14));
    CHECK(f[0][1] + f[1][1] == Approx(F[1]).margin(1e-14));
    const double moment = (a[0] - p[0]) * f[0][1] - (a[1] - p[1]) * f[0][0] +
                          (b[0] - p[0]) * f[1][1] - (b[1] - p[1]) * f[1][0];
    CHECK(moment == Approx(M).margin(1e-13));
  }
}

TEST_CASE("geometry, surface points and outward normals", "[coupling]") {
  Solver s(bar(0));
  CouplingHook hook(s);
  REQUIRE(hook.num_bodies() == 2);
  const BodyGeometry g = hook.geometry(0);
  CHECK(g.name == "bar");
  CHECK(g.kind == BodyKind::elastic);
  CHECK(g.x_ref.size() == 2 * 63);
  CHECK(g.triangles.size() == 80);
  CHECK(g.surface.size() == 44);
  CHECK(hook.geometry(1).kind == BodyKind::rigid);
  CHECK_FALSE(hook.geometry(1).moving);
  // Every surface edge's normal points away from the bar's centre line region.
  for (int e = 0; e < static_cast<int>(g.surface.size()); ++e) {
    const SurfacePoint p = hook.surface_point(0, e, 0.5);
    const double cx = std::clamp(p.position[0], 0.05, 0.95), cy = 0.05;
    CHECK((p.position[0] - cx) * p.normal[0] + (p.position[1] - cy) * p.normal[1] > 0);
    CHECK(std::hypot(p.normal[0], p.normal[1]) == Approx(1));
  }
  CHECK_THROWS_WITH(hook.surface_point(0, 44, 0.5), Catch::Contains("44 surface edges"));
}

TEST_CASE("advance with coupling forces; a body with rho_s = rho_f follows them quasi-statically",
          "[coupling]") {
  // Tip force and moment through the hook on a massless (rho_s = rho_f) bar, against the same
  // force and moment as a static load.
  Solver s(bar(1.0));
  CouplingHook hook(s);
  int tip_edge = -1;
  const Mesh& m = s.mesh(0);
  for (int e = 0; e < static_cast<int>(m.surface.size()); ++e) {
    const auto& ed = m.surface[e];
    if (m.x[2 * ed[0]] == 1 && m.x[2 * ed[1]] == 1 &&
        std::min(m.x[2 * ed[0] + 1], m.x[2 * ed[1] + 1]) == 0)
      tip_edge = e;
  }
  REQUIRE(tip_edge >= 0);
  std::vector<std::vector<double>> forces(2);
  hook.add_point_load(0, tip_edge, 0.3, {0, -2}, 0.0, forces[0]);
  hook.advance(1e-3, forces);
  const double uy_force = hook.positions(0)[2 * 62 + 1] - 0.1;  // top right corner
  CHECK(uy_force < -1e-4);
  // The same total force as a uniform traction on the tip edge gives nearly the same deflection
  // (the point of application differs by less than the edge).
  Model st = bar(1.0);
  st.settings.analysis = Analysis::statics;
  Load l;
  l.boundary = "right";
  l.value = {0, -2 / 0.1};
  st.bodies[0].loads = {l};
  Solver ss(st);
  ss.solve_static();
  CHECK(uy_force == Approx(ss.displacements(0)[2 * 62 + 1]).epsilon(0.02));
  // A counter-clockwise moment alone lifts the tip.
  Solver s2(bar(1.0));
  CouplingHook h2(s2);
  std::vector<std::vector<double>> f2(2);
  h2.add_point_load(0, tip_edge, 0.5, {0, 0}, 0.05, f2[0]);
  h2.advance(1e-3, f2);
  CHECK(h2.positions(0)[2 * 62 + 1] - 0.1 > 1e-5);
}

TEST_CASE("a rigid body follows its prescribed motion and carries no equations",
          "[coupling][rigid]") {
  Model model = bar(0);
  RigidMotion& m = model.bodies[1].motion;
  m.center = {-0.1, 0.05};
  m.velocity = {0.2, 0};
  m.omega = 0.5;
  Solver s(model);
  CouplingHook hook(s);
  CHECK(hook.geometry(1).moving);
  const int neq = s.num_equations();
  std::vector<std::vector<double>> forces(2);
  for (int k = 0; k < 4; ++k) hook.advance(0.25, forces);
  CHECK(s.num_equations() == neq);
  // After t = 1: rotated by 0.5 rad about the centre, which moved by (0.2, 0).
  const auto& X = s.mesh(1).x;
  const auto& x = hook.positions(1);
  const auto& v = hook.velocities(1);
  const double c = std::cos(0.5), sn = std::sin(0.5);
  for (int n = 0; n < s.mesh(1).num_nodes(); ++n) {
    const double rx = X[2 * n] + 0.1, ry = X[2 * n + 1] - 0.05;
    CHECK(x[2 * n] == Approx(-0.1 + 0.2 + c * rx - sn * ry).margin(1e-14));
    CHECK(x[2 * n + 1] == Approx(0.05 + sn * rx + c * ry).margin(1e-14));
    // v = velocity + omega x (x - c)
    CHECK(v[2 * n] == Approx(0.2 - 0.5 * (sn * rx + c * ry)).margin(1e-14));
    CHECK(v[2 * n + 1] == Approx(0.5 * (c * rx - sn * ry)).margin(1e-14));
  }
}

TEST_CASE("coupled iterations: the linearised reaction vanishes at convergence and holds a free "
          "body without excess mass",
          "[coupling]") {
  // (a) A held bar with mass (rho_s = 2 rho_f) under a tip load: the explicit step gives v1;
  // redone from the same state with w = v1 the term -M_f (v - w)/dt is zero at v = v1, so the
  // step must return v1 again (to Newton's tolerance), and with another w a different v.
  Solver s(bar(0.5));
  std::vector<std::vector<double>> f(2);
  f[0].assign(s.positions(0).size(), 0.0);
  f[0][2 * 62 + 1] = -0.05;
  StepState start;
  s.save_state(start);
  s.advance(1e-3, &f);
  const std::vector<double> v1 = s.velocities(0);
  double vmax = 0;
  for (double x : v1) vmax = std::max(vmax, std::abs(x));
  REQUIRE(vmax > 1e-6);
  s.restore_state(start);
  std::vector<std::vector<double>> w(2);
  w[0] = v1;
  s.advance(1e-3, &f, &w);
  double diff = 0;
  for (std::size_t d = 0; d < v1.size(); ++d) diff = std::max(diff, std::abs(s.velocities(0)[d] - v1[d]));
  CHECK(diff <= 1e-9 * vmax);
  s.restore_state(start);
  w[0].assign(v1.size(), 0.0);  // the forcing used a bar at rest: the linearisation pulls v back
  s.advance(1e-3, &f, &w);
  double pulled = 0;
  for (std::size_t d = 0; d < v1.size(); ++d) pulled = std::max(pulled, std::abs(s.velocities(0)[d] - v1[d]));
  CHECK(pulled > 1e-3 * vmax);

  // (b) A free square with rho_s = rho_f (no mass, no support): its matrix is singular in the
  // explicit step; with the linearisation about a rigid translation w and no load, the step is
  // that translation exactly (v = w, no strain).
  Model free_model;
  free_model.settings.fluid_density = 1.0;
  free_model.settings.newton_tolerance = 1e-12;
  BodySpec sq;
  sq.name = "square";
  sq.mesh = rectangle_mesh(0, 0, 0.2, 0.2, 4, 4, Diagonals::criss_cross);
  sq.materials = {Material::from_young(MaterialModel::neo_hookean, 1e3, 0.3, 1.0)};
  free_model.bodies = {sq};
  {
    Solver singular(free_model);  // pushed without the linearisation: nothing holds it
    std::vector<std::vector<double>> push(1, std::vector<double>(singular.positions(0).size(), 0.01));
    CHECK_THROWS_WITH(singular.advance(1e-3, &push), Catch::Contains("singular"));
  }
  Solver fs(free_model);
  const std::size_t n = fs.positions(0).size();
  std::vector<std::vector<double>> wf(1, std::vector<double>(n));
  for (std::size_t d = 0; d < n; ++d) wf[0][d] = d % 2 == 0 ? 0.3 : -0.1;
  const std::vector<double> x0 = fs.positions(0);
  fs.advance(1e-3, nullptr, &wf);
  for (std::size_t d = 0; d < n; ++d) {
    CHECK(fs.velocities(0)[d] == Approx(wf[0][d]).margin(1e-12));
    CHECK(fs.positions(0)[d] - x0[d] == Approx(1e-3 * wf[0][d]).margin(1e-15));
  }

  // (c) The same free square, w = 0, under the nodal forces of a uniform body force g on the
  // fluid's mass (F_a = rho_f g int N_a): the linearised reaction -M_f v / dt balances it by a
  // rigid translation with v = g dt exactly (the sign of the term decides the direction).
  Solver gs(free_model);
  const Mesh& gm = gs.mesh(0);
  const double g[2] = {2.0, -3.0}, dt = 1e-3;
  std::vector<std::vector<double>> fg(1, std::vector<double>(n, 0.0));
  for (const auto& t : gm.triangles) {
    const double* a = &gm.x[2 * t[0]];
    const double* b = &gm.x[2 * t[1]];
    const double* c = &gm.x[2 * t[2]];
    const double area = 0.5 * std::abs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 2; ++i) fg[0][2 * t[k] + i] += free_model.settings.fluid_density * g[i] * area / 3;
  }
  std::vector<std::vector<double>> w0(1, std::vector<double>(n, 0.0));
  gs.advance(dt, &fg, &w0);
  for (std::size_t d = 0; d < n; ++d)
    CHECK(gs.velocities(0)[d] == Approx(g[d % 2] * dt).margin(1e-12));
}

// Work ahead of the forces: factorising the next step's first Newton matrix beforehand
// (factorize_ahead) leaves every step bit for bit as it was, and each step reuses that factor
// (with keep_factor, a step that keeps the last factor skips the look-ahead: still the same bits);
// also with a prescribed displacement moving the right end (its increment enters the residual).
// With the predictor a step without a look-ahead factorises the matrix at its start itself
// (newmark.cpp, predict): the same bits and the same reuses, except with a prescribed increment,
// where it does not predict.
TEST_CASE("factorising ahead: same steps, factor reused", "[coupling]") {
  for (Predictor predictor : {Predictor::none, Predictor::acceleration})
  for (bool prescribed : {false, true}) {
    Model m = bar(0);
    m.settings.predictor = predictor;
    if (prescribed) {
      Constraint c;
      c.type = Constraint::Type::displacement;
      c.boundary = "right";
      c.x = false;
      c.displacement = {0, 0.02};
      c.time.kind = TimeFunction::Kind::sine;
      c.time.frequency = 2;
      m.bodies[0].constraints.push_back(c);
    }
    for (bool keep : {false, true}) {
      m.settings.keep_factor = keep;
      Solver a(m), b(m);
      const double dt = 2e-3;
      const int steps = 12;
      std::vector<std::vector<double>> f(2);
      f[0].assign(a.positions(0).size(), 0.0);
      for (int n = 0; n < steps; ++n) {
        f[0][f[0].size() - 1] = 5.0 * std::sin(0.7 * n);  // a varying load on the last node
        a.advance(dt, &f);
        b.factorize_ahead(dt);
        b.advance(dt, &f);
      }
      CHECK(a.positions(0) == b.positions(0));
      CHECK(a.velocities(0) == b.velocities(0));
      const long ahead_gain = predictor == Predictor::acceleration && !prescribed ? 0 : steps;
      if (!keep || prescribed) CHECK(b.factor_reuses() - a.factor_reuses() == ahead_gain);
      double moved = 0;  // the comparison is of a bar that moves
      for (std::size_t d = 0; d < a.displacements(0).size(); ++d)
        moved = std::max(moved, std::abs(a.displacements(0)[d]));
      CHECK(moved > 1e-4);
    }
  }
}

// A contact plane within reach of the bar's lower edge but never touched: its slots are open
// candidates of every iteration, not constraints, and cost no factorisation. The steps solve with
// the look-ahead's factor (iteration 0, the residual assembled alone) and keep it while Newton
// contracts (modified Newton), as the bar without the plane does: the same factorisations, the
// same motion bit for bit. (Before, any contact slot made every later iteration factorise.)
TEST_CASE("open contact candidates keep the look-ahead's factor", "[coupling][contact]") {
  Model free = bar(0), near = bar(0);
  ContactPlane plane;
  plane.point = {0, -0.03};  // within one element edge (0.05) of the lower edge
  plane.normal = {0, 1};
  plane.bodies = {0};
  near.planes = {plane};
  free.settings.keep_factor = near.settings.keep_factor = false;  // no factor kept across steps
  Solver a(free), b(near);
  const double dt = 1e-4;  // inertia dominates: later iterations keep the factor
  const int steps = 40;
  std::vector<std::vector<double>> f(2);
  f[0].assign(a.positions(0).size(), 0.0);
  long iterations = 0;
  for (int n = 0; n < steps; ++n) {
    f[0][f[0].size() - 1] = 50.0 * std::sin(0.2 * n);  // a varying load on the last node
    a.factorize_ahead(dt);
    a.advance(dt, &f);
    b.factorize_ahead(dt);
    iterations += b.advance(dt, &f).iterations;
    REQUIRE(b.min_contact_gap() > 0.02);
    REQUIRE(b.min_contact_gap() < 0.05);  // within reach: the slots are open candidates
  }
  INFO(a.factorizations() << " and " << b.factorizations() << " factorisations, "
                          << a.factor_reuses() << " and " << b.factor_reuses() << " reuses, "
                          << iterations << " Newton iterations in " << steps << " steps");
  CHECK(iterations >= 2 * steps);
  CHECK(b.factorizations() == a.factorizations());
  CHECK(b.factor_reuses() == a.factor_reuses());
  CHECK(b.factor_reuses() >= 2 * steps);  // iteration 0 and a later one
  CHECK(a.displacements(0) == b.displacements(0));
  double moved = 0;
  for (double u : a.displacements(0)) moved = std::max(moved, std::abs(u));
  CHECK(moved > 1e-6);
}

// Two neo-Hookean blocks held at their outer ends, touching at t = 0 on meshes that do not match
// (8 and 7 cells across), a two-way contact pair between them; no factor kept across steps.
namespace {
Model pressed_blocks(double newton_tolerance) {
  Model model;
  model.settings.newton_tolerance = newton_tolerance;
  model.settings.keep_factor = false;
  for (int k = 0; k < 2; ++k) {
    BodySpec b;
    b.name = k == 0 ? "lower" : "upper";
    b.mesh = rectangle_mesh(0, 0.5 * k, 0.4, 0.5, 8 - k, 10, Diagonals::right);
    b.materials = {Material::from_young(MaterialModel::neo_hookean, 1e5, 0.3, 1000)};
    Constraint c;
    c.boundary = k == 0 ? "bottom" : "top";
    b.constraints = {c};
    model.bodies.push_back(b);
  }
  ContactPair p;
  p.slave = 0;
  p.master = 1;
  p.two_way = true;
  model.contacts = {p};
  return model;
}
}  // namespace

// Two blocks held at their outer ends, touching at t = 0 on meshes that do not match (8 and 7
// cells across: slave nodes on master edges, whose curvature enters the matrix), pressed
// together by a varying load, then pulled apart. The look-ahead adds the curvature of the slots
// the last step left active: iteration 0's matrix when detection at x^n keeps them, found
// factorised then (a reuse instead of a factorisation). The motion, through the release too, is
// the same bit for bit as without the look-ahead. (The other branch, iteration 0's matrix
// differing from the look-ahead's, is not reached here: detection at x^n keeps the slots the
// last step's converged iteration left active.)
TEST_CASE("in lasting contact the look-ahead factorises iteration 0's matrix", "[coupling][contact]") {
  const Model model = pressed_blocks(1e-10);
  Solver a(model), b(model);
  const double dt = 2e-4;
  const int pressed = 200, steps = 300;
  std::vector<std::vector<double>> f(2);
  f[0].assign(a.positions(0).size(), 0.0);
  f[1].assign(a.positions(1).size(), 0.0);
  int start_in_contact = 0, pressed_in_contact = 0, apart_at_end = 0;
  int active = 0;  // slots active at the last step's converged iterate: this step's start
  long reuses_pressed = 0;
  for (int n = 0; n < steps; ++n) {
    // The upper block pushed down, harder and softer, with a sideways part; then pulled up.
    for (std::size_t d = 0; d < f[1].size(); d += 2) {
      f[1][d] = 20.0 * std::sin(0.05 * n);
      f[1][d + 1] = n < pressed ? -200.0 * (1.5 + std::sin(0.1 * n)) : 2000.0;
    }
    const bool in_contact = active > 0;
    const long reuses = b.factor_reuses() - a.factor_reuses();
    a.advance(dt, &f);
    b.factorize_ahead(dt);
    active = b.advance(dt, &f).active_contacts;
    if (n < pressed) {
      start_in_contact += in_contact;
      pressed_in_contact += active > 0;
      reuses_pressed += (b.factor_reuses() - a.factor_reuses()) - reuses;
    } else {
      apart_at_end = active == 0;
    }
  }
  INFO(start_in_contact << " pressed steps start in contact; extra reuses " << reuses_pressed);
  CHECK(pressed_in_contact > pressed * 9 / 10);
  CHECK(apart_at_end);
  for (int k = 0; k < 2; ++k) {
    CHECK(a.positions(k) == b.positions(k));
    CHECK(a.velocities(k) == b.velocities(k));
  }
  // Nearly every step that starts in contact found iteration 0's matrix factorised ahead (each
  // step of b looks ahead; a step of a that starts in contact factorises at iteration 0).
  CHECK(reuses_pressed >= start_in_contact * 9 / 10);
  double moved = 0;
  for (double u : a.displacements(1)) moved = std::max(moved, std::abs(u));
  CHECK(moved > 1e-5);
}

// Modified Newton in contact (newton.cpp, kReuseRatio): the later iterations of a step in
// contact solve with an earlier factor while the residual falls fast, the contact conditions
// linearised afresh in each. Two blocks pressed together: the steps in contact take fewer
// factorisations than Newton iterations (every iteration in contact factorised before), and the
// motion converges to that of a run with a far tighter tolerance as the tolerance tightens.
TEST_CASE("a step in contact solves its later iterations with an earlier factor",
          "[coupling][contact]") {
  // Tolerances 1e-9, 1e-10, 1e-11 and the reference at 1e-13.
  const std::vector<double> tolerances{1e-9, 1e-10, 1e-11, 1e-13};
  std::vector<std::unique_ptr<Solver>> runs;
  for (double t : tolerances) runs.push_back(std::make_unique<Solver>(pressed_blocks(t)));
  const double dt = 2e-4;
  const int steps = 200;
  std::vector<std::vector<double>> f(2);
  f[0].assign(runs[0]->positions(0).size(), 0.0);
  f[1].assign(runs[0]->positions(1).size(), 0.0);
  long contact_iterations = 0, contact_factorisations = 0;
  int contact_steps = 0;
  for (int n = 0; n < steps; ++n) {
    for (std::size_t d = 0; d < f[1].size(); d += 2) {
      f[1][d] = 20.0 * std::sin(0.05 * n);
      f[1][d + 1] = -200.0 * (1.5 + std::sin(0.1 * n));
    }
    for (std::size_t k = 0; k < runs.size(); ++k) {
      Solver& s = *runs[k];
      const long before = s.factorizations();
      s.factorize_ahead(dt);
      const long ahead = s.factorizations() - before;
      const StepReport r = s.advance(dt, &f);
      if (k == 1 && r.active_contacts > 0) {
        ++contact_steps;
        contact_iterations += r.iterations;
        contact_factorisations += s.factorizations() - before - ahead;
      }
    }
  }
  INFO(contact_steps << " steps in contact: " << contact_iterations << " Newton iterations, "
                     << contact_factorisations << " factorisations in the steps");
  CHECK(contact_steps > steps * 9 / 10);
  CHECK(contact_iterations > contact_steps);
  CHECK(contact_factorisations < contact_iterations / 2);
  double moved = 0;
  std::vector<double> diff(3, 0.0);
  for (int b = 0; b < 2; ++b)
    for (std::size_t d = 0; d < runs[3]->displacements(b).size(); ++d) {
      const double ref = runs[3]->displacements(b)[d];
      moved = std::max(moved, std::abs(ref));
      for (int k = 0; k < 3; ++k)
        diff[k] = std::max(diff[k], std::abs(runs[k]->displacements(b)[d] - ref));
    }
  INFO("moved " << moved << ", difference from the reference at 1e-9, 1e-10, 1e-11: " << diff[0]
                << ", " << diff[1] << ", " << diff[2]);
  CHECK(moved > 1e-5);
  // The error follows the tolerance (1e-4 of the motion at 1e-10, as with a fresh factor in every
  // iteration: 8.1e-6 against 1e-12 on this case before modified Newton in contact).
  CHECK(diff[1] < 2e-4 * moved);
  CHECK(diff[2] < 0.5 * diff[0]);
  CHECK(diff[2] < 0.5 * diff[1]);
}

// A factor kept across steps (keep_factor, newton.cpp's kKeepRatio) on a body whose inertia
// dominates its stiffness: far fewer factorisations than steps, the same motion as a fresh
// factor every step to the Newton tolerance; and a checkpoint's kept factor (kept_factor,
// restore_kept_factor) continues the run bit for bit.
TEST_CASE("a factor kept across steps: fewer factorisations, the same motion", "[coupling]") {
  Model m = bar(0);
  m.settings.newton_tolerance = 1e-12;
  const double dt = 1e-5;
  const int steps = 400;
  auto load = [](int n, std::vector<std::vector<double>>& f) {
    f[0][f[0].size() - 1] = 20.0 * std::sin(0.05 * n);  // a load on the last node
  };
  m.settings.keep_factor = false;
  Solver fresh(m);
  m.settings.keep_factor = true;
  Solver kept(m), first_half(m);
  std::vector<std::vector<double>> f(2);
  f[0].assign(fresh.positions(0).size(), 0.0);
  for (int n = 0; n < steps; ++n) {
    load(n, f);
    fresh.factorize_ahead(dt);
    fresh.advance(dt, &f);
    kept.factorize_ahead(dt);
    kept.advance(dt, &f);
    if (n < steps / 2) {
      first_half.factorize_ahead(dt);
      first_half.advance(dt, &f);
    }
  }
  INFO("factorisations " << fresh.factorizations() << " fresh, " << kept.factorizations() << " kept");
  CHECK(fresh.factorizations() > steps / 2);
  CHECK(kept.factorizations() < steps / 10);
  double moved = 0, diff = 0;
  for (std::size_t d = 0; d < fresh.displacements(0).size(); ++d) {
    moved = std::max(moved, std::abs(fresh.displacements(0)[d]));
    diff = std::max(diff, std::abs(fresh.displacements(0)[d] - kept.displacements(0)[d]));
  }
  INFO("moved " << moved << ", difference " << diff);
  CHECK(moved > 1e-3);
  CHECK(diff <= 1e-10 * moved);
  // Resume the second half from the first half's state and kept factor, in a new solver.
  StepState s;
  first_half.save_state(s);
  const KeptFactor factor = first_half.kept_factor();
  CHECK_FALSE(factor.values.empty());
  Solver resumed(m);
  resumed.restore_state(s);
  resumed.restore_kept_factor(factor);
  for (int n = steps / 2; n < steps; ++n) {
    load(n, f);
    resumed.factorize_ahead(dt);
    resumed.advance(dt, &f);
  }
  CHECK(resumed.positions(0) == kept.positions(0));
  CHECK(resumed.velocities(0) == kept.velocities(0));
}
