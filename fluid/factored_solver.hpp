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
//
// On several ranks (the fluid's slabs of rows, x fastest): the lines along x are whole on each
// rank and swept by all ranks at once; the lines along y are solved rank after rank, each
// eliminating its rows once the rank below has sent its last eliminated row, and substituting
// back once the rank above has sent its first solved row (one row of x unknowns per message and
// direction): that part, about a third of the solve, does not run in parallel. Every operation
// on a value is that of the one-rank solve, so the result is bit-identical.
#pragma once

#include <mpi.h>

#include <vector>

#include "fast_solver.hpp"

namespace fluid {

class FactoredSolver {
 public:
  // f, s: the operators along the contiguous and the other direction, as tridiagonal rows
  // (a, b, c: the boundary rows folded in) or Closure::periodic with rows whose a[0] and c[n-1]
  // are the wrap-around coefficients. sigma = 1 / theta = 2 / (nu dt).
  FactoredSolver(const Operator1D& f, const Operator1D& s, double sigma);
  // On the slabs of rows: f along x, s along y, whose unknowns are the global rows [pad, rows);
  // this rank holds the rows [lo, hi) of `comm` (a padded row is returned as zero).
  FactoredSolver(const Operator1D& f, const Operator1D& s, double sigma, MPI_Comm comm, int lo,
                 int hi, int pad);

  int nt() const { return m_f.n; }
  int ns() const { return m_s.n; }  // the s direction's unknowns (all ranks)
  // Right-hand side in, solution out: one rank, nt() x ns(); on slabs, the rows [lo, hi).
  double* data() { return m_buf.data(); }
  std::size_t size() const { return m_buf.size(); }
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
  // The rows of s this rank solves: [m_k0, m_k1), from row m_off of the buffer; the ranks below
  // and above (MPI_PROC_NULL at the ends, or when no unknown row borders this rank's).
  int m_k0 = 0, m_k1 = 0, m_off = 0;
  MPI_Comm m_comm = MPI_COMM_NULL;
  int m_below = MPI_PROC_NULL, m_above = MPI_PROC_NULL;
  std::vector<double> m_prev, m_next, m_ends;
};

}  // namespace fluid
