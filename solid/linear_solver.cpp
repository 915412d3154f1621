// LinearSolver: CHOLMOD supernodal Cholesky (when built with it) or Eigen's simplicial LDL^T.
#include "linear_solver.hpp"

#include <Eigen/SparseCholesky>
#ifdef FSI_SOLID_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace solid {

namespace {

// An LDL^T pivot below this fraction of the largest is a zero pivot: the matrix is singular
// (a rigid motion without support), not merely ill-conditioned by a stiffness contrast.
constexpr double kSingularPivot = 1e-13;

}  // namespace

struct LinearSolver::Impl {
  Backend requested = Backend::automatic;
  bool use_cholmod = false;  // last factorisation
  bool ldlt_analyzed = false;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
#ifdef FSI_SOLID_CHOLMOD
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  bool llt_analyzed = false;
#endif
};

LinearSolver::LinearSolver(Backend backend) : m(std::make_unique<Impl>()) {
  m->requested = backend;
}
LinearSolver::~LinearSolver() = default;

bool LinearSolver::has_cholmod() {
#ifdef FSI_SOLID_CHOLMOD
  return true;
#else
  return false;
#endif
}

void LinearSolver::analyze(const Eigen::SparseMatrix<double>& lower) {
#ifdef FSI_SOLID_CHOLMOD
  if (m->requested == Backend::cholmod) {
    m->llt.analyzePattern(lower);
    m->llt_analyzed = true;
    // A new pattern: the LDL^T fallback's analysis (of an earlier pattern, if any) is stale;
    // factorising with its permutation read out of bounds (a crash when contact entries grew
    // the pattern after a fallback).
    m->ldlt_analyzed = false;
    return;
  }
#endif
  m->ldlt.analyzePattern(lower);
  m->ldlt_analyzed = true;
}

bool LinearSolver::factorize(const Eigen::SparseMatrix<double>& lower) {
#ifdef FSI_SOLID_CHOLMOD
  if (m->requested == Backend::cholmod) {
    m->llt.factorize(lower);
    if (m->llt.info() == Eigen::Success) {
      m->use_cholmod = true;
      return true;
    }
  }
#endif
  // Not positive definite (or no CHOLMOD): LDL^T, whose pivots also reveal a singular matrix.
  m->use_cholmod = false;
  if (!m->ldlt_analyzed) {
    m->ldlt.analyzePattern(lower);
    m->ldlt_analyzed = true;
  }
  m->ldlt.factorize(lower);
  if (m->ldlt.info() != Eigen::Success) return false;
  const Eigen::VectorXd D = m->ldlt.vectorD().cwiseAbs();
  return D.size() == 0 || D.minCoeff() > kSingularPivot * D.maxCoeff();
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& b) const {
#ifdef FSI_SOLID_CHOLMOD
  if (m->use_cholmod) return m->llt.solve(b);
#endif
  return m->ldlt.solve(b);
}

Eigen::MatrixXd LinearSolver::solve(const Eigen::MatrixXd& b) const {
#ifdef FSI_SOLID_CHOLMOD
  if (m->use_cholmod) return m->llt.solve(b);
#endif
  return m->ldlt.solve(b);
}

std::string LinearSolver::backend() const {
  return m->use_cholmod ? "cholmod-supernodal" : "simplicial-ldlt";
}

}  // namespace solid
