// The fluid's viscosity taken out of the bodies ([fluid] body_viscosity = "none").
#include <algorithm>

#include "solver.hpp"

namespace fluid {

// The immersed solid's forcing holds the fluid inside a body at the body's velocity, and the
// fluid's momentum equation there keeps its viscous term; through the reaction the body receives
// it, so a body behaves as a Kelvin-Voigt solid with μ_s = μ_f (runs/two-layer-channel). With
// body_viscosity = "none" the fluid's stress is that of a mixture, (1 − φ) μ ∇u, φ the bodies'
// volume fraction, so that a body carries only its own (elastic) stress. Discretely the
// predictor's viscous term ν L uⁿ becomes ν L_(1−φ) uⁿ: on each face f
//   ũ_f −= Δt ν Σ_g φ_fg c_fg (uⁿ_g − uⁿ_f),
// g the four neighbours of f in the MAC Laplacian L (c_fg its coefficients: the same
// differences as momentum.cpp), φ_fg = min(α_f, α_g) (α from the coupling input, capped at 1):
// the flux between two faces is taken out as far as both control volumes lie in a body. A link
// with a face of the fluid (α = 0) keeps its flux, so the fluid's traction on a body's surface
// stays whole and only faces of the footprint change. Each flux between two faces is taken out
// on both with the same difference, so where L conserves momentum L_(1−φ) does too (the mean
// (α_f + α_g)/2 would halve the traction where a surface lies on a grid line). Crank-Nicolson:
// the explicit prediction û carries ν Δt L uⁿ (predictor.cpp) and takes the same correction
// before its solve; the solve's ½ ν Δt L₀ (ũ − uⁿ) is left inside the body, O(Δt).
//
// F holds the prediction (ũ or û); uⁿ is m_un, m_vn. One rank only (checked at set-up).
void Solver::remove_body_viscosity(double dt, const CouplingIn& in) {
  if (!m_cfg.bodies_inviscid) return;
  const int nx = m_grid.nx(), ny = m_grid.ny();
  const bool px = m_grid.x().periodic(), py = m_grid.y().periodic();
  const Axis& X = m_grid.x();
  const Axis& Y = m_grid.y();
  const double *xwi = X.wi(), *xdi = X.di(), *xci = X.ci();
  const double *ywi = Y.wi(), *ydi = Y.di(), *yci = Y.ci();
  for (int comp = 0; comp < 2; ++comp) {
    Field& F = comp == 0 ? m_u : m_v;
    const Field& Fn = comp == 0 ? m_un : m_vn;
    Field& A = m_body_alpha[comp];
    std::vector<char>& mark = m_body_mark[comp];
    const auto& idx = comp == 0 ? in.solid_u_index : in.solid_v_index;
    const auto& alpha = comp == 0 ? in.solid_u_alpha : in.solid_v_alpha;
    // Faces along x and y of this family (a periodic direction's last face is its first).
    const int ni = comp == 0 ? (px ? nx : nx + 1) : nx;
    const int nj = comp == 0 ? ny : (py ? ny : ny + 1);
    // The faces whose velocity the step solves for.
    const int i_lo = comp == 0 ? m_iu0 : 0, i_hi = comp == 0 ? m_iu1 : nx;
    const int j_lo = comp == 0 ? 0 : m_j0, j_hi = ny;
    auto wrap = [](int k, int n, bool periodic) { return periodic ? (k + n) % n : k; };
    auto inside = [&](int i, int j) { return i >= 0 && i < ni && j >= 0 && j < nj; };
    auto a_at = [&](int i, int j) {
      i = wrap(i, ni, px), j = wrap(j, nj, py);
      return inside(i, j) ? A(i, j) : 0.0;
    };
    for (std::size_t q = 0; q < idx.size(); ++q) {
      const auto [i, j] = face_of(comp, idx[q]);
      A(i, j) = std::min(1.0, A(i, j) + alpha[q]);
    }
    // −Δt ν Σ_g φ_fg c_fg (uⁿ_g − uⁿ_f) on each face of the footprint, once.
    for (std::size_t q = 0; q < idx.size(); ++q) {
      const auto [i, j] = face_of(comp, idx[q]);
      if (i < i_lo || i >= i_hi || j < j_lo || j >= j_hi) continue;
      char& m = mark[std::size_t(i) + std::size_t(ni) * j];
      if (m) continue;
      m = 1;
      const double a = A(i, j), c = Fn(i, j);
      double cx_e, cx_w, cy_n, cy_s;  // coefficients of the east, west, north, south links
      if (comp == 0) {
        cx_e = xwi[i] * xdi[i], cx_w = xwi[i - 1] * xdi[i];
        cy_n = ydi[j + 1] * yci[j], cy_s = ydi[j] * yci[j];
      } else {
        cx_e = xdi[i + 1] * xci[i], cx_w = xdi[i] * xci[i];
        cy_n = ywi[j] * ydi[j], cy_s = ywi[j - 1] * ydi[j];
      }
      const double d = std::min(a, a_at(i + 1, j)) * cx_e * (Fn(i + 1, j) - c) +
                       std::min(a, a_at(i - 1, j)) * cx_w * (Fn(i - 1, j) - c) +
                       std::min(a, a_at(i, j + 1)) * cy_n * (Fn(i, j + 1) - c) +
                       std::min(a, a_at(i, j - 1)) * cy_s * (Fn(i, j - 1) - c);
      F(i, j) -= dt * m_nu * d;
    }
    // Back to zero for the next step (the footprint moves).
    for (std::size_t q = 0; q < idx.size(); ++q) {
      const auto [i, j] = face_of(comp, idx[q]);
      A(i, j) = 0;
      mark[std::size_t(i) + std::size_t(ni) * j] = 0;
    }
  }
}

}  // namespace fluid
