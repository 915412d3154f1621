// Shared by the coupler's tests: a uniform grid description as the fluid sends it.
#pragma once

#include "protocol.hpp"

namespace coupler::testing {

// A uniform grid on [0, lx] × [0, ly] with nx × ny cells.
inline fsi::proto::GridInfo grid(int nx, int ny, double lx, double ly, bool px, bool py) {
  fsi::proto::GridInfo g;
  g.nx = nx, g.ny = ny, g.periodic_x = px, g.periodic_y = py, g.density = 1;
  for (int i = 0; i <= nx; ++i) g.x_face.push_back(lx * i / nx);
  for (int j = 0; j <= ny; ++j) g.y_face.push_back(ly * j / ny);
  return g;
}

}  // namespace coupler::testing
