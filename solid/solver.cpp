// The Solver's construction and state: validating the model, the per-body element data (areas,
// gradients, inertial density, mass rows, gravity and load coefficients), the state accessors,
// and keeping / restoring a step's start for coupled iterations.
#include "solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

Solver::~Solver() = default;

Solver::Solver(Model model, LinearSolver::Backend backend)
    : m_model(std::move(model)), m_linear(backend) {
  const auto& s = m_model.settings;
  if (!(s.newton_tolerance > 0)) throw fsi::InputError("newton tolerance must be > 0");
  if (s.newton_max_iterations < 1) throw fsi::InputError("newton iterations must be >= 1");
  if (s.step_cutbacks < 0 || s.step_cutbacks > kMaxStepCutbacks)
    throw fsi::InputError(fmt::format("step cutbacks must be in [0, {}], got {}",
                                      kMaxStepCutbacks, s.step_cutbacks));
  if (s.analysis == Analysis::statics && s.load_steps < 1)
    throw fsi::InputError("load_steps must be >= 1");
  if (!(s.newmark_gamma >= 0.5 && s.newmark_gamma <= 1) || !(s.newmark_beta > 0) ||
      !(2 * s.newmark_beta >= s.newmark_gamma))
    throw fsi::InputError(fmt::format("Newmark parameters beta = {}, gamma = {}: need gamma in "
                                      "[0.5, 1] and 2 beta >= gamma > 0",
                                      s.newmark_beta, s.newmark_gamma));
  for (std::size_t b = 0; b < m_model.bodies.size(); ++b) {
    for (std::size_t c = 0; c < b; ++c)
      if (m_model.bodies[b].name == m_model.bodies[c].name)
        throw fsi::InputError(
            fmt::format("two bodies are named '{}'", m_model.bodies[b].name));
    m_bodies.push_back(std::make_unique<Body>());
    m_bodies.back()->spec = m_model.bodies[b];
    m_bodies.back()->index = static_cast<int>(b);
    setup_body(static_cast<int>(b));
  }
  number_equations();
  build_pattern();
  std::vector<const Mesh*> meshes;
  std::vector<BodyKind> kinds;
  for (const auto& b : m_bodies) {
    meshes.push_back(&b->spec.mesh);
    kinds.push_back(b->spec.kind);
  }
  for (const auto& p : m_model.contacts)
    if (p.slave < 0 || p.master < 0 || p.slave >= num_bodies() || p.master >= num_bodies())
      throw fsi::InputError("a contact pair names a body the model does not have");
    else if (p.slave == p.master && !m_bodies[p.slave]->is_elastic())
      throw fsi::InputError(fmt::format("self-contact of body '{}', which is rigid",
                                        m_bodies[p.slave]->spec.name));
  m_contact.setup(meshes, kinds, m_model.contacts, m_model.planes);
  update_rigid(0);
  update_prescribed(0);
  check_initial_overlap();
  // The mass matrix that the predictor and a damped Newmark step's velocity solve with, on the
  // element pattern: factorised here, before a resumed run's contact entries grow the pattern
  // (the fill-reducing ordering depends on it), so that a resumed run continues bit for bit.
  if (s.analysis == Analysis::dynamic && m_neq > 0 &&
      (!s.trapezoidal() || s.predictor == Predictor::acceleration))
    factorize_mass();
}

// Bodies of a contact pair (or a body and a contact plane) that overlap at t = 0 by more than
// the contact tolerance have no admissible start: the first step would throw them apart with an
// arbitrary impulse. The deepest node of each pair is named.
void Solver::check_initial_overlap() {
  if (m_contact.empty()) return;
  detect_contacts();
  const double tol = contact_gap_tolerance();
  const ContactSlot* worst = nullptr;
  for (const auto& s : m_contact.slots())
    if (s.gap < -tol && (!worst || s.gap < worst->gap)) worst = &s;
  if (!worst) return;
  const Body& S = *m_bodies[worst->slave_body];
  const std::string other =
      worst->master_body < 0                       ? fmt::format("contact plane {}", worst->plane)
      : worst->master_body == worst->slave_body    ? std::string("its own surface (self-contact)")
                                                   : fmt::format("body '{}'", m_bodies[worst->master_body]->spec.name);
  throw fsi::InputError(fmt::format(
      "body '{}' and {} overlap at t = 0: node {} of '{}' at ({:.6g}, {:.6g}) is {:.3g} inside "
      "{}, beyond the contact tolerance {:.3g} ([solid] contact_tolerance = {:g} of the "
      "smallest surface edge): move the bodies apart (their meshes, a clearance)",
      S.spec.name, other, worst->slave_node, S.spec.name, S.x[2 * worst->slave_node],
      S.x[2 * worst->slave_node + 1], -worst->gap, other, tol,
      m_model.settings.contact_tolerance));
}

