// The fluid's viscosity taken out of the bodies ([fluid] body_viscosity = "none").
#include <algorithm>

#include "solver.hpp"

namespace fluid {

// The immersed solid's forcing holds the fluid inside a body at the body's velocity, and the
// fluid's momentum equation there keeps its viscous term; through the reaction the body receives
// it, so a body behaves as a Kelvin-Voigt solid with μ_s = μ_f (runs/two-layer-channel). With
// body_viscosity = "none" the fluid's stress is that of a mixture, (1 − φ) 2μ D(u), φ the bodies'
// volume fraction, so that a body carries only its own (elastic) stress. The predictor's viscous
// term ν L uⁿ = ν div(∇uⁿ) (= ν div(2D(uⁿ)) for div u = 0 and uniform ν) loses
// ν div(φ 2D(uⁿ)) on the footprint; in the symmetric form, so that a rigid motion (D = 0) is left
// alone and a body's surface keeps the whole traction, normal and tangential. On the MAC grid:
//   u face (i, j):  2 ∂x(φ ∂x u) + ∂y(φ (∂y u + ∂x v)),   v face:  ∂x(φ (∂y u + ∂x v)) + 2 ∂y(φ ∂y v),
// with ∂x u, ∂y v at the cell centres between two faces (the Laplacian's differences, momentum.cpp)
// and ∂y u + ∂x v at the cell corners, each divided by the Laplacian's widths. φ is the smallest
// α of the faces a difference reads: the two faces at a centre, the four around a corner (α from
// the coupling input, capped at 1). A face beyond a wall, or a boundary face (no unknown), does
// not count, so a body on a wall loses the wall's shear too. A difference that reads a fluid face
// (α = 0) keeps its flux. Every flux is taken out on both faces it joins, so momentum is
// conserved where L conserves it. Explicit in uⁿ: with AB2 the extrapolated part
// ½ ν Δt/Δt' L (uⁿ − uⁿ⁻¹) stays, O(Δt). Crank-Nicolson: û carries ν Δt L uⁿ (predictor.cpp) and
// takes the same correction before its solve; the solve's ½ ν Δt L₀ (ũ − uⁿ) is left inside the
// body, O(Δt).
//
// F holds the prediction (ũ or û); uⁿ is m_un, m_vn. On several ranks each rank has its own
// rows' faces in the coupling input; the α of the rows beyond the slab (a stencil reads one)
// come from the neighbours by a halo exchange, which overwrites them at every step (a slab's
// end without a neighbour is never written), as uⁿ's are the step's. With a periodic y the
// halo brings the rows across the periodic boundary (the first and last ranks are neighbours),
// so there the rows are read where they are stored instead of wrapped.
//
// Whether any rank has faces of an elastic body decides, the same on every rank (the halos
// below are collective); with explicit diffusion a step whose footprint has such faces after a
// step without any did not keep uⁿ and keeps the viscosity inside the bodies that once (a body
// entering the grid; bodies there from the start have faces at the first step; Crank-Nicolson
// always keeps uⁿ).
//
// Only elastic bodies lose the viscosity: the coupler's α of the elastic bodies alone (CouplingIn
// solid_*_elastic; α itself when every body is elastic). A rigid body has no strain inside, so
// the correction would touch only its surface, where it moves the wall the flow sees up to a
// third of a cell further into the body (runs/sub-cell-wall); a rigid body keeps the fluid's
// viscosity, which is the same rigid body. In the minima a rigid body's face counts as fluid, so
// where an elastic body meets a rigid one (a bar clamped to a cylinder) the viscous flux between
// them stays: a joint of the fluid's viscosity, nothing against a tissue's elastic stress.
void Solver::remove_body_viscosity(double dt, const CouplingIn& in) {
  if (!m_cfg.bodies_inviscid) return;
  const std::span<const std::int32_t> idx[2] = {in.solid_u_index, in.solid_v_index};
  // Per family (the protocol sends the elastic part for both or for neither).
  const bool mixed[2] = {!in.solid_u_elastic.empty(), !in.solid_v_elastic.empty()};
  const std::span<const double> alpha[2] = {mixed[0] ? in.solid_u_elastic : in.solid_u_alpha,
                                            mixed[1] ? in.solid_v_elastic : in.solid_v_alpha};
  for (int c = 0; c < 2; ++c)
    if (alpha[c].size() != idx[c].size())
      fsi::fail("fluid: {} volume fractions for {} solid faces", alpha[c].size(), idx[c].size());
  // Whether this rank has faces of an elastic body.
  bool here = false;
  for (int c = 0; c < 2; ++c)
    here |= mixed[c] ? std::any_of(alpha[c].begin(), alpha[c].end(), [](double a) { return a > 0; })
                     : !idx[c].empty();
  m_body_faces = m_dec.serial() ? here : m_dec.sum(here ? 1.0 : 0.0) > 0;
  if (!m_body_faces || !m_un_kept) return;
  const int nx = m_grid.nx(), ny = m_grid.ny();
  if (m_body_alpha[0].a.empty())
    m_body_alpha = {Field(nx + 1, ny, m_dec.lo(), m_dec.hi()),
                    Field(nx, ny + 1, m_dec.lo(), m_dec.v_hi())};
  const bool px = m_grid.x().periodic(), py = m_grid.y().periodic();
  const Axis& X = m_grid.x();
  const Axis& Y = m_grid.y();
  const double *xwi = X.wi(), *xdi = X.di(), *xci = X.ci();
  const double *ywi = Y.wi(), *ydi = Y.di(), *yci = Y.ci();
  // Faces along x and y of each family (a periodic direction's last face is its first), and
  // the faces whose velocity the step solves for: [i_lo, i_hi) x [j_lo, j_hi).
  const int ni[2] = {px ? nx : nx + 1, nx}, nj[2] = {ny, py ? ny : ny + 1};
  const int i_lo[2] = {m_i0, 0}, i_hi[2] = {nx, nx};
  const int j_lo[2] = {0, m_j0}, j_hi[2] = {ny, ny};
  auto wrap = [](int k, int n, bool periodic) { return periodic ? (k + n) % n : k; };
  // α of face (i, j) of family c for the minima: 1 (no say) beyond a wall or on a boundary face.
  const bool wrap_y = py && m_dec.serial();
  auto a_at = [&](int c, int i, int j) {
    i = wrap(i, ni[c], px), j = wrap(j, nj[c], wrap_y);
    if (i < i_lo[c] || i >= i_hi[c]) return 1.0;
    if (!py && (j < j_lo[c] || j >= j_hi[c])) return 1.0;
    return m_body_alpha[c](i, j);
  };
  // The α per face, and per family the box f of the footprint's faces the step solves for.
  Box f[2] = {Box::none(), Box::none()};
  for (int c = 0; c < 2; ++c)
    for (std::size_t q = 0; q < idx[c].size(); ++q) {
      const auto [i, j] = face_of(c, idx[c][q]);
      if (!(alpha[c][q] > 0)) continue;  // a rigid body's face
      double& a = m_body_alpha[c](i, owned(j, c));
      a = std::min(1.0, a + alpha[c][q]);
      if (i >= i_lo[c] && i < i_hi[c] && j >= j_lo[c] && j < j_hi[c]) f[c].join({i, i, j, j});
    }
  m_dec.halo(m_body_alpha[0]);
  m_dec.halo(m_body_alpha[1]);
  // Each flux once, on boxes: the corners the faces of f border, the centres between them and
  // their neighbours, and the α those fluxes read (each a_at once). A flux reading a face outside
  // the footprint has φ = 0, and each is the one the difference at a face would compute, so a
  // face gets the same bits as with its fluxes computed for it alone. The work is that of the
  // boxes: bodies far apart on one rank make them span the grid between them.
  if (!f[0].empty() || !f[1].empty()) {
    // Corners: (i, j), (i, j + 1) of a u face; (i, j), (i + 1, j) of a v face.
    Box k = Box::none();
    if (!f[0].empty()) k.join({f[0].i0, f[0].i1, f[0].j0, f[0].j1 + 1});
    if (!f[1].empty()) k.join({f[1].i0, f[1].i1 + 1, f[1].j0, f[1].j1});
    // α read: a u face's centre neighbours (i ± 1) and a corner's u faces (j − 1, j); a v face's
    // (j ± 1) and a corner's v faces (i − 1, i).
    Box b[2] = {Box::none(), Box::none()};
    if (!f[0].empty()) b[0].join({f[0].i0 - 1, f[0].i1 + 1, f[0].j0, f[0].j1});
    b[0].join({k.i0, k.i1, k.j0 - 1, k.j1});
    if (!f[1].empty()) b[1].join({f[1].i0, f[1].i1, f[1].j0 - 1, f[1].j1 + 1});
    b[1].join({k.i0 - 1, k.i1, k.j0, k.j1});
    for (int c = 0; c < 2; ++c) {
      m_bv_phi[c].resize(b[c]);
      for (int j = b[c].j0; j <= b[c].j1; ++j)
        for (int i = b[c].i0; i <= b[c].i1; ++i) m_bv_phi[c](i, j) = a_at(c, i, j);
    }
    const Patch& A = m_bv_phi[0];
    const Patch& B = m_bv_phi[1];
    const Field& U = m_un;
    const Field& V = m_vn;
    // φ (∂y u + ∂x v) at the corners, φ the smallest α of u faces (i, j − 1), (i, j) and v faces
    // (i − 1, j), (i, j).
    Patch& K = m_bv_corner;
    K.resize(k);
    for (int j = k.j0; j <= k.j1; ++j)
      for (int i = k.i0; i <= k.i1; ++i) {
        const double phi = std::min(std::min(A(i, j - 1), A(i, j)), std::min(B(i - 1, j), B(i, j)));
        K(i, j) = phi * ((U(i, j) - U(i, j - 1)) * ydi[j] + (V(i, j) - V(i - 1, j)) * xdi[i]);
      }
    // φ ∂x u between u faces i and i + 1; φ ∂y v between v faces j and j + 1.
    Patch& Cu = m_bv_centre[0];
    Patch& Cv = m_bv_centre[1];
    if (!f[0].empty()) {
      Cu.resize({f[0].i0 - 1, f[0].i1, f[0].j0, f[0].j1});
      for (int j = f[0].j0; j <= f[0].j1; ++j)
        for (int i = f[0].i0 - 1; i <= f[0].i1; ++i)
          Cu(i, j) = std::min(A(i, j), A(i + 1, j)) * (U(i + 1, j) - U(i, j)) * xwi[i];
    }
    if (!f[1].empty()) {
      Cv.resize({f[1].i0, f[1].i1, f[1].j0 - 1, f[1].j1});
      for (int j = f[1].j0 - 1; j <= f[1].j1; ++j)
        for (int i = f[1].i0; i <= f[1].i1; ++i)
          Cv(i, j) = std::min(B(i, j), B(i, j + 1)) * (V(i, j + 1) - V(i, j)) * ywi[j];
    }
    // Each face of the footprint once (α > 0 in its box: a face listed twice is taken once).
    const double s = dt * m_nu;
    for (int j = f[0].j0; j <= f[0].j1; ++j)
      for (int i = f[0].i0; i <= f[0].i1; ++i)
        if (m_body_alpha[0](i, j) > 0)
          m_u(i, j) -= s * (2 * (Cu(i, j) - Cu(i - 1, j)) * xdi[i] +
                            (K(i, j + 1) - K(i, j)) * yci[j]);
    for (int j = f[1].j0; j <= f[1].j1; ++j)
      for (int i = f[1].i0; i <= f[1].i1; ++i)
        if (m_body_alpha[1](i, j) > 0)
          m_v(i, j) -= s * ((K(i + 1, j) - K(i, j)) * xci[i] +
                            2 * (Cv(i, j) - Cv(i, j - 1)) * ydi[j]);
  }
  // Back to zero for the next step (the footprint moves).
  for (int c = 0; c < 2; ++c)
    for (std::size_t q = 0; q < idx[c].size(); ++q) {
      const auto [i, j] = face_of(c, idx[c][q]);
      m_body_alpha[c](i, j) = 0;
    }
}

}  // namespace fluid
