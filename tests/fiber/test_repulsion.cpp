// Fiber-fiber repulsion: the cell list finds exactly the close pairs, and two fibers driven
// towards each other are held apart.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "fixtures.hpp"

using namespace fiber;
using namespace fiber::test;

TEST_CASE("cell list finds the same pairs as the all-pairs search", "[fiber][repulsion]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double cutoff : {0.01, 0.05, 0.3}) {
    std::vector<double> x(2 * 800);
    for (auto& v : x) v = u(rng);
    // some points far away and some clustered: the hash must not depend on a bounding box
    x[0] = 1e6;
    x[1] = -1e6;
    for (int i = 1; i < 40; ++i) x[2 * i] = 0.5 + 1e-4 * i, x[2 * i + 1] = 0.5;
    CellList cells;
    cells.build(x, cutoff);
    std::set<std::pair<std::size_t, std::size_t>> found, brute;
    std::size_t visits = 0;
    cells.for_each_pair(x, cutoff, [&](std::size_t i, std::size_t j, double, double, double) {
      found.insert({i, j});
      ++visits;
    });
    for (std::size_t i = 0; i < 800; ++i)
      for (std::size_t j = i + 1; j < 800; ++j) {
        const double dx = x[2 * i] - x[2 * j], dy = x[2 * i + 1] - x[2 * j + 1];
        if (dx * dx + dy * dy < cutoff * cutoff) brute.insert({i, j});
      }
    CHECK(visits == found.size());  // each pair once
    CHECK(found == brute);
  }
}

TEST_CASE("two fibers pushed towards each other are held apart by the repulsion", "[fiber][repulsion]") {
  // Two parallel clamped fibers, 0.1 apart, pushed together by a uniform load per unit length.
  const int n = 20;
  const double cutoff = 0.05, k = 1e-7, push = 0.05;
  Config c;
  FiberSpec a = make_fiber(1.0, n, 1.0, 1e-3, {0, -0.05}, 0.0);
  a.root.kind = EndKind::clamped;
  a.damping = 0.5;
  FiberSpec b = a;
  b.name = std::string("b");
  b.key = std::string("fiber.fiber[1]");
  b.position = {0, 0.05};
  c.fibers = {a, b};
  c.repulsion = {true, k, cutoff};
  std::vector<double> ext(2 * 2 * (n + 1), 0.0);
  for (int i = 0; i <= n; ++i) {
    ext[2 * i + 1] = push;
    ext[2 * (n + 1 + i) + 1] = -push;
  }
  const double dt = 0.5 * bending_dt_limit(a);
  const auto min_gap = [&](const FiberSystem& sys) {
    const auto x = sys.positions();
    double m = 1e9;
    for (int i = 0; i <= n; ++i) m = std::min(m, x[2 * (n + 1 + i) + 1] - x[2 * i + 1]);
    return m;
  };
  FiberSystem sys(c);
  double closest = 1e9;
  for (int s = 0; s < 40000; ++s) {
    sys.advance(dt, ext);
    closest = std::min(closest, min_gap(sys));
  }
  // Static balance at the tips, where a marker faces one marker of the other fiber at distance r
  // and its neighbours at sqrt(r^2 + (j ds)^2): push = sum_j k r / (r^2 + (j ds)^2)^2.
  const double ds = 1.0 / n;
  const auto repel = [&](double r) {
    double s = 0;
    for (int j = -n; j <= n; ++j) {
      const double q = r * r + j * ds * j * ds;
      if (q < cutoff * cutoff) s += k * r / (q * q);
    }
    return s;
  };
  double lo = 1e-6, hi = cutoff;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (repel(mid) > push ? lo : hi) = mid;
  }
  const double final_gap = min_gap(sys);
  INFO("closest gap " << closest << ", final " << final_gap << ", static balance " << lo << ", cut-off " << cutoff);
  CHECK(closest > 0);  // never crossed
  CHECK(final_gap < cutoff);  // they did come into range
  CHECK(final_gap == Approx(lo).epsilon(0.3));

  // Without repulsion they pass through each other.
  c.repulsion.is_enabled = false;
  FiberSystem free_sys(c);
  closest = 1e9;
  for (int s = 0; s < 40000; ++s) {
    free_sys.advance(dt, ext);
    closest = std::min(closest, min_gap(free_sys));
  }
  CHECK(closest < 0);
}
