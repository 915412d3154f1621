// Peskin-delta interpolation and spreading on the staggered grid (see ib.hpp).
#include "ib.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.hpp"
#include "sorted_marks.hpp"

namespace coupler {

double peskin4(double r) {
  const double a = std::abs(r);
  if (a <= 1) return (3 - 2 * a + std::sqrt(1 + 4 * a - 4 * a * a)) / 8;
  if (a <= 2) return (5 - 2 * a - std::sqrt(std::max(0.0, -7 + 12 * a - 4 * a * a))) / 8;
  return 0;
}

void peskin4_weights(double r, double w[4]) {
  const double q = std::sqrt(1 + 4 * r - 4 * r * r);  // in [1, √2] for r in [0, 1]
  w[0] = (3 - 2 * r - q) / 8;
  w[1] = (3 - 2 * r + q) / 8;
  w[2] = (1 + 2 * r + q) / 8;
  w[3] = (1 + 2 * r - q) / 8;
}

namespace {
// ⌊s⌋ for |s| within int's range, without a call to floor (not inlined on the baseline x86-64).
inline int floor_int(double s) {
  const int i = static_cast<int>(s);
  return i - (s < i);
}

// Spacings within this fraction of their mean count as equal: round-off of the face coordinates,
// not a stretching.
constexpr double kUniform = 1e-9;

bool uniform(const std::vector<double>& f, double& h) {
  const int n = static_cast<int>(f.size()) - 1;
  h = (f[n] - f[0]) / n;
  for (int i = 0; i < n; ++i)
    if (std::abs(f[i + 1] - f[i] - h) > kUniform * h) return false;
  return true;
}

// The `width` face indices from i0 along a direction of n faces: wrapped once and then stepped
// (an integer division per face would cost more than the kernel's arithmetic), or −1 outside a
// bounded direction.
void face_run(int i0, int n, bool periodic, int width, int* out) {
  if (periodic) {
    int i = i0 % n;
    if (i < 0) i += n;
    for (int k = 0; k < width; ++k, i = i + 1 == n ? 0 : i + 1) out[k] = i;
  } else {
    for (int k = 0; k < width; ++k) out[k] = (i0 + k < 0 || i0 + k >= n) ? -1 : i0 + k;
  }
}

}  // namespace

FeedbackIB::FeedbackIB(const proto::GridInfo& g) {
  if (!uniform(g.x_face, m_hx) || !uniform(g.y_face, m_hy))
    fsi::fail("fibers need a uniform fluid grid (the delta function's moment conditions hold on "
              "a uniform grid only); this grid is stretched");
  m_lx = g.x_face.back() - g.x_face.front();
  m_ly = g.y_face.back() - g.y_face.front();
  // u-faces at (x_face[i], y_centre[j]); v-faces at (x_centre[i], y_face[j]).
  m_u.ni = g.periodic_x ? g.nx : g.nx + 1, m_u.nj = g.ny;
  m_u.x0 = g.x_face[0], m_u.y0 = g.y_face[0] + 0.5 * m_hy;
  m_v.ni = g.nx, m_v.nj = g.periodic_y ? g.ny : g.ny + 1;
  m_v.x0 = g.x_face[0] + 0.5 * m_hx, m_v.y0 = g.y_face[0];
  for (Family* f : {&m_u, &m_v}) {
    f->px = g.periodic_x != 0, f->py = g.periodic_y != 0;
    // One slot past the faces: `outside` (see Family).
    const std::size_t n = static_cast<std::size_t>(f->ni) * f->nj + 1;
    f->value.assign(n, 0.0), f->has_value.assign(n, 0), f->force.assign(n, 0.0);
    f->mark.assign(n, 0);
    f->has_value.back() = 1;
  }
}

void FeedbackIB::kernel(const Family& f, double X, double Y, std::int32_t idx[16], double w[16]) const {
  const double sx = (X - f.x0) / m_hx, sy = (Y - f.y0) / m_hy;
  const int i0 = floor_int(sx) - 1, j0 = floor_int(sy) - 1;
  double wx[4], wy[4];
  int ii[4], jj[4];
  peskin4_weights(sx - (i0 + 1), wx);
  peskin4_weights(sy - (j0 + 1), wy);
  face_run(i0, f.ni, f.px, 4, ii);
  face_run(j0, f.nj, f.py, 4, jj);
  const std::int32_t outside = f.ni * f.nj;
  for (int b = 0; b < 4; ++b) {
    const std::int32_t row = jj[b] < 0 ? -1 : f.ni * jj[b];
    for (int a = 0; a < 4; ++a) {
      idx[4 * b + a] = (ii[a] < 0 || row < 0) ? outside : ii[a] + row;
      w[4 * b + a] = wx[a] * wy[b];
    }
  }
}

// Each face is marked once and listed; where the marks lie in a narrow index range (the faces of a
// fiber layer in a band of rows) the sorted list is read off them, else the list is sorted (fibers
// far apart in y, or across a periodic y boundary): the cost follows the footprint, not the grid.
void FeedbackIB::stencil(const std::vector<std::vector<double>>& markers, int margin,
                         std::vector<std::int32_t>& u_faces, std::vector<std::int32_t>& v_faces) {
  const int width = 4 + 2 * margin;
  std::vector<int> cols(static_cast<std::size_t>(width)), rows(static_cast<std::size_t>(width));
  for (auto [f, out] : {std::pair{&m_u, &u_faces}, std::pair{&m_v, &v_faces}}) {
    // The windows' lower-left cells, one per run of markers in the same cell. Markers move far
    // less than a cell per step, so most steps find the windows, and so the faces, of the last
    // call: then its list is the answer.
    auto& cells = f->window_scratch;
    cells.clear();
    for (const auto& x : markers) {
      for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
        const double sx = (x[m] - f->x0) / m_hx, sy = (x[m + 1] - f->y0) / m_hy;
        // floor_int needs int's range; a marker this far off is lost anyway.
        if (!(std::abs(sx) < kFarCells && std::abs(sy) < kFarCells))
          fsi::fail("fiber marker at ({}, {}) is not finite or far outside the fluid grid", x[m],
                    x[m + 1]);
        const int ic = floor_int(sx), jc = floor_int(sy);
        const std::size_t n = cells.size();
        if (m > 0 && cells[n - 2] == ic && cells[n - 1] == jc) continue;
        cells.push_back(ic), cells.push_back(jc);
      }
      cells.push_back(kFiberEnd), cells.push_back(kFiberEnd);
    }
    if (margin == f->window_margin && cells == f->windows) {
      *out = f->window_faces;
      continue;
    }
    out->clear();
    std::int32_t lo = std::numeric_limits<std::int32_t>::max(), hi = -1;
    for (std::size_t w = 0; w < cells.size(); w += 2) {
      const int ic = cells[w], jc = cells[w + 1];
      if (ic == kFiberEnd) continue;
      face_run(ic - 1 - margin, f->ni, f->px, width, cols.data());
      face_run(jc - 1 - margin, f->nj, f->py, width, rows.data());
      for (const int b : rows) {
        if (b < 0) continue;
        for (const int a : cols) {
          if (a < 0) continue;
          const std::int32_t k = a + f->ni * b;
          if (f->mark[k]) continue;
          f->mark[k] = 1;
          out->push_back(k);
          lo = std::min(lo, k), hi = std::max(hi, k);
        }
      }
    }
    sort_marked(*out, lo, hi, [f](std::int32_t k) { return f->mark[k] != 0; });
    for (const std::int32_t k : *out) f->mark[k] = 0;
    f->windows.swap(cells);
    f->window_margin = margin;
    f->window_faces = *out;
  }
}

