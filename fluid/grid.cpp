// Face and centre coordinates, ghost mirroring and the stencil coefficients of the MAC grid.
#include "grid.hpp"

#include <algorithm>
#include <cmath>

#include "error.hpp"

namespace fluid {

namespace {

// The ratio r > 0 with h (r + r^2 + ... + r^n) = L: n cells that cover L, the first r h wide,
// each r times its predecessor. Bisection on log r: the sum grows monotonically with r.
double growth_for(int n, double L, double h) {
  auto covered = [&](double r) {
    double w = h, sum = 0;
    for (int k = 0; k < n; ++k) w *= r, sum += w;
    return sum;
  };
  double lo = std::log(1e-3), hi = std::log(10.0);
  if (covered(std::exp(hi)) < L) return std::exp(hi);
  if (covered(std::exp(lo)) > L) return std::exp(lo);
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    (covered(std::exp(mid)) < L ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

double abruptness(double r) { return std::max(r, 1.0 / r); }

}  // namespace

double BandLayout::worst() const {
  return std::max(below > 0 ? abruptness(growth_below) : 1.0, above > 0 ? abruptness(growth_above) : 1.0);
}

BandLayout band_layout(const AxisSpec& s) {
  const double end = s.origin + s.length;
  if (!(s.band_from >= s.origin && s.band_to <= end && s.band_from < s.band_to))
    fsi::fail("the band [{}, {}] must lie within [{}, {}] and have from < to", s.band_from,
              s.band_to, s.origin, end);
  if (s.band_cells < 1 || s.band_cells > s.cells)
    fsi::fail("the band's cells ({}) must be between 1 and the direction's cells ({})",
              s.band_cells, s.cells);
  const double h = (s.band_to - s.band_from) / s.band_cells;
  const double room_below = s.band_from - s.origin, room_above = end - s.band_to;
  const int outside = s.cells - s.band_cells;
  // A side without room takes no cell; a side with room needs at least one.
  const int min_below = room_below > 0 ? 1 : 0, min_above = room_above > 0 ? 1 : 0;
  if (min_below + min_above > outside)
    fsi::fail("the band [{}, {}] leaves {} cell(s) for the {} side(s) outside it", s.band_from,
              s.band_to, outside, min_below + min_above);
  BandLayout best;
  double best_worst = INFINITY;
  for (int below = min_below; below <= outside - min_above; ++below) {
    const int above = outside - below;
    if ((room_below == 0 && below > 0) || (room_above == 0 && above > 0)) continue;
    BandLayout l{below, above, below > 0 ? growth_for(below, room_below, h) : 1.0,
                 above > 0 ? growth_for(above, room_above, h) : 1.0};
    if (l.worst() < best_worst) best_worst = l.worst(), best = l;
  }
  return best;
}

Axis::Axis(const AxisSpec& s) : m_n(s.cells + s.sponge_cells), m_periodic(s.periodic) {
  if (s.cells < 1 || !(s.length > 0))
    fsi::fail("fluid::Axis: an axis needs cells >= 1 and a length > 0, got {} cells over {}",
              s.cells, s.length);
  const int n = m_n;
  std::vector<double> f(n + 1);
  for (int i = 0; i <= s.cells; ++i) {
    const double xi = double(i) / s.cells;
    double x = s.length * xi;
    if (s.tanh_beta > 0) {
      x = 0.5 * s.length * (1.0 + std::tanh(s.tanh_beta * (2 * xi - 1)) / std::tanh(s.tanh_beta));
    }
    f[i] = s.origin + x;
  }
  if (s.band_cells > 0) {
    // Below the band, cells widen by growth_below per cell away from it, above by growth_above;
    // the band's faces are even. The ends and the band's edges are set exactly.
    const BandLayout l = band_layout(s);
    const double h = (s.band_to - s.band_from) / s.band_cells;
    const int b0 = l.below, b1 = l.below + s.band_cells;
    for (int i = 0; i <= s.band_cells; ++i) f[b0 + i] = s.band_from + i * h;
    double w = h;
    for (int i = b0 - 1; i >= 0; --i) w *= l.growth_below, f[i] = f[i + 1] - w;
    w = h;
    for (int i = b1 + 1; i <= s.cells; ++i) w *= l.growth_above, f[i] = f[i - 1] + w;
    f[b0] = s.band_from, f[b1] = s.band_to;
  }
  f[0] = s.origin;
  f[s.cells] = s.origin + s.length;
  double w = f[s.cells] - f[s.cells - 1];
  for (int i = s.cells + 1; i <= n; ++i) {
    w *= s.sponge_ratio;
    f[i] = f[i - 1] + w;
  }
  m_sponge_start = s.sponge_cells > 0 ? s.cells : n;
  m_uniform = s.tanh_beta <= 0 && s.band_cells == 0 &&
              (s.sponge_cells == 0 || s.sponge_ratio == 1.0);

  // Widths with two ghost cells per side: mirrored, or wrapped around when periodic.
  auto width = [&](int i) {
    if (i >= 0 && i < n) return f[i + 1] - f[i];
    if (m_periodic) {
      const int k = ((i % n) + n) % n;
      return f[k + 1] - f[k];
    }
    const int k = i < 0 ? -1 - i : 2 * n - 1 - i;  // mirror image
    return f[k + 1] - f[k];
  };
  m_face.assign(n + 3, 0);
  m_centre.assign(n + 2, 0);
  for (int i = 0; i <= n; ++i) m_face[i + 1] = f[i];
  m_face[0] = f[0] - width(-1);
  m_face[n + 2] = f[n] + width(n);
  for (int i = -1; i <= n; ++i) m_centre[i + 1] = 0.5 * (face(i) + face(i + 1));

  m_w.assign(n + 2, 0);
  m_wi.assign(n + 2, 0);
  m_ci.assign(n + 2, 0);
  for (int i = -1; i <= n; ++i) {
    m_w[i + 1] = width(i);
    m_wi[i + 1] = 1.0 / width(i);
    // centre(i+1) - centre(i-1) = (w(i-1) + 2 w(i) + w(i+1)) / 2
    m_ci[i + 1] = 4.0 / (width(i - 1) + 2 * width(i) + width(i + 1));
  }
  m_di.assign(n + 3, 0);
  m_wlo.assign(n + 3, 0);
  m_whi.assign(n + 3, 0);
  for (int i = -1; i <= n + 1; ++i) {
    const double a = width(i - 1), b = width(i);
    m_di[i + 1] = 2.0 / (a + b);
    m_wlo[i + 1] = b / (a + b);
    m_whi[i + 1] = a / (a + b);
  }
}

}  // namespace fluid
