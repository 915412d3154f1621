// A real transform of one of FFTW's r2r kinds (or any given matrix) done as a matrix product, for the lengths where
// FFTW 3.3's planner (FFTW_ESTIMATE) takes its generic O(n^2) scalar code (an odd prime below
// 173, or such a factor: 101 rows of the vocal folds' channel at h = 0.01, 41 in 82, 123, 164):
// the same O(n^2) work, half of it saved by the matrix's symmetry and the rest vectorised across
// the lines. Each line's result depends on that line alone, so any split of the lines over
// ranks gives the same bits.
#pragma once

#include <fftw3.h>

#include <memory>
#include <vector>

namespace fluid {

class DenseTransform {
 public:
  // The product's kernel: vectorised (AVX2 + FMA) where the CPU has them, or plain sums.
  enum class Kernel { best, plain };
  // The transform `kind` of length n >= 2 (FFTW's definition, unnormalised) on `lines` lines of
  // n contiguous values each, line l starting at l * dist (dist >= n).
  DenseTransform(fftw_r2r_kind kind, int n, int lines, int dist, Kernel kernel = Kernel::best);
  // Any n x n matrix c (row-major) as the transform: y = c x on each line. With `symmetric`
  // false the product is never halved: a matrix whose rows or columns are even or odd only to
  // round-off (computed eigenvectors) is used whole, so the result stays exact to round-off.
  DenseTransform(const std::vector<double>& c, int n, int lines, int dist, bool symmetric,
                 Kernel kernel = Kernel::best);
  // In place on the lines starting at x.
  void apply(double* x);

  // FFTW's kind as a matrix, y = C x, row-major n x n, from its defining sums.
  static std::vector<double> matrix(fftw_r2r_kind kind, int n);
  // Multiply-adds per line.
  double fmas_per_line() const { return m_fmas; }
  // The product's kernel runs vectorised (AVX2 with FMA) on this machine.
  static bool vectorised();
  // Use this transform instead of FFTW's for this kind and length: only with the vectorised
  // kernel, and when its flops are under kAdvantage times those of FFTW's plan for contiguous
  // lines (a fixed plan, so every caller, on any rank, decides alike).
  static bool preferred(fftw_r2r_kind kind, int n);
  // The transform for these lines when it is preferred, else null (FFTW's plan serves them).
  static std::unique_ptr<DenseTransform> if_preferred(fftw_r2r_kind kind, int n, int lines,
                                                      int dist);

 private:
  // How C's symmetry under index reversal r(i) = n - 1 - i halves the product:
  //   rows:    C[k][r(j)] = s_k C[k][j] (each row even or odd): y_k = C[k][:h] (x[:h] ± x[r(:h)])
  //            (+ C[k][m] x_m, m the middle index of an odd n, in the even rows)
  //   columns: C[r(k)][j] = s_j C[k][j] (each column even or odd): with a_k, b_k the sums over
  //            the even and the odd columns (k < ceil(n/2)), y_k = a_k + b_k, y_r(k) = a_k - b_k.
  enum class Symmetry { none, rows, columns };
  struct Block {  // Y (rows x lines) = C_block (rows x cols) S (cols x lines)
    int rows = 0, cols = 0;
    std::vector<double> c;  // rows padded to a multiple of 4 (zero), row-major
    std::vector<double> s, y;
  };
  void gather(const double* x);
  void scatter(double* x) const;

  int m_n, m_lines, m_dist;
  int m_stride;  // lines padded to a multiple of 8
  bool m_vector_kernel;
  Symmetry m_sym = Symmetry::none;
  std::vector<int> m_index[2];  // rows (Symmetry::rows) or columns (::columns) of each block
  Block m_block[2];             // [0] even, [1] odd; Symmetry::none uses [0] only
  double m_fmas = 0;
};

}  // namespace fluid
