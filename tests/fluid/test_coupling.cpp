// The coupling hook: face indexing, immersed-solid forcing f_s and its return, fiber forces,
// samples of the new velocity.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "diagnostics.hpp"
#include "program.hpp"
#include "solver.hpp"

using namespace fluid;

namespace {
Config box(BcType xb) {
  Config c;
  c.density = 2;
  c.viscosity = 0.02;
  c.x = {16, 1.0, 0.0};
  c.y = {8, 0.5, 0.0};
  c.bc[left].type = c.bc[right].type = xb;
  c.bc[bottom].type = c.bc[top].type = BcType::wall;
  return c;
}

// The immersed input: faces, volume fractions and solid velocities of the u and v families (the
// vectors must outlive the spans of the result).
CouplingIn solid_input(const std::vector<std::int32_t>& iu, const std::vector<double>& au,
                       const std::vector<double>& uu, const std::vector<std::int32_t>& iv,
                       const std::vector<double>& av, const std::vector<double>& vv) {
  CouplingIn in;
  in.solid_u_index = iu;
  in.solid_u_alpha = au;
  in.solid_u_velocity = uu;
  in.solid_v_index = iv;
  in.solid_v_alpha = av;
  in.solid_v_velocity = vv;
  return in;
}

// An immersed input of u faces only, built face by face (`in` spans the vectors).
struct UFaceInput {
  std::vector<std::int32_t> index;
  std::vector<double> alpha, velocity;
  CouplingIn in;
  UFaceInput() = default;
  UFaceInput(const UFaceInput&) = delete;  // the spans point into this object
  UFaceInput& operator=(const UFaceInput&) = delete;
  void add(std::int32_t face, double a, double w) {
    index.push_back(face), alpha.push_back(a), velocity.push_back(w);
    in.solid_u_index = index;  // the vectors may have moved
    in.solid_u_alpha = alpha;
    in.solid_u_velocity = velocity;
  }
};

// Faces (4..7, 3) of a solid block moving at 0.3 with alpha 0.6: the immersed input of the
// bit-identity tests below.
struct BlockInput : UFaceInput {
  explicit BlockInput(const Solver& s) {
    for (int i = 4; i < 8; ++i) add(i + s.grid().nu() * 3, 0.6, 0.3);
  }
};

// The diffusion options: explicit AB2, Crank-Nicolson with the forcing in its increment (the
// default) or after its solve.
enum Diffusion { explicit_ab2, crank_nicolson, crank_nicolson_after_solve };
constexpr Diffusion kDiffusions[] = {explicit_ab2, crank_nicolson, crank_nicolson_after_solve};
Config with(Config c, Diffusion d) {
  c.implicit = d != explicit_ab2;
  c.forcing_in_increment = d != crank_nicolson_after_solve;
  return c;
}

// Two solvers' fields and forcing are the same bit for bit.
void check_same(const Solver& a, const Solver& b, const CouplingOut& oa, const CouplingOut& ob) {
  CHECK(a.u().a == b.u().a);
  CHECK(a.v().a == b.v().a);
  CHECK(a.p().a == b.p().a);
  CHECK(oa.solid_u_force == ob.solid_u_force);
  CHECK(*std::max_element(a.u().a.begin(), a.u().a.end()) > 0.01);  // the solid moved the fluid
}
}  // namespace

TEST_CASE("immersed-solid forcing returns f_s and drives the faces to the solid velocity",
          "[fluid][coupling]") {
  for (Diffusion d : kDiffusions)
  for (BcType xb : {BcType::periodic, BcType::wall}) {
    CAPTURE(d, xb);
    const Config c = with(box(xb), d);
    const bool implicit = c.implicit;
    const double dt = 1e-3;
    Solver s(c, dt);
    const Grid& g = s.grid();
    const int nu = g.nu();
    CHECK(nu == (xb == BcType::periodic ? 16 : 17));
    CHECK(g.nv() == 9);
    // A block of faces fully inside a solid moving with (0.3, 0): alpha = 1.
    std::vector<std::int32_t> iu, iv;
    std::vector<double> au, uu, av, vv;
    for (int j = 2; j < 6; ++j)
      for (int i = 5; i < 9; ++i) {
        iu.push_back(i + nu * j);
        au.push_back(1.0);
        uu.push_back(0.3);
        iv.push_back(i + g.nx() * j);
        av.push_back(1.0);
        vv.push_back(0.0);
      }
    // A boundary face (non-periodic: i = 0) is ignored and returns 0.
    if (xb == BcType::wall) {
      iu.push_back(0 + nu * 3);
      au.push_back(1.0);
      uu.push_back(5.0);
    }
    CouplingIn in = solid_input(iu, au, uu, iv, av, vv);
    in.sample_u_index = iu;
    CouplingOut out;
    s.step(dt, in, out);
    REQUIRE(out.solid_u_force.size() == iu.size());
    REQUIRE(out.sample_u.size() == iu.size());
    // From rest, u~ = 0 on the first step: f_s = rho alpha u_s / dt, also with Crank-Nicolson in
    // increment form, which forces its explicit prediction (0) and then solves: the block's faces
    // keep the solve's values, below u_s by what the implicit diffusion carries out of the block
    // within the step.
    for (std::size_t q = 0; q < 16; ++q) CHECK(out.solid_u_force[q] == Approx(2 * 0.3 / dt));
    if (xb == BcType::wall) CHECK(out.solid_u_force.back() == 0.0);
    // The projection keeps the field divergence-free...
    CHECK(max_divergence(s).value < 1e-10);
    // ... and the samples are u^{n+1} at the requested faces.
    for (std::size_t q = 0; q < 16; ++q) {
      const int i = iu[q] % nu, j = iu[q] / nu;
      CHECK(out.sample_u[q] == s.u()(i, j));
      CHECK(out.sample_u[q] > 0.0);  // the solid drags the fluid it occupies forward
      if (implicit && c.forcing_in_increment) CHECK(out.sample_u[q] < 0.3);
    }
    // Total momentum injected equals the integral of f_s (periodic: closed in x; walls carry
    // no momentum through the projection for u in a periodic channel, and explicit diffusion
    // acts on the fluid at rest; the implicit one reaches the walls within the step).
    if (xb == BcType::periodic && !implicit) {
      double mom = 0, fint = 0;
      for (int j = 0; j < g.ny(); ++j)
        for (int i = 0; i < g.nx(); ++i) mom += s.u()(i, j) * g.x().h() * g.y().width(j);
      for (std::size_t q = 0; q < 16; ++q) {
        const int j = iu[q] / nu;
        fint += out.solid_u_force[q] * g.x().h() * g.y().width(j);
      }
      CHECK(c.density * mom == Approx(fint * dt).epsilon(1e-9));
    }
  }
}

TEST_CASE("fiber body force enters the predictor", "[fluid][coupling]") {
  Config c = box(BcType::periodic);
  const double dt = 1e-3;
  Solver s(c, dt);
  const int nu = s.grid().nu();
  std::vector<std::int32_t> idx{3 + nu * 4, 4 + nu * 4};
  std::vector<double> f{10.0, 10.0};
  CouplingIn in;
  in.fiber_u_index = idx;
  in.fiber_u_force = f;
  CouplingOut out;
  s.step(dt, in, out);
  // x-momentum gained = integral of f_f dt (periodic in x, the projection conserves it).
  double mom = 0;
  for (int j = 0; j < s.grid().ny(); ++j)
    for (int i = 0; i < s.grid().nx(); ++i) mom += s.u()(i, j) * s.grid().x().h() * s.grid().y().width(j);
  const double area = s.grid().x().h() * s.grid().y().width(4);
  CHECK(c.density * mom == Approx(2 * 10.0 * area * dt).epsilon(1e-9));
}

