// The fast solver of fast_solver.hpp on a grid split in slabs of rows over the ranks of a
// communicator: the same problem (L_t + L_s - sigma) x = r, the same transforms and Thomas
// sweeps, with FFTW's MPI transposes in between so that every 1D transform and every tridiagonal
// line is whole on one rank.
//
// The data are the grid's rows (y) split in blocks: rank r holds rows [r B, min((r+1) B, rows)),
// B = ceil(rows / P), each row whole and contiguous (x fastest). `rows` counts the fluid's cell
// rows; an unknown set with one row fewer (the v faces between two walls) is padded with a
// dummy first row (`pad` = 1), so that every field of the fluid is split the same way.
//
// Transform along x (t = x, the rows; s = y):
//   1. transform every local row (FFTW r2r along t),
//   2. transpose rows x t to t x rows, kept locally as rows x (local t) (FFTW_MPI_TRANSPOSED_OUT),
//   3. per local wavenumber k: Thomas along s (or the s transform, when y is periodic),
//      vectorised across k as in FastSolver,
//   4. transpose back (FFTW_MPI_TRANSPOSED_IN), 5. back-transform every local row.
// Transform along y (t = y, split over the ranks; s = x):
//   1. transpose rows x s to s x rows: every y line whole on a rank, 2. transform the y lines,
//   3. transpose back, kept as s x (local rows), 4. Thomas along x per local wavenumber (or the
//   x transform when x is periodic), 5.-7. the transposes and the back-transform in reverse.
// A stretched t (both directions stretched: t = y) takes FastSolver's dense eigenvector products
// in place of the FFTs, on the same lines. Every arithmetic operation on a value is that of
// FastSolver, so the result equals the one-rank solve up to the transforms' round-off.
#pragma once

#include <fftw3-mpi.h>
#include <mpi.h>

#include <memory>
#include <vector>

#include "fast_solver.hpp"

namespace fluid {

// The block split of the rows over P ranks (FFTW's: blocks of ceil(rows / P)).
struct RowSplit {
  int rows = 0, block = 0;
  int lo = 0, hi = 0;  // this rank's rows [lo, hi)
  int rank = 0, ranks = 1;
  int lo_of(int r) const;
  int hi_of(int r) const;
};
// Throws fsi::InputError, naming the nearest rank counts that fit, when the last rank would get
// fewer than min_rows rows.
RowSplit split_rows(int rows, int ranks, int rank, int min_rows = 1);

class SlabSolver {
 public:
  // t, s: as for FastSolver. t_axis: 0 when t runs along x (the rows), 1 when along y. rows: the
  // split row count (the cell rows); the y direction's unknowns are rows [pad, rows).
  SlabSolver(const Operator1D& t, const Operator1D& s, double sigma, int t_axis, int rows,
             int pad, MPI_Comm comm);
  ~SlabSolver();
  SlabSolver(const SlabSolver&) = delete;
  SlabSolver& operator=(const SlabSolver&) = delete;

  const RowSplit& split() const { return m_split; }
  int row_length() const { return m_nx; }  // unknowns per row (x)
  // This rank's rows [split().lo, split().hi), x fastest: right-hand side in, solution out.
  // A padded row (global row < pad) is ignored on input and returned as zero.
  double* data() { return m_buf; }
  void solve();
  // The transposes so far: their count, wall seconds and the bytes this rank sent to others.
  long transposes() const { return m_transposes; }
  double transpose_seconds() const { return m_transpose_seconds; }
  double transpose_bytes() const { return m_transpose_bytes; }
  // For a singular problem: the solution's weighted mean (weights per s index, whole) is zero.
  void set_mean_weights(const std::vector<double>& w) { m_weights = w; }

 private:
  void lines();  // step 3 (t = x) or 4 (t = y): per local wavenumber, along s
  void t_forward();
  void t_backward();
  void transpose(fftw_plan p);

  int m_t_axis, m_pad, m_nx, m_nt, m_ns;
  RowSplit m_split;
  bool m_transform_s;
  double* m_buf = nullptr;
  double* m_work = nullptr;
  // Local transforms along t and along s (when transformed), forward and backward.
  fftw_plan m_t_fwd = nullptr, m_t_bwd = nullptr, m_s_fwd = nullptr, m_s_bwd = nullptr;
  std::unique_ptr<DenseTransform> m_dense_fwd, m_dense_bwd;  // see FastSolver
  double* m_t_lines = nullptr;                                // this rank's first t-line
  // The transposes: to_lines before the solve along s, from_lines after it (t = x); for t = y
  // also the pair around the y transforms.
  fftw_plan m_to_lines = nullptr, m_from_lines = nullptr, m_to_y = nullptr, m_from_y = nullptr;
  double m_norm = 1;
  int m_k0 = 0, m_nk = 0;  // the local wavenumbers [m_k0, m_k0 + m_nk) of the solve along s
  std::vector<double> m_lt, m_ls;
  std::vector<double> m_a, m_inv_piv, m_gamma, m_inv_eig;  // per (s, local k), k fastest
  std::vector<double> m_weights;
  int m_zero_col = -1;  // the local column of a singular problem's zero mode (-1: none here)
  MPI_Comm m_comm;
  long m_transposes = 0;
  double m_transpose_seconds = 0, m_transpose_bytes = 0;
  double m_bytes_per_transpose = 0;
};

}  // namespace fluid