void FeedbackIB::store_samples(const std::vector<std::int32_t>& u_faces, const std::vector<double>& u,
                               const std::vector<std::int32_t>& v_faces, const std::vector<double>& v) {
  for (auto [f, idx, val] : {std::tuple{&m_u, &u_faces, &u}, std::tuple{&m_v, &v_faces, &v}}) {
    if (idx->size() != val->size())
      fsi::fail("protocol error: {} velocity samples for {} faces", val->size(), idx->size());
    std::fill(f->has_value.begin(), f->has_value.end() - 1, 0);  // `outside` keeps its 1
    for (std::size_t k = 0; k < idx->size(); ++k) {
      f->value[(*idx)[k]] = (*val)[k];
      f->has_value[(*idx)[k]] = 1;
    }
  }
}

void FeedbackIB::kernels(const std::vector<double>& x) const {
  if (x == m_kernel_x) return;
  const std::size_t markers = x.size() / 2;
  m_idx.resize(32 * markers), m_w.resize(32 * markers);
  for (std::size_t m = 0; m < markers; ++m) {
    if (!(std::abs(x[2 * m] - m_u.x0) < kFarCells * m_hx &&
          std::abs(x[2 * m + 1] - m_v.y0) < kFarCells * m_hy))
      fsi::fail("fiber marker at ({}, {}) is not finite or far outside the fluid grid", x[2 * m],
                x[2 * m + 1]);
    for (int c = 0; c < 2; ++c)
      kernel(c == 0 ? m_u : m_v, x[2 * m], x[2 * m + 1], &m_idx[32 * m + 16 * c],
             &m_w[32 * m + 16 * c]);
  }
  m_kernel_x = x;
}