// Coupled iterations: a redo with the step's own input gives the step's fields bit for bit, a
// redo with another solid velocity changes them; a step taken without keeping its predictor
// refuses a redo.
TEST_CASE("redo of a step: same input, same fields; refused when not kept", "[fluid][coupling]") {
  for (Diffusion d : kDiffusions) {
  CAPTURE(d);
  const Config c = with(box(BcType::periodic), d);
  const double dt = 1e-3;
  Solver s(c, dt);
  const int nu = s.grid().nu();
  std::vector<std::int32_t> iu;
  std::vector<double> au, uu, uu2;
  // The first face covered, the others cut (Crank-Nicolson in increment form: a redo solves
  // again with the iteration's u_s).
  for (int i = 4; i < 8; ++i) iu.push_back(i + nu * 3), au.push_back(i == 4 ? 1.0 : 0.7),
                                  uu.push_back(0.2), uu2.push_back(0.5);
  CouplingIn in;
  in.solid_u_index = iu;
  in.solid_u_alpha = au;
  in.solid_u_velocity = uu;
  CouplingOut out, out2;
  s.step(dt, in, out);  // a first step, so the next has AB2 history
  s.step(dt, in, out);
  const Field u1 = s.u(), p1 = s.p();
  s.redo_step(dt, in, out2);
  CHECK(out2.solid_u_force == out.solid_u_force);
  CHECK(s.u().a == u1.a);
  CHECK(s.p().a == p1.a);
  CHECK(s.step_count() == 2);
  in.solid_u_velocity = uu2;
  s.redo_step(dt, in, out2);
  CHECK(out2.solid_u_force[0] > out.solid_u_force[0]);
  CHECK(s.u().a != u1.a);

  s.set_keep_for_redo(false);
  s.step(dt, in, out);
  CHECK_THROWS_WITH(s.redo_step(dt, in, out2), Catch::Contains("kept for a redo"));
  }
}

// Work ahead of the input: the step begun before its input (explicit terms, boundary values,
// the predictor or Crank-Nicolson's right-hand side) and ended with it gives the fields of plain
// steps bit for bit, with the immersed forcing and the fibers' force, for both diffusion
// options. Misuse is refused: a step begun twice, an end without a begin, a redo of the step
// before once the next is begun.
TEST_CASE("work ahead gives the plain steps bit for bit", "[fluid][coupling]") {
  for (Diffusion d : kDiffusions) {
    CAPTURE(d);
    const Config c = with(box(BcType::periodic), d);
    const double dt = 1e-3;
    Solver a(c, dt), b(c, dt);
    const int nu = a.grid().nu(), nx = a.grid().nx();
    BlockInput block(a);
    CouplingIn& in = block.in;
    std::vector<std::int32_t> fu, fv;
    std::vector<double> ffu, ffv;
    for (int i = 9; i < 12; ++i) fu.push_back(i + nu * 5), ffu.push_back(40.0 * i);
    fv.push_back(10 + nx * 6), ffv.push_back(-25.0);
    in.fiber_u_index = fu;
    in.fiber_u_force = ffu;
    in.fiber_v_index = fv;
    in.fiber_v_force = ffv;
    CouplingOut oa, ob;
    for (int n = 0; n < 5; ++n) {
      a.step(dt, in, oa);
      b.begin_step(dt);
      b.end_step(dt, in, ob);
    }
    check_same(a, b, oa, ob);
    CHECK(std::abs(a.v()(10, 6)) > 1e-6);  // the fibers' force moved the fluid
    CHECK_THROWS_WITH(b.end_step(dt, in, ob), Catch::Contains("no step of this dt begun"));
    b.begin_step(dt);
    CHECK_THROWS_WITH(b.redo_step(dt, in, ob), Catch::Contains("kept for a redo"));
    CHECK_THROWS_WITH(b.begin_step(dt), Catch::Contains("begun"));
    CHECK_THROWS_WITH(b.step(dt, in, ob), Catch::Contains("begun"));
  }
}

// Sub-cycling: a coupled step of dt in m substeps is m plain steps of dt / m with the same
// input, bit for bit, for each diffusion option, with the immersed forcing and the fibers'
// force; the solid's force is the mean of the m steps' forces (their impulse over dt); the
// samples are the last step's. The substep count may change from one coupled step to the next.
TEST_CASE("substeps are plain steps of dt / m; the force is their mean", "[fluid][coupling]") {
  for (Diffusion d : kDiffusions) {
    CAPTURE(d);
    const Config c = with(box(BcType::periodic), d);
    const double dt = 2e-3;
    Solver a(c, dt), b(c, dt);
    const int nu = a.grid().nu();
    BlockInput block(a);
    CouplingIn& in = block.in;
    std::vector<std::int32_t> fu{int(10 + nu * 5)}, su{int(2 + nu * 2)};
    std::vector<double> ffu{30.0};
    in.fiber_u_index = fu;
    in.fiber_u_force = ffu;
    in.sample_u_index = su;
    CouplingOut oa, ob;
    for (int m : {1, 3, 2, 4}) {
      CAPTURE(m);
      std::vector<double> sum(block.index.size(), 0.0);
      for (int k = 0; k < m; ++k) {
        a.step(dt / m, in, oa);
        for (std::size_t q = 0; q < sum.size(); ++q) sum[q] += oa.solid_u_force[q];
      }
      b.begin_step(dt / m);
      b.end_substeps(dt, m, in, ob);
      CouplingOut mean = oa;
      for (std::size_t q = 0; q < sum.size(); ++q) mean.solid_u_force[q] = sum[q] / m;
      check_same(a, b, mean, ob);
      CHECK(ob.sample_u == oa.sample_u);
      CHECK(b.step_count() == a.step_count());
      CHECK(b.time() == a.time());
    }
  }
}

// The substep count (cfl 0.5, max 4): up at once to ceil(C / cfl), down by one only with the
// margin, never above max, one for a non-finite C or without sub-cycling.
TEST_CASE("substep count: rises at once, falls by one with a margin", "[fluid][coupling]") {
  CHECK(substep_count(0, 0.0, 4, 0.5) == 1);
  CHECK(substep_count(0, 0.5, 4, 0.5) == 1);
  CHECK(substep_count(0, 0.51, 4, 0.5) == 2);
  CHECK(substep_count(1, 1.3, 4, 0.5) == 3);
  CHECK(substep_count(2, 9.0, 4, 0.5) == 4);  // capped; the health check judges C / 4
  CHECK(substep_count(3, 1.5, 4, 0.5) == 3);  // at cfl x 3: stays
  CHECK(substep_count(3, 0.81, 4, 0.5) == 3);  // within the margin: stays
  CHECK(substep_count(3, 0.8, 4, 0.5) == 2);   // 0.8 x 0.5 x 2
  CHECK(substep_count(4, 0.01, 4, 0.5) == 3);  // by one per step
  CHECK(substep_count(2, 0.4, 4, 0.5) == 1);
  CHECK(substep_count(3, std::nan(""), 4, 0.5) == 1);
  CHECK(substep_count(0, 9.0, 1, 0.5) == 1);
}

