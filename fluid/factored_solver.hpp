// Approximately factored Helmholtz solve of Crank-Nicolson (Beam & Warming 1976; the form Kim &
// Moin 1985 use for the momentum equations):
//   (I - theta L_f)(I - theta L_s) Y = r   in place of   (I - theta (L_f + L_s)) Y = r,
// theta = nu dt / 2, L_f and L_s the 1D second-difference operators along the contiguous (f) and
// the other (s) direction, boundary rows included. The two differ by theta^2 L_f L_s Y. The
// predictor solves for the increment Y = u~ - u^n = O(dt), so the difference is O(dt^3) per step
// and the scheme stays second order in time. Each factor is a tridiagonal solve per grid line
// (cyclic, by Sherman-Morrison, along a periodic direction): O(N), no transform, and neither
// direction has to be uniform.
//
// Stability: for a Fourier mode with a = -theta lambda_f >= 0, b = -theta lambda_s >= 0 the
// increment-form step u~ = u^n + F^(-1) 2 theta L u^n multiplies it by
//   1 - 2 (a + b) / ((1 + a)(1 + b)) = (1 - a)(1 - b) / ((1 + a)(1 + b)),  |.| <= 1 at any dt.
#pragma once

#include <vector>

#include "fast_solver.hpp"

namespace fluid {

class FactoredSolver {
 public:
  // f, s: the operators along the contiguous and the other direction, as tridiagonal rows
  // (a, b, c: the boundary rows folded in) or Closure::periodic with rows whose a[0] and c[n-1]
  // are the wrap-around coefficients. sigma = 1 / theta = 2 / (nu dt).
  FactoredSolver(const Operator1D& f, const Operator1D& s, double sigma);

  int nt() const { return m_f.n; }
  int ns() const { return m_s.n; }
  double* data() { return m_buf.data(); }  // right-hand side in, solution out
  // FastSolver's convention: data() holds b of (L - sigma) x = b, here with L - sigma replaced by
  // -sigma (I - L_f / sigma)(I - L_s / sigma); solved in place.
  void solve();

  // The factors of I - L / sigma along one direction.
  struct Line {
    int n = 0;
    bool cyclic = false;
    std::vector<double> sub;              // sub-diagonal -a[k] / sigma
    std::vector<double> sub_over_piv;     // sub[k] * inv_piv[k]
    std::vector<double> inv_piv, gamma;   // Thomas factors (cyclic: of the modified matrix)
    // Cyclic: x = y - (y_0 + ratio y_(n-1)) / denom * z (Sherman-Morrison).
    std::vector<double> z;
    double ratio = 0, denom = 1;
  };

 private:
  Line m_f, m_s;
  double m_sigma = 0;
  std::vector<double> m_buf, m_tmp;
};

}  // namespace fluid
