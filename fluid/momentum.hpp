// Explicit momentum terms on the MAC grid: convection in divergence form with 2nd-order
// central fluxes (first-order upwind fluxes inside the outlet sponge) and viscous diffusion.
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
// explicit diffusion and 0 for implicit. Ghosts of u and v must be filled.
void momentum_terms(const Grid& g, const SpongeWeights& sw, const Field& u, const Field& v,
                    double nu_e, int i0, int j0, Field& hu, Field& hv, Field* lu, Field* lv);

}  // namespace fluid
