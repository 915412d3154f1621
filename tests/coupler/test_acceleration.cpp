// The coupler's acceleration of the coupled iterations (acceleration.hpp) on linear
// fixed points x = J x + c with a known solution.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "acceleration.hpp"

using coupler::Acceleration;
using coupler::IterationSettings;

namespace {

// J = -Q diag(mu) Q^T with a random orthogonal Q: the eigenvalues -mu of the explicit coupling's
// amplification (real, negative: the lagged inertia overshoots). Returns the iterations needed
// for |x~ - x| <= tol |x~|, or -1 after max.
struct Linear {
  int n;
  std::vector<double> J, c, solution;
  Linear(const std::vector<double>& mu, unsigned seed) : n(static_cast<int>(mu.size())) {
    std::mt19937 gen(seed);
    std::normal_distribution<double> g;
    // Q from Gram-Schmidt on random columns.
    std::vector<std::vector<double>> q;
    while (static_cast<int>(q.size()) < n) {
      std::vector<double> a(n);
      for (double& z : a) z = g(gen);
      for (const auto& b : q) {
        double d = 0;
        for (int i = 0; i < n; ++i) d += a[i] * b[i];
        for (int i = 0; i < n; ++i) a[i] -= d * b[i];
      }
      double l = 0;
      for (double z : a) l += z * z;
      for (double& z : a) z /= std::sqrt(l);
      q.push_back(a);
    }
    J.assign(n * n, 0.0);
    for (int k = 0; k < n; ++k)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) J[i * n + j] -= mu[k] * q[k][i] * q[k][j];
    solution.resize(n);
    for (double& z : solution) z = g(gen);
    c = solution;  // c = (I - J) x*
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) c[i] -= J[i * n + j] * solution[j];
  }
  std::vector<double> operator()(const std::vector<double>& x) const {
    std::vector<double> y = c;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) y[i] += J[i * n + j] * x[j];
    return y;
  }
};

int solve(const Linear& H, Acceleration& a, std::vector<double>& x, int max, double tol) {
  a.begin_step();
  std::vector<double> next;
  for (int k = 0; k < max; ++k) {
    const auto xt = H(x);
    double r = 0, v = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      r += (xt[i] - x[i]) * (xt[i] - x[i]), v += xt[i] * xt[i];
    if (std::sqrt(r) <= tol * std::sqrt(v)) {
      a.end_step(true);
      return k + 1;
    }
    a.update(x, xt, next);
    x = next;
  }
  a.end_step(false);
  return -1;
}

double error(const Linear& H, const std::vector<double>& x) {
  double e = 0, s = 0;
  for (int i = 0; i < H.n; ++i)
    e += std::pow(x[i] - H.solution[i], 2), s += std::pow(H.solution[i], 2);
  return std::sqrt(e / s);
}

}  // namespace

// 6 modes amplified 50 to 5000 times (the explicit coupling's blow-up), 34 damped ones.
Linear amplifying(unsigned seed) {
  std::vector<double> mu{5000, 1200, 400, 150, 60, 50};
  mu.resize(40, 0.3);
  return Linear(mu, seed);
}

TEST_CASE(
    "IQN-ILS solves a strongly amplifying linear coupling in about as many iterations as it has "
    "amplified modes") {
  const Linear H = amplifying(7);
  IterationSettings s;
  Acceleration a(s);
  std::vector<double> x(40, 0.0);
  const int its = solve(H, a, x, 60, 1e-10);
  INFO("iterations " << its);
  CHECK(its > 0);
  CHECK(its <= 20);
  CHECK(error(H, x) < 1e-9);
}

TEST_CASE("IQN-ILS with reuse needs fewer iterations on the next step of the same coupling") {
  const Linear H = amplifying(11);
  IterationSettings s;
  s.reuse = 2;
  Acceleration a(s);
  std::vector<double> x(40, 0.0);
  const int first = solve(H, a, x, 60, 1e-8);
  for (double& z : x) z *= 0.9;  // the next step starts near the solution
  const int second = solve(H, a, x, 60, 1e-8);
  INFO("first " << first << ", second " << second);
  REQUIRE(first > 0);
  REQUIRE(second > 0);
  CHECK(second <= 3);
  CHECK(second < first);
  CHECK(error(H, x) < 1e-7);
}

TEST_CASE("IQN-ILS forgets its kept pairs after a step that did not converge") {
  const Linear H = amplifying(11);
  IterationSettings s;
  s.reuse = 2;
  Acceleration a(s);
  std::vector<double> x(40, 0.0);
  const int first = solve(H, a, x, 60, 1e-8);
  REQUIRE(first > 0);
  // A step cut short: not converged, so the next step must start without kept pairs ...
  std::vector<double> y(40, 0.0);
  REQUIRE(solve(H, a, y, 1, 1e-8) == -1);
  for (double& z : x) z *= 0.9;
  const int after = solve(H, a, x, 60, 1e-8);
  // ... and take the iterations of a fresh start from there, not the 2-3 of a reused one.
  Acceleration fresh(s);
  std::vector<double> w(40, 0.0);
  REQUIRE(solve(H, fresh, w, 60, 1e-8) > 0);
  for (double& z : w) z *= 0.9;
  Acceleration fresh2(s);
  const int fresh_count = solve(H, fresh2, w, 60, 1e-8);
  INFO("first " << first << ", after a failed step " << after << ", fresh " << fresh_count);
  REQUIRE(after > 0);
  CHECK(after == fresh_count);
  CHECK(after > 3);
  CHECK(error(H, x) < 1e-7);
}

TEST_CASE("An update without secant columns is the relaxation x + w r") {
  IterationSettings s;
  s.relaxation = 0.25;
  Acceleration a(s);
  a.begin_step();
  const std::vector<double> x{1.0, -2.0, 0.5}, xt{3.0, 2.0, 0.5};
  std::vector<double> next;
  a.update(x, xt, next);
  CHECK(a.columns() == 0);
  CHECK(a.omega() == 0.25);
  REQUIRE(next.size() == 3);
  CHECK(next[0] == 1.5);
  CHECK(next[1] == -1.0);
  CHECK(next[2] == 0.5);
  // The second update has one column: the secant step, no longer the relaxation.
  const std::vector<double> x1 = next;
  a.update(x1, {2.0, 0.0, 0.5}, next);
  CHECK(a.columns() == 1);
}
