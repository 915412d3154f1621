// The fluid's grid split over ranks in slabs of cell rows (y), FFTW's block split (see
// slab_solver.hpp): rank r holds cell rows [lo, hi), u and p rows [lo, hi), v rows [lo, hi) and
// on the last rank also the top boundary face ny. Every field keeps one ghost row on each side,
// filled from the neighbours by halo(); with a periodic y the first and last ranks are
// neighbours. On one rank (the default) nothing here calls MPI: the solver is the serial one.
#pragma once

#include <mpi.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "field.hpp"

namespace fluid {

class Decomposition {
 public:
  // Rows of a grid of ny cell rows split over the ranks of comm (MPI_COMM_NULL: one rank).
  // Throws fsi::InputError when a rank would hold fewer than two rows, its message beginning
  // with `what` (the grid's key and file) and naming the rank counts that fit.
  Decomposition(MPI_Comm comm, int ny, bool periodic_y, const std::string& what = "the fluid's");

  bool serial() const { return m_ranks == 1; }
  int rank() const { return m_rank; }
  int ranks() const { return m_ranks; }
  MPI_Comm comm() const { return m_comm; }
  int lo() const { return m_lo; }
  int hi() const { return m_hi; }
  // The rank whose cell rows hold row j (j clamped to the grid's rows).
  int owner(int j) const;
  // Rank r's cell rows [lo_of(r), hi_of(r)).
  int lo_of(int r) const { return m_ranks == 1 ? 0 : std::min(m_ny, r * m_block); }
  int hi_of(int r) const { return m_ranks == 1 ? m_ny : std::min(m_ny, (r + 1) * m_block); }
  // The stored rows of f (its ghost rows included, of the whole grid's first and last rank only)
  // gathered on rank 0 in the one-rank layout of a Field of f's extents; empty elsewhere.
  // Collective.
  std::vector<double> gather_field(const Field& f) const;
  bool has_bottom() const { return m_rank == 0; }
  bool has_top() const { return m_rank == m_ranks - 1; }
  // Rows a field stores besides its ghosts: cell-row fields [lo, hi); the v faces [lo, v_hi()).
  int v_hi() const { return has_top() ? m_ny + 1 : m_hi; }
  bool owns_row(int j) const { return j >= m_lo && j < m_hi; }
  bool owns_v_row(int j) const { return j >= m_lo && j < v_hi(); }

  // The ghost rows lo - 1 and hi of f from the neighbours (the whole stored rows, ghost columns
  // included). Collective.
  void halo(Field& f) const;
  // The second rows beyond the slab, lo - 2 and hi + 1, of f into o (the whole stored rows;
  // those beyond a non-periodic end left as they are). Collective; nothing on one rank.
  void outer_rows(const Field& f, OuterRows& o) const;
  // Sums and maxima over the ranks (collective; on one rank the value itself).
  double sum(double x) const;
  void sum(double* x, int n) const;
  // The rank holding the largest value (NaN counts as larger than every number; ties: the
  // lowest rank). Collective.
  int argmax(double x) const;
  // One value per cell row: this rank's rows [lo, hi) in, every row's out (in row order), on
  // every rank. Collective.
  void gather_all_rows(const double* mine, double* all) const;
  // The bytes of `x` from rank `root` to every rank. Collective.
  void broadcast(void* x, int bytes, int root) const;
  // What the exchanges cost this rank so far (the scaling model's input): wall seconds, calls
  // and bytes sent, for the halos (two messages each) and for the reductions and gathers.
  struct Traffic {
    double halo_seconds = 0, collective_seconds = 0;
    long halos = 0, collectives = 0;
    double halo_bytes = 0;
  };
  const Traffic& traffic() const { return m_traffic; }
  // Each rank's rows [lo, hi) of `n_per_row` values (row-major; the last rank's with
  // `extra_last_rows` more, e.g. the top v faces) gathered on rank 0 into `all`, in row order.
  // Collective.
  void gather_rows(const double* local, int n_per_row, int local_rows, double* all,
                   int extra_last_rows = 0) const;

 private:
  void swap_rows(const double* to_down, double* from_up, const double* to_up, double* from_down,
                 int n, int tag) const;
  template <class F>
  void collective(F&& f) const;

  MPI_Comm m_comm = MPI_COMM_NULL;
  int m_rank = 0, m_ranks = 1, m_ny = 0, m_lo = 0, m_hi = 0, m_block = 0;
  bool m_periodic = false;
  mutable Traffic m_traffic;
};

}  // namespace fluid
