// Set-up of the fiber system: initial marker layout of every fiber (straight, arc or given
// points at uniform arclength), lumped masses, the laws of supported ends and of prescribed
// fibers, and the check that no two fibers start overlapping.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "error.hpp"
#include "system.hpp"

namespace fiber {

namespace {

Vec2 unit(double angle) { return {std::cos(angle), std::sin(angle)}; }

Vec2 at(std::span<const double> x, std::size_t i) { return {x[2 * i], x[2 * i + 1]}; }

void put(std::span<double> x, std::size_t i, const Vec2& v) {
  x[2 * i] = v.x();
  x[2 * i + 1] = v.y();
}

// Beating law: tangent angle at the mid-point of each segment, markers integrated from the root
// with the mid-point rule, so that every segment keeps length ds exactly:
//   X_{j+1} = X_j + ds (cos psi_{j+1/2}, sin psi_{j+1/2}),
//   psi(s, t) = angle + amplitude sin(2 pi f t - 2 pi s / wavelength + phase).
void beating_shape(const FiberSpec& f, double t, std::span<double> x) {
  const double ds = f.ds();
  const double k = f.motion.wavelength > 0 ? 2 * std::numbers::pi / f.motion.wavelength : 0.0;
  const double w = 2 * std::numbers::pi * f.motion.frequency;
  Vec2 p = f.position;
  put(x, 0, p);
  for (int j = 0; j < f.segments; ++j) {
    const double s = (j + 0.5) * ds;
    const double psi = f.angle + f.motion.amplitude * std::sin(w * t - k * s + f.motion.phase);
    p += ds * unit(psi);
    put(x, j + 1, p);
  }
}

std::string where(const Config& c) { return c.file.empty() ? std::string() : " (in " + c.file + ")"; }

}  // namespace

const char* end_kind_name(EndKind k) {
  switch (k) {
    case EndKind::free: return "free";
    case EndKind::clamped: return "clamped";
    case EndKind::hinged: return "hinged";
    case EndKind::attached: return "attached";
  }
  return "?";
}

const char* motion_kind_name(MotionKind k) {
  switch (k) {
    case MotionKind::dynamic: return "dynamic";
    case MotionKind::fixed: return "fixed";
    case MotionKind::translating: return "translating";
    case MotionKind::rotating: return "rotating";
    case MotionKind::beating: return "beating";
  }
  return "?";
}

Vec2 EndLaw::position_at(double t) const {
  return position + velocity * t + amplitude * std::sin(2 * std::numbers::pi * frequency * t + phase);
}

double EndLaw::angle_at(double t) const {
  return angle + angular_velocity * t +
         angle_amplitude * std::sin(2 * std::numbers::pi * frequency * t + phase);
}

FiberSystem::FiberSystem(Config config) : m_config(std::move(config)) {
  const auto& cfg = m_config;
  const std::string in = where(cfg);
  if (cfg.substeps < 1) throw fsi::InputError(fmt::format("fiber.substeps must be >= 1, got {}{}", cfg.substeps, in));

  // Sizes and offsets.
  std::size_t markers = 0, segments = 0;
  m_fibers.resize(cfg.fibers.size());
  for (std::size_t k = 0; k < cfg.fibers.size(); ++k) {
    const FiberSpec& f = cfg.fibers[k];
    if (!(f.length > 0))
      throw fsi::InputError(fmt::format("{}.length must be > 0, got {}{}", f.key, f.length, in));
    if (f.segments < 2)
      throw fsi::InputError(fmt::format("{}.segments must be >= 2, got {}{}", f.key, f.segments, in));
    if (!f.is_prescribed() && !(f.density > 0))
      throw fsi::InputError(fmt::format(
          "{}.density must be > 0 for a fiber that follows the equation of motion, got {}{}", f.key,
          f.density, in));
    if (f.density < 0 || f.bending < 0 || f.damping < 0)
      throw fsi::InputError(fmt::format("{}: density, bending and damping must be >= 0{}", f.key, in));
    Fiber& s = m_fibers[k];
    s.segments = f.segments;
    s.ds = f.ds();
    s.offset = markers;
    s.seg_offset = segments;
    s.is_prescribed = f.is_prescribed();
    s.is_root_fixed = !s.is_prescribed && f.root.is_supported();
    s.is_tip_fixed = !s.is_prescribed && f.tip.is_supported();
    markers += f.segments + 1;
    segments += f.segments;
  }
  m_x.assign(2 * markers, 0.0);
  m_mass.assign(markers, 0.0);
  m_weight.assign(markers, 0.0);
  m_owner.assign(markers, 0);
  m_tension.assign(segments, 0.0);

  // Marker positions and masses.
  for (std::size_t k = 0; k < cfg.fibers.size(); ++k) {
    FiberSpec& f = m_config.fibers[k];
    Fiber& s = m_fibers[k];
    const int n = f.segments;
    std::span<double> x(m_x.data() + 2 * s.offset, 2 * (n + 1));
    if (f.motion.kind == MotionKind::beating) {
      beating_shape(f, 0.0, x);
    } else if (f.shape == ShapeKind::points) {
      if (static_cast<int>(f.points.size()) != n + 1)
        throw fsi::InputError(fmt::format("{}: the shape has {} points, expected segments + 1 = {}{}", f.key,
                                          f.points.size(), n + 1, in));
      // Uniform arclength within 1e-6; the small remainder is removed along each segment.
      Vec2 p = f.points[0];
      put(x, 0, p);
      for (int j = 0; j < n; ++j) {
        const Vec2 d = f.points[j + 1] - f.points[j];
        const double len = d.norm();
        if (!(std::abs(len / s.ds - 1) <= 1e-6))
          throw fsi::InputError(fmt::format(
              "{}: segment {} of the given shape has length {:.9g}, expected ds = length / segments "
              "= {:.9g}: markers must be at uniform arclength{}",
              f.key, j, len, s.ds, in));
        p += s.ds * d / len;
        put(x, j + 1, p);
      }
      f.position = f.points[0];
    } else {
      // Straight or arc: tangent angle psi(s) = angle + curvature s at the segment mid-points.
      Vec2 p = f.position;
      put(x, 0, p);
      for (int j = 0; j < n; ++j) {
        const double psi = f.angle + (f.shape == ShapeKind::arc ? f.curvature * (j + 0.5) * s.ds : 0.0);
        p += s.ds * unit(psi);
        put(x, j + 1, p);
      }
    }
    for (int i = 0; i <= n; ++i) {
      const double w = (i == 0 || i == n) ? 0.5 : 1.0;
      m_weight[s.offset + i] = w * s.ds;
      m_mass[s.offset + i] = f.density * w * s.ds;
      m_owner[s.offset + i] = static_cast<int>(k);
    }
  }

  // Supported ends: the law's position and angle default to the fiber's end at t = 0; given
  // ones must match where the fiber starts.
  for (std::size_t k = 0; k < cfg.fibers.size(); ++k) {
    FiberSpec& f = m_config.fibers[k];
    Fiber& s = m_fibers[k];
    const std::span<const double> x(m_x.data() + 2 * s.offset, 2 * (s.segments + 1));
    if (f.is_prescribed()) continue;
    if (f.bending == 0 && (f.root.kind == EndKind::clamped || f.root.kind == EndKind::attached ||
                           f.tip.kind == EndKind::clamped))
      throw fsi::InputError(fmt::format(
          "{}: a clamped end needs bending > 0 (a fiber without bending rigidity cannot hold a "
          "direction); use a hinged end{}",
          f.key, in));
    if (f.tip.kind == EndKind::attached)
      throw fsi::InputError(fmt::format(
          "{}.tip.kind = \"attached\": only the root (s = 0) can be attached to a solid{}", f.key, in));
    const int n = s.segments;
    const double tol = 1e-9 * f.length;
    for (int e = 0; e < 2; ++e) {
      EndLaw& law = e == 0 ? f.root : f.tip;
      if (law.kind == EndKind::free) continue;
      const Vec2 q = at(x, e == 0 ? 0 : n);
      const Vec2 d = e == 0 ? at(x, 1) - at(x, 0) : at(x, n) - at(x, n - 1);
      if (!law.has_position) law.position = q;
      if (!law.has_angle) law.angle = std::atan2(d.y(), d.x());
      if (law.kind == EndKind::attached) {
        s.root_pose_old = {q, d.normalized()};
        s.root_pose_new = s.root_pose_old;
        continue;
      }
      const Vec2 p = law.position_at(0.0);
      if ((p - q).norm() > tol)
        throw fsi::InputError(fmt::format(
            "{}.{}: the support is at ({:.9g}, {:.9g}) at t = 0 but the fiber's {} is at ({:.9g}, {:.9g}){}",
            f.key, e == 0 ? "root" : "tip", p.x(), p.y(), e == 0 ? "root" : "tip", q.x(), q.y(), in));
    }
  }

  m_x_initial = m_x;
  m_x_old = m_x;
  m_x_new = m_x;
  m_x_star = m_x;
  m_x_step_old = m_x;
  m_force.assign(m_x.size(), 0.0);
  m_repulsion.assign(m_x.size(), 0.0);
  m_coef.assign(markers, 0.0);
  m_ref.assign(2 * segments, 0.0);
  m_lo.assign(segments, 0.0);
  m_di.assign(segments, 0.0);
  m_up.assign(segments, 0.0);
  m_rhs.assign(segments, 0.0);
  m_root_acc.assign(cfg.fibers.size(), EndLoad{});
  m_tip_acc.assign(cfg.fibers.size(), EndLoad{});

  // Overlap: markers of different fibers closer than the repulsion cut-off (the repulsion
  // potential is singular) or, without repulsion, practically coincident.
  double min_ds = std::numeric_limits<double>::infinity();
  for (const auto& s : m_fibers) min_ds = std::min(min_ds, s.ds);
  if (m_fibers.empty()) return;
  const double gap = cfg.repulsion.is_enabled ? cfg.repulsion.cutoff : 1e-3 * min_ds;
  m_cells.build(m_x, gap);
  m_cells.for_each_pair(m_x, gap, [&](std::size_t i, std::size_t j, double, double, double r2) {
    const int a = m_owner[i], b = m_owner[j];
    if (a == b) return;
    const auto& fa = cfg.fibers[a];
    const auto& fb = cfg.fibers[b];
    const std::string rule =
        cfg.repulsion.is_enabled
            ? fmt::format("closer than the repulsion cut-off fiber.repulsion.cutoff = {}", cfg.repulsion.cutoff)
            : fmt::format("closer than {:.3g} (1e-3 ds): they coincide", gap);
    throw fsi::InputError(fmt::format(
        "fibers '{}' ({}) and '{}' ({}) start overlapping: marker {} of '{}' at ({:.6g}, {:.6g}) and marker {} "
        "of '{}' at ({:.6g}, {:.6g}) are {:.3g} apart, {}{}",
        fa.name, fa.key, fb.name, fb.key, i - m_fibers[a].offset, fa.name, m_x[2 * i], m_x[2 * i + 1],
        j - m_fibers[b].offset, fb.name, m_x[2 * j], m_x[2 * j + 1], std::sqrt(r2), rule, in));
  });
}

void FiberSystem::place_root(int k, const EndPose& pose) {
  if (m_steps > 0) fsi::fail("FiberSystem::place_root() is for set-up, before the first step");
  const FiberSpec& f = m_config.fibers[k];
  Fiber& s = m_fibers[k];
  const Vec2 dir = pose.direction.normalized();
  for (int i = 0; i <= s.segments; ++i) {
    const Vec2 p = pose.position + i * s.ds * dir;
    for (auto* v : {&m_x, &m_x_old, &m_x_new, &m_x_star, &m_x_step_old}) put(*v, s.offset + i, p);
  }
  s.root_pose_old = {pose.position, dir};
  s.root_pose_new = s.root_pose_old;
  (void)f;
}

// Positions of a prescribed fiber at time t (x: that fiber's markers).
void FiberSystem::prescribe(int k, double t, std::span<double> x) const {
  const FiberSpec& f = m_config.fibers[k];
  const Fiber& s = m_fibers[k];
  const std::span<const double> x0(m_x_initial.data() + 2 * s.offset, 2 * (s.segments + 1));
  switch (f.motion.kind) {
    case MotionKind::dynamic:
    case MotionKind::fixed:
      std::copy(x0.begin(), x0.end(), x.begin());
      break;
    case MotionKind::translating:
      for (int i = 0; i <= s.segments; ++i) put(x, i, at(x0, i) + f.motion.velocity * t);
      break;
    case MotionKind::rotating: {
      const double c = std::cos(f.motion.angular_velocity * t), sn = std::sin(f.motion.angular_velocity * t);
      for (int i = 0; i <= s.segments; ++i) {
        const Vec2 r = at(x0, i) - f.motion.center;
        put(x, i, f.motion.center + Vec2(c * r.x() - sn * r.y(), sn * r.x() + c * r.y()));
      }
      break;
    }
    case MotionKind::beating:
      beating_shape(f, t, x);
      break;
  }
}

// Pose of fiber k's root or tip at time t; attached roots interpolate between the poses handed
// in at t^n and t^(n+1) with weight w in [0, 1].
EndPose FiberSystem::end_pose(int k, bool is_root, double t, double w) const {
  const FiberSpec& f = m_config.fibers[k];
  const EndLaw& law = is_root ? f.root : f.tip;
  if (law.kind == EndKind::attached) {
    const Fiber& s = m_fibers[k];
    EndPose p;
    p.position = (1 - w) * s.root_pose_old.position + w * s.root_pose_new.position;
    p.direction = ((1 - w) * s.root_pose_old.direction + w * s.root_pose_new.direction).normalized();
    return p;
  }
  return {law.position_at(t), unit(law.angle_at(t))};
}

}  // namespace fiber
