// [fiber] scene table -> fiber::Config (see config.hpp, and README.md for the keys): rows of
// fibers expanded, end and motion laws in radians, probes resolved to fiber indices.
#include "config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "system.hpp"

namespace fiber {

namespace {

constexpr double kDeg = std::numbers::pi / 180;

Vec2 vec(const std::array<double, 2>& a) { return {a[0], a[1]}; }

// Marker positions from a text file: one "x, y" (or "x y") pair per line; empty lines and lines
// starting with '#' or a letter (a header) are skipped.
std::vector<Vec2> read_points(const fsi::SceneTable& t, std::string_view key) {
  const auto path = t.existing_file(key);
  std::ifstream in(path);
  std::vector<Vec2> pts;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#' || std::isalpha(static_cast<unsigned char>(line[first])))
      continue;
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t') c = ' ';
    std::istringstream is(line);
    double x = 0, y = 0;
    if (!(is >> x >> y) || !std::isfinite(x) || !std::isfinite(y))
      t.fail(key, fmt::format("names '{}', whose line {} is not a pair of numbers x, y", path.string(), line_no));
    pts.emplace_back(x, y);
  }
  return pts;
}

EndLaw read_end(const fsi::SceneTable& t, bool is_root, bool is_prescribed) {
  EndLaw e;
  std::vector<std::string> kinds = {"free", "clamped", "hinged"};
  if (is_root) kinds.push_back("attached");
  const std::string kind = t.choice("kind", kinds, std::string("free"));
  if (is_prescribed && kind != "free")
    t.fail("kind", "cannot hold a fiber with a prescribed motion (fiber.fiber.motion): its markers follow the law");
  e.kind = kind == "clamped" ? EndKind::clamped
           : kind == "hinged" ? EndKind::hinged
           : kind == "attached" ? EndKind::attached
                                : EndKind::free;
  if (e.kind == EndKind::free) {
    t.finish();
    return e;
  }
  if (e.kind == EndKind::attached) {
    e.body = t.string("body");
    if (e.body.empty()) t.fail("body", "must name the solid body that holds the root, got \"\"");
    e.point = vec(t.vec2("point"));
    t.finish();
    return e;
  }
  e.has_position = t.has("position");
  if (e.has_position) e.position = vec(t.vec2("position"));
  else t.skip("position");
  const bool is_clamped = e.kind == EndKind::clamped;
  if (is_clamped) {
    e.has_angle = t.has("angle");
    if (e.has_angle) e.angle = t.number("angle") * kDeg;
    else t.skip("angle");
    e.angular_velocity = t.number("angular_velocity", 0.0) * kDeg;
    e.angle_amplitude = t.number("angle_amplitude", 0.0) * kDeg;
  }
  e.velocity = vec(t.vec2("velocity", {0.0, 0.0}));
  e.amplitude = vec(t.vec2("amplitude", {0.0, 0.0}));
  e.frequency = t.non_negative("frequency", 0.0);
  e.phase = t.number("phase", 0.0) * kDeg;
  t.finish();
  return e;
}

MotionLaw read_motion(const fsi::SceneTable& t) {
  MotionLaw m;
  const std::string kind = t.choice("kind", {"fixed", "translating", "rotating", "beating"});
  if (kind == "fixed") {
    m.kind = MotionKind::fixed;
  } else if (kind == "translating") {
    m.kind = MotionKind::translating;
    m.velocity = vec(t.vec2("velocity"));
  } else if (kind == "rotating") {
    m.kind = MotionKind::rotating;
    m.center = vec(t.vec2("center"));
    m.angular_velocity = t.number("angular_velocity") * kDeg;
  } else {
    m.kind = MotionKind::beating;
    m.frequency = t.positive("frequency");
    m.amplitude = t.number("amplitude") * kDeg;
    m.wavelength = t.non_negative("wavelength", 0.0);
    m.phase = t.number("phase", 0.0) * kDeg;
  }
  t.finish();
  return m;
}

}  // namespace

