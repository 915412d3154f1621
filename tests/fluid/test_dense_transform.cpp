// The real transforms as matrix products (DenseTransform) against FFTW's own plans, for every
// kind the fast solver uses, at even, odd, prime and composite lengths (the fast solver on a prime
// length, where it takes them: test_core.cpp).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "dense_transform.hpp"

using namespace fluid;

namespace {

// max |dense - fftw| / max |fftw| over `lines` random lines of length n, `dist` apart (the
// values between lines must stay untouched).
double dense_against_fftw(fftw_r2r_kind kind, int n, int lines, int dist,
                          DenseTransform::Kernel kernel) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  const std::size_t size = static_cast<std::size_t>(dist) * lines;
  double* buf = fftw_alloc_real(size);
  std::vector<double> x(size);
  for (auto& q : x) q = d(rng);
  std::copy(x.begin(), x.end(), buf);
  const int dims[1] = {n};
  fftw_r2r_kind k[1] = {kind};
  fftw_plan p = fftw_plan_many_r2r(1, dims, lines, buf, nullptr, 1, dist, buf, nullptr, 1, dist,
                                   k, FFTW_ESTIMATE);
  REQUIRE(p != nullptr);
  fftw_execute(p);
  DenseTransform dense(kind, n, lines, dist, kernel);
  dense.apply(x.data());
  double err = 0, scale = 0;
  for (std::size_t q = 0; q < size; ++q) {
    err = std::max(err, std::abs(x[q] - buf[q]));
    scale = std::max(scale, std::abs(buf[q]));
  }
  fftw_destroy_plan(p);
  fftw_free(buf);
  return err / scale;
}

}  // namespace

TEST_CASE("dense transforms agree with FFTW for every kind and length", "[fluid][poisson]") {
  for (fftw_r2r_kind kind : {FFTW_REDFT00, FFTW_REDFT10, FFTW_REDFT01, FFTW_REDFT11, FFTW_RODFT00,
                             FFTW_RODFT10, FFTW_RODFT01, FFTW_RODFT11, FFTW_R2HC, FFTW_HC2R})
    for (int n : {2, 3, 4, 7, 8, 41, 101, 102}) {
      INFO("kind " << int(kind) << ", n = " << n);
      // 13 lines: the product's padding to 8 lines and to 4 rows is exercised; 3 values between
      // lines. The plain kernel too, whatever the machine.
      CHECK(dense_against_fftw(kind, n, 13, n, DenseTransform::Kernel::best) < 1e-13);
      CHECK(dense_against_fftw(kind, n, 13, n + 3, DenseTransform::Kernel::plain) < 1e-13);
    }
}

TEST_CASE("the symmetric kinds take half the multiply-adds", "[fluid][poisson]") {
  for (fftw_r2r_kind kind : {FFTW_REDFT10, FFTW_REDFT01, FFTW_RODFT00, FFTW_RODFT10, FFTW_RODFT01})
    for (int n : {7, 8, 101}) {
      INFO("kind " << int(kind) << ", n = " << n);
      DenseTransform t(kind, n, 3, n);
      CHECK(t.fmas_per_line() <= double((n + 1) / 2) * n);
    }
  DenseTransform iv(FFTW_REDFT11, 8, 3, 8);
  CHECK(iv.fmas_per_line() == 64.0);
}

TEST_CASE("any matrix as a transform, and one that is symmetric only to round-off used whole",
          "[fluid][poisson]") {
  // A random matrix: the product equals the plain sums. A DCT-II matrix with 1e-13 of noise is
  // even/odd row by row within the symmetry tolerance: halved, it loses the noise's antisymmetric
  // part; with symmetric = false it is used whole and matches the noisy matrix to round-off.
  const int n = 23, lines = 13;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<double> random(n * n), noisy = DenseTransform::matrix(FFTW_REDFT10, n);
  for (auto& q : random) q = d(rng);
  for (auto& q : noisy) q += 1e-13 * d(rng);
  for (const auto* c : {&random, &noisy}) {
    std::vector<double> x(n * lines), y(n * lines, 0.0);
    for (auto& q : x) q = d(rng);
    for (int l = 0; l < lines; ++l)
      for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j) y[l * n + k] += (*c)[k * n + j] * x[l * n + j];
    std::vector<double> whole = x, halved = x;
    DenseTransform(*c, n, lines, n, false).apply(whole.data());
    DenseTransform(*c, n, lines, n, true).apply(halved.data());
    double e_whole = 0, e_halved = 0;
    for (int q = 0; q < n * lines; ++q) {
      e_whole = std::max(e_whole, std::abs(whole[q] - y[q]));
      e_halved = std::max(e_halved, std::abs(halved[q] - y[q]));
    }
    INFO((c == &random ? "random" : "noisy DCT-II") << ": whole " << e_whole << ", halved "
                                                    << e_halved);
    CHECK(e_whole < 1e-14 * n);
    if (c == &random) CHECK(e_halved < 1e-14 * n);  // no symmetry found: used whole either way
    if (c == &noisy) CHECK(e_halved > 1e-14);       // halved: the noise's odd part is lost
  }
}