// Crank-Nicolson: the momentum the step gains is the integral of the f_s it returns (doubly
// periodic box: neither walls nor the projection take momentum), on a step from a moving state,
// with faces the body covers (alpha = 1) and cut ones (0.6); with Eq. 21's alpha and with
// forcing_time's beta (tau = 0, and tau = 2 dt).
TEST_CASE("Crank-Nicolson: the momentum gained is the returned forcing", "[fluid][coupling]") {
  for (double tau : {-1.0, 0.0, 2e-3}) {
    CAPTURE(tau);
    Config c = with(box(BcType::periodic), crank_nicolson);
    c.bc[bottom].type = c.bc[top].type = BcType::periodic;
    c.forcing_time = tau;
    const double dt = 1e-3;
    Solver s(c, dt);
    const Grid& g = s.grid();
    BlockInput block(s);
    for (int i = 4; i < 8; ++i) block.add(i + g.nu() * 4, 1.0, 0.3);
    CouplingOut out;
    for (int n = 0; n < 3; ++n) s.step(dt, block.in, out);
    auto momentum = [&] {
      double m = 0;
      for (int j = 0; j < g.ny(); ++j)
        for (int i = 0; i < g.nx(); ++i) m += c.density * s.u()(i, j) * g.x().h() * g.y().width(j);
      return m;
    };
    const double before = momentum();
    s.step(dt, block.in, out);
    double fint = 0;
    for (std::size_t q = 0; q < block.index.size(); ++q) {
      const int j = block.index[q] / g.nu();
      fint += out.solid_u_force[q] * g.x().h() * g.y().width(j);
    }
    CHECK(std::abs(fint) > 1e-3);
    CHECK(momentum() - before == Approx(fint * dt).epsilon(1e-9));
  }
}

// body_viscosity = "none" (body_viscosity.cpp): a layer of faces inside a body (alpha = 1; the
// v faces at its top and bottom half inside) over a shear u = y^2 (L u = 2 exactly on the uniform
// grid). Against the default, the forcing of a u face whose links all lie in the body grows by
// mu L u (the viscous force the fluid inside no longer gets, so the body no longer receives it),
// the layer's edge rows by their inner link's flux only (the link to the fluid keeps the
// traction), the v faces not at all, nothing changes outside the footprint, and the changes sum
// to zero: the stress is moved, not lost.
TEST_CASE("body_viscosity = none: no viscous force inside a body, the traction kept",
          "[fluid][coupling]") {
  for (Diffusion d : {explicit_ab2, crank_nicolson_after_solve}) {
    CAPTURE(d);
    const double dt = 1e-3;
    std::vector<double> force[2], force_v[2], u_after[2];
    std::vector<std::int32_t> iu, iv;
    std::vector<double> au, uu, av, vv;
    double mu = 0, h = 0;
    int nu = 0;
    for (int none = 0; none < 2; ++none) {
      Config c = with(box(BcType::periodic), d);
      c.bodies_inviscid = none == 1;
      mu = c.viscosity;
      Solver s(c, dt);
      const Grid& g = s.grid();
      h = g.y().h();
      nu = g.nu();
      for (int j = -1; j <= g.ny(); ++j)
        for (int i = -1; i <= g.nx(); ++i) {
          const double y = (j + 0.5) * h;
          s.u()(i, j) = y * y;
        }
      iu.clear(), au.clear(), uu.clear(), iv.clear(), av.clear(), vv.clear();
      for (int j = 2; j < 6; ++j)
        for (int i = 0; i < g.nx(); ++i)
          iu.push_back(i + nu * j), au.push_back(1.0), uu.push_back(s.u()(i, j));
      for (int j = 2; j <= 6; ++j)
        for (int i = 0; i < g.nx(); ++i)
          iv.push_back(i + g.nx() * j), av.push_back(j == 2 || j == 6 ? 0.5 : 1.0), vv.push_back(0);
      const CouplingIn in = solid_input(iu, au, uu, iv, av, vv);
      CouplingOut out;
      s.step(dt, in, out);
      force[none] = out.solid_u_force;
      force_v[none] = out.solid_v_force;
      u_after[none] = s.u().a;
    }
    double sum = 0, scale = 0;
    for (std::size_t q = 0; q < iu.size(); ++q) {
      const int j = iu[q] / nu;
      const double y = (j + 0.5) * h;
      const double change = force[1][q] - force[0][q];
      // The flux the link to the row above (below) carried, mu (u_(j+1) - u_j) / h^2.
      const double up = mu * ((y + h) * (y + h) - y * y) / (h * h);
      const double down = mu * ((y - h) * (y - h) - y * y) / (h * h);
      const double expected = j == 2 ? up : j == 5 ? down : 2 * mu;
      // Explicit: exactly; Crank-Nicolson: the solve spreads the correction by O(lambda).
      if (d == explicit_ab2) CHECK(change == Approx(expected).epsilon(1e-9));
      else CHECK(change == Approx(expected).epsilon(0.02));
      sum += change, scale += std::abs(change);
    }
    if (d == explicit_ab2) {
      CHECK(std::abs(sum) <= 1e-9 * scale);
      CHECK(force_v[0] == force_v[1]);
      // Outside the footprint the explicit step's fields are the same (the forced faces end at
      // u_s either way, and no fluid face was corrected).
      CHECK(u_after[0] == u_after[1]);
    }
  }
}

// The elastic part of α (protocol version 8): "none" with it equal to α is "none" with none sent
// (every body elastic), and with it zero (every body rigid) is "kelvin-voigt", bit for bit; the
// same layer over the shear as above, both diffusions.
TEST_CASE("body_viscosity = none acts on the elastic part of alpha only", "[fluid][coupling]") {
  for (Diffusion d : {explicit_ab2, crank_nicolson_after_solve}) {
    CAPTURE(d);
    const double dt = 1e-3;
    enum Variant { all_elastic, elastic_is_alpha, all_rigid, kelvin_voigt };
    std::vector<double> u[4], v[4], fu[4], fv[4];
    for (int k = 0; k < 4; ++k) {
      Config c = with(box(BcType::periodic), d);
      c.bodies_inviscid = k != kelvin_voigt;
      Solver s(c, dt);
      const Grid& g = s.grid();
      for (int j = -1; j <= g.ny(); ++j)
        for (int i = -1; i <= g.nx(); ++i) {
          const double y = (j + 0.5) * g.y().h();
          s.u()(i, j) = y * y;
        }
      std::vector<std::int32_t> iu, iv;
      std::vector<double> au, uu, av, vv;
      for (int j = 2; j < 6; ++j)
        for (int i = 0; i < g.nx(); ++i)
          iu.push_back(i + g.nu() * j), au.push_back(j == 2 ? 0.6 : 1.0), uu.push_back(s.u()(i, j));
      for (int j = 2; j <= 6; ++j)
        for (int i = 0; i < g.nx(); ++i)
          iv.push_back(i + g.nx() * j), av.push_back(j == 2 || j == 6 ? 0.5 : 1.0), vv.push_back(0);
      CouplingIn in = solid_input(iu, au, uu, iv, av, vv);
      const std::vector<double> zu(au.size(), 0.0), zv(av.size(), 0.0);
      if (k == elastic_is_alpha) in.solid_u_elastic = au, in.solid_v_elastic = av;
      if (k == all_rigid) in.solid_u_elastic = zu, in.solid_v_elastic = zv;
      CouplingOut out;
      for (int n = 0; n < 3; ++n) s.step(dt, in, out);
      u[k] = s.u().a, v[k] = s.v().a, fu[k] = out.solid_u_force, fv[k] = out.solid_v_force;
    }
    CHECK(u[elastic_is_alpha] == u[all_elastic]);
    CHECK(v[elastic_is_alpha] == v[all_elastic]);
    CHECK(fu[elastic_is_alpha] == fu[all_elastic]);
    CHECK(fv[elastic_is_alpha] == fv[all_elastic]);
    CHECK(u[all_rigid] == u[kelvin_voigt]);
    CHECK(v[all_rigid] == v[kelvin_voigt]);
    CHECK(fu[all_rigid] == fu[kelvin_voigt]);
    CHECK(fv[all_rigid] == fv[kelvin_voigt]);
    CHECK(fu[all_elastic] != fu[kelvin_voigt]);  // the correction acts at all
  }
}

