// Diagnostics of the fluid state: CFL number, discrete divergence, kinetic energy, point
// samples, wall shear stress (paper Eq. 30), vorticity and cell-centred velocities for output.
// On a fluid split over ranks each is collective and returns the whole grid's value on every
// rank, except the two output fields (vorticity, centred velocity): this rank's rows.
#pragma once

#include <array>
#include <limits>
#include <vector>

#include "solver.hpp"

namespace fluid {

// A maximum and where it is (cell indices and coordinates of the cell centre).
struct Extremum {
  double value = 0;
  int i = 0, j = 0;
  double x = 0, y = 0;
};

// dt max over cells of (max|u| on the cell's x faces / w_x + max|v| on its y faces / w_y).
// A NaN anywhere makes the value NaN.
Extremum cfl(const Solver& s, double dt);
// max over cells of |D u| = |du/dx + dv/dy| (per unit time).
Extremum max_divergence(const Solver& s);
// (rho/2) integral of |u - ref|^2 over x in [x_lo, x_hi], each face's control volume counted
// by its centre.
double kinetic_energy(const Solver& s, double x_lo = -std::numeric_limits<double>::infinity(),
                      double x_hi = std::numeric_limits<double>::infinity(),
                      std::array<double, 2> ref = {0, 0});
// Bilinear interpolation of u (q = 0), v (1) or p (2) at (x, y), clamped to the grid.
double sample(const Solver& s, int q, double x, double y);
// Wall shear stress tau = mu t . (grad u + grad u^T) . n along a wall side, n pointing into the
// fluid and t along +x (bottom, top) or +y (left, right); the tangential derivative of the normal
// velocity vanishes on a flat wall, so tau = mu d(u_t)/dn from the quadratic through the wall
// value and the first two interior values. Returns one value per tangential cell position
// (positions: the face coordinates of the tangential component along the wall).
std::vector<double> wall_shear(const Solver& s, Side side, std::vector<double>* position = nullptr);
// The u-face column nearest to x: the section a flow_rate line x = x0 is measured on (ties go to
// the lower index; on a periodic x the last face, at the domain's end, is face 0).
int nearest_u_column(const Solver& s, double x);
// The volume flux per unit depth through u-face column i, exact on the MAC grid:
//   Q_i = sum_j u(i, j) w_y(j)
// (the flux the discrete divergence balances, so the same in every column of a steady flow
// without sources; inside an immersed body it counts the forced velocity, i.e. the body's).
double flow_rate(const Solver& s, int i);
// Vorticity dv/dx - du/dy at the cell centres (nx per row of this rank, i fastest): mean of the
// four corners.
void vorticity(const Solver& s, std::vector<double>& out);
// Cell-centred velocity (nx per row of this rank, i fastest).
void centred_velocity(const Solver& s, std::vector<double>& uc, std::vector<double>& vc);

}  // namespace fluid
