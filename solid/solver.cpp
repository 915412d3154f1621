// The solid solver: equation numbering with constraints, sparse assembly into a fixed pattern,
// Newmark + Newton with the contact active set, static load stepping, health checks.
#include "solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include "error.hpp"
#include "solver_body.hpp"

namespace solid {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

constexpr double two_pi = 6.283185307179586;

}  // namespace

double TimeFunction::operator()(double t) const {
  switch (kind) {
    case Kind::constant:
      return 1.0;
    case Kind::ramp:
      return ramp_time > 0 ? std::clamp(t / ramp_time, 0.0, 1.0) : 1.0;
    case Kind::sine:
      return std::sin(two_pi * frequency * t + phase);
  }
  return 1.0;
}

Solver::~Solver() = default;

Solver::Solver(Model model, LinearSolver::Backend backend)
    : m_model(std::move(model)), m_linear(backend) {
  const auto& s = m_model.settings;
  if (!(s.newton_tolerance > 0)) throw fsi::InputError("solid: newton tolerance must be > 0");
  if (s.newton_max_iterations < 1) throw fsi::InputError("solid: newton iterations must be >= 1");
  if (s.analysis == Analysis::statics && s.load_steps < 1)
    throw fsi::InputError("solid: load_steps must be >= 1");
  for (std::size_t b = 0; b < m_model.bodies.size(); ++b) {
    for (std::size_t c = 0; c < b; ++c)
      if (m_model.bodies[b].name == m_model.bodies[c].name)
        throw fsi::InputError(
            fmt::format("solid: two bodies are named '{}'", m_model.bodies[b].name));
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
    if (p.slave < 0 || p.master < 0 || p.slave >= num_bodies() || p.master >= num_bodies() ||
        p.slave == p.master)
      throw fsi::InputError("solid: a contact pair needs two different bodies");
  m_contact.setup(meshes, kinds, m_model.contacts, m_model.planes);
  update_rigid(0);
  update_prescribed(0);
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
  B.v.assign(2 * nn, 0.0);
  B.ma.assign(2 * nn, 0.0);
  B.f_cpl.assign(2 * nn, 0.0);
  B.f_ext.assign(2 * nn, 0.0);
  B.q.assign(2 * nn, 0.0);
  B.r.assign(2 * nn, 0.0);
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
    throw fsi::InputError(fmt::format("solid: body '{}' has {} regions but {} materials", name,
                                      mesh.region_names.size(), B.spec.materials.size()));
  for (std::size_t r = 0; r < B.spec.materials.size(); ++r) {
    const Material& m = B.spec.materials[r];
    if (!(m.mu > 0) || !(m.density > 0) ||
        (m.model == MaterialModel::neo_hookean ? !(m.bulk > 0) : !(m.lambda + m.mu > 0)))
      throw fsi::InputError(fmt::format(
          "solid: body '{}' region '{}': material constants must be positive (mu {}, lambda {}, "
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
          "solid: body '{}' region '{}': density {} is below the fluid density {} (a buoyant "
          "solid needs a negative excess mass, which Newmark cannot integrate)",
          name, mesh.region_names[B.material[e]], B.spec.materials[B.material[e]].density,
          st.fluid_density));
    B.rho_inertia[e] = rho;
    double me[3][3];
    element_mass(B.geo[e].area, st.lumped_mass, me);
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
            fmt::format("solid: body '{}': load boundary '{}' is not an edge set "
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

void Solver::number_equations() {
  m_neq = 0;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    const Mesh& mesh = B.spec.mesh;
    const int ndof = 2 * mesh.num_nodes();
    const std::string& name = B.spec.name;
    // Per dof: prescribing constraint (or -1) and periodic master dof (or -1).
    std::vector<int> by(ndof, -1), master(ndof, -1);
    for (std::size_t c = 0; c < B.spec.constraints.size(); ++c) {
      const auto& con = B.spec.constraints[c];
      if (!mesh.has_boundary(con.boundary))
        throw fsi::InputError(
            fmt::format("solid: body '{}': constraint boundary '{}' is not in mesh {} (it has: {})",
                        name, con.boundary, mesh.source, fmt::join(mesh.boundary_names(), ", ")));
      const auto nodes = mesh.boundary_nodes(con.boundary);
      if (con.type != Constraint::Type::periodic) {
        for (int n : nodes) {
          if (con.x) by[2 * n] = static_cast<int>(c);
          if (con.y) by[2 * n + 1] = static_cast<int>(c);
        }
        continue;
      }
      if (!mesh.has_boundary(con.partner))
        throw fsi::InputError(
            fmt::format("solid: body '{}': periodic partner '{}' is not in mesh {} (it has: {})",
                        name, con.partner, mesh.source, fmt::join(mesh.boundary_names(), ", ")));
      const auto partners = mesh.boundary_nodes(con.partner);
      Vec2 shift = con.shift;
      if (!con.shift_given) {
        Vec2 ca{0, 0}, cb{0, 0};
        for (int n : nodes)
          for (int i = 0; i < 2; ++i) ca[i] += mesh.x[2 * n + i] / nodes.size();
        for (int n : partners)
          for (int i = 0; i < 2; ++i) cb[i] += mesh.x[2 * n + i] / partners.size();
        shift = {ca[0] - cb[0], ca[1] - cb[1]};
      }
      const double tol = 1e-6 * B.min_edge;
      for (int n : nodes) {
        int match = -1;
        for (int p : partners)
          if (std::hypot(mesh.x[2 * p] + shift[0] - mesh.x[2 * n],
                         mesh.x[2 * p + 1] + shift[1] - mesh.x[2 * n + 1]) < tol)
            match = p;
        if (match < 0)
          throw fsi::InputError(fmt::format(
              "solid: body '{}': periodic boundary '{}' node {} at ({}, {}) has no partner on '{}' "
              "(shift ({}, {}))",
              name, con.boundary, n, mesh.x[2 * n], mesh.x[2 * n + 1], con.partner, shift[0],
              shift[1]));
        if (match == n) continue;
        if (con.x) master[2 * n] = 2 * match;
        if (con.y) master[2 * n + 1] = 2 * match + 1;
      }
    }
    // Resolve periodic chains to their root; a prescribed dof is its own root.
    std::vector<int> root(ndof);
    for (int d = 0; d < ndof; ++d) {
      int r = d, guard = 0;
      while (by[r] < 0 && master[r] >= 0 && guard++ < ndof) r = master[r];
      if (guard >= ndof)
        throw fsi::InputError(
            fmt::format("solid: body '{}': periodic constraints form a loop", name));
      root[d] = r;
    }
    B.prescribed.clear();
    for (int d = 0; d < ndof; ++d) {
      if (by[d] >= 0) {
        Prescribed p;
        p.dof = d;
        p.constraint = by[d];
        p.component = d % 2;
        B.prescribed.push_back(p);
      } else if (root[d] != d && by[root[d]] >= 0) {
        Prescribed p;
        p.dof = d;
        p.follow = root[d];
        p.component = d % 2;
        B.prescribed.push_back(p);
      }
    }
    std::vector<bool> is_prescribed(ndof, false);
    for (const auto& p : B.prescribed) is_prescribed[p.dof] = true;
    for (int d = 0; d < ndof; ++d)
      if (!is_prescribed[d] && root[d] == d) B.eq[d] = m_neq++;
    for (int d = 0; d < ndof; ++d)
      if (!is_prescribed[d] && root[d] != d) B.eq[d] = B.eq[root[d]];
    // A static solve needs the rigid motions removed by the body's own supports.
    if (m_model.settings.analysis == Analysis::statics) {
      int px = 0, py = 0;
      for (const auto& p : B.prescribed) (p.component == 0 ? px : py)++;
      if (px == 0 || py == 0 || px + py < 3)
        throw fsi::InputError(fmt::format(
            "solid: body '{}' has no constraint that holds it in {} ({} x and {} y components "
            "prescribed): a static solve is singular; fix or prescribe a boundary",
            name, px == 0 && py == 0 ? "place" : (px == 0 ? "x" : (py == 0 ? "y" : "rotation")), px,
            py));
    }
  }
  if (m_neq == 0)
    for (const auto& b : m_bodies)
      if (b->is_elastic())
        throw fsi::InputError(
            fmt::format("solid: body '{}' has every node prescribed", b->spec.name));
}

int Solver::matrix_index(int row, int col) const {
  const int* inner = m_matrix.innerIndexPtr();
  const int* begin = inner + m_matrix.outerIndexPtr()[col];
  const int* end = inner + m_matrix.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  return it != end && *it == row ? static_cast<int>(it - inner) : -1;
}

void Solver::build_pattern() {
  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> trip;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (const auto& t : B.spec.mesh.triangles)
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) {
          const int er = B.eq[2 * t[r / 2] + r % 2], ec = B.eq[2 * t[c / 2] + c % 2];
          if (er >= 0 && ec >= 0 && er >= ec) trip.emplace_back(er, ec, 0.0);
        }
  }
  for (int i = 0; i < m_neq; ++i) trip.emplace_back(i, i, 0.0);
  for (const auto& [r, c] : m_contact_entries) trip.emplace_back(r, c, 0.0);
  m_matrix.resize(m_neq, m_neq);
  m_matrix.setFromTriplets(trip.begin(), trip.end());
  m_matrix.makeCompressed();
  auto index_of = [&](int row, int col) {
    const int k = matrix_index(row, col);
    FSI_ASSERT(k >= 0);
    return k;
  };
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    B.kmap.resize(B.spec.mesh.triangles.size());
    for (std::size_t e = 0; e < B.kmap.size(); ++e) {
      const auto& t = B.spec.mesh.triangles[e];
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) {
          const int er = B.eq[2 * t[r / 2] + r % 2], ec = B.eq[2 * t[c / 2] + c % 2];
          B.kmap[e][6 * r + c] = (er >= 0 && ec >= 0 && er >= ec) ? index_of(er, ec) : -1;
        }
    }
  }
  m_residual.setZero(m_neq);
  m_factored_valid = false;
  if (m_neq > 0) m_linear.analyze(m_matrix);
}

