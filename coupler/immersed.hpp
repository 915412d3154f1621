// The immersed solid method's transfers (paper Sec. 3.2.1): exact volume
// fractions and mean solid velocities on the staggered control volumes a body touches, and the
// exact nodal reaction of the fluid's forcing. Cost grows with the bodies' footprint, not the grid.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "protocol.hpp"

namespace coupler {

namespace proto = fsi::proto;

// One family of staggered faces (u or v) seen as control-volume boxes: face (i, j) owns
// [ex[i], ex[i+1]] × [ey[j], ey[j+1]]. Only faces with an unknown velocity take part: a face on a
// non-periodic boundary (a wall, an inflow, an outflow) carries a boundary value, not a forced one.
struct FaceBoxes {
  std::vector<double> ex, ey;
  int ni = 0, nj = 0;            // faces along x and y; flat index i + ni*j
  int i_lo = 0, i_hi = 0;        // faces [i_lo, i_hi) × [j_lo, j_hi) are unknowns
  int j_lo = 0, j_hi = 0;
  double period_x = 0, period_y = 0;  // domain lengths when periodic, else 0

  // u-face (i, j) at (x_face[i], y_centre[j]): box [x_centre[i-1], x_centre[i]] × [y_face[j], y_face[j+1]].
  static FaceBoxes u_faces(const proto::GridInfo& g);
  // v-face (i, j) at (x_centre[i], y_face[j]): box [x_face[i], x_face[i+1]] × [y_centre[j-1], y_centre[j]].
  static FaceBoxes v_faces(const proto::GridInfo& g);
  double volume(int i, int j) const { return (ex[i + 1] - ex[i]) * (ey[j + 1] - ey[j]); }
};

// A smoothed footprint (`[coupler] footprint_smoothing = ε`, 0 < ε ≤ 1): each face's weight
// along a direction is 1 inside its box, ramps linearly to 0 across each box edge over a width
// ε min(adjacent box widths) centred on the edge, while the neighbour's ramps from 0 to 1: a
// partition of unity whose integral over each face is its box width (so Σ α |V| is still the
// body's area). On a uniform grid the weight is the box convolved with a box of width ε h (on a
// stretched one each edge has its own ramp width). It is C⁰, so α varies with C¹ smoothness as
// a body crosses the grid, where the box's α (ε = 0, paper Sec. 3.2.1) has a kink each time an
// edge of the body meets a box edge. ε = 1 on a uniform grid is the tent of width 2h. Along each direction the line is cut into intervals, flat (one face, weight 1) or ramps
// (two faces, linear weights); `boxes` holds the intervals as boxes (ex, ey their edges) and
// face[k][e], w0[k][e], w1[k][e] (e = 0, 1) each interval's faces (−1: none) and weights at its
// two ends.
struct SmoothBoxes {
  FaceBoxes boxes;
  struct Axis {
    std::vector<std::array<int, 2>> face;
    std::vector<std::array<double, 2>> w0, w1;
  };
  Axis ax, ay;
  static SmoothBoxes of(const FaceBoxes& faces, double smoothing);
};

// Where a coordinate falls among sorted box edges e[0..n]: last_at_or_below(c) is the largest k
// with e[k] <= c, last_below(c) the largest k with e[k] < c (−1 when there is none). On evenly
// spaced edges the index comes from one division, checked against the edges themselves (so
// round-off never misplaces it); uneven edges take a binary search.
class EdgeIndex {
 public:
  explicit EdgeIndex(const std::vector<double>& e);
  int last_at_or_below(double c) const { return locate<false>(c); }
  int last_below(double c) const { return locate<true>(c); }