int Solver::body_index(const std::string& name) const {
  for (int b = 0; b < num_bodies(); ++b)
    if (m_bodies[b]->spec.name == name) return b;
  return -1;
}

void Solver::setup_body(int index) {
  Body& B = *m_bodies[index];
  const Mesh& mesh = B.spec.mesh;
  const int nn = mesh.num_nodes(), ne = mesh.num_triangles();
  const std::string& name = B.spec.name;
  B.X = mesh.x;
  B.x = mesh.x;
  B.u.assign(2 * nn, 0.0);
  B.abs_q.assign(2 * nn, 0.0);
  B.abs_floor.assign(2 * nn, 0.0);
  B.abs_ku.assign(2 * nn, 0.0);
  B.v.assign(2 * nn, 0.0);
  B.ma.assign(2 * nn, 0.0);
  B.f_cpl.assign(2 * nn, 0.0);
  B.f_ext.assign(2 * nn, 0.0);
  B.q.assign(2 * nn, 0.0);
  B.r.assign(2 * nn, 0.0);
  B.r_0.assign(2 * nn, 0.0);
  B.contact.assign(2 * nn, 0.0);
  B.gravity.assign(2 * nn, 0.0);
  B.mass_row.assign(2 * nn, 0.0);
  B.det_f.assign(ne, 1.0);
  B.eq.assign(2 * nn, -1);
  B.min_edge = std::numeric_limits<double>::max();
  for (const auto& e : mesh.surface)
    B.min_edge = std::min(B.min_edge, std::hypot(mesh.x[2 * e[1]] - mesh.x[2 * e[0]],
                                                 mesh.x[2 * e[1] + 1] - mesh.x[2 * e[0] + 1]));
  if (!B.is_elastic()) return;

  if (B.spec.materials.size() != mesh.region_names.size())
    throw fsi::InputError(fmt::format("body '{}' has {} regions but {} materials", name,
                                      mesh.region_names.size(), B.spec.materials.size()));
  for (std::size_t r = 0; r < B.spec.materials.size(); ++r) {
    const Material& m = B.spec.materials[r];
    if (!(m.mu > 0) || !(m.density > 0) ||
        (m.model == MaterialModel::neo_hookean ? !(m.bulk > 0) : !(m.lambda + m.mu > 0)))
      throw fsi::InputError(fmt::format(
          "body '{}' region '{}': material constants must be positive (mu {}, lambda {}, "
          "bulk {}, density {})",
          name, mesh.region_names[r], m.mu, m.lambda, m.bulk, m.density));
  }
  B.geo.resize(ne);
  B.material.resize(ne);
  B.rho_inertia.resize(ne);
  const auto& st = m_model.settings;
  for (int e = 0; e < ne; ++e) {
    const auto& t = mesh.triangles[e];
    B.geo[e] = element_geometry(&mesh.x[2 * t[0]], &mesh.x[2 * t[1]], &mesh.x[2 * t[2]]);
    B.material[e] = mesh.triangle_region[e];
    const double rho = B.spec.materials[B.material[e]].density - st.fluid_density;
    if (rho < 0)
      throw fsi::InputError(fmt::format(
          "body '{}' region '{}': density {} is below the fluid density {} (a buoyant "
          "solid needs a negative excess mass, which Newmark cannot integrate)",
          name, mesh.region_names[B.material[e]], B.spec.materials[B.material[e]].density,
          st.fluid_density));
    B.rho_inertia[e] = rho;
    double me[3][3];
    element_mass(B.geo[e].area, me);
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) {
        B.mass_row[2 * t[a]] += rho * me[a][c];
        B.mass_row[2 * t[a] + 1] += rho * me[a][c];
      }
    if (B.spec.gravity)
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 2; ++i)
          B.gravity[2 * t[a] + i] += rho * B.geo[e].area / 3 * st.gravity[i];
  }
  // Scene loads as nodal coefficients.
  for (const auto& load : B.spec.loads) {
    std::vector<std::pair<int, double>> coeffs;
    if (load.type == Load::Type::traction) {
      auto it = mesh.boundaries.find(load.boundary);
      if (it == mesh.boundaries.end())
        throw fsi::InputError(
            fmt::format("body '{}': load boundary '{}' is not an edge set "
                        "of mesh {}",
                        name, load.boundary, mesh.source));
      for (const auto& e : it->second) {
        const double len = std::hypot(mesh.x[2 * e[1]] - mesh.x[2 * e[0]],
                                      mesh.x[2 * e[1] + 1] - mesh.x[2 * e[0] + 1]);
        for (int a : e)
          for (int i = 0; i < 2; ++i) coeffs.push_back({2 * a + i, load.value[i] * len / 2});
      }
    } else {
      int best = 0;
      double bd = std::numeric_limits<double>::max();
      for (int n = 0; n < nn; ++n) {
        const double d =
            std::hypot(mesh.x[2 * n] - load.point[0], mesh.x[2 * n + 1] - load.point[1]);
        if (d < bd) {
          bd = d;
          best = n;
        }
      }
      for (int i = 0; i < 2; ++i) coeffs.push_back({2 * best + i, load.value[i]});
    }
    B.load_dofs.push_back(std::move(coeffs));
  }
  for (int n = 0; n < nn; ++n)
    for (int i = 0; i < 2; ++i) B.v[2 * n + i] = B.spec.initial_velocity[i];
}

