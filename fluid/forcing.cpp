// The immersed solid's forcing of the fluid (paper Eq. 21) on the predictor u~.
#include "solver.hpp"

namespace fluid {

namespace {
// A face the body covers (alpha = 1 up to the footprint's round-off).
constexpr double kCovered = 1 - 1e-9;
}  // namespace

// The relaxation time tau (fluid.forcing_time). The predictor carries the pressure gradient of
// step n, u~ = u^n + dt R (R: convection, diffusion, -grad p^n, body force), so in a steady flow
// the projection's increment vanishes, u^(n+1) = u^n = u, and a face blended by beta keeps
//   u = (1 - beta)(u + dt R) + beta u_s   =>   u - u_s = (1 - beta)/beta dt R:
// with beta = alpha the slip of a cut face grows with dt. Blending by
//   beta = alpha dt / ((1 - alpha) tau + alpha dt)
// gives (1 - beta)/beta dt = (1 - alpha)/alpha tau: the slip (1 - alpha)/alpha tau R whatever
// dt. It is the implicit relaxation u = (u~ + K u_s)/(1 + K), K = alpha dt / ((1 - alpha) tau),
// so 0 <= beta <= 1 for any dt: a contraction towards u_s, stable for any tau >= 0. tau = dt is
// Eq. 21; tau = 0 holds every face the body touches at u_s (the limit dt -> 0 of Eq. 21).
// The increment form blends u^ by the same beta before its solve, pull = beta (u_s - u^): its
// steady state is the explicit balance u = (1 - beta)(u + dt R) + beta u_s above, so the slip
// (1 - alpha)/alpha tau R holds there at any dt and any lambda (tau = 0: u = u_s on a touched
// face at a steady state; within a step the faces keep the solve's values, as covered ones do).
double Solver::forcing_fraction(double alpha, double dt) const {
  const double tau = m_cfg.forcing_time;
  if (tau < 0 || alpha <= 0) return alpha;
  return alpha >= kCovered ? 1.0 : alpha * dt / ((1 - alpha) * tau + alpha * dt);
}

// Immersed solid (paper Eq. 21): f_s = rho_f alpha (u_s - u~) / dt (beta with forcing_time:
// forcing_fraction above), then u~ += dt f_s / rho_f, i.e. u~ <- (1 - alpha) u~ + alpha u_s, on
// the solid's faces (the u faces the step solves for: the interior and a pressure side's
// boundary faces; Crank-Nicolson has no pressure sides).
//
// Crank-Nicolson in increment form (implicit_forcing = "increment", predictor.cpp) forced its
// explicit prediction before the solve, pull = alpha (u_s - u^) (beta with forcing_time), and
// f_s = rho_f pull / dt: the momentum the forcing put into the solve. The faces keep the solve's
// values, the covered ones too. Its step, with A = I - (nu dt/2) L, D = diag(1 - alpha) and the
// body at rest,
//   u^(n+1) = u^n + A^-1 (D (I + nu dt L) u^n - u^n),
// has the explicit balance u = D (I + nu dt L) u as its steady state (u = u_s on a covered face),
// and is stable at any lambda = nu dt / h^2 in a model of a wall (runs/sub-cell-wall/README.md).
// Setting the covered faces to u_s after the solve, as an earlier form did, made it unstable from
// lambda ~ 5: the solve treats the covered faces as fluid, so it gives the free faces next to
// the body a larger increment than a solve with those faces held would, and the mode there grew
// by a factor below -1 per step. A coupled iteration's redo solves again with its alpha and u_s.
void Solver::immersed_forcing(double dt, const CouplingIn& in, CouplingOut& out) {
  const double rho = m_cfg.density;
  const int ny = m_grid.ny();
  out.solid_u_force.resize(in.solid_u_index.size());
  out.solid_v_force.resize(in.solid_v_index.size());
  const bool cn = m_cfg.implicit && m_cfg.forcing_in_increment;
  if (cn && (m_pull[0].size() != in.solid_u_index.size() ||
             m_pull[1].size() != in.solid_v_index.size()))
    fsi::fail("protocol error: the step's solid faces changed between its solve and its forcing "
              "({} and {} u, v faces against {} and {})", m_pull[0].size(), m_pull[1].size(),
              in.solid_u_index.size(), in.solid_v_index.size());
  // The force on one face, whose velocity is w (alpha a, body velocity ws, pull of the
  // increment's forcing).
  auto force = [&](double& w, double a, double ws, double pull) {
    if (cn) return rho * pull / dt;
    const double f = rho * forcing_fraction(a, dt) * (ws - w) / dt;
    w += dt * f / rho;
    return f;
  };
  for (std::size_t q = 0; q < in.solid_u_index.size(); ++q) {
    const auto [i, j] = face_of(0, in.solid_u_index[q]);
    out.solid_u_force[q] =
        i >= m_iu0 && i < m_iu1
            ? force(m_u(i, owned(j, 0)), in.solid_u_alpha[q], in.solid_u_velocity[q],
                    cn ? m_pull[0][q] : 0.0)
            : 0.0;
  }
  for (std::size_t q = 0; q < in.solid_v_index.size(); ++q) {
    const auto [i, j] = face_of(1, in.solid_v_index[q]);
    out.solid_v_force[q] =
        j >= m_j0 && owned(j, 1) < ny
            ? force(m_v(i, j), in.solid_v_alpha[q], in.solid_v_velocity[q],
                    cn ? m_pull[1][q] : 0.0)
            : 0.0;
  }
}

}  // namespace fluid
