// Triangle-box clipping (see clip.hpp).
#include "clip.hpp"

namespace coupler {

int clip_triangle_box(const Vec2 tri[3], double x0, double x1, double y0, double y1, Vec2 out[7]) {
  // Four splits, keeping the side of the box each time; a triangle clipped by four half-planes
  // has at most 3 + 4 = 7 vertices.
  Vec2 a[kMaxSplit], b[kMaxSplit], drop[kMaxSplit];
  int na = 0, nb = 0, nd = 0;
  split_polygon(tri, 3, true, x0, drop, nd, a, na);
  if (na < 3) return 0;
  split_polygon(a, na, true, x1, b, nb, drop, nd);
  if (nb < 3) return 0;
  split_polygon(b, nb, false, y0, drop, nd, a, na);
  if (na < 3) return 0;
  split_polygon(a, na, false, y1, b, nb, drop, nd);
  if (nb < 3) return 0;
  for (int k = 0; k < nb; ++k) out[k] = b[k];
  return nb;
}

}  // namespace coupler
