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
    // One period off at most for a marker near the domain; the division only beyond.
    int i = i0 < 0 ? i0 + n : i0 >= n ? i0 - n : i0;
    if (i < 0 || i >= n) i = ((i0 % n) + n) % n;
    for (int k = 0; k < width; ++k, i = i + 1 == n ? 0 : i + 1) out[k] = i;
  } else {
    for (int k = 0; k < width; ++k) out[k] = (i0 + k < 0 || i0 + k >= n) ? -1 : i0 + k;
  }
}

// face_run for the four faces of a kernel, inlined for the common case of a kernel inside the
// direction's faces.
inline void kernel_run(int i0, int n, bool periodic, int* out) {
  if (i0 >= 0 && i0 + 3 < n) {
    for (int k = 0; k < 4; ++k) out[k] = i0 + k;
  } else {
    face_run(i0, n, periodic, 4, out);
  }
}

}  // namespace

bool FeedbackIB::uniform_grid(const proto::GridInfo& g) {
  double h;
  return uniform(g.x_face, h) && uniform(g.y_face, h);
}

FeedbackIB::FeedbackIB(const proto::GridInfo& g) {
  if (!uniform(g.x_face, m_hx) || !uniform(g.y_face, m_hy))
    fsi::fail("fibers need a uniform fluid grid (the delta function's moment conditions hold on "
              "a uniform grid only); this grid is stretched");
  m_ihx = 1 / m_hx, m_ihy = 1 / m_hy;
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

// The weights along one direction of a point at s (in cells from the family's first face) and
// the first of its four faces.
static inline int axis_weights(double s, double w[4]) {
  const int i0 = floor_int(s) - 1;
  peskin4_weights(s - (i0 + 1), w);
  return i0;
}

// Each family's weights along x and y, face columns and row offsets. (One direction at a time,
// in registers: computing the four square roots as a packed pair went through the stack, and
// the pair's reload stalled on the two stores before it.)
void FeedbackIB::kernel(double X, double Y, Kernel k[2]) const {
  for (int c = 0; c < 2; ++c) {
    const Family& f = c == 0 ? m_u : m_v;
    Kernel& K = k[c];
    const int i0 = axis_weights((X - f.x0) * m_ihx, K.wx);
    const int j0 = axis_weights((Y - f.y0) * m_ihy, K.wy);
    kernel_run(i0, f.ni, f.px, K.col);
    kernel_run(j0, f.nj, f.py, K.row);
    K.inner = true;
    for (int d = 0; d < 4; ++d) {
      K.inner &= K.col[d] >= 0 && K.row[d] >= 0;
      if (K.row[d] >= 0) K.row[d] *= f.ni;
    }
  }
}

// Face (a, b) of a kernel: its flat index, or `outside` beyond a bounded side.
inline std::int32_t FeedbackIB::face(const Family& f, const Kernel& K, int a, int b) {
  return K.inner || (K.col[a] >= 0 && K.row[b] >= 0) ? K.col[a] + K.row[b] : f.ni * f.nj;
}

// Σ_b φ_y,b Σ_a φ_x,a u(a, b) over the kernel's faces, and whether each was sampled. (The
// arrays' pointers are taken once: the compiler cannot know the stores of scatter() leave them.)
inline double FeedbackIB::gather(const Family& f, const Kernel& K, char& sampled) {
  const double* value = f.value.data();
  const char* has = f.has_value.data();
  double s = 0;
  for (int b = 0; b < 4; ++b) {
    double t = 0;
    for (int a = 0; a < 4; ++a) {
      const std::int32_t id = K.inner ? K.col[a] + K.row[b] : face(f, K, a, b);
      sampled &= has[id];
      t += K.wx[a] * value[id];
    }
    s += K.wy[b] * t;
  }
  return s;
}

// force(a, b) += φ_x,a (φ_y,b t) on the kernel's faces.
inline void FeedbackIB::scatter(Family& f, const Kernel& K, double t) {
  double* force = f.force.data();
  for (int b = 0; b < 4; ++b) {
    const double tb = K.wy[b] * t;
    for (int a = 0; a < 4; ++a)
      force[K.inner ? K.col[a] + K.row[b] : face(f, K, a, b)] += K.wx[a] * tb;
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
        const double sx = (x[m] - f->x0) * m_ihx, sy = (x[m + 1] - f->y0) * m_ihy;
        // floor_int needs int's range; a marker this far off is lost anyway. The same products as
        // kernel()'s, so that a marker on a face line falls in the same cell in both.
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

void FeedbackIB::check_marker(double X, double Y) const {
  if (!(std::abs(X - m_u.x0) < kFarCells * m_hx && std::abs(Y - m_v.y0) < kFarCells * m_hy))
    fsi::fail("fiber marker at ({}, {}) is not finite or far outside the fluid grid", X, Y);
}

void FeedbackIB::unsampled(double X, double Y) {
  fsi::fail("fiber marker at ({}, {}) moved beyond the sampled stencil in one step (more than a "
            "grid cell): reduce dt",
            X, Y);
}

void FeedbackIB::interpolate(const std::vector<double>& x, std::vector<double>& u) const {
  u.assign(x.size(), 0.0);
  Kernel k[2];
  for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
    check_marker(x[m], x[m + 1]);
    kernel(x[m], x[m + 1], k);
    char sampled = 1;
    for (int c = 0; c < 2; ++c) u[m + c] = gather(c == 0 ? m_u : m_v, k[c], sampled);
    if (!sampled) unsampled(x[m], x[m + 1]);
  }
}

void FeedbackIB::spread(const std::vector<double>& x, const std::vector<double>& F, double ds) {
  const std::size_t last = x.size() - 2;
  Kernel k[2];
  for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
    check_marker(x[m], x[m + 1]);
    kernel(x[m], x[m + 1], k);
    const double scale = -(m == 0 || m == last ? 0.5 * ds : ds) / (m_hx * m_hy);
    for (int c = 0; c < 2; ++c) scatter(c == 0 ? m_u : m_v, k[c], scale * F[m + c]);
  }
}

void FeedbackIB::feedback(const std::vector<double>& x, const std::vector<double>& x_old,
                          double kappa, double dt, double ds, std::vector<double>& F) {
  if (x_old.size() != x.size())
    fsi::fail("fiber feedback: {} marker coordinates now, {} before", x.size(), x_old.size());
  F.resize(x.size());
  const std::size_t last = x.size() - 2;
  Kernel k[2];
  for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
    check_marker(x[m], x[m + 1]);
    kernel(x[m], x[m + 1], k);
    const double scale = -(m == 0 || m == last ? 0.5 * ds : ds) / (m_hx * m_hy);
    char sampled = 1;
    for (int c = 0; c < 2; ++c) {
      Family& f = c == 0 ? m_u : m_v;
      const double U = gather(f, k[c], sampled);
      F[m + c] = kappa * (dt * U - (x[m + c] - x_old[m + c]));
      scatter(f, k[c], scale * F[m + c]);
    }
    if (!sampled) unsampled(x[m], x[m + 1]);
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
