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
