// The contact solve of one Newton iteration (paper Eq. 3-5, 13-14): the gaps and their rows of
// B = dg/dx at the iterate, the contact curvature in the tangent, the complementarity problem for
// the multipliers (the active set), and the physical contact forces of the converged step. The
// geometry (gap, closest point, normal) is contact.cpp's.
#include <Eigen/Dense>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "solver_body.hpp"

namespace solid {

namespace {

// Regularisation of the Schur complement, relative to its largest diagonal entry: makes the
// repeated constraint of a two-way pair (two slots on one contact, a singular S) solvable, a
// perturbation near the round-off of S itself.
constexpr double kSchurRegularisation = 1e-12;
// A multiplier this small is zero: the absolute bound is next to the smallest normal double (an
// underflowed step), the relative one is round-off of the value z it was stepping towards.
constexpr double kZeroMultiplier = 1e-300;
constexpr double kZeroMultiplierRelative = 1e-14;

// Iteration cap of each Lawson-Hanson loop for m constraints: each pass adds or removes one
// constraint, and the method terminates in far fewer; the cap only guards against cycling.
int lcp_iteration_cap(int m) {
  return 4 * m + 10;
}

// The linearised contact conditions of one Newton iteration as a complementarity problem:
//   w = S lambda + q >= 0,  lambda >= 0,  lambda . w = 0,
// with S = B K^-1 B^T (symmetric, positive semi-definite) and q = g + B K^-1 R the gaps after the
// step without contact. Equivalent to min 1/2 l^T S l + q^T l over l >= 0, solved exactly by the
// Lawson-Hanson active-set method on S + eps I (eps = kSchurRegularisation max diag S). `tol` is
// the accepted negative gap. `warm` (one flag per constraint) is the active set to start from:
// the last iteration's. Two slots on one contact (a two-way pair whose nodes coincide, as
// mirrored meshes that touch have) are nearly the same constraint, and which of them carries
// the force is decided by round-off; started cold, the method picked the other one from one
// Newton iteration to the next and Newton stalled. Started from the last set, it keeps its
// choice while that choice solves the problem.
Eigen::VectorXd solve_contact_lcp(const Eigen::MatrixXd& S0, const Eigen::VectorXd& q, double tol,
                                  const std::vector<bool>& warm) {
  const int m = static_cast<int>(q.size());
  Eigen::MatrixXd S = S0;
  S.diagonal().array() += kSchurRegularisation * S0.diagonal().cwiseAbs().maxCoeff();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m);
  std::vector<bool> passive = warm;
  bool start_warm = std::find(warm.begin(), warm.end(), true) != warm.end();
  for (int outer = 0; outer < lcp_iteration_cap(m); ++outer) {
    if (!start_warm) {
      const Eigen::VectorXd w = S * lambda + q;
      int j = -1;
      for (int i = 0; i < m; ++i)
        if (!passive[i] && w[i] < -tol && (j < 0 || w[i] < w[j])) j = i;
      if (j < 0) break;
      passive[j] = true;
    }
    // The passive set's equations; a multiplier that would turn negative leaves the set. From a
    // warm start (lambda = 0 everywhere) the constraints with z <= 0 leave at once.
    for (int inner = 0; inner < lcp_iteration_cap(m); ++inner) {
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
      if (np == 0) break;
      if (z.minCoeff() > 0) {
        for (int a = 0; a < np; ++a) lambda[p[a]] = z[a];
        break;
      }
      if (start_warm) {
        for (int a = 0; a < np; ++a)
          if (z[a] <= 0) passive[p[a]] = false;
        continue;
      }
      // Step from lambda towards z until the first passive multiplier reaches zero.
      double alpha = 1;
      for (int a = 0; a < np; ++a)
        if (z[a] <= 0) alpha = std::min(alpha, lambda[p[a]] / (lambda[p[a]] - z[a]));
      for (int a = 0; a < np; ++a) {
        lambda[p[a]] += alpha * (z[a] - lambda[p[a]]);
        if (lambda[p[a]] <= kZeroMultiplier ||
            (z[a] <= 0 && lambda[p[a]] <= kZeroMultiplierRelative * std::abs(z[a]))) {
          lambda[p[a]] = 0;
          passive[p[a]] = false;
        }
      }
    }
    start_warm = false;
  }
  return lambda;
}

}  // namespace

bool Solver::any_contact_active() const {
  for (const auto& s : m_contact.slots())
    if (s.active) return true;
  return false;
}

