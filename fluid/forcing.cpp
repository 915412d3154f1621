// The immersed solid's forcing of the fluid (paper Eq. 21) on the predictor u~.
#include "solver.hpp"

namespace fluid {

namespace {
// A face the body covers (alpha = 1 up to the footprint's round-off).
constexpr double kCovered = 1 - 1e-9;
// A face the body only touches (alpha = 0 up to the footprint's round-off: a body's edge on the
// box's edge).
constexpr double kTouched = 1e-9;
}  // namespace

// The relaxation time tau (fluid.forcing_time). The predictor carries the pressure gradient of
// step n, u~ = u^n + dt R (R: convection, diffusion, -grad p^n, body force), so in a steady flow
// the projection's increment vanishes, u^(n+1) = u^n = u, and a face blended by beta keeps
//   u = (1 - beta)(u + dt R) + beta u_s   =>   u - u_s = (1 - beta)/beta dt R:
// with beta = alpha the slip of a cut face grows with dt. Blending by
//   beta = alpha dt / ((1 - alpha) tau + alpha dt)
// gives (1 - beta)/beta dt = (1 - alpha)/alpha tau: the slip (1 - alpha)/alpha tau R whatever
// dt. It is the implicit relaxation u = (u~ + K u_s)/(1 + K), K = alpha dt / ((1 - alpha) tau),
// so 0 <= beta <= 1 for any dt: a contraction towards u_s, stable for any tau >= 0. tau = dt is
// Eq. 21; tau = 0 holds every face the body touches at u_s (the limit dt -> 0 of Eq. 21).
// The increment form blends u^ by the same beta before its solve, pull = beta (u_s - u^): its
// steady state is the explicit balance u = (1 - beta)(u + dt R) + beta u_s above, so the slip
// (1 - alpha)/alpha tau R holds there at any dt and any lambda (tau = 0: u = u_s on a touched
// face at a steady state; within a step the faces keep the solve's values, as covered ones do).
double Solver::forcing_fraction(double alpha, double dt) const {
  const double tau = m_cfg.forcing_time;
  if (tau < 0 || alpha <= 0) return alpha;
  return alpha >= kCovered ? 1.0 : alpha * dt / ((1 - alpha) * tau + alpha * dt);
}

// Immersed solid (paper Eq. 21): f_s = rho_f alpha (u_s - u~) / dt (beta with forcing_time:
// forcing_fraction above), then u~ += dt f_s / rho_f, i.e. u~ <- (1 - alpha) u~ + alpha u_s, on
// the solid's faces (the u faces the step solves for: the interior and a pressure side's
// boundary faces; Crank-Nicolson has no pressure sides).
//
// Crank-Nicolson in increment form (implicit_forcing = "increment", predictor.cpp) forced its
// explicit prediction before the solve, pull = alpha (u_s - u^) (beta with forcing_time), and
// f_s = rho_f pull / dt: the momentum the forcing put into the solve. The faces keep the solve's
// values, the covered ones too. Its step, with A = I - (nu dt/2) L, D = diag(1 - alpha) and the
// body at rest,
//   u^(n+1) = u^n + A^-1 (D (I + nu dt L) u^n - u^n),
// has the explicit balance u = D (I + nu dt L) u as its steady state (u = u_s on a covered face),
// and is stable at any lambda = nu dt / h^2 in a model of a wall (runs/sub-cell-wall/README.md).
// Setting the covered faces to u_s after the solve, as an earlier form did, made it unstable from
// lambda ~ 5: the solve treats the covered faces as fluid, so it gives the free faces next to
// the body a larger increment than a solve with those faces held would, and the mode there grew
// by a factor below -1 per step. A coupled iteration's redo solves again with its alpha and u_s.
void Solver::immersed_forcing(double dt, const CouplingIn& in, CouplingOut& out) {
  const double rho = m_cfg.density;
  const int ny = m_grid.ny();
  out.solid_u_force.resize(in.solid_u_index.size());
  out.solid_v_force.resize(in.solid_v_index.size());
  const bool cn = m_cfg.implicit && m_cfg.forcing_in_increment;
  if (cn && (m_pull[0].size() != in.solid_u_index.size() ||
             m_pull[1].size() != in.solid_v_index.size()))
    fsi::fail("protocol error: the step's solid faces changed between its solve and its forcing "
              "({} and {} u, v faces against {} and {})", m_pull[0].size(), m_pull[1].size(),
              in.solid_u_index.size(), in.solid_v_index.size());
  const bool sharp = m_cfg.sharp_interface;
  if (sharp) {
    sharp_targets(0, in, m_sharp_target[0]);
    sharp_targets(1, in, m_sharp_target[1]);
    sealed_cells();
  }
  // The force on one face, whose velocity is w (alpha a, body velocity ws, pull of the
  // increment's forcing; sharp: ws is the face's target, reached whole).
  auto force = [&](double& w, double a, double ws, double pull) {
    if (cn) return rho * pull / dt;
    if (sharp) {
      const double f = rho * (ws - w) / dt;
      w = ws;
      return f;
    }
    const double f = rho * forcing_fraction(a, dt) * (ws - w) / dt;
    w += dt * f / rho;
    return f;
  };
  for (std::size_t q = 0; q < in.solid_u_index.size(); ++q) {
    const auto [i, j] = face_of(0, in.solid_u_index[q]);
    out.solid_u_force[q] =
        i >= m_iu0 && i < m_iu1
            ? force(m_u(i, owned(j, 0)), in.solid_u_alpha[q],
                    sharp ? m_sharp_target[0][q] : in.solid_u_velocity[q], cn ? m_pull[0][q] : 0.0)
            : 0.0;
  }
  for (std::size_t q = 0; q < in.solid_v_index.size(); ++q) {
    const auto [i, j] = face_of(1, in.solid_v_index[q]);
    out.solid_v_force[q] =
        j >= m_j0 && owned(j, 1) < ny
            ? force(m_v(i, j), in.solid_v_alpha[q],
                    sharp ? m_sharp_target[1][q] : in.solid_v_velocity[q], cn ? m_pull[1][q] : 0.0)
            : 0.0;
  }
}

// interface = "sharp": a face's target from the predictor u~ (before any face is forced).
// The face's control volume V (its box) is cut by the wall; its volume fraction alpha and the
// volume fractions of its four neighbours of the same family give the wall's normal,
// n ~ -grad alpha (central differences on the face positions). Along the grid direction d where
// |d alpha/dx_d| is largest, with s = +1 when the fluid lies towards +x_d (alpha falls that way),
// the wall crosses the face's own grid line at
//   x_w = lo + alpha (hi - lo)  (s = +1),   x_w = hi - alpha (hi - lo)  (s = -1),
// [lo, hi] the box along d: exact for a straight wall across the box's middle band at right
// angles to d (the box's area fraction is then the fraction of its centre line, on whichever
// side; on even cells the box's own centre line along d is the face's, where the face's
// velocity lives; on graded ones a slanted wall is placed off by a fraction of the cells'
// difference). With x_f the face and x_n its neighbour one face further into the fluid,
// dist = s (x_f - x_w) (in about [-h/2, h/2]: the box meets the wall),
//   u = u_s + (u~_n - u_s) dist / (s (x_n - x_w)),
// the line from the wall's velocity at x_w through the fluid's at x_n: an interpolation when the
// face's centre is in the fluid (Fadlun et al. 2000, J. Comput. Phys. 161, 35, along one grid
// direction), an extrapolation into the body when it is inside (weight on u~_n down to -1 on
// even cells, below it where cells shrink towards the fluid), as a ghost cell. Either way the
// faces hold a linear profile whatever the wall's place in the cell:
// the faces a box-based footprint lists are those within half a cell of the wall, so the first
// fluid face beyond a face whose centre is inside is not listed, and holding that face at u_s
// would put the wall at its centre. u_s, the body's mean velocity in the box, stands for the
// wall's.
// Only the faces of rigid bodies (no elastic part in alpha; the coupler admits fixed ones only)
// are placed so: an elastic body's faces keep Eq. 21, whose alpha makes the fluid the body
// carries its own volume (the coupler's solid equation counts on it; with the line on an elastic
// bar, FSI2 and FSI1 diverged: runs/turek-hron-fsi/README.md).
// A covered face (alpha = 1) is held at u_s, unless the wall runs along its box's edge: its
// neighbour along d is not touched (alpha_n = 0, so not listed), and it extrapolates as above with
// the wall at the edge (dist = -h/2). A face with no usable neighbour (the neighbour a boundary
// face, as covered as the face, or more than a quarter covered: half inside the body at a
// concave corner, no fluid value to draw a line through) keeps the paper's blend,
// (1 - alpha) u~ + alpha u_s; so does a face without a gradient (a sliver inside one box).
// So does a face whose box holds a convex corner of two walls along the grid directions (a
// rectangle's end: alpha = f_x f_y with both fractions partial, recognised from its neighbours
// into the body, at_corner below). One line must take one of the two walls, and mirror-image
// corners that meet the cells differently take different ones (the larger gradient along x at
// one, along y at the other): two different corners where the body has two alike. At the
// Turek-Hron bar's trailing edge such lines set the lift's dependence on the cells' alignment
// (runs/turek-hron-cfd/README.md, "The sharp interface"). Not recognised, so keeping a line: a
// corner between walls not along the grid directions, and one whose neighbour boxes one face
// further in are not covered across (a body about two boxes thick or long).
void Solver::sharp_targets(int comp, const CouplingIn& in, std::vector<double>& target) {
  const auto index = comp == 0 ? in.solid_u_index : in.solid_v_index;
  const auto alpha = comp == 0 ? in.solid_u_alpha : in.solid_v_alpha;
  const auto us = comp == 0 ? in.solid_u_velocity : in.solid_v_velocity;
  // The elastic bodies' part of alpha (empty: every body is elastic).
  const auto elastic = comp == 0 ? in.solid_u_elastic : in.solid_v_elastic;
  const Field& w = comp == 0 ? m_u : m_v;
  const Axis& ax = m_grid.x();
  const Axis& ay = m_grid.y();
  // The family's faces: ni x nj, and its unknowns [ilo, ihi) x [jlo, jhi).
  const int ni = comp == 0 ? m_grid.nu() : m_grid.nx();
  const int nj = comp == 0 ? m_grid.ny() : m_grid.nv();
  const int ilo = comp == 0 ? m_iu0 : 0, ihi = comp == 0 ? m_iu1 : m_grid.nx();
  const int jlo = comp == 0 ? 0 : m_j0, jhi = m_grid.ny();
  const bool per[2] = {ax.periodic(), ay.periodic()};
  // Position of face i along x (or j along y) for this family, and its box [lo, hi]: a u-face
  // sits on x faces, its box between the cell centres; along y on centres, its box between the
  // faces (v the other way round). Indices may run one past either end (Axis has them).
  auto pos = [&](int a, int k) {
    const Axis& g = a == 0 ? ax : ay;
    return (a == comp) ? g.face(k) : g.centre(k);
  };
  auto box = [&](int a, int k) -> std::array<double, 2> {
    const Axis& g = a == 0 ? ax : ay;
    if (a == comp) return {g.centre(k - 1), g.centre(k)};
    return {g.face(k), g.face(k + 1)};
  };
  std::vector<double>& amap = m_sharp_alpha[comp];
  std::vector<std::int32_t>& slot = m_sharp_slot[comp];
  if (amap.size() != std::size_t(ni) * nj) {
    amap.assign(std::size_t(ni) * nj, 0.0);
    slot.assign(std::size_t(ni) * nj, -1);
  }
  for (std::size_t q = 0; q < index.size(); ++q)
    amap[index[q]] = alpha[q], slot[index[q]] = std::int32_t(q);
  // Index k + step along axis a wrapped when periodic; -1 when it leaves the faces.
  auto along = [&](int a, int k, int step) {
    const int n = a == 0 ? ni : nj;
    k += step;
    if (per[a]) return (k + n) % n;
    return k < 0 || k >= n ? -1 : k;
  };
  // Whether the face's box holds a convex corner of two walls along the grid directions: the
  // box is cut along x by the fraction f_x and along y by f_y, so alpha = f_x f_y, and its
  // neighbours one face into the body along x (cut along y only: f_y) and along y (f_x) are
  // partly covered with alpha_x alpha_y = alpha. g: d alpha / dx_d, both non-zero (the body lies
  // where alpha rises).
  auto at_corner = [&](int i, int j, double a, const double* g) {
    const int ki = along(0, i, g[0] > 0 ? 1 : -1), kj = along(1, j, g[1] > 0 ? 1 : -1);
    if (ki < 0 || kj < 0) return false;
    const double bx = amap[ki + std::size_t(ni) * j], by = amap[i + std::size_t(ni) * kj];
    return bx < kCovered && by < kCovered && std::abs(a - bx * by) <= kTouched;
  };
  // Each face's line: its neighbour (i, j) and the weight dist / span, or none (i = -1).
  std::vector<SharpLine>& lines = m_sharp_lines[comp];
  lines.assign(index.size(), SharpLine{});
  target.resize(index.size());
  for (std::size_t q = 0; q < index.size(); ++q) {
    const auto [i, j] = face_of(comp, index[q]);
    const double a = alpha[q];
    const bool covered = a >= kCovered;
    target[q] = covered ? us[q] : (1 - a) * w(i, j) + a * us[q];
    if (a <= kTouched || elastic.empty() || elastic[q] > kTouched) continue;
    // d alpha / dx_d by central differences (one-sided where a neighbour leaves the faces).
    double g[2];
    for (int d = 0; d < 2; ++d) {
      const int k = d == 0 ? i : j;
      const int kp = along(d, k, 1), km = along(d, k, -1);
      auto at = [&](int kk) {
        if (kk < 0) return a;
        return d == 0 ? amap[kk + std::size_t(ni) * j] : amap[i + std::size_t(ni) * kk];
      };
      const double xp = kp < 0 ? pos(d, k) : pos(d, k + 1);
      const double xm = km < 0 ? pos(d, k) : pos(d, k - 1);
      g[d] = xp > xm ? (at(kp) - at(km)) / (xp - xm) : 0.0;
    }
    const int d = std::abs(g[0]) >= std::abs(g[1]) ? 0 : 1;
    if (g[d] == 0) continue;
    if (!covered && g[1 - d] != 0 && at_corner(i, j, a, g)) continue;
    const int s = g[d] < 0 ? 1 : -1;
    const int k = d == 0 ? i : j;
    const auto [lo, hi] = box(d, k);
    const double xw = s > 0 ? lo + a * (hi - lo) : hi - a * (hi - lo);
    const double dist = s * (pos(d, k) - xw);
    const int kn = along(d, k, s);
    if (kn < 0) continue;
    const int in_ = d == 0 ? kn : i, jn = d == 0 ? j : kn;
    if (in_ < ilo || in_ >= ihi || jn < jlo || jn >= jhi) continue;
    const double an = amap[in_ + std::size_t(ni) * jn];
    if (an >= a || an > 0.25 || (covered && an > kTouched)) continue;
    // The neighbour's coordinate unwrapped (one face on from k, across a periodic seam too).
    const double span = s * (pos(d, k + s) - xw);
    if (span <= 0) continue;
    lines[q] = {in_, jn, dist / span};
    target[q] = us[q] + (w(in_, jn) - us[q]) * lines[q].r;
  }
  // A neighbour that is itself forced (a cut face, alpha_n <= 1/4) takes its own target, not
  // its predictor: in a steady flow the predictor of a forced face differs from its velocity by
  // dt R, which would otherwise leave a slip of order dt in the faces that read it. The
  // neighbour's own line reads a face further out, which is free (or forced the same way, read
  // here at its first value).
  std::vector<double>& first = m_sharp_first[comp];
  first.assign(target.begin(), target.end());
  for (std::size_t q = 0; q < index.size(); ++q) {
    const SharpLine& l = lines[q];
    if (l.i < 0) continue;
    const std::int32_t qn = slot[l.i + std::size_t(ni) * l.j];
    if (qn >= 0) target[q] = us[q] + (first[qn] - us[q]) * l.r;
  }
  // Every listed face for sealed_cells(): 1 when set whole on a rigid body (held at u_s when
  // covered, or on a line), 2 otherwise.
  std::vector<std::uint8_t>& whole = m_sharp_whole[comp];
  if (whole.size() != std::size_t(ni) * nj) whole.assign(std::size_t(ni) * nj, 0);
  for (std::size_t q = 0; q < index.size(); ++q) {
    const bool set = !elastic.empty() && !(elastic[q] > kTouched) &&
                     (alpha[q] >= kCovered || lines[q].i >= 0);
    whole[index[q]] = set ? 1 : 2;
    m_sharp_whole_list.push_back({comp, index[q]});
  }
  for (std::size_t q = 0; q < index.size(); ++q) amap[index[q]] = 0.0, slot[index[q]] = -1;
}

// The groups of cells walled in by faces the sharp interface set whole this step: the fluid
// inside a rigid body. The lines' ghost values are no body's velocity, so the forced field
// leaves a divergence in such cells at every step, which the projection answers with an
// increment there; the incremental projection kept it, and p grew linearly without bound
// (inside the Turek-Hron obstacle to 1e7 Pa by t = 10 on 600 x 123, against about 500 Pa
// outside), and with it the velocity of the few faces inside a group that the forcing blends
// (Eq. 21 with alpha near 1, where no line was drawn), by (1 - alpha) dt grad p / rho a step.
// project() keeps p^n in these cells. Their pressure reaches the fluid only through those
// blended faces: a face between a group and the fluid is set whole whatever its predictor's
// -grad p^n, and the sum of the whole faces' reactions f |V| over a body takes each inner
// cell's pressure once with each sign (a blended face's reaction takes alpha of its gradient,
// so a body's force moves by (1 - alpha) of the pressure differences across those faces, which
// no longer grow). A group is found by walking from the cells beside whole faces across every
// other face the coupling listed; one that meets a face it did not list (alpha = 0: fluid) or
// a domain side is the fluid, so the walk stays within the listed faces.
void Solver::sealed_cells() {
  const int nx = m_grid.nx(), ny = m_grid.ny();
  const int nu = m_grid.nu(), nv = m_grid.nv();
  const bool px = m_grid.x().periodic(), py = m_grid.y().periodic();
  const std::vector<std::uint8_t>&wu = m_sharp_whole[0], &wv = m_sharp_whole[1];
  m_sharp_sealed.clear();
  std::vector<std::uint8_t>& mark = m_sharp_mark;
  if (mark.size() != std::size_t(nx) * ny) mark.assign(std::size_t(nx) * ny, 0);
  std::vector<std::int32_t>& queue = m_sharp_queue;
  std::vector<std::int32_t>& touched = m_sharp_touched;
  touched.clear();
  // From cell (i, j), the neighbour across side k (0 west, 1 east, 2 south, 3 north): -1 when a
  // whole face is between them, -2 when the face is not listed or the side is a domain side.
  auto across = [&](int i, int j, int k) -> std::int32_t {
    const bool xdir = k < 2;
    const int f = xdir ? i + (k == 1) : j + (k == 3);  // the face's index along its direction
    const int fi = xdir ? (px ? f % nu : f) : i, fj = xdir ? j : (py ? f % nv : f);
    const std::uint8_t w = xdir ? wu[fi + std::size_t(nu) * fj] : wv[fi + std::size_t(nx) * fj];
    if (w == 1) return -1;
    if (w == 0) return -2;
    int ci = i + (k == 1) - (k == 0), cj = j + (k == 3) - (k == 2);
    if (px) ci = (ci + nx) % nx;
    if (py) cj = (cj + ny) % ny;
    if (ci < 0 || ci >= nx || cj < 0 || cj >= ny) return -2;
    return ci + nx * cj;
  };
  auto seed = [&](std::int32_t c) {
    if (mark[c] != 0) return;
    // Walk the group: 1 while walking, then 2 (sealed) or 3 (the fluid).
    queue.assign(1, c);
    mark[c] = 1;
    touched.push_back(c);
    bool is_open = false;
    for (std::size_t h = 0; h < queue.size() && !is_open; ++h) {
      const int i = queue[h] % nx, j = queue[h] / nx;
      for (int k = 0; k < 4; ++k) {
        const std::int32_t n = across(i, j, k);
        if (n == -1) continue;
        if (n == -2 || mark[n] == 3) {
          is_open = true;
          break;
        }
        if (mark[n] == 0) mark[n] = 1, queue.push_back(n), touched.push_back(n);
      }
    }
    for (const std::int32_t q : queue) mark[q] = is_open ? 3 : 2;
    if (!is_open) m_sharp_sealed.insert(m_sharp_sealed.end(), queue.begin(), queue.end());
  };
  // Seeds: the cells on either side of each whole face.
  for (const auto& [comp, f] : m_sharp_whole_list) {
    if ((comp == 0 ? wu : wv)[f] != 1) continue;
    if (comp == 0) {
      const int i = f % nu, j = f / nu;
      if (i < nx) seed(i + nx * j);
      if (i > 0 || px) seed((i + nx - 1) % nx + nx * j);
    } else {
      const int i = f % nx, j = f / nx;
      if (j < ny) seed(i + nx * j);
      if (j > 0 || py) seed(i + nx * ((j + ny - 1) % ny));
    }
  }
  // Every mark and flag back to zero for the next step.
  for (const std::int32_t q : touched) mark[q] = 0;
  for (const auto& [comp, f] : m_sharp_whole_list) m_sharp_whole[comp][f] = 0;
  m_sharp_whole_list.clear();
}

}  // namespace fluid
