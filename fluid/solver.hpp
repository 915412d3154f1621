// The fluid solver: 2D incompressible Navier-Stokes on a MAC grid, fractional step with AB2
// convection (Euler on the first step), explicit AB2 or Crank-Nicolson diffusion, incremental
// pressure projection with an exact direct Poisson solve. One step reads as the paper's
// procedure (Sec. 3.3; between messages 2 and 3 of common/PROTOCOL.md): predictor (with the
// fibers' force f_f), immersed-solid forcing f_s, boundary conditions, Poisson right-hand side,
// solve, correct.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "boundary.hpp"
#include "config.hpp"
#include "decomposition.hpp"
#include "factored_solver.hpp"
#include "fast_solver.hpp"
#include "field.hpp"
#include "grid.hpp"
#include "momentum.hpp"
#include "slab_solver.hpp"

namespace fluid {

// The coupling hook. Face indexing (flat, as the coupler sees it):
//   u face (i, j) sits at (x_face(i), y_centre(j)), i in [0, nu), nu = nx if x is periodic else
//   nx + 1, j in [0, ny): index i + nu * j.
//   v face (i, j) sits at (x_centre(i), y_face(j)), i in [0, nx), j in [0, nv), nv = ny if y is
//   periodic else ny + 1: index i + nx * j.
// Input of one step (all spans may be empty; they must stay valid during step()):
//   solid_*: immersed solid on the footprint: index, volume fraction alpha in [0, 1] and the mean
//            solid velocity component (u on u faces, v on v faces) over the control volume.
//   fiber_*: body force per unit volume f_f from the fibers (any indices, may differ from the
//            solid's), added in the predictor.
//   sample_*: faces whose new velocity u^(n+1) is returned.
// Faces on a non-periodic boundary carry a prescribed velocity: forcing there is ignored and
// their f_s is returned as 0.
struct CouplingIn {
  std::span<const std::int32_t> solid_u_index, solid_v_index;
  std::span<const double> solid_u_alpha, solid_u_velocity, solid_v_alpha, solid_v_velocity;
  // The part of alpha that belongs to elastic bodies, in the same order, where body_viscosity =
  // "none" takes the viscosity out; empty when every body is elastic (then alpha).
  std::span<const double> solid_u_elastic, solid_v_elastic;
  // The one body on each face, -1 where several are (its ū_s a mean over them); empty with one
  // body in the scene.
  std::span<const std::int32_t> solid_u_body, solid_v_body;
  std::span<const std::int32_t> fiber_u_index, fiber_v_index;
  std::span<const double> fiber_u_force, fiber_v_force;
  std::span<const std::int32_t> sample_u_index, sample_v_index;
  std::span<const std::int32_t> sample_p_index;  // cells i + nx j
};
// Output of one step:
//   solid_*_force: f_s = rho_f alpha (u_s - u~) / dt on the solid's faces (forcing_time and
//                  interface = "sharp" change the target: forcing.cpp), in the input order,
//                  force per unit volume ON THE FLUID (the solid receives its reaction).
//   sample_*:      u^(n+1) on the requested faces, p^(n+1) in the requested cells, in the
//                  input order.
struct CouplingOut {
  std::vector<double> solid_u_force, solid_v_force;
  std::vector<double> sample_u, sample_v, sample_p;
};

// Seconds spent per phase, accumulated over steps.
struct Timings {
  double predictor = 0, boundaries = 0, poisson = 0, projection = 0;
  double cpu = 0;  // CPU time of the phases above (the solver's thread), all together
  long steps = 0;
  long repeats = 0;  // steps redone (coupled iterations), not in `steps`
};

class Solver {
 public:
  // dt: the time step the implicit operators are built for (they are rebuilt if it changes).
  // comm: the ranks the grid is split over in slabs of rows (decomposition.hpp); MPI_COMM_NULL
  // or one rank: the whole grid here, without MPI. On several ranks the fields hold this rank's
  // rows, and the coupling input names faces of those rows only.
  Solver(const Config& c, double dt, MPI_Comm comm = MPI_COMM_NULL);
  ~Solver();

  const Config& config() const { return m_cfg; }
  const Grid& grid() const { return m_grid; }
  const Boundaries& boundaries() const { return m_bnd; }
  const Decomposition& decomposition() const { return m_dec; }
  double time() const { return m_t; }
  long step_count() const { return m_step; }
  // Axis whose direction the fast solver transforms (0 = x, 1 = y).
  int transform_axis() const { return m_t_axis; }

