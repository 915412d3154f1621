// The solid model as plain data: bodies (mesh, materials per region, constraints, loads, rigid
// motion), contact pairs, rigid planes and solver settings. Built by read_config() from a scene
// or directly in code (tests); the Solver takes it by value.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "material.hpp"
#include "mesh.hpp"

namespace solid {

using Vec2 = std::array<double, 2>;

// Time (dynamic analysis) or load factor (static analysis, 0 -> 1 over the load steps) profile
// that multiplies a load or a prescribed displacement.
struct TimeFunction {
  enum class Kind { constant, ramp, sine };
  Kind kind = Kind::constant;
  double ramp_time = 0;  // ramp: linear from 0 to 1 over [0, ramp_time], then 1
  double frequency = 0;  // sine: sin(2 pi f t + phase)
  double phase = 0;
  double operator()(double t) const;
};

struct Constraint {
  enum class Type { fixed, displacement, periodic };
  Type type = Type::fixed;
  std::string boundary;     // edge set or node set of the mesh
  bool x = true, y = true;  // constrained components
  Vec2 displacement{0, 0};  // displacement: u = displacement * time(t)
  TimeFunction time;
  // periodic: every node of `boundary` follows the node of `partner` at X - shift, i.e.
  // u(X) = u(X - shift). shift_given false: shift = centroid(boundary) - centroid(partner).
  std::string partner;
  bool shift_given = false;
  Vec2 shift{0, 0};
};

struct Load {
  enum class Type { traction, point };
  Type type = Type::traction;
  std::string boundary;  // traction: edge set; dead load per unit reference length
  Vec2 value{0, 0};      // traction [force/length] or point force [force]
  Vec2 point{0, 0};      // point: reference position; applied at the nearest node
  TimeFunction time;
};

// Prescribed rigid motion: x(t) = c + d(t) + R(theta(t)) (X - c), with
// d(t) = velocity t + amplitude sin(2 pi f t + phase), theta(t) = omega t + angle sin(2 pi f t +
// phase).
struct RigidMotion {
  Vec2 center{0, 0};
  Vec2 velocity{0, 0};
  Vec2 amplitude{0, 0};
  double omega = 0;
  double angle = 0;
  double frequency = 0;
  double phase = 0;
};

enum class BodyKind { elastic, rigid };

struct BodySpec {
  std::string name;
  BodyKind kind = BodyKind::elastic;
  Mesh mesh;
  std::vector<Material> materials;  // one per mesh.region_names entry (elastic bodies)
  std::vector<Constraint> constraints;
  std::vector<Load> loads;
  RigidMotion motion;           // rigid bodies
  Vec2 initial_velocity{0, 0};  // elastic bodies: uniform initial velocity
  bool gravity = true;          // gravity acts on this body
};

// Frictionless contact between two bodies: the nodes of `slave` against the surface of `master`
// and, when two_way, the nodes of master against the surface of slave.
struct ContactPair {
  int slave = -1, master = -1;
  bool two_way = true;
};

// Rigid plane: bodies stay on the side its normal points to.
struct ContactPlane {
  Vec2 point{0, 0};
  Vec2 normal{0, 1};        // unit
  std::vector<int> bodies;  // elastic bodies that touch it
};

enum class Analysis { dynamic, statics };

// Where a dynamic step's Newton starts (newmark.cpp, Solver::predict): at x^n, or at the
// Newmark step taken with the acceleration of the step's start.
enum class Predictor { none, acceleration };

// Halvings of a failed step at most (Settings::step_cutbacks): dt / 1024, and at most 2^10 parts
// of one step when every part fails whole.
constexpr int kMaxStepCutbacks = 10;

struct Settings {
  Analysis analysis = Analysis::dynamic;
  int load_steps = 1;        // static analysis
  double fluid_density = 0;  // rho_f: inertia and gravity use rho_s - rho_f
  Vec2 gravity{0, 0};
  double newton_tolerance = 1e-10;  // on ||R|| relative to the force scale
  int newton_max_iterations = 30;
  // A dynamic step that fails (Newton, det F <= 0, not finite) is taken again as two half steps,
  // each of which may be halved again, at most this many times (down to dt / 2^step_cutbacks).
  int step_cutbacks = 3;
  double contact_tolerance = 1e-10;  // on the gap, relative to the smallest element edge
  bool keep_factor = true;  // a dynamic step may start with the last step's factor (newton.cpp)
  Predictor predictor = Predictor::none;  // opt-in (solid/README.md, "The predictor")
  // The Newmark parameters of the paper's Eq. 13-14. The trapezoidal rule (1/4, 1/2, the
  // paper's choice) keeps every mode's energy; gamma > 1/2 with 2 beta >= gamma damps the energy
  // of a mode of angular frequency omega at the rate (gamma - 1/2) omega^2 dt to leading order
  // (solid/README.md, "Newmark's parameters").
  double newmark_beta = 0.25;
  double newmark_gamma = 0.5;
  bool trapezoidal() const { return newmark_beta == 0.25 && newmark_gamma == 0.5; }
};

struct Model {
  Settings settings;
  std::vector<BodySpec> bodies;
  std::vector<ContactPair> contacts;
  std::vector<ContactPlane> planes;
};

}  // namespace solid
