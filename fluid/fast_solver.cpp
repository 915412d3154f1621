// FFTW transforms + Thomas sweeps: the exact direct solver of the discrete Poisson and
// Helmholtz problems on the MAC grid.
#include "fast_solver.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <numbers>

#include "error.hpp"

namespace fluid {

TransformPair transform_pair(int n, Closure lo, Closure hi) {
  using C = Closure;
  if (lo == C::periodic && hi == C::periodic) return {FFTW_R2HC, FFTW_HC2R, double(n)};
  if (lo == C::dirichlet_node && hi == C::dirichlet_node)
    return {FFTW_RODFT00, FFTW_RODFT00, 2.0 * (n + 1)};
  if (lo == C::neumann_half && hi == C::neumann_half) return {FFTW_REDFT10, FFTW_REDFT01, 2.0 * n};
  if (lo == C::dirichlet_half && hi == C::dirichlet_half)
    return {FFTW_RODFT10, FFTW_RODFT01, 2.0 * n};
  if (lo == C::dirichlet_half && hi == C::neumann_half)
    return {FFTW_RODFT11, FFTW_RODFT11, 2.0 * n};
  if (lo == C::neumann_half && hi == C::dirichlet_half)
    return {FFTW_REDFT11, FFTW_REDFT11, 2.0 * n};
  fsi::fail("fluid::FastSolver: no real transform for this pair of closures");
}

int thomas_factors(const Operator1D& s, const std::vector<double>& lt, double sigma, int k0,
                   int cols, std::vector<double>& inv_piv, std::vector<double>& gamma) {
  const int ns = s.n;
  inv_piv.assign(std::size_t(cols) * ns, 0);
  gamma.assign(std::size_t(cols) * ns, 0);
  int zero_col = -1;
  for (int col = 0; col < cols; ++col) {
    const int k = k0 + col;
    if (k < 0) continue;
    const bool zero = sigma == 0.0 && lt[k] == 0.0 && s.singular;
    if (zero) zero_col = col;
    double gprev = 0;
    for (int j = 0; j < ns; ++j) {
      const double piv = s.b[j] + lt[k] - sigma - s.a[j] * gprev;
      const std::size_t q = col + std::size_t(cols) * j;
      const bool last = j == ns - 1;
      inv_piv[q] = (zero && last) ? 0.0 : 1.0 / piv;
      gamma[q] = last ? 0.0 : s.c[j] / piv;
      gprev = gamma[q];
    }
  }
  return zero_col;
}

void thomas_sweep(double* x, int cols, int col_first, int ns, const double* a,
                  const double* inv_piv, const double* gamma, double inv_norm) {
  for (int c = col_first; c < cols; ++c) x[c] *= inv_norm * inv_piv[c];
  for (int j = 1; j < ns; ++j) {
    double* xj = x + std::size_t(cols) * j;
    const double* xm = xj - cols;
    const double* ip = inv_piv + std::size_t(cols) * j;
    const double aj = a[j];
    for (int c = col_first; c < cols; ++c) xj[c] = (xj[c] * inv_norm - aj * xm[c]) * ip[c];
  }
  for (int j = ns - 2; j >= 0; --j) {
    double* xj = x + std::size_t(cols) * j;
    const double* xp = xj + cols;
    const double* g = gamma + std::size_t(cols) * j;
    for (int c = col_first; c < cols; ++c) xj[c] -= g[c] * xp[c];
  }
}

void remove_weighted_mean(double* x, int cols, int col, int ns, const std::vector<double>& w) {
  double sw = 0, s = 0;
  for (int j = 0; j < ns; ++j) {
    sw += w[j];
    s += w[j] * x[col + std::size_t(cols) * j];
  }
  const double mean = s / sw;
  for (int j = 0; j < ns; ++j) x[col + std::size_t(cols) * j] -= mean;
}

// lambda_k = -(4 / h^2) sin^2(theta_k / 2), theta_k the angle of mode k:
//   periodic 2 pi k / n, dirichlet_node pi (k+1) / (n+1), neumann_half pi k / n,
//   dirichlet_half pi (k+1) / n, mixed half closures pi (k + 1/2) / n.
std::vector<double> eigenvalues(int n, double h, Closure lo, Closure hi) {
  using C = Closure;
  const double pi = std::numbers::pi;
  std::vector<double> lam(n);
  for (int k = 0; k < n; ++k) {
    double theta;
    if (lo == C::periodic) {
      const int m = k <= n / 2 ? k : n - k;  // halfcomplex: index n-k holds mode k's sine part
      theta = 2 * pi * m / n;
    } else if (lo == C::dirichlet_node) {
      theta = pi * (k + 1) / (n + 1);
    } else if (lo == C::neumann_half && hi == C::neumann_half) {
      theta = pi * k / n;
    } else if (lo == C::dirichlet_half && hi == C::dirichlet_half) {
      theta = pi * (k + 1) / n;
    } else {
      theta = pi * (k + 0.5) / n;
    }
    const double s = std::sin(0.5 * theta);
    lam[k] = -4.0 * s * s / (h * h);
  }
  return lam;
}

// A stretched direction's L (rows a, b, c) is similar to the symmetric tridiagonal
//   S = D L D^-1,  D = diag(d),  d[k+1] / d[k] = sqrt(c[k] / a[k+1]),
// whose diagonal is b and whose off-diagonals are sqrt(a[k+1] c[k]). With S = Q diag(lambda) Q^T
// (Q orthogonal): L = (D^-1 Q) diag(lambda) (Q^T D), so F = Q^T D and B = D^-1 Q. For the
// pressure operator d^2 is proportional to the cell widths w: F's row of the zero eigenvalue is
// then proportional to w (the constant mode's coefficient is the w-weighted mean) and every other
// mode's backward image has zero w-weighted mean.
EigenTransform eigen_transform(const Operator1D& t) {
  const int n = t.n;
  if (n < 2 || int(t.a.size()) != n || int(t.b.size()) != n || int(t.c.size()) != n)
    fsi::fail("fluid::eigen_transform: {} unknowns with {} rows", n, t.b.size());
  std::vector<double> d(n, 1.0);
  Eigen::VectorXd diag(n), off(n - 1);
  for (int k = 0; k < n; ++k) diag[k] = t.b[k];
  for (int k = 0; k + 1 < n; ++k) {
    const double ac = t.a[k + 1] * t.c[k];
    if (!(ac > 0))
      fsi::fail("fluid::eigen_transform: rows {} and {} couple with signs that no diagonal scaling "
                "makes symmetric (a c = {})",
                k, k + 1, ac);
    off[k] = std::sqrt(ac);
    d[k + 1] = d[k] * std::sqrt(t.c[k] / t.a[k + 1]);
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es;
  es.computeFromTridiagonal(diag, off, Eigen::ComputeEigenvectors);
  if (es.info() != Eigen::Success) fsi::fail("fluid::eigen_transform: no eigen-decomposition");
  const Eigen::MatrixXd& q = es.eigenvectors();
  EigenTransform e;
  e.lambda.assign(es.eigenvalues().data(), es.eigenvalues().data() + n);
  if (t.singular) {
    // The constant's eigenvalue, zero to round-off: exactly zero, for the Thomas sweep's choice.
    int z = 0;
    for (int m = 1; m < n; ++m)
      if (std::abs(e.lambda[m]) < std::abs(e.lambda[z])) z = m;
    e.lambda[z] = 0.0;
  }
  e.fwd.resize(std::size_t(n) * n);
  e.bwd.resize(std::size_t(n) * n);
  for (int m = 0; m < n; ++m)
    for (int k = 0; k < n; ++k) {
      e.fwd[std::size_t(m) * n + k] = q(k, m) * d[k];
      e.bwd[std::size_t(k) * n + m] = q(k, m) / d[k];
    }
  return e;
}

FastSolver::FastSolver(const Operator1D& t, const Operator1D& s, double sigma)
    : m_nt(t.n), m_ns(s.n), m_transform_s(s.lo == Closure::periodic) {
  const std::size_t size = std::size_t(m_nt) * m_ns;
  m_buf = fftw_alloc_real(size);
  for (std::size_t q = 0; q < size; ++q) m_buf[q] = 0;
  if (!t.a.empty()) {
    // A stretched t: its eigenvectors as dense products (norm 1), Thomas along s.
    if (m_transform_s)
      fsi::fail("fluid::FastSolver: a stretched transform direction beside a periodic one");
    const EigenTransform et = eigen_transform(t);
    m_dense_fwd = std::make_unique<DenseTransform>(et.fwd, m_nt, m_ns, m_nt, false);
    m_dense_bwd = std::make_unique<DenseTransform>(et.bwd, m_nt, m_ns, m_nt, false);
    m_a = s.a;
    m_zero_mode = thomas_factors(s, et.lambda, sigma, 0, m_nt, m_inv_piv, m_gamma);
    return;
  }
  const TransformPair kt = transform_pair(m_nt, t.lo, t.hi);
  const std::vector<double> lt = eigenvalues(m_nt, t.h, t.lo, t.hi);
  // FFTW_ESTIMATE: the plan does not depend on timings, so two runs are bit-identical.
  if (m_transform_s) {
    const TransformPair ks = transform_pair(m_ns, s.lo, s.hi);
    m_fwd = fftw_plan_r2r_2d(m_ns, m_nt, m_buf, m_buf, ks.fwd, kt.fwd, FFTW_ESTIMATE);
    m_bwd = fftw_plan_r2r_2d(m_ns, m_nt, m_buf, m_buf, ks.bwd, kt.bwd, FFTW_ESTIMATE);
    m_norm = kt.norm * ks.norm;
    const std::vector<double> ls = eigenvalues(m_ns, s.h, s.lo, s.hi);
    m_inv_eig.assign(size, 0);
    for (int j = 0; j < m_ns; ++j) {
      for (int k = 0; k < m_nt; ++k) {
        const double e = lt[k] + ls[j] - sigma;
        // The constant mode of a singular problem: its coefficient is set to zero (zero mean).
        m_inv_eig[k + std::size_t(m_nt) * j] = (e == 0.0) ? 0.0 : 1.0 / (e * m_norm);
      }
    }
  } else {
    const int n[1] = {m_nt};
    fftw_r2r_kind kf[1] = {kt.fwd}, kb[1] = {kt.bwd};
    m_fwd = fftw_plan_many_r2r(1, n, m_ns, m_buf, nullptr, 1, m_nt, m_buf, nullptr, 1, m_nt, kf,
                               FFTW_ESTIMATE);
    m_bwd = fftw_plan_many_r2r(1, n, m_ns, m_buf, nullptr, 1, m_nt, m_buf, nullptr, 1, m_nt, kb,
                               FFTW_ESTIMATE);
    m_norm = kt.norm;
    m_dense_fwd = DenseTransform::if_preferred(kt.fwd, m_nt, m_ns, m_nt);
    m_dense_bwd = DenseTransform::if_preferred(kt.bwd, m_nt, m_ns, m_nt);
    // Thomas factors of (a, b + lambda_k - sigma, c) for every wavenumber k; the
    // normalisation of the transform pair is folded into the first pivot's right-hand side.
    m_a = s.a;
    m_zero_mode = thomas_factors(s, lt, sigma, 0, m_nt, m_inv_piv, m_gamma);
  }
  if (!m_fwd || !m_bwd) fsi::fail("fluid::FastSolver: FFTW could not plan the transforms");
}

FastSolver::~FastSolver() {
  if (m_fwd) fftw_destroy_plan(m_fwd);
  if (m_bwd) fftw_destroy_plan(m_bwd);
  fftw_free(m_buf);
}

void FastSolver::forward() {
  if (m_dense_fwd) m_dense_fwd->apply(m_buf);
  else fftw_execute(m_fwd);
}
void FastSolver::backward() {
  if (m_dense_bwd) m_dense_bwd->apply(m_buf);
  else fftw_execute(m_bwd);
}

// Per wavenumber k: a_j y_{j-1} + (b_j + lambda_k - sigma) y_j + c_j y_{j+1} = rhat_j / norm,
// forward elimination then back substitution, vectorised across k (k is contiguous).
void FastSolver::tridiagonal() {
  const int nt = m_nt, ns = m_ns;
  double* x = m_buf;
  if (m_transform_s) {
    const std::size_t size = std::size_t(nt) * ns;
    const double* e = m_inv_eig.data();
    for (std::size_t q = 0; q < size; ++q) x[q] *= e[q];
    return;
  }
  thomas_sweep(x, nt, 0, ns, m_a.data(), m_inv_piv.data(), m_gamma.data(), 1.0 / m_norm);
  // Remove the weighted mean of the singular mode's line (the t-mean of the solution).
  if (m_zero_mode >= 0 && !m_weights.empty()) remove_weighted_mean(x, nt, m_zero_mode, ns, m_weights);
}

void FastSolver::solve() {
  forward();
  tridiagonal();
  backward();
}

}  // namespace fluid
