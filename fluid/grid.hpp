// The fluid's fixed Cartesian grid: cell faces and centres along x and y, each direction uniform,
// tanh-clustered towards both ends (y), uniform in a band with cells growing geometrically away
// from it (either direction), or uniform with a geometrically stretched outlet sponge appended at
// x = x_max. Holds the precomputed inverse spacings and interpolation weights that the
// staggered (MAC) stencils use, ghost cells included.
#pragma once

#include <vector>

namespace fluid {

// How one direction is laid out.
struct AxisSpec {
  int cells = 0;             // cells in [origin, origin + length]
  double length = 0;
  double origin = 0;
  bool periodic = false;
  double tanh_beta = 0;      // > 0: faces clustered towards both ends, x = L/2 (1 + tanh(b s)/tanh(b))
  int sponge_cells = 0;      // extra cells appended beyond origin + length ...
  double sponge_ratio = 1;   // ... each this much wider than the previous one
  int band_cells = 0;        // > 0: this many of `cells` evenly over [band_from, band_to], the
  double band_from = 0;      //   others outside it, growing geometrically away from it
  double band_to = 0;
};

// How the cells outside a band are laid out: `below` cells between origin and band_from and
// `above` between band_to and the far end, each `growth_*` times as wide as its neighbour on the
// band's side (the first one growth times the band's spacing), so that every width varies
// smoothly. The split of the outside cells is the one with the smallest largest growth. A growth
// below 1 (outside cells narrower than the band's) is reported as it is.
struct BandLayout {
  double from = 0, to = 0;  // the band's edges (an edge within round-off of an end: that end)
  int below = 0, above = 0;
  double growth_below = 1, growth_above = 1;
  // The largest of the growths and their inverses: how abruptly the widths change.
  double worst() const;
};
// Throws fsi::Error when the band does not fit (outside [origin, origin + length], no cells
// left for a side with room, more band cells than cells, or a band over the whole direction
// with fewer cells than the direction's).
BandLayout band_layout(const AxisSpec& s);

// One direction. Index conventions: cells 0..n-1, faces 0..n (face i is the low side of cell i).
// Stencil arrays also cover one ghost cell on each side: widths w(i) for i in [-1, n], ghost
// cells mirror the first/last cell (or wrap around when periodic).
class Axis {
 public:
  explicit Axis(const AxisSpec& spec);
  int n() const { return m_n; }
  bool periodic() const { return m_periodic; }
  bool uniform() const { return m_uniform; }
  double h() const { return m_w[1]; }  // width of cell 0 (the spacing when uniform)
  double face(int i) const { return m_face[i + 1]; }      // i in [-1, n+1]
  double centre(int i) const { return m_centre[i + 1]; }  // i in [-1, n]
  double lo() const { return face(0); }
  double hi() const { return face(m_n); }
  double length() const { return hi() - lo(); }
  double width(int i) const { return m_w[i + 1]; }         // i in [-1, n]
  // Arrays with offset 1 (index i + 1) for the hot loops:
  const double* wi() const { return m_wi.data() + 1; }   // 1 / width(i), i in [-1, n]
  const double* di() const { return m_di.data() + 1; }   // 1 / (centre(i) - centre(i-1)), i in [-1, n+1]
  const double* ci() const { return m_ci.data() + 1; }   // 2 / (centre(i+1) - centre(i-1)), i in [-1, n]
  // Interpolation from centres i-1, i to face i: weight of centre i-1 (lo) and i (hi).
  const double* wlo() const { return m_wlo.data() + 1; }  // i in [-1, n+1]
  const double* whi() const { return m_whi.data() + 1; }
  int sponge_start() const { return m_sponge_start; }     // first sponge cell (n when none)

 private:
  int m_n;
  bool m_periodic, m_uniform;
  int m_sponge_start;
  std::vector<double> m_face, m_centre, m_w, m_wi, m_di, m_ci, m_wlo, m_whi;
};

class Grid {
 public:
  Grid(const AxisSpec& x, const AxisSpec& y) : m_x(x), m_y(y) {}
  const Axis& x() const { return m_x; }
  const Axis& y() const { return m_y; }
  const Axis& axis(int a) const { return a == 0 ? m_x : m_y; }
  int nx() const { return m_x.n(); }
  int ny() const { return m_y.n(); }
  // Face counts of the coupling index (periodic directions have no duplicate last face).
  int nu() const { return m_x.periodic() ? nx() : nx() + 1; }
  int nv() const { return m_y.periodic() ? ny() : ny() + 1; }

 private:
  Axis m_x, m_y;
};

}  // namespace fluid
