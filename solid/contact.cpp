// Contact geometry: closest point on a master surface, signed gap, normal, ray-casting inside
// test; bounding boxes skip far pairs.
#include "contact.hpp"

#include <algorithm>
#include <cmath>

namespace solid {

namespace {

// Two squared distances within this relative tolerance are a tie (a vertex shared by two edges):
// the edge whose interior holds the projection wins, so the normal is the segment's.
constexpr double kClosestTie = 1e-12;
// A point farther than this from a vertex (relative to the edge length) takes the vertex's
// direction as its normal; nearer, the vertex's direction is round-off and the edge's is used.
constexpr double kVertexDistance = 1e-9;
// How far (relative to its length) a slot's last edge is extended before the slot moves on to
// the neighbouring edge or vertex: far above round-off of positions, far below a step's motion.
constexpr double kKeepEdge = 1e-6;
// Self-contact: a node never touches the surface edges nearer to it than this many of the
// body's longest surface edges in the reference configuration (its own neighbourhood, and the
// other side of a part thinner than that).
constexpr double kSelfNear = 3;
// Self-contact: features farther than this many reaches (smallest surface edges) from a node
// are not looked for; its slot is then far (gap +infinity), and it has no front for the next
// step. A candidate needs a gap below one reach.
constexpr double kSelfSearch = 4;
// A node within this fraction of the shorter edge at a vertex of a surface (twice that while the
// vertex is already its feature as a zone) touches the vertex, with the vertex's pseudo-normal
// as the gap's gradient (detect_self, and detect_slot between two bodies).
constexpr double kVertexZone = 0.01;
// Self-contact: a node behind a feature is the body's other side unless it is within this many
// times its motion since the step's start, relative to the feature's point under it (plus the
// accepted gap, at least kKeepEdge reaches; at most one reach, except at the guarded features:
// what it faced at the step's start or touches now). Behind a guarded feature within that bound,
// having been in front of it at the start, the node went through it (detect_self). Not for the
// vertex whose zone held the node at the last detection and holds it still (kept_zone).
constexpr double kSelfCrossing = 2;
const std::vector<double> kNoPositions;

// Distance from p to the segment a-b.
double segment_distance(double px, double py, double ax, double ay, double bx, double by) {
  const double ex = bx - ax, ey = by - ay;
  const double xi = std::clamp(((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
  return std::hypot(ax + xi * ex - px, ay + xi * ey - py);
}

// The bin of coordinate v on n bins of 1/inv from origin, the outer bins extended to infinity
// (clamped as a double: a far coordinate would overflow an int).
int bin_of(double v, double origin, double inv, int n) {
  const double t = (v - origin) * inv;
  return t < 1 ? 0 : t >= n - 1 ? n - 1 : static_cast<int>(t);
}

}  // namespace

bool inside_surface(const Mesh& mesh, const std::vector<double>& x, double px, double py) {
  // Crossings of the ray from p towards +x with every surface edge (half-open in y).
  bool inside = false;
  for (const auto& e : mesh.surface) {
    const double ax = x[2 * e[0]], ay = x[2 * e[0] + 1];
    const double bx = x[2 * e[1]], by = x[2 * e[1] + 1];
    if ((ay > py) != (by > py)) {
      const double xc = ax + (py - ay) * (bx - ax) / (by - ay);
      if (xc > px) inside = !inside;
    }
  }
  return inside;
}

void segment_gap_hessian(const Vec2& xs, const Vec2& x1, const Vec2& x2, double H[36]) {
  const double ex = x2[0] - x1[0], ey = x2[1] - x1[1];
  const double l = std::hypot(ex, ey);
  const double t[2] = {ex / l, ey / l}, n[2] = {ey / l, -ex / l};
  const double dx = xs[0] - x1[0], dy = xs[1] - x1[1];
  const double g = dx * n[0] + dy * n[1];
  const double xi = (dx * t[0] + dy * t[1]) / l;
  double hde[2][2], hee[2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      hde[i][j] = -t[i] * n[j] / l;
      hee[i][j] = xi * (n[i] * t[j] + t[i] * n[j]) / l - g * n[i] * n[j] / (l * l);
    }
  const double cd[3] = {1, -1, 0}, ce[3] = {0, -1, 1};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          H[6 * (2 * a + i) + 2 * b + j] =
              cd[a] * ce[b] * hde[i][j] + ce[a] * cd[b] * hde[j][i] + ce[a] * ce[b] * hee[i][j];
}

void ContactSet::setup(const std::vector<const Mesh*>& meshes, const std::vector<BodyKind>& kinds,
                       const std::vector<ContactPair>& pairs,
                       const std::vector<ContactPlane>& planes) {
  m_surfaces.clear();
  m_slots.clear();
  m_planes = planes;
  for (const Mesh* m : meshes) {
    Surface s;
    s.mesh = m;
    for (const auto& e : m->surface) s.nodes.insert(s.nodes.end(), e.begin(), e.end());
    std::sort(s.nodes.begin(), s.nodes.end());
    s.nodes.erase(std::unique(s.nodes.begin(), s.nodes.end()), s.nodes.end());
    s.vertex_edges.assign(m->num_nodes(), {});
    for (std::size_t k = 0; k < m->surface.size(); ++k)
      for (int v : m->surface[k]) s.vertex_edges[v].push_back(static_cast<int>(k));
    m_surfaces.push_back(std::move(s));
  }
  auto add = [&](int slave, int master) {
    if (kinds[slave] != BodyKind::elastic) return;  // rigid nodes cannot move
    for (int n : m_surfaces[slave].nodes) {
      ContactSlot c;
      c.slave_body = slave;
      c.slave_node = n;
      c.master_body = master;
      m_slots.push_back(c);
    }
  };
  for (const auto& p : pairs) {
    add(p.slave, p.master);
    if (p.slave == p.master)
      setup_self(m_surfaces[p.slave]);
    else if (p.two_way)
      add(p.master, p.slave);
  }
  for (std::size_t k = 0; k < planes.size(); ++k)
    for (int b : planes[k].bodies) {
      if (kinds[b] != BodyKind::elastic) continue;
      for (int n : m_surfaces[b].nodes) {
        ContactSlot c;
        c.slave_body = b;
        c.slave_node = n;
        c.plane = static_cast<int>(k);
        m_slots.push_back(c);
      }
    }
  m_front.assign(m_slots.size(), {-1, -1});
  // Each pair's slot per slave node (for the pairs of nodes at each other's vertex, detect()).
  const std::size_t nb = meshes.size();
  m_node_slot.assign(nb * nb, {});
  for (std::size_t k = 0; k < m_slots.size(); ++k) {
    const ContactSlot& c = m_slots[k];
    if (c.master_body < 0) continue;
    auto& index = m_node_slot[c.slave_body * nb + c.master_body];
    if (index.empty()) index.assign(meshes[c.slave_body]->num_nodes(), -1);
    index[c.slave_node] = static_cast<int>(k);
  }
}

void ContactSet::setup_self(Surface& s) const {
  const Mesh& m = *s.mesh;
  const auto& X = m.x;
  auto length = [&](const std::array<int, 2>& e) {
    return std::hypot(X[2 * e[1]] - X[2 * e[0]], X[2 * e[1] + 1] - X[2 * e[0] + 1]);
  };
  // Node n does not look at edge k when they are within kSelfNear times the longer of n's
  // surface edges and k in the reference configuration (local lengths: a graded mesh's long
  // edges do not widen the small edges' neighbourhoods).
  s.self_near.assign(m.num_nodes(), {});
  for (int n : s.nodes) {
    double ln = 0;
    for (int k : s.vertex_edges[n]) ln = std::max(ln, length(m.surface[k]));
    for (std::size_t k = 0; k < m.surface.size(); ++k) {
      const auto& e = m.surface[k];
      const double near = kSelfNear * std::max(ln, length(e));
      if (segment_distance(X[2 * n], X[2 * n + 1], X[2 * e[0]], X[2 * e[0] + 1], X[2 * e[1]],
                           X[2 * e[1] + 1]) <= near)
        s.self_near[n].push_back(static_cast<int>(k));
    }
  }
}

void ContactSet::remember_fronts(const std::vector<const std::vector<double>*>& x,
                                 double gap_tol) {
  m_gap_tol = gap_tol;
  m_start.assign(m_surfaces.size(), {});
  for (std::size_t b = 0; b < x.size() && b < m_surfaces.size(); ++b)
    if (!m_surfaces[b].self_near.empty()) m_start[b] = *x[b];
  for (std::size_t k = 0; k < m_slots.size(); ++k) {
    const ContactSlot& c = m_slots[k];
    const bool front =
        c.master_body == c.slave_body && c.m0 >= 0 && (c.active || c.gap >= -gap_tol);
    m_front[k] = front ? std::array<int, 2>{c.m0, c.m1} : std::array<int, 2>{-1, -1};
  }
}

void ContactSet::detect(const std::vector<const std::vector<double>*>& x,
                        const std::vector<double>& reach) {
  // Bounding boxes of every surface (xmin, ymin, xmax, ymax).
  std::vector<std::array<double, 4>> boxes(m_surfaces.size());
  for (std::size_t b = 0; b < m_surfaces.size(); ++b) {
    auto& box = boxes[b];
    box = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
           -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max()};
    for (int n : m_surfaces[b].nodes) {
      box[0] = std::min(box[0], (*x[b])[2 * n]);
      box[1] = std::min(box[1], (*x[b])[2 * n + 1]);
      box[2] = std::max(box[2], (*x[b])[2 * n]);
      box[3] = std::max(box[3], (*x[b])[2 * n + 1]);
    }
  }
  m_self_bins.resize(m_surfaces.size());
  for (std::size_t b = 0; b < m_surfaces.size(); ++b)
    if (!m_node_slot[b * m_surfaces.size() + b].empty())
      bin_edges(m_surfaces[b], *x[b], kSelfSearch * reach[b], m_self_bins[b]);
  m_reach.assign(reach.begin(), reach.end());
  for (std::size_t k = 0; k < m_slots.size(); ++k) {
    ContactSlot& s = m_slots[k];
    if (m_hold && m_held[k])
      hold_slot(s, x);
    else
      detect_slot(s, x, boxes, reach[s.slave_body]);
  }
  join_vertex_pairs(x);
}

void ContactSet::hold_features(bool on) {
  m_hold = on;
  m_held.assign(on ? m_slots.size() : 0, 0);
  if (!on) return;
  for (std::size_t k = 0; k < m_slots.size(); ++k) {
    const ContactSlot& s = m_slots[k];
    const double reach = s.slave_body < static_cast<int>(m_reach.size()) ? m_reach[s.slave_body] : 0;
    m_held[k] = s.plane < 0 && s.m0 >= 0 && (s.active || s.gap < reach);
  }
}

// Bins of about the search distance (at most kMaxBins along a side), each edge entered in every
// bin its widened box [min - search, max + search] meets: a point inside that box lies in one
// of those bins. Edges with a position that is not finite are entered in every bin.
void ContactSet::bin_edges(const Surface& surf, const std::vector<double>& x, double search,
                           EdgeBins& bins) const {
  constexpr int kMaxBins = 64;
  const auto& edges = surf.mesh->surface;
  double lo[2] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
  double hi[2] = {-std::numeric_limits<double>::max(), -std::numeric_limits<double>::max()};
  for (int n : surf.nodes)
    for (int c = 0; c < 2; ++c) {
      lo[c] = std::min(lo[c], x[2 * n + c]);
      hi[c] = std::max(hi[c], x[2 * n + c]);
    }
  const double w = std::max(hi[0] - lo[0], hi[1] - lo[1]) + 2 * search;
  if (!(std::isfinite(w) && search > 0)) {
    // One bin holding every edge, outside which no point is looked up (inv = 0: every point
    // falls in bin 0).
    bins = {0, 0, 0, 1, 1, {0, static_cast<int>(edges.size())}, {}};
    for (int k = 0; k < static_cast<int>(edges.size()); ++k) bins.edges.push_back(k);
    return;
  }
  const double size = std::max(search, w / kMaxBins);
  bins.x0 = lo[0] - search;
  bins.y0 = lo[1] - search;
  bins.inv = 1 / size;
  bins.nx = std::min(kMaxBins, static_cast<int>((hi[0] - lo[0] + 2 * search) * bins.inv) + 1);
  bins.ny = std::min(kMaxBins, static_cast<int>((hi[1] - lo[1] + 2 * search) * bins.inv) + 1);
  auto cell = [&](double v, double origin, int n) { return bin_of(v, origin, bins.inv, n); };
  auto range = [&](int k, int r[4]) {
    const auto& e = edges[k];
    const double ax = x[2 * e[0]], ay = x[2 * e[0] + 1], bx = x[2 * e[1]], by = x[2 * e[1] + 1];
    if (!(std::isfinite(ax) && std::isfinite(ay) && std::isfinite(bx) && std::isfinite(by))) {
      r[0] = 0, r[1] = bins.nx - 1, r[2] = 0, r[3] = bins.ny - 1;
      return;
    }
    r[0] = cell(std::min(ax, bx) - search, bins.x0, bins.nx);
    r[1] = cell(std::max(ax, bx) + search, bins.x0, bins.nx);
    r[2] = cell(std::min(ay, by) - search, bins.y0, bins.ny);
    r[3] = cell(std::max(ay, by) + search, bins.y0, bins.ny);
  };
  bins.start.assign(static_cast<std::size_t>(bins.nx * bins.ny + 1), 0);
  int r[4];
  for (int k = 0; k < static_cast<int>(edges.size()); ++k) {
    range(k, r);
    for (int j = r[2]; j <= r[3]; ++j)
      for (int i = r[0]; i <= r[1]; ++i) ++bins.start[i + bins.nx * j + 1];
  }
  for (std::size_t c = 1; c < bins.start.size(); ++c) bins.start[c] += bins.start[c - 1];
  bins.edges.resize(static_cast<std::size_t>(bins.start.back()));
  // Filled through start[c] as bin c's insertion point, which then holds bin c + 1's start:
  // shifted back by one bin afterwards (no scratch array per detection).
  for (int k = 0; k < static_cast<int>(edges.size()); ++k) {
    range(k, r);
    for (int j = r[2]; j <= r[3]; ++j)
      for (int i = r[0]; i <= r[1]; ++i) bins.edges[bins.start[i + bins.nx * j]++] = k;
  }
  for (std::size_t c = bins.start.size() - 1; c > 0; --c) bins.start[c] = bins.start[c - 1];
  bins.start[0] = 0;
}

// Two surface nodes a and b, each at the other's vertex: of one surface (a curled fold's two
// shoulders pressed onto each other) or of two bodies in a two-way pair (two folds' corners
// meeting). Slot a has the vertex b as its feature with b's pseudo-normal n_b, slot b the
// vertex a with n_a. They are one point contact, but as two constraints with two normals both
// hold only where b - a is normal to n_a and to n_b, that is a = b: the contact glued the nodes,
// Newton converged on it slowly (the normals were not the gaps' gradients in the vertex zone
// then) and, at Δt = 5e-5 in the vocal folds' flow, not within 30 iterations. Both slots now
// take one normal, n = (n_b - n_a) / |n_b - n_a| (for a: b's side outward; for b: -n), and the
// gap (a - b) . n: the same constraint twice, which the complementarity solve handles as any two
// slots on one contact (it keeps one), and the nodes may slide along each other. Only when both
// are in the other's zone: a node outside it, nearest to the vertex itself, has the direction
// from the vertex as its normal and its distance as its gap (that gradient is exact). Joined
// with a node in the zone that is behind its edges, the pair took the gap +1.7e-4 where one slot
// had -5.4e-5 and the other +2.1e-4 (a fold's surface creased, two nodes five apart pressed
// together: vocal folds, finer cover); the join came and went as the outer node crossed the
// Voronoi border of the vertex, and Newton cycled between the two gaps through every step
// cutback.
void ContactSet::join_vertex_pairs(const std::vector<const std::vector<double>*>& x) {
  const std::size_t nb = m_surfaces.size();
  for (std::size_t ka = 0; ka < m_slots.size(); ++ka) {
    ContactSlot& sa = m_slots[ka];
    if (sa.master_body < 0 || sa.m0 < 0 || sa.m1 >= 0 || !sa.zone) continue;  // no zone vertex
    const auto& index = m_node_slot[sa.master_body * nb + sa.slave_body];
    if (index.empty()) continue;  // no slots the other way
    const int kb = index[sa.m0];
    if (kb <= static_cast<int>(ka)) continue;  // each pair once
    ContactSlot& sb = m_slots[kb];
    if (sb.m0 != sa.slave_node || sb.m1 >= 0) continue;
    if (!sb.zone) continue;  // b nearest to the vertex a itself (above)
    Vec2 n{sa.normal[0] - sb.normal[0], sa.normal[1] - sb.normal[1]};
    const double ln = std::hypot(n[0], n[1]);
    if (!(ln > 1e-6)) continue;  // normals that cancel: no common direction
    n = {n[0] / ln, n[1] / ln};
    const std::vector<double>& xa = *x[sa.slave_body];
    const std::vector<double>& xv = *x[sa.master_body];
    const int a = sa.slave_node, v = sb.slave_node;
    const double g = (xa[2 * a] - xv[2 * v]) * n[0] + (xa[2 * a + 1] - xv[2 * v + 1]) * n[1];
    sa.normal = n;
    sb.normal = {-n[0], -n[1]};
    sa.gap = sb.gap = g;
  }
}

namespace {
// The slot's feature the edge from (ax, ay) along (ex, ey), at parameter xi (as given: clamped or
// not): its unit normal (the master body on its left) and the signed distance of (px, py) from
// the edge's point at xi along that normal.
void set_edge(ContactSlot& s, double ax, double ay, double ex, double ey, double xi, double px,
              double py) {
  const double le = std::hypot(ex, ey);
  s.xi = xi;
  s.normal = {ey / le, -ex / le};
  s.gap = (px - ax - xi * ex) * s.normal[0] + (py - ay - xi * ey) * s.normal[1];
}

// Surface edge k's unit normal (the body on its left) at positions pos.
Vec2 edge_normal(const Mesh& mesh, const std::vector<double>& pos, int k) {
  const auto& e = mesh.surface[k];
  const double dx = pos[2 * e[1]] - pos[2 * e[0]], dy = pos[2 * e[1] + 1] - pos[2 * e[0] + 1];
  const double l = std::hypot(dx, dy);
  return Vec2{dy / l, -dx / l};
}
}  // namespace

Vec2 ContactSet::pseudo_normal(const Surface& surf, const std::vector<double>& pos, int v) {
  Vec2 nv{0, 0};
  for (int j : surf.vertex_edges[v]) {
    const Vec2 nj = edge_normal(*surf.mesh, pos, j);
    nv[0] += nj[0], nv[1] += nj[1];
  }
  return nv;
}

double ContactSet::zone_radius(const Surface& surf, const std::vector<double>& pos, int v) {
  double shortest = std::numeric_limits<double>::max();
  for (int j : surf.vertex_edges[v]) {
    const auto& e = surf.mesh->surface[j];
    shortest = std::min(shortest, std::hypot(pos[2 * e[1]] - pos[2 * e[0]],
                                             pos[2 * e[1] + 1] - pos[2 * e[0] + 1]));
  }
  return kVertexZone * shortest;
}

double ContactSet::zone_gap(const std::vector<double>& pos, int v, const Vec2& n_v, double qx,
                            double qy) {
  return (qx - pos[2 * v]) * n_v[0] + (qy - pos[2 * v + 1]) * n_v[1];
}

double ContactSet::vertex_gap(const Surface& surf, const std::vector<double>& pos, int v,
                              double qx, double qy, const Vec2& n_v) {
  double nearest = std::numeric_limits<double>::max(), g = 0;
  for (int j : surf.vertex_edges[v]) {
    const auto& ej = surf.mesh->surface[j];
    const double bx = pos[2 * ej[0]], by = pos[2 * ej[0] + 1];
    const double fx = pos[2 * ej[1]] - bx, fy = pos[2 * ej[1] + 1] - by;
    const double t = std::clamp(((qx - bx) * fx + (qy - by) * fy) / (fx * fx + fy * fy), 0.0, 1.0);
    const double rx = qx - bx - t * fx, ry = qy - by - t * fy;
    const double dj = std::hypot(rx, ry);
    if (dj >= nearest) continue;
    nearest = dj;
    const Vec2 nj = t > 0 && t < 1 ? edge_normal(*surf.mesh, pos, j) : n_v;
    g = rx * nj[0] + ry * nj[1] < 0 ? -dj : dj;
  }
  return g;
}

// A held slot (hold_features): its feature's gap and normal at the positions x, as detection
// takes them for that feature, without looking for another. An edge is the line through it
// (the parameter not clamped: the node may slide past its end while held); a vertex zone the
// pseudo-normal with the distance along it; another vertex the direction from it, on the side
// detection finds (ray casting between two bodies, the pseudo-normal on the body's own surface).
void ContactSet::hold_slot(ContactSlot& s, const std::vector<const std::vector<double>*>& x) const {
  const std::vector<double>& xs = *x[s.slave_body];
  const std::vector<double>& xm = *x[s.master_body];
  const double px = xs[2 * s.slave_node], py = xs[2 * s.slave_node + 1];
  const Surface& surf = m_surfaces[s.master_body];
  if (s.m1 >= 0) {
    const double ax = xm[2 * s.m0], ay = xm[2 * s.m0 + 1];
    const double ex = xm[2 * s.m1] - ax, ey = xm[2 * s.m1 + 1] - ay;
    set_edge(s, ax, ay, ex, ey, ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey), px, py);
    return;
  }
  const int v = s.m0;
  const bool self = s.master_body == s.slave_body;
  // The pseudo-normal: the zone's normal, and on the body's own surface the side of the vertex.
  const Vec2 nv = s.zone || self ? pseudo_normal(surf, xm, v) : Vec2{0, 0};
  const double ln = std::hypot(nv[0], nv[1]);
  if (s.zone && ln > 1e-6) {
    s.normal = {nv[0] / ln, nv[1] / ln};
    s.gap = zone_gap(xm, v, s.normal, px, py);
    return;
  }
  s.zone = false;  // (a zone whose vertex's edges now fold back onto each other)
  const double qx = px - xm[2 * v], qy = py - xm[2 * v + 1];
  const double d = std::hypot(qx, qy);
  if (d == 0) {  // on the vertex: no direction from it; the last normal stays
    s.gap = 0;
    return;
  }
  const double sign = self ? (qx * nv[0] + qy * nv[1] < 0 ? -1.0 : 1.0)
                           : (inside_surface(*surf.mesh, xm, px, py) ? -1.0 : 1.0);
  s.normal = {sign * qx / d, sign * qy / d};
  s.gap = sign * d;
}

void ContactSet::detect_slot(ContactSlot& s, const std::vector<const std::vector<double>*>& x,
                             const std::vector<std::array<double, 4>>& boxes,
                             double reach) const {
  const double px = (*x[s.slave_body])[2 * s.slave_node];
  const double py = (*x[s.slave_body])[2 * s.slave_node + 1];
  if (s.plane >= 0) {
    const auto& pl = m_planes[s.plane];
    s.normal = pl.normal;
    s.gap = (px - pl.point[0]) * pl.normal[0] + (py - pl.point[1]) * pl.normal[1];
    s.m0 = s.m1 = -1;
    s.xi = 0;
    return;
  }
  if (s.master_body == s.slave_body)
    return detect_self(s, m_front[&s - m_slots.data()], *x[s.slave_body], reach,
                       m_self_bins[s.slave_body]);
  const bool was_zone = s.zone && s.m0 >= 0 && s.m1 < 0;  // the last detection's zone vertex
  s.zone = false;
  const auto& box = boxes[s.master_body];
  const double dx = std::max({box[0] - px, 0.0, px - box[2]});
  const double dy = std::max({box[1] - py, 0.0, py - box[3]});
  const double box_distance = std::hypot(dx, dy);
  if (box_distance > reach && !s.active) {
    // Farther than `reach` from the master's box: a lower bound of the gap is enough to stay
    // inactive. Nearer, the slot may become a constraint and needs its feature: a node just
    // outside the box (two flat faces meeting at the box's edge, as touching folds do) used to
    // become a candidate without one, and its row of B read the equations of node -1.
    s.gap = box_distance;
    s.m0 = s.m1 = -1;
    return;
  }
  const Mesh& mesh = *m_surfaces[s.master_body].mesh;
  const std::vector<double>& xm = *x[s.master_body];
  double best = std::numeric_limits<double>::max();
  int best_edge = -1;
  double best_xi = 0;
  // The edge of the last detection, if the slot had one: its parameter (not clamped) and squared
  // distance to the edge extended by kKeepEdge of its length at both ends.
  int last_edge = -1;
  double last_d2 = 0, last_xi = 0;
  for (std::size_t k = 0; k < mesh.surface.size(); ++k) {
    const auto& e = mesh.surface[k];
    const double ax = xm[2 * e[0]], ay = xm[2 * e[0] + 1];
    const double ex = xm[2 * e[1]] - ax, ey = xm[2 * e[1] + 1] - ay;
    const double l2 = ex * ex + ey * ey;
    const double xi_line = ((px - ax) * ex + (py - ay) * ey) / l2;
    const double xi = std::clamp(xi_line, 0.0, 1.0);
    const double qx = ax + xi * ex - px, qy = ay + xi * ey - py;
    const double d2 = qx * qx + qy * qy;
    if (e[0] == s.m0 && e[1] == s.m1 && xi_line >= -kKeepEdge && xi_line <= 1 + kKeepEdge) {
      const double rx = ax + xi_line * ex - px, ry = ay + xi_line * ey - py;
      last_edge = static_cast<int>(k);
      last_d2 = rx * rx + ry * ry;
      last_xi = xi_line;
    }
    // Ties (a vertex shared by two edges) prefer the edge whose interior holds the projection.
    const bool interior = xi > 0 && xi < 1;
    if (d2 < best * (1 - kClosestTie) || (d2 <= best * (1 + kClosestTie) && interior)) {
      best = d2;
      best_edge = static_cast<int>(k);
      best_xi = xi;
    }
  }
  // A vertex's zone: nearest to the vertex v itself (beyond both its edges' ends) and within
  // kVertexZone of v's shorter edge, or within twice that while v is the slot's zone already
  // (from whichever side). There the normal is v's unit pseudo-normal n_v and the gap
  // (p - v) . n_v, as on a body's own surface (detect_self), and two nodes each in the other's
  // zone are one contact (join_vertex_pairs). Before the zone, the normal at a vertex was the
  // direction from it, exact but turning as fast as the node moves round v: two folds' corner
  // nodes pressed onto each other (vocal folds, h = 0.01, t = 2.752) were 4e-6 and 1e-9 apart in
  // alternate Newton iterations, the normal swung by 90 degrees between them, and Newton cycled
  // through every cutback, with the features held too. In v's wedge the two gaps differ by
  // |p - v| (1 - n . n_v), a fraction of a zone's radius. The zone's slot keeps it while within
  // the doubled radius, also where the node is nearer to an edge's interior or coincides with v
  // (its projection then ties between the edges): the normal does not switch back and forth
  // between n_v and an edge's at the wedge's border. A node facing an edge, its end included,
  // does not enter a zone: at a punch's corner on a flat base the pseudo-normal tilted the
  // contact force (solid/README.md, Contact).
  const Surface& surf = m_surfaces[s.master_body];
  auto take_zone = [&](int v, double widen) {
    if (surf.vertex_edges[v].size() != 2) return false;
    const double r = zone_radius(surf, xm, v) * widen;
    const Vec2 nv = pseudo_normal(surf, xm, v);
    const double ln = std::hypot(nv[0], nv[1]);
    // (a vertex whose edges fold back onto each other has no pseudo-normal)
    if (!(std::hypot(px - xm[2 * v], py - xm[2 * v + 1]) <= r && ln > 1e-6)) return false;
    s.m0 = v;
    s.m1 = -1;
    s.xi = 0;
    s.normal = {nv[0] / ln, nv[1] / ln};
    s.gap = zone_gap(xm, v, s.normal, px, py);
    s.zone = true;
    return true;
  };
  if (was_zone && take_zone(s.m0, 2)) return;
  // A node at a vertex of the master (coincident nodes of mirrored meshes that touch, a node on
  // a kink of the surface) is as close to both edges that share it; which one wins above is
  // decided by round-off and flips from one Newton iteration to the next, and with it the normal
  // and the gap's curvature, so Newton cycles and never settles. The slot keeps its last edge
  // while its projection stays on that edge extended by kKeepEdge of its length and the
  // distance is the closest within kKeepEdge of the edge's length (the gap then errs by at most
  // that times the kink's angle).
  if (last_edge >= 0) {
    const auto& e = mesh.surface[last_edge];
    const double ex = xm[2 * e[1]] - xm[2 * e[0]], ey = xm[2 * e[1] + 1] - xm[2 * e[0] + 1];
    const double margin = kKeepEdge * kKeepEdge * (ex * ex + ey * ey);
    if (std::sqrt(last_d2) <= std::sqrt(best) + std::sqrt(margin)) {
      s.m0 = e[0];
      s.m1 = e[1];
      set_edge(s, xm[2 * e[0]], xm[2 * e[0] + 1], ex, ey, last_xi, px, py);
      return;
    }
  }
  const auto& e = mesh.surface[best_edge];
  const double ax = xm[2 * e[0]], ay = xm[2 * e[0] + 1];
  const double ex = xm[2 * e[1]] - ax, ey = xm[2 * e[1] + 1] - ay;
  const double le = std::hypot(ex, ey);
  const double dist = std::sqrt(best);
  const bool vertex = best_xi <= 0 || best_xi >= 1;
  if (vertex && dist > kVertexDistance * le) {
    const int v = best_xi <= 0 ? e[0] : e[1];
    if (take_zone(v, 1)) return;
    const double sign = inside_surface(mesh, xm, px, py) ? -1.0 : 1.0;
    s.m0 = v;
    s.m1 = -1;
    s.xi = 0;
    s.normal = {sign * (px - xm[2 * v]) / dist, sign * (py - xm[2 * v + 1]) / dist};
    s.gap = sign * dist;
    return;
  }
  s.m0 = e[0];
  s.m1 = e[1];
  set_edge(s, ax, ay, ex, ey, best_xi, px, py);
}

// Self-contact, a node of a body against its own surface. Three differences from two bodies:
// - A surface is at distance 0 of itself near every node: a node looks only at the edges
//   farther than kSelfNear of the local surface edge lengths from it in the reference
//   configuration (Surface::self_near lists the others). Parts nearer never touch.
// - Inside is not decided by ray casting (the node lies on the very surface it would cast
//   against) but by the edge's normal; at a vertex v by the sum of the two edges' normals there,
//   n_v (the pseudo-normal: when v is the closest point of the surface, (p - v) . n_v > 0
//   exactly outside, at a convex and a concave vertex alike; Baerentzen & Aanaes 2005).
// - A feature with the node behind it by more than the node can have crossed since the step's
//   start (kSelfCrossing times its motion since relative to the feature's point under it, plus
//   a floor) is the body's other side, not a contact, and is passed over. For most features the
//   bound is at most `reach` (and `reach` when no start positions were given); it has no cap at
//   the guarded edges: those at the slot's front feature (what it faced at the start of the
//   step, remember_fronts) and at its feature while it is active. A node behind a guarded
//   feature within the bound, and in front of it at the step's start, has gone through it (the
//   nearest such feature, even if a nearer guarded one has the node in front: it tunnelled
//   through a corner): that is its feature, even if the body's other side is nearer by then.
//   So a node driven through the surface it faced, by a Newton iterate however large, is still
//   caught in the next; a node driven through a surface that was not its closest at the step's
//   start, deeper than that bound, would not be.
//   Behind a guarded feature beyond the bound, or already at the start, is no crossing:
//   - at a corner of about 90 degrees a node resting on one edge projects inside the other
//     and behind its line by up to an edge's length; taken as through, a vocal fold's node
//     touching one edge got a gap of -1.4e-2 from the next, and Newton cycled;
//   - a short edge of a crumpled surface can turn over between two steps (or a vertex's
//     pseudo-normal swing past the node) while the node stands still: 3.4e-2 behind a vertex
//     by its pseudo-normal, a vocal fold's node was taken as through it once the feature it
//     faced was the vertex's neighbour, and the constraint threw the surface by that much in
//     one iteration (Newton diverged).
// - Within a vertex's zone (kVertexZone) the vertex is the feature, with its pseudo-normal
//   as the normal, from whichever of its edges it is found, and the distance along it as the
//   gap; whether the node is behind the feature (the body's other side, a crossing) is still
//   decided on its distance to the nearer edge.
// Only features within kSelfSearch reaches are looked for (a box test first).
// The closest remaining feature wins, with detect_slot's rules: ties prefer the edge whose
// interior holds the projection, and the last edge extended by kKeepEdge is kept.
void ContactSet::detect_self(ContactSlot& s, const std::array<int, 2>& front,
                             const std::vector<double>& x, double reach,
                             const EdgeBins& bins) const {
  const Surface& surf = m_surfaces[s.slave_body];
  const Mesh& mesh = *surf.mesh;
  const double px = x[2 * s.slave_node], py = x[2 * s.slave_node + 1];
  // Whether the node was in front of (or on) the feature at the step's start (`start`, the
  // body's positions then; none given: yes): the feature's point under it then (the vertex, or
  // the edge's point at the same xi), its normal then (the pseudo-normal, or the edge's), and
  // the same floor as the crossing bound. Only a node in front then can have gone through it
  // within the step. Without this test the crossing bound alone decided, and it depends on how
  // far the node has moved: a node behind a corner's other edge already at the start, by
  // about twice its motion, took that edge in one Newton iteration and not in the next.
  auto in_front_at_start = [&](const std::array<int, 2>& e, double xi, bool vertex,
                               const std::vector<double>& start) {
    if (start.empty()) return true;
    const double floor = -std::max(kKeepEdge * reach, m_gap_tol);
    const double sx = start[2 * s.slave_node], sy = start[2 * s.slave_node + 1];
    if (vertex) {  // the side of the surface at a vertex: the nearer of its two edges'
      const int v = xi <= 0 ? e[0] : e[1];
      return vertex_gap(surf, start, v, sx, sy, pseudo_normal(surf, start, v)) >= floor;
    }
    const double w = std::clamp(xi, 0.0, 1.0);
    const double ax0 = start[2 * e[0]], ay0 = start[2 * e[0] + 1];
    const double dx = start[2 * e[1]] - ax0, dy = start[2 * e[1] + 1] - ay0;
    const double l = std::hypot(dx, dy);
    return ((sx - ax0 - w * dx) * dy - (sy - ay0 - w * dy) * dx) / l >= floor;
  };
  // Nodes whose edges are never passed over as the body's other side.
  const int guard[4] = {front[0], front[1], s.active ? s.m0 : -1, s.active ? s.m1 : -1};
  auto guarded = [&](const std::array<int, 2>& e) {
    for (int g : guard)
      if (g >= 0 && (e[0] == g || e[1] == g)) return true;
    return false;
  };
  struct Feature {
    double rank = std::numeric_limits<double>::max();
    int edge = -1;
    double xi = 0, gap = 0;
    Vec2 normal{0, 0};
    bool vertex = false;
    bool zone = false;
  };
  // crossed: the nearest guarded feature the node is behind by no more than it can have
  // crossed since the step's start, and was in front of then.
  Feature closest, crossed;
  const auto& near = surf.self_near[s.slave_node];  // sorted
  const double search = kSelfSearch * reach;
  const std::vector<double>& start = m_start.size() > static_cast<std::size_t>(s.slave_body)
                                         ? m_start[s.slave_body]
                                         : kNoPositions;
  // The edges to examine, in edge order: those of the node's bin (bin_edges: every edge whose
  // box widened by `search` may hold the node) and the guarded ones (the edges at a guard node).
  thread_local std::vector<int> examine;
  examine.clear();
  {
    if (std::isfinite(px) && std::isfinite(py)) {
      const int c = bin_of(px, bins.x0, bins.inv, bins.nx) +
                    bins.nx * bin_of(py, bins.y0, bins.inv, bins.ny);
      examine.assign(bins.edges.begin() + bins.start[c], bins.edges.begin() + bins.start[c + 1]);
    } else {
      for (int k = 0; k < static_cast<int>(mesh.surface.size()); ++k) examine.push_back(k);
    }
    const std::size_t binned = examine.size();
    for (int g : guard)
      if (g >= 0)
        for (int k : surf.vertex_edges[g]) examine.push_back(k);
    if (examine.size() > binned) {
      std::sort(examine.begin(), examine.end());
      examine.erase(std::unique(examine.begin(), examine.end()), examine.end());
    }
  }
  std::size_t skip = 0;
  for (const int k : examine) {
    while (skip < near.size() && near[skip] < k) ++skip;
    if (skip < near.size() && near[skip] == k) continue;
    const auto& e = mesh.surface[k];
    const bool guard_edge = guarded(e);
    // Farther than `search` along x or y from the edge's box: not a feature (unless guarded).
    if (!guard_edge) {
      const double x0 = x[2 * e[0]], x1 = x[2 * e[1]], y0 = x[2 * e[0] + 1], y1 = x[2 * e[1] + 1];
      if (px < std::min(x0, x1) - search || px > std::max(x0, x1) + search ||
          py < std::min(y0, y1) - search || py > std::max(y0, y1) + search)
        continue;
    }
    const double ax = x[2 * e[0]], ay = x[2 * e[0] + 1];
    const double ex = x[2 * e[1]] - ax, ey = x[2 * e[1] + 1] - ay;
    const double l2 = ex * ex + ey * ey;
    const double xi_line = ((px - ax) * ex + (py - ay) * ey) / l2;
    // The slot's last edge, extended by kKeepEdge of its length (detect_slot's rule).
    const bool kept = e[0] == s.m0 && e[1] == s.m1 && xi_line >= -kKeepEdge &&
                      xi_line <= 1 + kKeepEdge;
    double xi = kept ? xi_line : std::clamp(xi_line, 0.0, 1.0);
    const double qx = px - ax - xi * ex, qy = py - ay - xi * ey;
    const double d = std::hypot(qx, qy);
    const double le = std::sqrt(l2);
    const double rank = kept ? d - kKeepEdge * le : d;
    if (!guard_edge && (d > search || rank > closest.rank * (1 + kClosestTie))) continue;
    const bool interior = xi > 0 && xi < 1;
    Vec2 n{ey / le, -ex / le};
    double g = qx * n[0] + qy * n[1];
    bool vertex = !kept && !interior && d > kVertexDistance * le;
    // Near a vertex v, within its zone: the feature is v with the pseudo-normal n_v as its
    // normal, whichever of v's two edges is examined. Two surface nodes pressed onto each other
    // (a curled fold tip's two shoulders: each node at the other's vertex) otherwise took the
    // edge on one side of v, were placed by its constraint where the edge on the other side was
    // the closer, and switched between the two at every iteration. The gap is the distance along
    // n_v, g = (p - v) . n_v, whose gradient the constraint takes (B: n_v and -n_v; n_v's own
    // change with the motion of v and its neighbours is left out, a term of the order of
    // |p - v|, a hundredth of an edge): Newton converges as at an edge. It is the gap to the
    // plane through v normal to n_v: it differs from the distance to the nearer edge by up to
    // |p - v| |n_v - n_e| (n_e that edge's normal; within 1.5 zone radii), and a node on a convex
    // corner's edge is behind that plane. So whether the node is behind the feature (the
    // body's other side, a crossing, below) is decided on the distance to the nearer edge,
    // `depth`. That distance as the gap has the nearer edge's normal as its gradient, up to half
    // the kink away from n_v, and Newton would converge by only 1 - cos of that angle per
    // iteration (solid/README.md, Self-contact).
    int zone = -1;
    for (int v : e) {
      if (surf.vertex_edges[v].size() != 2) continue;
      const double r = zone_radius(surf, x, v) * (s.zone && s.m0 == v ? 2 : 1);
      if (std::hypot(px - x[2 * v], py - x[2 * v + 1]) <= r) zone = v;
    }
    const Vec2 nv = zone >= 0 ? pseudo_normal(surf, x, zone) : Vec2{0, 0};
    const double ln = std::hypot(nv[0], nv[1]);
    const bool in_zone = zone >= 0 && ln > 1e-6;
    if (in_zone) {  // (a vertex whose edges fold back onto each other has no pseudo-normal)
      n = {nv[0] / ln, nv[1] / ln};
      g = zone_gap(x, zone, n, px, py);
      vertex = true;
      xi = zone == e[0] ? 0 : 1;
    } else if (vertex) {
      const int v = xi <= 0 ? e[0] : e[1];
      const auto& ve = surf.vertex_edges[v];
      if (ve.size() == 2) {
        // v is the closest point of its two edges only beyond the end of the one arriving
        // (a -> v: (p - v) . t_a >= 0) and before the start of the one leaving (v -> b:
        // (p - v) . t_b <= 0). Elsewhere an edge next to v is nearer: it is the feature if the
        // node may touch it; if not (it is in the node's neighbourhood: a far vertex of the
        // node's own face, seen along the face) v is no feature and its sign is meaningless.
        const auto& e0 = mesh.surface[ve[0]];
        const auto& in = e0[1] == v ? e0 : mesh.surface[ve[1]];
        const auto& out = e0[0] == v ? e0 : mesh.surface[ve[1]];
        const double ta = qx * (x[2 * v] - x[2 * in[0]]) + qy * (x[2 * v + 1] - x[2 * in[0] + 1]);
        const double tb = qx * (x[2 * out[1]] - x[2 * v]) + qy * (x[2 * out[1] + 1] - x[2 * v + 1]);
        if (ta < 0 || tb > 0) continue;
      }
      const Vec2 nv = pseudo_normal(surf, x, v);
      const double sign = qx * nv[0] + qy * nv[1] < 0 ? -1.0 : 1.0;
      n = {sign * qx / d, sign * qy / d};
      g = sign * d;
    }
    // Behind a feature by more than the node can have crossed since the step's start: the
    // body's other side. A guarded feature's bound has no cap: a Newton iterate may drive a
    // node through what it faced by more than a reach, and twice the motion still covers that
    // (without start positions: any depth).
    double cross = guard_edge ? std::numeric_limits<double>::infinity() : reach;
    if (!start.empty()) {
      const double w = std::clamp(xi, 0.0, 1.0);
      auto delta = [&](int v, int c) { return x[2 * v + c] - start[2 * v + c]; };
      auto relative = [&](int c) {
        return delta(s.slave_node, c) - (1 - w) * delta(e[0], c) - w * delta(e[1], c);
      };
      cross = std::min(cross, kSelfCrossing * std::hypot(relative(0), relative(1)) +
                                  std::max(kKeepEdge * reach, m_gap_tol));
    }
    // Except the vertex whose zone held the node at the last detection and holds it now: within
    // a zone (one or two hundredths of an edge from the vertex) the node is at that vertex, not
    // at the body's other side, and the bound, twice a motion that changes from one Newton
    // iteration to the next, took and dropped it by turns. Two nodes of a creased fold pressed
    // onto each other (vocal folds at h = 0, upwind3): behind the other's vertex by 1.26e-5 and
    // 1.46e-5 against bounds of 0.91e-5 and 3.4e-5 in alternate iterations, so the pair was
    // joined in one iteration and not in the next, and Newton cycled through every cutback.
    const bool kept_zone = in_zone && s.zone && s.m1 < 0 && s.m0 == zone;
    // The signed distance to the surface there: g, but in a zone.
    const double depth = in_zone ? vertex_gap(surf, x, zone, px, py, n) : g;
    if (depth < -cross && !kept_zone) continue;
    auto offer = [&](Feature& f) {
      if (rank < f.rank * (1 - kClosestTie) || (rank <= f.rank * (1 + kClosestTie) && interior))
        f = {rank, k, xi, g, n, vertex, in_zone};
    };
    offer(closest);
    if (guard_edge && depth < 0 && in_front_at_start(e, xi, vertex, start)) offer(crossed);
  }
  // Behind what it faced (or touched) by no more than the node can have crossed since the
  // step's start: that is the contact (the nearest such), even when the body's other side is
  // nearer by then.
  const Feature& f = crossed.edge >= 0 ? crossed : closest;
  const int best_edge = f.edge;
  const double best_xi = f.xi, best_gap = f.gap;
  const Vec2 best_normal = f.normal;
  const bool best_vertex = f.vertex;
  s.zone = best_vertex && f.zone;
  if (best_edge < 0) {
    // No feature: far. An active slot can get here too (its vertex, seen from where the edge
    // next to it is in the node's neighbourhood, is no feature): it is released, since a
    // constraint without a feature has no row of B.
    s.gap = std::numeric_limits<double>::infinity();
    s.m0 = s.m1 = -1;
    s.xi = 0;
    s.active = false;
    s.lambda = 0;
    return;
  }
  const auto& e = mesh.surface[best_edge];
  s.gap = best_gap;
  s.normal = best_normal;
  if (best_vertex) {
    s.m0 = best_xi <= 0 ? e[0] : e[1];
    s.m1 = -1;
    s.xi = 0;
  } else {
    s.m0 = e[0];
    s.m1 = e[1];
    s.xi = best_xi;
  }
}

}  // namespace solid