void Solver::update_prescribed(double t) {
  const bool statics = m_model.settings.analysis == Analysis::statics;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (const auto& p : B.prescribed) {
      if (p.constraint < 0) continue;
      const auto& con = B.spec.constraints[p.constraint];
      double u = 0;
      if (con.type == Constraint::Type::displacement)
        u = con.displacement[p.component] * (statics ? t : con.time(t));
      B.u[p.dof] = u;
    }
    for (const auto& p : B.prescribed)
      if (p.follow >= 0) B.u[p.dof] = B.u[p.follow];
    B.sync_positions();
  }
}

// The prescribed displacements at t (or load factor) become a pending increment: the first
// Newton iteration carries it through the linearised system, K_ff du_f = R_f - K_fp du_p, so
// that the free nodes follow the moved boundary instead of meeting it as a jump (which can
// invert the elements next to it).
bool Solver::prepare_prescribed(double t) {
  const bool statics = m_model.settings.analysis == Analysis::statics;
  bool any = false;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    B.dirichlet_step.assign(B.u.size(), 0.0);
    if (!B.is_elastic()) continue;
    std::vector<double> target(B.u);
    for (const auto& p : B.prescribed) {
      if (p.constraint < 0) continue;
      const auto& con = B.spec.constraints[p.constraint];
      target[p.dof] = con.type == Constraint::Type::displacement
                          ? con.displacement[p.component] * (statics ? t : con.time(t))
                          : 0.0;
    }
    for (const auto& p : B.prescribed)
      if (p.follow >= 0) target[p.dof] = target[p.follow];
    for (const auto& p : B.prescribed) {
      B.dirichlet_step[p.dof] = target[p.dof] - B.u[p.dof];
      if (B.dirichlet_step[p.dof] != 0) any = true;
    }
  }
  m_dirichlet_pending = any;
  return any;
}

void Solver::apply_prescribed_step() {
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (const auto& p : B.prescribed) B.u[p.dof] += B.dirichlet_step[p.dof];
    B.sync_positions();
  }
  m_dirichlet_pending = false;
}