// The accepted gap: contact_tolerance times the smallest surface edge of the elastic bodies.
double Solver::contact_gap_tolerance() const {
  double gap_tol = std::numeric_limits<double>::max();
  for (const auto& b : m_bodies)
    if (b->is_elastic()) gap_tol = std::min(gap_tol, b->min_edge);
  return gap_tol * m_model.settings.contact_tolerance;
}

// Contact at the current iterate: the geometry of every slot; the slots that are active
// (lambda > 0) or within reach (gap below one element edge of the slave) become the candidates
// of this iteration's complementarity problem, each with its row of B = dg/dx on the free
// equations. A pending prescribed increment moves a gap by its own part, B_p du_p. The residual
// becomes R + B^T lambda of the active slots. `with_curvature`: the iteration assembled its
// matrix, which then takes the active slots' curvature (an iteration that solves with an
// earlier factor has no matrix of its own to add it to).
// Every slot's gap and feature at the bodies' current positions, a body's reach its smallest
// surface edge.
void Solver::detect_contacts() {
  std::vector<const std::vector<double>*> xs;
  std::vector<double> reach;
  for (const auto& b : m_bodies) xs.push_back(&b->x), reach.push_back(b->min_edge);
  m_contact.detect(xs, reach);
}

Solver::ContactLinearisation Solver::linearise_contact(
    double c0, double dt, double time_or_factor, const std::vector<std::vector<double>>* external,
    bool with_curvature) {
  ContactLinearisation con;
  con.residual = m_residual;
  if (m_contact.empty()) return con;
  auto& slots = m_contact.slots();
  detect_contacts();
  for (auto& s : slots) {
    if (s.active) {
      con.worst_gap = std::max(con.worst_gap, std::abs(s.gap));
      con.active++;
    } else {
      con.worst_gap = std::max(con.worst_gap, -s.gap);
    }
    // A slot against a body without its master feature cannot be a row of B (it is far).
    if ((s.active || s.gap < m_bodies[s.slave_body]->min_edge) && (s.master_body < 0 || s.m0 >= 0))
      con.candidates.push_back(static_cast<int>(&s - slots.data()));
  }
  con.rows.resize(con.candidates.size());
  con.gap_shift.assign(con.candidates.size(), 0.0);
  for (std::size_t k = 0; k < con.candidates.size(); ++k) {
    const ContactSlot& s = slots[con.candidates[k]];
    auto add = [&](int body, int node, double w) {
      assert(node >= 0 && "a contact candidate without its master feature");
      const Body& B = *m_bodies[body];
      for (int i = 0; i < 2; ++i) {
        const int e = B.eq[2 * node + i];
        if (e >= 0)
          con.rows[k].push_back({e, w * s.normal[i]});
        else if (m_dirichlet_pending && B.is_elastic())
          con.gap_shift[k] += w * s.normal[i] * B.dirichlet_step[2 * node + i];
      }
    };
    add(s.slave_body, s.slave_node, 1.0);
    if (s.master_body >= 0) {
      add(s.master_body, s.m0, s.m1 >= 0 ? -(1 - s.xi) : -1.0);
      if (s.m1 >= 0) add(s.master_body, s.m1, -s.xi);
    }
    if (s.active)
      for (const auto& [e, w] : con.rows[k]) con.residual[e] += s.lambda * w;
  }
  if (con.active > 0 && with_curvature) add_contact_curvature(c0, dt, time_or_factor, external);
  return con;
}

// Contact curvature: K_eff -= lambda d2g/dx2 (segment_gap_hessian) for every active slot on an
// elastic segment. It couples the slave node to the master's nodes, entries the element pattern
// lacks: the pattern grows once (re-analysed, re-assembled) the first time a pair of nodes meets.
// Without may_grow (the look-ahead) a missing entry leaves the matrix as it is and returns false.
bool Solver::add_contact_curvature(double c0, double dt, double time_or_factor,
                                   const std::vector<std::vector<double>>* external,
                                   bool may_grow) {
  const auto& slots = m_contact.slots();
  std::vector<std::pair<int, int>> missing;
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
        if (a >= 0 && b >= 0 && a >= b && matrix_index(a, b) < 0) missing.push_back({a, b});
    slot_eqs.push_back(eqs);
    slot_index.push_back(static_cast<int>(k));
  }
  if (!missing.empty()) {
    if (!may_grow) return false;
    m_contact_entries.insert(missing.begin(), missing.end());
    build_pattern();
    assemble(c0, dt, true, time_or_factor, external);
  }
  double* values = m_matrix.valuePtr();
  if (!slot_eqs.empty()) m_matrix_curved = true;
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
  return true;
}

