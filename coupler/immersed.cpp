// Volume fractions, mean solid velocities and the nodal reaction (see immersed.hpp).
#include "immersed.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <thread>

#include "clip.hpp"
#include "error.hpp"
#include "sorted_marks.hpp"

namespace coupler {

namespace {

// Edges whose spacings agree within this fraction of their mean are evenly spaced (round-off of
// the coordinates, not a stretching): their index comes from one division.
constexpr double kEven = 1e-9;

// Box edges at the cell centres c(k−1), k = 0..n, of a direction with faces f[0..nc]: the
// control volumes of the faces of that direction. Outside the grid, a periodic direction wraps;
// a bounded one mirrors (those boxes belong to boundary faces, which never take part).
std::vector<double> centre_edges(const std::vector<double>& f, bool periodic, int n) {
  const int nc = static_cast<int>(f.size()) - 1;
  auto centre = [&](int k) {
    if (k < 0) return periodic ? 0.5 * (f[nc - 1] + f[nc]) - (f[nc] - f[0]) : f[0] - 0.5 * (f[1] - f[0]);
    if (k >= nc) return f[nc] + 0.5 * (f[nc] - f[nc - 1]);
    return 0.5 * (f[k] + f[k + 1]);
  };
  std::vector<double> e(static_cast<std::size_t>(n + 1));
  for (int k = 0; k <= n; ++k) e[k] = centre(k - 1);
  return e;
}

}  // namespace

FaceBoxes FaceBoxes::u_faces(const proto::GridInfo& g) {
  FaceBoxes b;
  const bool px = g.periodic_x != 0;
  b.ni = px ? g.nx : g.nx + 1;
  b.ex = centre_edges(g.x_face, px, b.ni);
  b.i_lo = px ? 0 : 1;
  b.i_hi = g.nx;
  b.nj = g.ny;
  b.ey = g.y_face;
  b.j_lo = 0;
  b.j_hi = g.ny;
  b.period_x = px ? g.x_face.back() - g.x_face.front() : 0;
  b.period_y = g.periodic_y ? g.y_face.back() - g.y_face.front() : 0;
  return b;
}

FaceBoxes FaceBoxes::v_faces(const proto::GridInfo& g) {
  FaceBoxes b;
  const bool py = g.periodic_y != 0;
  b.ni = g.nx;
  b.ex = g.x_face;
  b.i_lo = 0;
  b.i_hi = g.nx;
  b.nj = py ? g.ny : g.ny + 1;
  b.ey = centre_edges(g.y_face, py, b.nj);
  b.j_lo = py ? 0 : 1;
  b.j_hi = g.ny;
  b.period_x = g.periodic_x ? g.x_face.back() - g.x_face.front() : 0;
  b.period_y = py ? g.y_face.back() - g.y_face.front() : 0;
  return b;
}

SmoothBoxes SmoothBoxes::of(const FaceBoxes& faces, double smoothing) {
  // One direction: boxes e[i]..e[i+1] (i = 0..n-1, box i owned by face i), a ramp of half-width
  // r[k] about each edge k between two faces (a periodic direction's edge 0 is its edge n).
  auto direction = [smoothing](const std::vector<double>& e, int n, bool periodic,
                               std::vector<double>& edges, Axis& axis) {
    std::vector<double> r(static_cast<std::size_t>(n + 1), 0.0);
    for (int k = 1; k < n; ++k) r[k] = 0.5 * smoothing * std::min(e[k] - e[k - 1], e[k + 1] - e[k]);
    if (periodic) r[0] = r[n] = 0.5 * smoothing * std::min(e[1] - e[0], e[n] - e[n - 1]);
    edges.assign(1, e[0]);
    auto add = [&](double end, std::array<int, 2> f, std::array<double, 2> w0, std::array<double, 2> w1) {
      // A flat interval thinner than round-off of the box (ε = 1) is left out.
      if (end - edges.back() <= 1e-12 * (e[n] - e[0]) / n) return;
      edges.push_back(end);
      axis.face.push_back(f), axis.w0.push_back(w0), axis.w1.push_back(w1);
    };
    if (periodic && r[0] > 0) add(e[0] + r[0], {n - 1, 0}, {0.5, 0.5}, {0.0, 1.0});
    for (int i = 0; i < n; ++i) {
      add(e[i + 1] - r[i + 1], {i, -1}, {1.0, 0.0}, {1.0, 0.0});
      if (r[i + 1] <= 0) continue;
      if (i + 1 < n)
        add(e[i + 1] + r[i + 1], {i, i + 1}, {1.0, 0.0}, {0.0, 1.0});
      else
        add(e[n], {n - 1, 0}, {1.0, 0.0}, {0.5, 0.5});
    }
    edges.back() = e[n];  // one period exactly, whatever the round-off of the sums
  };
  SmoothBoxes s;
  s.boxes.period_x = faces.period_x;
  s.boxes.period_y = faces.period_y;
  direction(faces.ex, faces.ni, faces.period_x > 0, s.boxes.ex, s.ax);
  direction(faces.ey, faces.nj, faces.period_y > 0, s.boxes.ey, s.ay);
  s.boxes.ni = static_cast<int>(s.ax.face.size());
  s.boxes.nj = static_cast<int>(s.ay.face.size());
  s.boxes.i_lo = 0, s.boxes.i_hi = s.boxes.ni;
  s.boxes.j_lo = 0, s.boxes.j_hi = s.boxes.nj;
  return s;
}

ImmersedSolid::Family::Family(const FaceBoxes& f, double smoothing)
    : faces(f),
      smooth(smoothing > 0 ? SmoothBoxes::of(f, smoothing) : SmoothBoxes{}),
      ix(clip_boxes().ex),
      iy(clip_boxes().ey) {}

EdgeIndex::EdgeIndex(const std::vector<double>& e) : m_e(&e) {
  const std::size_t n = e.size() - 1;
  const double h = (e[n] - e[0]) / static_cast<double>(n);
  m_even = n > 0 && h > 0;
  for (std::size_t k = 1; k <= n && m_even; ++k)
    m_even = std::abs(e[k] - e[k - 1] - h) <= kEven * h;
  if (m_even) m_inv = 1.0 / h;
}

namespace {
double checked_smoothing(double smoothing) {
  if (!(smoothing >= 0 && smoothing <= 1))
    fsi::fail("footprint smoothing {} outside [0, 1]", smoothing);
  return smoothing;
}
}  // namespace

ImmersedSolid::ImmersedSolid(const proto::GridInfo& grid, const proto::BodyMeshes& meshes,
                             double smoothing)
    : m_meshes(meshes),
      m_uf(FaceBoxes::u_faces(grid), checked_smoothing(smoothing)),
      m_vf(FaceBoxes::v_faces(grid), smoothing) {
  m_scratch_u.slot.assign(static_cast<std::size_t>(m_uf.faces.ni * m_uf.faces.nj), -1);
  m_scratch_v.slot.assign(static_cast<std::size_t>(m_vf.faces.ni * m_vf.faces.nj), -1);
  m_threads = std::thread::hardware_concurrency() > 1;
  for (std::size_t b = 0; b < meshes.bodies.size(); ++b)
    m_any_rigid |= !deforms(static_cast<int>(b));
}

// Every triangle of body b at positions x, against every box its bounding box meets (and its
// periodic images).
//
// Smoothed (SmoothBoxes), a piece P in interval box (i, j), with local coordinates
// ξ = (x − ex[i])/(ex[i+1] − ex[i]), η likewise, gives each face of the interval's one or two
// along x times one or two along y the weight φ = w_x(ξ) w_y(η) (linear in each), and node a of
// T the weight ∫_P φ N_a dA. The integrand is cubic: P is cut into the triangles of a fan and
// each is integrated by the four-point rule exact for cubics (weight −27/48 at the centroid,
// 25/48 at the points with barycentric coordinates (3/5, 1/5, 1/5) and its permutations).
void ImmersedSolid::clip_body(const Family& fam, int b, const std::vector<double>& x,
                              Raw& raw) const {
  const FaceBoxes& boxes = fam.clip_boxes();
  const FaceBoxes& faces = fam.faces;
  const EdgeIndex& ix = fam.ix;
  const EdgeIndex& iy = fam.iy;
  const bool smoothed = fam.smoothed();
  const SmoothBoxes::Axis& sax = fam.smooth.ax;
  const SmoothBoxes::Axis& say = fam.smooth.ay;
  const auto& tri = m_meshes.bodies[b].tri;
  const double sx[3] = {0.0, -boxes.period_x, boxes.period_x};
  const double sy[3] = {0.0, -boxes.period_y, boxes.period_y};
  const int nsx = boxes.period_x > 0 ? 3 : 1, nsy = boxes.period_y > 0 ? 3 : 1;
  const double xlo = boxes.ex[boxes.i_lo], xhi = boxes.ex[boxes.i_hi];
  const double ylo = boxes.ey[boxes.j_lo], yhi = boxes.ey[boxes.j_hi];
  Vec2 t[3];
  for (std::size_t e = 0; e + 2 < tri.size(); e += 3) {
    const int a[3] = {tri[e], tri[e + 1], tri[e + 2]};
    Vec2 p[3];
    for (int k = 0; k < 3; ++k) p[k] = {x[2 * a[k]], x[2 * a[k] + 1]};
    // A body may have travelled any number of periods: bring the triangle back to the period
    // that holds its first node, then its images at ±period cover the boxes it overlaps.
    if (boxes.period_x > 0) {
      const double shift = boxes.period_x * std::floor((p[0].x - xlo) / boxes.period_x);
      for (auto& q : p) q.x -= shift;
    }
    if (boxes.period_y > 0) {
      const double shift = boxes.period_y * std::floor((p[0].y - ylo) / boxes.period_y);
      for (auto& q : p) q.y -= shift;
    }
    const double bx0 = std::min({p[0].x, p[1].x, p[2].x}), bx1 = std::max({p[0].x, p[1].x, p[2].x});
    const double by0 = std::min({p[0].y, p[1].y, p[2].y}), by1 = std::max({p[0].y, p[1].y, p[2].y});
    for (int qy = 0; qy < nsy; ++qy) {
      for (int qx = 0; qx < nsx; ++qx) {
        const double x0 = bx0 + sx[qx], x1 = bx1 + sx[qx], y0 = by0 + sy[qy], y1 = by1 + sy[qy];
        if (x1 <= xlo || x0 >= xhi || y1 <= ylo || y0 >= yhi) continue;
        for (int k = 0; k < 3; ++k) t[k] = {p[k].x + sx[qx], p[k].y + sy[qy]};
        const int i0 = std::max(boxes.i_lo, ix.last_at_or_below(x0));
        const int i1 = std::min(boxes.i_hi - 1, ix.last_below(x1));
        const int j0 = std::max(boxes.j_lo, iy.last_at_or_below(y0));
        const int j1 = std::min(boxes.j_hi - 1, iy.last_below(y1));
        if (i0 > i1 || j0 > j1) continue;
        // Barycentric coordinates of T as an affine map, set up once per triangle:
        //   (N_1, N_2) = B (q − t_0),  B = [t_1 − t_0, t_2 − t_0]^{-1},  N_0 = 1 − N_1 − N_2.
        const double e1x = t[1].x - t[0].x, e1y = t[1].y - t[0].y;
        const double e2x = t[2].x - t[0].x, e2y = t[2].y - t[0].y;
        const double inv = 1.0 / (e1x * e2y - e2x * e1y);
        const double b11 = e2y * inv, b12 = -e2x * inv, b21 = -e1y * inv, b22 = e1x * inv;
        // Smoothed: a piece of interval box (i, j) to its faces.
        auto emit_smooth = [&](const Vec2* poly, int n, int i, int j) {
          const double x0b = boxes.ex[i], y0b = boxes.ey[j];
          const double sxb = 1.0 / (boxes.ex[i + 1] - x0b), syb = 1.0 / (boxes.ey[j + 1] - y0b);
          const auto &fx = sax.face[i], &fy = say.face[j];
          const auto &ax0 = sax.w0[i], &ax1 = sax.w1[i], &ay0 = say.w0[j], &ay1 = say.w1[j];
          double w[4][3] = {};
          auto point = [&](double px, double py, double weight) {
            // (clamped: a point on the piece's border may fall a round-off outside the box)
            const double xi = std::clamp((px - x0b) * sxb, 0.0, 1.0);
            const double eta = std::clamp((py - y0b) * syb, 0.0, 1.0);
            const double wx[2] = {ax0[0] + (ax1[0] - ax0[0]) * xi, ax0[1] + (ax1[1] - ax0[1]) * xi};
            const double wy[2] = {ay0[0] + (ay1[0] - ay0[0]) * eta, ay0[1] + (ay1[1] - ay0[1]) * eta};
            const double qx = px - t[0].x, qy = py - t[0].y;
            const double n1 = b11 * qx + b12 * qy, n2 = b21 * qx + b22 * qy;
            const double nn[3] = {1.0 - n1 - n2, n1, n2};
            for (int c = 0; c < 4; ++c) {
              const double phi = weight * wx[c & 1] * wy[c >> 1];
              for (int k = 0; k < 3; ++k) w[c][k] += phi * nn[k];
            }
          };
          const Vec2 o = poly[0];
          double piece_area = 0;
          for (int k = 1; k + 1 < n; ++k) {
            const Vec2 p1 = poly[k], p2 = poly[k + 1];
            const double area = 0.5 * std::abs((p1.x - o.x) * (p2.y - o.y) - (p2.x - o.x) * (p1.y - o.y));
            if (area == 0) continue;
            piece_area += area;
            point((o.x + p1.x + p2.x) / 3, (o.y + p1.y + p2.y) / 3, -27.0 / 48.0 * area);
            const Vec2 v[3] = {o, p1, p2};
            for (int a3 = 0; a3 < 3; ++a3) {
              const Vec2 &pa = v[a3], &pb = v[(a3 + 1) % 3], &pc = v[(a3 + 2) % 3];
              point(0.6 * pa.x + 0.2 * (pb.x + pc.x), 0.6 * pa.y + 0.2 * (pb.y + pc.y), 25.0 / 48.0 * area);
            }
          }
          for (int c = 0; c < 4; ++c) {
            const int fi = fx[c & 1], fj = fy[c >> 1];
            if (fi < faces.i_lo || fi >= faces.i_hi || fj < faces.j_lo || fj >= faces.j_hi) continue;
            // A face whose weight vanishes on the piece (a sliver at a ramp's end) takes none of
            // it: its few digits left would make ū_s = Σ w u / Σ w arbitrary.
            if (w[c][0] + w[c][1] + w[c][2] <= 1e-12 * piece_area) continue;
            raw.push_back({fi + faces.ni * fj, b, {a[0], a[1], a[2]}, {w[c][0], w[c][1], w[c][2]}});
          }
        };
        auto emit = [&](const Vec2* poly, int n, int i, int j) {
          if (n < 3) return;
          if (smoothed) return emit_smooth(poly, n, i, j);
          const PolygonMoments m = polygon_moments(poly, n);
          const double area = std::abs(m.area);
          if (area == 0) return;
          const double qx = m.centroid.x - t[0].x, qy = m.centroid.y - t[0].y;
          const double n1 = b11 * qx + b12 * qy, n2 = b21 * qx + b22 * qy;
          raw.push_back({i + boxes.ni * j, b, {a[0], a[1], a[2]},
                         {area * (1.0 - n1 - n2), area * n1, area * n2}});
        };
        // Inside one box: the piece is the whole triangle.
        if (i0 == i1 && j0 == j1 && x0 >= boxes.ex[i0] && x1 <= boxes.ex[i0 + 1] &&
            y0 >= boxes.ey[j0] && y1 <= boxes.ey[j0 + 1]) {
          emit(t, 3, i0, j0);
          continue;
        }
        // Columns: cut the triangle at the box edges ex[i0] .. ex[i1 + 1], then each column at
        // ey[j0] .. ey[j1 + 1] (split_polygon); parts outside [i0, i1] × [j0, j1] are dropped. A
        // line the polygon does not cross is not cut: the first and last edges lie outside the
        // triangle's extent unless the range was clamped to the unknown faces.
        Vec2 s1[kMaxSplit], s2[kMaxSplit], col[kMaxSplit], c1[kMaxSplit], c2[kMaxSplit];
        Vec2 piece[kMaxSplit], drop[kMaxSplit];
        int nr = 3, nd = 0;
        Vec2* rem = s1;
        Vec2* spare = s2;
        for (int k = 0; k < 3; ++k) rem[k] = t[k];
        if (boxes.ex[i0] > x0) {
          split_polygon(rem, nr, true, boxes.ex[i0], drop, nd, spare, nr);
          std::swap(rem, spare);
        }
        for (int i = i0; i <= i1 && nr >= 3; ++i) {
          int nc = 0;
          const Vec2* column = rem;
          if (i < i1 || boxes.ex[i1 + 1] < x1) {
            split_polygon(rem, nr, true, boxes.ex[i + 1], col, nc, spare, nr);
            std::swap(rem, spare);
            column = col;
          } else {
            nc = nr, nr = 0;
          }
          if (nc < 3) continue;
          Vec2* crem = c1;
          Vec2* cspare = c2;
          int ncr = nc;
          if (boxes.ey[j0] > y0) {
            split_polygon(column, nc, false, boxes.ey[j0], drop, nd, crem, ncr);
          } else {
            for (int k = 0; k < nc; ++k) crem[k] = column[k];
          }
          for (int j = j0; j <= j1 && ncr >= 3; ++j) {
            if (j < j1 || boxes.ey[j1 + 1] < y1) {
              int np = 0;
              split_polygon(crem, ncr, false, boxes.ey[j + 1], piece, np, cspare, ncr);
              std::swap(crem, cspare);
              emit(piece, np, i, j);
            } else {
              emit(crem, ncr, i, j);
              ncr = 0;
            }
          }
        }
      }
    }
  }
}

// The faces the pieces touch, each once, sorted. `slot` (per face: -1) marks them with 0; the
// caller sets their slots and resets them.
void ImmersedSolid::touched_faces(const Raw& raw, std::vector<std::int32_t>& slot,
                                  std::vector<std::int32_t>& face) {
  face.clear();
  std::int32_t lo = std::numeric_limits<std::int32_t>::max(), hi = -1;
  for (const Piece& q : raw)
    if (slot[q.face] < 0) {
      slot[q.face] = 0, face.push_back(q.face);
      lo = std::min(lo, q.face), hi = std::max(hi, q.face);
    }
  sort_marked(face, lo, hi, [&slot](std::int32_t k) { return slot[k] == 0; });
}

// Once, after the fixed bodies are clipped: their faces (sorted), each face's area and each
// piece's index among those faces.
void ImmersedSolid::index_fixed(Fixed& f, Scratch& s) {
  auto& slot = s.slot;
  touched_faces(f.raw, slot, f.face);
  for (std::size_t k = 0; k < f.face.size(); ++k) slot[f.face[k]] = static_cast<std::int32_t>(k);
  f.area.assign(f.face.size(), 0.0);
  f.body.assign(f.face.size(), kUnseen);
  f.local.resize(f.raw.size());
  for (std::size_t e = 0; e < f.raw.size(); ++e) {
    const Piece& q = f.raw[e];
    f.local[e] = slot[q.face];
    f.area[f.local[e]] += q.area();
    std::int32_t& b = f.body[f.local[e]];
    b = b == kUnseen || b == q.body ? q.body : kSeveral;
  }
  for (const std::int32_t face : f.face) slot[face] = -1;
}

// The touched faces (sorted): the moving bodies' faces, sorted, merged with the fixed bodies'
// (sorted once); each moving piece's slot and each fixed face's slot; the area of each face.
void ImmersedSolid::gather(const Fixed& fixed, const Raw& moving, Faces& p, Scratch& s) {
  auto& slot = s.slot;
  p.fixed = &fixed;
  p.moving = &moving;
  auto& mf = p.moving_face;
  touched_faces(moving, slot, mf);
  p.face.resize(mf.size() + fixed.face.size());
  p.face.erase(std::set_union(mf.begin(), mf.end(), fixed.face.begin(), fixed.face.end(),
                              p.face.begin()),
               p.face.end());
  const std::size_t nf = p.face.size();
  for (std::size_t k = 0; k < nf; ++k) slot[p.face[k]] = static_cast<std::int32_t>(k);
  p.area.assign(nf, 0.0);
  p.slot_fixed_face.resize(fixed.face.size());
  for (std::size_t m = 0; m < fixed.face.size(); ++m) {
    p.slot_fixed_face[m] = slot[fixed.face[m]];
    p.area[p.slot_fixed_face[m]] += fixed.area[m];
  }
  p.slot_moving.resize(moving.size());
  for (std::size_t e = 0; e < moving.size(); ++e) {
    p.slot_moving[e] = slot[moving[e].face];
    p.area[p.slot_moving[e]] += moving[e].area();
  }
  // The elastic bodies' part (the fixed pieces are all rigid): where the fluid may take its
  // viscosity out of a body, which a rigid one does not need (no strain inside) and which moves
  // a rigid wall the flow sees into the body (runs/sub-cell-wall).
  if (m_any_rigid) {
    p.elastic_area.assign(nf, 0.0);
    for (std::size_t e = 0; e < moving.size(); ++e)
      if (deforms(moving[e].body)) p.elastic_area[p.slot_moving[e]] += moving[e].area();
  }
  // The body on each face, kSeveral where pieces of two or more cover it: there ū_s is the mean
  // of their velocities, whose divergence is their approach, not a volume change
  // (FaceSolid::body). The fixed faces' bodies were found once (index_fixed).
  p.body.clear();
  if (m_meshes.bodies.size() > 1) {
    p.body.assign(nf, kUnseen);
    auto mark = [&](std::int32_t k, std::int32_t b) {
      std::int32_t& o = p.body[k];
      o = o == kUnseen || o == b ? b : kSeveral;
    };
    for (std::size_t m = 0; m < fixed.face.size(); ++m) mark(p.slot_fixed_face[m], fixed.body[m]);
    for (std::size_t e = 0; e < moving.size(); ++e) mark(p.slot_moving[e], moving[e].body);
  }
  p.total_area = 0;
  for (std::size_t k = 0; k < nf; ++k) {
    p.total_area += p.area[k];
    slot[p.face[k]] = -1;
  }
}

// A fixed body's pieces add nothing to ū_s while its nodes are at rest, which is what a fixed
// body's state says; fill() sums them should it say otherwise.
bool ImmersedSolid::fixed_at_rest(const proto::SolidState& state) const {
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b)
    if (m_meshes.bodies[b].kind == proto::BodyKind::rigid_fixed)
      for (const double vb : state.v[b])
        if (vb != 0.0) return false;
  return true;
}

