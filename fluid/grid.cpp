// Face and centre coordinates, ghost mirroring and the stencil coefficients of the MAC grid.
#include "grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.hpp"

namespace fluid {

namespace {

// The ratio r with h (r + r^2 + ... + r^n) = L: n cells that cover L, the first r h wide, each r
// times its predecessor. Bisection on log r over [1e-3, 10] (the sum grows with r); beyond those
// bounds no smooth layout exists, and the result is 0 or infinity, which BandLayout::worst()
// reports as infinitely abrupt.
double growth_for(int n, double L, double h) {
  auto covered = [&](double r) {
    if (std::abs(r - 1) < 1e-9) return h * n * (1 + 0.5 * (n + 1) * (r - 1));
    return h * r * (std::pow(r, n) - 1) / (r - 1);
  };
  double lo = std::log(1e-3), hi = std::log(10.0);
  if (covered(std::exp(hi)) < L) return std::numeric_limits<double>::infinity();
  if (covered(std::exp(lo)) > L) return 0.0;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (covered(std::exp(mid)) < L ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

double abruptness(double r) {
  return r > 0 ? std::max(r, 1.0 / r) : std::numeric_limits<double>::infinity();
}

}  // namespace

double BandLayout::worst() const {
  return std::max(below > 0 ? abruptness(growth_below) : 1.0,
                  above > 0 ? abruptness(growth_above) : 1.0);
}

BandLayout band_layout(const AxisSpec& s) {
  const double end = s.origin + s.length;
  // Within round-off of an end, the band's edge is that end (no room for cells beyond it).
  const double tol = 1e-9 * s.length;
  if (!(s.band_from >= s.origin - tol && s.band_to <= end + tol && s.band_from < s.band_to))
    fsi::fail("the band [{}, {}] must lie within [{}, {}] and have from < to", s.band_from,
              s.band_to, s.origin, end);
  if (s.band_cells < 1 || s.band_cells > s.cells)
    fsi::fail("the band's cells ({}) must be between 1 and the direction's cells ({})",
              s.band_cells, s.cells);
  BandLayout best;
  best.from = s.band_from - s.origin <= tol ? s.origin : s.band_from;
  best.to = end - s.band_to <= tol ? end : s.band_to;
  const double h = (best.to - best.from) / s.band_cells;
  const double room_below = best.from - s.origin, room_above = end - best.to;
  const int outside = s.cells - s.band_cells;
  if (room_below == 0 && room_above == 0) {
    if (outside > 0)
      fsi::fail(
          "the band [{}, {}] covers the whole direction: its cells must be the "
          "direction's {}, got {}",
          s.band_from, s.band_to, s.cells, s.band_cells);
    return best;
  }
  // A side without room takes no cell; a side with room needs at least one.
  const int min_below = room_below > 0 ? 1 : 0, min_above = room_above > 0 ? 1 : 0;
  if (min_below + min_above > outside)
    fsi::fail("the band [{}, {}] leaves {} cell(s) for the {} side(s) outside it", s.band_from,
              s.band_to, outside, min_below + min_above);
  double best_worst = std::numeric_limits<double>::infinity();
  bool found = false;
  for (int below = min_below; below <= outside - min_above; ++below) {
    const int above = outside - below;
    if ((room_below == 0 && below > 0) || (room_above == 0 && above > 0)) continue;
    BandLayout l = best;
    l.below = below, l.above = above;
    l.growth_below = below > 0 ? growth_for(below, room_below, h) : 1.0;
    l.growth_above = above > 0 ? growth_for(above, room_above, h) : 1.0;
    if (!found || l.worst() < best_worst) best_worst = l.worst(), best = l, found = true;
  }
  FSI_ASSERT(found);
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
    const double h = (l.to - l.from) / s.band_cells;
    const int b0 = l.below, b1 = l.below + s.band_cells;
    for (int i = 0; i <= s.band_cells; ++i) f[b0 + i] = l.from + i * h;
    double w = h;
    for (int i = b0 - 1; i >= 0; --i) w *= l.growth_below, f[i] = f[i + 1] - w;
    w = h;
    for (int i = b1 + 1; i <= s.cells; ++i) w *= l.growth_above, f[i] = f[i - 1] + w;
    f[b0] = l.from, f[b1] = l.to;
  }
  f[0] = s.origin;
  f[s.cells] = s.origin + s.length;
  double w = f[s.cells] - f[s.cells - 1];
  for (int i = s.cells + 1; i <= n; ++i) {
    w *= s.sponge_ratio;
    f[i] = f[i - 1] + w;
  }
  m_sponge_start = s.sponge_cells > 0 ? s.cells : n;
  m_uniform =
      s.tanh_beta <= 0 && s.band_cells == 0 && (s.sponge_cells == 0 || s.sponge_ratio == 1.0);

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
