// The approximately factored Crank-Nicolson solve: one tridiagonal sweep per grid line and
// direction (factored_solver.hpp).
#include "factored_solver.hpp"

#include <cstddef>

#include "error.hpp"

namespace fluid {
namespace {

// Thomas factors of the rows (l, d, u), l[0] = u[n-1] = 0: pivots p_0 = d_0,
// p_k = d_k - l_k g_(k-1), g_k = u_k / p_k. Forward y_k = (r_k - l_k y_(k-1)) / p_k, back
// x_k = y_k - g_k x_(k+1).
void factor(const std::vector<double>& l, const std::vector<double>& d,
            const std::vector<double>& u, FactoredSolver::Line& line) {
  const int n = line.n;
  line.sub = l;
  line.inv_piv.assign(n, 0);
  line.gamma.assign(n, 0);
  double g = 0;
  for (int k = 0; k < n; ++k) {
    const double p = d[k] - (k > 0 ? l[k] * g : 0.0);
    if (!(p != 0.0)) fsi::fail("fluid::FactoredSolver: zero pivot in row {} of {}", k, n);
    line.inv_piv[k] = 1.0 / p;
    g = k + 1 < n ? u[k] / p : 0.0;
    line.gamma[k] = g;
  }
  line.sub_over_piv.resize(n);
  for (int k = 0; k < n; ++k) line.sub_over_piv[k] = line.sub[k] * line.inv_piv[k];
}

// The rows of I - L / sigma along one direction, factored. A periodic direction's cyclic matrix
// M (corners alpha = M[0][n-1], beta = M[n-1][0]) is B + w v^T with w = (gam, 0.., beta),
// v = (1, 0.., alpha / gam), gam = -M[0][0]: B is tridiagonal, B z = w is solved once, and
// M^(-1) r = y - (v.y) / (1 + v.z) z with B y = r (Sherman-Morrison).
FactoredSolver::Line make_line(const Operator1D& op, double sigma) {
  FactoredSolver::Line line;
  const int n = op.n;
  line.n = n;
  if (n < 1 || int(op.a.size()) != n || int(op.b.size()) != n || int(op.c.size()) != n)
    fsi::fail("fluid::FactoredSolver: an operator of {} unknowns needs {} tridiagonal rows", n, n);
  std::vector<double> l(n), d(n), u(n);
  for (int k = 0; k < n; ++k) {
    l[k] = -op.a[k] / sigma;
    d[k] = 1.0 - op.b[k] / sigma;
    u[k] = -op.c[k] / sigma;
  }
  line.cyclic = op.lo == Closure::periodic;
  if (!line.cyclic) {
    l[0] = u[n - 1] = 0;
    factor(l, d, u, line);
    return line;
  }
  if (n < 3) fsi::fail("fluid::FactoredSolver: a periodic direction needs 3 unknowns, not {}", n);
  const double alpha = l[0], beta = u[n - 1], gam = -d[0];
  l[0] = u[n - 1] = 0;
  d[0] -= gam;
  d[n - 1] -= alpha * beta / gam;
  factor(l, d, u, line);
  std::vector<double> z(n, 0.0);
  z[0] = gam;
  z[n - 1] = beta;
  z[0] *= line.inv_piv[0];
  for (int k = 1; k < n; ++k) z[k] = (z[k] - line.sub[k] * z[k - 1]) * line.inv_piv[k];
  for (int k = n - 2; k >= 0; --k) z[k] -= line.gamma[k] * z[k + 1];
  line.z = z;
  line.ratio = alpha / gam;
  line.denom = 1.0 + z[0] + line.ratio * z[n - 1];
  return line;
}

// R lines along the contiguous direction at x, x + stride, ...: their recurrences interleaved,
// so that the R chains of dependent operations overlap; each chain's step is one multiply-add
// (y_k = r_k / p_k - (l_k / p_k) y_(k-1), the products precomputed). The right-hand side is
// scaled by `scale`.
template <int R>
void sweep_contiguous(double* x, std::size_t stride, const FactoredSolver::Line& L,
                      double scale) {
  const int n = L.n;
  const double* ip = L.inv_piv.data();
  const double* m = L.sub_over_piv.data();
  const double* g = L.gamma.data();
  double* p[R];
  for (int r = 0; r < R; ++r) p[r] = x + stride * r;
  double prev[R];
  for (int r = 0; r < R; ++r) prev[r] = p[r][0] *= scale * ip[0];
  for (int k = 1; k < n; ++k) {
    const double a = scale * ip[k], b = m[k];
    for (int r = 0; r < R; ++r) prev[r] = p[r][k] = a * p[r][k] - b * prev[r];
  }
  for (int k = n - 2; k >= 0; --k) {
    for (int r = 0; r < R; ++r) prev[r] = p[r][k] -= g[k] * prev[r];
  }
  if (!L.cyclic) return;
  const double* z = L.z.data();
  for (int r = 0; r < R; ++r) {
    const double fac = (p[r][0] + L.ratio * p[r][n - 1]) / L.denom;
    for (int k = 0; k < n; ++k) p[r][k] -= fac * z[k];
  }
}

// The lines along the other direction, x[c + cols j]: all columns at once (vectorised). The
// forward elimination of row j, once rows up to j hold their final right-hand side, ...
void eliminate_across(double* x, int cols, const FactoredSolver::Line& L, int j) {
  double* xj = x + std::size_t(cols) * j;
  const double ip = L.inv_piv[j];
  if (j == 0) {
    for (int c = 0; c < cols; ++c) xj[c] *= ip;
    return;
  }
  const double* xm = xj - cols;
  const double s = L.sub[j];
  for (int c = 0; c < cols; ++c) xj[c] = (xj[c] - s * xm[c]) * ip;
}

// ... and the back substitution of all rows (with the periodic correction).
void substitute_across(double* x, int cols, const FactoredSolver::Line& L, double* tmp) {
  const int n = L.n;
  const std::size_t w = cols;
  for (int j = n - 2; j >= 0; --j) {
    double* xj = x + w * j;
    const double* xp = xj + w;
    const double g = L.gamma[j];
    for (int c = 0; c < cols; ++c) xj[c] -= g * xp[c];
  }
  if (!L.cyclic) return;
  const double* last = x + w * (n - 1);
  for (int c = 0; c < cols; ++c) tmp[c] = (x[c] + L.ratio * last[c]) / L.denom;
  for (int j = 0; j < n; ++j) {
    double* xj = x + w * j;
    const double zj = L.z[j];
    for (int c = 0; c < cols; ++c) xj[c] -= zj * tmp[c];
  }
}

}  // namespace

FactoredSolver::FactoredSolver(const Operator1D& f, const Operator1D& s, double sigma)
    : m_f(make_line(f, sigma)), m_s(make_line(s, sigma)) {
  FSI_ASSERT(sigma > 0);
  m_buf.assign(std::size_t(m_f.n) * m_s.n, 0.0);
  m_tmp.assign(m_f.n, 0.0);
  m_sigma = sigma;
}

// -sigma (I - L_f / sigma)(I - L_s / sigma) x = b: the contiguous lines solve
// (I - L_f / sigma) w = -b / sigma, then the other direction (I - L_s / sigma) x = w. Each block
// of contiguous lines is eliminated along the other direction while still in cache, so that
// only the back substitution takes a second pass over the array.
void FactoredSolver::solve() {
  const int nf = m_f.n, ns = m_s.n;
  const std::size_t w = nf;
  const double scale = -1.0 / m_sigma;
  double* x = m_buf.data();
  int j = 0;
  for (; j + 8 <= ns; j += 8) {
    sweep_contiguous<8>(x + w * j, w, m_f, scale);
    for (int r = j; r < j + 8; ++r) eliminate_across(x, nf, m_s, r);
  }
  for (; j < ns; ++j) {
    sweep_contiguous<1>(x + w * j, w, m_f, scale);
    eliminate_across(x, nf, m_s, j);
  }
  substitute_across(x, nf, m_s, m_tmp.data());
}

}  // namespace fluid