// A rigid rotation has no strain (D = 0): "none" must leave a rotating body's forcing as it is,
// at its edges too (the Laplacian form (1 - phi) mu grad u would not: it would take half the
// viscous torque on the body's surface, the part the fluid inside carries).
TEST_CASE("body_viscosity = none leaves a rigid rotation alone", "[fluid][coupling]") {
  const double dt = 1e-3, omega = 0.7, xc = 0.5, yc = 0.25;
  std::vector<double> force[2][2];
  for (int none = 0; none < 2; ++none) {
    Config c = box(BcType::wall);
    c.bodies_inviscid = none == 1;
    Solver s(c, dt);
    const Grid& g = s.grid();
    const double hx = g.x().h(), hy = g.y().h();
    for (int j = -1; j <= g.ny(); ++j)
      for (int i = -1; i <= g.nx() + 1; ++i) s.u()(i, j) = -omega * ((j + 0.5) * hy - yc);
    for (int j = -1; j <= g.ny() + 1; ++j)
      for (int i = -1; i <= g.nx(); ++i) s.v()(i, j) = omega * ((i + 0.5) * hx - xc);
    // A 4 x 4-cell block at the centre, alpha = 1, with a row and a column of half faces round it.
    std::vector<std::int32_t> idx[2];
    std::vector<double> a[2], w[2];
    for (int c2 = 0; c2 < 2; ++c2)
      for (int j = 1; j <= 6; ++j)
        for (int i = 5; i <= 11; ++i) {
          const bool edge = i == 5 || i == 11 || j == 1 || j == 6;
          const double x = c2 == 0 ? i * hx : (i + 0.5) * hx, y = c2 == 0 ? (j + 0.5) * hy : j * hy;
          idx[c2].push_back(i + (c2 == 0 ? g.nu() : g.nx()) * j);
          a[c2].push_back(edge ? 0.5 : 1.0);
          w[c2].push_back(c2 == 0 ? -omega * (y - yc) : omega * (x - xc));
        }
    const CouplingIn in = solid_input(idx[0], a[0], w[0], idx[1], a[1], w[1]);
    CouplingOut out;
    s.step(dt, in, out);
    force[none][0] = out.solid_u_force, force[none][1] = out.solid_v_force;
  }
  for (int c2 = 0; c2 < 2; ++c2) {
    double scale = 0;
    for (double f : force[0][c2]) scale = std::max(scale, std::abs(f));
    REQUIRE(scale > 0);
    for (std::size_t q = 0; q < force[0][c2].size(); ++q)
      CHECK(std::abs(force[1][c2][q] - force[0][c2][q]) <= 1e-9 * scale);
  }
}

namespace {
// A channel over a wall layer of faces the body holds at rest: the bottom row covered
// (alpha = 1), the next one cut (alpha = 0.4). Driven by a body force g per unit volume (periodic
// in x) or by the pressure 0.02 at x = 0 against 0 at x = 1 (pressure sides: the predictor
// carries grad p^n); diffusion d.
enum Drive { body_force, pressure_drop };
Config wall_layer_channel(Drive drive, double tau, Diffusion d = explicit_ab2, double g = 2.0) {
  Config c = with(box(drive == body_force ? BcType::periodic : BcType::pressure), d);
  if (drive == body_force)
    c.body = {g, 0.0};
  else
    c.bc[left].value = 0.02;
  c.forcing_time = tau;
  return c;
}

// The layer's faces and the body's velocity (0) on them.
struct WallLayer : UFaceInput {
  explicit WallLayer(const Grid& g) {
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < g.nu(); ++i) add(i + g.nu() * j, j == 0 ? 1.0 : 0.4, 0.0);
  }
};

// The steady u along a column after t = 150 at time step dt (< 0 tau: Eq. 21 as written).
std::vector<double> steady_channel(double dt, double tau, Drive drive = body_force,
                                   Diffusion d = explicit_ab2, double g = 2.0) {
  Solver s(wall_layer_channel(drive, tau, d, g), dt);
  const WallLayer layer(s.grid());
  CouplingOut out;
  const int steps = static_cast<int>(std::lround(150.0 / dt));
  for (int n = 0; n < steps; ++n) s.step(dt, layer.in, out);
  std::vector<double> u;
  for (int j = 0; j < s.grid().ny(); ++j) u.push_back(s.u()(3, j));
  return u;
}
// The largest difference of two profiles relative to the first's largest value.
double gap(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0, m = 0;
  for (std::size_t j = 0; j < a.size(); ++j)
    d = std::max(d, std::abs(a[j] - b[j])), m = std::max(m, std::abs(a[j]));
  return d / m;
}
}  // namespace

