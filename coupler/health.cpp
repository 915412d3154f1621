// The coupler's health checks: bodies and fibers inside the fluid domain, the growth of the
// explicit coupling, element and marker sizes against the grid (README.md, "Checks").
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "coupler.hpp"

namespace coupler {

namespace {

// Mean element edges above this many grid spacings are only resolved at the grid's scale.
constexpr double kCoarseElements = 4;
// Mean element edges below 1/kFineElements of a grid spacing cost clipping work for nothing.
constexpr double kFineElements = 8;
// Fiber markers farther apart than this many grid spacings let the fluid leak between them.
constexpr double kMarkerGap = 2;
// A node beyond a non-periodic boundary by less than this fraction of the domain is on it.
constexpr double kRoundOff = 1e-10;

}  // namespace

// The non-periodic boundary a point (x, y) is beyond, or nullptr when it is inside the domain.
// A node held on a wall (by a contact plane there, or a fixed node of the mesh) may sit a
// round-off beyond it, y = -1e-17 against a wall at 0: forgiven up to kRoundOff of the domain's
// extent in that direction. Clipping drops what lies outside the cells, here nothing to speak of.
const char* Coupler::outside(double x, double y) const {
  const double tx = kRoundOff * (m_grid.x_face.back() - m_grid.x_face.front());
  const double ty = kRoundOff * (m_grid.y_face.back() - m_grid.y_face.front());
  if (!m_grid.periodic_x && x < m_grid.x_face.front() - tx) return "left";
  if (!m_grid.periodic_x && x > m_grid.x_face.back() + tx) return "right";
  if (!m_grid.periodic_y && y < m_grid.y_face.front() - ty) return "bottom";
  if (!m_grid.periodic_y && y > m_grid.y_face.back() + ty) return "top";
  return nullptr;
}

// A body must stay inside the fluid domain, except across a periodic boundary.
void Coupler::check_bodies_in_domain(long step) const {
  const double x0 = m_grid.x_face.front(), x1 = m_grid.x_face.back();
  const double y0 = m_grid.y_face.front(), y1 = m_grid.y_face.back();
  for (std::size_t b = 0; b < m_meshes.bodies.size(); ++b) {
    const auto& x = m_solid.x[b];
    for (std::size_t k = 0; k + 1 < x.size(); k += 2) {
      if (const char* side = outside(x[k], x[k + 1])) {
        // Thrown out by the explicit coupling's instability before check_growth() could count
        // growth_steps steps of it: say so, it is the cause to fix.
        const long grew = b < m_growing.size() ? m_growing[b] : 0;
        const std::string cause =
            grew > 0 ? fmt::format("; its motion grew and reversed in the {} step(s) before: the "
                                   "explicit coupling cannot hold this body at this density "
                                   "ratio (make it heavier, or turn on coupled iterations, "
                                   "[coupler.iterations] max > 1)",
                                   grew)
                     : std::string();
        fsi::fail("body '{}' is outside the fluid domain [{}, {}] x [{}, {}] through its {} "
                  "boundary at step {}: node {} at ({}, {}){}",
                  m_meshes.bodies[b].name, x0, x1, y0, y1, side, step, k / 2, x[k], x[k + 1],
                  cause);
      }
    }
  }
}

// A fiber must stay inside the fluid domain, except across a periodic boundary: outside, its
// markers would neither feel the fluid nor act on it.
void Coupler::check_fibers_in_domain(long step) const {
  const double x0 = m_grid.x_face.front(), x1 = m_grid.x_face.back();
  const double y0 = m_grid.y_face.front(), y1 = m_grid.y_face.back();
  for (std::size_t k = 0; k < m_fiber.x.size() && k < m_layout.fibers.size(); ++k) {
    const auto& x = m_fiber.x[k];
    for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
      if (const char* side = outside(x[m], x[m + 1]))
        fsi::fail("fiber '{}' left the fluid domain [{}, {}] x [{}, {}] through its {} boundary "
                  "at step {}: marker {} at ({:.6g}, {:.6g})",
                  m_layout.fibers[k].name, x0, x1, y0, y1, side, step, m / 2, x[m], x[m + 1]);
    }
  }
}

