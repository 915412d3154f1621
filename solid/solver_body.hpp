// Internal: the per-body data of the Solver (equation map, element data, state vectors),
// shared by the solver's translation units (solid/*.cpp of the Solver). Not part of the API.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "solver.hpp"

namespace solid {

// A prescribed dof: u = value(t) from a constraint, or that of another prescribed dof (a
// periodic image of a prescribed node).
struct Prescribed {
  int dof = -1;
  int constraint = -1;  // index into spec.constraints, or -1
  int component = 0;
  int follow = -1;  // dof whose displacement this one copies
};

struct Solver::Body {
  BodySpec spec;
  int index = 0;
  std::vector<ElementGeometry> geo;
  std::vector<int> material;        // per element
  std::vector<double> rho_inertia;  // per element: rho_s - rho_f
  std::vector<double> f_cpl;        // coupling force of the current step: an impulse over it
  std::vector<double> mass_row;     // per dof: row sum of M (zero: massless dof)
  // The weight of a force acting as an impulse over the step in dof d's trapezoidal residual
  // (2 with mass, 1 on a massless dof; assembly.cpp), and the step's velocity v^(n+1) of dof d at
  // the iterate: s (x - x^n) / dt - [mass] v^n. Only for the trapezoidal rule: advance() refuses
  // the users of these (coupled iterations, root masses) with other Newmark parameters.
  double impulse_weight(std::size_t d) const { return mass_row[d] > 0 ? 2.0 : 1.0; }
  double step_velocity(std::size_t d, double dt) const {
    return impulse_weight(d) * (u[d] - u_old[d]) / dt - (mass_row[d] > 0 ? v_old[d] : 0.0);
  }
  std::vector<int> eq;              // per dof: equation, -1 when prescribed
  std::vector<Prescribed> prescribed;
  std::vector<std::array<int, 36>> kmap;  // per element: index into the matrix values
  std::vector<double> X;                  // reference positions
  std::vector<double> u, v, ma;           // state: displacements, velocities, M a (Newmark)
  std::vector<double> x;                  // positions X + u, kept in step with u
  std::vector<double> u_old, v_old;       // state at the start of the step
  std::vector<double> f_ext, q, r;        // last assembly: loads, internal force, residual
  std::vector<double> r_0;                // ... the residual without the coupling force
  std::vector<double> contact;            // contact force on the nodes (physical)
  Vec2 contact_bodies{0, 0};  // its sum from the other bodies (no planes, no self-contact)
  std::vector<double> det_f;              // per element, last assembly
  std::vector<double> dirichlet_step;     // pending increment of the prescribed dofs
  std::vector<double> abs_q, abs_floor;   // assembly scratch: scales of the residual
  std::vector<double> abs_ku;             // ... and |K| |u| of the last matrix assembly
  // Loads: constant part (gravity) and per-load nodal coefficients.
  std::vector<double> gravity;
  std::vector<std::vector<std::pair<int, double>>> load_dofs;  // per spec.loads entry
  double min_edge = 0;
  bool is_elastic() const { return spec.kind == BodyKind::elastic; }
  void sync_positions() {
    for (std::size_t d = 0; d < x.size(); ++d) x[d] = X[d] + u[d];
  }
};

// The contact terms of one Newton iteration (contact_solve.cpp): the candidate slots, each with
// its row of B = dg/dx on the free equations and the gap shift B_p du_p of a pending prescribed
// increment; the largest violation (penetration or open active gap); the residual R + B^T lambda.
struct Solver::ContactLinearisation {
  std::vector<int> candidates;                             // slot indices
  std::vector<std::vector<std::pair<int, double>>> rows;  // per candidate: (equation, dg/dx)
  std::vector<double> gap_shift;                           // per candidate
  double worst_gap = 0;
  int active = 0;  // active slots
  Eigen::VectorXd residual;
};

}  // namespace solid
