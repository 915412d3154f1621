// Halo exchanges, reductions and gathers of the row slabs (decomposition.hpp).
#include "decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "error.hpp"
#include "slab_solver.hpp"

namespace fluid {

Decomposition::Decomposition(MPI_Comm comm, int ny, bool periodic_y, const std::string& what)
    : m_comm(comm), m_ny(ny), m_lo(0), m_hi(ny), m_block(ny), m_periodic(periodic_y) {
  if (comm == MPI_COMM_NULL) return;
  MPI_Comm_size(comm, &m_ranks);
  MPI_Comm_rank(comm, &m_rank);
  if (m_ranks == 1) return;
  // The wall ghosts of u use the first two rows; a stencil reads one row beyond the slab.
  try {
    const RowSplit s = split_rows(ny, m_ranks, m_rank, 2);
    m_lo = s.lo, m_hi = s.hi, m_block = s.block;
  } catch (const fsi::InputError& e) {
    throw fsi::InputError(fmt::format(
        "{} {} (the fluid's ranks: mpirun -n, [fluid] ranks or ./fsi run --fluid-ranks)", what,
        e.what()));
  }
}

int Decomposition::owner(int j) const {
  if (m_ranks == 1) return 0;
  return std::clamp(std::clamp(j, 0, m_ny - 1) / m_block, 0, m_ranks - 1);
}

// One row down and one up: `to_down` to the lower neighbour while `from_up` comes from the upper
// one, then `to_up` up while `from_down` comes from below (n doubles each; a missing neighbour at
// a non-periodic end sends and receives nothing). Counted as one halo.
void Decomposition::swap_rows(const double* to_down, double* from_up, const double* to_up,
                              double* from_down, int n, int tag) const {
  const bool first = m_rank == 0, last = m_rank == m_ranks - 1;
  const int down = first ? (m_periodic ? m_ranks - 1 : MPI_PROC_NULL) : m_rank - 1;
  const int up = last ? (m_periodic ? 0 : MPI_PROC_NULL) : m_rank + 1;
  const double t0 = MPI_Wtime();
  MPI_Sendrecv(to_down, n, MPI_DOUBLE, down, tag, from_up, n, MPI_DOUBLE, up, tag, m_comm,
               MPI_STATUS_IGNORE);
  MPI_Sendrecv(to_up, n, MPI_DOUBLE, up, tag + 1, from_down, n, MPI_DOUBLE, down, tag + 1, m_comm,
               MPI_STATUS_IGNORE);
  m_traffic.halo_seconds += MPI_Wtime() - t0;
  ++m_traffic.halos;
  m_traffic.halo_bytes += 8.0 * n * ((down != MPI_PROC_NULL) + (up != MPI_PROC_NULL));
}

// Row lo down (the lower neighbour's row hi), row hi up from it; row hi - 1 up, row lo - 1 in.
void Decomposition::halo(Field& f) const {
  if (m_ranks == 1) return;
  swap_rows(f.row(m_lo) - 1, f.row(m_hi) - 1, f.row(m_hi - 1) - 1, f.row(m_lo - 1) - 1, f.sx,
            7301);
}

// Row lo + 1 down (the lower neighbour's hi + 1), row hi - 2 up (the upper one's lo - 2); a slab
// has at least two rows.
void Decomposition::outer_rows(const Field& f, OuterRows& o) const {
  if (m_ranks == 1) return;
  o.below.resize(f.sx);
  o.above.resize(f.sx);
  swap_rows(f.row(m_lo + 1) - 1, o.above.data(), f.row(m_hi - 2) - 1, o.below.data(), f.sx, 7303);
}

// Times a collective into the traffic counters.
template <class F>
void Decomposition::collective(F&& f) const {
  const double t0 = MPI_Wtime();
  f();
  m_traffic.collective_seconds += MPI_Wtime() - t0;
  ++m_traffic.collectives;
}

double Decomposition::sum(double x) const {
  if (m_ranks == 1) return x;
  double s = 0;
  collective([&] { MPI_Allreduce(&x, &s, 1, MPI_DOUBLE, MPI_SUM, m_comm); });
  return s;
}

void Decomposition::sum(double* x, int n) const {
  if (m_ranks == 1) return;
  collective([&] { MPI_Allreduce(MPI_IN_PLACE, x, n, MPI_DOUBLE, MPI_SUM, m_comm); });
}

int Decomposition::argmax(double x) const {
  if (m_ranks == 1) return 0;
  struct {
    double value;
    int rank;
  } in{std::isnan(x) ? std::numeric_limits<double>::infinity() : x, m_rank}, out{};
  collective([&] { MPI_Allreduce(&in, &out, 1, MPI_DOUBLE_INT, MPI_MAXLOC, m_comm); });
  return out.rank;
}

void Decomposition::gather_all_rows(const double* mine, double* all) const {
  if (m_ranks == 1) {
    std::copy(mine, mine + m_ny, all);
    return;
  }
  std::vector<int> counts(m_ranks), displs(m_ranks);
  for (int r = 0; r < m_ranks; ++r) {
    displs[r] = std::min(m_ny, r * m_block);
    counts[r] = std::min(m_ny, (r + 1) * m_block) - displs[r];
  }
  collective([&] {
    MPI_Allgatherv(mine, m_hi - m_lo, MPI_DOUBLE, all, counts.data(), displs.data(), MPI_DOUBLE,
                   m_comm);
  });
}

std::vector<double> Decomposition::gather_field(const Field& f) const {
  if (m_ranks == 1) return f.a;
  // Rank r sends its rows [lo, top) (top: f's stored end, hi or the v faces' ny + 1), rank 0
  // also the ghost row below, the last rank the ghost row above: the whole grid's rows -1 ..
  // nj once each.
  auto first = [&](int r) { return lo_of(r) - (r == 0 ? 1 : 0); };
  auto end = [&](int r) {
    const int top = r == m_ranks - 1 ? f.nj : hi_of(r);
    return top + (r == m_ranks - 1 ? 1 : 0);
  };
  std::vector<int> counts(m_ranks), displs(m_ranks);
  for (int r = 0; r < m_ranks; ++r) {
    counts[r] = (end(r) - first(r)) * f.sx;
    displs[r] = (first(r) + 1) * f.sx;
  }
  if (end(m_rank) > f.jhi + 1 || first(m_rank) < f.jlo - 1)
    fsi::fail("fluid::Decomposition::gather_field: a field of rows [{}, {}) on rank {}", f.jlo,
              f.jhi, m_rank);
  std::vector<double> all(m_rank == 0 ? std::size_t(f.sx) * (f.nj + 2) : 0);
  collective([&] {
    MPI_Gatherv(f.row(first(m_rank)) - 1, counts[m_rank], MPI_DOUBLE, all.data(), counts.data(),
                displs.data(), MPI_DOUBLE, 0, m_comm);
  });
  return all;
}

void Decomposition::broadcast(void* x, int bytes, int root) const {
  if (m_ranks == 1) return;
  collective([&] { MPI_Bcast(x, bytes, MPI_BYTE, root, m_comm); });
}

void Decomposition::gather_rows(const double* local, int n_per_row, int local_rows, double* all,
                                int extra_last_rows) const {
  if (m_ranks == 1) {
    std::copy(local, local + std::size_t(n_per_row) * local_rows, all);
    return;
  }
  std::vector<int> counts(m_ranks), displs(m_ranks);
  const RowSplit s = split_rows(m_ny, m_ranks, m_rank);
  for (int r = 0; r < m_ranks; ++r) {
    const int rows = s.hi_of(r) - s.lo_of(r) + (r == m_ranks - 1 ? extra_last_rows : 0);
    counts[r] = rows * n_per_row;
    displs[r] = s.lo_of(r) * n_per_row;
  }
  if (local_rows * n_per_row != counts[m_rank])
    fsi::fail("fluid::Decomposition::gather_rows: {} rows given, {} expected", local_rows,
              counts[m_rank] / std::max(1, n_per_row));
  MPI_Gatherv(local, counts[m_rank], MPI_DOUBLE, all, counts.data(), displs.data(), MPI_DOUBLE, 0,
              m_comm);
}

}  // namespace fluid