namespace {
// Couette flow over a fixed block in a channel of width 1 and length 0.25, periodic along it,
// 16 cells across and 4 along. The wall at 0 is covered by the block up to y0 (normal = 1: y
// across, u the flow, the family whose lines run across its own rows) or x0 (normal = 0: x
// across, v the flow, its lines along x, across the v boxes' columns); the far wall moves at 1
// along the channel. Each face's alpha is the share of its box below y0 (x0): the box spans the
// cell across for the flow's family, from centre to centre for the other. stretched: across,
// 10 of the 16 cells evenly over [0.5, 1] and 6 growing towards the block's wall at 0, so the
// wall lies in graded cells. Stepped to its steady state: the flow's profile across, and the
// force the block's forcing puts into the fluid, sum of f_s |V| over the faces.
struct Couette {
  std::vector<double> u, y;
  double force = 0;
};
AxisSpec couette_across(bool stretched) {
  AxisSpec across{16, 1.0, 0.0};
  if (stretched) across.band_cells = 10, across.band_from = 0.5, across.band_to = 1.0;
  return across;
}
Couette couette_over_block(double y0, bool sharp, bool elastic = false, int normal = 1,
                           bool stretched = false) {
  Config c = box(BcType::periodic);
  c.density = 1;
  c.viscosity = 0.05;
  const AxisSpec across = couette_across(stretched), along{4, 0.25, 0.0};
  c.x = normal == 1 ? along : across;
  c.y = normal == 1 ? across : along;
  for (auto& b : c.bc) b.type = BcType::periodic;
  const Side lo = normal == 1 ? bottom : left, hi = normal == 1 ? top : right;
  c.bc[lo].type = c.bc[hi].type = BcType::wall;
  c.bc[hi].velocity = 1.0;
  c.sharp_interface = sharp;
  const Axis a(across);
  double hmin = 1;
  for (int k = 0; k < a.n(); ++k) hmin = std::min(hmin, a.width(k));
  const double dt = 0.1 * hmin * hmin / c.viscosity;  // lambda = 0.1 on the smallest cell
  Solver s(c, dt);
  const Grid& g = s.grid();
  const Axis& ax = normal == 1 ? g.y() : g.x();
  auto share = [&](double a, double b) { return std::clamp((y0 - a) / (b - a), 0.0, 1.0); };
  // Faces (i, j) of family comp (0 = u, 1 = v) with their alpha and box volume.
  std::vector<std::int32_t> idx[2];
  std::vector<double> al[2], vol[2];
  for (int comp = 0; comp < 2; ++comp) {
    const int ni = comp == 0 ? g.nu() : g.nx(), nj = comp == 0 ? g.ny() : g.nv();
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i) {
        // The unknowns only: across a wall the first and last faces of the family across it.
        const int k = normal == 1 ? j : i;
        const bool own = comp == normal;  // the family whose faces lie on lines across
        if (own && (k == 0 || k == ax.n())) continue;
        const double bx0 = comp == 0 ? g.x().centre(i - 1) : g.x().face(i);
        const double bx1 = comp == 0 ? g.x().centre(i) : g.x().face(i + 1);
        const double by0 = comp == 0 ? g.y().face(j) : g.y().centre(j - 1);
        const double by1 = comp == 0 ? g.y().face(j + 1) : g.y().centre(j);
        const double a = normal == 1 ? share(by0, by1) : share(bx0, bx1);
        if (a <= 0) continue;
        idx[comp].push_back(i + ni * j), al[comp].push_back(a);
        vol[comp].push_back((bx1 - bx0) * (by1 - by0));
      }
  }
  const std::vector<double> zu(idx[0].size(), 0.0), zv(idx[1].size(), 0.0);
  CouplingIn in = solid_input(idx[0], al[0], zu, idx[1], al[1], zv);
  // The block rigid (no elastic part: its wall placed) or elastic (its faces keep Eq. 21).
  in.solid_u_elastic = elastic ? std::span<const double>(al[0]) : std::span<const double>(zu);
  in.solid_v_elastic = elastic ? std::span<const double>(al[1]) : std::span<const double>(zv);
  CouplingOut out;
  // 2.5 diffusion times of the layer above the block.
  const int steps = int(std::lround(2.5 / c.viscosity / dt));
  for (int n = 0; n < steps; ++n) s.step(dt, in, out);
  Couette r;
  for (int k = 0; k < ax.n(); ++k) {
    r.u.push_back(normal == 1 ? s.u()(2, k) : s.v()(k, 2));
    r.y.push_back(ax.centre(k));
  }
  const auto& f = normal == 1 ? out.solid_u_force : out.solid_v_force;
  const int flow = normal == 1 ? 0 : 1;
  for (std::size_t q = 0; q < f.size(); ++q) r.force += f[q] * vol[flow][q];
  return r;
}
}  // namespace

// The exact profile u = (y - y0)/(1 - y0) is linear, which the sharp interface's line from the
// wall through the next face holds on any grid: every face above the block exact, and the force
// on the fluid the wall's shear, -mu/(1 - y0) per unit length over the 0.25 of the channel. The
// paper's blend puts the wall up to half a cell off (runs/sub-cell-wall), which these checks see.
// The block is rigid; an elastic one is left to Eq. 21. Both families: u faces with lines across
// their rows (normal y), v faces with lines across the v boxes (normal x), uniform and with the
// wall in graded cells.
TEST_CASE("interface = sharp: a wall anywhere in its cell, a linear profile held exactly",
          "[fluid][coupling]") {
  for (int normal : {1, 0})
    for (bool stretched : {false, true})
      for (double delta : {0.0, 0.1, 0.5, 0.8}) {
        CAPTURE(normal, stretched, delta);
        // The wall delta of the way across the cell that holds 0.25 + a bit.
        const Axis ax(couette_across(stretched));
        int k = 0;
        while (ax.face(k + 1) < 0.25) ++k;
        const double y0 = ax.face(k) + delta * ax.width(k);
        const Couette sharp = couette_over_block(y0, true, false, normal, stretched);
        const Couette volume = couette_over_block(y0, false, false, normal, stretched);
        double err = 0, err_volume = 0;
        for (std::size_t j = 0; j < sharp.u.size(); ++j) {
          if (sharp.y[j] <= y0) continue;
          const double exact = (sharp.y[j] - y0) / (1 - y0);
          err = std::max(err, std::abs(sharp.u[j] - exact));
          err_volume = std::max(err_volume, std::abs(volume.u[j] - exact));
        }
        CHECK(err < 1e-8);
        CHECK(err_volume > 1e-3);
        // The force on uniform grids only: on graded cells the fluid's Laplacian across them is
        // in finite-difference form (2/(c_(j+1) - c_(j-1)) where a balance over the boxes would
        // take 1/w_j), so the forcing summed over the boxes is not the momentum balance there
        // (measured here: -0.48 %, -19 % with the wall on a grid line; Eq. 21 -0.8 ... -6.4 %).
        const double shear = -0.05 / (1 - y0) * 0.25;
        if (!stretched) CHECK(sharp.force == Approx(shear).epsilon(1e-6));
        // An elastic block's faces keep Eq. 21: the volume blend's steady state to round-off
        // (the update is written differently; an elastic body's viscosity taken out in both,
        // body_viscosity = "none").
        CHECK(gap(couette_over_block(y0, true, true, normal, stretched).u,
                  couette_over_block(y0, false, true, normal, stretched).u) < 1e-12);
      }
}

// A rigid body's faces of family comp (0 = u, 1 = v; ni of them in a row): those of rows
// 0 .. rows - 1 with a(i, j) > 0, all at the velocity w along the family, no elastic part
// (`in` spans the vectors).
struct RigidFaces {
  std::vector<std::int32_t> index;
  std::vector<double> alpha, velocity, zero;
  CouplingIn in;
  template <class Alpha>
  RigidFaces(int comp, int ni, int rows, Alpha a_of, double w = 0) {
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < ni; ++i)
        if (const double a = a_of(i, j); a > 0)
          index.push_back(i + ni * j), alpha.push_back(a), velocity.push_back(w), zero.push_back(0);
    (comp == 0 ? in.solid_u_index : in.solid_v_index) = index;
    (comp == 0 ? in.solid_u_alpha : in.solid_v_alpha) = alpha;
    (comp == 0 ? in.solid_u_velocity : in.solid_v_velocity) = velocity;
    (comp == 0 ? in.solid_u_elastic : in.solid_v_elastic) = zero;
  }
  RigidFaces(const RigidFaces&) = delete;  // the spans point into this object
  RigidFaces& operator=(const RigidFaces&) = delete;
};

// The u faces' alpha of a block over rows 0..2 of the box, cut in row 3 (alpha 0.6) and in every
// other face of row 4 (alpha 0.2).
double cut_block(int i, int j) { return j < 3 ? 1.0 : j == 3 ? 0.6 : (i % 2 ? 0.2 : 0.0); }

// That block at rest in the body-force-driven periodic channel; its steady u along a column
// after t = 150 at time step dt. Row 3's faces at odd i read row 4's cut faces, which are forced
// themselves: read at their targets, every target depends on velocities alone, so the steady
// state does not depend on dt (read at their predictors, the slip dt R of a forced face would
// enter).

std::vector<double> steady_sharp_block(double dt) {
  Config c = box(BcType::periodic);
  c.body = {2.0, 0.0};
  c.sharp_interface = true;
  Solver s(c, dt);
  const RigidFaces block(0, s.grid().nu(), 5, cut_block);
  CouplingOut out;
  const int steps = static_cast<int>(std::lround(150.0 / dt));
  for (int n = 0; n < steps; ++n) s.step(dt, block.in, out);
  std::vector<double> u;
  for (int j = 0; j < s.grid().ny(); ++j) u.push_back(s.u()(3, j)), u.push_back(s.u()(4, j));
  return u;
}