 private:
  template <bool strict>
  int locate(double c) const;
  const std::vector<double>* m_e = nullptr;
  bool m_even = false;
  double m_inv = 0;
};

// The largest k with e[k] <= c (strict: e[k] < c), −1 when there is none.
template <bool strict>
inline int EdgeIndex::locate(double c) const {
  const std::vector<double>& e = *m_e;
  const int n = static_cast<int>(e.size()) - 1;
  auto below = [c](double edge) { return strict ? edge < c : edge <= c; };
  if (!m_even)
    return static_cast<int>(strict ? std::lower_bound(e.begin(), e.end(), c) - e.begin()
                                   : std::upper_bound(e.begin(), e.end(), c) - e.begin()) -
           1;
  const double g = std::floor((c - e[0]) * m_inv);
  int k = g < -1 ? -1 : (g > n ? n : static_cast<int>(g));
  while (k >= 0 && !below(e[k])) --k;
  while (k < n && below(e[k + 1])) ++k;
  return k;
}

class ImmersedSolid {
 public:
  // smoothing: `[coupler] footprint_smoothing` ε in [0, 1] (SmoothBoxes); 0, the box.
  ImmersedSolid(const proto::GridInfo& grid, const proto::BodyMeshes& meshes,
                double smoothing = 0.0);

  // Before message 2 of a step (common/PROTOCOL.md), from the bodies' current state: for every
  // face whose control volume V meets a body, α = min(1, Σ_bodies |V ∩ body| / |V|) and the
  // mean solid velocity component
  //   ū_s = Σ_T Σ_a u_a ∫_{V∩T} N_a dA / Σ_T |V ∩ T|,
  // exact because N_a is linear on each triangle T: ∫_P N_a dA = |P| N_a(centroid of P).
  // Smoothed (ε > 0), |V ∩ T| becomes ∫_T φ dA and ∫_{V∩T} N_a dA becomes ∫_T φ N_a dA, with φ
  // the face's weight (SmoothBoxes), whose integral is |V|. Rigid fixed bodies are clipped once
  // and reused.
  void update(const proto::SolidState& state, proto::FaceSolid& u, proto::FaceSolid& v);
  // The same faces and α as the last update(), ū_s from the velocities of `state` (whose positions
  // must be those of that update): the coupled iterations change only the velocities. The
  // faces' bodies (FaceSolid::body) are left as that update() set them in `u`, `v`: pass the
  // same objects.
  void update_velocities(const proto::SolidState& state, proto::FaceSolid& u,
                         proto::FaceSolid& v) const;

  // Step 6: the nodal force on every body, the exact reaction of f_s (force per unit volume on
  // the fluid, on the faces of the last update, in their order):
  //   F_a = − Σ_V f_s(V) |V| ∫_{V∩body} N_a dA / Σ_bodies |V ∩ body|,
  // so Σ_a F_a = − Σ_V f_s(V) |V| to round-off. `force` gets one vector (2 per node) per body.
  void reaction(const std::vector<double>& fs_u, const std::vector<double>& fs_v,
                std::vector<std::vector<double>>& force) const;

  // The u- and v-families on two threads (default: when the machine has more than one core).
  void set_threads(bool on) { m_threads = on; }

  // The solid area seen by each family in the last update (Σ_V α|V| without the cap), for checks.
  double area_u() const { return m_u.total_area; }
  double area_v() const { return m_v.total_area; }