  // One step, t^n -> t^(n+1): predictor, immersed forcing, projection, samples (solver.cpp).
  void step(double dt);
  void step(double dt, const CouplingIn& in, CouplingOut& out);
  // The same step in two parts, so that the first runs before the coupling input exists:
  // begin_step() does everything up to the predictor u~ without the fibers' force (Crank-Nicolson:
  // up to its right-hand side); end_step() adds that force (Crank-Nicolson: then solves), then
  // the immersed forcing, projection and samples. step() is begin_step() then end_step().
  void begin_step(double dt);
  void end_step(double dt, const CouplingIn& in, CouplingOut& out);
  bool is_begun() const { return m_phase == Phase::begun; }
  // Sub-cycling: one coupled step of dt as m equal steps dt / m with the same coupling input
  // (the first begun by begin_step(dt / m)); the solid's force is the mean of the m steps'
  // (their impulse over dt), the samples are the last step's. m = 1 is end_step(dt, ...).
  // Not for coupled iterations (redo_step redoes one step).
  void end_substeps(double dt, int m, const CouplingIn& in, CouplingOut& out);
  // Coupled iterations: the step just taken again from its predictor u~ and p^n (kept by
  // end_step() while set_keep_for_redo(true), the default), with new solid input: immersed
  // forcing, projection, samples; Crank-Nicolson with implicit_forcing = "increment" keeps u^
  // before its solve and solves again. The fibers' force and the explicit prediction are not
  // recomputed (in.fiber_* is ignored). dt must be that of the step.
  void redo_step(double dt, const CouplingIn& in, CouplingOut& out);
  // Whether end_step() keeps u~, v~ and p^n for a redo (three copies of the grid each step).
  void set_keep_for_redo(bool keep) { m_keep_for_redo = keep; }

  // Fields. u: (nx+1) x ny, v: nx x (ny+1), p: nx x ny, with ghosts (Field). After set-up of
  // u and v by hand, call project_initial().
  Field& u() { return m_u; }
  Field& v() { return m_v; }
  Field& p() { return m_p; }
  const Field& u() const { return m_u; }
  const Field& v() const { return m_v; }
  const Field& p() const { return m_p; }
  // body_divergence = "solid": the divergence the last projection left in each cell on purpose
  // (S_c inside elastic bodies, projection.cpp; zero elsewhere), for the health check.
  // Null before any.
  const Field* allowed_divergence() const {
    return m_div_allowed.a.empty() ? nullptr : &m_div_allowed;
  }
  // Make the current velocity discretely divergence-free (boundary values at the current time).
  void project_initial();
  // Checkpoints (checkpoint.cpp): the state a step starts from, between steps: u, v, p with their
  // ghosts, the last step's explicit terms H^n (AB2), its dt, the clock, the boundaries' state.
  // The file holds the whole grid whatever the rank count (a run may resume on another): on
  // several ranks save() gathers on rank 0, which passes the file (the others nullptr); load()
  // reads the whole grid on every rank and keeps its rows.
  void save(fsi::H5File* h5) const;
  void save(fsi::H5File& h5) const { save(&h5); }
  void load(const fsi::H5File& h5);

  // First active u column (0 if x periodic, else 1) and v row.
  int i0() const { return m_i0; }
  int j0() const { return m_j0; }

  const Timings& timings() const { return m_time; }
  void reset_timings() { m_time = {}; }
  // Acceleration of the body force at time t (force per unit volume / rho + g).
  std::array<double, 2> body_acceleration(double t) const;
  // On several ranks: the transposes of the Poisson and Helmholtz solves so far (count, wall
  // seconds, bytes this rank sent).
  struct TransposeTraffic {
    long count = 0;
    double seconds = 0, bytes = 0;
  };
  TransposeTraffic transpose_traffic() const;
  // The bare Poisson solver (for the benchmark's floor and tests; on one rank).
  FastSolver& poisson() { return *m_poisson; }

 private:
  // Where the step stands: between steps, its first part done (begin_step), or done with its
  // predictor kept (a redo may follow).
  enum class Phase { between_steps, begun, redoable };