TEST_CASE("interface = sharp: a forced neighbour read at its target, no slip of order dt",
          "[fluid][coupling]") {
  // lambda = 0.10 and 0.05 (dt = 0.04, 0.02), as the forcing_time test above.
  const auto coarse = steady_sharp_block(0.04), fine = steady_sharp_block(0.02);
  CHECK(coarse[2 * 5] > 0.1);  // the flow above the block (row 5)
  CHECK(gap(coarse, fine) < 1e-10);
}

// A block at rest in a uniform stream U along the family's direction (periodic both ways, so
// u~ = U on every face exactly), its edges at 3/4 and 1/4 of their cells: along the stream
// [4.25 h, 8.75 h], across it [2.75 h, 5.75 h]. Each face's target is read back from its force,
// target = u~ + dt f / rho. The four faces whose boxes hold a corner keep Eq. 21 (target
// (1 - alpha) U); the faces cut by one wall take the line through their neighbour (target r U,
// r = dist / span). A face's box spans the cell centres along its own direction and the cell
// across it, for either family.
TEST_CASE("interface = sharp: a convex corner keeps Eq. 21, a side its line", "[fluid][coupling]") {
  for (int comp : {0, 1}) {
    CAPTURE(comp);
    Config c = box(BcType::periodic);
    c.y = {16, 1.0, 0.0};
    c.bc[bottom].type = c.bc[top].type = BcType::periodic;
    c.sharp_interface = true;
    const double dt = 1e-3, U = 0.4, h = 1.0 / 16;
    Solver s(c, dt);
    const int n = 16;  // faces per row and rows, either family
    Field& w = comp == 0 ? s.u() : s.v();
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) w(i, j) = U;
    auto overlap = [](double lo, double hi, double a, double b) {
      return std::max(0.0, std::min(hi, b) - std::max(lo, a));
    };
    // Face (k, m): k along the stream, m across it.
    auto alpha = [&](int k, int m) {
      return overlap((k - 0.5) * h, (k + 0.5) * h, 4.25 * h, 8.75 * h) / h *
             overlap(m * h, (m + 1) * h, 2.75 * h, 5.75 * h) / h;
    };
    const RigidFaces block(comp, n, n, [&](int i, int j) {
      return comp == 0 ? alpha(i, j) : alpha(j, i);
    });
    CouplingOut out;
    s.step(dt, block.in, out);
    const std::vector<double>& force = comp == 0 ? out.solid_u_force : out.solid_v_force;
    auto target = [&](int k, int m) {
      const std::int32_t idx = comp == 0 ? k + n * m : m + n * k;
      const auto& ix = block.index;
      const auto q = std::find(ix.begin(), ix.end(), idx) - ix.begin();
      REQUIRE(std::size_t(q) < ix.size());
      return U + dt * force[q] / c.density;
    };
    // The corners: alpha = f_along f_across.
    CHECK(target(9, 5) == Approx((1 - 0.25 * 0.75) * U).epsilon(1e-12));
    CHECK(target(9, 2) == Approx((1 - 0.25 * 0.25) * U).epsilon(1e-12));
    CHECK(target(4, 5) == Approx((1 - 0.25 * 0.75) * U).epsilon(1e-12));
    CHECK(target(4, 2) == Approx((1 - 0.25 * 0.25) * U).epsilon(1e-12));
    // The downstream end (k = 9, wall 0.25 h behind, neighbour at 10 h), the upstream end
    // (k = 4, wall 0.25 h ahead), one side (centre 5.5 h inside, wall 0.25 h further out,
    // neighbour at 6.5 h) and the other (centre 2.5 h, wall 0.25 h further in, neighbour at
    // 1.5 h).
    CHECK(target(9, 4) == Approx(0.2 * U).epsilon(1e-12));
    CHECK(target(4, 4) == Approx(0.2 * U).epsilon(1e-12));
    CHECK(target(6, 5) == Approx(-U / 3).epsilon(1e-12));
    CHECK(target(6, 2) == Approx(0.2 * U).epsilon(1e-12));
  }
}

// The fluid walled in by a rigid body's forced faces: the ghost faces' values leave the forced
// field a divergence in the cells beside them at every step, whose increment the incremental
// projection would keep, so that p inside grew linearly. Those cells keep p^n (here the
// initial 0), and the fluid's cells go on: in a box periodic both ways no domain side tells
// the fluid from a body, the faces the coupling did not list do.
TEST_CASE("interface = sharp: the pressure walled in by a rigid body keeps p^n",
          "[fluid][coupling]") {
  Config c = box(BcType::periodic);
  c.y = {16, 1.0, 0.0};
  c.bc[bottom].type = c.bc[top].type = BcType::periodic;
  c.body = {2.0, 0.0};
  c.sharp_interface = true;
  const double dt = 2e-3, h = 1.0 / 16;
  Solver s(c, dt);
  const int n = 16;
  auto overlap = [](double lo, double hi, double a, double b) {
    return std::max(0.0, std::min(hi, b) - std::max(lo, a));
  };
  // A block over x in [4.25, 8.75] h, y in [2.75, 5.75] h: every wall inside its cells.
  auto cut = [&](double x, double y) {
    return overlap(x - 0.5 * h, x + 0.5 * h, 4.25 * h, 8.75 * h) / h *
           overlap(y - 0.5 * h, y + 0.5 * h, 2.75 * h, 5.75 * h) / h;
  };
  const RigidFaces u(0, n, n, [&](int i, int j) { return cut(i * h, (j + 0.5) * h); });
  const RigidFaces v(1, n, n, [&](int i, int j) { return cut((i + 0.5) * h, j * h); });
  CouplingIn in = u.in;
  in.solid_v_index = v.in.solid_v_index;
  in.solid_v_alpha = v.in.solid_v_alpha;
  in.solid_v_velocity = v.in.solid_v_velocity;
  in.solid_v_elastic = v.in.solid_v_elastic;
  CouplingOut out;
  auto run = [&](int steps) {
    for (int k = 0; k < steps; ++k) s.step(dt, in, out);
  };
  // Cells (5..7, 3..4) lie inside the block; (12, 8) is in the stream.
  auto inside = [&] {
    std::vector<double> p;
    for (int j = 3; j <= 4; ++j)
      for (int i = 5; i <= 7; ++i) p.push_back(s.p()(i, j));
    return p;
  };
  run(200);
  const auto p1 = inside();
  const double free1 = s.p()(12, 8);
  run(200);
  const auto p2 = inside();
  CHECK(p2 == p1);
  // The stream's pressure still moves: the fluid was not taken for a walled-in group.
  CHECK(s.p()(12, 8) != free1);
}

// A redo with the step's own input gives the step's fields and force bit for bit: the lines
// are built afresh from the kept predictor, nothing of the first pass stays behind.
TEST_CASE("interface = sharp: a redo with the same input repeats the step", "[fluid][coupling]") {
  Config c = box(BcType::periodic);
  c.sharp_interface = true;
  const double dt = 1e-3;
  Solver s(c, dt);
  // The cut block above, moving at 0.2: covered faces that extrapolate, cut ones that
  // interpolate, a forced neighbour read at its target.
  const RigidFaces block(0, s.grid().nu(), 5, cut_block, 0.2);
  const CouplingIn& in = block.in;
  CouplingOut out, out2;
  for (int n = 0; n < 3; ++n) s.step(dt, in, out);
  const Field u1 = s.u(), p1 = s.p();
  s.redo_step(dt, in, out2);
  CHECK(out2.solid_u_force == out.solid_u_force);
  CHECK(s.u().a == u1.a);
  CHECK(s.p().a == p1.a);
}