void FeedbackIB::interpolate(const std::vector<double>& x, std::vector<double>& u) const {
  kernels(x);
  u.assign(x.size(), 0.0);
  for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
    for (int c = 0; c < 2; ++c) {
      const Family& f = c == 0 ? m_u : m_v;
      const std::int32_t* idx = &m_idx[16 * m + 16 * c];
      const double* w = &m_w[16 * m + 16 * c];
      double s = 0;
      char sampled = 1;
      for (int k = 0; k < 16; ++k) {
        sampled &= f.has_value[idx[k]];
        s += w[k] * f.value[idx[k]];
      }
      if (!sampled)
        fsi::fail(
            "fiber marker at ({}, {}) moved beyond the sampled stencil in one step "
            "(more than a grid cell): reduce dt",
            x[m], x[m + 1]);
      u[m + c] = s;
    }
  }
}

void FeedbackIB::spread(const std::vector<double>& x, const std::vector<double>& F, double ds) {
  kernels(x);
  const std::size_t last = x.size() - 2;
  for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
    const double scale = -(m == 0 || m == last ? 0.5 * ds : ds) / (m_hx * m_hy);
    for (int c = 0; c < 2; ++c) {
      double* force = (c == 0 ? m_u : m_v).force.data();
      const std::int32_t* idx = &m_idx[16 * m + 16 * c];
      const double* w = &m_w[16 * m + 16 * c];
      const double s = scale * F[m + c];
      for (int k = 0; k < 16; ++k) force[idx[k]] += s * w[k];
    }
  }
}

// Every face a spread() touched lies in the stencil of its markers (the same 4 × 4 windows), so
// the stencil's list, in index order, is read for the forces; faces whose force is exactly zero
// carry nothing and are left out.
void FeedbackIB::take_spread(const std::vector<std::int32_t>& u_faces,
                             const std::vector<std::int32_t>& v_faces, proto::FaceForce& u,
                             proto::FaceForce& v) {
  for (auto [f, faces, out] : {std::tuple{&m_u, &u_faces, &u}, std::tuple{&m_v, &v_faces, &v}}) {
    f->force.back() = 0;  // `outside`: what the kernels put beyond a wall, dropped
    out->index.clear();
    out->force.clear();
    for (const std::int32_t k : *faces) {
      if (f->force[k] == 0) continue;
      out->index.push_back(k);
      out->force.push_back(f->force[k]);
      f->force[k] = 0;
    }
#ifndef NDEBUG
    // Every face spread to was in the list (the stencil of the spread markers): none kept a force.
    for (std::size_t k = 0; k + 1 < f->force.size(); ++k) FSI_ASSERT(f->force[k] == 0);
#endif
  }
}

}  // namespace coupler
