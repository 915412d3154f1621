// Static analysis: the loads and prescribed displacements scaled by the load factor
// k / load_steps, each load step an equilibrium R(x) + B^T lambda = 0 solved by Newton
// (newton.cpp, no inertia: c0 = 0).
#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

StepReport Solver::solve_static_step(double factor) {
  const std::string when = fmt::format("load factor {:.6g}", factor);
  prepare_prescribed(factor);
  m_contact_force_factor = 1.0;  // without inertia the multiplier is the contact force
  keep_step_start();
  remember_fronts();
  StepReport rep = newton(0, 0, factor, nullptr, when);
  check_finite(when);
  check_inverted(when);
  return rep;
}

std::vector<StepReport> Solver::solve_static() {
  if (m_model.settings.analysis != Analysis::statics)
    fsi::fail("solve_static() needs a static analysis");
  std::vector<StepReport> reps;
  const int n = m_model.settings.load_steps;
  for (int k = 1; k <= n; ++k) {
    reps.push_back(solve_static_step(static_cast<double>(k) / n));
    m_step = k;
  }
  return reps;
}

}  // namespace solid
