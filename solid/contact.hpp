// Frictionless node-to-segment contact (paper Eq. 3-4, Wriggers 2006): every surface node of a
// slave body is a candidate against the surface of a master body (elastic or rigid), against the
// far parts of its own surface (self-contact: slave body == master body), or a rigid plane. The
// signed gap g = (x_s - x_p) . n, with x_p the closest point of the master surface and n its
// outward normal, is negative inside the master (inside is decided by ray casting, so deep
// penetration is caught too; for self-contact see detect_self). Active constraints g = 0 are
// enforced by Lagrange multipliers lambda >= 0 (contact_solve.cpp); this file only does the
// geometry.
#pragma once

#include <array>
#include <limits>
#include <vector>

#include "model.hpp"

namespace solid {

// One candidate constraint and its state.
struct ContactSlot {
  int slave_body = -1, slave_node = -1;
  int master_body = -1;  // -1: a plane
  int plane = -1;
  // From the last detection: the gap, the master feature (segment m0 -> m1 at parameter xi, or
  // the vertex m0 when m1 == -1) and the normal n, so that dg/dx_s = n,
  // dg/dx_m0 = -(1 - xi) n, dg/dx_m1 = -xi n.
  double gap = std::numeric_limits<double>::infinity();
  int m0 = -1, m1 = -1;
  double xi = 0;
  Vec2 normal{0, 0};
  // The feature is a vertex whose zone holds the node, the normal its pseudo-normal
  // (detect_self, detect_slot); only such slots are joined in pairs (join_vertex_pairs).
  bool zone = false;
  // Active-set state carried across Newton iterations and steps.
  bool active = false;
  double lambda = 0;  // multiplier, > 0 pushes the bodies apart
};

class ContactSet {
 public:
  // Builds the slots: the surface nodes of each pair's slave against its master (and back when
  // two-way), and of each plane's bodies against the plane.
  void setup(const std::vector<const Mesh*>& meshes, const std::vector<BodyKind>& kinds,
             const std::vector<ContactPair>& pairs, const std::vector<ContactPlane>& planes);
  bool empty() const { return m_slots.empty(); }
  // Updates gap, feature and normal of every slot from current positions (one vector per body).
  // reach[b] (one per body): a slave node of body b within this distance of a master's bounding
  // box gets its closest feature; farther, an inactive slot keeps only the distance to the box
  // (a lower bound of its gap, > reach) and no feature. A caller that turns slots with
  // gap < reach into constraints so always finds their feature.
  void detect(const std::vector<const std::vector<double>*>& x, const std::vector<double>& reach);
  // Self-contact: each slot's feature (when it faces it or touches it) becomes its front for
  // the coming step (detect_self), and the positions x (one vector per body) the step starts
  // from; gap_tol is the accepted gap (a slot that far inside keeps its front). Called at the
  // start of every step from the last detection. Without positions, a node may be found up
  // to one reach behind any feature, and at any depth behind a guarded one (see detect_self).
  void remember_fronts(const std::vector<const std::vector<double>*>& x = {}, double gap_tol = 0);
  // Held features: within a Newton solve that has come back to an earlier iterate's residual
  // (a cycle among the discrete choices of detection: which edge, which vertex zone, a joined
  // pair; newton.cpp), every slot that is active or a candidate (a feature within one reach at
  // the last detection) keeps its feature, and detect() only evaluates that feature's gap and
  // normal at the new positions (hold_slot): the conditions are then one smooth set. The other
  // slots are detected as always. The solver releases the hold at the start and at the end of
  // every solve, and checks a state reached under it with a detection without it.
  void hold_features(bool on);
  bool holds_features() const { return m_hold; }
  std::vector<ContactSlot>& slots() { return m_slots; }
  const std::vector<ContactSlot>& slots() const { return m_slots; }

