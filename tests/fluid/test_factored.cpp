// The approximately factored Crank-Nicolson solve (helmholtz = "factored"): exact inversion of
// its factored operator (its steady states: test_core.cpp; second order in time: test_time.cpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "factored_solver.hpp"

using namespace fluid;

namespace {

// Tridiagonal rows of n unknowns, stretched, or periodic with the wrap-around in a[0], c[n-1].
Operator1D rows(int n, bool periodic) {
  Operator1D op;
  op.n = n;
  op.a.resize(n);
  op.b.resize(n);
  op.c.resize(n);
  for (int k = 0; k < n; ++k) {
    op.a[k] = 1.0 + 0.1 * k;
    op.c[k] = 1.2 - 0.05 * k;
    op.b[k] = -(op.a[k] + op.c[k]) - (periodic ? 0.0 : 0.3);
  }
  if (periodic) {
    op.lo = op.hi = Closure::periodic;
  } else {
    op.lo = op.hi = Closure::dirichlet_half;
    op.a[0] = op.c[n - 1] = 0;
  }
  return op;
}

// y = (I - L / sigma) x along one direction of the 2D array x[k + nf j] (dir 0: k, 1: j).
std::vector<double> apply(const Operator1D& op, double sigma, const std::vector<double>& x, int nf,
                          int ns, int dir) {
  std::vector<double> y(x.size());
  const bool per = op.lo == Closure::periodic;
  for (int j = 0; j < ns; ++j)
    for (int k = 0; k < nf; ++k) {
      const int m = dir == 0 ? k : j, n = op.n;
      auto at = [&](int mm) -> double {
        if (mm < 0 || mm >= n) {
          if (!per) return 0.0;
          mm = (mm + n) % n;
        }
        return dir == 0 ? x[mm + nf * j] : x[k + nf * mm];
      };
      const double lx = op.a[m] * at(m - 1) + op.b[m] * at(m) + op.c[m] * at(m + 1);
      y[k + nf * j] = at(m) - lx / sigma;
    }
  return y;
}

}  // namespace

TEST_CASE("factored solve inverts its factored operator exactly", "[fluid][factored]") {
  const int nf = 11, ns = 7;
  const double sigma = 3.0;
  for (bool pf : {false, true})
    for (bool ps : {false, true}) {
      const Operator1D f = rows(nf, pf), s = rows(ns, ps);
      FactoredSolver fs(f, s, sigma);
      REQUIRE(fs.nt() == nf);
      REQUIRE(fs.ns() == ns);
      std::mt19937 rng(5);
      std::uniform_real_distribution<double> d(-1, 1);
      std::vector<double> x(nf * ns);
      for (auto& q : x) q = d(rng);
      // b = -sigma (I - L_f / sigma)(I - L_s / sigma) x
      const std::vector<double> b = apply(f, sigma, apply(s, sigma, x, nf, ns, 1), nf, ns, 0);
      for (int q = 0; q < nf * ns; ++q) fs.data()[q] = -sigma * b[q];
      fs.solve();
      double err = 0;
      for (int q = 0; q < nf * ns; ++q) err = std::max(err, std::abs(fs.data()[q] - x[q]));
      INFO("periodic f " << pf << ", s " << ps << ": max error " << err);
      CHECK(err < 1e-13);
    }
}
