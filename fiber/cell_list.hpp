// Neighbour search for fiber-fiber repulsion: a spatial hash of square cells of side >= cutoff.
// build() sorts the markers into hash buckets (counting sort, O(markers)); for_each_pair()
// visits every pair closer than the cutoff once, looking only into the 3x3 cells around each
// marker, so the cost grows linearly with the marker count, not with its square.
#pragma once

#include <algorithm>
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
  // (cutoff <= cell), dx = x_i - x_j, and j >= first_partner(i): points of one fiber are
  // consecutive, so first_partner(i) = the end of i's fiber skips a fiber's own markers without
  // looking at them (a bucket lists its points in increasing order).
  template <class F, class G>
  void for_each_pair(std::span<const double> x, double cutoff, G&& first_partner, F&& f) const;
  template <class F>
  void for_each_pair(std::span<const double> x, double cutoff, F&& f) const {
    for_each_pair(x, cutoff, [](std::size_t i) { return i + 1; }, f);
  }

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

template <class F, class G>
void CellList::for_each_pair(std::span<const double> x, double cutoff, G&& first_partner, F&& f) const {
  const std::size_t n = m_cx.size();
  const double c2 = cutoff * cutoff;
  // The neighbour buckets and where their candidates start depend only on the cell and on
  // first_partner(i): consecutive markers of a fiber mostly share both, so they are reused.
  std::array<std::size_t, 9> first{}, last{};
  int n_buckets = 0;
  std::int64_t cx = 0, cy = 0;
  std::size_t j0 = 0;
  bool is_cached = false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t ji = std::max(first_partner(i), i + 1);
    if (!is_cached || m_cx[i] != cx || m_cy[i] != cy || ji != j0) {
      cx = m_cx[i];
      cy = m_cy[i];
      j0 = ji;
      is_cached = true;
      // The 3x3 neighbour cells may share buckets: list each bucket once.
      std::array<std::size_t, 9> seen{};
      n_buckets = 0;
      for (int oy = -1; oy <= 1; ++oy) {
        for (int ox = -1; ox <= 1; ++ox) {
          const std::size_t b = bucket(cx + ox, cy + oy);
          bool is_new = true;
          for (int q = 0; q < n_buckets; ++q) is_new = is_new && seen[q] != b;
          if (!is_new) continue;
          seen[n_buckets] = b;
          // first entry with j >= j0 (a bucket lists its points in increasing order)
          std::size_t lo = m_start[b], hi = m_start[b + 1];
          while (lo < hi) {
            const std::size_t mid = (lo + hi) / 2;
            if (m_sorted[mid] < j0) lo = mid + 1;
            else hi = mid;
          }
          first[n_buckets] = lo;
          last[n_buckets] = m_start[b + 1];
          ++n_buckets;
        }
      }
    }
    const double xi = x[2 * i], yi = x[2 * i + 1];
    for (int q = 0; q < n_buckets; ++q) {
      for (std::size_t p = first[q]; p < last[q]; ++p) {
        const std::size_t j = m_sorted[p];
        const double dx = xi - x[2 * j], dy = yi - x[2 * j + 1];
        const double r2 = dx * dx + dy * dy;
        if (r2 < c2) f(i, j, dx, dy, r2);
      }
    }
  }
}

}  // namespace fiber
