// Triangle-box clipping and polygon moments (see clip.hpp).
#include "clip.hpp"

namespace coupler {

void split_polygon(const Vec2* p, int n, bool is_x, double c, Vec2* below, int& nb, Vec2* above,
                   int& na) {
  nb = na = 0;
  for (int k = 0; k < n; ++k) {
    const Vec2 a = p[k];
    const Vec2 b = p[k + 1 == n ? 0 : k + 1];
    const double da = (is_x ? a.x : a.y) - c;
    const double db = (is_x ? b.x : b.y) - c;
    if (da <= 0) below[nb++] = a;
    if (da >= 0) above[na++] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      const double t = da / (da - db);
      Vec2 q{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
      if (is_x) q.x = c;
      else q.y = c;
      below[nb++] = q;
      above[na++] = q;
    }
  }
}

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

PolygonMoments polygon_moments(const Vec2* p, int n) {
  // Coordinates relative to the first vertex keep the cross products small (less cancellation).
  double a2 = 0, cx = 0, cy = 0;
  const Vec2 o = p[0];
  for (int k = 1; k + 1 < n; ++k) {
    const double x1 = p[k].x - o.x, y1 = p[k].y - o.y;
    const double x2 = p[k + 1].x - o.x, y2 = p[k + 1].y - o.y;
    const double cr = x1 * y2 - x2 * y1;
    a2 += cr;
    cx += (x1 + x2) * cr;
    cy += (y1 + y2) * cr;
  }
  PolygonMoments m{0.5 * a2, o};
  if (a2 != 0) m.centroid = {o.x + cx / (3 * a2), o.y + cy / (3 * a2)};
  return m;
}

void barycentric(const Vec2 t[3], Vec2 q, double n[3]) {
  const double det = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
  n[1] = ((q.x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (q.y - t[0].y)) / det;
  n[2] = ((t[1].x - t[0].x) * (q.y - t[0].y) - (q.x - t[0].x) * (t[1].y - t[0].y)) / det;
  n[0] = 1.0 - n[1] - n[2];
}

}  // namespace coupler
