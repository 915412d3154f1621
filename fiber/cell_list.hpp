// Neighbour search for fiber-fiber repulsion: a spatial hash of square cells of side >= cutoff.
// build() sorts the markers into hash buckets (counting sort, O(markers)); for_each_pair()
// visits every pair closer than the cutoff once, looking only into the 3x3 cells around each
// marker, so the cost grows linearly with the marker count, not with its square.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace fiber {

class CellList {
 public:
  // Sort `count` points x = (x0, y0, x1, y1, ...) into cells of side `cell` (> 0). Reuses its
  // memory: no allocation once it has seen the largest count.
  void build(std::span<const double> x, double cell);

  // Calls f(i, j, dx, dy, r2) for every pair i < j with r2 = |x_i - x_j|^2 < cutoff^2
  // (cutoff <= cell), dx = x_i - x_j.
  template <class F>
  void for_each_pair(std::span<const double> x, double cutoff, F&& f) const;

  std::size_t bucket_count() const { return m_start.empty() ? 0 : m_start.size() - 1; }

 private:
  std::size_t bucket(std::int64_t cx, std::int64_t cy) const {
    const auto h = static_cast<std::uint64_t>(cx) * 73856093u ^ static_cast<std::uint64_t>(cy) * 19349663u;
    return static_cast<std::size_t>((h ^ (h >> 29)) & m_mask);
  }

  double m_inv_cell = 1;
  std::uint64_t m_mask = 0;
  std::vector<std::int64_t> m_cx, m_cy;  // cell of each point
  std::vector<std::size_t> m_start;      // bucket b holds m_sorted[m_start[b] .. m_start[b+1])
  std::vector<std::size_t> m_sorted;     // point indices by bucket
  std::vector<std::size_t> m_fill;
};

template <class F>
void CellList::for_each_pair(std::span<const double> x, double cutoff, F&& f) const {
  const std::size_t n = m_cx.size();
  const double c2 = cutoff * cutoff;
  for (std::size_t i = 0; i < n; ++i) {
    // The 3x3 neighbour cells may share buckets: visit each bucket once.
    std::array<std::size_t, 9> seen{};
    int n_seen = 0;
    for (int oy = -1; oy <= 1; ++oy) {
      for (int ox = -1; ox <= 1; ++ox) {
        const std::size_t b = bucket(m_cx[i] + ox, m_cy[i] + oy);
        bool is_new = true;
        for (int q = 0; q < n_seen; ++q) is_new = is_new && seen[q] != b;
        if (!is_new) continue;
        seen[n_seen++] = b;
        for (std::size_t p = m_start[b]; p < m_start[b + 1]; ++p) {
          const std::size_t j = m_sorted[p];
          if (j <= i) continue;
          const double dx = x[2 * i] - x[2 * j], dy = x[2 * i + 1] - x[2 * j + 1];
          const double r2 = dx * dx + dy * dy;
          if (r2 < c2) f(i, j, dx, dy, r2);
        }
      }
    }
  }
}

}  // namespace fiber
