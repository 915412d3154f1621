// The slab-split fast solver against the one-rank FastSolver, run under mpirun on 1, 2 and 3
// ranks: the same right-hand side, the same solution to round-off, for every closure pair, both
// transform directions, a periodic second direction, a padded row and a singular problem.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "error.hpp"
#include "slab_solver.hpp"

using namespace fluid;

namespace {

int g_rank = 0, g_ranks = 1;

// A stretched tridiagonal operator of n unknowns, like the pressure's with zero-flux ends when
// `singular` (rows sum to zero).
Operator1D stretched(int n, bool singular) {
  Operator1D s;
  s.n = n;
  s.a.resize(n);
  s.b.resize(n);
  s.c.resize(n);
  for (int j = 0; j < n; ++j) {
    s.a[j] = j > 0 ? 1.0 + 0.1 * j : 0.0;
    s.c[j] = j < n - 1 ? 1.2 - 0.05 * j : 0.0;
    s.b[j] = singular ? -(s.a[j] + s.c[j]) : -(2.3 + 0.1 * j);
  }
  s.singular = singular;
  return s;
}

struct Case {
  Operator1D t, s;
  double sigma;
  int t_axis, pad;
};

// Largest difference between the slab solve and FastSolver, relative to the largest value.
double difference(const Case& c) {
  const int nt = c.t.n, ns = c.s.n;
  const int nx = c.t_axis == 0 ? nt : ns;
  const int rows = (c.t_axis == 0 ? ns : nt) + c.pad;
  std::vector<double> w(ns);
  for (int j = 0; j < ns; ++j) w[j] = 1.0 + 0.01 * j;
  FastSolver serial(c.t, c.s, c.sigma);
  SlabSolver slab(c.t, c.s, c.sigma, c.t_axis, rows, c.pad, MPI_COMM_WORLD);
  serial.set_mean_weights(w);
  slab.set_mean_weights(w);
  // The same random right-hand side on every rank, in natural order (rows, x fastest).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<double> nat(std::size_t(rows) * nx);
  for (auto& q : nat) q = d(rng);
  // FastSolver's layout: t fastest, unknown rows only.
  auto serial_index = [&](int i, int r) {
    return c.t_axis == 0 ? i + std::size_t(nt) * (r - c.pad) : (r - c.pad) + std::size_t(nt) * i;
  };
  for (int r = c.pad; r < rows; ++r)
    for (int i = 0; i < nx; ++i) serial.data()[serial_index(i, r)] = nat[i + std::size_t(nx) * r];
  serial.solve();
  const RowSplit& sp = slab.split();
  for (int r = sp.lo; r < sp.hi; ++r)
    for (int i = 0; i < nx; ++i) slab.data()[i + std::size_t(nx) * (r - sp.lo)] = nat[i + std::size_t(nx) * r];
  slab.solve();
  double diff = 0, scale = 0;
  for (int r = sp.lo; r < sp.hi; ++r) {
    for (int i = 0; i < nx; ++i) {
      const double got = slab.data()[i + std::size_t(nx) * (r - sp.lo)];
      if (r < c.pad) {
        diff = std::max(diff, std::abs(got));  // a padded row comes back zero
        continue;
      }
      const double want = serial.data()[serial_index(i, r)];
      diff = std::max(diff, std::abs(got - want));
      scale = std::max(scale, std::abs(want));
    }
  }
  double out[2] = {diff, -scale}, all[2];
  MPI_Allreduce(out, all, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return all[0] / std::max(1e-300, -all[1]);
}

}  // namespace

TEST_CASE("slab solver equals the one-rank solver", "[fluid][slab]") {
  using C = Closure;
  const std::pair<C, C> closures[] = {{C::periodic, C::periodic},
                                      {C::neumann_half, C::neumann_half},
                                      {C::dirichlet_half, C::dirichlet_half},
                                      {C::dirichlet_half, C::neumann_half},
                                      {C::neumann_half, C::dirichlet_half},
                                      {C::dirichlet_node, C::dirichlet_node}};
  for (int t_axis : {0, 1}) {
    for (int pad : {0, 1}) {
      for (auto [lo, hi] : closures) {
        for (double sigma : {0.0, 2.5}) {
          Case c;
          c.t = Operator1D{t_axis == 0 ? 13 : 11, lo, hi, 0.3, {}, {}, {}, false};
          c.s = stretched(t_axis == 0 ? 10 : 14, sigma == 0.0);
          c.sigma = sigma;
          c.t_axis = t_axis;
          c.pad = pad;
          INFO("t_axis " << t_axis << " pad " << pad << " closures " << int(lo) << int(hi)
                         << " sigma " << sigma << " ranks " << g_ranks);
          CHECK(difference(c) < 1e-12);
        }
      }
    }
  }
}

TEST_CASE("slab solver with both directions transformed", "[fluid][slab]") {
  using C = Closure;
  for (int t_axis : {0, 1}) {
    for (double sigma : {0.0, 2.5}) {
      Case c;
      c.t = Operator1D{12, C::periodic, C::periodic, 0.3, {}, {}, {}, false};
      c.s = Operator1D{9, C::periodic, C::periodic, 0.4, {}, {}, {}, sigma == 0.0};
      c.sigma = sigma;
      c.t_axis = t_axis;
      c.pad = 0;
      INFO("t_axis " << t_axis << " sigma " << sigma << " ranks " << g_ranks);
      CHECK(difference(c) < 1e-12);
    }
  }
}

TEST_CASE("slab solver with a stretched transform direction (both directions stretched)",
          "[fluid][slab]") {
  // FastSolver takes a stretched t through its eigenvectors; the slab solver does the same on
  // its t-lines. t along y (the fluid's choice when x is stretched too) and along x, with and
  // without a padded row, singular (the pressure) and not (a Helmholtz operator).
  for (int t_axis : {0, 1}) {
    for (int pad : {0, 1}) {
      for (double sigma : {0.0, 2.5}) {
        Case c;
        c.t = stretched(t_axis == 0 ? 13 : 11, sigma == 0.0);
        c.s = stretched(t_axis == 0 ? 10 : 14, sigma == 0.0);
        c.sigma = sigma;
        c.t_axis = t_axis;
        c.pad = pad;
        INFO("t_axis " << t_axis << " pad " << pad << " sigma " << sigma << " ranks " << g_ranks);
        CHECK(difference(c) < 1e-12);
      }
    }
  }
}

TEST_CASE("a split that leaves a rank too few rows is refused", "[fluid][slab]") {
  CHECK_THROWS_WITH(split_rows(9, 4, 0),
                    Catch::Contains("9 cell rows cannot be split over 4 ranks") &&
                        Catch::Contains("3 or 5 ranks would do"));
  // The fluid's minimum of two rows: 5 ranks would leave the last one row.
  CHECK_THROWS_WITH(split_rows(9, 4, 0, 2), Catch::Contains("; 3 ranks would do"));
  CHECK_THROWS_WITH(split_rows(10, 4, 0, 2),
                    Catch::Contains("leave the last rank 1 (each needs 2); 3 or 5 ranks would do"));
  const RowSplit s = split_rows(10, 3, 2, 2);
  CHECK(s.block == 4);
  CHECK(s.lo == 8);
  CHECK(s.hi == 10);
}

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_ranks);
  const int failed = Catch::Session().run(argc, argv);
  int any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return any ? 1 : 0;
}
