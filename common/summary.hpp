// summary.json: what a run did and how well. A JSON document (nlohmann::json) with the scene
// name, step count, wall time per process and per phase, and the case's metrics as
// {value, reference, error, tolerance, pass}; written atomically so a reader never sees half a
// file. Also the wall-clock PhaseTimer that fills the per-phase times.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "error.hpp"

namespace fsi {

// CPU seconds of the calling thread (phase timers: a phase's own work).
double thread_cpu_seconds();

// Write `text` to `path` through a temporary file in the same folder and a rename, so that the
// file is at every moment either the old or the new content. Throws fsi::Error naming the path.
void write_file_atomically(const std::filesystem::path& path, std::string_view text);

// One measured quantity against its reference. pass = (error <= tolerance), false when the value
// or the error is not finite.
struct Metric {
  double value = 0.0;
  double reference = 0.0;
  double error = 0.0;
  double tolerance = 0.0;
  bool pass = false;

  // error = |value - reference| / |reference|; the absolute difference when reference == 0.
  static Metric relative(double value, double reference, double tolerance);
  // error = |value - reference|.
  static Metric absolute(double value, double reference, double tolerance);
  // An error computed by the caller (a norm over a profile, an order of convergence ...).
  static Metric with_error(double value, double reference, double error, double tolerance);
};

// JSON conversions for nlohmann::json and nlohmann::ordered_json (found by ADL).
template <class Json>
void to_json(Json& j, const Metric& m) {
  j = Json{{"value", m.value}, {"reference", m.reference}, {"error", m.error},
           {"tolerance", m.tolerance}, {"pass", m.pass}};
}
// A non-finite number is stored as null by nlohmann::json; it reads back as NaN.
template <class Json>
void from_json(const Json& j, Metric& m) {
  auto number = [&](const char* key) {
    const auto& v = j.at(key);
    return v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.template get<double>();
  };
  m.value = number("value");
  m.reference = number("reference");
  m.error = number("error");
  m.tolerance = number("tolerance");
  m.pass = j.at("pass").template get<bool>();
}

// Wall-clock time per named phase, accumulated over start/stop pairs. Call it around a step's
// phases, never inside their loops. Look a phase up once (phase(name) -> Id) and use the Id in
// the time loop to skip the name search. Not thread-safe; one per process.
class PhaseTimer {
 public:
  using Id = std::size_t;
  using Clock = std::chrono::steady_clock;

  Id phase(std::string_view name);  // registers the phase on first use; report order = this order
  void start(Id id);
  void stop(Id id);  // throws fsi::Error if the phase is not running
  void start(std::string_view name) { start(phase(name)); }
  void stop(std::string_view name) { stop(phase(name)); }

  // Starts a phase and stops it at scope exit.
  class Scope {
   public:
    Scope(PhaseTimer& timer, Id id) : m_timer(timer), m_id(id) { m_timer.start(m_id); }
    ~Scope() { m_timer.stop(m_id); }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    PhaseTimer& m_timer;
    Id m_id;
  };
  Scope scope(Id id) { return Scope(*this, id); }
  Scope scope(std::string_view name) { return Scope(*this, phase(name)); }

  double seconds(std::string_view name) const;  // 0 for a phase never timed
  long calls(std::string_view name) const;
  double total_seconds() const;  // sum over phases (phases are meant not to overlap)
  std::vector<std::string> names() const;

  // {"predictor": {"seconds": s, "calls": n, "seconds_per_call": s/n, "cpu_seconds": c,
  // "cpu_seconds_per_call": c/n}, ...} in registration order (nlohmann::ordered_json keeps it).
  // The CPU time is that of the thread that times the phase (not of helper threads): its own
  // work, without the time it was descheduled while the phase ran.
  nlohmann::ordered_json to_json() const;

 private:
  struct Entry {
    std::string name;
    double seconds = 0.0;
    double cpu_seconds = 0.0;  // of the thread that starts and stops the phase
    long calls = 0;
    Clock::time_point started{};
    double cpu_started = 0.0;
    bool is_running = false;
  };
  const Entry* find(std::string_view name) const;
  std::vector<Entry> m_entries;
};

// The summary document. Layout:
//   { "scene": "...", "steps": n,
//     "processes": { "fluid": { "wall_time": s, "steps": n, "phases": {...} }, ... },
//     "metrics": { "drag": { "value", "reference", "error", "tolerance", "pass" }, ... },
//     "pass": true }            // all metrics pass; absent when there are no metrics
// Anything else (settings, the effective scene) goes through json().
class Summary {
 public:
  explicit Summary(std::string_view scene_name);
  // A document read back (or built elsewhere); throws fsi::Error if it is not an object.
  static Summary from_json(nlohmann::ordered_json document);

  void set_steps(long steps);
  // One process's wall time (seconds) and its phase times; steps < 0 leaves its step count out.
  void set_process(std::string_view role, double wall_seconds, const PhaseTimer& phases, long steps = -1);
  void add_metric(std::string_view name, const Metric& metric);
  Metric metric(std::string_view name) const;

  // True when there is at least one metric and every metric passes.
  bool pass() const;

  // Adds the processes and metrics of `other` (the same scene run by another program) and any
  // top-level key this document lacks.
  void merge(const Summary& other);

  nlohmann::ordered_json& json() { return m_doc; }
  const nlohmann::ordered_json& json() const { return m_doc; }

  std::string dump() const;  // indented text with "pass" brought up to date
  void write(const std::filesystem::path& path) const;  // atomically
  static Summary read(const std::filesystem::path& path);

 private:
  nlohmann::ordered_json m_doc;
};

}  // namespace fsi
