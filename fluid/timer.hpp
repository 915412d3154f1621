// A scope's wall time added to one phase's total, and its CPU time (of the calling thread) to
// the phases' common CPU total (Solver::timings()).
#pragma once

#include <chrono>
#include <ctime>

namespace fluid {

class PhaseTimer {
 public:
  PhaseTimer(double& total, double& cpu_total)
      : m_total(total), m_cpu_total(cpu_total), m_t0(std::chrono::steady_clock::now()),
        m_cpu0(thread_cpu()) {}
  ~PhaseTimer() {
    m_total += std::chrono::duration<double>(std::chrono::steady_clock::now() - m_t0).count();
    m_cpu_total += thread_cpu() - m_cpu0;
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  static double thread_cpu() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
  }
  double& m_total;
  double& m_cpu_total;
  std::chrono::steady_clock::time_point m_t0;
  double m_cpu0;
};

}  // namespace fluid
