// Spatial-hash cell list (see cell_list.hpp): counting sort of the points into hash buckets of
// square cells, rebuilt every step without allocation once the largest count has been seen.
#include "cell_list.hpp"

namespace fiber {

void CellList::build(std::span<const double> x, double cell) {
  const std::size_t n = x.size() / 2;
  std::size_t buckets = 16;
  while (buckets < 2 * n) buckets *= 2;
  m_mask = buckets - 1;
  m_inv_cell = 1.0 / cell;
  m_cx.resize(n);
  m_cy.resize(n);
  m_sorted.resize(n);
  m_start.assign(buckets + 1, 0);
  m_fill.resize(buckets);
  for (std::size_t i = 0; i < n; ++i) {
    m_cx[i] = static_cast<std::int64_t>(std::floor(x[2 * i] * m_inv_cell));
    m_cy[i] = static_cast<std::int64_t>(std::floor(x[2 * i + 1] * m_inv_cell));
    ++m_start[bucket(m_cx[i], m_cy[i]) + 1];
  }
  for (std::size_t b = 0; b < buckets; ++b) m_start[b + 1] += m_start[b];
  for (std::size_t b = 0; b < buckets; ++b) m_fill[b] = m_start[b];
  for (std::size_t i = 0; i < n; ++i) m_sorted[m_fill[bucket(m_cx[i], m_cy[i])]++] = i;
}

}  // namespace fiber