TEST_CASE("forcing_time: a steady flow's slip in cut faces does not depend on dt",
          "[fluid][coupling]") {
  // lambda = nu dt / h^2 = 2.56 dt at h = 1/16: dt = 0.04 and 0.02 (lambda 0.10, 0.05).
  for (Drive drive : {body_force, pressure_drop}) {
    CAPTURE(drive);
    const auto paper_coarse = steady_channel(0.04, -1, drive);
    const auto paper_fine = steady_channel(0.02, -1, drive);
    // Eq. 21 as written: the cut face slips by (1 - alpha)/alpha dt R, so the profile moves
    // with dt by a visible fraction.
    CHECK(gap(paper_coarse, paper_fine) > 1e-3);
    // With tau: the same steady state at both steps, to the iteration's convergence.
    CHECK(gap(steady_channel(0.04, 0.02, drive), steady_channel(0.02, 0.02, drive)) < 1e-12);
    // tau = 0 holds the cut face at rest; the flow is the channel above it.
    const auto pinned = steady_channel(0.04, 0.0, drive);
    CHECK(std::abs(pinned[1]) < 1e-12 * pinned[4]);
    CHECK(gap(pinned, steady_channel(0.02, 0.0, drive)) < 1e-12);
  }
}

// Crank-Nicolson with the forcing in its increment blends u^ by the same beta: its steady state
// is the explicit balance, so the slip does not depend on dt at any lambda (here up to 2.05, a
// step 16 times explicit diffusion's limit and 40 times the explicit run compared with). Periodic
// only: Crank-Nicolson has no pressure sides.
TEST_CASE("forcing_time with Crank-Nicolson's increment forcing: the slip does not depend on dt",
          "[fluid][coupling]") {
  // lambda = 2.56 dt: dt = 0.8, 0.2 (lambda 2.05, 0.51). The flow is parallel, so convection
  // vanishes; a weak drive (u below 0.03, CFL number about 0.3 at the larger step) keeps its
  // round-off from growing (with the drive of the test above it does, at CFL numbers above 1).
  const double g = 0.02;
  auto steady = [&](double dt, double tau, Diffusion d) {
    return steady_channel(dt, tau, body_force, d, g);
  };
  // Eq. 21 as written: the cut face's slip (1 - alpha)/alpha dt R moves the profile with dt.
  CHECK(gap(steady(0.8, -1, crank_nicolson), steady(0.2, -1, crank_nicolson)) > 1e-2);
  // With tau: one steady state whatever dt, and the explicit scheme's at the same tau.
  const auto relaxed = steady(0.8, 0.02, crank_nicolson);
  CHECK(gap(relaxed, steady(0.2, 0.02, crank_nicolson)) < 1e-12);
  CHECK(gap(relaxed, steady(0.02, 0.02, explicit_ab2)) < 1e-12);
  // tau = 0 holds the cut face at rest at any lambda.
  const auto pinned = steady(0.8, 0.0, crank_nicolson);
  CHECK(std::abs(pinned[1]) < 1e-12 * pinned[4]);
  CHECK(gap(pinned, steady(0.2, 0.0, crank_nicolson)) < 1e-12);
}

TEST_CASE("forcing_time = dt is Eq. 21 step by step, the returned force too",
          "[fluid][coupling]") {
  // Explicit diffusion with either drive; Crank-Nicolson's increment forcing (no pressure sides).
  const std::pair<Drive, Diffusion> runs[] = {
      {body_force, explicit_ab2}, {pressure_drop, explicit_ab2}, {body_force, crank_nicolson}};
  for (const auto& [drive, d] : runs) {
    CAPTURE(drive, d);
    const double dt = 0.02;
    Solver a(wall_layer_channel(drive, -1, d), dt), b(wall_layer_channel(drive, dt, d), dt);
    const WallLayer layer(a.grid());
    CouplingOut oa, ob;
    for (int n = 0; n < 5; ++n) {
      a.step(dt, layer.in, oa);
      b.step(dt, layer.in, ob);
    }
    double du = 0, scale = 0, df = 0, fscale = 0;
    for (std::size_t k = 0; k < a.u().a.size(); ++k)
      du = std::max(du, std::abs(a.u().a[k] - b.u().a[k])), scale = std::max(scale, std::abs(a.u().a[k]));
    for (std::size_t q = 0; q < oa.solid_u_force.size(); ++q)
      df = std::max(df, std::abs(oa.solid_u_force[q] - ob.solid_u_force[q])),
      fscale = std::max(fscale, std::abs(oa.solid_u_force[q]));
    REQUIRE(scale > 0);
    REQUIRE(fscale > 0);
    CHECK(du <= 1e-14 * scale);
    CHECK(df <= 1e-14 * fscale);
  }
}

namespace {
// A 6 x 4-cell block of an elastic body (every face inside it and on its edge covered, alpha = 1)
// dilating at the rate 2 eps: u_s = eps (x - xc, y - yc). The step's pressure increment at the
// block's centre cell after `steps` steps, and each cell's divergence.
struct Dilating {
  std::vector<double> dp;                // p^(n+1) - p^n at the centre, per step
  std::vector<double> div_inside;        // D u in the block's cells after the last step
  double div_outside = 0;                // the largest |D u| elsewhere
  double health_after = 0;               // max_divergence after one more step without the block
  double div_sum = 0;                    // sum of D u |c| over the grid
  double health = 0;                     // max_divergence (the allowed part taken out)
};
// `last`: the last step's substep count when not `substeps`; `shared_row` >= 0: the block's
// faces named as of body 0 (protocol version 9), those of this row as of several bodies (-1),
// or with `shared_row` = 100 the faces of rows 4 and above as of body 1.
Dilating dilating_block(Config::BodyDivergence mode, BcType sides, int steps, int substeps = 1,
                        int last = 0, int shared_row = -1) {
  const double dt = 1e-3, eps = 0.4, xc = 0.5, yc = 0.25;
  Config c = box(sides);
  c.body_divergence = mode;
  Solver s(c, dt);
  const Grid& g = s.grid();
  const double hx = g.x().h(), hy = g.y().h();
  // Cells i in [5, 11), j in [2, 6): u faces i in [5, 11], j in [2, 6); v faces i in [5, 11),
  // j in [2, 6].
  std::vector<std::int32_t> idx[2];
  std::vector<double> a[2], w[2];
  for (int j = 2; j <= 6; ++j)
    for (int i = 5; i <= 11; ++i) {
      if (j < 6) {
        idx[0].push_back(i + g.nu() * j), a[0].push_back(1.0);
        w[0].push_back(eps * (i * hx - xc));
      }
      if (i < 11) {
        idx[1].push_back(i + g.nx() * j), a[1].push_back(1.0);
        w[1].push_back(eps * (j * hy - yc));
      }
    }
  CouplingIn in = solid_input(idx[0], a[0], w[0], idx[1], a[1], w[1]);
  std::vector<std::int32_t> body[2];
  if (shared_row >= 0) {
    for (int c = 0; c < 2; ++c)
      for (const std::int32_t f : idx[c]) {
        const int row = f / (c == 0 ? g.nu() : g.nx());
        body[c].push_back(shared_row == 100 ? (row >= 4 ? 1 : 0) : row == shared_row ? -1 : 0);
      }
    in.solid_u_body = body[0];
    in.solid_v_body = body[1];
  }
  CouplingOut out;
  Dilating r;
  for (int n = 0; n < steps; ++n) {
    const double p0 = s.p()(8, 4);
    const int m = n + 1 == steps && last > 0 ? last : substeps;
    s.begin_step(dt / m);
    s.end_substeps(dt, m, in, out);
    r.dp.push_back(s.p()(8, 4) - p0);
  }
  for (int j = 0; j < g.ny(); ++j)
    for (int i = 0; i < g.nx(); ++i) {
      const double d = (s.u()(i + 1, j) - s.u()(i, j)) / hx + (s.v()(i, j + 1) - s.v()(i, j)) / hy;
      r.div_sum += d * hx * hy;
      if (i >= 5 && i < 11 && j >= 2 && j < 6)
        r.div_inside.push_back(d);  // the block's cells
      else
        r.div_outside = std::max(r.div_outside, std::abs(d));
    }
  r.health = max_divergence(s).value;
  // The body gone: nothing of its divergence is left, in the fields or in the health check.
  s.step(dt, CouplingIn{}, out);
  r.health_after = max_divergence(s).value;
  return r;
}
}  // namespace

