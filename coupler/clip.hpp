// Exact geometry of the immersed solid: a triangle clipped against an axis-aligned box (a
// control volume of the staggered grid), and the area and centroid of the resulting polygon.
#pragma once

namespace coupler {

struct Vec2 {
  double x, y;
};

// The convex polygon T ∩ [x0, x1] × [y0, y1] (Sutherland-Hodgman against the box's four
// half-planes), counter-clockwise when T is. Returns its vertex count n (0 when empty, at most 7)
// and writes the vertices to out[0..n).
int clip_triangle_box(const Vec2 tri[3], double x0, double x1, double y0, double y1, Vec2 out[7]);

// Split the convex polygon p (n vertices, n <= kMaxSplit) by the line p_axis = c into the part
// with p_axis <= c (`below`, nb vertices) and the part with p_axis >= c (`above`, na vertices),
// in one pass: a vertex on the line goes to both, an edge that crosses it contributes the crossing
// point (placed exactly on the line) to both. Each part stays convex and keeps the orientation.
// Cutting a triangle by the column lines and then each column by the row lines gives the same
// pieces as clipping it against every box, for one split per line crossed instead of four
// half-plane clips per box.
constexpr int kMaxSplit = 16;
// Inline: the callers pass the axis as a constant and the branches on it fold away.
inline void split_polygon(const Vec2* p, int n, bool is_x, double c, Vec2* below, int& nb,
                          Vec2* above, int& na) {
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

// Area and centroid of a simple polygon (shoelace formula):
//   A = ½ Σ_k (x_k y_{k+1} − x_{k+1} y_k),
//   c = 1/(6A) Σ_k (p_k + p_{k+1}) (x_k y_{k+1} − x_{k+1} y_k).
// A is signed (> 0 counter-clockwise); the centroid is meaningless when A = 0.
struct PolygonMoments {
  double area;
  Vec2 centroid;
};
inline PolygonMoments polygon_moments(const Vec2* p, int n) {
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

}  // namespace coupler
