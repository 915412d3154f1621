// Direct fast solver for (L_t + L_s - sigma) x = r on a 2D array of unknowns, where L_t and L_s
// are the 1D second-difference operators along the two grid directions. Along a uniform transform
// direction t FFTW's real transforms (DFT for periodic, DCT/DST for the other closures)
// diagonalise L_t exactly; along a stretched one (not periodic) its own eigenvectors do, as
// dense products (eigen_transform). Either way the solve is exact to round-off. The other
// direction s may be stretched: it is solved by a tridiagonal (Thomas) sweep per wavenumber, or
// transformed too when it is periodic. Used for the pressure Poisson equation (sigma = 0) and for the
// Crank-Nicolson Helmholtz equations of the velocity components (sigma = 2 / (nu dt)).
#pragma once

#include <fftw3.h>

#include <memory>
#include <vector>

#include "dense_transform.hpp"

namespace fluid {

// How a 1D operator ends, seen from its unknowns.
//   dirichlet_node: the boundary value sits one spacing beyond the last unknown (zero there)
//   dirichlet_half / neumann_half: zero value / zero gradient half a spacing beyond it
enum class Closure { periodic, dirichlet_node, dirichlet_half, neumann_half };

// A 1D operator along one direction: n unknowns. In a uniform transform direction only n, h and
// the closures matter (a, b, c empty); a stretched transform direction gives its rows. In a tridiagonal direction row k reads a[k] x[k-1] + b[k] x[k] + c[k] x[k+1]
// (a[0] = c[n-1] = 0), whatever the grid and the boundary rows; `singular` says the operator
// annihilates constants (pure Neumann), so that the sigma = 0 problem is solved up to a constant.
struct Operator1D {
  int n = 0;
  Closure lo = Closure::neumann_half, hi = Closure::neumann_half;
  double h = 0;                   // spacing (transform direction)
  std::vector<double> a, b, c;    // tridiagonal rows (tridiagonal direction)
  bool singular = false;
};

// Eigenvalues of the uniform 1D operator with the given closures, in the order of the FFTW
// transform that diagonalises it (halfcomplex order for periodic).
std::vector<double> eigenvalues(int n, double h, Closure lo, Closure hi);

// The real transform pair that diagonalises that operator: backward(forward(x)) = norm x.
struct TransformPair {
  fftw_r2r_kind fwd, bwd;
  double norm;
};
TransformPair transform_pair(int n, Closure lo, Closure hi);

// The eigen-decomposition of a transform direction given by its rows (a stretched direction):
// L = B diag(lambda) F with F B = I, F and B n x n row-major (the forward and the backward
// transform). L must be similar to a symmetric matrix through a diagonal one (a[k+1] c[k] > 0);
// a singular L gets its zero eigenvalue exactly.
struct EigenTransform {
  std::vector<double> lambda, fwd, bwd;
};
EigenTransform eigen_transform(const Operator1D& t);

// The Thomas factors of (a, b + lambda_k - sigma, c) along s for the wavenumbers k = k0 + col,
// col in [0, cols), stored per (j, col) with col fastest: inverse pivots and gammas (resized).
// Columns with k < 0 (padded rows of a slab) stay zero. A singular problem's zero mode
// (sigma = 0, lambda_k = 0, s singular) gets a zero last inverse pivot, which picks one solution.
// Returns that mode's column, or -1.
int thomas_factors(const Operator1D& s, const std::vector<double>& lt, double sigma, int k0,
                   int cols, std::vector<double>& inv_piv, std::vector<double>& gamma);
// Forward elimination and back substitution on x[col + cols j], j in [0, ns), for the columns
// [col_first, cols), the right-hand side scaled by inv_norm: vectorised across the columns.
void thomas_sweep(double* x, int cols, int col_first, int ns, const double* a,
                  const double* inv_piv, const double* gamma, double inv_norm);
// Column `col` of x[col + cols j], j in [0, ns): its mean weighted by w[j] subtracted (the zero
// mode of a singular problem, whose solution is fixed up to a constant).
void remove_weighted_mean(double* x, int cols, int col, int ns, const std::vector<double>& w);

class FastSolver {
 public:
  // t: the transform direction's operator (uniform, or stretched with its rows); s: the other
  // one. When s.lo is periodic (t then uniform), s is transformed too. The unknowns are stored t-fastest: x[k + nt * j].
  FastSolver(const Operator1D& t, const Operator1D& s, double sigma);
  ~FastSolver();
  FastSolver(const FastSolver&) = delete;
  FastSolver& operator=(const FastSolver&) = delete;

  int nt() const { return m_nt; }
  int ns() const { return m_ns; }
  double* data() { return m_buf; }  // right-hand side in, solution out
  // Solve in place on data(). For sigma = 0 with a singular operator, the solution has zero
  // mean weighted by `weights` (per s-row) and by the t-direction's cell widths when given.
  void solve();
  // The three phases, for the benchmark of a bare solve.
  void forward();
  void tridiagonal();
  void backward();
  void set_mean_weights(const std::vector<double>& w) { m_weights = w; }
  // The forward or the backward t-transform is a matrix product (DenseTransform).
  bool dense() const { return m_dense_fwd || m_dense_bwd; }

 private:
  int m_nt, m_ns;
  bool m_transform_s;
  double* m_buf = nullptr;
  fftw_plan m_fwd = nullptr, m_bwd = nullptr;
  // The t-transforms as matrix products where FFTW has only its generic O(n^2) code for the
  // length (DenseTransform::preferred; not with s periodic, the 2D plan) or where t is stretched
  // (eigen_transform); null: FFTW's plans.
  std::unique_ptr<DenseTransform> m_dense_fwd, m_dense_bwd;
  double m_norm = 1;
  std::vector<double> m_a;                // sub-diagonal per s-row
  std::vector<double> m_inv_piv, m_gamma;  // Thomas factors per (k, j), k fastest
  std::vector<double> m_inv_eig;           // 2D transform: 1 / eigenvalue per (k, j)
  std::vector<double> m_weights;
  int m_zero_mode = -1;                    // index k of the t-mode whose s-problem is singular
};

}  // namespace fluid
