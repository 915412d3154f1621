// Listing the marked entries of a per-face array in index order at a cost that follows the
// footprint, not the grid.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace coupler {

// `list` holds exactly the indices k in [lo, hi] with marked(k), each once, in any order (the
// scan relies on no other marks in the range); on return it is sorted. Where the range is at most
// kScanFactor times the list (a body or a fiber layer covers a band of rows) the list is read off
// the marks by one scan of the range, else std::sort.
template <class Marked>
void sort_marked(std::vector<std::int32_t>& list, std::int32_t lo, std::int32_t hi,
                 Marked&& marked) {
  constexpr std::int64_t kScanFactor = 8;
  if (list.empty()) return;
  if (std::int64_t(hi) - lo + 1 <= kScanFactor * std::int64_t(list.size())) {
    list.clear();
    for (std::int32_t k = lo; k <= hi; ++k)
      if (marked(k)) list.push_back(k);
    return;
  }
  std::sort(list.begin(), list.end());
}

}  // namespace coupler
