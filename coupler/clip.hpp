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
void split_polygon(const Vec2* p, int n, bool is_x, double c, Vec2* below, int& nb, Vec2* above,
                   int& na);

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
