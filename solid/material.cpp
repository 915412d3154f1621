// Saint Venant-Kirchhoff and compressible neo-Hookean materials in plane strain: energy, second
// Piola-Kirchhoff stress and consistent tangent (the equations are in material.hpp).
#include "material.hpp"

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace solid {

Material Material::from_young(MaterialModel model, double young, double poisson, double density) {
  Material m;
  m.model = model;
  m.mu = young / (2 * (1 + poisson));
  m.lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  m.bulk = young / (3 * (1 - 2 * poisson));
  m.density = density;
  return m;
}

double Material::young() const {
  const double lam = model == MaterialModel::neo_hookean ? bulk - 2 * mu / 3 : lambda;
  return mu * (3 * lam + 2 * mu) / (lam + mu);
}

double Material::poisson() const {
  const double lam = model == MaterialModel::neo_hookean ? bulk - 2 * mu / 3 : lambda;
  return lam / (2 * (lam + mu));
}

MaterialModel material_model_from_name(const std::string& name) {
  if (name == "saint-venant-kirchhoff") return MaterialModel::saint_venant_kirchhoff;
  if (name == "neo-hookean") return MaterialModel::neo_hookean;
  throw std::invalid_argument("unknown material model '" + name + "'");
}

std::string material_model_name(MaterialModel model) {
  return model == MaterialModel::neo_hookean ? "neo-hookean" : "saint-venant-kirchhoff";
}

namespace {

// Voigt index pairs (11, 22, 12).
constexpr int voigt_i[3] = {0, 1, 0};
constexpr int voigt_j[3] = {0, 1, 1};

Eigen::Matrix2d green_lagrange(const Eigen::Matrix2d& H) {
  return 0.5 * (H + H.transpose() + H.transpose() * H);
}

double svk(const Material& m, const Eigen::Matrix2d& H, Eigen::Vector3d* S, Eigen::Matrix3d* D) {
  const Eigen::Matrix2d E = green_lagrange(H);
  const double trE = E.trace();
  const double W = 0.5 * m.lambda * trE * trE + m.mu * (E.array() * E.array()).sum();
  if (S) {
    (*S)(0) = m.lambda * trE + 2 * m.mu * E(0, 0);
    (*S)(1) = m.lambda * trE + 2 * m.mu * E(1, 1);
    (*S)(2) = 2 * m.mu * E(0, 1);
  }
  if (D) {
    *D << m.lambda + 2 * m.mu, m.lambda, 0,  //
        m.lambda, m.lambda + 2 * m.mu, 0,    //
        0, 0, m.mu;
  }
  return W;
}

double neo_hookean(const Material& m, const Eigen::Matrix2d& H, Eigen::Vector3d* S,
                   Eigen::Matrix3d* D, bool with_energy) {
  const double J = 1 + H.trace() + H.determinant();
  if (!(J > 0)) {
    if (S) S->setConstant(std::numeric_limits<double>::quiet_NaN());
    if (D) D->setConstant(std::numeric_limits<double>::quiet_NaN());
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Eigen::Matrix2d C = Eigen::Matrix2d::Identity() + 2 * green_lagrange(H);
  const double I1 = C.trace() + 1;
  const double cbrt_j = std::cbrt(J);
  const double Jm23 = 1 / (cbrt_j * cbrt_j);
  // J^(-2/3) I1 - 3 and J - 1 evaluated without cancellation near the reference state.
  const double tr_e2 = 2 * green_lagrange(H).trace();  // I1 - 3
  const double jm1 = H.trace() + H.determinant();      // J - 1
  double W = std::numeric_limits<double>::quiet_NaN();
  if (with_energy) {
    const double jm23m1 = std::expm1(-2.0 / 3.0 * std::log1p(jm1));  // J^(-2/3) - 1
    W = 0.5 * m.mu * (jm23m1 * I1 + tr_e2) + 0.5 * m.bulk * jm1 * jm1;
  }
  const double detC = J * J;
  Eigen::Matrix2d Ci;
  Ci << C(1, 1) / detC, -C(0, 1) / detC, -C(1, 0) / detC, C(0, 0) / detC;
  const double G = m.mu, K = m.bulk;
  if (S) {
    // S = G J^(-2/3) [(I - C^-1) - (I1 - 3)/3 C^-1] + K J (J - 1) C^-1, with
    // I - C^-1 = (det C I - adj C) / det C written in E = (C - I)/2 so that no term is a
    // difference of numbers near 1: a stress of a small strain keeps its relative precision
    // (otherwise its absolute error is eps (G + K) and Newton cannot reduce a small residual).
    const Eigen::Matrix2d E = green_lagrange(H);
    Eigen::Matrix2d IminusCi;
    IminusCi << (2 * C(1, 1) * E(0, 0) - C(0, 1) * C(1, 0)) / detC, C(0, 1) / detC, C(1, 0) / detC,
        (2 * C(0, 0) * E(1, 1) - C(0, 1) * C(1, 0)) / detC;
    for (int a = 0; a < 3; ++a) {
      const int i = voigt_i[a], j = voigt_j[a];
      (*S)(a) = G * Jm23 * (IminusCi(i, j) - tr_e2 / 3 * Ci(i, j)) + K * J * jm1 * Ci(i, j);
    }
  }
  if (D) {
    const double c_iso = G * Jm23;
    const double c_pp = c_iso * 2.0 / 9.0 * I1 + K * (2 * J * J - J);  // C^-1 (x) C^-1
    const double c_ic = c_iso * 2.0 / 3.0 * I1 - 2 * K * (J * J - J);  // I_C
    for (int a = 0; a < 3; ++a) {
      const int i = voigt_i[a], j = voigt_j[a];
      const double dij = i == j ? 1.0 : 0.0;
      for (int b = 0; b < 3; ++b) {
        const int k = voigt_i[b], l = voigt_j[b];
        const double dkl = k == l ? 1.0 : 0.0;
        const double ic = 0.5 * (Ci(i, k) * Ci(j, l) + Ci(i, l) * Ci(j, k));
        (*D)(a, b) = c_iso * (-2.0 / 3.0) * (dij * Ci(k, l) + Ci(i, j) * dkl) +
                     c_pp * Ci(i, j) * Ci(k, l) + c_ic * ic;
      }
    }
  }
  return W;
}

}  // namespace

double evaluate_material(const Material& m, const Eigen::Matrix2d& H, Eigen::Vector3d* S,
                         Eigen::Matrix3d* D, bool with_energy) {
  return m.model == MaterialModel::neo_hookean ? neo_hookean(m, H, S, D, with_energy)
                                               : svk(m, H, S, D);
}

Eigen::Vector4d cauchy_stress(const Material& m, const Eigen::Matrix2d& H) {
  const Eigen::Matrix2d F = Eigen::Matrix2d::Identity() + H;
  Eigen::Vector3d Sv;
  evaluate_material(m, H, &Sv, nullptr);
  Eigen::Matrix2d S;
  S << Sv(0), Sv(2), Sv(2), Sv(1);
  const double J = F.determinant();
  const Eigen::Matrix2d sigma = F * S * F.transpose() / J;
  double S33 = 0;
  if (m.model == MaterialModel::neo_hookean) {
    const Eigen::Matrix2d C = F.transpose() * F;
    const double I1 = C.trace() + 1;
    S33 = m.mu * std::pow(J, -2.0 / 3.0) * (1 - I1 / 3) + m.bulk * (J * J - J);
  } else {
    S33 = m.lambda * green_lagrange(H).trace();
  }
  return {sigma(0, 0), sigma(1, 1), sigma(0, 1), S33 / J};
}

double von_mises(const Eigen::Vector4d& s) {
  const double a = s(0) - s(1), b = s(1) - s(3), c = s(3) - s(0);
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3 * s(2) * s(2));
}

}  // namespace solid
