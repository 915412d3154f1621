// The status line printer (see progress.hpp).
#include "progress.hpp"

#include <unistd.h>

#include <cmath>

namespace fsi {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 10) return fmt::format("{:.1f} s", seconds);
  if (seconds < 60) return fmt::format("{:.0f} s", seconds);
  long s = std::lround(seconds);
  if (s < 3600) return fmt::format("{}m{:02d}s", s / 60, s % 60);
  return fmt::format("{}h{:02d}m", s / 3600, (s % 3600) / 60);
}

namespace {
std::string rate_text(double steps_per_second) {
  return steps_per_second >= 100 ? fmt::format("{:.0f} steps/s", steps_per_second)
                                 : fmt::format("{:.3g} steps/s", steps_per_second);
}
}  // namespace

Progress::Progress(std::string label, long total_steps, double t_end, Options options)
    : m_label(std::move(label)), m_total_steps(total_steps), m_t_end(t_end), m_options(options) {
  m_is_tty = m_options.is_tty ? *m_options.is_tty : ::isatty(::fileno(m_options.out)) == 1;
  m_interval = m_is_tty ? m_options.tty_interval : m_options.plain_interval;
  m_start = m_last_wall = Clock::now();
  m_last_step = m_options.first_step;
  m_last_t = m_options.first_time;
  m_next = m_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(m_interval));
}

void Progress::print(long step, double t, double dt, std::initializer_list<ProgressField> fields,
                     std::string_view extra) {
  const auto now = Clock::now();
  const double window = std::chrono::duration<double>(now - m_last_wall).count();
  if (window > 0 && step > m_last_step) {
    // Rates over the last window, smoothed so that one slow step does not swing the ETA.
    const double steps = (step - m_last_step) / window, time = (t - m_last_t) / window;
    const bool is_first = m_rate_steps == 0.0;
    m_rate_steps = is_first ? steps : 0.5 * (m_rate_steps + steps);
    m_rate_time = is_first ? time : 0.5 * (m_rate_time + time);
  }
  m_last_wall = now;
  m_last_step = step;
  m_last_t = t;

  std::string line = fmt::format("{} step {}", m_label, step);
  if (m_total_steps > 0) line += fmt::format("/{}", m_total_steps);
  line += fmt::format("  t {:.6g}", t);
  if (m_t_end > 0) line += fmt::format("/{:.6g}", m_t_end);
  line += fmt::format("  dt {:.3g}", dt);
  if (m_rate_steps > 0) {
    line += "  " + rate_text(m_rate_steps);
    double eta = -1;
    if (m_t_end > 0 && m_rate_time > 0)
      eta = std::max(0.0, (m_t_end - t) / m_rate_time);
    else if (m_total_steps > 0)
      eta = std::max(0.0, (m_total_steps - step) / m_rate_steps);
    if (eta >= 0) line += "  ETA " + format_duration(eta);
  }
  for (const ProgressField& f : fields) line += fmt::format("  {} {:.3g}", f.name, f.value);
  if (!extra.empty()) {
    line += "  ";
    line += extra;
  }
  emit(line, false);
  m_next = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(m_interval));
}

void Progress::emit(const std::string& line, bool is_final) {
  std::string text;
  if (m_is_tty) {
    // Redraw in place; the padding clears what a longer previous line left behind.
    text = "\r" + line;
    if (line.size() < m_last_width) text.append(m_last_width - line.size(), ' ');
    m_last_width = line.size();
    if (is_final) text += "\n";
  } else {
    text = line + "\n";
  }
  std::fputs(text.c_str(), m_options.out);
  std::fflush(m_options.out);
  ++m_lines;
}

void Progress::finish(long step, double t, std::string_view extra) {
  if (!m_options.is_enabled) return;
  const double wall = std::chrono::duration<double>(Clock::now() - m_start).count();
  std::string line = fmt::format("{} done: step {}, t {:.6g}, {} wall", m_label, step, t, format_duration(wall));
  const long done = step - m_options.first_step;
  if (wall > 0 && done > 0) line += " (" + rate_text(done / wall) + ")";
  if (!extra.empty()) {
    line += "  ";
    line += extra;
  }
  emit(line, true);
}

}  // namespace fsi
