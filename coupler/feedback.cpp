// The feedback immersed boundary's force on the fibers (paper Sec. 3.2.2, Eq. 23-25; Huang & Sung
// 2009) and its default stiffness κ. The 4-point delta it interpolates and spreads with: ib.hpp.
#include <algorithm>
#include <cstdio>

#include "coupler.hpp"

namespace coupler {

// Default κ: the feedback acts as a spring between a marker and where the fluid carries it,
// applied explicitly. Over one step it closes the fraction
//   g = κ Δt² (1/m' + 1/m_f)
// of the gap, with m' the fiber's line density (∞ for prescribed motion) and m_f = ρ_f h a lower
// bound of the fluid mass per unit length the delta function reaches. g < 2 is the explicit
// stability bound of that spring; the default takes g = coupler.kappa_gain for the lightest fiber.
void Coupler::default_kappa() {
  const double h = std::min(m_ib->hx(), m_ib->hy());
  const double dt = m_rt.settings().dt;
  double inv_mass = 1.0 / (m_grid.density * h);
  double lightest = 0;
  for (const auto& f : m_layout.fibers)
    if (f.line_density > 0) lightest = std::max(lightest, 1.0 / f.line_density);
  inv_mass += lightest;
  m_kappa = m_kappa_gain / (dt * dt * inv_mass);
  std::fprintf(stderr, "[coupler] feedback stiffness kappa = %.4g (gain %.2g at dt = %.3g)\n",
               m_kappa, m_kappa_gain, dt);
}

// Feedback force on each fiber's markers (Eq. 23-24, force per unit length on the fiber):
//   F = κ (X_ib − 2Xⁿ + X^(n−1)),  X_ib = Xⁿ + Δt U(Xⁿ),
// i.e. κ Δt (U(Xⁿ) − (Xⁿ − X^(n−1))/Δt): it pulls each marker towards the fluid's velocity. The
// fluid receives the opposite, f_f, spread with the same delta function (Eq. 25). U(Xⁿ) comes from
// the fluid's samples of uⁿ taken after the previous step; on the very first step there are none
// and the feedback starts one step later. The faces to sample for the next step are the kernels
// of Xⁿ widened by one cell (a marker moves less than a cell per step).
void Coupler::feedback_forces() {
  if (!m_ib) return;
  m_phases.start("fibers");
  const double dt = m_rt.settings().dt;
  for (std::size_t k = 0; k < m_layout.fibers.size(); ++k) {
    const auto& X = m_fiber.x[k];
    const auto& Xo = m_fiber.x_old[k];
    auto& F = m_fiber_in.force[k];
    if (!m_have_samples) {
      F.assign(X.size(), 0.0);
      continue;
    }
    m_ib->feedback(X, Xo, m_kappa, dt, m_layout.fibers[k].ds, F);
  }
  // The next step's samples: the kernels of Xⁿ widened by a cell, which hold the faces spread to.
  m_ib->stencil(m_fiber.x, 1, m_fluid_in.sample_u, m_fluid_in.sample_v);
  m_ib->take_spread(m_fluid_in.sample_u, m_fluid_in.sample_v, m_fluid_in.force_u,
                    m_fluid_in.force_v);
  m_phases.stop("fibers");
}

}  // namespace coupler
