// Boundary conditions of the MAC grid: boundary-face values of the normal velocity (walls,
// inflow profile with its ramp, convective outflow with global flux correction) and ghost values
// of the tangential velocity (no-slip by quadratic extrapolation, which is exact for a parabolic
// profile; free slip by reflection; periodic copies).
//
// A pressure side (left or right) gives the pressure p_b(t) on the boundary face instead of the
// normal velocity. Its u faces are unknowns of the step: the predictor steps them with the
// momentum equation, the explicit terms taken from the first interior face (zero normal gradient:
// the flow crosses the side developed) and the pressure gradient (p_0 - p_b) / (w_0 / 2) to the
// face's value; the projection corrects them with phi_b = p_b(t^{n+1}) - p_b(t^n) on the face
// (Dirichlet: the cell-centred ghost is 2 phi_b - phi_0). The tangential velocity has zero normal
// gradient there (ghost = first interior value). The Poisson problem is then regular (the face
// fixes the pressure level) and compatible whatever flux crosses the side.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "config.hpp"
#include "decomposition.hpp"
#include "field.hpp"
#include "grid.hpp"
#include "h5.hpp"

namespace fluid {

// Ghost value of the tangential component at one side: g = ga q0 + gb q1 + gc * data, with q0,
// q1 the first two interior values and data the wall speed (0 for inflow).
struct GhostRule {
  double ga = 0, gb = 0, gc = 0;
  bool is_data = false;  // outflow: the ghost is a value of its own (convected), not a rule
};

// Per row j of the left (0) and right (1) side: the pressure on a pressure side's boundary face;
// empty for the other sides.
using FacePressure = std::array<std::vector<double>, 2>;

class Boundaries {
 public:
  // d: the rows this process holds (its loops run over them; sums over the sides are taken
  // over all ranks, in the same order of collectives on every rank).
  // d must outlive the Boundaries (the solver's own).
  Boundaries(const Grid& g, const std::array<SideBc, 4>& bc, const Decomposition& d);
  const SideBc& side(int s) const { return m_bc[s]; }
  const GhostRule& rule(int s) const { return m_rule[s]; }
  bool has_outflow() const { return m_has_outflow; }
  bool is_pressure(int s) const { return m_bc[s].type == BcType::pressure; }

  // Inflow velocity into the domain at tangential coordinate s, time t.
  double inflow(int side, double s, double t) const;
  // Normal-velocity boundary faces at time t: walls 0 (and their tangential speed at t for the
  // ghosts), inflow profile. Outflow faces: convected
  // from their current values over dt, then all outflow faces are shifted by one constant so
  // that the net flux through the boundary is zero. Tangential outflow ghosts are convected too.
  void advance_normal(Field& u, Field& v, double t, double dt);
  // Tangential ghosts (rules; outflow ghosts keep their convected value) and periodic copies.
  void fill_ghosts(Field& u, Field& v) const;
  // Periodic copies and ghosts of a cell-centred field: zero gradient, and on a pressure side
  // the value face[s][j] on the boundary face (ghost = 2 face[s][j] - first interior value).
  void fill_scalar(Field& p, const FacePressure& face = {}) const;
  // Net volume flux into the domain through its boundary (per unit depth).
  double net_inflow(const Field& u, const Field& v) const;
  // What advance_normal() carries from step to step (the outflows' last interior lines, the
  // walls' speeds), for checkpoints: saved into and loaded from group `group`, the whole
  // boundary's (on several ranks save() gathers on rank 0, which passes the file; collective).
  void save(fsi::H5File* h5, const std::string& group) const;
  void load(const fsi::H5File& h5, const std::string& group);

 private:
  // Rows [k0, k1) of a left/right side (cell rows; v: up to v_hi) and whether a bottom/top
  // side is on this rank.
  int row_lo() const { return m_d.lo(); }
  int row_hi() const { return m_d.hi(); }
  bool holds(int s) const { return s < 2 || (s == bottom ? m_d.has_bottom() : m_d.has_top()); }

  // Per-position values along side s, given for this rank's positions in m_mine (its rows, or
  // every column when it holds a bottom or top side), as the whole side's on every rank: sums
  // over a side then run in the one-rank order, and give its bits on any number of ranks.
  const std::vector<double>& whole_side(int s) const;

  const Grid& m_g;
  const Decomposition& m_d;
  std::array<SideBc, 4> m_bc;
  std::array<GhostRule, 4> m_rule;
  bool m_has_outflow = false;
  std::array<std::vector<double>, 4> m_prev;  // Orlanski: last step's first interior line
  std::array<double, 4> m_speed{};            // walls: tangential speed at the last advance_normal
  mutable std::vector<double> m_mine, m_all;  // whole_side()'s buffers
};

}  // namespace fluid
