// What a fiber scene describes, as plain data: each fiber's geometry, material, end conditions
// or prescribed motion, the repulsion between fibers and the probes. config.cpp fills it from
// the [fiber] table of a scene; tests and benchmarks fill it directly. Angles are in radians here
// (the scene gives degrees). Lengths, times and masses are in the scene's consistent units.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace fiber {

using Vec2 = Eigen::Vector2d;

// Condition at one end of a fiber. s = 0 is the root, s = L the tip.
enum class EndKind {
  free,      // T = 0, X_ss = 0, X_sss = 0
  clamped,   // position and direction X_s given (by the law below, possibly moving)
  hinged,    // position given, X_ss = 0
  attached,  // clamped to a solid surface point; position and direction handed in each step
};
const char* end_kind_name(EndKind k);

// Position and direction of a supported end over time:
//   p(t)     = position + velocity t + amplitude sin(2 pi frequency t + phase)
//   theta(t) = angle + angular_velocity t + angle_amplitude sin(2 pi frequency t + phase)
// The direction is (cos theta, sin theta), the tangent X_s in the direction of increasing s.
struct EndLaw {
  EndKind kind = EndKind::free;
  Vec2 position = Vec2::Zero();
  double angle = 0;
  // When not given, position and angle are those of the fiber's end at t = 0.
  bool has_position = false, has_angle = false;
  Vec2 velocity = Vec2::Zero();
  Vec2 amplitude = Vec2::Zero();
  double angular_velocity = 0;
  double angle_amplitude = 0;
  double frequency = 0;
  double phase = 0;
  // attached: the solid body and the surface point (body's reference configuration) that holds
  // the root; the coupler resolves them.
  std::string body;
  Vec2 point = Vec2::Zero();

  bool is_supported() const { return kind != EndKind::free; }
  Vec2 position_at(double t) const;
  double angle_at(double t) const;
};

// A fiber whose markers follow a law instead of the equation of motion.
enum class MotionKind {
  dynamic,      // the equation of motion (the default)
  fixed,        // markers stay where they start
  translating,  // X(s, t) = X(s, 0) + velocity t
  rotating,     // rigid rotation of the initial shape about `center` at `angular_velocity`
  beating,      // tangent angle psi(s, t) = angle + amplitude sin(2 pi f t - 2 pi s / wavelength + phase)
};
const char* motion_kind_name(MotionKind k);

struct MotionLaw {
  MotionKind kind = MotionKind::dynamic;
  Vec2 velocity = Vec2::Zero();  // translating
  Vec2 center = Vec2::Zero();    // rotating
  double angular_velocity = 0;   // rotating [rad / time]
  double frequency = 0;          // beating
  double amplitude = 0;          // beating [rad]
  double wavelength = 0;         // beating; 0 = infinite (the whole fiber flaps rigidly)
  double phase = 0;              // beating [rad]
};

enum class ShapeKind {
  straight,  // from `position` along `angle`
  arc,       // tangent angle grows as angle + curvature s
  points,    // marker positions given (uniform arclength)
};

struct FiberSpec {
  std::string name;
  std::string key;  // where it was defined, for messages: "fiber.fiber[2]"
  double length = 1;
  int segments = 16;
  double density = 1;  // rho': line density in excess of the displaced fluid's [mass / length]
  double bending = 0;  // gamma: bending rigidity [force length^2]
  double damping = 0;  // viscous damping per unit length [force time / length^2]
  Vec2 position = Vec2::Zero();  // X(0) at t = 0
  double angle = 0;               // X_s(0) at t = 0
  ShapeKind shape = ShapeKind::straight;
  double curvature = 0;           // arc
  std::vector<Vec2> points;       // points: segments + 1 positions
  EndLaw root, tip;               // root: s = 0; tip: s = L
  MotionLaw motion;

  double ds() const { return length / segments; }
  bool is_prescribed() const { return motion.kind != MotionKind::dynamic; }
};

// Fiber-fiber repulsion (paper Eq. 11-12): W_r = k / (2 r^2) for r < cutoff between markers of
// different fibers; F_r = -dW_r/dX is a force per unit length (step.cpp says how it is applied
// so that action = reaction).
struct RepulsionSpec {
  bool is_enabled = false;
  double stiffness = 0;  // k [force length^2 / length]
  double cutoff = 0;     // half a fluid grid cell in the paper
};

// A probe: position, tension and curvature at arclength s of one fiber, written each step.
struct ProbeSpec {
  std::string name;
  int fiber = 0;
  double s = 0;
};

struct Config {
  std::vector<FiberSpec> fibers;
  RepulsionSpec repulsion;
  Vec2 gravity = Vec2::Zero();
  int substeps = 1;                  // fiber steps per time step of the scene
  double tension_tolerance = 1e-12;  // Newton stop: max | |d|^2/ds^2 - 1 |
  int tension_iterations = 8;        // Newton iterations at most (1 = a single linear solve)
  double stretch_limit = 1e-4;       // health: max | |X_s| - 1 | that stops the run
  std::vector<ProbeSpec> probes;
  double probe_interval = 0;         // time between rows of the probe and load files; 0 = every step
  std::string file;                  // scene file, for messages
};

}  // namespace fiber
