// A scope's wall time added to one phase's total, and its CPU time (of the calling thread) to
// the phases' common CPU total (Solver::timings()).
#pragma once

#include <chrono>

#include "summary.hpp"

namespace fluid {

class PhaseTimer {
 public:
  PhaseTimer(double& total, double& cpu_total)
      : m_total(total), m_cpu_total(cpu_total), m_t0(std::chrono::steady_clock::now()),
        m_cpu0(fsi::thread_cpu_seconds()) {}
  ~PhaseTimer() {
    m_total += std::chrono::duration<double>(std::chrono::steady_clock::now() - m_t0).count();
    m_cpu_total += fsi::thread_cpu_seconds() - m_cpu0;
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  double& m_total;
  double& m_cpu_total;
  std::chrono::steady_clock::time_point m_t0;
  double m_cpu0;
};

}  // namespace fluid
