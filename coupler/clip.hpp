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

// Area and centroid of a simple polygon (shoelace formula):
//   A = ½ Σ_k (x_k y_{k+1} − x_{k+1} y_k),
//   c = 1/(6A) Σ_k (p_k + p_{k+1}) (x_k y_{k+1} − x_{k+1} y_k).
// A is signed (> 0 counter-clockwise); the centroid is meaningless when A = 0.
struct PolygonMoments {
  double area;
  Vec2 centroid;
};
PolygonMoments polygon_moments(const Vec2* p, int n);

// Barycentric coordinates (the linear shape functions N_a) of point q in triangle t.
void barycentric(const Vec2 t[3], Vec2 q, double n[3]);

}  // namespace coupler
