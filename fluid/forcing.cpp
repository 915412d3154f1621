// The immersed solid's forcing of the fluid (paper Eq. 21) on the predictor u~.
#include "solver.hpp"

namespace fluid {

namespace {
// A face the body covers (alpha = 1 up to the footprint's round-off).
constexpr double kCovered = 1 - 1e-9;
}  // namespace

// Immersed solid (paper Eq. 21): f_s = rho_f alpha (u_s - u~) / dt, then u~ += dt f_s / rho_f,
// i.e. u~ <- (1 - alpha) u~ + alpha u_s, on the solid's faces (the u faces the step solves for:
// the interior and a pressure side's boundary faces). Crank-Nicolson in increment form
// (predictor.cpp) forced its explicit prediction before the solve (m_pull); here it sets the
// covered faces to u_s, and f_s is the sum of both.
void Solver::immersed_forcing(double dt, const CouplingIn& in, CouplingOut& out) {
  const double rho = m_cfg.density;
  const int ny = m_grid.ny();
  out.solid_u_force.resize(in.solid_u_index.size());
  out.solid_v_force.resize(in.solid_v_index.size());
  const bool cn = m_cfg.implicit && m_cfg.forcing_in_increment;
  for (std::size_t q = 0; q < in.solid_u_index.size(); ++q) {
    const auto [i, j] = face_of(0, in.solid_u_index[q]);
    double f = 0;
    if (i >= m_iu0 && i < m_iu1) {
      double& u = m_u(i, owned(j, 0));
      const double a = in.solid_u_alpha[q], us = in.solid_u_velocity[q];
      if (cn) {
        const double post = a >= kCovered ? us - u : 0.0;
        u += post;
        f = rho * (m_pull[0][q] + post) / dt;
      } else {
        f = rho * a * (us - u) / dt;
        u += dt * f / rho;
      }
    }
    out.solid_u_force[q] = f;
  }
  for (std::size_t q = 0; q < in.solid_v_index.size(); ++q) {
    const auto [i, j] = face_of(1, in.solid_v_index[q]);
    double f = 0;
    if (j >= m_j0 && owned(j, 1) < ny) {
      double& v = m_v(i, j);
      const double a = in.solid_v_alpha[q], vs = in.solid_v_velocity[q];
      if (cn) {
        const double post = a >= kCovered ? vs - v : 0.0;
        v += post;
        f = rho * (m_pull[1][q] + post) / dt;
      } else {
        f = rho * a * (vs - v) / dt;
        v += dt * f / rho;
      }
    }
    out.solid_v_force[q] = f;
  }
}

}  // namespace fluid
