// Boundary-face values and ghost values for the velocity and pressure fields.
#include "boundary.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fluid {
namespace {

// The normal component of side s is u on left/right, v on bottom/top; `n` indexes along the
// side's normal axis, `k` along the side.
inline double& at(Field& f, int axis, int n, int k) { return axis == 0 ? f(n, k) : f(k, n); }

// Quadratic through (0, data), (s0, q0), (s1, q1), evaluated at the mirrored ghost centre -s0.
GhostRule quadratic_rule(double w0, double w1) {
  const double s0 = 0.5 * w0, s1 = w0 + 0.5 * w1, sg = -s0;
  GhostRule r;
  r.gc = (sg - s0) * (sg - s1) / (s0 * s1);
  r.ga = sg * (sg - s1) / (s0 * (s0 - s1));
  r.gb = sg * (sg - s0) / (s1 * (s1 - s0));
  return r;
}

}  // namespace

Boundaries::Boundaries(const Grid& g, const std::array<SideBc, 4>& bc, const Decomposition& d)
    : m_g(g), m_d(d), m_bc(bc) {
  for (int s = 0; s < 4; ++s) m_speed[s] = bc[s].type == BcType::wall ? bc[s].wall_speed(0.0) : 0.0;
  for (int s = 0; s < 4; ++s) {
    const Axis& ax = g.axis(s / 2);
    const bool hi = s % 2;
    const double w0 = ax.width(hi ? ax.n() - 1 : 0), w1 = ax.width(hi ? ax.n() - 2 : 1);
    switch (bc[s].type) {
      case BcType::wall:
      case BcType::inflow: m_rule[s] = quadratic_rule(w0, w1); break;
      case BcType::slip:
      case BcType::pressure: m_rule[s] = {1, 0, 0, false}; break;
      case BcType::outflow:
        m_rule[s] = {0, 0, 0, true};
        m_has_outflow = true;
        break;
      case BcType::periodic: break;
    }
  }
}

double Boundaries::inflow(int s, double coord, double t) const {
  const SideBc& b = m_bc[s];
  const double ramp = b.ramp_factor(t);
  if (b.profile == Profile::uniform) return ramp * b.mean;
  const Axis& o = m_g.axis(1 - s / 2);
  const double lo = o.lo(), len = o.length();
  const double e = (coord - lo) * (lo + len - coord) / (len * len);
  return ramp * 6.0 * b.mean * e;  // parabola with mean `mean`: 1.5 mean y (H - y) / (H/2)^2
}

const std::vector<double>& Boundaries::whole_side(int s) const {
  if (m_d.serial()) return m_mine;
  if (s < 2) {
    m_all.resize(m_g.ny());
    m_d.gather_all_rows(m_mine.data(), m_all.data());
  } else {
    m_all = m_mine;
    m_all.resize(m_g.nx());
    m_d.broadcast(m_all.data(), int(m_all.size() * sizeof(double)),
                  s == bottom ? 0 : m_d.ranks() - 1);
  }
  return m_all;
}

double Boundaries::net_inflow(const Field& u, const Field& v) const {
  double q = 0;
  for (int s = 0; s < 4; ++s) {
    if (m_bc[s].type == BcType::periodic) continue;
    const int a = s / 2;
    const bool hi = s % 2;
    const Axis& ax = m_g.axis(a);
    const Axis& o = m_g.axis(1 - a);
    const Field& f = a == 0 ? u : v;
    const int b = hi ? ax.n() : 0;
    const double sign = hi ? -1.0 : 1.0;
    const int k0 = a == 0 ? row_lo() : 0, k1 = a == 0 ? row_hi() : holds(s) ? o.n() : 0;
    m_mine.resize(k1 - k0);
    for (int k = k0; k < k1; ++k) m_mine[k - k0] = sign * (a == 0 ? f(b, k) : f(k, b)) * o.width(k);
    for (double t : whole_side(s)) q += t;
  }
  return q;
}