void Solver::update_rigid(double t) {
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (B.is_elastic()) continue;
    const RigidMotion& m = B.spec.motion;
    const double w = two_pi * m.frequency;
    const double s = std::sin(w * t + m.phase), c = std::cos(w * t + m.phase);
    const double theta = m.omega * t + m.angle * s;
    const double dtheta = m.omega + m.angle * w * c;
    const double ct = std::cos(theta), st = std::sin(theta);
    for (int n = 0; n < B.spec.mesh.num_nodes(); ++n) {
      const double rx = B.X[2 * n] - m.center[0], ry = B.X[2 * n + 1] - m.center[1];
      const double qx = ct * rx - st * ry, qy = st * rx + ct * ry;
      B.x[2 * n] = m.center[0] + m.velocity[0] * t + m.amplitude[0] * s + qx;
      B.x[2 * n + 1] = m.center[1] + m.velocity[1] * t + m.amplitude[1] * s + qy;
      B.v[2 * n] = m.velocity[0] + m.amplitude[0] * w * c - dtheta * qy;
      B.v[2 * n + 1] = m.velocity[1] + m.amplitude[1] * w * c + dtheta * qx;
      B.u[2 * n] = B.x[2 * n] - B.X[2 * n];
      B.u[2 * n + 1] = B.x[2 * n + 1] - B.X[2 * n + 1];
    }
  }
}

std::vector<double> Solver::scene_loads(int b, double t) const {
  std::vector<double> f(m_bodies[b]->X.size(), 0.0);
  add_scene_loads(*m_bodies[b], t, f);
  return f;
}

// F(t) = (gravity + sum_k f_k(t) load_k), or factor * (gravity + sum_k load_k) in statics.
void Solver::add_scene_loads(const Body& B, double t, std::vector<double>& f) const {
  if (!B.is_elastic()) return;
  const bool statics = m_model.settings.analysis == Analysis::statics;
  const double scale = statics ? t : 1.0;
  for (std::size_t d = 0; d < f.size(); ++d) f[d] += scale * B.gravity[d];
  for (std::size_t k = 0; k < B.load_dofs.size(); ++k) {
    const double s = statics ? t : B.spec.loads[k].time(t);
    for (const auto& [dof, c] : B.load_dofs[k]) f[dof] += s * c;
  }
}

