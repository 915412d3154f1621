// Hyperelastic materials for plane strain (C33 = 1): strain energy W, second Piola-Kirchhoff
// stress S = dW/dE (paper Eq. 8) and the material tangent D = dS/dE, in Voigt order
// (11, 22, 12) with engineering shear (D maps (dE11, dE22, 2 dE12) to dS).
#pragma once

#include <Eigen/Core>
#include <string>

namespace solid {

enum class MaterialModel { saint_venant_kirchhoff, neo_hookean };

struct Material {
  MaterialModel model = MaterialModel::saint_venant_kirchhoff;
  double mu = 0;       // shear modulus: Lamé mu (SVK), G (neo-Hookean)
  double lambda = 0;   // Lamé lambda (SVK only)
  double bulk = 0;     // bulk modulus K (neo-Hookean only)
  double density = 0;  // rho_s in the reference configuration

  // From Young's modulus and Poisson's ratio (3D constants; plane strain follows from C33 = 1).
  static Material from_young(MaterialModel model, double young, double poisson, double density);
  // Small-strain Young's modulus and Poisson's ratio of this material (3D constants).
  double young() const;
  double poisson() const;
};

MaterialModel material_model_from_name(const std::string& name);  // throws std::invalid_argument
std::string material_model_name(MaterialModel model);

// Saint Venant-Kirchhoff (Eq. 6):  W = lambda/2 (tr E)^2 + mu tr(E^2),
//   S = lambda tr(E) I + 2 mu E,  D = lambda I (x) I + 2 mu I_sym.
// Compressible neo-Hookean (Eq. 7) in plane strain, with the 3D invariants of C = diag(C2D, 1):
//   I1 = C11 + C22 + 1,  J = det F,  W = G/2 (J^(-2/3) I1 - 3) + K/2 (J - 1)^2,
//   S = G J^(-2/3) (I - I1/3 C^-1) + K (J^2 - J) C^-1,
//   D = G J^(-2/3) [-2/3 (I (x) C^-1 + C^-1 (x) I) + 2/9 I1 C^-1 (x) C^-1 + 2/3 I1 I_C]
//       + K (2 J^2 - J) C^-1 (x) C^-1 - 2 K (J^2 - J) I_C,
//   with (I_C)_IJKL = (Cinv_IK Cinv_JL + Cinv_IL Cinv_JK) / 2.
// (Eq. 7 prints "tr C^ - 2"; with C33 = 1 the unstressed reference needs the 3D form above.)
// H = F - I is the 2x2 in-plane displacement gradient (E = (H + H^T + H^T H) / 2 without the
// cancellation of F^T F - I at small strain). Returns W per unit reference volume; S and D are
// written when the pointers are non-null. J <= 0 gives a NaN energy for neo-Hookean. Without
// `with_energy` the neo-Hookean W is not evaluated (the assembly needs S and D only; that
// energy takes two transcendental functions of its own) and NaN is returned; St.Venant-
// Kirchhoff returns W either way.
double evaluate_material(const Material& m, const Eigen::Matrix2d& H, Eigen::Vector3d* S,
                         Eigen::Matrix3d* D, bool with_energy = true);

// Cauchy stress (11, 22, 12, 33) from H = F - I: sigma = F S F^T / J, sigma33 = S33 / J with
// the out-of-plane S33 that plane strain implies.
Eigen::Vector4d cauchy_stress(const Material& m, const Eigen::Matrix2d& H);
// von Mises equivalent of a plane-strain Cauchy stress (11, 22, 12, 33).
double von_mises(const Eigen::Vector4d& sigma);

}  // namespace solid
