// A scope's wall time added to one phase's total (Solver::timings()).
#pragma once

#include <chrono>

namespace fluid {

class PhaseTimer {
 public:
  explicit PhaseTimer(double& total) : m_total(total), m_t0(std::chrono::steady_clock::now()) {}
  ~PhaseTimer() {
    m_total += std::chrono::duration<double>(std::chrono::steady_clock::now() - m_t0).count();
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

 private:
  double& m_total;
  std::chrono::steady_clock::time_point m_t0;
};

}  // namespace fluid