// Residual on the free equations, for Newmark (c0 = 4 / dt^2) or statics (c0 = 0):
//   R = F(t) - Q(x) - c0 M (x - x^n - dt v^n) + (M a)^n,
// with Q_a = sum_e A0 F S dN_a/dX (element.hpp) and, when with_matrix,
//   K_eff = dQ/dx + c0 M  (material + geometric stiffness plus the Newmark mass term).
// `time_or_factor` is t^(n+1) in dynamics and the load factor in statics.
std::pair<int, int> Solver::assemble(double c0, double dt, bool with_matrix, double time_or_factor,
                                     const std::vector<std::vector<double>>* external) {
  std::pair<int, int> inverted{-1, -1};
  if (with_matrix) std::fill_n(m_matrix.valuePtr(), m_matrix.nonZeros(), 0.0);
  m_residual.setZero();
  double scale2 = 0, floor2 = 0;
  double* values = m_matrix.valuePtr();
  const bool dynamic = c0 > 0;
  const bool lumped = m_model.settings.lumped_mass;
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    const Mesh& mesh = B.spec.mesh;
    std::fill(B.f_ext.begin(), B.f_ext.end(), 0.0);
    add_scene_loads(B, time_or_factor, B.f_ext);
    if (external && static_cast<int>(external->size()) > B.index && !(*external)[B.index].empty()) {
      const auto& fe = (*external)[B.index];
      if (fe.size() != B.f_ext.size())
        fsi::fail("solid: external forces for body '{}' have {} values, expected {}", B.spec.name,
                  fe.size(), B.f_ext.size());
      for (std::size_t d = 0; d < fe.size(); ++d) B.f_cpl[d] = fe[d];
    } else {
      std::fill(B.f_cpl.begin(), B.f_cpl.end(), 0.0);
    }
    std::fill(B.q.begin(), B.q.end(), 0.0);
    const std::vector<double>* iter_w = nullptr;
    if (dynamic && m_iteration_velocity &&
        static_cast<int>(m_iteration_velocity->size()) > B.index &&
        !(*m_iteration_velocity)[B.index].empty()) {
      iter_w = &(*m_iteration_velocity)[B.index];
      if (iter_w->size() != B.u.size())
        fsi::fail("solid: iteration velocities for body '{}' have {} values, expected {}",
                  B.spec.name, iter_w->size(), B.u.size());
    }
    std::vector<double>& r = B.r;
    // The coupling force is the reaction of the fluid's velocity correction over this step: an
    // impulse F_c dt within the step, like the contact acceleration of the paper's Eq. 13-14
    // (x^(n+1) = ... + dt^2/2 a_c, v^(n+1) = ... + dt a_c). In the trapezoidal residual
    // (4/dt^2) M (x^(n+1) - x^n - dt v^n) - M a^n = F^(n+1) - Q^(n+1) + 2 F_c it enters twice,
    // and it stays out of the stored M a (the next step does not average it in again): the
    // solid receives the whole impulse in the step the fluid lost it, so momentum balances step
    // by step. Averaging it over two steps delays the reaction and pumps energy into the solid's
    // element-scale modes. Massless dofs (rho_s = rho_f) are quasi-static: F - Q + F_c = 0.
    for (std::size_t d = 0; d < r.size(); ++d)
      r[d] = B.f_ext[d] +
             (dynamic ? B.ma[d] + (B.mass_row[d] > 0 ? 2.0 : 1.0) * B.f_cpl[d] : B.f_cpl[d]);
    std::vector<double>& absq = B.abs_q;  // |element forces| and |K| |u|: scales of R
    std::vector<double>& absm = B.abs_floor;
    std::fill(absq.begin(), absq.end(), 0.0);
    std::fill(absm.begin(), absm.end(), 0.0);
    for (int e = 0; e < mesh.num_triangles(); ++e) {
      const auto& t = mesh.triangles[e];
      double fe[6], ke[36];
      double J = 1;
      element_internal(B.spec.materials[B.material[e]], B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]],
                       &B.u[2 * t[2]], fe, with_matrix ? ke : nullptr, &J);
      B.det_f[e] = J;
      if (!(J > 0) && inverted.first < 0) inverted = {B.index, e};
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 2; ++i) {
          const int d = 2 * t[a] + i;
          B.q[d] += fe[2 * a + i];
          absq[d] += std::abs(fe[2 * a + i]);
        }
      // The element's mass matrix (unit density), for the inertia and the coupled iterations'
      // term; each removes scale(k) * (M vec)_k from the residual and adds scale(k) * (M |vec|)_k
      // to its round-off floor, k = 2a + i.
      double me[3][3] = {};
      if (dynamic && (B.rho_inertia[e] > 0 || iter_w)) element_mass(B.geo[e].area, lumped, me);
      auto mass_terms = [&](const double* vec, const double* vec_abs, auto scale) {
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < 2; ++i) {
            double m = 0, mabs = 0;
            for (int c = 0; c < 3; ++c) {
              m += me[a][c] * vec[2 * c + i];
              mabs += me[a][c] * vec_abs[2 * c + i];
            }
            r[2 * t[a] + i] -= scale(2 * a + i) * m;
            absm[2 * t[a] + i] += scale(2 * a + i) * mabs;
          }
      };
      if (dynamic && B.rho_inertia[e] > 0) {
        const double rho = B.rho_inertia[e];
        double w[6], wabs[6];
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < 2; ++i) {
            const int d = 2 * t[a] + i;
            w[2 * a + i] = B.u[d] - B.u_old[d] - dt * B.v_old[d];
            wabs[2 * a + i] = std::abs(B.u[d]) + std::abs(B.u_old[d]) + dt * std::abs(B.v_old[d]);
          }
        mass_terms(w, wabs, [&](int) { return c0 * rho; });
        if (with_matrix)
          for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c)
              for (int i = 0; i < 2; ++i) ke[6 * (2 * a + i) + 2 * c + i] += c0 * rho * me[a][c];
      }
      if (iter_w) {
        // Coupled iterations: the reaction F_c the coupler sent was computed from the
        // velocity w it gave the fluid; about w it is F_c(v) ~ F_c - M_f (v - w) / dt, M_f the
        // mass matrix of density rho_f (the fluid inside the body, which the forcing makes
        // follow v). In the residual F_c enters with the weight s_d (2 on dofs with mass, 1 on
        // massless ones, as above) and v_c^(n+1) = s_c (x_c^(n+1) - x_c^n) / dt - [mass] v_c^n,
        // so
        //   r_d -= s_d / dt sum_c M_f,dc (v_c - w_c),   K_dc += s_d s_c / dt^2 M_f,dc.
        // The term vanishes when the step returns v^(n+1) = w (a converged iteration), and it
        // gives a body without excess mass (rho_s = rho_f) the inertia rho_f it otherwise lacks
        // within the step: a free neutrally buoyant body has a regular matrix.
        const double rf = m_model.settings.fluid_density;
        double sw[6], dv[6], vabs[6];  // vabs: |v| + |w|, the scale of the terms that cancel
        for (int c = 0; c < 6; ++c) {
          const int d = 2 * t[c / 2] + c % 2;
          const bool mass = B.mass_row[d] > 0;
          sw[c] = mass ? 2.0 : 1.0;
          const double v = sw[c] * (B.u[d] - B.u_old[d]) / dt - (mass ? B.v_old[d] : 0.0);
          dv[c] = v - (*iter_w)[d];
          vabs[c] = std::abs(v) + std::abs((*iter_w)[d]);
        }
        mass_terms(dv, vabs, [&](int k) { return sw[k] * rf / dt; });
        if (with_matrix)
          for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c)
              for (int i = 0; i < 2; ++i)
                ke[6 * (2 * a + i) + 2 * c + i] +=
                    sw[2 * a + i] * sw[2 * c + i] * rf / (dt * dt) * me[a][c];
      }
      if (with_matrix && m_dirichlet_pending) {
        double dp[6];
        bool moved = false;
        for (int c = 0; c < 6; ++c) {
          dp[c] = B.dirichlet_step[2 * t[c / 2] + c % 2];
          moved = moved || dp[c] != 0;
        }
        if (moved)
          for (int rr = 0; rr < 6; ++rr) {
            double f = 0;
            for (int c = 0; c < 6; ++c) f += ke[6 * rr + c] * dp[c];
            r[2 * t[rr / 2] + rr % 2] -= f;
          }
      }
      if (with_matrix) {
        // Round-off floor of the residual: |K| |u| (a residual cannot be resolved below eps of
        // the element forces that cancel in it).
        for (int rr = 0; rr < 6; ++rr) {
          double f = 0;
          for (int c = 0; c < 6; ++c)
            f += std::abs(ke[6 * rr + c]) * std::abs(B.u[2 * t[c / 2] + c % 2]);
          absm[2 * t[rr / 2] + rr % 2] += f;
        }
        const auto& map = B.kmap[e];
        for (int k = 0; k < 36; ++k)
          if (map[k] >= 0) values[map[k]] += ke[k];
      }
    }
    for (std::size_t d = 0; d < r.size(); ++d) {
      r[d] -= B.q[d];
      if (B.eq[d] >= 0) {
        m_residual[B.eq[d]] += r[d];
        // The coupling force counts as it enters r: twice with mass, once on a massless dof.
        const double w_cpl = dynamic && B.mass_row[d] > 0 ? 2.0 : 1.0;
        const double s = std::abs(B.f_ext[d]) + w_cpl * std::abs(B.f_cpl[d]) + absq[d] +
                         (dynamic ? std::abs(B.ma[d]) : 0.0);
        scale2 += s * s;
        floor2 += (s + absm[d]) * (s + absm[d]);
      }
    }
  }
  m_force_scale = std::sqrt(scale2);
  m_roundoff_scale = std::sqrt(floor2);
  return inverted;
}

// The factor is kept with the values it was computed from: an unchanged matrix (same pattern,
// same values bit for bit; build_pattern() forgets the factor) is not factorised again.
bool Solver::factorize_cached() {
  const double* v = m_matrix.valuePtr();
  const auto nnz = static_cast<std::size_t>(m_matrix.nonZeros());
  if (m_factored_valid && m_factored.size() == nnz &&
      std::memcmp(v, m_factored.data(), nnz * sizeof(double)) == 0) {
    ++m_factor_reuses;
    return true;
  }
  m_factored_valid = false;
  if (!m_linear.factorize(m_matrix)) return false;
  m_factored.assign(v, v + nnz);
  m_factored_valid = true;
  return true;
}

