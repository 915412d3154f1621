// End conditions and end loads: the load on the supports balances the loads on a static fiber
// (force and moment), clamped-clamped fixed-end moments, attached = clamped to the pose handed in.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "fixtures.hpp"

using namespace fiber;
using namespace fiber::test;

namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Integral of the loads on fiber 0 (gravity + external force per unit length): force and moment
// about the root marker.
EndLoad applied_loads(const FiberSystem& sys, const std::vector<double>& ext) {
  EndLoad sum;
  const auto x = sys.positions(0);
  const Vec2 x0(x[0], x[1]);
  const FiberSpec& f = sys.config().fibers[0];
  for (int i = 0; i < sys.marker_count(0); ++i) {
    const double w = sys.marker_arclength(0, i);
    const Vec2 load = f.density * w * sys.config().gravity + w * Vec2(ext[2 * i], ext[2 * i + 1]);
    sum.force += load;
    sum.moment += cross(Vec2(x[2 * i], x[2 * i + 1]) - x0, load);
  }
  return sum;
}

}  // namespace

TEST_CASE("root load of a static cantilever equals the integral of its loads", "[fiber][ends]") {
  FiberSpec f = make_fiber(1.0, 20, 1.0, 1.0);
  f.root.kind = EndKind::clamped;
  f.damping = 5.0;
  Config c = one_fiber(f);
  c.gravity = {0, -0.1};
  FiberSystem sys(c);
  std::vector<double> ext(2 * 21);
  for (int i = 0; i <= 20; ++i) {
    ext[2 * i] = 0.03;                // axial pull
    ext[2 * i + 1] = 0.02 * i / 20.0;  // growing transverse load
  }
  const double dt = 0.9 * bending_dt_limit(f);
  for (int n = 0; n < 20000; ++n) sys.advance(dt, ext);
  CHECK(sys.kinetic_energy(0) < 1e-20);
  const EndLoad applied = applied_loads(sys, ext);
  const EndLoad root = sys.root_load(0);
  INFO("root load " << root.force.transpose() << " M " << root.moment << "; applied " << applied.force.transpose()
                    << " M " << applied.moment);
  CHECK(root.force.x() == Approx(applied.force.x()).epsilon(1e-8));
  CHECK(root.force.y() == Approx(applied.force.y()).epsilon(1e-8));
  CHECK(root.moment == Approx(applied.moment).epsilon(1e-8));
  CHECK(root.moment < 0);  // a fiber sagging to the right turns its wall clockwise
}

TEST_CASE("static cantilever deflection matches Euler-Bernoulli q L^4 / (8 gamma)", "[fiber][ends]") {
  FiberSpec f = make_fiber(1.0, 32, 1.0, 1.0);
  f.root.kind = EndKind::clamped;
  f.damping = 6.0;
  Config c = one_fiber(f);
  c.gravity = {0, -0.01};
  FiberSystem sys(c);
  const double dt = 0.9 * bending_dt_limit(f);
  for (int n = 0; n < 30000; ++n) sys.advance(dt);
  const double tip = -sys.positions(0)[2 * 32 + 1];
  INFO("tip deflection " << tip << ", beam theory " << 0.01 / 8);
  CHECK(tip == Approx(0.01 / 8).epsilon(2e-3));
}