// Convective outflow: q_b^{n+1} = q_b^n - r (q_b^n - q_1^n), r = c dt / w, 0 <= r <= 1, with c the
// bulk outward velocity or, with Orlanski's choice, c dt / w = -(q_1^n - q_1^{n-1}) / (q_1^n - q_2^n)
// per line. Then every outflow face gets the same shift Q / A_out so that the net flux through the
// whole boundary vanishes (the Poisson problem is then compatible).
void Boundaries::advance_normal(Field& u, Field& v, double t, double dt) {
  double out_length = 0;
  for (int s = 0; s < 4; ++s) {
    const SideBc& bc = m_bc[s];
    if (bc.type == BcType::periodic || bc.type == BcType::pressure) continue;  // pressure: the solver's
    const int a = s / 2;
    const bool hi = s % 2;
    const Axis& ax = m_g.axis(a);
    const Axis& o = m_g.axis(1 - a);
    Field& nf = a == 0 ? u : v;
    Field& tf = a == 0 ? v : u;
    const int b = hi ? ax.n() : 0;
    const double sign_in = hi ? -1.0 : 1.0;
    // The side's positions on this rank: its rows (left, right) or all columns, when it holds
    // the side (bottom, top).
    const bool here = holds(s);
    const int k0 = a == 0 ? row_lo() : 0, k1 = a == 0 ? row_hi() : here ? o.n() : 0;
    if (bc.type == BcType::wall || bc.type == BcType::slip) {
      for (int k = k0; k < k1; ++k) at(nf, a, b, k) = 0;
      m_speed[s] = bc.type == BcType::wall ? bc.wall_speed(t) : 0.0;
    } else if (bc.type == BcType::inflow) {
      for (int k = k0; k < k1; ++k) at(nf, a, b, k) = sign_in * inflow(s, o.centre(k), t);
    } else {  // outflow
      const int b1 = hi ? b - 1 : 1, b2 = hi ? b - 2 : 2;
      const double w = ax.width(hi ? ax.n() - 1 : 0);
      double flux = 0, len = 0;
      m_mine.resize(k1 - k0);
      for (int k = k0; k < k1; ++k) m_mine[k - k0] = sign_in * at(nf, a, b, k) * o.width(k);
      for (double t : whole_side(s)) flux -= t;
      for (int k = 0; k < o.n(); ++k) len += o.width(k);
      const double r_bulk = std::clamp(flux / len * dt / w, 0.0, 1.0);
      std::vector<double>& prev = m_prev[s];
      const bool orlanski = bc.phase == Phase::orlanski && int(prev.size()) == k1 - k0;
      m_mine.resize(k1 - k0);
      for (int k = k0; k < k1; ++k) {
        double r = r_bulk;
        const double q1 = at(nf, a, b1, k);
        if (orlanski) {
          const double den = q1 - at(nf, a, b2, k);
          r = den != 0.0 ? std::clamp(-(q1 - prev[k - k0]) / den, 0.0, 1.0) : 0.0;
        }
        m_mine[k - k0] = r;
        double& qb = at(nf, a, b, k);
        qb -= r * (qb - q1);
      }
      double r_sum = 0;
      for (double r : whole_side(s)) r_sum += r;
      prev.resize(k1 - k0);
      for (int k = k0; k < k1; ++k) prev[k - k0] = at(nf, a, b1, k);
      // Tangential ghost, one cell width beyond the first interior value.
      // (its distance to the first interior value is the first cell's width, w); along a
      // left/right side the v faces of this rank's rows (the top face on the last rank).
      const double r_t = r_sum / o.n();
      const int g = hi ? ax.n() : -1, q0 = hi ? ax.n() - 1 : 0;
      const int t1 = a == 0 ? m_d.v_hi() : here ? o.n() + 1 : 0;
      for (int k = k0; k < t1; ++k) {
        double& gv = at(tf, a, g, k);
        gv -= r_t * (gv - at(tf, a, q0, k));
      }
      out_length += len;
    }
  }
  if (!m_has_outflow) return;
  const double shift = net_inflow(u, v) / out_length;
  for (int s = 0; s < 4; ++s) {
    if (m_bc[s].type != BcType::outflow || !holds(s)) continue;
    const int a = s / 2;
    const bool hi = s % 2;
    Field& nf = a == 0 ? u : v;
    const int b = hi ? m_g.axis(a).n() : 0;
    const double sign_out = hi ? 1.0 : -1.0;
    const int k0 = a == 0 ? row_lo() : 0, k1 = a == 0 ? row_hi() : m_g.axis(1 - a).n();
    for (int k = k0; k < k1; ++k) at(nf, a, b, k) += sign_out * shift;
  }
}