void Solver::keep_step_start() {
  for (auto& bp : m_bodies) {
    bp->u_old = bp->u;
    bp->v_old = bp->v;
  }
}

void Solver::factorize_ahead(double dt) {
  if (m_bodies.empty() || m_neq == 0 || m_model.settings.analysis != Analysis::dynamic) return;
  // Active contact adds its curvature to iteration 0's matrix after assembly: no match to hope for.
  for (const auto& s : m_contact.slots())
    if (s.active) return;
  keep_step_start();  // as advance() begins (the residual's inertia reads them)
  assemble(newmark_c0(dt), dt, true, m_time + dt, nullptr);
  if (m_residual.allFinite()) factorize_cached();
}

void Solver::factorize(const std::string& when) {
  if (!factorize_cached())
    fsi::fail(
        "solid: the stiffness matrix is singular at {}: a body is not held against rigid "
        "motion (no constraint, no mass, no contact) or an element has collapsed",
        when);
}

void Solver::fail_health(const std::string& what, int body, int element,
                         const std::string& when) const {
  const Body& B = *m_bodies[body];
  const auto& t = B.spec.mesh.triangles[element];
  fsi::fail("solid: {} in body '{}' element {} (nodes {}, {}, {}; det F = {:.4g}) at {}", what,
            B.spec.name, element, t[0], t[1], t[2], B.det_f[element], when);
}

void Solver::check_finite(const std::string& when) const {
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    for (std::size_t d = 0; d < B.x.size(); ++d)
      if (!std::isfinite(B.x[d]) || !std::isfinite(B.v[d]))
        fsi::fail("solid: non-finite {} in body '{}' node {} at {}",
                  std::isfinite(B.x[d]) ? "velocity" : "position", B.spec.name, d / 2, when);
  }
}

void Solver::check_inverted(const std::string& when) const {
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (std::size_t e = 0; e < B.det_f.size(); ++e)
      if (!(B.det_f[e] > 0))
        fail_health("element turned inside out (det F <= 0)", B.index, static_cast<int>(e), when);
  }
}

// The linearised contact conditions of one Newton iteration as a complementarity problem:
//   w = S lambda + q >= 0,  lambda >= 0,  lambda . w = 0,
// with S = B K^-1 B^T (symmetric, positive semi-definite) and q = g + B K^-1 R the gaps after the
// step without contact. Equivalent to min 1/2 l^T S l + q^T l over l >= 0, solved exactly by the
// Lawson-Hanson active-set method; S + eps I (eps = 1e-12 max diag S) makes a constraint that
// two-way pairs repeat harmless. `tol` is the accepted negative gap.
namespace {

Eigen::VectorXd solve_contact_lcp(const Eigen::MatrixXd& S0, const Eigen::VectorXd& q, double tol) {
  const int m = static_cast<int>(q.size());
  Eigen::MatrixXd S = S0;
  S.diagonal().array() += 1e-12 * S0.diagonal().cwiseAbs().maxCoeff();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  std::vector<bool> passive(m, false);
  for (int outer = 0; outer < 4 * m + 10; ++outer) {
    const Eigen::VectorXd w = S * lambda + q;
    int j = -1;
    for (int i = 0; i < m; ++i)
      if (!passive[i] && w[i] < -tol && (j < 0 || w[i] < w[j])) j = i;
    if (j < 0) break;
    passive[j] = true;
    for (int inner = 0; inner < 4 * m + 10; ++inner) {
      std::vector<int> p;
      for (int i = 0; i < m; ++i)
        if (passive[i]) p.push_back(i);
      const int np = static_cast<int>(p.size());
      Eigen::MatrixXd Spp(np, np);
      Eigen::VectorXd rhs(np);
      for (int a = 0; a < np; ++a) {
        rhs[a] = -q[p[a]];
        for (int b = 0; b < np; ++b) Spp(a, b) = S(p[a], p[b]);
      }
      const Eigen::VectorXd z = Spp.ldlt().solve(rhs);
      if (z.minCoeff() > 0) {
        for (int a = 0; a < np; ++a) lambda[p[a]] = z[a];
        break;
      }
      // Step from lambda towards z until the first passive multiplier reaches zero.
      double alpha = 1;
      for (int a = 0; a < np; ++a)
        if (z[a] <= 0) alpha = std::min(alpha, lambda[p[a]] / (lambda[p[a]] - z[a]));
      for (int a = 0; a < np; ++a) {
        lambda[p[a]] += alpha * (z[a] - lambda[p[a]]);
        if (lambda[p[a]] <= 1e-300 || (z[a] <= 0 && lambda[p[a]] <= 1e-14 * std::abs(z[a]))) {
          lambda[p[a]] = 0;
          passive[p[a]] = false;
        }
      }
    }
  }
  return lambda;
}

}  // namespace