void ImmersedSolid::fill(const Family& fam, const Faces& p, const proto::SolidState& state,
                         int component, bool fixed_rest, proto::FaceSolid& out) const {
  const FaceBoxes& boxes = fam.faces;
  const std::size_t nf = p.face.size();
  p.sum.assign(nf, 0.0);
  auto add = [&](const Piece& q, std::int32_t slot) {
    const double* v = state.v[q.body].data() + component;
    p.sum[slot] += q.w[0] * v[2 * q.node[0]] + q.w[1] * v[2 * q.node[1]] + q.w[2] * v[2 * q.node[2]];
  };
  if (!fixed_rest)
    for (std::size_t e = 0; e < p.fixed->raw.size(); ++e)
      add(p.fixed->raw[e], p.slot_fixed_face[p.fixed->local[e]]);
  for (std::size_t e = 0; e < p.moving->size(); ++e) add((*p.moving)[e], p.slot_moving[e]);
  out.index = p.face;
  out.alpha.resize(nf);
  out.velocity.resize(nf);
  out.elastic.resize(m_any_rigid ? nf : 0);
  for (std::size_t k = 0; k < nf; ++k) {
    const int i = p.face[k] % boxes.ni, j = p.face[k] / boxes.ni;
    out.alpha[k] = std::min(1.0, p.area[k] / boxes.volume(i, j));
    out.velocity[k] = p.sum[k] / p.area[k];
    if (m_any_rigid) out.elastic[k] = std::min(1.0, p.elastic_area[k] / boxes.volume(i, j));
  }
}

