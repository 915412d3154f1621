// The solid side of the coupling (common/PROTOCOL.md, messages 1, 4 and 5): what the
// coupler needs from the solid solver and the one call that advances it. Layouts follow the
// protocol: node vectors are interleaved (x0, y0, x1, y1, ...); forces are ON THE SOLID.
//
// Use, per run:
//   1. once: geometry(b) for every body: reference nodes, counter-clockwise triangles, kind,
//      surface edges (body on the left of a -> b, outward normal (dy, -dx) / |b - a|).
//   2. once, then after every step: positions(b), velocities(b) at the current time.
//   3. every step: advance(dt, forces) with forces[b] the nodal forces on body b over the step
//      (the reaction of the immersed-solid forcing plus fiber-root loads, see point_load_on_edge;
//      empty for a body without coupling force, ignored for rigid bodies). Newmark + Newton
//      (+ contact) from t to t + dt; throws fsi::Error on failure (message names body, element or
//      node, step and time).
//   4. for fibers rooted on a body: surface_point(b, edge, s) gives the root's current position
//      and the outward normal of that edge (the fiber leaves the surface along it).
// Not thread-safe; no MPI (the solid program's main does the messaging).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "solver.hpp"

namespace solid {

// Reference geometry of one body, sent once.
struct BodyGeometry {
  std::string name;
  BodyKind kind = BodyKind::elastic;
  bool moving = false;                        // rigid bodies: prescribed motion
  std::vector<double> x_ref;                  // 2 per node
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise
  std::vector<std::array<int, 2>> surface;    // body on the left
};

// A material point on a surface edge, at the current time.
struct SurfacePoint {
  Vec2 position{0, 0};
  Vec2 normal{0, 0};  // unit outward normal of the edge
  std::array<int, 2> nodes{-1, -1};
};

// Equivalent nodal forces on an edge a -> b (current positions xa, xb) of a point force `force`
// and a moment `moment` (counter-clockwise positive) acting at p = (1 - s) xa + s xb (paper
// Sec. 3.2.3, Fig. 2): f_a = (1 - s) F + c, f_b = s F - c with the couple c = -M / |b - a|^2 *
// (-(yb - ya), xb - xa). Their resultant is F and their moment about p is M, exactly.
std::array<Vec2, 2> point_load_on_edge(const Vec2& xa, const Vec2& xb, double s, const Vec2& force,
                                       double moment);

class CouplingHook {
 public:
  explicit CouplingHook(Solver& solver) : m_solver(solver) {}
  int num_bodies() const { return m_solver.num_bodies(); }
  BodyGeometry geometry(int body) const;
  const std::vector<double>& positions(int body) const { return m_solver.positions(body); }
  const std::vector<double>& velocities(int body) const { return m_solver.velocities(body); }
  StepReport advance(double dt, const std::vector<std::vector<double>>& forces) {
    return m_solver.advance(dt, &forces);
  }
  // Throws fsi::Error for a body, edge or parameter out of range.
  SurfacePoint surface_point(int body, int edge, double s) const;
  // Adds the equivalent nodal forces of a point force and moment at (body, edge, s) to `nodal`
  // (layout as positions(body); resized if empty).
  void add_point_load(int body, int edge, double s, const Vec2& force, double moment,
                      std::vector<double>& nodal) const;

 private:
  Solver& m_solver;
};

}  // namespace solid