// Newton-Raphson on R(x) + B^T lambda = 0 with the contact conditions g(x) >= 0, lambda >= 0,
// lambda g = 0 (paper Eq. 3-5). Each iteration linearises both:
//   K_eff dx = R + B^T lambda,  g + B dx >= 0,  lambda >= 0,  lambda (g + B dx) = 0,
// solved through the factorised K_eff: y0 = K^-1 R, Y = K^-1 B^T, the complementarity problem
// for lambda with S = B Y, q = g + B y0 (solve_contact_lcp), then dx = y0 + Y lambda. The active
// set is the lambda > 0 of the last iteration. Converged when ||R + B^T lambda|| <= tol, no slot
// penetrates and every active gap is closed, both within the contact tolerance.
StepReport Solver::newton(double c0, double dt, double time_or_factor,
                          const std::vector<std::vector<double>>* external,
                          const std::string& when) {
  using clock = std::chrono::steady_clock;
  const auto& st = m_model.settings;
  StepReport rep;
  auto& slots = m_contact.slots();
  double gap_tol = std::numeric_limits<double>::max();
  for (const auto& b : m_bodies)
    if (b->is_elastic()) gap_tol = std::min(gap_tol, b->min_edge);
  gap_tol *= st.contact_tolerance;
  std::vector<const std::vector<double>*> xs;
  for (const auto& b : m_bodies) xs.push_back(&b->x);
  Eigen::VectorXd dx(m_neq);
  double previous = std::numeric_limits<double>::infinity();
  bool have_step = false;

  for (int it = 0;; ++it) {
    auto t0 = clock::now();
    auto inverted = assemble(c0, dt, true, time_or_factor, external);
    // An iterate that leaves the material's domain (neo-Hookean J <= 0) is pulled back.
    for (int halving = 0; have_step && !m_residual.allFinite() && halving < 12; ++halving) {
      dx *= 0.5;
      for (auto& bp : m_bodies) {
        Body& B = *bp;
        if (!B.is_elastic()) continue;
        for (std::size_t d = 0; d < B.u.size(); ++d)
          if (B.eq[d] >= 0) B.u[d] -= dx[B.eq[d]];
        B.sync_positions();
      }
      inverted = assemble(c0, dt, true, time_or_factor, external);
    }
    rep.assembly_seconds += seconds_since(t0);
    if (!m_residual.allFinite()) {
      if (inverted.first >= 0)
        fail_health("element turned inside out (det F <= 0) during Newton", inverted.first,
                    inverted.second, when);
      for (const auto& bp : m_bodies)
        for (std::size_t d = 0; d < bp->r.size(); ++d)
          if (bp->is_elastic() && bp->eq[d] >= 0 && !std::isfinite(bp->r[d]))
            fsi::fail("solid: non-finite residual (NaN or Inf) in body '{}' node {} at {}",
                      bp->spec.name, d / 2, when);
      fsi::fail("solid: non-finite residual (NaN or Inf) at {}", when);
    }

    // Contact: geometry at the current iterate; the slots that are active (lambda > 0) or
    // within reach (gap below one element edge) become candidates of this iteration's
    // complementarity problem.
    std::vector<int> cand;
    double worst_gap = 0;
    Eigen::VectorXd R = m_residual;
    int n_active = 0;
    if (!m_contact.empty()) {
      m_contact.detect(xs);
      for (auto& s : slots) {
        if (s.active) {
          worst_gap = std::max(worst_gap, std::abs(s.gap));
          n_active++;
        } else {
          worst_gap = std::max(worst_gap, -s.gap);
        }
        if (s.active || s.gap < m_bodies[s.slave_body]->min_edge)
          cand.push_back(static_cast<int>(&s - slots.data()));
      }
    }
    // Rows of B = dg/dx on the free equations; a pending prescribed increment moves the gaps
    // by its own part, B_p du_p.
    std::vector<std::vector<std::pair<int, double>>> rows(cand.size());
    std::vector<double> gap_shift(cand.size(), 0.0);
    for (std::size_t k = 0; k < cand.size(); ++k) {
      const ContactSlot& s = slots[cand[k]];
      auto add = [&](int body, int node, double w) {
        const Body& B = *m_bodies[body];
        for (int i = 0; i < 2; ++i) {
          const int e = B.eq[2 * node + i];
          if (e >= 0)
            rows[k].push_back({e, w * s.normal[i]});
          else if (m_dirichlet_pending && B.is_elastic())
            gap_shift[k] += w * s.normal[i] * B.dirichlet_step[2 * node + i];
        }
      };
      add(s.slave_body, s.slave_node, 1.0);
      if (s.master_body >= 0) {
        add(s.master_body, s.m0, s.m1 >= 0 ? -(1 - s.xi) : -1.0);
        if (s.m1 >= 0) add(s.master_body, s.m1, -s.xi);
      }
      if (s.active)
        for (const auto& [e, w] : rows[k]) R[e] += s.lambda * w;
    }
    // Contact curvature: -lambda d2g/dx2 for every active slot on an elastic segment. It
    // couples the slave node to the master's nodes, entries the element pattern lacks: the
    // pattern grows once (re-analysed) the first time a pair of nodes meets.
    if (n_active > 0) {
      bool grow = false;
      std::vector<std::array<int, 6>> slot_eqs;
      std::vector<int> slot_index;
      for (std::size_t k = 0; k < slots.size(); ++k) {
        const ContactSlot& s = slots[k];
        if (!s.active || s.master_body < 0 || s.m1 < 0 || !m_bodies[s.master_body]->is_elastic())
          continue;
        const Body& S = *m_bodies[s.slave_body];
        const Body& M = *m_bodies[s.master_body];
        const std::array<int, 6> eqs{S.eq[2 * s.slave_node], S.eq[2 * s.slave_node + 1],
                                     M.eq[2 * s.m0],         M.eq[2 * s.m0 + 1],
                                     M.eq[2 * s.m1],         M.eq[2 * s.m1 + 1]};
        for (int a : eqs)
          for (int b : eqs)
            if (a >= 0 && b >= 0 && a >= b && matrix_index(a, b) < 0) {
              m_contact_entries.insert({a, b});
              grow = true;
            }
        slot_eqs.push_back(eqs);
        slot_index.push_back(static_cast<int>(k));
      }
      if (grow) {
        build_pattern();
        assemble(c0, dt, true, time_or_factor, external);
      }
      double* values = m_matrix.valuePtr();
      for (std::size_t q = 0; q < slot_eqs.size(); ++q) {
        const ContactSlot& s = slots[slot_index[q]];
        const auto& xs = m_bodies[s.slave_body]->x;
        const auto& xm = m_bodies[s.master_body]->x;
        double H[36];
        segment_gap_hessian({xs[2 * s.slave_node], xs[2 * s.slave_node + 1]},
                            {xm[2 * s.m0], xm[2 * s.m0 + 1]}, {xm[2 * s.m1], xm[2 * s.m1 + 1]}, H);
        const auto& eqs = slot_eqs[q];
        for (int r = 0; r < 6; ++r)
          for (int c = 0; c < 6; ++c)
            if (eqs[r] >= 0 && eqs[c] >= 0 && eqs[r] >= eqs[c])
              values[matrix_index(eqs[r], eqs[c])] -= s.lambda * H[6 * r + c];
      }
    }
    const double rn = R.norm();
    rep.residuals.push_back(rn);
    rep.tolerance = st.newton_tolerance * m_force_scale;
    rep.active_contacts = n_active;
    // Converged: below tolerance, or stalled at round-off after at least one solve; no
    // penetration and every active constraint closed.
    const bool small = rn <= rep.tolerance;
    const bool stalled = it > 0 && rn > 0.5 * previous && rn <= 1e-12 * m_roundoff_scale;
    if ((small || stalled) && worst_gap <= gap_tol && !m_dirichlet_pending) {
      rep.converged = true;
      break;
    }
    if (it >= st.newton_max_iterations) break;
    previous = rn;

    t0 = clock::now();
    factorize(when);
    rep.factor_seconds += seconds_since(t0);
    t0 = clock::now();
    dx = m_linear.solve(m_residual);
    if (!cand.empty()) {
      const int nc = static_cast<int>(cand.size());
      Eigen::MatrixXd Bt = Eigen::MatrixXd::Zero(m_neq, nc);
      Eigen::VectorXd q(nc);
      for (int k = 0; k < nc; ++k) {
        for (const auto& [e, w] : rows[k]) Bt(e, k) += w;
        q[k] = slots[cand[k]].gap + gap_shift[k];
      }
      const Eigen::MatrixXd Y = m_linear.solve(Bt);
      const Eigen::MatrixXd S = Bt.transpose() * Y;
      q += Bt.transpose() * dx;
      const Eigen::VectorXd lambda = solve_contact_lcp(S, q, gap_tol);
      dx += Y * lambda;
      for (auto& s : slots) {
        s.active = false;
        s.lambda = 0;
      }
      for (int k = 0; k < nc; ++k) {
        slots[cand[k]].lambda = lambda[k];
        slots[cand[k]].active = lambda[k] > 0;
      }
    }
    rep.solve_seconds += seconds_since(t0);
    if (m_dirichlet_pending) apply_prescribed_step();
    for (auto& bp : m_bodies) {
      Body& B = *bp;
      if (!B.is_elastic()) continue;
      for (std::size_t d = 0; d < B.u.size(); ++d)
        if (B.eq[d] >= 0) B.u[d] += dx[B.eq[d]];
      B.sync_positions();
    }
    have_step = true;
    rep.iterations++;
  }

  // Physical contact forces on the nodes.
  for (auto& bp : m_bodies) std::fill(bp->contact.begin(), bp->contact.end(), 0.0);
  for (const auto& s : slots) {
    if (!s.active) continue;
    const double f = m_contact_force_factor * s.lambda;
    auto add = [&](int body, int node, double w) {
      for (int i = 0; i < 2; ++i) m_bodies[body]->contact[2 * node + i] += f * w * s.normal[i];
    };
    add(s.slave_body, s.slave_node, 1.0);
    if (s.master_body >= 0) {
      add(s.master_body, s.m0, s.m1 >= 0 ? -(1 - s.xi) : -1.0);
      if (s.m1 >= 0) add(s.master_body, s.m1, -s.xi);
    }
  }
  if (!rep.converged) {
    // Name the node with the largest residual: that of the assembled equation (a periodic
    // pair's nodes share one, and their own shares cancel in it), at its first node.
    int worst_eq = -1;
    if (m_neq > 0) m_residual.cwiseAbs().maxCoeff(&worst_eq);
    int wb = -1, wn = -1;
    for (const auto& bp : m_bodies)
      for (std::size_t d = 0; d < bp->eq.size() && wb < 0; ++d)
        if (bp->is_elastic() && bp->eq[d] == worst_eq) {
          wb = bp->index;
          wn = static_cast<int>(d / 2);
        }
    fsi::fail(
        "solid: Newton did not converge in {} iterations at {}: residual {:.3e}, tolerance "
        "{:.3e}, {} active contacts; largest residual in body '{}' node {}",
        rep.iterations, when, rep.residuals.back(), rep.tolerance, rep.active_contacts,
        wb >= 0 ? m_bodies[wb]->spec.name : "?", wn);
  }
  return rep;
}