  void build_implicit(double dt);                                            // solver.cpp
  void explicit_terms();                                                     // predictor.cpp
  void predictor(double dt, double t_half);                                  // predictor.cpp
  void predictor_implicit(double dt, double t_half);                         // predictor.cpp
  void add_fiber_force(double dt, const CouplingIn& fibers);                 // predictor.cpp
  void solve_implicit(const CouplingIn& in);                                 // predictor.cpp
  void immersed_forcing(double dt, const CouplingIn& in, CouplingOut& out);  // forcing.cpp
  // The fraction of the way to u_s a face of volume fraction alpha is forced in a step of dt:
  // alpha (Eq. 21), or beta with forcing_time (forcing.cpp).
  double forcing_fraction(double alpha, double dt) const;
  // interface = "sharp": the value each solid face of family comp (0 = u, 1 = v) is forced to
  // from the predictor, in the input's order (forcing.cpp).
  void sharp_targets(int comp, const CouplingIn& in, std::vector<double>& target);
  void sealed_cells();
  void remove_body_viscosity(double dt, const CouplingIn& in);  // body_viscosity.cpp
  // dt, and the time whose boundary pressures p^(n+1) takes (t^n + dt; t^n for project_initial).
  void project(double dt, double t_new);                                    // projection.cpp
  void dilating_cells(const CouplingIn& in);                                 // projection.cpp
  // The face pressures at time t into m_face_p (pressure sides; per row; solver.cpp).
  void face_pressure(double t);
  void keep_predictor();                                                     // solver.cpp
  // implicit_forcing = "increment": a redo solves the increment again (its forcing is on u^).
  bool solve_in_redo() const { return m_cfg.implicit && m_cfg.forcing_in_increment; }
  void restore_predictor();                                                  // solver.cpp
  void correct(double dt, const CouplingIn& in, CouplingOut& out);           // solver.cpp
  void sample(const CouplingIn& in, CouplingOut& out) const;                 // solver.cpp
  // j, when this rank holds row j of u or p (comp 0, 2) or of v (1); else a clear error.
  int owned(int j, int comp) const;                                          // solver.cpp
  // (i, j) of the face with the coupling index idx, of u (comp 0) or v (comp 1).
  std::array<int, 2> face_of(int comp, std::int32_t idx) const {
    const int w = comp == 0 ? m_grid.nu() : m_grid.nx();
    return {int(idx % w), int(idx / w)};
  }
  // Index of unknown (i, j) in a direct solver's data: FastSolver's t-fastest layout (nt: its
  // t count), or on several ranks the slab's rows (nt: the row length, x unknowns).
  int buf_index(int i, int j, int i_first, int j_first, int nt) const {
    if (!m_dec.serial()) return (i - i_first) + nt * (j - m_dec.lo());
    return m_t_axis == 0 ? (i - i_first) + nt * (j - j_first) : (j - j_first) + nt * (i - i_first);
  }
  // The direct solvers, whichever kind: 0 = u, 1 = v (Helmholtz), 2 = pressure (Poisson).
  double* solve_data(int which);
  int solve_nt(int which) const;
  std::size_t solve_size(int which) const;  // values in solve_data() on this rank
  void solve(int which);
  // First row of this rank's u, p rows and of its v unknowns (j0 or lo).
  int row_lo() const { return m_dec.lo(); }
  int row_hi() const { return m_dec.hi(); }
  int v_row_lo() const { return std::max(m_j0, m_dec.lo()); }