void ImmersedSolid::update(const proto::SolidState& state, proto::FaceSolid& u, proto::FaceSolid& v) {
  const auto& bodies = m_meshes.bodies;
  if (state.x.size() != bodies.size() || state.v.size() != bodies.size())
    fsi::fail("solid state has {} bodies, the meshes {}", state.x.size(), bodies.size());
  // The two families are independent (own boxes, pieces and scratch): the v-family runs on a
  // second thread while this one does the u-family. The solid waits meanwhile; the fluid runs its
  // predictor ahead of its input (one core's worth of work).
  const bool fixed_rest = fixed_at_rest(state);
  auto family = [&](const Family& fam, Fixed& fixed, Raw& raw, Faces& p, Scratch& s, int c,
                    proto::FaceSolid& out) {
    if (!m_fixed_done) {
      for (int b = 0; b < static_cast<int>(bodies.size()); ++b)
        if (bodies[b].kind == proto::BodyKind::rigid_fixed) clip_body(fam, b, state.x[b], fixed.raw);
      index_fixed(fixed, s);
    }
    raw.clear();
    for (int b = 0; b < static_cast<int>(bodies.size()); ++b)
      if (bodies[b].kind != proto::BodyKind::rigid_fixed) clip_body(fam, b, state.x[b], raw);
    gather(fixed, raw, p, s);
    fill(fam, p, state, c, fixed_rest, out);
  };
  if (m_threads) {
    // An error on either thread reaches the caller (and the error funnel) once both are done.
    std::exception_ptr second_failed;
    std::thread second([&] {
      try {
        family(m_vf, m_fixed_v, m_raw_v, m_v, m_scratch_v, 1, v);
      } catch (...) {
        second_failed = std::current_exception();
      }
    });
    try {
      family(m_uf, m_fixed_u, m_raw_u, m_u, m_scratch_u, 0, u);
    } catch (...) {
      second.join();
      throw;
    }
    second.join();
    if (second_failed) std::rethrow_exception(second_failed);
  } else {
    family(m_uf, m_fixed_u, m_raw_u, m_u, m_scratch_u, 0, u);
    family(m_vf, m_fixed_v, m_raw_v, m_v, m_scratch_v, 1, v);
  }
  m_fixed_done = true;
  // Sent for every face of both families when the scene has more than one body, else for none.
  u.body = m_u.body;
  v.body = m_v.body;
}