Config read_config(const fsi::SceneTable& fiber) {
  Config c;
  c.file = fiber.file().string();
  c.substeps = static_cast<int>(fiber.positive_integer("substeps", 1));
  c.gravity = vec(fiber.vec2("gravity", {0.0, 0.0}));
  c.stretch_limit = fiber.positive("stretch_limit", 1e-4);
  c.tension_tolerance = fiber.positive("tension_tolerance", 1e-12);
  c.tension_iterations = static_cast<int>(fiber.positive_integer("tension_iterations", 8));

  if (auto rep = fiber.optional_table("repulsion")) {
    c.repulsion.is_enabled = true;
    c.repulsion.stiffness = rep->positive("stiffness");
    c.repulsion.cutoff = rep->positive("cutoff");
    rep->finish();
  }

  // An empty [fiber] is a scene without fibers (the program then runs with nothing to move).
  const auto tables = fiber.tables("fiber");
  std::map<std::string, std::string> names;  // name -> key, for duplicates and probes
  double markers = 0;  // over every fiber table so far, for the memory estimate
  for (const auto& t : tables) {
    FiberSpec f;
    f.key = t.path();
    const std::string base = t.string("name");
    if (base.empty() || base.find_first_of(" ,\"'\n") != std::string::npos)
      t.fail("name", "must be a non-empty name without spaces, commas or quotes");
    f.length = t.positive("length");
    const long segments = t.integer("segments");
    if (segments < 2) t.fail("segments", fmt::format("must be >= 2, got {}", segments));
    if (segments > 1000000) t.fail("segments", fmt::format("must be <= 1000000, got {}", segments));
    f.segments = static_cast<int>(segments);
    f.bending = t.non_negative("bending");
    f.damping = t.non_negative("damping", 0.0);

    std::optional<fsi::SceneTable> motion = t.optional_table("motion");
    if (motion) f.motion = read_motion(*motion);
    // A fiber that follows the equation of motion needs mass; a prescribed one may have none
    // (its density only enters the load on its driver).
    f.density = f.is_prescribed() ? t.non_negative("density", 0.0) : t.positive("density");

    const auto root = t.optional_table("root");
    if (root) f.root = read_end(*root, true, f.is_prescribed());
    const auto tip = t.optional_table("tip");
    if (tip) f.tip = read_end(*tip, false, f.is_prescribed());

    // Initial shape. An attached root starts at its surface point; a "points" shape at its
    // first point.
    const std::string shape = t.choice("shape", {"straight", "arc", "points"}, std::string("straight"));
    if (shape == "points") {
      f.shape = ShapeKind::points;
      if (t.has("position")) t.fail("position", "is the first point of the file for shape = \"points\"; remove it");
      t.skip("position");
      f.points = read_points(t, "points");
      if (static_cast<long>(f.points.size()) != segments + 1)
        t.fail("points", fmt::format("has {} points, expected segments + 1 = {}", f.points.size(), segments + 1));
      f.position = f.points[0];
    } else if (f.root.kind == EndKind::attached) {
      if (t.has("position"))
        t.fail("position", "is taken from root.point for a root attached to a solid; remove it");
      t.skip("position");
      f.position = f.root.point;
    } else {
      f.position = vec(t.vec2("position"));
    }
    f.angle = t.number("angle", 0.0) * kDeg;
    if (shape == "arc") {
      f.shape = ShapeKind::arc;
      f.curvature = t.number("curvature");
    }
    if (f.motion.kind == MotionKind::beating && shape != "straight")
      t.fail("shape", "is set by the beating law for motion.kind = \"beating\"; remove it");
    if (f.root.kind == EndKind::attached && shape == "points")
      t.fail("shape", "must be \"straight\" or \"arc\" for a root attached to a solid (it starts at root.point)");
    // Clamped ends hold the shape's tangent at t = 0 unless an angle is given.
    if (f.shape != ShapeKind::points) {
      if (f.root.kind == EndKind::clamped && !f.root.has_angle) {
        f.root.angle = f.angle;
        f.root.has_angle = true;
      }
      if (f.tip.kind == EndKind::clamped && !f.tip.has_angle) {
        f.tip.angle = f.angle + (f.shape == ShapeKind::arc ? f.curvature * f.length : 0.0);
        f.tip.has_angle = true;
      }
    }

    // A row of identical fibers: fiber i of the row is shifted by i * spacing.
    const long count = t.positive_integer("count", 1);
    const Vec2 spacing = count > 1 ? vec(t.vec2("spacing")) : vec(t.vec2("spacing", {0.0, 0.0}));
    if (count > 1 && spacing.norm() == 0) t.fail("spacing", "must be non-zero for a row of fibers (count > 1)");
    // About 40 doubles a marker (X^n, X^(n-1), velocity, forces, tension, the tension solve,
    // the repulsion's cell lists), over every fiber of the scene so far: less than it takes.
    constexpr double kBytesPerMarker = 40 * 8;
    markers += static_cast<double>(count) * static_cast<double>(segments + 1);
    fsi::check_memory(t, "count", markers * kBytesPerMarker,
                      fmt::format("{} fiber(s) of {} markers ({:.3g} markers in the scene so far)",
                                  count, segments + 1, markers));
    t.finish();

    for (long i = 0; i < count; ++i) {
      FiberSpec g = f;
      g.name = count > 1 ? fmt::format("{}_{}", base, i) : base;
      g.key = count > 1 ? fmt::format("{} (fiber {} of the row)", f.key, i) : f.key;
      const Vec2 shift = static_cast<double>(i) * spacing;
      g.position += shift;
      for (auto& p : g.points) p += shift;
      for (EndLaw* e : {&g.root, &g.tip}) {
        e->position += shift;
        e->point += shift;
      }
      if (f.motion.kind == MotionKind::rotating) g.motion.center += shift;
      if (auto [it, is_new] = names.emplace(g.name, g.key); !is_new)
        t.fail("name", fmt::format("\"{}\" is used twice (also by {})", g.name, it->second));
      c.fibers.push_back(std::move(g));
    }
  }

  c.probe_interval = fiber.non_negative("probe_interval", 0.0);
  for (const auto& t : fiber.tables("probe")) {
    ProbeSpec p;
    p.name = t.string("name");
    if (p.name.empty() || p.name.find_first_of(" ,.\"'\n") != std::string::npos)
      t.fail("name", "must be a non-empty name without spaces, commas, dots or quotes");
    const std::string on = t.string("fiber");
    p.fiber = -1;
    for (std::size_t k = 0; k < c.fibers.size(); ++k)
      if (c.fibers[k].name == on) p.fiber = static_cast<int>(k);
    if (p.fiber < 0) {
      std::vector<std::string> all;
      for (const auto& f : c.fibers) all.push_back(f.name);
      t.fail("fiber", fmt::format("names no fiber of the scene; fibers: {}", fmt::join(all, ", ")));
    }
    const double length = c.fibers[p.fiber].length;
    p.s = t.in_range("s", 0.0, length, false);
    for (const auto& q : c.probes)
      if (q.name == p.name) t.fail("name", fmt::format("\"{}\" is used by two probes", p.name));
    t.finish();
    c.probes.push_back(p);
  }
  fiber.finish();
  return c;
}

void check_attachments(const Config& config, const fsi::SceneTable& fiber, bool has_solid) {
  if (has_solid) return;
  const auto tables = fiber.tables("fiber");
  for (const auto& f : config.fibers) {
    if (f.root.kind != EndKind::attached) continue;
    const std::string path = f.key.substr(0, f.key.find(' '));
    for (const auto& t : tables) {
      if (t.path() != path) continue;
      t.table("root").fail("body", fmt::format(
          "= \"{}\": no solid body can hold this root, because the scene has no [solid] section; "
          "use root.kind = \"clamped\" or add the body",
          f.root.body));
    }
  }
}

void check_time_step(const Config& config, double dt) {
  if (const std::string problem = time_step_problem(config, dt); !problem.empty())
    throw fsi::InputError(problem);
}

}  // namespace fiber
