// read_config(): the [solid] table into a solid::Config, strictly (unknown keys are errors, with
// a "did you mean"), with each bad value reported against its key and file.
#include "config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "gmsh_mesh.hpp"
#include "scene.hpp"

namespace solid {

namespace {

// Uniform refinements of a Gmsh mesh: each one quadruples the elements, 6 make 4096 times as
// many, beyond any mesh this solver's direct factorisation handles.
constexpr int kMaxMeshRefine = 6;

TimeFunction read_time(const fsi::SceneTable& t) {
  TimeFunction f;
  const std::string kind = t.choice("time", {"constant", "ramp", "sine"}, "constant");
  if (kind == "ramp") {
    f.kind = TimeFunction::Kind::ramp;
    f.ramp_time = t.positive("ramp_time");
  } else if (kind == "sine") {
    f.kind = TimeFunction::Kind::sine;
    f.frequency = t.positive("frequency");
    f.phase = t.number("phase", 0.0);
  }
  return f;
}

// "nx = 140, ny = 8" -> {{"nx", 140}, {"ny", 8}}.
std::vector<std::pair<std::string, double>> parse_parameters(const fsi::SceneTable& t,
                                                             const std::string& key) {
  std::vector<std::pair<std::string, double>> out;
  const std::string text = t.string(key);
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    const auto eq = item.find('=');
    auto trim = [](std::string s) {
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t") + 1);
      return s;
    };
    if (trim(item).empty()) continue;
    if (eq == std::string::npos)
      t.fail(key,
             fmt::format("must be \"name = value, ...\", got \"{}\" in \"{}\"", trim(item), text));
    const std::string name = trim(item.substr(0, eq)), value = trim(item.substr(eq + 1));
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (name.empty() || value.empty() || *end != '\0')
      t.fail(key,
             fmt::format("must be \"name = value, ...\", got \"{}\" in \"{}\"", trim(item), text));
    out.push_back({name, v});
  }
  return out;
}

Material read_material(const fsi::SceneTable& t) {
  const std::string model = t.choice("model", {"saint-venant-kirchhoff", "neo-hookean"});
  const MaterialModel mm = material_model_from_name(model);
  const double density = t.positive("density");
  const bool has_e = t.has("youngs_modulus"), has_nu = t.has("poisson_ratio");
  const bool has_g = t.has("shear_modulus"), has_k = t.has("bulk_modulus");
  const bool has_l = t.has("lame_lambda");
  Material m;
  m.model = mm;
  m.density = density;
  auto poisson = [&] { return t.in_range("poisson_ratio", -1.0, 0.5, true); };
  if (has_e && has_nu && !has_g && !has_k && !has_l) {
    const double e = t.positive("youngs_modulus");
    m = Material::from_young(mm, e, poisson(), density);
  } else if (has_g && has_nu && !has_e && !has_k && !has_l) {
    const double g = t.positive("shear_modulus");
    const double nu = poisson();
    m = Material::from_young(mm, 2 * g * (1 + nu), nu, density);
  } else if (has_g && has_k && !has_e && !has_nu && !has_l) {
    m.mu = t.positive("shear_modulus");
    m.bulk = t.positive("bulk_modulus");
    m.lambda = m.bulk - 2 * m.mu / 3;
  } else if (has_g && has_l && !has_e && !has_nu && !has_k) {
    m.mu = t.positive("shear_modulus");
    m.lambda = t.number("lame_lambda");
    m.bulk = m.lambda + 2 * m.mu / 3;
    if (!(m.bulk > 0))
      t.fail("lame_lambda", fmt::format("must give a positive bulk modulus lambda + 2 mu / 3, got "
                                        "{}",
                                        m.bulk));
  } else {
    t.fail_table(
        "give the elastic constants as one pair: youngs_modulus and poisson_ratio, "
        "shear_modulus and poisson_ratio, shear_modulus and bulk_modulus, or "
        "shear_modulus and lame_lambda");
  }
  return m;
}

Mesh read_mesh(const fsi::SceneTable& b, MeshQuality& quality) {
  const bool has_file = b.has("mesh");
  const auto rect = b.optional_table("rectangle");
  if (has_file == rect.has_value())
    b.fail_table("give the mesh either as mesh = \"file.geo\" (or .msh) or as a [rectangle] table");
  Mesh mesh;
  if (has_file) {
    const auto path = b.existing_file("mesh");
    GmshOptions opt;
    opt.size_factor = b.positive("mesh_size_factor", 1.0);
    opt.refine = static_cast<int>(b.integer("mesh_refine", 0));
    if (opt.refine < 0 || opt.refine > kMaxMeshRefine)
      b.fail("mesh_refine", fmt::format("must be in [0, {}], got {}", kMaxMeshRefine, opt.refine));
    if (b.has("mesh_parameters")) opt.parameters = parse_parameters(b, "mesh_parameters");
    mesh = read_gmsh(path, opt, b.path() + ".mesh");
    quality = finalize_mesh(mesh);
  } else {
    const auto& r = *rect;
    const Vec2 origin = r.vec2("origin", {0, 0});
    const Vec2 size = r.vec2("size");
    if (!(size[0] > 0 && size[1] > 0))
      r.fail("size", fmt::format("must be positive, got [{}, {}]", size[0], size[1]));
    const auto cells = r.numbers("cells");
    if (cells.size() != 2 || cells[0] < 1 || cells[1] < 1 || cells[0] != std::floor(cells[0]) ||
        cells[1] != std::floor(cells[1]))
      r.fail("cells", "must be two integers >= 1, [nx, ny]");
    const std::string d =
        r.choice("diagonals", {"criss-cross", "right", "left", "union-jack"}, "criss-cross");
    const std::string region = r.string("region", "body");
    r.finish();
    mesh = rectangle_mesh(origin[0], origin[1], size[0], size[1], static_cast<int>(cells[0]),
                          static_cast<int>(cells[1]), diagonals_from_name(d), region);
    quality = finalize_mesh(mesh);
  }
  return mesh;
}

void require_boundary(const fsi::SceneTable& t, const std::string& key, const Mesh& mesh) {
  const std::string name = t.string(key);
  if (!mesh.has_boundary(name))
    t.fail(key, fmt::format("names \"{}\", which mesh {} lacks (its boundaries: {})", name,
                            mesh.source, fmt::join(mesh.boundary_names(), ", ")));
}

BodySpec read_body(const fsi::SceneTable& b, MeshQuality& quality) {
  BodySpec body;
  body.name = b.string("name");
  const std::string kind = b.choice("kind", {"elastic", "rigid"}, "elastic");
  body.kind = kind == "rigid" ? BodyKind::rigid : BodyKind::elastic;
  body.mesh = read_mesh(b, quality);
  const Mesh& mesh = body.mesh;
  if (body.kind == BodyKind::rigid) {
    if (auto m = b.optional_table("motion")) {
      body.motion.center = m->vec2("center", {0, 0});
      body.motion.velocity = m->vec2("velocity", {0, 0});
      body.motion.amplitude = m->vec2("amplitude", {0, 0});
      body.motion.omega = m->number("omega", 0.0);
      body.motion.angle = m->number("angle", 0.0);
      body.motion.frequency = m->non_negative("frequency", 0.0);
      body.motion.phase = m->number("phase", 0.0);
      m->finish();
    }
    b.finish();
    return body;
  }
  body.initial_velocity = b.vec2("velocity", {0, 0});
  body.gravity = b.boolean("gravity", true);

  // Materials: one per region; a single material without `region` covers the whole mesh.
  const auto mats = b.tables("material");
  if (mats.empty()) b.fail_table("an elastic body needs at least one [[material]]");
  body.materials.assign(mesh.region_names.size(), Material{});
  std::vector<bool> set(mesh.region_names.size(), false);
  for (const auto& t : mats) {
    const Material m = read_material(t);
    if (!t.has("region")) {
      if (mats.size() > 1) t.fail_table("with several materials, each names its region");
      std::fill(body.materials.begin(), body.materials.end(), m);
      std::fill(set.begin(), set.end(), true);
    } else {
      const std::string region = t.string("region");
      const int r = mesh.region_index(region);
      if (r < 0)
        t.fail("region", fmt::format("names \"{}\", which mesh {} lacks (its regions: {})", region,
                                     mesh.source, fmt::join(mesh.region_names, ", ")));
      if (set[r]) t.fail("region", fmt::format("\"{}\" has two materials", region));
      body.materials[r] = m;
      set[r] = true;
    }
    t.finish();
  }
  for (std::size_t r = 0; r < set.size(); ++r)
    if (!set[r])
      b.fail_table(fmt::format("region \"{}\" of mesh {} has no material", mesh.region_names[r],
                               mesh.source));

  for (const auto& t : b.tables("constraint")) {
    Constraint c;
    const std::string type = t.choice("type", {"fixed", "displacement", "periodic"});
    require_boundary(t, "boundary", mesh);
    c.boundary = t.string("boundary");
    const std::string comp = t.choice("components", {"xy", "x", "y"}, "xy");
    c.x = comp != "y";
    c.y = comp != "x";
    if (type == "fixed") {
      c.type = Constraint::Type::fixed;
    } else if (type == "displacement") {
      c.type = Constraint::Type::displacement;
      c.displacement = t.vec2("displacement");
      c.time = read_time(t);
    } else {
      c.type = Constraint::Type::periodic;
      require_boundary(t, "partner", mesh);
      c.partner = t.string("partner");
      if (t.has("shift")) {
        c.shift_given = true;
        c.shift = t.vec2("shift");
      }
    }
    t.finish();
    body.constraints.push_back(c);
  }
  for (const auto& t : b.tables("load")) {
    Load l;
    if (t.has("traction") == t.has("force"))
      t.fail_table(
          "a load is either traction = [tx, ty] on a boundary or force = [fx, fy] at a point");
    if (t.has("traction")) {
      l.type = Load::Type::traction;
      require_boundary(t, "boundary", mesh);
      l.boundary = t.string("boundary");
      if (mesh.boundaries.count(l.boundary) == 0)
        t.fail("boundary",
               fmt::format("names \"{}\", a node set: a traction needs edges", l.boundary));
      l.value = t.vec2("traction");
    } else {
      l.type = Load::Type::point;
      l.value = t.vec2("force");
      l.point = t.vec2("point");
    }
    l.time = read_time(t);
    t.finish();
    body.loads.push_back(l);
  }
  b.skip("probe");
  b.finish();
  return body;
}

int body_named(const fsi::SceneTable& t, const std::string& key, const std::string& name,
               const std::vector<BodySpec>& bodies) {
  for (std::size_t b = 0; b < bodies.size(); ++b)
    if (bodies[b].name == name) return static_cast<int>(b);
  std::vector<std::string> names;
  for (const auto& b : bodies) names.push_back(b.name);
  t.fail(key, fmt::format("names body \"{}\", which does not exist (bodies: {})", name,
                          fmt::join(names, ", ")));
}

}  // namespace