void ImmersedSolid::update_velocities(const proto::SolidState& state, proto::FaceSolid& u,
                                      proto::FaceSolid& v) const {
  if (state.v.size() != m_meshes.bodies.size())
    fsi::fail("solid state has {} bodies, the meshes {}", state.v.size(), m_meshes.bodies.size());
  const bool fixed_rest = fixed_at_rest(state);
  fill(m_uf, m_u, state, 0, fixed_rest, u);
  fill(m_vf, m_v, state, 1, fixed_rest, v);
}

void ImmersedSolid::reaction(const std::vector<double>& fs_u, const std::vector<double>& fs_v,
                             std::vector<std::vector<double>>& force) const {
  const auto& bodies = m_meshes.bodies;
  force.resize(bodies.size());
  for (std::size_t b = 0; b < bodies.size(); ++b) force[b].assign(bodies[b].x_ref.size(), 0.0);
  auto add = [&](const FaceBoxes& boxes, const Faces& p, const std::vector<double>& fs, int c) {
    if (fs.size() != p.face.size())
      fsi::fail("protocol error: {} forcing values for {} solid faces", fs.size(), p.face.size());
    // Per face, −f_s |V| / Σ|V ∩ T|; then each piece's share of it.
    p.sum.resize(p.face.size());
    for (std::size_t k = 0; k < p.face.size(); ++k) {
      const int i = p.face[k] % boxes.ni, j = p.face[k] / boxes.ni;
      p.sum[k] = -fs[k] * boxes.volume(i, j) / p.area[k];
    }
    auto spread = [&](const Piece& q, double s) {
      double* f = force[q.body].data() + c;
      for (int k = 0; k < 3; ++k) f[2 * q.node[k]] += s * q.w[k];
    };
    for (std::size_t e = 0; e < p.fixed->raw.size(); ++e)
      spread(p.fixed->raw[e], p.sum[p.slot_fixed_face[p.fixed->local[e]]]);
    for (std::size_t e = 0; e < p.moving->size(); ++e)
      spread((*p.moving)[e], p.sum[p.slot_moving[e]]);
  };
  add(m_uf.faces, m_u, fs_u, 0);
  add(m_vf.faces, m_v, fs_v, 1);
}

}  // namespace coupler
