// Convection and diffusion kernels: plain loops, j outer, i inner, on precomputed inverse
// spacings.
#include "momentum.hpp"

#include <algorithm>

#include "error.hpp"

namespace fluid {

SpongeWeights sponge_weights(const Grid& g, double blend) {
  SpongeWeights s;
  const int nx = g.nx(), start = g.x().sponge_start();
  const bool sponge = start < nx;
  s.active = sponge || blend > 0;
  s.centre.assign(nx + 2, 0);
  s.face.assign(nx + 3, 0);
  // Without a sponge the ghost column and the last face take the blend too.
  for (int i = -1; i <= nx; ++i) s.centre[i + 1] = sponge && i >= start ? 1.0 : blend;
  for (int i = -1; i <= nx + 1; ++i) s.face[i + 1] = sponge && i >= start ? 1.0 : blend;
  return s;
}

namespace {

// Flux value carried by velocity `a` across a face between values lo and hi: the average, or,
// with weight b, the upwind value.
template <bool Upwind>
inline double carried(double a, double lo, double hi, double b) {
  const double c = 0.5 * (lo + hi);
  if constexpr (Upwind) {
    const double up = a > 0 ? lo : hi;
    return c + b * (up - c);
  } else {
    (void)a;
    (void)b;
    return c;
  }
}

// u face (i, j) at (x_face_i, y_centre_j):
//   d(uu)/dx = (U_{i+1/2} q_{i+1/2} - U_{i-1/2} q_{i-1/2}) / (xc_i - xc_{i-1}),  U = (u_i + u_{i+1})/2
//   d(vu)/dy = (V_{j+1/2} q_{j+1/2} - V_{j-1/2} q_{j-1/2}) / (yf_{j+1} - yf_j),  V, q at the corners
//   lap(u)   = [(u_{i+1}-u_i)/w_i - (u_i-u_{i-1})/w_{i-1}] / d_i
//            + [(u_{j+1}-u_j)/d_{j+1} - (u_j-u_{j-1})/d_j] * 2 / (yc_{j+1} - yc_{j-1})
// with q the carried value (central average or upwind), corner interpolation weighted by distance.
// v face (i, j) at (x_centre_i, y_face_j) likewise with the roles of x and y exchanged.
template <bool Upwind, bool Lap>
void kernel(const Grid& g, const SpongeWeights& sw, const Field& u, const Field& v, double nu_e,
            int i0, int j0, Field& hu, Field& hv, Field* lu, Field* lv) {
  const int nx = g.nx(), ny = g.ny();
  const Axis& X = g.x();
  const Axis& Y = g.y();
  const double *xwi = X.wi(), *xdi = X.di(), *xci = X.ci(), *xlo = X.wlo(), *xhi = X.whi();
  const double *ywi = Y.wi(), *ydi = Y.di(), *yci = Y.ci(), *ylo = Y.wlo(), *yhi = Y.whi();
  const double* bc = Upwind ? sw.centre.data() + 1 : nullptr;
  const double* bf = Upwind ? sw.face.data() + 1 : nullptr;

  // The rows this process holds (hu's; on one rank all of them).
  for (int j = hu.jlo; j < hu.jhi; ++j) {
    const double* uc = u.row(j);
    const double* un = u.row(j + 1);
    const double* us = u.row(j - 1);
    const double* vc = v.row(j);
    const double* vn = v.row(j + 1);
    double* h = hu.row(j);
    double* l = Lap ? lu->row(j) : nullptr;
    const double ylo_n = ylo[j + 1], yhi_n = yhi[j + 1], ylo_s = ylo[j], yhi_s = yhi[j];
    const double ywij = ywi[j], ydn = ydi[j + 1], yds = ydi[j], ycj = yci[j];
    // The outputs (hu, hv, lu, lv) are other fields than u and v: no iteration reads what another
    // writes. Said to the compiler, which otherwise needs more run-time alias checks than it will
    // make and leaves the loop scalar.
#pragma GCC ivdep
    for (int i = i0; i < nx; ++i) {
      const double ue = 0.5 * (uc[i] + uc[i + 1]), uw = 0.5 * (uc[i - 1] + uc[i]);
      const double be = Upwind ? bc[i] : 0, bw = Upwind ? bc[i - 1] : 0, bfi = Upwind ? bf[i] : 0;
      const double fx = ue * carried<Upwind>(ue, uc[i], uc[i + 1], be) -
                        uw * carried<Upwind>(uw, uc[i - 1], uc[i], bw);
      const double vnn = xlo[i] * vn[i - 1] + xhi[i] * vn[i];
      const double vss = xlo[i] * vc[i - 1] + xhi[i] * vc[i];
      double qn, qs;
      if constexpr (Upwind) {
        const double cn = ylo_n * uc[i] + yhi_n * un[i], cs = ylo_s * us[i] + yhi_s * uc[i];
        qn = cn + bfi * ((vnn > 0 ? uc[i] : un[i]) - cn);
        qs = cs + bfi * ((vss > 0 ? us[i] : uc[i]) - cs);
      } else {
        qn = ylo_n * uc[i] + yhi_n * un[i];
        qs = ylo_s * us[i] + yhi_s * uc[i];
      }
      const double fy = vnn * qn - vss * qs;
      const double lap = ((uc[i + 1] - uc[i]) * xwi[i] - (uc[i] - uc[i - 1]) * xwi[i - 1]) * xdi[i] +
                         ((un[i] - uc[i]) * ydn - (uc[i] - us[i]) * yds) * ycj;
      h[i] = -(fx * xdi[i] + fy * ywij) + nu_e * lap;
      if constexpr (Lap) l[i] = lap;
    }
  }

  for (int j = std::max(j0, hv.jlo); j < std::min(ny, hv.jhi); ++j) {
    const double* vc = v.row(j);
    const double* vn = v.row(j + 1);
    const double* vs = v.row(j - 1);
    const double* uc = u.row(j);
    const double* us = u.row(j - 1);
    double* h = hv.row(j);
    double* l = Lap ? lv->row(j) : nullptr;
    const double ylo_j = ylo[j], yhi_j = yhi[j], ydj = ydi[j], ywn = ywi[j], yws = ywi[j - 1];
#pragma GCC ivdep
    for (int i = 0; i < nx; ++i) {
      const double ue = ylo_j * us[i + 1] + yhi_j * uc[i + 1];
      const double uw = ylo_j * us[i] + yhi_j * uc[i];
      double qe, qw;
      if constexpr (Upwind) {
        const double ce = xlo[i + 1] * vc[i] + xhi[i + 1] * vc[i + 1];
        const double cw = xlo[i] * vc[i - 1] + xhi[i] * vc[i];
        qe = ce + bf[i + 1] * ((ue > 0 ? vc[i] : vc[i + 1]) - ce);
        qw = cw + bf[i] * ((uw > 0 ? vc[i - 1] : vc[i]) - cw);
      } else {
        qe = xlo[i + 1] * vc[i] + xhi[i + 1] * vc[i + 1];
        qw = xlo[i] * vc[i - 1] + xhi[i] * vc[i];
      }
      const double fx = ue * qe - uw * qw;
      const double vnn = 0.5 * (vc[i] + vn[i]), vss = 0.5 * (vs[i] + vc[i]);
      const double bci = Upwind ? bc[i] : 0;
      const double fy = vnn * carried<Upwind>(vnn, vc[i], vn[i], bci) -
                        vss * carried<Upwind>(vss, vs[i], vc[i], bci);
      const double lap = ((vc[i + 1] - vc[i]) * xdi[i + 1] - (vc[i] - vc[i - 1]) * xdi[i]) * xci[i] +
                         ((vn[i] - vc[i]) * ywn - (vc[i] - vs[i]) * yws) * ydj;
      h[i] = -(fx * xwi[i] + fy * ydj) + nu_e * lap;
      if constexpr (Lap) l[i] = lap;
    }
  }
}

}  // namespace

void momentum_terms(const Grid& g, const SpongeWeights& sw, const Field& u, const Field& v,
                    double nu_e, int i0, int j0, Field& hu, Field& hv, Field* lu, Field* lv) {
  const bool lap = lu != nullptr;
  if (sw.active) {
    lap ? kernel<true, true>(g, sw, u, v, nu_e, i0, j0, hu, hv, lu, lv)
        : kernel<true, false>(g, sw, u, v, nu_e, i0, j0, hu, hv, lu, lv);
  } else {
    lap ? kernel<false, true>(g, sw, u, v, nu_e, i0, j0, hu, hv, lu, lv)
        : kernel<false, false>(g, sw, u, v, nu_e, i0, j0, hu, hv, lu, lv);
  }
}

namespace {

// q3 - (l + r)/2 for the carried value across the face between l and r, carried by a (the
// header's formula).
inline double third_order(double a, double m, double l, double r, double p) {
  const double s = a > 0 ? 1.0 : a < 0 ? -1.0 : 0.0;
  return ((l + r - m - p) + s * (p - 3.0 * r + 3.0 * l - m)) * (1.0 / 12.0);
}

// Stored index of position k along a direction of n periodic cells whose field stores
// [-1, last]: beyond it, the position one period in.
inline int wrap(int k, int n, int last, bool periodic) {
  if (!periodic) return k;
  return k < -1 ? k + n : k > last ? k - n : k;
}

}  // namespace

void upwind3_terms(const Grid& g, const SpongeWeights& sw, const Field& u, const Field& v,
                   const OuterRows& ou, const OuterRows& ov, int i0, int j0, Field& hu, Field& hv,
                   std::vector<double>& work) {
  const int nx = g.nx(), ny = g.ny();
  const bool px = g.x().periodic(), py = g.y().periodic();
  const Axis& X = g.x();
  const Axis& Y = g.y();
  const double *xwi = X.wi(), *xdi = X.di(), *xlo = X.wlo(), *xhi = X.whi();
  const double *ywi = Y.wi(), *ydi = Y.di(), *ylo = Y.wlo(), *yhi = Y.whi();
  const double* bc = sw.centre.data() + 1;
  const double* bf = sw.face.data() + 1;
  // The rows filled on every rank are [lo - 1, hi] (hi = u's last stored row; v's top rank
  // stores one more, which a periodic y leaves unfilled there).
  const int hi = u.jhi;
  auto row = [&](const Field& f, const OuterRows& o, int j) -> const double* {
    if (j >= f.jlo - 1 && j <= hi) return f.row(j);
    if (o.below.empty()) return f.row(wrap(j, ny, hi, py));
    FSI_ASSERT(j == f.jlo - 2 || j == hi + 1);
    return (j < f.jlo ? o.below.data() : o.above.data()) + 1;
  };
  // Whether a four-value stencil [k - 1, k + 2] lies in [0, last] (always when periodic).
  auto inside = [](int k, int last, bool periodic) {
    return periodic || (k >= 1 && k + 2 <= last);
  };
  // A flux along a row (x) at positions [k0, k1], each reading q[k - 1 .. k + 2] with the
  // carrying velocity a(k) and weight w[k]; q's values are [0, valid] (a bounded row's ghosts
  // are not read) and stored [-1, last]. The stencil's inner part in one plain loop; the others
  // wrapped (periodic) or zero (bounded: the two-point flux kept).
  work.resize(3 * std::size_t(nx + 2));
  double* f = work.data();
  double* gs = f + nx + 2;
  double* gn = gs + nx + 2;
  auto along_x = [&](const double* q, int k0, int k1, int valid, int last, const double* w,
                     auto&& a, double* out) {
    const int in0 = std::max(k0, px ? 0 : 1), in1 = std::min(k1, px ? last - 2 : valid - 2);
    for (int k = in0; k <= in1; ++k) {
      const double ak = a(k);
      out[k] = (1.0 - w[k]) * ak * third_order(ak, q[k - 1], q[k], q[k + 1], q[k + 2]);
    }
    for (int k = k0; k <= k1; ++k) {
      if (k >= in0 && k <= in1) continue;
      if (!px) {
        out[k] = 0;
        continue;
      }
      const double ak = a(k);
      out[k] = (1.0 - w[k]) * ak *
               third_order(ak, q[wrap(k - 1, nx, last, true)], q[k], q[k + 1],
                           q[wrap(k + 2, nx, last, true)]);
    }
  };
  // A flux across rows (y) at row boundary or cell c, reading rows c - off .. c - off + 3 of f.
  auto across_y = [&](const Field& fld, const OuterRows& o, int c, int off, int last, int k0,
                      int k1, const double* w, auto&& a, double* out) {
    if (!inside(c + 1 - off, last, py)) {
      for (int k = k0; k < k1; ++k) out[k] = 0;
      return;
    }
    const double *r0 = row(fld, o, c - off), *r1 = row(fld, o, c - off + 1),
                 *r2 = row(fld, o, c - off + 2), *r3 = row(fld, o, c - off + 3);
    for (int k = k0; k < k1; ++k) {
      const double ak = a(k, r1, r2);
      out[k] = (1.0 - w[k]) * ak * third_order(ak, r0[k], r1[k], r2[k], r3[k]);
    }
  };

  // u faces: x fluxes at cells c (between faces c and c + 1; u stores faces [-1, nx + 1]), y
  // fluxes at corners (face i, row boundary j between rows j - 1 and j: rows j - 2 .. j + 1).
  const int ju0 = hu.jlo, ju1 = hu.jhi;
  auto u_corner = [&](int j, double* out) {
    const double* vr = v.row(j);
    across_y(u, ou, j, 2, ny - 1, i0, nx, bf,
             [&](int i, const double*, const double*) {
               return xlo[i] * vr[i - 1] + xhi[i] * vr[i];
             },
             out);
  };
  if (ju0 < ju1) u_corner(ju0, gs);
  for (int j = ju0; j < ju1; ++j) {
    const double* uc = u.row(j);
    along_x(uc, i0 - 1, nx - 1, nx, nx + 1, bc,
            [&](int c) { return 0.5 * (uc[c] + uc[c + 1]); }, f + 1);
    u_corner(j + 1, gn);
    double* h = hu.row(j);
    const double ywij = ywi[j];
    for (int i = i0; i < nx; ++i) h[i] -= (f[i + 1] - f[i]) * xdi[i] + (gn[i] - gs[i]) * ywij;
    std::swap(gs, gn);
  }

  // v faces: y fluxes at cells c (between faces c and c + 1: faces c - 1 .. c + 2), x fluxes at
  // corners (column boundary i between cells i - 1 and i: cells i - 2 .. i + 1; v stores
  // cells [-1, nx]).
  const int jv0 = std::max(j0, hv.jlo), jv1 = std::min(ny, hv.jhi);
  auto v_cells = [&](int c, double* out) {
    across_y(v, ov, c, 1, ny, 0, nx, bc,
             [](int i, const double* r1, const double* r2) { return 0.5 * (r1[i] + r2[i]); },
             out);
  };
  if (jv0 < jv1) v_cells(jv0 - 1, gs);
  for (int j = jv0; j < jv1; ++j) {
    const double* vc = v.row(j);
    const double* uc = u.row(j);
    const double* us = u.row(j - 1);
    const double yl = ylo[j], yh = yhi[j];
    // The corner i's stencil is cells i - 2 .. i + 1: position k = i - 1 of along_x.
    along_x(vc, -1, nx - 1, nx - 1, nx, bf + 1,
            [&](int k) { return yl * us[k + 1] + yh * uc[k + 1]; }, f + 1);
    v_cells(j, gn);
    double* h = hv.row(j);
    const double ydj = ydi[j];
    for (int i = 0; i < nx; ++i) h[i] -= (f[i + 1] - f[i]) * xwi[i] + (gn[i] - gs[i]) * ydj;
    std::swap(gs, gn);
  }
}

}  // namespace fluid