Config read_config(const fsi::SceneTable& s, double fluid_density) {
  Config c;
  Settings& st = c.model.settings;
  // Which program plays the solid role (./fsi and common/tools/plan.cpp read it): a scene for
  // another one (solid_rigid/) is refused here rather than half read.
  if (s.has("program")) {
    const std::string program = s.string("program");
    if (program != "solid")
      s.fail("program", fmt::format("= \"{}\": this scene is for the program {}, not for solid; "
                                    "launch {} in the solid role (./fsi run composes the job "
                                    "from the scene)",
                                    program, program, program));
  }
  const std::string analysis = s.choice("analysis", {"dynamic", "static"}, "dynamic");
  st.analysis = analysis == "static" ? Analysis::statics : Analysis::dynamic;
  st.fluid_density = fluid_density;
  st.gravity = s.vec2("gravity", {0, 0});
  const Settings defaults;
  st.newton_tolerance = s.positive("newton_tolerance", defaults.newton_tolerance);
  st.newton_max_iterations = static_cast<int>(
      s.positive_integer("newton_max_iterations", defaults.newton_max_iterations));
  const long cutbacks = s.integer("step_cutbacks", defaults.step_cutbacks);
  if (cutbacks < 0 || cutbacks > kMaxStepCutbacks)
    s.fail("step_cutbacks",
           fmt::format("must be in [0, {}], got {}", kMaxStepCutbacks, cutbacks));
  st.step_cutbacks = static_cast<int>(cutbacks);
  st.contact_tolerance = s.positive("contact_tolerance", defaults.contact_tolerance);
  st.keep_factor = s.boolean("keep_factor", defaults.keep_factor);
  st.predictor = s.choice("predictor", {"none", "acceleration"},
                          defaults.predictor == Predictor::acceleration ? "acceleration" : "none") ==
                         "acceleration"
                     ? Predictor::acceleration
                     : Predictor::none;
  // gamma in [1/2, 1]; beta defaults to (gamma + 1/2)^2 / 4, the member of the family that
  // damps the highest frequencies most for this gamma, and must keep 2 beta >= gamma (the
  // condition for unconditional stability in the linear regime). Only when given: a scene
  // without them keeps its effective scene (and its checkpoints) as it was.
  if (s.has("newmark_gamma") || s.has("newmark_beta")) {
    st.newmark_gamma = s.in_range("newmark_gamma", 0.5, 1.0, false, defaults.newmark_gamma);
    const double beta_default = 0.25 * (st.newmark_gamma + 0.5) * (st.newmark_gamma + 0.5);
    st.newmark_beta = s.in_range("newmark_beta", 0.0, 1.0, true, beta_default);
    if (2 * st.newmark_beta < st.newmark_gamma)
      s.fail("newmark_beta", fmt::format("must be at least newmark_gamma / 2 = {} "
                                         "(unconditional stability), got {}",
                                         st.newmark_gamma / 2, st.newmark_beta));
  }
  c.modes = static_cast<int>(s.integer("modes", 0));
  if (c.modes < 0) s.fail("modes", fmt::format("must be >= 0, got {}", c.modes));
  c.initial_mode = static_cast<int>(s.integer("initial_mode", 0));
  if (c.initial_mode < 0 || c.initial_mode > std::max(c.modes, 0) ||
      (c.initial_mode > 0 && c.modes == 0))
    s.fail("initial_mode",
           fmt::format("must be in [0, modes = {}], got {}", c.modes, c.initial_mode));
  if (c.initial_mode > 0) c.initial_mode_speed = s.positive("initial_mode_speed");

  const auto bodies = s.tables("body");
  // No body: a coupled scene may carry an empty [solid] (the program then only keeps the clock).
  if (bodies.empty())
    std::fprintf(stderr, "[solid] note: [solid] has no [[solid.body]]: no solid to advance\n");
  for (const auto& b : bodies) {
    MeshQuality q;
    c.model.bodies.push_back(read_body(b, q));
    c.quality.push_back(q);
    for (std::size_t k = 0; k + 1 < c.model.bodies.size(); ++k)
      if (c.model.bodies[k].name == c.model.bodies.back().name)
        b.fail("name", fmt::format("\"{}\" is used by two bodies", c.model.bodies.back().name));
  }
  // A static solve needs every elastic body held by at least one support of its own.
  if (st.analysis == Analysis::statics)
    for (std::size_t bi = 0; bi < bodies.size(); ++bi) {
      const auto& body = c.model.bodies[bi];
      if (body.kind != BodyKind::elastic) continue;
      const bool held =
          std::any_of(body.constraints.begin(), body.constraints.end(),
                      [](const Constraint& k) { return k.type != Constraint::Type::periodic; });
      if (!held)
        bodies[bi].fail_table(
            fmt::format("body \"{}\" has no fixed or displacement constraint: its "
                        "static solve (solid.analysis = \"static\") is singular",
                        body.name));
    }
  // Probes, now that body indices are known.
  for (std::size_t bi = 0; bi < bodies.size(); ++bi)
    for (const auto& p : bodies[bi].tables("probe")) {
      ProbeSpec ps;
      ps.name = p.string("name");
      ps.body = static_cast<int>(bi);
      ps.point = p.vec2("point");
      if (locate(c.model.bodies[bi].mesh, ps.point[0], ps.point[1], kProbeLocateTolerance).triangle < 0)
        p.fail("point",
               fmt::format("[{}, {}] is outside body \"{}\" in its reference configuration",
                           ps.point[0], ps.point[1], c.model.bodies[bi].name));
      for (const auto& other : c.probes)
        if (other.name == ps.name) p.fail("name", fmt::format("\"{}\" names two probes", ps.name));
      p.finish();
      c.probes.push_back(ps);
    }
  for (const auto& t : s.tables("contact")) {
    const auto names = t.strings("bodies");
    if (names.size() != 2)
      t.fail("bodies", fmt::format("must name two bodies, got {}", names.size()));
    ContactPair p;
    p.slave = body_named(t, "bodies", names[0], c.model.bodies);
    p.master = body_named(t, "bodies", names[1], c.model.bodies);
    // The same body twice: its surface against its own far parts (self-contact).
    if (p.slave == p.master) {
      if (c.model.bodies[p.slave].kind != BodyKind::elastic)
        t.fail("bodies", fmt::format("names body \"{}\" twice (self-contact), which is rigid: "
                                     "only an elastic body can touch itself",
                                     names[0]));
      if (t.has("two_way"))
        t.fail("two_way", "has no meaning for a body against itself (self-contact): remove it");
    }
    if (c.model.bodies[p.slave].kind == BodyKind::rigid &&
        c.model.bodies[p.master].kind == BodyKind::rigid)
      t.fail("bodies", "names two rigid bodies: one of them must be elastic");
    p.two_way = p.slave != p.master && t.boolean("two_way", true);
    // A rigid body only ever provides the surface.
    if (c.model.bodies[p.slave].kind == BodyKind::rigid) std::swap(p.slave, p.master);
    // Each direction (slave against master) once: a repeated one would have two slots per node,
    // each with its own multiplier on one constraint, and only one of them could be joined with
    // its partner at a vertex (ContactSet::join_vertex_pairs).
    auto covers = [](const ContactPair& q, int slave, int master) {
      return (q.slave == slave && q.master == master) ||
             (q.two_way && q.slave == master && q.master == slave);
    };
    for (const auto& q : c.model.contacts)
      if (covers(q, p.slave, p.master) || (p.two_way && covers(q, p.master, p.slave)))
        t.fail("bodies",
               fmt::format("repeats the contact of \"{}\" with \"{}\" that an earlier "
                           "[[solid.contact]] has (one table per pair of bodies: two_way = true, "
                           "the default, takes both directions)",
                           names[0], names[1]));
    t.finish();
    c.model.contacts.push_back(p);
  }
  for (const auto& t : s.tables("plane")) {
    ContactPlane p;
    p.point = t.vec2("point");
    const Vec2 n = t.vec2("normal");
    const double len = std::hypot(n[0], n[1]);
    if (!(len > 0)) t.fail("normal", "must be a non-zero vector");
    p.normal = {n[0] / len, n[1] / len};
    if (t.has("bodies")) {
      for (const auto& name : t.strings("bodies"))
        p.bodies.push_back(body_named(t, "bodies", name, c.model.bodies));
    } else {
      for (std::size_t b = 0; b < c.model.bodies.size(); ++b)
        if (c.model.bodies[b].kind == BodyKind::elastic) p.bodies.push_back(static_cast<int>(b));
    }
    t.finish();
    c.model.planes.push_back(p);
  }
  s.finish();
  return c;
}

}  // namespace solid
