// The approximately factored Crank-Nicolson solve: one tridiagonal sweep per grid line and
// direction (factored_solver.hpp).
#include "factored_solver.hpp"

#include <algorithm>
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

}  // namespace

FactoredSolver::FactoredSolver(const Operator1D& f, const Operator1D& s, double sigma)
    : FactoredSolver(f, s, sigma, MPI_COMM_NULL, 0, s.n, 0) {}

FactoredSolver::FactoredSolver(const Operator1D& f, const Operator1D& s, double sigma,
                               MPI_Comm comm, int lo, int hi, int pad)
    : m_f(make_line(f, sigma)), m_s(make_line(s, sigma)), m_sigma(sigma), m_comm(comm) {
  FSI_ASSERT(sigma > 0);
  FSI_ASSERT(lo <= hi && pad >= 0);
  const int n = m_s.n;
  m_k0 = std::max(lo, pad) - pad;
  m_k1 = std::max(hi - pad, m_k0);
  FSI_ASSERT(m_k1 <= n);
  m_off = std::max(lo, pad) - lo;
  m_buf.assign(std::size_t(m_f.n) * (hi - lo), 0.0);
  m_tmp.assign(m_f.n, 0.0);
  if (comm != MPI_COMM_NULL) {
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    // The rows next to this rank's unknown rows belong to the neighbouring ranks (every rank
    // holds at least one row).
    if (m_k1 > m_k0 && m_k0 > 0) m_below = rank - 1;
    if (m_k1 > m_k0 && m_k1 < n) m_above = rank + 1;
    m_prev.assign(m_f.n, 0.0);
    m_next.assign(m_f.n, 0.0);
    m_ends.assign(2 * std::size_t(m_f.n), 0.0);
  }
}

// -sigma (I - L_f / sigma)(I - L_s / sigma) x = b: the contiguous lines solve
// (I - L_f / sigma) w = -b / sigma, then the other direction (I - L_s / sigma) x = w. Each block
// of contiguous lines is eliminated along the other direction while still in cache, so that
// only the back substitution takes a second pass over the array. Along s, row k's forward step
// is x_k = (x_k - l_k x_(k-1)) / p_k (x_0 / p_0), its back step x_k -= g_k x_(k+1).
void FactoredSolver::solve() {
  const int nf = m_f.n, n = m_s.n, m = m_k1 - m_k0;
  const std::size_t w = nf;
  const double scale = -1.0 / m_sigma;
  const Line& S = m_s;
  double* x = m_buf.data() + w * m_off;
  // Tags of their own (the fluid's halo exchange uses others on the same communicator).
  constexpr int kTagUp = 7411, kTagDown = 7412;
  auto eliminate = [&](int q) {
    const int k = m_k0 + q;
    double* xj = x + w * q;
    const double ip = S.inv_piv[k];
    if (k == 0) {
      for (int c = 0; c < nf; ++c) xj[c] *= ip;
      return;
    }
    const double* xm = q == 0 ? m_prev.data() : xj - w;
    const double l = S.sub[k];
    for (int c = 0; c < nf; ++c) xj[c] = (xj[c] - l * xm[c]) * ip;
  };
  // A rank with a rank below sweeps all its x lines first, so that every rank does its larger
  // part at once and only the elimination along y waits for the row from below.
  const bool wait = m_below != MPI_PROC_NULL;
  int q = 0;
  for (; q + 8 <= m; q += 8) {
    sweep_contiguous<8>(x + w * q, w, m_f, scale);
    if (!wait)
      for (int r = q; r < q + 8; ++r) eliminate(r);
  }
  for (; q < m; ++q) {
    sweep_contiguous<1>(x + w * q, w, m_f, scale);
    if (!wait) eliminate(q);
  }
  if (wait) {
    MPI_Recv(m_prev.data(), nf, MPI_DOUBLE, m_below, kTagUp, m_comm, MPI_STATUS_IGNORE);
    for (int r = 0; r < m; ++r) eliminate(r);
  }
  if (m_above != MPI_PROC_NULL) {
    MPI_Send(x + w * (m - 1), nf, MPI_DOUBLE, m_above, kTagUp, m_comm);
    MPI_Recv(m_next.data(), nf, MPI_DOUBLE, m_above, kTagDown, m_comm, MPI_STATUS_IGNORE);
  }
  for (int r = m - 1; r >= 0; --r) {
    const int k = m_k0 + r;
    if (k == n - 1) continue;
    double* xj = x + w * r;
    const double* xp = r == m - 1 ? m_next.data() : xj + w;
    const double g = S.gamma[k];
    for (int c = 0; c < nf; ++c) xj[c] -= g * xp[c];
  }
  if (m_below != MPI_PROC_NULL) MPI_Send(x, nf, MPI_DOUBLE, m_below, kTagDown, m_comm);
  if (!S.cyclic) return;
  // x -= (x_0 + ratio x_(n-1)) / denom z, x_0 and x_(n-1) from the ranks that hold them.
  const double* first = x;
  const double* last = m_k1 == n ? x + w * (n - 1 - m_k0) : nullptr;
  if (m_comm != MPI_COMM_NULL) {
    std::fill(m_ends.begin(), m_ends.end(), 0.0);
    if (m_k0 == 0 && m > 0) std::copy(x, x + nf, m_ends.begin());
    if (last && m > 0) std::copy(last, last + nf, m_ends.begin() + nf);
    MPI_Allreduce(MPI_IN_PLACE, m_ends.data(), 2 * nf, MPI_DOUBLE, MPI_SUM, m_comm);
    first = m_ends.data();
    last = m_ends.data() + nf;
  }
  for (int c = 0; c < nf; ++c) m_tmp[c] = (first[c] + S.ratio * last[c]) / S.denom;
  for (int r = 0; r < m; ++r) {
    double* xj = x + w * r;
    const double zj = S.z[m_k0 + r];
    for (int c = 0; c < nf; ++c) xj[c] -= zj * m_tmp[c];
  }
}

}  // namespace fluid
