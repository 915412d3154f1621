// Eigenmodes (paper Eq. 28): |K - omega^2 M| = 0 about the reference configuration, with K the
// linear stiffness (tangent at u = 0) and M the mass of the inertial density rho_s - rho_f, on
// the free equations. Lowest modes by Spectra's shift-invert Lanczos about a shift sigma.
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

namespace {

// Spectra's Lanczos: iteration cap, relative tolerance of the eigenvalues (near round-off, the
// modes are validated against beam theory to many digits), and the extra Krylov vectors beyond
// the 2 nev + 1 it needs at least (more converge the lowest modes in fewer restarts).
constexpr int kLanczosMaxIterations = 1000;
constexpr double kLanczosTolerance = 1e-12;
constexpr int kLanczosExtraVectors = 20;

// y = (K - sigma M)^-1 x through one sparse factorisation (lower triangles stored).
class ShiftInvertOp {
 public:
  using Scalar = double;
  ShiftInvertOp(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M)
      : m_K(K), m_M(M) {}
  Eigen::Index rows() const { return m_K.rows(); }
  Eigen::Index cols() const { return m_K.cols(); }
  void set_shift(double sigma) {
    const Eigen::SparseMatrix<double> A = m_K - sigma * m_M;
    m_solver.analyze(A);
    if (!m_solver.factorize(A))
      fsi::fail(
          "modes: K - sigma M is singular for sigma = {} (a body without constraint "
          "has zero-frequency modes; give a negative shift)",
          sigma);
  }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, m_K.rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, m_K.rows());
    y = m_solver.solve(Eigen::VectorXd(x));
  }

 private:
  const Eigen::SparseMatrix<double>& m_K;
  const Eigen::SparseMatrix<double>& m_M;
  LinearSolver m_solver;
};

}  // namespace

// M += the consistent mass of the inertial density rho_s - rho_f of every element that has one,
// on the values of M, a matrix of m_matrix's pattern (its lower triangle).
void Solver::add_mass(Eigen::SparseMatrix<double>& M) const {
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
      const double rho = B.rho_inertia[e];
      if (!(rho > 0)) continue;
      double me[3][3];
      element_mass(B.geo[e].area, me);
      const auto& map = B.kmap[e];
      for (int r = 0; r < 6; ++r)
        for (int c = r % 2; c < 6; c += 2)
          if (map[6 * r + c] >= 0) M.valuePtr()[map[6 * r + c]] += rho * me[r / 2][c / 2];
    }
  }
}

Modes Solver::modes(int count, double shift) const {
  if (count < 1) fsi::fail("modes: need at least one mode, got {}", count);
  Eigen::SparseMatrix<double> K = m_matrix, M = m_matrix;
  std::fill_n(K.valuePtr(), K.nonZeros(), 0.0);
  std::fill_n(M.valuePtr(), M.nonZeros(), 0.0);
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    const double zero[2] = {0, 0};
    for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
      if (!(B.rho_inertia[e] > 0))
        fsi::fail(
            "modes need a positive inertial density rho_s - rho_f; body '{}' element "
            "{} has {}",
            B.spec.name, e, B.rho_inertia[e]);
      double fe[6], ke[36], J;
      element_internal(B.spec.materials[B.material[e]], B.geo[e], zero, zero, zero, fe, ke, &J);
      const auto& map = B.kmap[e];
      for (int k = 0; k < 36; ++k)
        if (map[k] >= 0) K.valuePtr()[map[k]] += ke[k];
    }
  }
  add_mass(M);
  const int n = m_neq;
  const int nev = std::min(count, n - 1);
  const int ncv = std::min(n, std::max(2 * nev + 1, nev + kLanczosExtraVectors));
  ShiftInvertOp op(K, M);
  Spectra::SparseSymMatProd<double, Eigen::Lower> bop(M);
  Spectra::SymGEigsShiftSolver<ShiftInvertOp, Spectra::SparseSymMatProd<double, Eigen::Lower>,
                               Spectra::GEigsMode::ShiftInvert>
      solver(op, bop, nev, ncv, shift);
  solver.init();
  solver.compute(Spectra::SortRule::LargestMagn, kLanczosMaxIterations, kLanczosTolerance);
  if (solver.info() != Spectra::CompInfo::Successful)
    fsi::fail("modes: the eigensolver did not converge for {} modes", nev);
  const Eigen::VectorXd lam = solver.eigenvalues();
  const Eigen::MatrixXd vec = solver.eigenvectors();
  std::vector<int> order(lam.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return lam[a] < lam[b]; });
  Modes out;
  for (int k : order) {
    out.omega.push_back(std::sqrt(std::max(lam[k], 0.0)));
    std::vector<std::vector<double>> shape;
    for (const auto& bp : m_bodies) {
      std::vector<double> s(bp->X.size(), 0.0);
      if (bp->is_elastic())
        for (std::size_t d = 0; d < s.size(); ++d)
          if (bp->eq[d] >= 0) s[d] = vec(bp->eq[d], k);
      shape.push_back(std::move(s));
    }
    out.shapes.push_back(std::move(shape));
  }
  return out;
}

}  // namespace solid
