// What the fiber system reports besides its state: the explicit bending limit, stretch, marker
// tension and curvature, kinetic energy, and views of the flat arrays per fiber.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "system.hpp"

namespace fiber {

namespace {
Vec2 at(std::span<const double> x, std::size_t i) { return {x[2 * i], x[2 * i + 1]}; }
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
// Signed turning angle from a to b.
double turn(const Vec2& a, const Vec2& b) { return std::atan2(cross(a, b), a.dot(b)); }
}  // namespace

// Von Neumann analysis of X^(n+1) - 2 X^n + X^(n-1) = -dt^2 lambda (2 X^n - X^(n-1)) for one
// mode of the bending operator (lambda = gamma mu / rho', mu its eigenvalue): the amplification
// z solves z^2 - (2 - 2a) z + (1 - a) = 0 with a = dt^2 lambda, and |z| <= 1 iff a <= 4/3.
// Gershgorin bounds mu by 16 / ds^4 (interior rows 1 -4 6 -4 1 over the lumped mass; the end
// rows stay below it), so dt <= sqrt(4/3) ds^2 / 4 sqrt(rho'/gamma) = ds^2 sqrt(rho' / (12 gamma)).
double bending_dt_limit(const FiberSpec& f) {
  if (f.is_prescribed() || !(f.bending > 0)) return std::numeric_limits<double>::infinity();
  const double ds = f.ds();
  return ds * ds * std::sqrt(f.density / (12 * f.bending));
}

std::string time_step_problem(const Config& config, double dt) {
  const int m = std::max(config.substeps, 1);
  const double h = dt / m;
  for (const FiberSpec& f : config.fibers) {
    const double limit = bending_dt_limit(f);
    if (h <= limit * (1 + 1e-12)) continue;
    const long need = static_cast<long>(std::ceil(dt / limit * (1 - 1e-12)));
    return fmt::format(
        "time.dt = {:.6g}{} is above the explicit bending stability limit of fiber '{}' ({}): "
        "dt <= ds^2 sqrt(rho'/(12 gamma)) = {:.6g} (ds = {:.6g}, density = {:.6g}, bending = {:.6g}); lower "
        "time.dt to {:.6g} or set fiber.substeps >= {}{}",
        dt, m > 1 ? fmt::format(" / fiber.substeps = {} = {:.6g}", m, h) : std::string(), f.name, f.key,
        limit, f.ds(), f.density, f.bending, limit, need,
        config.file.empty() ? std::string() : fmt::format(" (in {})", config.file));
  }
  return {};
}

double FiberSystem::marker_arclength(int k, int i) const { return m_weight[m_fibers[k].offset + i]; }

std::span<const double> FiberSystem::positions(int k) const {
  return {m_x.data() + 2 * m_fibers[k].offset, 2 * static_cast<std::size_t>(m_fibers[k].segments + 1)};
}

std::span<const double> FiberSystem::previous_positions(int k) const {
  return {m_x_step_old.data() + 2 * m_fibers[k].offset, 2 * static_cast<std::size_t>(m_fibers[k].segments + 1)};
}

std::span<const double> FiberSystem::segment_tension(int k) const {
  return {m_tension.data() + m_fibers[k].seg_offset, static_cast<std::size_t>(m_fibers[k].segments)};
}

double FiberSystem::max_stretch(int k) const {
  const Fiber& s = m_fibers[k];
  double worst = 0;
  for (int j = 0; j < s.segments; ++j) {
    const Vec2 d = at(m_x, s.offset + j + 1) - at(m_x, s.offset + j);
    worst = std::max(worst, std::abs(d.norm() / s.ds - 1));
  }
  return worst;
}

double FiberSystem::max_stretch() const {
  double worst = 0;
  for (int k = 0; k < fiber_count(); ++k) worst = std::max(worst, max_stretch(k));
  return worst;
}

void FiberSystem::marker_tension(int k, std::vector<double>& out) const {
  const Fiber& s = m_fibers[k];
  const FiberSpec& f = m_config.fibers[k];
  const int n = s.segments;
  const double* T = m_tension.data() + s.seg_offset;
  out.resize(n + 1);
  for (int i = 1; i < n; ++i) out[i] = 0.5 * (T[i - 1] + T[i]);
  out[0] = f.root.kind == EndKind::free || s.is_prescribed ? 0.0 : T[0];
  out[n] = f.tip.kind == EndKind::free || s.is_prescribed ? 0.0 : T[n - 1];
}

void FiberSystem::marker_curvature(int k, std::vector<double>& out) const {
  const Fiber& s = m_fibers[k];
  const FiberSpec& f = m_config.fibers[k];
  const int n = s.segments;
  const std::size_t o = s.offset;
  out.resize(n + 1);
  for (int i = 1; i < n; ++i)
    out[i] = turn(at(m_x, o + i) - at(m_x, o + i - 1), at(m_x, o + i + 1) - at(m_x, o + i)) / s.ds;
  out[0] = out[n] = 0;
  if (s.is_prescribed) return;
  // Clamped ends: the ghost marker X_{-1} = X_1 - 2 ds tau (root), X_{N+1} = X_{N-1} + 2 ds tau (tip).
  if (f.root.kind == EndKind::clamped || f.root.kind == EndKind::attached) {
    const EndPose p = end_pose(k, true, m_time, 1.0);
    const Vec2 ghost = at(m_x, o + 1) - 2 * s.ds * p.direction;
    out[0] = turn(at(m_x, o) - ghost, at(m_x, o + 1) - at(m_x, o)) / s.ds;
  }
  if (f.tip.kind == EndKind::clamped) {
    const EndPose p = end_pose(k, false, m_time, 1.0);
    const Vec2 ghost = at(m_x, o + n - 1) + 2 * s.ds * p.direction;
    out[n] = turn(at(m_x, o + n) - at(m_x, o + n - 1), ghost - at(m_x, o + n)) / s.ds;
  }
}

double FiberSystem::kinetic_energy(int k) const {
  if (m_last_h <= 0) return 0;
  const Fiber& s = m_fibers[k];
  double e = 0;
  for (int i = 0; i <= s.segments; ++i) {
    const std::size_t q = s.offset + i;
    e += 0.5 * m_mass[q] * ((at(m_x, q) - at(m_x_old, q)) / m_last_h).squaredNorm();
  }
  return e;
}

}  // namespace fiber
