// Health checks: an inverted element (det F <= 0), a non-finite state or residual, a Newton
// iteration that did not converge. Each stops the run with a message naming the body, element or
// node, the step and the time.
#include <cmath>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

void Solver::fail_health(const std::string& what, int body, int element,
                         const std::string& when) const {
  const Body& B = *m_bodies[body];
  const auto& t = B.spec.mesh.triangles[element];
  step_failed("{} in body '{}' element {} (nodes {}, {}, {}; det F = {:.4g}) at {}", what,
            B.spec.name, element, t[0], t[1], t[2], B.det_f[element], when);
}

void Solver::check_finite(const std::string& when) const {
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    for (std::size_t d = 0; d < B.x.size(); ++d)
      if (!std::isfinite(B.x[d]) || !std::isfinite(B.v[d]))
        step_failed("non-finite {} in body '{}' node {} at {}",
                  std::isfinite(B.x[d]) ? "velocity" : "position", B.spec.name, d / 2, when);
  }
}

void Solver::check_inverted(const std::string& when) const {
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (std::size_t e = 0; e < B.det_f.size(); ++e)
      if (!(B.det_f[e] > 0))
        fail_health("element turned inside out (det F <= 0)", B.index, static_cast<int>(e), when);
  }
}

// A residual that stayed non-finite after the step halvings: an inverted element of the last
// assembly if there is one, else the first free node whose residual is NaN or Inf.
void Solver::fail_non_finite_residual(std::pair<int, int> inverted, const std::string& when) const {
  if (inverted.first >= 0)
    fail_health("element turned inside out (det F <= 0) during Newton", inverted.first,
                inverted.second, when);
  for (const auto& bp : m_bodies)
    for (std::size_t d = 0; d < bp->r.size(); ++d)
      if (bp->is_elastic() && bp->eq[d] >= 0 && !std::isfinite(bp->r[d]))
        step_failed("non-finite residual (NaN or Inf) in body '{}' node {} at {}",
                  bp->spec.name, d / 2, when);
  step_failed("non-finite residual (NaN or Inf) at {}", when);
}

// Newton at its iteration limit. Names the node with the largest residual: that of the assembled
// equation (a periodic pair's nodes share one, and their own shares cancel in it), at its first
// node.
void Solver::fail_not_converged(const StepReport& rep, const std::string& when) const {
  int worst_eq = -1;
  if (m_neq > 0) m_residual.cwiseAbs().maxCoeff(&worst_eq);
  int wb = -1, wn = -1;
  for (const auto& bp : m_bodies)
    for (std::size_t d = 0; d < bp->eq.size() && wb < 0; ++d)
      if (bp->is_elastic() && bp->eq[d] == worst_eq) {
        wb = bp->index;
        wn = static_cast<int>(d / 2);
      }
  step_failed(
      "Newton did not converge in {} iterations at {}: residual {:.3e}, tolerance "
      "{:.3e}, {} active contacts; largest residual in body '{}' node {}",
      rep.iterations, when, rep.residuals.back(), rep.tolerance, rep.active_contacts,
      wb >= 0 ? m_bodies[wb]->spec.name : "?", wn);
}

}  // namespace solid
