// The sparse direct solver of the Newton iterations: one symbolic analysis for the fixed
// pattern, a numeric factorisation per iteration. Eigen's simplicial LDL^T (AMD ordering) by
// default; CHOLMOD's supernodal Cholesky on request when the build has it (FSI_SOLID_CHOLMOD),
// falling back to LDL^T for a matrix that is not positive definite. LDL^T is the default as the
// faster of the two on the meshes of this project (solid/README.md, Performance). Matrices are
// given by their lower triangle.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

namespace solid {

class LinearSolver {
 public:
  enum class Backend { automatic, cholmod, ldlt };  // automatic: LDL^T
  explicit LinearSolver(Backend backend = Backend::automatic);
  ~LinearSolver();
  void analyze(const Eigen::SparseMatrix<double>& lower);
  // False when the matrix is singular (LDL^T pivot below 1e-13 of the largest) or cannot be
  // factorised.
  bool factorize(const Eigen::SparseMatrix<double>& lower);
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  // The backend of the last factorisation: "cholmod-supernodal" or "simplicial-ldlt".
  std::string backend() const;
  static bool has_cholmod();

 private:
  struct Impl;
  std::unique_ptr<Impl> m;
};

}  // namespace solid
