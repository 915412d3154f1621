// The direct fast solver on row slabs: local FFTW transforms, FFTW's MPI transposes, Thomas
// sweeps on whole lines (slab_solver.hpp).
#include "slab_solver.hpp"

#include <algorithm>

#include "error.hpp"
#include "protocol.hpp"

namespace fluid {
namespace {

// count lines of length n, `stride` apart within a line and `dist` apart from line to line.
fftw_plan lines_plan(int n, int count, double* p, int stride, int dist, fftw_r2r_kind kind) {
  if (count <= 0 || n <= 0) return nullptr;
  const int dims[1] = {n};
  fftw_r2r_kind k[1] = {kind};
  fftw_plan plan =
      fftw_plan_many_r2r(1, dims, count, p, nullptr, stride, dist, p, nullptr, stride, dist, k,
                         FFTW_ESTIMATE);
  if (!plan) fsi::fail("fluid::SlabSolver: FFTW could not plan a transform of {} lines", count);
  return plan;
}

// FFTW_MEASURE: a transpose only moves values, so whichever algorithm the timings pick, the
// results keep their bits (the transforms stay FFTW_ESTIMATE, whose round-off is the same from
// run to run); measured, it halves the transposes' time against FFTW_ESTIMATE
// (runs/bench-fluid-ranks). Planning overwrites the buffer: the solver's input is written whole
// before each solve.
fftw_plan transpose_plan(int n0, int n1, int b0, int b1, double* p, MPI_Comm comm,
                         unsigned flags) {
  fftw_plan plan = fftw_mpi_plan_many_transpose(n0, n1, 1, b0, b1, p, p, comm,
                                                FFTW_MEASURE | flags);
  if (!plan) fsi::fail("fluid::SlabSolver: FFTW could not plan a {} x {} transpose", n0, n1);
  return plan;
}

void run(fftw_plan p) {
  if (p) fftw_execute(p);
}

int ceil_div(int a, int b) { return (a + b - 1) / b; }

}  // namespace

int RowSplit::lo_of(int r) const { return std::min(rows, r * block); }
int RowSplit::hi_of(int r) const { return std::min(rows, (r + 1) * block); }

RowSplit split_rows(int rows, int ranks, int rank, int min_rows) {
  if (ranks < 1 || rank < 0 || rank >= ranks)
    fsi::fail("fluid: rank {} of {} ranks", rank, ranks);
  RowSplit s;
  s.rows = rows;
  s.ranks = ranks;
  s.rank = rank;
  s.block = fsi::proto::fluid_row_block(rows, ranks);
  // Blocks of ceil(rows / P): the last rank holds what is left, at least min_rows.
  auto last = [&](int p) { return rows - fsi::proto::fluid_row_block(rows, p) * (p - 1); };
  if (last(ranks) < min_rows) {
    int below = ranks - 1, above = ranks + 1;
    while (below > 1 && last(below) < min_rows) --below;
    while (above <= rows && last(above) < min_rows) ++above;
    const std::string other = above <= rows ? fmt::format("{} or {}", below, above)
                                            : fmt::format("{}", below);
    throw fsi::InputError(fmt::format(
        "{} cell rows cannot be split over {} ranks: blocks of {} rows leave the last rank {} "
        "(each needs {}); {} ranks would do",
        rows, ranks, s.block, std::max(0, last(ranks)), min_rows, other));
  }
  s.lo = s.lo_of(rank);
  s.hi = s.hi_of(rank);
  return s;
}

SlabSolver::SlabSolver(const Operator1D& t, const Operator1D& s, double sigma, int t_axis,
                       int rows, int pad, MPI_Comm comm)
    : m_t_axis(t_axis),
      m_pad(pad),
      m_nx(t_axis == 0 ? t.n : s.n),
      m_nt(t.n),
      m_ns(s.n),
      m_transform_s(s.lo == Closure::periodic),
      m_comm(comm) {
  static const bool initialised = [] {
    fftw_mpi_init();
    return true;
  }();
  (void)initialised;
  int ranks = 1, rank = 0;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm_rank(comm, &rank);
  if ((t_axis == 0 ? s.n : t.n) + pad != rows)
    fsi::fail("fluid::SlabSolver: {} rows with {} padded do not match the y operator's {}",
              rows, pad, t_axis == 0 ? s.n : t.n);
  m_split = split_rows(rows, ranks, rank);
  const int nloc = m_split.hi - m_split.lo;
  // The other direction's split in the transposed layouts: x columns (t = y: nx, t = x: the
  // wavenumbers of t).
  const int ncol = m_nx, bcol = ceil_div(ncol, ranks);
  const int c0 = std::min(ncol, rank * bcol), c1 = std::min(ncol, (rank + 1) * bcol);

  // Storage: the largest of the layouts FFTW's transposes pass through.
  ptrdiff_t n[2] = {rows, ncol}, ln0, l0s, ln1, l1s;
  const ptrdiff_t alloc = fftw_mpi_local_size_many_transposed(2, n, 1, m_split.block, bcol, comm,
                                                              &ln0, &l0s, &ln1, &l1s);
  if (ln0 != nloc || l0s != m_split.lo || ln1 != c1 - c0 || l1s != c0)
    fsi::fail("fluid::SlabSolver: FFTW's split differs from the slab's");
  const std::size_t size = std::max<std::size_t>(
      {std::size_t(alloc), std::size_t(nloc) * m_nx, std::size_t(c1 - c0) * rows, 1});
  m_buf = fftw_alloc_real(size);
  std::fill(m_buf, m_buf + size, 0.0);
  // A transpose sends this rank's values but its own block: about (P - 1) / P of its share.
  m_bytes_per_transpose = 8.0 * double(rows) * ncol / ranks * (ranks - 1) / ranks;

  // A stretched t (both directions stretched): its eigenvectors as dense products on the
  // t-lines, as FastSolver takes them (eigen_transform; the same matrices on every rank, so each
  // line's result is the one-rank solve's).
  const bool stretched_t = !t.a.empty();
  if (stretched_t && m_transform_s)
    fsi::fail("fluid::SlabSolver: a stretched transform direction beside a periodic one");
  EigenTransform et;
  TransformPair kt{};
  if (stretched_t) {
    et = eigen_transform(t);
    m_lt = et.lambda;
    m_norm = 1;
  } else {
    kt = transform_pair(m_nt, t.lo, t.hi);
    m_lt = eigenvalues(m_nt, t.h, t.lo, t.hi);
    m_norm = kt.norm;
  }
  int stride;  // the local wavenumbers' count in the layout of the solve along s
  // The t-transforms as FastSolver takes them (FFTW's plan or the matrix product; each line's
  // result is the same either way on any split), on this rank's t-lines.
  auto t_lines = [&](int count, int dist, double* p) {
    m_t_lines = p;
    if (stretched_t) {
      if (count <= 0) return;
      m_dense_fwd = std::make_unique<DenseTransform>(et.fwd, m_nt, count, dist, false);
      m_dense_bwd = std::make_unique<DenseTransform>(et.bwd, m_nt, count, dist, false);
      return;
    }
    m_t_fwd = lines_plan(m_nt, count, p, 1, dist, kt.fwd);
    m_t_bwd = lines_plan(m_nt, count, p, 1, dist, kt.bwd);
    m_dense_fwd = DenseTransform::if_preferred(kt.fwd, m_nt, count, dist);
    m_dense_bwd = DenseTransform::if_preferred(kt.bwd, m_nt, count, dist);
  };
  if (t_axis == 0) {
    t_lines(nloc, m_nt, m_buf);
    m_to_lines = transpose_plan(rows, m_nt, m_split.block, bcol, m_buf, comm,
                                FFTW_MPI_TRANSPOSED_OUT);
    m_from_lines = transpose_plan(m_nt, rows, bcol, m_split.block, m_buf, comm,
                                  FFTW_MPI_TRANSPOSED_IN);
    m_k0 = c0;
    m_nk = c1 - c0;
    stride = m_nk;
  } else {
    m_to_y = transpose_plan(rows, m_ns, m_split.block, bcol, m_buf, comm, 0);
    t_lines(c1 - c0, rows, m_buf + pad);
    m_to_lines = transpose_plan(m_ns, rows, bcol, m_split.block, m_buf, comm,
                                FFTW_MPI_TRANSPOSED_OUT);
    m_from_lines = transpose_plan(rows, m_ns, m_split.block, bcol, m_buf, comm,
                                  FFTW_MPI_TRANSPOSED_IN);
    m_from_y = transpose_plan(m_ns, rows, bcol, m_split.block, m_buf, comm, 0);
    m_k0 = m_split.lo - pad;
    m_nk = nloc;
    stride = nloc;
  }
  // The s lines of the solve: x[c + stride * j], j in [0, ns); for t = x they start after the
  // padded rows.
  double* base = m_buf + (t_axis == 0 ? std::size_t(pad) * stride : 0);
  const std::size_t lsize = std::size_t(stride) * m_ns;
  if (m_transform_s) {
    const TransformPair ks = transform_pair(m_ns, s.lo, s.hi);
    m_s_fwd = lines_plan(m_ns, stride, base, stride, 1, ks.fwd);
    m_s_bwd = lines_plan(m_ns, stride, base, stride, 1, ks.bwd);
    m_ls = eigenvalues(m_ns, s.h, s.lo, s.hi);
    m_norm *= ks.norm;
    m_inv_eig.assign(lsize, 0);
    for (int j = 0; j < m_ns; ++j) {
      for (int c = 0; c < stride; ++c) {
        const int k = m_k0 + c;
        if (k < 0) continue;  // a padded row
        const double e = m_lt[k] + m_ls[j] - sigma;
        m_inv_eig[c + std::size_t(stride) * j] = (e == 0.0) ? 0.0 : 1.0 / (e * m_norm);
      }
    }
  } else {
    // Thomas factors of (a, b + lambda_k - sigma, c) per local wavenumber, as FastSolver's.
    m_a = s.a;
    m_zero_col = thomas_factors(s, m_lt, sigma, m_k0, stride, m_inv_piv, m_gamma);
  }
}

SlabSolver::~SlabSolver() {
  for (fftw_plan p : {m_t_fwd, m_t_bwd, m_s_fwd, m_s_bwd, m_to_lines, m_from_lines, m_to_y, m_from_y})
    if (p) fftw_destroy_plan(p);
  fftw_free(m_buf);
}

void SlabSolver::transpose(fftw_plan p) {
  const double t0 = MPI_Wtime();
  run(p);
  m_transpose_seconds += MPI_Wtime() - t0;
  ++m_transposes;
  m_transpose_bytes += m_bytes_per_transpose;
}

void SlabSolver::t_forward() {
  if (m_dense_fwd) m_dense_fwd->apply(m_t_lines);
  else run(m_t_fwd);
}

void SlabSolver::t_backward() {
  if (m_dense_bwd) m_dense_bwd->apply(m_t_lines);
  else run(m_t_bwd);
}

void SlabSolver::solve() {
  if (m_t_axis == 0) {
    t_forward();
    transpose(m_to_lines);
    lines();
    transpose(m_from_lines);
    t_backward();
  } else {
    transpose(m_to_y);
    t_forward();
    transpose(m_to_lines);
    lines();
    transpose(m_from_lines);
    t_backward();
    transpose(m_from_y);
  }
}

// Per local wavenumber k = m_k0 + c (c fastest): the transformed problem along s, the same
// operations as FastSolver::tridiagonal(). Padded rows are set to zero.
void SlabSolver::lines() {
  const int stride = m_t_axis == 0 ? m_nk : m_split.hi - m_split.lo;
  const int ns = m_ns;
  double* x = m_buf + (m_t_axis == 0 ? std::size_t(m_pad) * stride : 0);
  const int c_first = std::max(0, -m_k0);  // t = y: the local columns of padded rows
  if (m_t_axis == 0)
    std::fill(m_buf, x, 0.0);
  else
    for (int j = 0; j < ns; ++j)
      for (int c = 0; c < c_first; ++c) x[c + std::size_t(stride) * j] = 0.0;
  if (stride == 0) return;
  if (m_transform_s) {
    run(m_s_fwd);
    const std::size_t size = std::size_t(stride) * ns;
    const double* e = m_inv_eig.data();
    for (std::size_t q = 0; q < size; ++q) x[q] *= e[q];
    run(m_s_bwd);
    return;
  }
  thomas_sweep(x, stride, c_first, ns, m_a.data(), m_inv_piv.data(), m_gamma.data(), 1.0 / m_norm);
  // The singular mode's line: remove its weighted mean (it is whole on this rank).
  if (m_zero_col >= 0 && !m_weights.empty()) remove_weighted_mean(x, stride, m_zero_col, ns, m_weights);
}

}  // namespace fluid
