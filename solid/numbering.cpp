// The sparse system: equations numbered over the free dofs of every elastic body (prescribed
// dofs removed, periodic images sharing their root's equation), the fixed lower-triangle
// pattern with each element's map into its values, and the factorisation that skips a matrix
// it has already factorised.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "error.hpp"
#include "scene.hpp"
#include "solver_body.hpp"

namespace solid {

namespace {

// A periodic node and its partner's shifted image are one point when closer than this fraction
// of the body's smallest surface edge: far below any edge, far above the round-off of a mesher's
// coordinates.
constexpr double kPeriodicMatch = 1e-6;

}  // namespace

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
            fmt::format("body '{}': constraint boundary '{}' is not in mesh {} (it has: {})",
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
            fmt::format("body '{}': periodic partner '{}' is not in mesh {} (it has: {})",
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
      const double tol = kPeriodicMatch * B.min_edge;
      for (int n : nodes) {
        int match = -1;
        for (int p : partners)
          if (std::hypot(mesh.x[2 * p] + shift[0] - mesh.x[2 * n],
                         mesh.x[2 * p + 1] + shift[1] - mesh.x[2 * n + 1]) < tol)
            match = p;
        if (match < 0)
          throw fsi::InputError(fmt::format(
              "body '{}': periodic boundary '{}' node {} at ({}, {}) has no partner on '{}' "
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
            fmt::format("body '{}': periodic constraints form a loop", name));
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
            "body '{}' has no constraint that holds it in {} ({} x and {} y components "
            "prescribed): a static solve is singular; fix or prescribe a boundary",
            name, px == 0 && py == 0 ? "place" : (px == 0 ? "x" : (py == 0 ? "y" : "rotation")), px,
            py));
    }
  }
  if (m_neq == 0)
    for (const auto& b : m_bodies)
      if (b->is_elastic())
        throw fsi::InputError(
            fmt::format("body '{}' has every node prescribed", b->spec.name));
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
  m_matrix_curved = false;
  m_ahead_fresh = false;
  if (m_neq > 0) m_linear.analyze(m_matrix);
}

// The factor is kept with the values it was computed from: an unchanged matrix (same pattern,
// same values bit for bit; build_pattern() forgets the factor) is not factorised again.
bool Solver::factorize_cached() {
  const double* v = m_matrix.valuePtr();
  const auto nnz = static_cast<std::size_t>(m_matrix.nonZeros());
  if (m_factored_valid && m_factored.size() == nnz &&
      std::memcmp(v, m_factored.data(), nnz * sizeof(double)) == 0) {
    // The factor is that of this matrix: it takes this matrix's flags (a look-ahead's matrix
    // marked curved whose curvature added nothing equals a plain one), as a fresh factorisation
    // of the same values would.
    m_factored_c0 = m_matrix_c0;
    m_factored_curved = m_matrix_curved;
    ++m_factor_reuses;
    return true;
  }
  m_factored_valid = false;
  // Not finite (overflowing constants): no factor, whatever the factorisation would return;
  // factorize() names the cause.
  for (std::size_t k = 0; k < nnz; ++k)
    if (!std::isfinite(v[k])) return false;
  if (!m_linear.factorize(m_matrix)) return false;
  ++m_factorizations;
  m_factored.assign(v, v + nnz);
  m_factored_c0 = m_matrix_c0;
  m_factored_curved = m_matrix_curved;
  m_factored_valid = true;
  return true;
}

std::vector<std::int64_t> Solver::contact_entries() const {
  std::vector<std::int64_t> pairs;
  for (const auto& [r, c] : m_contact_entries) pairs.push_back(r), pairs.push_back(c);
  return pairs;
}

void Solver::restore_contact_entries(const std::vector<std::int64_t>& pairs) {
  if (pairs.size() % 2 != 0) fsi::fail("restore_contact_entries: {} values, not pairs", pairs.size());
  bool grown = false;
  for (std::size_t k = 0; k < pairs.size(); k += 2) {
    const std::int64_t r = pairs[k], c = pairs[k + 1];
    if (r < 0 || c < 0 || r >= m_neq || c >= m_neq || c > r)
      fsi::fail("checkpoint: the contact pattern's entry ({}, {}) is outside the {} equations "
                "(a damaged checkpoint, or one of another model)", r, c, m_neq);
    grown = m_contact_entries.insert({int(r), int(c)}).second || grown;
  }
  if (grown) build_pattern();
}

KeptFactor Solver::kept_factor() const {
  if (!(m_keep_factor && m_factored_valid && m_contact.empty())) return {};
  return {m_factored, m_factored_c0, m_matrix_floor};
}

void Solver::restore_kept_factor(const KeptFactor& k) {
  m_keep_factor = false;
  m_matrix_floor = k.matrix_floor;
  // A checkpoint of another pattern (contact entries) or a run resumed without keeping starts
  // with the look-ahead as usual.
  if (k.values.empty() || !m_model.settings.keep_factor || !m_contact.empty() ||
      static_cast<std::size_t>(m_matrix.nonZeros()) != k.values.size())
    return;
  std::copy(k.values.begin(), k.values.end(), m_matrix.valuePtr());
  m_matrix_c0 = k.c0;
  m_matrix_curved = false;  // kept without contact only
  m_factored_valid = false;
  if (!factorize_cached()) fsi::fail("a checkpoint's kept factor is singular");
  m_keep_factor = true;
}

void Solver::factorize(const std::string& when) {
  if (factorize_cached()) return;
  // Overflowing material constants (a modulus of 1e300) make the entries infinite or NaN, which
  // the factorisation reports as singular: named first, as the cause.
  const double* v = m_matrix.valuePtr();
  for (Eigen::Index k = 0; k < m_matrix.nonZeros(); ++k)
    if (!std::isfinite(v[k]))
      fsi::fail(
          "the stiffness matrix at {} has entries that are not finite (Inf or NaN): the material "
          "constants or the time step overflow double precision{}",
          when, fsi::extreme_constants_hint());
  fsi::fail(
        "the stiffness matrix is singular at {}: a body is not held against rigid "
        "motion (no constraint, no mass, no contact) or an element has collapsed{}",
        when, fsi::extreme_constants_hint());
}

}  // namespace solid
