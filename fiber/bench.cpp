// bench_fiber: time per fiber step split into forces (bending, repulsion, predictor), tension
// equation and update (positions, end loads, health), for the paper's glycocalyx (16 fibers x 62
// segments, Table 4) and one fiber of 1000 segments, plus the growth with the marker count.
// Writes JSON to --out FILE and prints a table.
#include <fmt/format.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "system.hpp"

using namespace fiber;
using Clock = std::chrono::steady_clock;

namespace {

struct Result {
  std::string name;
  int fibers = 0;
  std::size_t markers = 0;
  long steps = 0;
  double forces = 0, tension = 0, update = 0;  // microseconds per step
  double solves = 0;                           // tension solves per fiber and step
  double total() const { return forces + tension + update; }
  double ns_per_marker() const { return 1e3 * total() / markers; }
};

// A row of `count` clamped fibers standing on y = 0, `segments` each, bent by a uniform
// sideways load that reverses periodically (a pulsating flow's drag, paper Sec. 5.2), with
// repulsion within half a cell of the paper's 128 x 96 grid.
Config row(int count, int segments) {
  Config c;
  for (int k = 0; k < count; ++k) {
    FiberSpec f;
    f.name = fmt::format("g{}", k);
    f.key = fmt::format("fiber.fiber[{}]", k);
    f.length = 0.125;
    f.segments = segments;
    f.density = 0.1;
    f.bending = 1e-4;
    f.position = {(k + 0.5) / 16.0, 0.0};
    f.angle = std::numbers::pi / 2;
    f.root.kind = EndKind::clamped;
    c.fibers.push_back(f);
  }
  c.repulsion = {true, 1e-10, 0.5 / 128};
  return c;
}

Result run(const std::string& name, const Config& c, long steps) {
  FiberSystem sys(c);
  const double dt = 0.9 * bending_dt_limit(c.fibers[0]);
  std::vector<double> ext(2 * sys.total_markers(), 0.0);
  const long period = 4000;
  for (long n = 0; n < steps + 200; ++n) {
    const double load = ((n / period) % 2 == 0 ? 1.0 : -1.0) * 0.02;
    for (std::size_t i = 0; i < sys.total_markers(); ++i) ext[2 * i] = load;
    if (n == 200) {  // warm-up done
      sys.reset_phase_times();
    }
    sys.advance(dt, ext);
  }
  const PhaseTimes& t = sys.phase_times();
  Result r;
  r.name = name;
  r.fibers = sys.fiber_count();
  r.markers = sys.total_markers();
  r.steps = t.steps;
  r.forces = 1e6 * t.forces / t.steps;
  r.tension = 1e6 * t.tension / t.steps;
  r.update = 1e6 * t.update / t.steps;
  r.solves = double(t.tension_solves) / (double(t.steps) * r.fibers);
  return r;
}

nlohmann::json to_json(const Result& r) {
  return {{"name", r.name},         {"fibers", r.fibers},   {"markers", r.markers},
          {"steps", r.steps},       {"us_per_step", r.total()}, {"forces_us", r.forces},
          {"tension_us", r.tension}, {"update_us", r.update}, {"ns_per_marker_step", r.ns_per_marker()},
          {"tension_solves_per_fiber_step", r.solves}};
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) out = argv[++i];

  std::vector<Result> main_cases = {run("16 fibers x 62 segments (paper Table 4)", row(16, 62), 20000),
                                    run("1 fiber x 1000 segments", row(1, 1000), 4000)};
  std::vector<Result> growth_one, growth_many;
  for (int n : {125, 250, 500, 1000, 2000, 4000, 8000})
    growth_one.push_back(run(fmt::format("1 fiber x {} segments", n), row(1, n), 4'000'000 / n));
  for (int k : {4, 16, 64, 256})
    growth_many.push_back(run(fmt::format("{} fibers x 62 segments", k), row(k, 62), 320'000 / k));

  fmt::print("{:<42} {:>8} {:>10} {:>9} {:>9} {:>9} {:>11} {:>8}\n", "case", "markers", "us/step", "forces",
             "tension", "update", "ns/marker", "solves");
  const auto line = [](const Result& r) {
    fmt::print("{:<42} {:>8} {:>10.2f} {:>9.2f} {:>9.2f} {:>9.2f} {:>11.1f} {:>8.2f}\n", r.name, r.markers,
               r.total(), r.forces, r.tension, r.update, r.ns_per_marker(), r.solves);
  };
  for (const auto& r : main_cases) line(r);
  fmt::print("growth with the marker count:\n");
  for (const auto& r : growth_one) line(r);
  for (const auto& r : growth_many) line(r);

  nlohmann::json j;
  j["benchmark"] = "fiber";
  j["note"] = "explicit step at 0.9 of the bending limit; clamped fibers under a reversing load; "
              "repulsion within 0.5/128 (cell list)";
  for (const auto& r : main_cases) j["cases"].push_back(to_json(r));
  for (const auto& r : growth_one) j["growth_one_fiber"].push_back(to_json(r));
  for (const auto& r : growth_many) j["growth_many_fibers"].push_back(to_json(r));
  // Linear growth: ns per marker-step should stay flat from the smallest to the largest case.
  j["ns_per_marker_ratio_one_fiber"] = growth_one.back().ns_per_marker() / growth_one.front().ns_per_marker();
  j["ns_per_marker_ratio_many_fibers"] = growth_many.back().ns_per_marker() / growth_many.front().ns_per_marker();
  if (!out.empty()) {
    std::ofstream f(out);
    f << j.dump(2) << "\n";
    if (!f) {
      fmt::print(stderr, "bench_fiber: cannot write {}\n", out);
      return 1;
    }
    fmt::print("written {}\n", out);
  }
  return 0;
}