void Solver::save_state(StepState& s) const {
  const std::size_t nb = m_bodies.size();
  s.u.resize(nb), s.v.resize(nb), s.ma.resize(nb), s.x.resize(nb), s.contact.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const Body& B = *m_bodies[b];
    s.u[b] = B.u, s.v[b] = B.v, s.ma[b] = B.ma, s.x[b] = B.x, s.contact[b] = B.contact;
  }
  s.slots = m_contact.slots();
  s.time = m_time;
  s.step = m_step;
  s.contact_force_factor = m_contact_force_factor;
  s.root_mass_tangent = m_root_mass_tangent;
}

void Solver::restore_state(const StepState& s) {
  if (s.u.size() != m_bodies.size()) fsi::fail("restore_state: a state of another model");
  for (std::size_t b = 0; b < m_bodies.size(); ++b) {
    Body& B = *m_bodies[b];
    B.u = s.u[b], B.v = s.v[b], B.ma = s.ma[b], B.x = s.x[b], B.contact = s.contact[b];
  }
  m_contact.slots() = s.slots;
  m_time = s.time;
  m_step = s.step;
  m_contact_force_factor = s.contact_force_factor;
  m_root_mass_tangent = s.root_mass_tangent;
  m_dirichlet_pending = false;
  m_ahead_fresh = false;  // a look-ahead of another state
}

const std::vector<double>& Solver::positions(int b) const {
  return m_bodies[b]->x;
}
const std::vector<double>& Solver::velocities(int b) const {
  return m_bodies[b]->v;
}
const Mesh& Solver::mesh(int b) const {
  return m_bodies[b]->spec.mesh;
}
BodyKind Solver::kind(int b) const {
  return m_bodies[b]->spec.kind;
}

std::vector<double> Solver::displacements(int b) const {
  return m_bodies[b]->u;
}

void Solver::set_velocity(int b, const std::vector<double>& v) {
  Body& B = *m_bodies[b];
  if (v.size() != B.v.size())
    fsi::fail("set_velocity: wrong size for body '{}'", B.spec.name);
  for (std::size_t d = 0; d < v.size(); ++d)
    if (B.eq[d] >= 0) B.v[d] = v[d];
}

void Solver::set_positions(int b, const std::vector<double>& x) {
  Body& B = *m_bodies[b];
  if (x.size() != B.x.size())
    fsi::fail("set_positions: wrong size for body '{}'", B.spec.name);
  for (std::size_t d = 0; d < x.size(); ++d)
    if (B.eq[d] >= 0) B.u[d] = x[d] - B.X[d];
  B.sync_positions();
  m_ahead_fresh = false;  // a look-ahead of another state
}

}  // namespace solid