TEST_CASE("fiber clamped at both ends: the two end loads balance the weight", "[fiber][ends]") {
  // A slack, symmetric arch (the supports closer than the length: an inextensible fiber between
  // supports exactly L apart could not deflect), sagging under its weight.
  FiberSpec f = make_fiber(1.0, 32, 1.0, 0.01, {0, 0}, -0.5);
  f.shape = ShapeKind::arc;
  f.curvature = 1.0;
  f.root.kind = EndKind::clamped;
  f.tip.kind = EndKind::clamped;
  f.damping = 2.0;
  Config c = one_fiber(f);
  const double q = 0.05;
  c.gravity = {0, -q};
  FiberSystem sys(c);
  const double dt = 0.9 * bending_dt_limit(f);
  for (int n = 0; n < 40000; ++n) sys.advance(dt);
  CHECK(sys.kinetic_energy(0) < 1e-20);
  const EndLoad a = sys.root_load(0), b = sys.tip_load(0);
  const auto x = sys.positions(0);
  const Vec2 arm(x[64] - x[0], x[65] - x[1]);
  INFO("root " << a.force.transpose() << " M " << a.moment << "; tip " << b.force.transpose() << " M " << b.moment);
  CHECK(a.force.y() + b.force.y() == Approx(-q).epsilon(1e-9));
  CHECK(a.force.x() + b.force.x() == Approx(0.0).margin(1e-11));
  // symmetry: half the weight each, mirrored moments
  CHECK(a.force.y() == Approx(-q / 2).epsilon(1e-6));
  CHECK(a.moment == Approx(-b.moment).epsilon(1e-6));
  // moment balance about the root: M_root + M_tip + arm x F_tip = moment of the weight
  std::vector<double> none(2 * 33, 0.0);
  const EndLoad applied = applied_loads(sys, none);
  CHECK(a.moment + b.moment + cross(arm, b.force) == Approx(applied.moment).epsilon(1e-8));
}

TEST_CASE("hinged root: weight carried without moment", "[fiber][ends]") {
  FiberSpec f = make_fiber(1.0, 16, 1.0, 0.5, {0, 0}, -std::numbers::pi / 2);
  f.root.kind = EndKind::hinged;
  Config c = one_fiber(f);
  c.gravity = {0, -1};
  FiberSystem sys(c);
  for (int n = 0; n < 100; ++n) sys.advance(0.5 * bending_dt_limit(f));
  CHECK(sys.root_load(0).moment == 0.0);
  CHECK(sys.root_load(0).force.y() == Approx(-1.0).epsilon(1e-9));
}

TEST_CASE("attached root = clamped root following the same pose", "[fiber][ends]") {
  FiberSpec f = make_fiber(1.0, 16, 1.0, 0.2, {0.1, 0.2}, 0.4);
  f.root.kind = EndKind::clamped;
  f.root.amplitude = {0.05, -0.02};
  f.root.angle_amplitude = 0.3;
  f.root.frequency = 2.0;
  Config clamped = one_fiber(f);
  clamped.gravity = {0, -1};
  clamped.substeps = 3;
  Config attached = clamped;
  attached.fibers[0].root.kind = EndKind::attached;
  FiberSystem a(clamped), b(attached);
  const double dt = 2.5 * bending_dt_limit(f);
  const double w = 2 * std::numbers::pi * 2.0;
  std::vector<EndPose> poses(1);
  // Sub-steps interpolate the attached pose linearly: compare at coarse steps with a law that the
  // interpolation reproduces closely, and with one sub-step exactly.
  Config clamped1 = clamped, attached1 = attached;
  clamped1.substeps = attached1.substeps = 1;
  FiberSystem a1(clamped1), b1(attached1);
  const double dt1 = 0.8 * bending_dt_limit(f);
  for (int n = 0; n < 400; ++n) {
    const double t = (n + 1) * dt1;
    poses[0].position = Vec2(0.1, 0.2) + Vec2(0.05, -0.02) * std::sin(w * t);
    const double ang = 0.4 + 0.3 * std::sin(w * t);
    poses[0].direction = Vec2(std::cos(ang), std::sin(ang));
    a1.advance(dt1);
    b1.advance(dt1, {}, poses);
  }
  double diff = 0;
  for (std::size_t i = 0; i < a1.positions().size(); ++i)
    diff = std::max(diff, std::abs(a1.positions()[i] - b1.positions()[i]));
  CHECK(diff < 1e-12);
  CHECK((a1.root_load(0).force - b1.root_load(0).force).norm() < 1e-9);
  CHECK(a1.root_load(0).moment == Approx(b1.root_load(0).moment).epsilon(1e-9));
  // With sub-steps: the pose is interpolated between t^n and t^(n+1).
  for (int n = 0; n < 100; ++n) {
    const double t = (n + 1) * dt;
    poses[0].position = Vec2(0.1, 0.2) + Vec2(0.05, -0.02) * std::sin(w * t);
    const double ang = 0.4 + 0.3 * std::sin(w * t);
    poses[0].direction = Vec2(std::cos(ang), std::sin(ang));
    a.advance(dt);
    b.advance(dt, {}, poses);
  }
  diff = 0;
  for (std::size_t i = 0; i < a.positions().size(); ++i)
    diff = std::max(diff, std::abs(a.positions()[i] - b.positions()[i]));
  CHECK(diff < 1e-4);
  CHECK(b.positions()[0] == Approx(poses[0].position.x()).epsilon(1e-14));
}

