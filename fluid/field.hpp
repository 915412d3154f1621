// A grid field: one contiguous array with one ghost layer on each side, i fastest. The
// staggering (which MAC location it samples) is the owner's business: u has (nx+1) x ny values,
// v nx x (ny+1), p nx x ny.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "error.hpp"

namespace fluid {

struct Field {
  int ni = 0, nj = 0;  // interior extents of the whole grid
  int jlo = 0, jhi = 0;  // the rows this process stores besides its ghosts: [jlo, jhi)
  int sx = 0;          // stride between rows
  std::vector<double> a;

  Field() = default;
  // The whole grid: storage (ni + 2) x (nj + 2).
  Field(int ni_, int nj_) : Field(ni_, nj_, 0, nj_) {}
  // Rows [jlo_, jhi_) of the grid (a slab of the fluid split over ranks) with a ghost row on each
  // side; indices stay the whole grid's.
  Field(int ni_, int nj_, int jlo_, int jhi_)
      : ni(ni_), nj(nj_), jlo(jlo_), jhi(jhi_), sx(ni_ + 2),
        a(std::size_t(ni_ + 2) * (jhi_ - jlo_ + 2), 0.0) {}
  // (i, j) with i in [-1, ni], j in [jlo - 1, jhi] (checked in debug builds)
  double& operator()(int i, int j) {
    FSI_ASSERT(i >= -1 && i <= ni && j >= jlo - 1 && j <= jhi);
    return a[std::size_t(i + 1) + std::size_t(sx) * (j - jlo + 1)];
  }
  double operator()(int i, int j) const {
    FSI_ASSERT(i >= -1 && i <= ni && j >= jlo - 1 && j <= jhi);
    return a[std::size_t(i + 1) + std::size_t(sx) * (j - jlo + 1)];
  }
  // Pointer to element (0, j); valid offsets -1 .. ni.
  double* row(int j) { return a.data() + 1 + std::size_t(sx) * (j - jlo + 1); }
  const double* row(int j) const { return a.data() + 1 + std::size_t(sx) * (j - jlo + 1); }
};

// An index box [i0, i1] x [j0, j1], both ends included; none() is empty and joins anything.
struct Box {
  int i0 = 0, i1 = -1, j0 = 0, j1 = -1;
  static Box none() {
    constexpr int lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
    return {hi, lo, hi, lo};
  }
  bool empty() const { return i0 > i1 || j0 > j1; }
  void join(const Box& o) {
    i0 = std::min(i0, o.i0), i1 = std::max(i1, o.i1);
    j0 = std::min(j0, o.j0), j1 = std::max(j1, o.j1);
  }
};

// Values on a box of grid indices (i fastest), a scratch array that keeps its capacity.
struct Patch {
  Box box;
  int w = 0;
  std::vector<double> v;
  void resize(const Box& b) {
    box = b;
    w = b.i1 - b.i0 + 1;
    v.resize(std::size_t(w) * std::size_t(b.j1 - b.j0 + 1));
  }
  double& operator()(int i, int j) { return v[at(i, j)]; }
  double operator()(int i, int j) const { return v[at(i, j)]; }

 private:
  // Offset of (i, j) in v (checked in debug builds).
  std::size_t at(int i, int j) const {
    FSI_ASSERT(i >= box.i0 && i <= box.i1 && j >= box.j0 && j <= box.j1);
    return std::size_t(i - box.i0) + std::size_t(w) * std::size_t(j - box.j0);
  }
};

// The second row beyond each edge of a slab (rows lo - 2 and hi + 1, ghost columns included),
// which the third-order convection reads across the slab's edges; empty on one rank.
struct OuterRows {
  std::vector<double> below, above;
};

}  // namespace fluid
