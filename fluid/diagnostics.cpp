// CFL, divergence, energy, probes, wall shear and vorticity of the MAC fields.
#include "diagnostics.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>

namespace fluid {

namespace {
// The largest of the ranks' extrema (a NaN above every number), on every rank.
Extremum largest(const Decomposition& d, Extremum e) {
  if (d.serial()) return e;
  d.broadcast(&e, sizeof e, d.argmax(e.value));
  return e;
}
}  // namespace

// Row by row: the row's largest value in a loop without branches (which the compiler
// vectorises), then the cell that holds the largest value
// only for a row that beats the best so far. Every step runs this; the location is rarely needed.
Extremum cfl(const Solver& s, double dt) {
  const Grid& g = s.grid();
  const double *xwi = g.x().wi(), *ywi = g.y().wi();
  Extremum e;
  // std::max drops a NaN in its second argument: the added 0 * (sum of the four values) is 0
  // for finite values and NaN when any of them is NaN or infinite.
  auto local = [&](const double* u, const double* v, const double* vn, double wy, int i) {
    return std::max(std::abs(u[i]), std::abs(u[i + 1])) * xwi[i] +
           std::max(std::abs(v[i]), std::abs(vn[i])) * wy + 0.0 * (u[i] + u[i + 1] + v[i] + vn[i]);
  };
  const Decomposition& d = s.decomposition();
  for (int j = d.lo(); j < d.hi(); ++j) {
    const double* u = s.u().row(j);
    const double* v = s.v().row(j);
    const double* vn = s.v().row(j + 1);
    const double wy = ywi[j];
    // |c| (the sign bit cleared, also of a NaN that an invalid operation made negative): its
    // bits order like its value as a signed integer, +Inf above every finite value and NaN above
    // +Inf, so an integer max finds both.
    std::int64_t mb = 0;
    for (int i = 0; i < g.nx(); ++i) {
      const std::int64_t b = std::bit_cast<std::int64_t>(std::abs(local(u, v, vn, wy, i)));
      mb = b > mb ? b : mb;
    }
    const double m = std::bit_cast<double>(mb);
    if (!std::isfinite(m)) {
      e = {std::numeric_limits<double>::quiet_NaN(), 0, j, g.x().centre(0), g.y().centre(j)};
      break;
    }
    if (m <= e.value) continue;
    e = {m, 0, j, g.x().centre(0), g.y().centre(j)};
    for (int i = 0; i < g.nx(); ++i)
      if (local(u, v, vn, wy, i) == m) {
        e = {m, i, j, g.x().centre(i), g.y().centre(j)};
        break;
      }
  }
  e.value *= dt;
  return largest(d, e);
}

Extremum max_divergence(const Solver& s) {
  const Grid& g = s.grid();
  const double *xwi = g.x().wi(), *ywi = g.y().wi();
  Extremum e;
  const Decomposition& dec = s.decomposition();
  // Less what the projection left inside elastic bodies on purpose (body_divergence = "solid").
  const Field* allowed = s.allowed_divergence();
  for (int j = dec.lo(); j < dec.hi(); ++j) {
    const double* u = s.u().row(j);
    const double* v = s.v().row(j);
    const double* vn = s.v().row(j + 1);
    const double* a = allowed ? allowed->row(j) : nullptr;
    for (int i = 0; i < g.nx(); ++i) {
      const double d =
          std::abs((u[i + 1] - u[i]) * xwi[i] + (vn[i] - v[i]) * ywi[j] - (a ? a[i] : 0.0));
      if (!(d <= e.value)) e = {d, i, j, g.x().centre(i), g.y().centre(j)};
    }
  }
  return largest(dec, e);
}

double kinetic_energy(const Solver& s, double x_lo, double x_hi, std::array<double, 2> ref) {
  const Grid& g = s.grid();
  const Axis& X = g.x();
  const Axis& Y = g.y();
  double e = 0;
  const int iu_end = X.periodic() ? g.nx() : g.nx() + 1;
  const Decomposition& d = s.decomposition();
  for (int j = d.lo(); j < d.hi(); ++j) {
    for (int i = 0; i < iu_end; ++i) {
      const double x = X.face(i);
      if (x < x_lo || x > x_hi) continue;
      // control volume of face i: half of each neighbouring cell inside the domain
      double w = 0.5 * ((i > 0 || X.periodic() ? X.width(i - 1) : 0.0) +
                        (i < g.nx() ? X.width(i) : 0.0));
      if (X.periodic() && i == 0) w = 0.5 * (X.width(g.nx() - 1) + X.width(0));
      const double q = s.u()(i, j) - ref[0];
      e += q * q * w * Y.width(j);
    }
  }
  const int jv_end = std::min(Y.periodic() ? g.ny() : g.ny() + 1, d.v_hi());
  for (int j = d.lo(); j < jv_end; ++j) {
    double w = 0.5 * ((j > 0 || Y.periodic() ? Y.width(j - 1) : 0.0) + (j < g.ny() ? Y.width(j) : 0.0));
    for (int i = 0; i < g.nx(); ++i) {
      const double x = X.centre(i);
      if (x < x_lo || x > x_hi) continue;
      const double q = s.v()(i, j) - ref[1];
      e += q * q * w * X.width(i);
    }
  }
  return 0.5 * s.config().density * d.sum(e);
}

namespace {
// Index k and weight of the last coordinate <= x among c(k), k in [k0, k1).
template <class Coord>
void bracket(Coord c, int k0, int k1, double x, int& k, double& w) {
  if (x <= c(k0)) {
    k = k0;
    w = 0;
    return;
  }
  if (x >= c(k1 - 1)) {
    k = k1 - 2;
    w = 1;
    return;
  }
  int lo = k0, hi = k1 - 1;
  while (hi - lo > 1) {
    const int m = (lo + hi) / 2;
    (c(m) <= x ? lo : hi) = m;
  }
  k = lo;
  w = (x - c(lo)) / (c(lo + 1) - c(lo));
}
}  // namespace

double sample(const Solver& s, int q, double x, double y) {
  const Grid& g = s.grid();
  const Axis& X = g.x();
  const Axis& Y = g.y();
  const Field& f = q == 0 ? s.u() : q == 1 ? s.v() : s.p();
  auto xf = [&](int i) { return X.face(i); };
  auto xc = [&](int i) { return X.centre(i); };
  auto yf = [&](int j) { return Y.face(j); };
  auto yc = [&](int j) { return Y.centre(j); };
  int i, j;
  double wx, wy;
  // Ghost cells extend the range by one so that points near a wall interpolate to it.
  if (q == 0) bracket(xf, 0, g.nx() + 1, x, i, wx);
  else bracket(xc, -1, g.nx() + 1, x, i, wx);
  if (q == 1) bracket(yf, 0, g.ny() + 1, y, j, wy);
  else bracket(yc, -1, g.ny() + 1, y, j, wy);
  // On several ranks the rank holding row j interpolates (row j + 1 is at most its ghost row).
  const Decomposition& d = s.decomposition();
  const bool here = d.serial() || d.owner(j) == d.rank();
  const double value = here ? (1 - wx) * (1 - wy) * f(i, j) + wx * (1 - wy) * f(i + 1, j) +
                                  (1 - wx) * wy * f(i, j + 1) + wx * wy * f(i + 1, j + 1)
                            : 0.0;
  return d.sum(value);
}

std::vector<double> wall_shear(const Solver& s, Side side, std::vector<double>* position) {
  const Grid& g = s.grid();
  const int a = side / 2;
  const bool hi = side % 2;
  const Axis& ax = g.axis(a);
  const Axis& o = g.axis(1 - a);
  const Field& t = a == 0 ? s.v() : s.u();  // tangential component
  const int n = ax.n();
  const double w0 = ax.width(hi ? n - 1 : 0), w1 = ax.width(hi ? n - 2 : 1);
  // d/ds at s = 0 of the quadratic through (0, wall), (s0, q0), (s1, q1), s into the fluid.
  const double s0 = 0.5 * w0, s1 = w0 + 0.5 * w1;
  const double d0 = s1 / (s0 * (s1 - s0)), d1 = -s0 / (s1 * (s1 - s0)), dw = -(d0 + d1);
  const SideBc& bc = s.boundaries().side(side);
  const double wall = bc.type == BcType::wall ? bc.wall_speed(s.time()) : 0.0;
  const int q0 = hi ? n - 1 : 0, q1 = hi ? n - 2 : 1;
  const int m = o.periodic() ? o.n() : o.n() + 1;
  std::vector<double> tau(m, 0.0);
  if (position) position->resize(m);
  // With n into the fluid and t along +x or +y: tau = mu d(u_t)/dn. On several ranks each
  // computes the positions it holds (a left or right side's rows, a bottom or top side on its
  // rank) and the sum over the ranks gathers them.
  const double mu = s.config().viscosity;
  const Decomposition& d = s.decomposition();
  const int k0 = a == 0 ? d.lo() : 0;
  const int k1 = a == 0                          ? std::min(m, d.v_hi())
                 : (hi ? d.has_top() : d.has_bottom()) ? m
                                                     : 0;
  for (int k = 0; k < m; ++k)
    if (position) (*position)[k] = o.face(k);
  for (int k = k0; k < k1; ++k) {
    const double v0 = a == 0 ? t(q0, k) : t(k, q0);
    const double v1 = a == 0 ? t(q1, k) : t(k, q1);
    tau[k] = mu * (dw * wall + d0 * v0 + d1 * v1);
  }
  d.sum(tau.data(), m);
  return tau;
}

int nearest_u_column(const Solver& s, double x) {
  const Axis& X = s.grid().x();
  const int n = X.n();
  int best = 0;
  for (int i = 1; i <= n; ++i)
    if (std::abs(X.face(i) - x) < std::abs(X.face(best) - x)) best = i;
  return X.periodic() && best == n ? 0 : best;
}

double flow_rate(const Solver& s, int i) {
  const Axis& Y = s.grid().y();
  double q = 0;
  const Decomposition& d = s.decomposition();
  if (d.serial()) {
    for (int j = 0; j < s.grid().ny(); ++j) q += s.u()(i, j) * Y.width(j);
    return q;
  }
  // On several ranks the terms of every row, summed in row order: the one-rank sum's bits.
  std::vector<double> mine(d.hi() - d.lo()), all(s.grid().ny());
  for (int j = d.lo(); j < d.hi(); ++j) mine[j - d.lo()] = s.u()(i, j) * Y.width(j);
  d.gather_all_rows(mine.data(), all.data());
  for (double t : all) q += t;
  return q;
}

void vorticity(const Solver& s, std::vector<double>& out) {
  const Grid& g = s.grid();
  const int nx = g.nx();
  const double *xdi = g.x().di(), *ydi = g.y().di();
  const Decomposition& d = s.decomposition();
  out.resize(std::size_t(nx) * (d.hi() - d.lo()));
  auto corner = [&](int i, int j) {
    return (s.v()(i, j) - s.v()(i - 1, j)) * xdi[i] - (s.u()(i, j) - s.u()(i, j - 1)) * ydi[j];
  };
  for (int j = d.lo(); j < d.hi(); ++j)
    for (int i = 0; i < nx; ++i)
      out[i + std::size_t(nx) * (j - d.lo())] =
          0.25 * (corner(i, j) + corner(i + 1, j) + corner(i, j + 1) + corner(i + 1, j + 1));
}

void centred_velocity(const Solver& s, std::vector<double>& uc, std::vector<double>& vc) {
  const Grid& g = s.grid();
  const int nx = g.nx();
  const Decomposition& d = s.decomposition();
  const int lo = d.lo(), rows = d.hi() - d.lo();
  uc.resize(std::size_t(nx) * rows);
  vc.resize(std::size_t(nx) * rows);
  for (int j = lo; j < d.hi(); ++j)
    for (int i = 0; i < nx; ++i) {
      uc[i + std::size_t(nx) * (j - lo)] = 0.5 * (s.u()(i, j) + s.u()(i + 1, j));
      vc[i + std::size_t(nx) * (j - lo)] = 0.5 * (s.v()(i, j) + s.v()(i, j + 1));
    }
}

}  // namespace fluid
