// Listing the marked entries of a per-face array in index order at a cost that follows the
// footprint, not the grid.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace coupler {

// Sorts `list`, whose entries lie in [lo, hi], by a least-significant-digit radix sort of
// k - lo: one counting pass and one stable scatter per digit of kRadixBits, as many digits as
// hi - lo needs (one up to 2 048 faces, two up to 4 million, three beyond). Linear in the
// list, where a comparison sort is n log n with a mispredicted branch per comparison.
inline void radix_sort(std::vector<std::int32_t>& list, std::int32_t lo, std::int32_t hi) {
  constexpr int kRadixBits = 11;
  constexpr std::uint32_t kMask = (1u << kRadixBits) - 1;
  thread_local std::vector<std::int32_t> spare;
  spare.resize(list.size());
  // Keys k - lo as unsigned (no signed overflow); shifts stay below the key's 32 bits.
  const std::uint32_t base = static_cast<std::uint32_t>(lo);
  const std::uint32_t span = static_cast<std::uint32_t>(hi) - base;
  for (int shift = 0; shift < 32 && (shift == 0 || (span >> shift) != 0); shift += kRadixBits) {
    std::array<std::uint32_t, kMask + 1> start{};
    for (const std::int32_t k : list) ++start[((std::uint32_t(k) - base) >> shift) & kMask];
    std::uint32_t sum = 0;
    for (auto& s : start) {
      const std::uint32_t n = s;
      s = sum;
      sum += n;
    }
    for (const std::int32_t k : list)
      spare[start[((std::uint32_t(k) - base) >> shift) & kMask]++] = k;
    list.swap(spare);
  }
}

// `list` holds exactly the indices k in [lo, hi] with marked(k), each once, in any order (the
// scan relies on no other marks in the range); on return it is sorted. Where the range is at most
// kScanFactor times the list (a body or a fiber layer covers a band of rows) the list is read off
// the marks by one scan of the range, else radix-sorted (bodies far apart, as the vocal folds on
// the two walls: the range is then the whole grid).
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
  radix_sort(list, lo, hi);
}

}  // namespace coupler