// On several ranks: the loops over rows run over this rank's, a bottom or top side is filled by
// the rank that holds it, and the ghost rows between ranks (and those of a periodic y) come
// from the neighbours last.
void Boundaries::fill_ghosts(Field& u, Field& v) const {
  const int nx = m_g.nx(), ny = m_g.ny();
  const int j0 = row_lo(), j1 = row_hi(), jv1 = m_d.v_hi();
  // x-direction sides first (rows of the interior), then y-direction sides over every column.
  if (m_bc[left].type == BcType::periodic) {
    for (int j = j0; j < j1; ++j) {
      u(nx, j) = u(0, j);
      u(-1, j) = u(nx - 1, j);
      u(nx + 1, j) = u(1, j);
    }
    for (int j = j0; j < jv1; ++j) {
      v(-1, j) = v(nx - 1, j);
      v(nx, j) = v(0, j);
    }
  } else {
    for (int s : {int(left), int(right)}) {
      const GhostRule& r = m_rule[s];
      if (r.is_data) continue;
      const bool hi = s % 2;
      const int g = hi ? nx : -1, q0 = hi ? nx - 1 : 0, q1 = hi ? nx - 2 : 1;
      const double data = m_speed[s];
      for (int j = j0; j < jv1; ++j) v(g, j) = r.ga * v(q0, j) + r.gb * v(q1, j) + r.gc * data;
    }
  }
  if (m_bc[bottom].type == BcType::periodic) {
    if (m_d.serial()) {
      for (int i = -1; i <= nx; ++i) {
        v(i, ny) = v(i, 0);
        v(i, -1) = v(i, ny - 1);
        v(i, ny + 1) = v(i, 1);
      }
      for (int i = -1; i <= nx + 1; ++i) {
        u(i, -1) = u(i, ny - 1);
        u(i, ny) = u(i, 0);
      }
    }
  } else {
    for (int s : {int(bottom), int(top)}) {
      const GhostRule& r = m_rule[s];
      if (r.is_data || !holds(s)) continue;
      const bool hi = s % 2;
      const int g = hi ? ny : -1, q0 = hi ? ny - 1 : 0, q1 = hi ? ny - 2 : 1;
      const double data = m_speed[s];
      for (int i = -1; i <= nx + 1; ++i) u(i, g) = r.ga * u(i, q0) + r.gb * u(i, q1) + r.gc * data;
    }
  }
  m_d.halo(u);
  m_d.halo(v);
}

void Boundaries::fill_scalar(Field& p, const FacePressure& face) const {
  const int nx = m_g.nx(), ny = m_g.ny();
  const bool px = m_bc[left].type == BcType::periodic, py = m_bc[bottom].type == BcType::periodic;
  const bool dl = is_pressure(left) && !face[0].empty(), dr = is_pressure(right) && !face[1].empty();
  for (int j = row_lo(); j < row_hi(); ++j) {
    p(-1, j) = px ? p(nx - 1, j) : dl ? 2 * face[0][j] - p(0, j) : p(0, j);
    p(nx, j) = px ? p(0, j) : dr ? 2 * face[1][j] - p(nx - 1, j) : p(nx - 1, j);
  }
  if (m_d.serial() || !py) {
    if (m_d.has_bottom())
      for (int i = -1; i <= nx; ++i) p(i, -1) = py ? p(i, ny - 1) : p(i, 0);
    if (m_d.has_top())
      for (int i = -1; i <= nx; ++i) p(i, ny) = py ? p(i, 0) : p(i, ny - 1);
  }
  m_d.halo(p);
}

}  // namespace fluid
