// A grid field: one contiguous array with one ghost layer on each side, i fastest. The
// staggering (which MAC location it samples) is the owner's business: u has (nx+1) x ny values,
// v nx x (ny+1), p nx x ny.
#pragma once

#include <cstddef>
#include <vector>

#include "error.hpp"

namespace fluid {

struct Field {
  int ni = 0, nj = 0;  // interior extents; storage is (ni + 2) x (nj + 2)
  int sx = 0;          // stride between rows
  std::vector<double> a;

  Field() = default;
  Field(int ni_, int nj_)
      : ni(ni_), nj(nj_), sx(ni_ + 2), a(std::size_t(ni_ + 2) * (nj_ + 2), 0.0) {}
  // (i, j) with i in [-1, ni], j in [-1, nj] (checked in debug builds)
  double& operator()(int i, int j) {
    FSI_ASSERT(i >= -1 && i <= ni && j >= -1 && j <= nj);
    return a[std::size_t(i + 1) + std::size_t(sx) * (j + 1)];
  }
  double operator()(int i, int j) const {
    FSI_ASSERT(i >= -1 && i <= ni && j >= -1 && j <= nj);
    return a[std::size_t(i + 1) + std::size_t(sx) * (j + 1)];
  }
  // Pointer to element (0, j); valid offsets -1 .. ni.
  double* row(int j) { return a.data() + 1 + std::size_t(sx) * (j + 1); }
  const double* row(int j) const { return a.data() + 1 + std::size_t(sx) * (j + 1); }
};

}  // namespace fluid