 private:
  // One piece V ∩ T: its face, the body and nodes of T, and ∫_{V∩T} N_a dA for the three nodes
  // (their sum is |V ∩ T|; smoothed: ∫_P φ N_a dA over a piece P of T in one interval box, for
  // each of its up to four faces). A family's pieces are kept in clipping order.
  struct Piece {
    std::int32_t face, body;
    std::int32_t node[3];
    double w[3];
    double area() const { return w[0] + w[1] + w[2]; }  // |P| (smoothed: ∫_P φ): the weights' sum
  };
  using Raw = std::vector<Piece>;
  // The rigid fixed bodies' pieces of one family, clipped once, and what never changes about
  // them: their faces (sorted), each face's fixed-body area Σ_fixed |V ∩ T| and each piece's
  // index among those faces. Each step then handles them per face, not per piece.
  struct Fixed {
    Raw raw;
    std::vector<std::int32_t> face, local;
    std::vector<double> area;
    std::vector<std::int32_t> body;  // per face: the one fixed body on it, kSeveral for more
  };
  static constexpr std::int32_t kSeveral = -1, kUnseen = -2;  // FaceSolid::body's marks
  // The touched faces of one family (sorted by index), the slot of each moving piece's face and
  // of each fixed face: per-face sums are then one pass over the pieces into slot-indexed
  // arrays, with no reordering of the pieces.
  struct Faces {
    std::vector<std::int32_t> face;
    std::vector<double> area;            // Σ |V ∩ T| of the face
    std::vector<double> elastic_area;    // the same over elastic bodies' T (m_any_rigid only)
    // The one body whose pieces cover the face, kSeveral where pieces of more than one do (its
    // ū_s is their mean); empty with one body (FaceSolid::body).
    std::vector<std::int32_t> body;
    std::vector<std::int32_t> slot_moving;
    std::vector<std::int32_t> slot_fixed_face;  // per face of Fixed::face
    const Fixed* fixed = nullptr;
    const Raw* moving = nullptr;
    double total_area = 0;
    mutable std::vector<double> sum;     // scratch: per-face sums in fill() and reaction()
    std::vector<std::int32_t> moving_face;  // scratch of gather(): the moving bodies' faces
  };
  // One family's clipping: its face boxes, or smoothed its interval boxes.
  struct Family {
    FaceBoxes faces;      // the faces and their control volumes
    SmoothBoxes smooth;   // the smoothed footprint's intervals (none when ε = 0)
    EdgeIndex ix, iy;     // box lookup of the boxes clipped against
    Family(const FaceBoxes& f, double smoothing);
    Family(const Family&) = delete;  // ix, iy point into this family's edges
    Family& operator=(const Family&) = delete;
    bool smoothed() const { return !smooth.ax.face.empty(); }
    const FaceBoxes& clip_boxes() const { return smoothed() ? smooth.boxes : faces; }
  };
  void clip_body(const Family& fam, int b, const std::vector<double>& x, Raw& raw) const;
  struct Scratch {  // per face of a family: -1, or its slot while gather() or index_fixed() runs
    std::vector<std::int32_t> slot;
  };
  static void touched_faces(const Raw& raw, std::vector<std::int32_t>& slot,
                            std::vector<std::int32_t>& face);
  static void index_fixed(Fixed& f, Scratch& s);
  void gather(const Fixed& fixed, const Raw& moving, Faces& p, Scratch& s);
  bool fixed_at_rest(const proto::SolidState& state) const;
  void fill(const Family& fam, const Faces& p, const proto::SolidState& state, int component,
            bool fixed_rest, proto::FaceSolid& out) const;

  const proto::BodyMeshes& m_meshes;
  Family m_uf, m_vf;
  // What each family's thread writes starts a cache line of its own: a piece appended to one
  // family's list must not invalidate the line holding the other's (the two threads would
  // hand it back and forth at every piece).
  static constexpr std::size_t kLine = 64;
  alignas(kLine) Fixed m_fixed_u;  // rigid fixed bodies' pieces, clipped once
  alignas(kLine) Fixed m_fixed_v;
  alignas(kLine) Raw m_raw_u;
  alignas(kLine) Raw m_raw_v;
  alignas(kLine) Faces m_u;
  alignas(kLine) Faces m_v;
  alignas(kLine) Scratch m_scratch_u;
  alignas(kLine) Scratch m_scratch_v;
  bool m_fixed_done = false;  // set after both threads are done
  // Some body is rigid (kind 1 or 2, or kind 0 with BodyMesh::rigid): FaceSolid::elastic is
  // sent (protocol version 8), else left empty.
  bool m_any_rigid = false;
  bool deforms(int b) const {
    return m_meshes.bodies[b].kind == proto::BodyKind::elastic && m_meshes.bodies[b].rigid == 0;
  }
  bool m_threads = false;  // the two families on two threads (more than one core)
};

}  // namespace coupler
