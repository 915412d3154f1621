// The status line of a long run on stderr: step, simulated time, dt, steps/s, ETA, and the
// caller's own fields (CFL, a key probe). On a terminal it redraws one line ('\r') at most every
// ~0.5 s; otherwise (a pipe, a log, mpirun's forwarding) it prints plain lines at most every few
// seconds. update() is cheap enough to call every step: when no line is due it reads a clock
// and compares, nothing more.
#pragma once

#include <chrono>
#include <cstdio>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>

#include <fmt/format.h>

namespace fsi {

// A caller-supplied field of the line, printed as "name value" with 3 significant digits.
struct ProgressField {
  const char* name;
  double value;
};

// "0.4 s", "12 s", "4m05s", "2h03m": a duration as a person reads it.
std::string format_duration(double seconds);

class Progress {
 public:
  using Clock = std::chrono::steady_clock;

  struct Options {
    std::FILE* out = stderr;
    std::optional<bool> is_tty;      // default: isatty(out)
    double tty_interval = 0.5;       // seconds between redraws on a terminal
    double plain_interval = 5.0;     // seconds between lines otherwise
    long every_steps = 0;            // > 0: print every this many steps instead (deterministic logs)
    bool is_enabled = true;          // false: print nothing (e.g. all but one process)
    long first_step = 0;             // a restarted run: the step and time it starts from
    double first_time = 0.0;
  };

  // `label` prefixes the line ("[fluid]"); total_steps and t_end give the ETA (<= 0: unknown).
  Progress(std::string label, long total_steps, double t_end, Options options);
  Progress(std::string label, long total_steps, double t_end)
      : Progress(std::move(label), total_steps, t_end, Options{}) {}

  // After step `step` reached time t with step size dt. Prints when a line is due.
  void update(long step, double t, double dt, std::initializer_list<ProgressField> fields = {}) {
    if (is_due(step)) print(step, t, dt, fields, {});
  }
  // The same with extra text that costs something to build ("CFL 0.31  div 1e-15"): `extra()`
  // returns a string and is called only when a line is printed.
  template <class F, class = std::enable_if_t<std::is_invocable_v<F&>>>
  void update(long step, double t, double dt, F&& extra) {
    if (is_due(step)) {
      const std::string text = extra();
      print(step, t, dt, {}, text);
    }
  }

  // The closing line ("done: ... steps in ... s"), always printed when enabled; ends the
  // terminal's redrawn line.
  void finish(long step, double t, std::string_view extra = {});

  long lines() const { return m_lines; }  // lines printed so far (tests)

 private:
  bool is_due(long step) {
    if (!m_options.is_enabled) return false;
    if (m_options.every_steps > 0) return step % m_options.every_steps == 0;
    return Clock::now() >= m_next;
  }
  void print(long step, double t, double dt, std::initializer_list<ProgressField> fields,
             std::string_view extra);
  void emit(const std::string& line, bool is_final);

  std::string m_label;
  long m_total_steps;
  double m_t_end;
  Options m_options;
  bool m_is_tty;
  double m_interval;
  Clock::time_point m_start;
  Clock::time_point m_next;
  // The previous printed line, for the rate over the last window.
  Clock::time_point m_last_wall;
  long m_last_step = 0;
  double m_last_t = 0.0;
  double m_rate_steps = 0.0;  // smoothed steps per wall second
  double m_rate_time = 0.0;   // smoothed simulated time per wall second
  long m_lines = 0;
  std::size_t m_last_width = 0;
};

}  // namespace fsi