// The explicit coupling of a body light against the fluid can be unstable at a given Δt: the
// fluid's reaction overshoots the body's own inertia, the motion reverses and grows every step
// (an amplification factor below −1), and the solid or the fluid fails a few steps later far
// from the cause. Caught here from each elastic body's velocity v (linear on each triangle T,
// integrals exact with ∫_T N_a N_b dA = |T| (1 + δ_ab)/12):
//   E = ½ ∫ |v|² dA = Σ_T |T|/24 (Σ_a |v_a|² + |Σ_a v_a|²)          (kinetic energy / density)
//   C = ∫ vⁿ⁺¹·vⁿ dA = Σ_T |T|/12 (Σ_a vⁿ⁺¹_a·vⁿ_a + Σ_a vⁿ⁺¹_a · Σ_a vⁿ_a)
// A step with E grown by more than coupler.health.growth_factor and C < 0 (the velocity field
// reversed) is a growth step; growth_steps of them in a row stop the run. Physical motion does
// not reverse at every step of the time discretisation while it grows.
void Coupler::check_growth(long step) {
  for (std::size_t b = 0; b < m_meshes.bodies.size() && b < m_solid.x.size(); ++b) {
    const auto& body = m_meshes.bodies[b];
    if (body.kind != proto::BodyKind::elastic) continue;
    const auto& x = m_solid.x[b];
    const auto& v = m_solid.v[b];
    auto& vo = m_velocity[b];
    const bool has_old = vo.size() == v.size();
    double e = 0, c = 0;
    for (std::size_t t = 0; t + 2 < body.tri.size(); t += 3) {
      const int i = body.tri[t], j = body.tri[t + 1], k = body.tri[t + 2];
      const double area = 0.5 * std::abs((x[2 * j] - x[2 * i]) * (x[2 * k + 1] - x[2 * i + 1]) -
                                         (x[2 * k] - x[2 * i]) * (x[2 * j + 1] - x[2 * i + 1]));
      double sq = 0, cr = 0;
      for (int d = 0; d < 2; ++d) {
        const double a = v[2 * i + d], bb = v[2 * j + d], cc = v[2 * k + d];
        sq += a * a + bb * bb + cc * cc + (a + bb + cc) * (a + bb + cc);
        if (has_old) {
          const double ao = vo[2 * i + d], bo = vo[2 * j + d], co = vo[2 * k + d];
          cr += a * ao + bb * bo + cc * co + (a + bb + cc) * (ao + bo + co);
        }
      }
      e += area / 24.0 * sq;
      c += area / 12.0 * cr;
    }
    const double before = m_energy[b];
    const bool grew = has_old && before > 0 && e > m_growth_factor * before && c < 0;
    m_growing[b] = grew ? m_growing[b] + 1 : 0;
    m_energy[b] = e;
    vo = v;
    if (m_growing[b] < m_growth_steps) continue;
    // Fibers rooted on the body: their root loads (roots.cpp) are the other explicit exchange.
    std::string rooted;
    int n_rooted = 0;
    bool has_mass = false;
    for (std::size_t k = 0; k < m_roots.size(); ++k) {
      if (m_roots[k].body != static_cast<int>(b)) continue;
      if (n_rooted++ < 4) rooted += fmt::format("{}'{}'", rooted.empty() ? "" : ", ", m_layout.fibers[k].name);
      for (int i = 0; i < 3 && 3 * k + i < m_fiber.root_mass.size(); ++i)
        has_mass = has_mass || m_fiber.root_mass[3 * k + i] != 0;
    }
    if (n_rooted > 4) rooted += fmt::format(" and {} more", n_rooted - 4);
    const std::string roots =
        n_rooted == 0 ? ""
        : has_mass
            ? fmt::format("; it holds the roots of fibers {}, whose inertia it takes within the "
                          "step: check their root loads (fiber_loads.csv)", rooted)
            : fmt::format("; it holds the roots of fibers {}, whose fiber program sends no root "
                          "mass: their inertia reaches the body one step late, which holds only "
                          "while each fiber is lighter than the nodes that hold it", rooted);
    fsi::fail("body '{}' is unstable at step {}: its kinetic energy per unit density "
              "1/2 int |v|^2 dA = {:.3g} grew by more than a factor {} and its velocity "
              "reversed in each of the last {} steps: the explicit coupling cannot hold this "
              "time.dt = {} (lower it, make the body heavier, or turn on coupled iterations, "
              "[coupler.iterations] max > 1){}",
              body.name, step, e, m_growth_factor, m_growth_steps, m_rt.settings().dt, roots);
  }
}

// Elements much larger than the grid spacing are clipped exactly but forced at the grid's
// resolution; much smaller ones cost clipping work for nothing.
void Coupler::warn_element_sizes() const {
  const double hmin = m_h_min;
  for (const auto& b : m_meshes.bodies) {
    if (b.tri.empty()) continue;
    double sum = 0;
    for (std::size_t e = 0; e + 2 < b.tri.size(); e += 3)
      for (int k = 0; k < 3; ++k) {
        const int i = b.tri[e + k], j = b.tri[e + (k + 1) % 3];
        sum += std::hypot(b.x_ref[2 * j] - b.x_ref[2 * i], b.x_ref[2 * j + 1] - b.x_ref[2 * i + 1]);
      }
    const double h = sum / static_cast<double>(b.tri.size());
    if (h > kCoarseElements * hmin)
      std::fprintf(stderr,
                   "[coupler] WARNING: body '%s' has elements (mean edge %.3g) much larger than the "
                   "grid spacing (%.3g): the volume fractions are still exact, but the forcing "
                   "only resolves the grid\n",
                   b.name.c_str(), h, hmin);
    if (h < hmin / kFineElements)
      std::fprintf(stderr,
                   "[coupler] WARNING: body '%s' has elements (mean edge %.3g) tiny against the "
                   "grid spacing (%.3g): clipping costs grow with no gain in the forcing\n",
                   b.name.c_str(), h, hmin);
  }
}

// Markers far apart against the grid spacing let the fluid through between them.
void Coupler::warn_marker_spacing() const {
  for (const auto& f : m_layout.fibers)
    if (f.ds > kMarkerGap * std::max(m_ib->hx(), m_ib->hy()))
      std::fprintf(stderr,
                   "[coupler] WARNING: fiber '%s' has markers %.3g apart, more than twice the grid "
                   "spacing: the fluid leaks between them\n",
                   f.name.c_str(), f.ds);
}

}  // namespace coupler
