// FFTW's real transforms as matrix products (see dense_transform.hpp): the matrix from FFTW's
// defining sums, its halves by symmetry, the product in register blocks across the lines.
#include "dense_transform.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "error.hpp"

namespace fluid {

namespace {

// The dense product's flops (2 per multiply-add) against FFTW's count for its plan: below this
// factor of FFTW's, the vectorised product is the faster one. Measured on 600 lines of REDFT10,
// FFTW 3.3.10, FFTW_ESTIMATE, AVX2 kernel (`./fsi bench fluid`, "REDFT10 on 600 lines"): lengths
// 82, 101, 102, 103, 123, 164 (flop ratios 1.7, 0.96, 3.7, 1.0, 2.5, 3.3) run 1.3-3.4x faster
// dense; 100, 104, 246 (ratios 6.0, 5.3, 4.8) as fast or faster with FFTW.
constexpr double kAdvantage = 4.0;
// Entries of a symmetric pair agree to this fraction of the largest entry (long double sums).
constexpr double kSymmetryTol = 1e-12;

// cos(pi m / d) and sin(pi m / d) for integers m, d > 0, with m reduced modulo 2d first so that
// the angle keeps its digits however large m is.
long double cos_pi(long long m, long long d) {
  m %= 2 * d;
  return std::cos(std::numbers::pi_v<long double> * static_cast<long double>(m) /
                  static_cast<long double>(d));
}
long double sin_pi(long long m, long long d) {
  m %= 2 * d;
  return std::sin(std::numbers::pi_v<long double> * static_cast<long double>(m) /
                  static_cast<long double>(d));
}

// Y (rows x stride) = C (rows x cols, rows a multiple of 4) S (cols x stride, stride a multiple
// of 8), in blocks of 4 rows x 8 lines held in registers while j runs over the columns.
using V4 = double __attribute__((vector_size(32)));
inline __attribute__((always_inline)) void product_blocks(const double* c, int rows, int cols,
                                                          const double* s, int stride, double* y) {
  for (int l0 = 0; l0 < stride; l0 += 8)
    for (int r0 = 0; r0 < rows; r0 += 4) {
      V4 a00{}, a01{}, a10{}, a11{}, a20{}, a21{}, a30{}, a31{};
      const double* c0 = c + static_cast<std::size_t>(r0) * cols;
      const double* c1 = c0 + cols;
      const double* c2 = c1 + cols;
      const double* c3 = c2 + cols;
      for (int j = 0; j < cols; ++j) {
        V4 s0, s1;
        const double* sj = s + static_cast<std::size_t>(j) * stride + l0;
        std::memcpy(&s0, sj, sizeof s0);
        std::memcpy(&s1, sj + 4, sizeof s1);
        a00 += c0[j] * s0, a01 += c0[j] * s1;
        a10 += c1[j] * s0, a11 += c1[j] * s1;
        a20 += c2[j] * s0, a21 += c2[j] * s1;
        a30 += c3[j] * s0, a31 += c3[j] * s1;
      }
      double* yr = y + static_cast<std::size_t>(r0) * stride + l0;
      const V4* acc[4][2] = {{&a00, &a01}, {&a10, &a11}, {&a20, &a21}, {&a30, &a31}};
      for (int a = 0; a < 4; ++a, yr += stride) {
        std::memcpy(yr, acc[a][0], sizeof(V4));
        std::memcpy(yr + 4, acc[a][1], sizeof(V4));
      }
    }
}

#if defined(__x86_64__) || defined(__i386__)
#define FSI_DENSE_AVX2 1
__attribute__((target("avx2,fma"))) void product_avx2(const double* c, int rows, int cols,
                                                      const double* s, int stride, double* y) {
  product_blocks(c, rows, cols, s, stride, y);
}
#endif

// Without AVX2 (the transform is then not preferred over FFTW): plain sums, same layout.
void product_plain(const double* c, int rows, int cols, const double* s, int stride, double* y) {
  for (int r = 0; r < rows; ++r) {
    double* yr = y + static_cast<std::size_t>(r) * stride;
    std::fill(yr, yr + stride, 0.0);
    for (int j = 0; j < cols; ++j) {
      const double crj = c[static_cast<std::size_t>(r) * cols + j];
      const double* sj = s + static_cast<std::size_t>(j) * stride;
      for (int l = 0; l < stride; ++l) yr[l] += crj * sj[l];
    }
  }
}

// Multiply-adds per line the product needs: about n^2 / 2 for the kinds whose matrix is even or
// odd under index reversal row by row or column by column, n^2 for the others.
double fmas_estimate(fftw_r2r_kind kind, int n) {
  switch (kind) {
    case FFTW_REDFT00:
    case FFTW_REDFT10:
    case FFTW_REDFT01:
    case FFTW_RODFT00:
    case FFTW_RODFT10:
    case FFTW_RODFT01:
      return static_cast<double>((n + 1) / 2) * n;
    default:
      return static_cast<double>(n) * n;
  }
}

int round_up(int v, int m) {
  return (v + m - 1) / m * m;
}

}  // namespace

bool DenseTransform::vectorised() {
#ifdef FSI_DENSE_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return avx2;
#else
  return false;
#endif
}

bool DenseTransform::preferred(fftw_r2r_kind kind, int n) {
  if (!vectorised() || n < 2) return false;
  constexpr int kLines = 16;  // FFTW's plan for 16 contiguous lines: its flops per line
  double* buf = fftw_alloc_real(static_cast<std::size_t>(n) * kLines);
  const int dims[1] = {n};
  fftw_r2r_kind k[1] = {kind};
  fftw_plan p =
      fftw_plan_many_r2r(1, dims, kLines, buf, nullptr, 1, n, buf, nullptr, 1, n, k, FFTW_ESTIMATE);
  double add = 0, mul = 0, fma = 0;
  if (p) fftw_flops(p, &add, &mul, &fma);
  if (p) fftw_destroy_plan(p);
  fftw_free(buf);
  if (!p) return false;
  const double fftw_per_line = (add + mul + 2 * fma) / kLines;
  return 2 * fmas_estimate(kind, n) < kAdvantage * fftw_per_line;
}

std::unique_ptr<DenseTransform> DenseTransform::if_preferred(fftw_r2r_kind kind, int n,
                                                             int lines, int dist) {
  if (lines < 1 || !preferred(kind, n)) return nullptr;
  return std::make_unique<DenseTransform>(kind, n, lines, dist);
}

// FFTW's definitions (manual, "What FFTW Really Computes"), j the input index, k the output's:
//   REDFT00 y_k = x_0 + (-1)^k x_{n-1} + 2 sum_{j=1}^{n-2} x_j cos(pi j k / (n-1))
//   REDFT10 y_k = 2 sum x_j cos(pi (j+1/2) k / n)
//   REDFT01 y_k = x_0 + 2 sum_{j>=1} x_j cos(pi j (k+1/2) / n)
//   REDFT11 y_k = 2 sum x_j cos(pi (j+1/2)(k+1/2) / n)
//   RODFT00 y_k = 2 sum x_j sin(pi (j+1)(k+1) / (n+1))
//   RODFT10 y_k = 2 sum x_j sin(pi (j+1/2)(k+1) / n)
//   RODFT01 y_k = (-1)^k x_{n-1} + 2 sum_{j<n-1} x_j sin(pi (j+1)(k+1/2) / n)
//   RODFT11 y_k = 2 sum x_j sin(pi (j+1/2)(k+1/2) / n)
//   R2HC    y_k = sum x_j cos(2 pi j k / n) (k <= n/2), y_{n-k} = -sum x_j sin(2 pi j k / n)
//           (0 < k < n/2): the halfcomplex order
//   HC2R    y_j = x_0 + 2 sum_{0<k<n/2} (x_k cos(2 pi j k / n) - x_{n-k} sin(2 pi j k / n))
//           + (-1)^j x_{n/2} (n even)
std::vector<double> DenseTransform::matrix(fftw_r2r_kind kind, int n) {
  if (n < 1 || (kind == FFTW_REDFT00 && n < 2))
    fsi::fail("fluid::DenseTransform: no transform of length {}", n);
  std::vector<double> c(static_cast<std::size_t>(n) * n);
  const long long N = n;
  for (long long k = 0; k < N; ++k)
    for (long long j = 0; j < N; ++j) {
      long double v = 0;
      switch (kind) {
        case FFTW_REDFT00:
          v = (j == 0 || j == N - 1 ? 1 : 2) * cos_pi(j * k, N - 1);
          break;
        case FFTW_REDFT10:
          v = 2 * cos_pi((2 * j + 1) * k, 2 * N);
          break;
        case FFTW_REDFT01:
          v = (j == 0 ? 1 : 2) * cos_pi(j * (2 * k + 1), 2 * N);
          break;
        case FFTW_REDFT11:
          v = 2 * cos_pi((2 * j + 1) * (2 * k + 1), 4 * N);
          break;
        case FFTW_RODFT00:
          v = 2 * sin_pi((j + 1) * (k + 1), N + 1);
          break;
        case FFTW_RODFT10:
          v = 2 * sin_pi((2 * j + 1) * (k + 1), 2 * N);
          break;
        case FFTW_RODFT01:
          v = (j == N - 1 ? 1 : 2) * sin_pi((j + 1) * (2 * k + 1), 2 * N);
          break;
        case FFTW_RODFT11:
          v = 2 * sin_pi((2 * j + 1) * (2 * k + 1), 4 * N);
          break;
        case FFTW_R2HC:
          v = 2 * k <= N ? cos_pi(2 * j * k, N) : -sin_pi(2 * j * (N - k), N);
          break;
        case FFTW_HC2R:
          // Row k is output index k; column j the halfcomplex entry.
          if (j == 0)
            v = 1;
          else if (2 * j < N)
            v = 2 * cos_pi(2 * k * j, N);
          else if (2 * j == N)
            v = cos_pi(k * j * 2, N);
          else
            v = -2 * sin_pi(2 * k * (N - j), N);
          break;
        default:
          fsi::fail("fluid::DenseTransform: FFTW kind {} has no matrix here", int(kind));
      }
      c[static_cast<std::size_t>(k * N + j)] = static_cast<double>(v);
    }
  return c;
}

DenseTransform::DenseTransform(fftw_r2r_kind kind, int n, int lines, int dist, Kernel kernel)
    : DenseTransform(matrix(kind, n), n, lines, dist, true, kernel) {}

DenseTransform::DenseTransform(const std::vector<double>& c, int n, int lines, int dist,
                               bool symmetric, Kernel kernel)
    : m_n(n),
      m_lines(lines),
      m_dist(dist),
      m_stride(round_up(std::max(lines, 1), 8)),
      m_vector_kernel(kernel == Kernel::best && vectorised()) {
  if (n < 2 || lines < 1 || dist < n)
    fsi::fail("fluid::DenseTransform: {} lines of length {}, {} apart", lines, n, dist);
  if (c.size() != static_cast<std::size_t>(n) * n)
    fsi::fail("fluid::DenseTransform: a matrix of {} entries for length {}", c.size(), n);
  const auto at = [&](int k, int j) { return c[static_cast<std::size_t>(k) * n + j]; };
  double cmax = 0;
  for (double v : c) cmax = std::max(cmax, std::abs(v));
  const double tol = kSymmetryTol * cmax;
  const auto rev = [n](int i) { return n - 1 - i; };
  // The sign s with a(i) = s b(i) for every i, or 0 when there is none (+1 for a zero line).
  const auto sign_of = [&](auto a, auto b) {
    bool plus = true, minus = true;
    for (int i = 0; i < n; ++i) {
      plus = plus && std::abs(a(i) - b(i)) <= tol;
      minus = minus && std::abs(a(i) + b(i)) <= tol;
    }
    return plus ? 1 : minus ? -1 : 0;
  };
  std::vector<int> row_sign(n), col_sign(n);
  bool rows_ok = symmetric, cols_ok = symmetric;
  for (int i = 0; i < n; ++i) {
    row_sign[i] = sign_of([&](int j) { return at(i, rev(j)); }, [&](int j) { return at(i, j); });
    col_sign[i] = sign_of([&](int k) { return at(rev(k), i); }, [&](int k) { return at(k, i); });
    rows_ok = rows_ok && row_sign[i] != 0;
    cols_ok = cols_ok && col_sign[i] != 0;
  }
  const int half_up = (n + 1) / 2, half_down = n / 2;
  auto fill = [&](Block& b, const std::vector<int>& rows, int ncols, auto entry) {
    b.rows = static_cast<int>(rows.size());
    b.cols = ncols;
    const int padded = round_up(b.rows, 4);
    b.c.assign(static_cast<std::size_t>(padded) * ncols, 0.0);
    for (int r = 0; r < b.rows; ++r)
      for (int q = 0; q < ncols; ++q) b.c[static_cast<std::size_t>(r) * ncols + q] = entry(r, q);
    b.s.assign(static_cast<std::size_t>(ncols) * m_stride, 0.0);
    b.y.assign(static_cast<std::size_t>(padded) * m_stride, 0.0);
  };
  if (rows_ok) {
    // Even rows against x_j + x_r(j) (and the middle x for odd n), odd rows against x_j - x_r(j).
    m_sym = Symmetry::rows;
    for (int k = 0; k < n; ++k) m_index[row_sign[k] > 0 ? 0 : 1].push_back(k);
    for (int g = 0; g < 2; ++g) {
      const std::vector<int>& rows = m_index[g];
      fill(m_block[g], rows, g == 0 ? half_up : half_down,
           [&](int r, int q) { return at(rows[r], q); });
    }
    m_fmas = double(m_index[0].size()) * half_up + double(m_index[1].size()) * half_down;
  } else if (cols_ok) {
    // The first ceil(n/2) rows, against the even columns and against the odd ones.
    m_sym = Symmetry::columns;
    for (int j = 0; j < n; ++j) m_index[col_sign[j] > 0 ? 0 : 1].push_back(j);
    std::vector<int> rows(half_up);
    for (int k = 0; k < half_up; ++k) rows[k] = k;
    for (int g = 0; g < 2; ++g) {
      const std::vector<int>& cols = m_index[g];
      fill(m_block[g], rows, static_cast<int>(cols.size()), [&](int r, int q) {
        // The middle row of an odd n is even: its odd columns are zero (exactly, not to round-off).
        return (g == 1 && rev(r) == r) ? 0.0 : at(r, cols[q]);
      });
    }
    m_fmas = double(half_up) * n;
  } else {
    m_sym = Symmetry::none;
    std::vector<int> rows(n);
    for (int k = 0; k < n; ++k) rows[k] = k;
    fill(m_block[0], rows, n, [&](int r, int q) { return at(r, q); });
    m_fmas = double(n) * n;
  }
}

void DenseTransform::gather(const double* x) {
  const int n = m_n, st = m_stride;
  for (int l = 0; l < m_lines; ++l) {
    const double* xl = x + static_cast<std::size_t>(l) * m_dist;
    switch (m_sym) {
      case Symmetry::rows: {
        double* sp = m_block[0].s.data() + l;
        double* sm = m_block[1].s.data() + l;
        for (int j = 0; j < n / 2; ++j) {
          sp[static_cast<std::size_t>(j) * st] = xl[j] + xl[n - 1 - j];
          sm[static_cast<std::size_t>(j) * st] = xl[j] - xl[n - 1 - j];
        }
        if (n % 2 == 1) sp[static_cast<std::size_t>(n / 2) * st] = xl[n / 2];
        break;
      }
      case Symmetry::columns:
        for (int g = 0; g < 2; ++g) {
          const std::vector<int>& cols = m_index[g];
          if (cols.empty()) continue;  // no storage to point into
          double* s = m_block[g].s.data() + l;
          for (std::size_t q = 0; q < cols.size(); ++q) s[q * st] = xl[cols[q]];
        }
        break;
      case Symmetry::none: {
        double* s = m_block[0].s.data() + l;
        for (int j = 0; j < n; ++j) s[static_cast<std::size_t>(j) * st] = xl[j];
        break;
      }
    }
  }
}

void DenseTransform::scatter(double* x) const {
  const int n = m_n, st = m_stride;
  for (int l = 0; l < m_lines; ++l) {
    double* xl = x + static_cast<std::size_t>(l) * m_dist;
    switch (m_sym) {
      case Symmetry::rows:
        for (int g = 0; g < 2; ++g) {
          const std::vector<int>& rows = m_index[g];
          if (rows.empty()) continue;  // no storage to point into
          const double* y = m_block[g].y.data() + l;
          for (std::size_t r = 0; r < rows.size(); ++r) xl[rows[r]] = y[r * st];
        }
        break;
      case Symmetry::columns: {
        // A group without columns sums to zero (its block's product is not run).
        const double* a = m_block[0].y.data() + l;
        const double* b = m_block[1].y.data() + l;
        const bool has_a = m_block[0].cols > 0, has_b = m_block[1].cols > 0;
        for (int k = 0; k < (n + 1) / 2; ++k) {
          const double ak = has_a ? a[static_cast<std::size_t>(k) * st] : 0.0;
          const double bk = has_b ? b[static_cast<std::size_t>(k) * st] : 0.0;
          xl[k] = ak + bk;
          if (n - 1 - k != k) xl[n - 1 - k] = ak - bk;
        }
        break;
      }
      case Symmetry::none: {
        const double* y = m_block[0].y.data() + l;
        for (int k = 0; k < n; ++k) xl[k] = y[static_cast<std::size_t>(k) * st];
        break;
      }
    }
  }
}

void DenseTransform::apply(double* x) {
  gather(x);
#ifdef FSI_DENSE_AVX2
  const auto product = m_vector_kernel ? product_avx2 : product_plain;
#else
  const auto product = product_plain;
#endif
  for (Block& b : m_block)
    if (b.rows > 0 && b.cols > 0)
      product(b.c.data(), round_up(b.rows, 4), b.cols, b.s.data(), m_stride, b.y.data());
  scatter(x);
}

}  // namespace fluid