StepReport Solver::advance(double dt, const std::vector<std::vector<double>>* external,
                           const std::vector<std::vector<double>>* iteration_velocity) {
  if (!(dt > 0)) fsi::fail("solid: time step must be > 0, got {}", dt);
  if (m_bodies.empty()) {  // a scene without bodies: only the clock moves
    m_time += dt;
    m_step++;
    StepReport none;
    none.converged = true;
    return none;
  }
  if (m_model.settings.analysis != Analysis::dynamic)
    fsi::fail("solid: advance() needs a dynamic analysis");
  const double t1 = m_time + dt;
  const std::string when = fmt::format("step {} (t = {:.6g})", m_step + 1, t1);
  if (m_step == 0 && m_time == 0) {
    // (M a)^0 = F^0 - Q(x^0) on the dofs that carry mass: the initial state starts in dynamic
    // balance with the scene's loads.
    assemble(0, dt, false, 0.0, nullptr);
    for (auto& bp : m_bodies)
      for (std::size_t d = 0; d < bp->ma.size(); ++d)
        bp->ma[d] = bp->is_elastic() && bp->mass_row[d] > 0 && bp->eq[d] >= 0
                        ? bp->f_ext[d] - bp->q[d]
                        : 0.0;
  }
  keep_step_start();
  update_rigid(t1);
  prepare_prescribed(t1);
  m_contact_force_factor = 0.5;
  m_iteration_velocity =
      m_model.settings.iteration_fluid_mass && m_model.settings.fluid_density > 0
          ? iteration_velocity
          : nullptr;
  StepReport rep;
  try {
    rep = newton(newmark_c0(dt), dt, t1, external, when);
  } catch (...) {
    m_iteration_velocity = nullptr;
    throw;
  }
  m_iteration_velocity = nullptr;
  // Newmark velocity from the positions, v^(n+1) = 2 (x^(n+1) - x^n) / dt - v^n (the trapezoidal
  // rule), and (M a)^(n+1) = F - Q: the acceleration without the contact part (Eq. 13-16).
  // Massless dofs (rho_s = rho_f) are quasi-static: v = (x^(n+1) - x^n) / dt, (M a) = 0.
  for (auto& bp : m_bodies) {
    Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (std::size_t d = 0; d < B.u.size(); ++d) {
      if (B.mass_row[d] > 0) {
        B.v[d] = 2 * (B.u[d] - B.u_old[d]) / dt - B.v_old[d];
        B.ma[d] = B.eq[d] >= 0 ? B.f_ext[d] - B.q[d] : 0.0;
      } else {
        B.v[d] = (B.u[d] - B.u_old[d]) / dt;
        B.ma[d] = 0;
      }
    }
  }
  m_time = t1;
  m_step++;
  check_finite(when);
  check_inverted(when);
  return rep;
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
}

