// The linear triangle in total-Lagrangian form: reference shape-function gradients, deformation
// gradient, internal force, tangent (material + geometric) and mass. Inline: called in the
// assembly loop.
#pragma once

#include <Eigen/Core>
#include <array>

#include "material.hpp"

namespace solid {

// Reference geometry of one triangle: area A0 and constant gradients dN_a/dX_K.
struct ElementGeometry {
  double area = 0;
  double dn[3][2] = {};
};

inline ElementGeometry element_geometry(const double* X0, const double* X1, const double* X2) {
  ElementGeometry g;
  const double a2 = (X1[0] - X0[0]) * (X2[1] - X0[1]) - (X2[0] - X0[0]) * (X1[1] - X0[1]);
  g.area = 0.5 * a2;
  g.dn[0][0] = (X1[1] - X2[1]) / a2;
  g.dn[0][1] = (X2[0] - X1[0]) / a2;
  g.dn[1][0] = (X2[1] - X0[1]) / a2;
  g.dn[1][1] = (X0[0] - X2[0]) / a2;
  g.dn[2][0] = (X0[1] - X1[1]) / a2;
  g.dn[2][1] = (X1[0] - X0[0]) / a2;
  return g;
}

// Displacement gradient H_iK = sum_a u_ai dN_a/dX_K (constant over the element); F = I + H.
// Working with displacements keeps small strains free of the cancellation in x - X.
inline Eigen::Matrix2d displacement_gradient(const ElementGeometry& g, const double* u0,
                                             const double* u1, const double* u2) {
  const double* u[3] = {u0, u1, u2};
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < 2; ++i)
      for (int K = 0; K < 2; ++K) H(i, K) += u[a][i] * g.dn[a][K];
  return H;
}

// Internal force and tangent of one element, local dof order (x0, y0, x1, y1, x2, y2):
//   Q_ai = A0 sum_JK F_iJ S_JK dN_a/dX_K,
//   K_ai,bj = A0 [ (B^T D B)_ai,bj + delta_ij dN_a/dX_J S_JK dN_b/dX_K ],
// with the Green-Lagrange variation rows B = dE/dx:
//   dE11 = F_i1 dN_a/dX1,  dE22 = F_i2 dN_a/dX2,  2 dE12 = F_i1 dN_a/dX2 + F_i2 dN_a/dX1.
// u0, u1, u2 are the nodal displacements. Returns the strain energy A0 W (neo-Hookean: NaN
// without `with_energy`, evaluate_material); `ke` (row-major 6x6) may be null. `det_f` receives
// det F.
inline double element_internal(const Material& m, const ElementGeometry& g, const double* u0,
                               const double* u1, const double* u2, double fe[6], double* ke,
                               double* det_f, bool with_energy = true) {
  const Eigen::Matrix2d H = displacement_gradient(g, u0, u1, u2);
  const Eigen::Matrix2d F = Eigen::Matrix2d::Identity() + H;
  *det_f = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  Eigen::Vector3d S;
  Eigen::Matrix3d D;
  const double W = evaluate_material(m, H, &S, ke ? &D : nullptr, with_energy);
  double B[3][6];
  for (int a = 0; a < 3; ++a) {
    const double d1 = g.dn[a][0], d2 = g.dn[a][1];
    for (int i = 0; i < 2; ++i) {
      const int c = 2 * a + i;
      B[0][c] = F(i, 0) * d1;
      B[1][c] = F(i, 1) * d2;
      B[2][c] = F(i, 0) * d2 + F(i, 1) * d1;
    }
  }
  for (int c = 0; c < 6; ++c) fe[c] = g.area * (B[0][c] * S(0) + B[1][c] * S(1) + B[2][c] * S(2));
  if (ke) {
    double DB[3][6];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 6; ++c)
        DB[r][c] = D(r, 0) * B[0][c] + D(r, 1) * B[1][c] + D(r, 2) * B[2][c];
    double G[3][3];  // dN_a/dX . S . dN_b/dX
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        G[a][b] = g.dn[a][0] * (S(0) * g.dn[b][0] + S(2) * g.dn[b][1]) +
                  g.dn[a][1] * (S(2) * g.dn[b][0] + S(1) * g.dn[b][1]);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) {
        double k = B[0][r] * DB[0][c] + B[1][r] * DB[1][c] + B[2][r] * DB[2][c];
        if (r % 2 == c % 2) k += G[r / 2][c / 2];
        ke[6 * r + c] = g.area * k;
      }
  }
  return g.area * W;
}

// Consistent mass of one element per unit inertial density and per direction (3x3, same for x
// and y): A0/12 [2 1 1; 1 2 1; 1 1 2].
inline void element_mass(double area, double me[3][3]) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) me[a][b] = area / 12 * (a == b ? 2.0 : 1.0);
}

}  // namespace solid
