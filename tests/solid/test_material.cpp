// Materials and the element kernel: stress = dW/dE, tangent = dS/dE and element stiffness =
// dQ/dx against central finite differences; small-strain limits.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include "element.hpp"
#include "material.hpp"

using namespace solid;

namespace {

// H = C^(1/2) - I for the symmetric C = I + 2E (so that W, S are functions of E only).
Eigen::Matrix2d stretch_from_e(const Eigen::Matrix2d& E) {
  const Eigen::Matrix2d C = Eigen::Matrix2d::Identity() + 2 * E;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(C);
  return es.eigenvectors() * es.eigenvalues().cwiseSqrt().asDiagonal() *
             es.eigenvectors().transpose() -
         Eigen::Matrix2d::Identity();
}

std::vector<Material> both_materials() {
  return {Material::from_young(MaterialModel::saint_venant_kirchhoff, 2.0e6, 0.4, 1000),
          Material::from_young(MaterialModel::neo_hookean, 2.0e6, 0.3, 1000)};
}

}  // namespace

TEST_CASE("stress is the derivative of the energy and the tangent that of the stress",
          "[material]") {
  Eigen::Matrix2d E;
  E << 0.08, -0.05, -0.05, -0.11;
  const double h = 1e-6;
  for (const Material& m : both_materials()) {
    INFO(material_model_name(m.model));
    Eigen::Vector3d S;
    Eigen::Matrix3d D;
    evaluate_material(m, stretch_from_e(E), &S, &D);
    const int I[3] = {0, 1, 0}, J[3] = {0, 1, 1};
    for (int a = 0; a < 3; ++a) {
      Eigen::Matrix2d dE = Eigen::Matrix2d::Zero();
      dE(I[a], J[a]) += h;
      if (I[a] != J[a]) dE(J[a], I[a]) += h;  // E12 and E21 together: d(2 E12) = 2h
      const double wp = evaluate_material(m, stretch_from_e(E + dE), nullptr, nullptr);
      const double wm = evaluate_material(m, stretch_from_e(E - dE), nullptr, nullptr);
      const double step = I[a] == J[a] ? h : 2 * h;
      CHECK((wp - wm) / (2 * step) == Approx(S(a)).epsilon(1e-6).margin(1e-9 * m.mu));
      Eigen::Vector3d Sp, Sm;
      evaluate_material(m, stretch_from_e(E + dE), &Sp, nullptr);
      evaluate_material(m, stretch_from_e(E - dE), &Sm, nullptr);
      const Eigen::Vector3d fd = (Sp - Sm) / (2 * step);
      for (int b = 0; b < 3; ++b) CHECK(fd(b) == Approx(D(b, a)).epsilon(1e-6).margin(1e-9 * m.mu));
    }
    CHECK((D - D.transpose()).norm() <= 1e-9 * D.norm());
  }
}

TEST_CASE("both materials reduce to linear elasticity at small strain", "[material]") {
  for (const Material& m : both_materials()) {
    INFO(material_model_name(m.model));
    Eigen::Vector3d S;
    Eigen::Matrix3d D;
    CHECK(evaluate_material(m, Eigen::Matrix2d::Zero(), &S, &D) == Approx(0).margin(1e-12));
    CHECK(S.norm() <= 1e-9);
    const double lam = m.model == MaterialModel::neo_hookean ? m.bulk - 2 * m.mu / 3 : m.lambda;
    CHECK(D(0, 0) == Approx(lam + 2 * m.mu).epsilon(1e-12));
    CHECK(D(0, 1) == Approx(lam).epsilon(1e-12));
    CHECK(D(2, 2) == Approx(m.mu).epsilon(1e-12));
    CHECK(std::abs(D(0, 2)) <= 1e-12 * m.mu);
    CHECK(m.young() == Approx(2.0e6).epsilon(1e-12));
  }
}

TEST_CASE("the stress of a tiny strain keeps its relative precision", "[material]") {
  // A strain of 1e-14 (a coupled run starting from rest): S must equal D0 : E to many digits,
  // not carry an absolute round-off of eps (G + K) from differences of numbers near 1.
  Eigen::Matrix2d H0;
  H0 << 0.3, 0.7, -0.2, 0.5;
  for (const Material& m : both_materials()) {
    INFO(material_model_name(m.model));
    Eigen::Vector3d S0, S;
    Eigen::Matrix3d D0;
    evaluate_material(m, Eigen::Matrix2d::Zero(), &S0, &D0);
    for (double scale : {1e-14, 1e-10, 1e-6}) {
      INFO("scale " << scale);
      const Eigen::Matrix2d H = scale * H0;
      const Eigen::Vector3d e(H(0, 0), H(1, 1), H(0, 1) + H(1, 0));  // linearised E (Voigt)
      evaluate_material(m, H, &S, nullptr);
      const Eigen::Vector3d linear = D0 * e;
      CHECK((S - linear).norm() <= 1e-5 * linear.norm());
    }
  }
}

TEST_CASE("neo-Hookean energy is undefined for an inverted element", "[material]") {
  const Material m = both_materials()[1];
  Eigen::Matrix2d H;  // F = diag(1, -0.5)
  H << 0, 0, 0, -1.5;
  CHECK(std::isnan(evaluate_material(m, H, nullptr, nullptr)));
}

TEST_CASE("element stiffness is the derivative of the internal force", "[material][element]") {
  const double X[3][2] = {{0.1, 0.2}, {1.3, 0.0}, {0.4, 1.1}};
  const double x0[3][2] = {{0.02, 0.05}, {0.2, 0.3}, {-0.2, 0.1}};  // displacements
  const ElementGeometry g = element_geometry(X[0], X[1], X[2]);
  REQUIRE(g.area > 0);
  for (const Material& m : both_materials()) {
    INFO(material_model_name(m.model));
    double x[3][2];
    std::copy(&x0[0][0], &x0[0][0] + 6, &x[0][0]);
    double fe[6], ke[36], J;
    element_internal(m, g, x[0], x[1], x[2], fe, ke, &J);
    REQUIRE(J > 0);
    const double h = 1e-6;
    double kmax = 0;
    for (double k : ke) kmax = std::max(kmax, std::abs(k));
    for (int c = 0; c < 6; ++c) {
      double fp[6], fm[6];
      x[c / 2][c % 2] += h;
      element_internal(m, g, x[0], x[1], x[2], fp, nullptr, &J);
      x[c / 2][c % 2] -= 2 * h;
      element_internal(m, g, x[0], x[1], x[2], fm, nullptr, &J);
      x[c / 2][c % 2] += h;
      for (int r = 0; r < 6; ++r)
        CHECK((fp[r] - fm[r]) / (2 * h) == Approx(ke[6 * r + c]).margin(1e-7 * kmax));
    }
    // Internal force: the nodal forces of one element balance (sum zero) and its energy is
    // W A0 with Q = dW/dx.
    double sx = 0, sy = 0;
    for (int a = 0; a < 3; ++a) {
      sx += fe[2 * a];
      sy += fe[2 * a + 1];
    }
    CHECK(std::abs(sx) + std::abs(sy) <= 1e-9 * kmax);
    for (int c = 0; c < 6; ++c) {
      double f[6];
      x[c / 2][c % 2] += h;
      const double wp = element_internal(m, g, x[0], x[1], x[2], f, nullptr, &J);
      x[c / 2][c % 2] -= 2 * h;
      const double wm = element_internal(m, g, x[0], x[1], x[2], f, nullptr, &J);
      x[c / 2][c % 2] += h;
      CHECK((wp - wm) / (2 * h) == Approx(fe[c]).margin(1e-7 * kmax));
    }
  }
}