 private:
  struct Surface {
    const Mesh* mesh = nullptr;
    std::vector<int> nodes;  // nodes on the surface
    // Indexed by mesh node: the surface edges a node never touches (those near it in the
    // reference configuration; sorted; self-contact only, empty otherwise), and the surface
    // edges that meet at the node (a vertex's pseudo-normal, the sign of a gap to it).
    std::vector<std::vector<int>> self_near;
    std::vector<std::vector<int>> vertex_edges;
  };
  void setup_self(Surface& s) const;
  // Self-contact's broad phase: the surface edges of one body binned on a uniform grid over
  // their boxes widened by the search distance, so that the edges whose widened box holds a
  // point are the edges of the point's bin (each bin's list in edge order). Rebuilt at each
  // detection.
  struct EdgeBins {
    double x0 = 0, y0 = 0, inv = 0;  // grid origin, 1 / bin size
    int nx = 0, ny = 0;
    std::vector<int> start, edges;  // bin (i, j)'s edges: edges[start[i + nx j] ...]
  };
  void bin_edges(const Surface& surf, const std::vector<double>& x, double search,
                 EdgeBins& bins) const;
  void detect_slot(ContactSlot& s, const std::vector<const std::vector<double>*>& x,
                   const std::vector<std::array<double, 4>>& boxes, double reach) const;
  void detect_self(ContactSlot& s, const std::array<int, 2>& front, const std::vector<double>& x,
                   double reach, const EdgeBins& bins) const;
  void join_vertex_pairs(const std::vector<const std::vector<double>*>& x);
  void hold_slot(ContactSlot& s, const std::vector<const std::vector<double>*>& x) const;
  // A surface's geometry at positions pos: the sum of the unit normals of the surface edges at
  // vertex v (its pseudo-normal, not normalised; detect_self, detect_slot, hold_slot), and the
  // signed distance from q to the nearer of v's edges (its sign from that edge's normal for a
  // projection inside it, from n_v at v itself; 0 for a vertex without edges), on which
  // detect_self decides whether a node is (or was at the step's start) behind a vertex.
  static Vec2 pseudo_normal(const Surface& surf, const std::vector<double>& pos, int v);
  static double vertex_gap(const Surface& surf, const std::vector<double>& pos, int v, double qx,
                           double qy, const Vec2& n_v);
  // The radius of vertex v's zone: kVertexZone times the shorter of its edges at pos (a vertex
  // with two edges; detect_self, detect_slot).
  static double zone_radius(const Surface& surf, const std::vector<double>& pos, int v);
  // A vertex zone's gap (detect_self, detect_slot, hold_slot): the distance from the vertex v
  // along its unit pseudo-normal n_v, (q - v) . n_v.
  static double zone_gap(const std::vector<double>& pos, int v, const Vec2& n_v, double qx,
                         double qy);
  std::vector<Surface> m_surfaces;
  std::vector<ContactPlane> m_planes;
  std::vector<ContactSlot> m_slots;
  std::vector<std::array<int, 2>> m_front;  // per slot (self-contact), remember_fronts
  std::vector<std::vector<double>> m_start;  // per body (self-contact), remember_fronts
  double m_gap_tol = 0;                       // remember_fronts
  bool m_hold = false;                        // hold_features
  std::vector<char> m_held;                   // per slot, while m_hold: its feature is kept
  std::vector<double> m_reach;                // per body, of the last detect()
  // Per (slave body, master body), slave * bodies + master: the slot of each slave node, or -1
  // (empty when the pair has no slots).
  std::vector<std::vector<int>> m_node_slot;
  std::vector<EdgeBins> m_self_bins;          // per body (self-contact), detect
};

// Second derivative of the gap to a segment, g = (x_s - x_1) . n with n = (e_y, -e_x) / l,
// e = x_2 - x_1, l = |e|, t = e / l, and xi the projection parameter: with d = x_s - x_1,
//   d2g/dd2 = 0,  d2g/dd de = -t n^T / l,  d2g/de2 = xi (n t^T + t n^T) / l - g n n^T / l^2,
// mapped to the nodes (s, 1, 2) through dd/dx = (I, -I, 0), de/dx = (0, -I, I). Output: 6 x 6
// row-major, dof order (s_x, s_y, 1_x, 1_y, 2_x, 2_y). Enters the tangent as -lambda H.
void segment_gap_hessian(const Vec2& xs, const Vec2& x1, const Vec2& x2, double H[36]);

// True when point p is inside the closed surface loops (edges a -> b) of a mesh at positions x.
bool inside_surface(const Mesh& mesh, const std::vector<double>& x, double px, double py);

}  // namespace solid