void Solver::restore_state(const StepState& s) {
  if (s.u.size() != m_bodies.size()) fsi::fail("solid: restore_state: a state of another model");
  for (std::size_t b = 0; b < m_bodies.size(); ++b) {
    Body& B = *m_bodies[b];
    B.u = s.u[b], B.v = s.v[b], B.ma = s.ma[b], B.x = s.x[b], B.contact = s.contact[b];
  }
  m_contact.slots() = s.slots;
  m_time = s.time;
  m_step = s.step;
  m_contact_force_factor = s.contact_force_factor;
  m_dirichlet_pending = false;
}

StepReport Solver::solve_static_step(double factor) {
  const std::string when = fmt::format("load factor {:.6g}", factor);
  prepare_prescribed(factor);
  m_contact_force_factor = 1.0;
  keep_step_start();
  StepReport rep = newton(0, 0, factor, nullptr, when);
  check_finite(when);
  check_inverted(when);
  return rep;
}

std::vector<StepReport> Solver::solve_static() {
  if (m_model.settings.analysis != Analysis::statics)
    fsi::fail("solid: solve_static() needs a static analysis");
  std::vector<StepReport> reps;
  const int n = m_model.settings.load_steps;
  for (int k = 1; k <= n; ++k) {
    reps.push_back(solve_static_step(static_cast<double>(k) / n));
    m_step = k;
  }
  return reps;
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
    fsi::fail("solid: set_velocity: wrong size for body '{}'", B.spec.name);
  for (std::size_t d = 0; d < v.size(); ++d)
    if (B.eq[d] >= 0) B.v[d] = v[d];
}

void Solver::set_positions(int b, const std::vector<double>& x) {
  Body& B = *m_bodies[b];
  if (x.size() != B.x.size())
    fsi::fail("solid: set_positions: wrong size for body '{}'", B.spec.name);
  for (std::size_t d = 0; d < x.size(); ++d)
    if (B.eq[d] >= 0) B.u[d] = x[d] - B.X[d];
  B.sync_positions();
}

double Solver::kinetic_energy() const {
  double k = 0;
  const bool lumped = m_model.settings.lumped_mass;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
      const auto& t = B.spec.mesh.triangles[e];
      double me[3][3];
      element_mass(B.geo[e].area, lumped, me);
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c)
          for (int i = 0; i < 2; ++i)
            k += 0.5 * B.rho_inertia[e] * me[a][c] * B.v[2 * t[a] + i] * B.v[2 * t[c] + i];
    }
  }
  return k;
}

double Solver::strain_energy() const {
  double w = 0;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
      const auto& t = B.spec.mesh.triangles[e];
      const Eigen::Matrix2d H =
          displacement_gradient(B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]], &B.u[2 * t[2]]);
      w += B.geo[e].area * evaluate_material(B.spec.materials[B.material[e]], H, nullptr, nullptr);
    }
  }
  return w;
}

double Solver::load_potential() const {
  double p = 0;
  for (const auto& bp : m_bodies) {
    const Body& B = *bp;
    if (!B.is_elastic()) continue;
    const auto f =
        scene_loads(B.index, m_model.settings.analysis == Analysis::statics ? 1.0 : m_time);
    for (std::size_t d = 0; d < f.size(); ++d) p -= f[d] * B.u[d];
  }
  return p;
}

std::vector<double> Solver::element_det_f(int b) const {
  const Body& B = *m_bodies[b];
  std::vector<double> out(B.spec.mesh.num_triangles(), 1.0);
  if (!B.is_elastic()) return out;
  for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
    const auto& t = B.spec.mesh.triangles[e];
    const Eigen::Matrix2d H =
        displacement_gradient(B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]], &B.u[2 * t[2]]);
    out[e] = 1 + H.trace() + H.determinant();
  }
  return out;
}

std::vector<double> Solver::element_von_mises(int b) const {
  const Body& B = *m_bodies[b];
  std::vector<double> out(B.spec.mesh.num_triangles(), 0.0);
  if (!B.is_elastic()) return out;
  for (int e = 0; e < B.spec.mesh.num_triangles(); ++e) {
    const auto& t = B.spec.mesh.triangles[e];
    const Eigen::Matrix2d H =
        displacement_gradient(B.geo[e], &B.u[2 * t[0]], &B.u[2 * t[1]], &B.u[2 * t[2]]);
    out[e] = von_mises(cauchy_stress(B.spec.materials[B.material[e]], H));
  }
  return out;
}

std::vector<double> Solver::contact_forces(int b) const {
  return m_bodies[b]->contact;
}

std::vector<double> Solver::contact_pressure(int b) const {
  const Body& B = *m_bodies[b];
  const Mesh& mesh = B.spec.mesh;
  std::vector<double> length(mesh.num_nodes(), 0.0), p(mesh.num_nodes(), 0.0);
  for (const auto& e : mesh.surface) {
    const double l =
        std::hypot(B.x[2 * e[1]] - B.x[2 * e[0]], B.x[2 * e[1] + 1] - B.x[2 * e[0] + 1]);
    length[e[0]] += l / 2;
    length[e[1]] += l / 2;
  }
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (length[n] > 0) p[n] = std::hypot(B.contact[2 * n], B.contact[2 * n + 1]) / length[n];
  return p;
}

Vec2 Solver::total_contact_force(int b) const {
  Vec2 f{0, 0};
  const auto& c = m_bodies[b]->contact;
  for (std::size_t d = 0; d < c.size(); ++d) f[d % 2] += c[d];
  return f;
}

double Solver::min_contact_gap() const {
  double g = std::numeric_limits<double>::infinity();
  for (const auto& s : m_contact.slots()) g = std::min(g, s.gap);
  return g;
}

Vec2 Solver::reaction(int b, const std::string& boundary) const {
  const Body& B = *m_bodies[b];
  if (!B.spec.mesh.has_boundary(boundary))
    fsi::fail("solid: body '{}' has no boundary '{}'", B.spec.name, boundary);
  Vec2 f{0, 0};
  for (int n : B.spec.mesh.boundary_nodes(boundary))
    for (int i = 0; i < 2; ++i)
      if (B.eq[2 * n + i] < 0) f[i] -= B.r[2 * n + i] + B.contact[2 * n + i];
  return f;
}

}  // namespace solid