TEST_CASE("clamped root moving by a law carries the fiber along", "[fiber][ends]") {
  // A slow transverse oscillation of the clamp; damping removes the start-up transient. The
  // fiber then follows quasi-statically, bent by its damping load c v per unit length: the tip
  // lags by c v L^4 / (8 gamma) (cantilever under a uniform load).
  FiberSpec f = make_fiber(1.0, 16, 1.0, 1.0);
  f.root.kind = EndKind::clamped;
  f.root.amplitude = {0, 0.1};
  f.root.frequency = 0.05;
  f.damping = 3.0;
  Config c = one_fiber(f);
  FiberSystem sys(c);
  const double dt = 0.9 * bending_dt_limit(f);
  while (sys.time() < 3.0) sys.advance(dt);
  const auto x = sys.positions(0);
  const double w = 2 * std::numbers::pi * 0.05;
  const double y_root = 0.1 * std::sin(w * sys.time());
  const double v_root = 0.1 * w * std::cos(w * sys.time());
  CHECK(x[1] == Approx(y_root).epsilon(1e-12));
  const double lag = y_root - x[33];
  INFO("tip lag " << lag << ", quasi-static estimate " << 3.0 * v_root / 8);
  CHECK(lag == Approx(3.0 * v_root / 8).epsilon(0.1));
}

TEST_CASE("root mass: the root load's response to the root's acceleration", "[fiber][ends]") {
  // A straight attached fiber at rest in gravity; one step with the root moved by delta along
  // the fiber and one across it. The load's change must be -mass delta / h^2, and along a
  // straight inextensible fiber the mass is the whole fiber's. The linearisation leaves out
  // bending's dependence on the root, a stiffness k ~ 2 gamma / ds^3 against m_0 / h^2 across
  // the fiber: 12 % of the lateral response at half the bending limit, 0.5 % at the tenth taken.
  const double rho = 1.1, length = 0.125;
  FiberSpec f = make_fiber(length, 62, rho, 1e-4, {0.3, 0.2}, 1.2);
  f.root.kind = EndKind::attached;
  Config c = one_fiber(f);
  c.gravity = {0, -1};
  const double dt = 0.1 * bending_dt_limit(f);
  const Vec2 tau(std::cos(1.2), std::sin(1.2)), nrm(-tau.y(), tau.x());
  std::vector<EndPose> pose(1);
  pose[0].position = Vec2(0.3, 0.2);
  pose[0].direction = tau;
  FiberSystem base(c);
  for (int n = 0; n < 5; ++n) base.advance(dt, {}, pose);
  const double delta = 1e-9;
  for (const Vec2& dir : {tau, nrm}) {
    FiberSystem ref = base, moved = base;
    ref.advance(dt, {}, pose);
    std::vector<EndPose> p = pose;
    p[0].position += delta * dir;
    moved.advance(dt, {}, p);
    const Vec2 change = moved.root_load(0).force - ref.root_load(0).force;
    const Vec2 predicted = -(ref.root_load(0).mass * dir) * delta / (dt * dt);
    CHECK((change - predicted).norm() < 0.02 * predicted.norm());
  }
  const Eigen::Matrix2d m = base.root_load(0).mass;
  CHECK(tau.dot(m * tau) == Approx(rho * length).epsilon(0.01));
  CHECK(nrm.dot(m * nrm) == Approx(rho * length / 62 / 2).epsilon(0.01));
  CHECK(base.root_load(0).accel.norm() < 1e-6);
}
