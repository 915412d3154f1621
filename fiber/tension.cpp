// The tension equation: the discrete form of the paper's pseudo-Poisson equation (Eq. 17), solved
// for the segment tensions T_j of one fiber so that every segment keeps its length ds at t^(n+1).
#include <algorithm>
#include <cmath>

#include "system.hpp"

namespace fiber {

// With the predictor Xhat (all explicit forces) the update is
//   X^(n+1)_i = Xhat_i + c_i (T_i r_i - T_{i-1} r_{i-1}),   c_i = theta h^2 / (m_i ds),
// where r_j = X^n_{j+1} - X^n_j and T_j r_j / ds is the force of segment j's tension (the
// discrete (T X_s)_s ds; c_i = 0 for law-driven markers). Each segment d_j = X_{j+1} - X_j then
// satisfies
//   d_j(T) = dhat_j + c_{j+1} r_{j+1} T_{j+1} - (c_j + c_{j+1}) r_j T_j + c_j r_{j-1} T_{j-1},
// and the constraint g_j = |d_j(T)|^2 - ds^2 = 0 (Eq. 10 for every segment). Its Newton step
//   2 c_j (d_j.r_{j-1}) dT_{j-1} - 2 (c_j + c_{j+1}) (d_j.r_j) dT_j + 2 c_{j+1} (d_j.r_{j+1}) dT_{j+1} = -g_j
// is tridiagonal (Thomas algorithm, O(segments)). Started from T = 0 it is the discrete Eq. 17:
// expanding |dhat_j|^2 gives the terms rho'/2 (X_s.X_s)_tt (with |X_s^(n+1)| = 1 substituted,
// which pulls a drifted length back to ds), -rho' X_ts.X_ts and X_s.(forces)_s. Here the
// iteration starts from the previous step's tension and repeats until max |g_j| / ds^2 <= tol,
// which removes the O(h^4) remainder that a single linear solve leaves, plus one more step:
// the tension then carries no error of the stopping test (T is known only to about
// tol ds^2 / c, which grows as 1/h^2), and end loads balance to round-off.
void FiberSystem::solve_tension(int k) {
  Fiber& s = m_fibers[k];
  const int n = s.segments;
  const std::size_t o = s.offset;
  const double ds = s.ds;
  const double ds2 = ds * ds;
  const double* x = m_x.data() + 2 * o;
  const double* xh = m_x_new.data() + 2 * o;  // predictor on entry, X^(n+1) on exit
  const double* c = m_coef.data() + o;
  double* r = m_ref.data() + 2 * s.seg_offset;
  double* T = m_tension.data() + s.seg_offset;
  double* lo = m_lo.data() + s.seg_offset;
  double* di = m_di.data() + s.seg_offset;
  double* up = m_up.data() + s.seg_offset;
  double* rhs = m_rhs.data() + s.seg_offset;
  // X^(n+1) is built in m_x_star (free now that the forces are done) from the predictor.
  double* xn = m_x_star.data() + 2 * o;

  for (int j = 0; j < n; ++j) {
    r[2 * j] = x[2 * j + 2] - x[2 * j];
    r[2 * j + 1] = x[2 * j + 3] - x[2 * j + 1];
  }

  // Round-off floor of g_j: positions carry errors of about eps |X|, so |d_j|^2 - ds^2 cannot be
  // resolved below about eps |X| ds; asking for less would only spend iterations.
  double extent = 0;
  for (int i = 0; i <= n; ++i) extent = std::max({extent, std::abs(xh[2 * i]), std::abs(xh[2 * i + 1])});
  const double tol = std::max(m_config.tension_tolerance, 64 * 2.2e-16 * (1 + extent / ds));
  const int max_it = m_config.tension_iterations;
  int it = 0;
  bool is_polished = false;
  for (;;) {
    // X^(n+1)(T)
    for (int i = 0; i <= n; ++i) {
      double fx = 0, fy = 0;
      if (i < n) {
        fx += T[i] * r[2 * i];
        fy += T[i] * r[2 * i + 1];
      }
      if (i > 0) {
        fx -= T[i - 1] * r[2 * i - 2];
        fy -= T[i - 1] * r[2 * i - 1];
      }
      xn[2 * i] = xh[2 * i] + c[i] * fx;
      xn[2 * i + 1] = xh[2 * i + 1] + c[i] * fy;
    }
    // Residual and Jacobian.
    double worst = 0;
    for (int j = 0; j < n; ++j) {
      const double dx = xn[2 * j + 2] - xn[2 * j], dy = xn[2 * j + 3] - xn[2 * j + 1];
      const double g = dx * dx + dy * dy - ds2;
      worst = std::max(worst, std::abs(g));
      rhs[j] = -g;
      di[j] = -2 * (c[j] + c[j + 1]) * (dx * r[2 * j] + dy * r[2 * j + 1]);
      lo[j] = j > 0 ? 2 * c[j] * (dx * r[2 * j - 2] + dy * r[2 * j - 1]) : 0.0;
      up[j] = j < n - 1 ? 2 * c[j + 1] * (dx * r[2 * j + 2] + dy * r[2 * j + 3]) : 0.0;
    }
    const bool is_converged = !(worst > tol * ds2);
    if (it >= max_it || (is_converged && is_polished)) break;
    is_polished = is_converged;
    // Thomas algorithm: forward elimination (up and rhs overwritten), back substitution.
    up[0] /= di[0];
    rhs[0] /= di[0];
    for (int j = 1; j < n; ++j) {
      const double m = 1.0 / (di[j] - lo[j] * up[j - 1]);
      up[j] *= m;
      rhs[j] = (rhs[j] - lo[j] * rhs[j - 1]) * m;
    }
    for (int j = n - 2; j >= 0; --j) rhs[j] -= up[j] * rhs[j + 1];
    for (int j = 0; j < n; ++j) T[j] += rhs[j];
    ++it;
  }
  s.tension_iterations = it;
  m_times.tension_solves += it;
  std::copy(xn, xn + 2 * (n + 1), m_x_new.data() + 2 * o);
}

}  // namespace fiber