  Config m_cfg;
  Grid m_grid;
  Decomposition m_dec;
  Boundaries m_bnd;
  SpongeWeights m_sponge;
  OuterRows m_outer_u, m_outer_v;  // upwind3's rows beyond the slab (several ranks)
  std::vector<double> m_upwind3_work;  // upwind3_terms scratch
  int m_t_axis = 0;
  int m_i0 = 0, m_j0 = 0;
  // u faces the predictor and the projection step: [m_iu0, m_iu1) (the interior, and the
  // boundary faces of pressure sides).
  int m_iu0 = 0, m_iu1 = 0;
  // Pressure sides: the face pressure of the projection's p^(n+1) and its increment phi_b, per
  // row (sized once; empty without pressure sides).
  FacePressure m_face_p, m_phi_b;
  double m_t = 0, m_dt_prev = 0, m_dt_implicit = 0;
  long m_step = 0;
  double m_nu = 0;
  Field m_u, m_v, m_p, m_phi;
  Field m_hu, m_hv, m_hu_old, m_hv_old, m_lu, m_lv;
  // The last step's predictor u~ and p^n, and its t^n and dt' (for redo_step).
  Field m_u_pred, m_v_pred, m_p_start;
  double m_t_start = 0, m_dt_prev_start = 0;
  bool m_keep_for_redo = true;
  Phase m_phase = Phase::between_steps;
  double m_begun_dt = 0;  // dt of the step begin_step() began
  std::unique_ptr<FastSolver> m_poisson, m_helm_u, m_helm_v;
  std::unique_ptr<SlabSolver> m_slab_poisson, m_slab_u, m_slab_v;  // on several ranks
  std::unique_ptr<FactoredSolver> m_fact_u, m_fact_v;  // helmholtz = "factored"
  // Crank-Nicolson: the boundary increment of the step's solve, per component, in the Helmholtz
  // solver's layout (predictor_implicit), until the step's last solve (a redo's, "increment").
  std::array<std::vector<double>, 2> m_rhs;
  // Crank-Nicolson or body_viscosity = "none": u^n (with t^n's boundary values and ghosts) during
  // the step; implicit_forcing = "increment": the forcing alpha (u_s - u^) per solid face of the
  // coupling input (solve_implicit).
  Field m_un, m_vn;
  std::array<std::vector<double>, 2> m_pull;
  // interface = "sharp": each family's volume fractions and input slots on the whole grid (0
  // and -1 between steps), the step's targets, and sharp_targets' scratch.
  std::array<std::vector<double>, 2> m_sharp_alpha, m_sharp_target, m_sharp_first;
  std::array<std::vector<std::int32_t>, 2> m_sharp_slot;
  struct SharpLine {
    int i = -1, j = -1;  // the neighbour the face's line reads (i = -1: none)
    double r = 0;        // its weight, dist / span
  };
  std::array<std::vector<SharpLine>, 2> m_sharp_lines;
  // Per family, the listed faces (1: set whole on a rigid body, 2: otherwise, 0 between
  // steps) and their list; the step's cells walled in by whole faces (m_sharp_sealed), whose
  // p^n project() keeps (m_sharp_kept). Scratch: the cells' marks, a queue, the marked cells.
  std::array<std::vector<std::uint8_t>, 2> m_sharp_whole;
  std::vector<std::pair<int, std::int32_t>> m_sharp_whole_list;  // (family, face) of each
  std::vector<std::uint8_t> m_sharp_mark;
  std::vector<std::int32_t> m_sharp_sealed, m_sharp_queue, m_sharp_touched;
  std::vector<double> m_sharp_kept;
  // body_viscosity = "none": the elastic bodies' volume fraction per u, v face, zero
  // between steps; the step's α, centre fluxes (u, v) and corner fluxes on their boxes
  // (body_viscosity.cpp).
  std::array<Field, 2> m_body_alpha;
  std::array<Patch, 2> m_bv_phi, m_bv_centre;
  Patch m_bv_corner;
  // body_viscosity = "none": whether the last step's footprint had faces of an elastic body on
  // any rank (true before the first step; a checkpoint keeps it), and whether this step kept uⁿ
  // in m_un, m_vn (begin_step keeps it for the correction only while there are elastic bodies;
  // Crank-Nicolson always).
  bool m_body_faces = true;
  bool m_un_kept = false;
  std::array<std::vector<double>, 2> m_force_sum;  // end_substeps: the solid force's sums
  // body_divergence = "solid" (projection.cpp): the step's cells inside elastic bodies with
  // their φ (the smallest elastic α of the cell's four faces) and D ū_s, the faces' elastic α
  // and ū_s while the list is made (zero otherwise), per-row sums, and the divergence the
  // projection left in those cells.
  struct DilatingCell {
    int i, j;
    double phi, div;  // φ_c and D ū_s of the cell
  };
  std::vector<DilatingCell> m_dilating, m_dilated;
  bool m_dilate_step = false;  // dilating_cells() found elastic faces on some rank
  // The share w of the bodies' divergence the fluid takes in this (sub)step: S_c = w φ_c (...),
  // set for the step's substep count by end_substeps (dilation_share, projection.cpp).
  double m_dilation_share = 0;
  double dilation_share(int substeps) const;  // projection.cpp
  std::array<Field, 2> m_dil_alpha, m_dil_us, m_dil_body;  // m_dil_body: body + 1, 0 for several
  std::vector<double> m_dil_rows;
  Field m_div_allowed;
  Timings m_time;
};

// Set the initial velocity of the configuration (rest, uniform, Taylor-Green, vortex) and project.
void set_initial(Solver& s);

}  // namespace fluid
