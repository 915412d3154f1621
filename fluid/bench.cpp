// bench_fluid: time per fluid step split into predictor, boundaries, Poisson and projection, in
// ns per cell, next to the floor measured in the same run: one bare FFTW transform pair plus
// tridiagonal solve on the same grid. Writes JSON to --out FILE and prints a table.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dense_transform.hpp"
#include "momentum.hpp"
#include "solver.hpp"

using namespace fluid;
using Clock = std::chrono::steady_clock;

namespace {

struct Case {
  std::string name;
  Config cfg;
  double dt;
  bool direct = true;  // the direct Crank-Nicolson solve applies (one direction uniform)
};

// The Turek-Hron channel at a given resolution: 2.5 x 0.41, parabolic inflow (mean 1), walls,
// convective outflow, rho = 1000, mu = 1 (paper Table 2; dt scaled with the cell size).
Case channel(int nx, int ny) {
  Config c;
  c.density = 1000;
  c.viscosity = 1;
  c.x = {nx, 2.5, 0.0};
  c.y = {ny, 0.41, 0.0};
  c.bc[left].type = BcType::inflow;
  c.bc[left].mean = 1.0;
  c.bc[right].type = BcType::outflow;
  c.bc[bottom].type = c.bc[top].type = BcType::wall;
  c.initial.type = InitialType::uniform;
  c.initial.velocity = {1.0, 0.0};
  return {fmt::format("channel {}x{}", nx, ny), c, 2.5e-5 * 1500.0 / nx};
}

// The same channel with bands of cells in both directions where the cylinder and the bar are
// (x in [0.1, 0.7], y in [0.14, 0.26], 1.67 mm): y is then transformed by its eigenvectors.
Case banded_channel(int nx, int ny) {
  Case k = channel(nx, ny);
  k.cfg.x.band_from = 0.1, k.cfg.x.band_to = 0.7, k.cfg.x.band_cells = nx * 12 / 25;
  k.cfg.y.band_from = 0.14, k.cfg.y.band_to = 0.26, k.cfg.y.band_cells = ny * 72 / 123;
  k.name = fmt::format("banded {}x{}", nx, ny);
  k.dt = channel(1500, 246).dt;  // the band's cells are those of the 1500-column channel
  k.direct = false;
  return k;
}

Case cavity(int n) {
  Config c;
  c.density = 1;
  c.viscosity = 1e-3;
  c.x = {n, 1.0, 0.0};
  c.y = {n, 1.0, 0.0};
  for (auto& b : c.bc) b.type = BcType::wall;
  c.bc[top].velocity = 1.0;
  return {fmt::format("cavity {}x{}", n, n), c, 0.4 / n};
}

template <class F>
double seconds_per_call(F&& f, double budget) {
  f();  // warm-up
  long n = 0;
  const auto t0 = Clock::now();
  double el = 0;
  do {
    f();
    ++n;
    el = std::chrono::duration<double>(Clock::now() - t0).count();
  } while (el < budget);
  return el / n;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "fluid.json";
  double budget = 2.0;
  for (int k = 1; k < argc; ++k) {
    if (!std::strcmp(argv[k], "--out") && k + 1 < argc) out = argv[++k];
    else if (!std::strcmp(argv[k], "--seconds") && k + 1 < argc) budget = std::stod(argv[++k]);
  }
  nlohmann::json j;
  j["grids"] = nlohmann::json::array();
  fmt::print("{:<20} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>7} {:>7}\n", "grid", "pred ms",
             "bc ms", "poiss ms", "proj ms", "step ms", "ns/cell", "floor ms", "step/fl", "poi/fl");
  for (const Case& k : {cavity(256), channel(750, 123), channel(1500, 246), banded_channel(750, 123)}) {
    // explicit; Crank-Nicolson with the direct Helmholtz solves; with the factored ones
    for (int mode = 0; mode < 3; ++mode) {
      if (mode == 1 && !k.direct) continue;
      const bool implicit = mode > 0;
      Config c = k.cfg;
      c.implicit = implicit;
      c.factored_helmholtz = mode == 2;
      c.cfl_max = 1e9;
      Solver s(c, k.dt);
      set_initial(s);
      for (int w = 0; w < 5; ++w) s.step(k.dt);
      s.reset_timings();
      const auto t0 = Clock::now();
      long steps = 0;
      double el = 0;
      do {
        s.step(k.dt);
        ++steps;
        el = std::chrono::duration<double>(Clock::now() - t0).count();
      } while (el < budget);
      const Timings& tm = s.timings();
      // The floor: a bare transform pair and tridiagonal sweep on the same Poisson operator.
      FastSolver& ps = s.poisson();
      const double floor = seconds_per_call([&] { ps.forward(); ps.tridiagonal(); ps.backward(); }, 0.5 * budget);
      const double cells = double(s.grid().nx()) * s.grid().ny();
      const double step = el / steps;
      const double ms = 1e3 / steps;
      const double ratio = step / floor, poisson_ratio = tm.poisson / steps / floor;
      const std::string name = k.name + (mode == 2 ? " CN-fact" : implicit ? " CN" : "");
      fmt::print("{:<20} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.3f} {:>9.1f} {:>9.3f} {:>7.2f} {:>7.2f}\n",
                 name, tm.predictor * ms, tm.boundaries * ms, tm.poisson * ms, tm.projection * ms,
                 step * 1e3, step / cells * 1e9, floor * 1e3, ratio, poisson_ratio);
      j["grids"].push_back({{"name", name},
                            {"nx", s.grid().nx()},
                            {"ny", s.grid().ny()},
                            {"diffusion", implicit ? "implicit" : "explicit"},
                            {"helmholtz", mode == 2 ? "factored" : implicit ? "direct" : "none"},
                            {"steps", steps},
                            {"ms_per_step",
                             {{"predictor", tm.predictor * ms},
                              {"boundaries", tm.boundaries * ms},
                              {"poisson", tm.poisson * ms},
                              {"projection", tm.projection * ms},
                              {"total", step * 1e3}}},
                            {"ns_per_cell_step", step / cells * 1e9},
                            {"poisson_floor_ms", floor * 1e3},
                            {"step_to_floor_ratio", ratio},
                            {"poisson_to_floor_ratio", poisson_ratio}});
    }
  }
  // The convective terms alone on the vocal folds' grid (560 + 40 sponge cells by 100): central
  // fluxes, the upwind blend 0.2, and the third-order upwind correction added to either.
  {
    AxisSpec ax{560, 5.6, 0.0}, ay{100, 1.0, 0.0};
    ax.sponge_cells = 40;
    ax.sponge_ratio = 1.05;
    const Grid g(ax, ay);
    const int nx = g.nx(), ny = g.ny();
    Field u(nx + 1, ny), v(nx, ny + 1), hu(nx + 1, ny), hv(nx, ny + 1);
    std::vector<double> work;
    for (std::size_t q = 0; q < u.a.size(); ++q) u.a[q] = std::sin(0.37 * double(q));
    for (std::size_t q = 0; q < v.a.size(); ++q) v.a[q] = std::cos(0.29 * double(q));
    fmt::print("\nconvective terms on 600 x 100 (vocal folds), ms per call\n");
    j["convection"] = nlohmann::json::array();
    for (const double b : {0.0, 0.2}) {
      const SpongeWeights sw = sponge_weights(g, b);
      const double two = seconds_per_call(
          [&] { momentum_terms(g, sw, u, v, 1e-3, 1, 1, hu, hv, nullptr, nullptr); }, 0.1 * budget);
      const double three = seconds_per_call(
          [&] {
            momentum_terms(g, sw, u, v, 1e-3, 1, 1, hu, hv, nullptr, nullptr);
            upwind3_terms(g, sw, u, v, OuterRows{}, OuterRows{}, 1, 1, hu, hv, work);
          },
          0.1 * budget);
      fmt::print("  blend {:.1f}: two-point {:.3f}, with upwind3 {:.3f}\n", b, two * 1e3, three * 1e3);
      j["convection"].push_back({{"blend", b}, {"two_point_ms", two * 1e3}, {"upwind3_ms", three * 1e3}});
    }
  }
  // The immersed forcing on the Turek-Hron obstacle (cylinder of radius 0.05 at (0.2, 0.2) and
  // the bar [0.249, 0.6] x [0.19, 0.21]) in the 1000 x 164 channel: a whole step with Eq. 21 and
  // with interface = "sharp", one after the other. The faces' alpha by 8 x 8 samples per box
  // (a bench: the time, not the geometry, matters).
  {
    Case k = channel(1000, 164);
    auto inside = [](double x, double y) {
      return (x - 0.2) * (x - 0.2) + (y - 0.2) * (y - 0.2) < 0.05 * 0.05 ||
             (x > 0.24899 && x < 0.6 && y > 0.19 && y < 0.21);
    };
    std::vector<std::int32_t> index[2];
    std::vector<double> alpha[2], zero[2];
    {
      const Solver probe(k.cfg, k.dt);
      const Grid& g = probe.grid();
      for (int comp = 0; comp < 2; ++comp) {
        const int ni = comp == 0 ? g.nu() : g.nx(), nj = comp == 0 ? g.ny() : g.nv();
        for (int j = 0; j < nj; ++j)
          for (int i = 0; i < ni; ++i) {
            // The face's box: between the centres along its own direction, the faces across.
            const double x0 = comp == 0 ? g.x().centre(i - 1) : g.x().face(i);
            const double x1 = comp == 0 ? g.x().centre(i) : g.x().face(i + 1);
            const double y0 = comp == 0 ? g.y().face(j) : g.y().centre(j - 1);
            const double y1 = comp == 0 ? g.y().face(j + 1) : g.y().centre(j);
            if (x1 < 0.14 || x0 > 0.61 || y1 < 0.14 || y0 > 0.26) continue;
            int in = 0;
            for (int a = 0; a < 8; ++a)
              for (int b = 0; b < 8; ++b)
                in += inside(x0 + (a + 0.5) / 8 * (x1 - x0), y0 + (b + 0.5) / 8 * (y1 - y0));
            if (in == 0) continue;
            index[comp].push_back(i + ni * j);
            alpha[comp].push_back(in / 64.0);
          }
        zero[comp].assign(index[comp].size(), 0.0);
      }
    }
    CouplingIn in;
    in.solid_u_index = index[0], in.solid_v_index = index[1];
    in.solid_u_alpha = alpha[0], in.solid_v_alpha = alpha[1];
    in.solid_u_velocity = zero[0], in.solid_v_velocity = zero[1];
    in.solid_u_elastic = zero[0], in.solid_v_elastic = zero[1];  // a rigid body
    fmt::print("\nimmersed forcing on the Turek-Hron obstacle, 1000 x 164 ({} u, {} v faces), ms "
               "per step\n", index[0].size(), index[1].size());
    j["immersed_forcing"] = nlohmann::json::object();
    for (const bool sharp : {false, true}) {
      Config c = k.cfg;
      c.sharp_interface = sharp;
      Solver s(c, k.dt);
      CouplingOut o;
      const double step = seconds_per_call([&] { s.step(k.dt, in, o); }, 0.25 * budget);
      fmt::print("  {}: {:.3f}\n", sharp ? "sharp" : "Eq. 21", step * 1e3);
      j["immersed_forcing"][sharp ? "sharp_ms" : "volume_ms"] = step * 1e3;
    }
  }
  // The transforms along t on 600 lines (the vocal folds' channel has 100 (1 + h/D) rows across,
  // transformed, and 600 columns): FFTW's plan and the matrix product one after the other, and
  // which one the solver takes.
  fmt::print("\nREDFT10 on 600 lines, ms per transform: length, FFTW, dense product, the solver's\n");
  j["transforms"] = nlohmann::json::array();
  for (const int n : {82, 100, 101, 102, 103, 104, 123, 164, 246}) {
    const int lines = 600;
    const std::size_t size = std::size_t(n) * lines;
    double* buf = fftw_alloc_real(size);
    std::vector<double> input(size);
    for (std::size_t q = 0; q < size; ++q) input[q] = std::sin(0.37 * double(q));
    const int dims[1] = {n};
    fftw_r2r_kind kind[1] = {FFTW_REDFT10};
    fftw_plan p = fftw_plan_many_r2r(1, dims, lines, buf, nullptr, 1, n, buf, nullptr, 1, n, kind,
                                     FFTW_ESTIMATE);
    DenseTransform dense(FFTW_REDFT10, n, lines, n);
    // Each call transforms the same input (copied in: its time is measured and taken off).
    auto load = [&] { std::copy(input.begin(), input.end(), buf); };
    const double load_s = seconds_per_call(load, 0.05 * budget);
    const double fftw =
        seconds_per_call([&] { load(), fftw_execute(p); }, 0.1 * budget) - load_s;
    const double prod = seconds_per_call([&] { load(), dense.apply(buf); }, 0.1 * budget) - load_s;
    const bool taken = DenseTransform::preferred(FFTW_REDFT10, n);
    fmt::print("  {:>4} {:>8.3f} {:>8.3f}  {}\n", n, fftw * 1e3, prod * 1e3, taken ? "dense" : "FFTW");
    j["transforms"].push_back(
        {{"n", n}, {"lines", lines}, {"fftw_ms", fftw * 1e3}, {"dense_ms", prod * 1e3},
         {"solver_takes", taken ? "dense" : "fftw"}});
    fftw_destroy_plan(p);
    fftw_free(buf);
  }
  fmt::print("notes: change | predicted | measured\n");
  fmt::print("  Crank-Nicolson's Helmholtz solves factored along the grid lines (was: FFTW + Thomas, "
             "749 points in the u solve) | two solves 3.4 -> 0.6 Poisson floors, step 5.3 -> 2.9 | "
             "step/floor 5.20 -> 2.99 and 5.26 -> 2.76 (750x123), 5.34 -> 3.14 and 5.33 -> 2.98 (1500x246), "
             "two runs\n");
  fmt::print("  its x lines 8 at a time, one multiply-add per step of each chain; the y elimination "
             "while the rows are in cache | -30 % per solve | 0.33 -> 0.20-0.24 ms (749 x 123)\n");
  fmt::print("  the transform along t as a matrix product where FFTW has only its generic O(n^2) "
             "code (a prime length, a prime factor above 13), half of it by the matrix's symmetry, "
             "vectorised across the lines (AVX2) | 2-3x per transform at 101 rows | vocal folds "
             "h = 0.01 (600 x 101), Poisson 1.42 -> 0.46 ms per step\n");
  fmt::print("  a stretched transform direction by its eigenvectors as a dense product (bands in x "
             "and y at once) | the Poisson floor of 123 rows x 2 (no symmetry to halve the product) | "
             "see the banded 750x123 rows against channel 750x123\n");
  fmt::print("  fluid.convection = \"upwind3\": its correction as a second pass over the grid, the "
             "inner loops without index wrapping | about +50 % of the convective terms | see "
             "\"convective terms\" above (1.26-1.44 -> 1.91-2.37 ms, two runs beside a coupled "
             "run)\n");
  fmt::print("  fluid.interface = \"sharp\": each cut face's line from its family's alpha on the "
             "whole grid (two passes over the faces, O(grid) only to size the maps once) | a few "
             "per cent of a step | +8 % (3.99 -> 4.29 ms on 1000 x 164, one run beside a coupled run)\n");
  std::ofstream(out) << j.dump(2) << "\n";
  fmt::print("written {}\n", out);
  return 0;
}