// The active-set update of one iteration, through the factorised K_eff: given y0 = dx = K^-1 R,
// Y = K^-1 B^T, S = B Y and q = g + B_p du_p + B y0 give the multipliers (solve_contact_lcp);
// then dx = y0 + Y lambda, and the active set is the lambda > 0.
// Only a working set W of the candidates enters Y and S: the last iteration's active slots and
// those the step without contact takes through (q_k < -tol). A candidate outside W keeps
// lambda_k = 0, which solves the whole problem as long as its gap after the step,
// g_k + B_k dx, stays above -tol, the gap the problem accepts; one that does not joins W and W
// is solved again. Most candidates are open (a surface within an edge of another, of a wall
// plane, of its own fold), and each column of Y is a solve with the factor: with W the step
// pays for the contacts that act, not for those within reach.
void Solver::solve_contact(const ContactLinearisation& con, double gap_tol, Eigen::VectorXd& dx) {
  auto& slots = m_contact.slots();
  const int nc = static_cast<int>(con.candidates.size());
  // Candidate k's gap after the step d: g + B_p du_p + B_k d.
  auto gap_after = [&](int k, const Eigen::VectorXd& d) {
    double g = slots[con.candidates[k]].gap + con.gap_shift[k];
    for (const auto& [e, w] : con.rows[k]) g += w * d[e];
    return g;
  };
  std::vector<char> in_work(nc, 0);
  std::vector<int> work;
  for (int k = 0; k < nc; ++k)
    if (slots[con.candidates[k]].active || gap_after(k, dx) < -gap_tol)
      work.push_back(k), in_work[k] = 1;
  const Eigen::VectorXd y0 = dx;
  Eigen::VectorXd lambda;
  while (!work.empty()) {
    const int nw = static_cast<int>(work.size());
    Eigen::MatrixXd Bt = Eigen::MatrixXd::Zero(m_neq, nw);
    Eigen::VectorXd q(nw);
    std::vector<bool> warm(nw);
    for (int a = 0; a < nw; ++a) {
      for (const auto& [e, w] : con.rows[work[a]]) Bt(e, a) += w;
      q[a] = gap_after(work[a], y0);
      warm[a] = slots[con.candidates[work[a]]].active;
    }
    const Eigen::MatrixXd Y = m_linear.solve(Bt);
    const Eigen::MatrixXd S = Bt.transpose() * Y;
    lambda = solve_contact_lcp(S, q, gap_tol, warm);
    dx = y0 + Y * lambda;
    bool grown = false;
    for (int k = 0; k < nc; ++k)
      if (!in_work[k] && gap_after(k, dx) < -gap_tol) work.push_back(k), in_work[k] = 1, grown = true;
    if (!grown) break;
    ++m_working_set_growths;
  }
  for (auto& s : slots) {
    s.active = false;
    s.lambda = 0;
  }
  for (std::size_t a = 0; a < work.size() && a < std::size_t(lambda.size()); ++a) {
    ContactSlot& s = slots[con.candidates[work[a]]];
    s.lambda = lambda[a];
    s.active = lambda[a] > 0;
  }
}

// Physical contact forces on the nodes, f = m_contact_force_factor lambda B^T of the active
// slots (force ON each body). A slot between two bodies puts f n on its slave and, through the
// weights (1 − ξ) + ξ = 1, −f n on its master: their sums over those slots (contact_bodies) are
// the force of the other bodies alone, without the planes' reactions and self-contact (which
// sums to zero over a body), equal and opposite for a pair.
void Solver::store_contact_forces() {
  for (auto& bp : m_bodies) {
    std::fill(bp->contact.begin(), bp->contact.end(), 0.0);
    bp->contact_bodies = {0, 0};
  }
  for (const auto& s : m_contact.slots()) {
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
    if (s.master_body >= 0 && s.master_body != s.slave_body)
      for (int i = 0; i < 2; ++i) {
        m_bodies[s.slave_body]->contact_bodies[i] += f * s.normal[i];
        m_bodies[s.master_body]->contact_bodies[i] -= f * s.normal[i];
      }
  }
}

}  // namespace solid