// The fluid's incompressibility inside a compressible body is a pressure that the incremental
// projection adds to at every step (projection.cpp); body_divergence = "solid" lets the fluid in
// an elastic body take the body's divergence instead.
TEST_CASE("body_divergence: the fluid in a dilating body takes its divergence, not a pressure",
          "[fluid][coupling]") {
  const double rate = 2 * 0.4;  // D u_s
  // Pressure sides: the fluid outside takes the block's growth.
  const Dilating zero = dilating_block(Config::BodyDivergence::zero, BcType::pressure, 20);
  const Dilating solid = dilating_block(Config::BodyDivergence::solid, BcType::pressure, 20);
  // "zero": the same increment every step (after the fluid outside has started: steps 10-19),
  // the block's dilatation answered again and again.
  double zero_sum = 0, solid_sum = 0;
  for (std::size_t n = 10; n < 20; ++n) zero_sum += zero.dp[n], solid_sum += solid.dp[n];
  REQUIRE(std::abs(zero_sum) > 0);
  for (std::size_t n = 10; n < 20; ++n) CHECK(std::abs(zero.dp[n] - zero_sum / 10) <= 0.03 * std::abs(zero_sum / 10));
  for (double d : zero.div_inside) CHECK(std::abs(d) <= 1e-9 * rate);
  // "solid": once the fluid outside moves, no more: the block's cells keep the body's divergence.
  for (std::size_t n = 10; n < 20; ++n) CHECK(std::abs(solid.dp[n]) <= 0.02 * std::abs(zero.dp[n]));
  CHECK(std::abs(solid_sum) <= 0.01 * std::abs(zero_sum));
  REQUIRE(solid.div_inside.size() == 24);
  for (double d : solid.div_inside) CHECK(std::abs(d - rate) <= 1e-9 * rate);
  CHECK(solid.div_outside <= 1e-9 * rate);  // the fluid around it incompressible
  CHECK(solid.health_after <= 1e-9 * rate);
  // The health check sees what is left after the allowed part: round-off.
  CHECK(zero.health <= 1e-9 * rate);
  CHECK(solid.health <= 1e-9 * rate);
  // Closed by walls: the bodies' net volume change is taken out (the Poisson problem's
  // compatibility), so a block dilating uniformly is held as with "zero".
  const Dilating closed = dilating_block(Config::BodyDivergence::solid, BcType::wall, 3);
  for (double d : closed.div_inside) CHECK(std::abs(d) <= 1e-9 * rate);
  CHECK(std::abs(closed.div_sum) <= 1e-12);
  CHECK(closed.health <= 1e-9 * rate);
}

// Sub-cycled, "zero" answers the block's dilatation once per substep with increments m times a
// plain step's, m² per coupled step; "coupled_step" takes the share 1 − 1/m² of the divergence
// in each substep and keeps one plain step's pressure per coupled step (projection.cpp).
TEST_CASE("body_divergence: coupled_step keeps a plain step's pressure under substeps",
          "[fluid][coupling]") {
  using BD = Config::BodyDivergence;
  const Dilating plain = dilating_block(BD::zero, BcType::pressure, 20);
  // One substep: "zero" itself, bit for bit.
  const Dilating one = dilating_block(BD::coupled_step, BcType::pressure, 20);
  REQUIRE(one.dp.size() == plain.dp.size());
  for (std::size_t n = 0; n < plain.dp.size(); ++n) CHECK(one.dp[n] == plain.dp[n]);
  for (int m : {2, 3}) {
    CAPTURE(m);
    const Dilating zero = dilating_block(BD::zero, BcType::pressure, 20, m);
    const Dilating shared = dilating_block(BD::coupled_step, BcType::pressure, 20, m);
    double p1 = 0, pz = 0, ps = 0;
    for (std::size_t n = 10; n < 20; ++n) p1 += plain.dp[n], pz += zero.dp[n], ps += shared.dp[n];
    REQUIRE(std::abs(p1) > 0);
    CHECK(std::abs(pz / p1 - m * m) <= 0.01 * m * m);
    CHECK(std::abs(ps / p1 - 1) <= 0.01);
    // The rest of the body's divergence stays in its cells, the fluid around it incompressible.
    for (double d : shared.div_inside) CHECK(std::abs(d - (1 - 1.0 / (m * m)) * 0.8) <= 1e-9);
    CHECK(shared.div_outside <= 1e-9);
    CHECK(shared.health <= 1e-9);
    CHECK(shared.health_after <= 1e-9);
  }
  // Faces of several bodies (row 3 of the block's faces: the u faces of cell row 3, the v
  // faces between rows 2 and 3): no share in the cells they bound (rows 2 and 3), the others
  // keep it. Two bodies, the faces of rows >= 4 of the second: the cells of row 3, whose north
  // face is the second body's and the others the first's, span the two and take none.
  for (const int rows : {3, 100}) {
    CAPTURE(rows);
    const Dilating marked = dilating_block(BD::coupled_step, BcType::pressure, 12, 2, 0, rows);
    REQUIRE(marked.div_inside.size() == 24);
    for (std::size_t q = 0; q < 24; ++q) {
      const int row = 2 + int(q) / 6;  // the block's cells, row by row from j = 2
      const bool none = rows == 3 ? row == 2 || row == 3 : row == 3;
      CAPTURE(q, row);
      CHECK(std::abs(marked.div_inside[q] - (none ? 0.0 : 0.75 * 0.8)) <= 1e-9);
    }
    CHECK(marked.div_outside <= 1e-9);
    CHECK(marked.health <= 1e-9);
  }
  // "zero" does not look at the faces' bodies: the same bits with and without them.
  {
    const Dilating plain_zero = dilating_block(BD::zero, BcType::pressure, 12, 2);
    const Dilating named_zero = dilating_block(BD::zero, BcType::pressure, 12, 2, 0, 3);
    CHECK(plain_zero.dp == named_zero.dp);
    CHECK(plain_zero.div_inside == named_zero.div_inside);
  }
  // After sub-cycled steps a plain one is "zero" again: the block held divergence-free.
  const Dilating after = dilating_block(BD::coupled_step, BcType::pressure, 12, 2, 1);
  REQUIRE(after.div_inside.size() == 24);
  for (double d : after.div_inside) CHECK(std::abs(d) <= 1e-9);
  CHECK(after.health <= 1e-9);
}
