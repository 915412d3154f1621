// Explicit momentum terms on the MAC grid: convection in divergence form with 2nd-order
// central fluxes or third-order upwind-biased carried values (first-order upwind fluxes inside
// the outlet sponge) and viscous diffusion.
#pragma once

#include <vector>

#include "field.hpp"
#include "grid.hpp"

namespace fluid {

// Upwind weights per x position: beta = 1 inside the sponge (upwind), `blend` elsewhere (0:
// central; 0 < blend <= 1: the carried value moves that far from the average to the upwind one).
struct SpongeWeights {
  std::vector<double> centre;  // cell i, offset 1: index i + 1, i in [-1, nx]
  std::vector<double> face;    // face i, offset 1, i in [-1, nx + 1]
  bool active = false;
};
SpongeWeights sponge_weights(const Grid& g, double blend = 0.0);

// Over the active u faces i in [i0, nx), j in [0, ny), and v faces i in [0, nx), j in [j0, ny):
//   hu = -d(uu)/dx - d(vu)/dy + nu_e lap(u),   hv = -d(uv)/dx - d(vv)/dy + nu_e lap(v)
// and, when lu/lv are given, lu = lap(u), lv = lap(v). nu_e is the kinematic viscosity for
// explicit diffusion and 0 for implicit. Ghosts of u and v must be filled. hu, hv, lu and lv
// are other fields than u and v (the kernel's loops are compiled on that promise).
void momentum_terms(const Grid& g, const SpongeWeights& sw, const Field& u, const Field& v,
                    double nu_e, int i0, int j0, Field& hu, Field& hv, Field* lu, Field* lv);

// The third-order upwind correction (fluid.convection = "upwind3"), added to the terms of
// momentum_terms over the same faces. Each flux's carried value q becomes
//   q + (1 - beta) [ q3 - (q_l + q_r)/2 ],   q3 = (-q_m + 7 q_l + 7 q_r - q_p)/12
//                                                  + sgn(a) (q_p - 3 q_r + 3 q_l - q_m)/12
// (m, l, r, p the four values along the flux's direction, l and r beside the face; for a > 0
// q3 = (-q_m + 5 q_l + 2 q_r)/6, Leonard's third-order upwind-biased interpolation), with beta
// the sponge weight (1 inside: first-order upwind stays there; the blend outside). The correction
// is a second and a third difference added to the two-point value, with these coefficients on
// stretched cells too (consistent there, of lower order). Where the four values do not exist (the
// faces next to a non-periodic side) the flux keeps its two-point value. Ghosts of u and v must
// be filled; on several ranks ou, ov hold the outer rows. `work` is scratch space (resized once).
void upwind3_terms(const Grid& g, const SpongeWeights& sw, const Field& u, const Field& v,
                   const OuterRows& ou, const OuterRows& ov, int i0, int j0, Field& hu, Field& hv,
                   std::vector<double>& work);

}  // namespace fluid
