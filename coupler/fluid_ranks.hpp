// The fluid on several ranks (PROTOCOL.md, "The fluid on several ranks"): its cell rows split in
// blocks of proto::fluid_row_block(ny, P); each step's input split by the row each face or cell
// lies on, so that every rank gets the part of the footprint, the fibers' force and the samples
// that lies on its rows; the answers merged back into the input's order.
#pragma once

#include <array>
#include <vector>

#include "protocol.hpp"

namespace coupler {

class FluidRanks {
 public:
  FluidRanks(const fsi::proto::GridInfo& grid, int ranks);
  int ranks() const { return int(m_parts.size()); }
  // The rank holding a u face, v face or cell (flat indices of PROTOCOL.md).
  int rank_of_u(std::int32_t idx) const { return of_row(idx / m_nu); }
  int rank_of_v(std::int32_t idx) const { return of_row(idx / m_nx); }
  int rank_of_cell(std::int32_t idx) const { return of_row(idx / m_nx); }
  // in -> part(r): each list's entries of rank r, in the order of `in`.
  void split(const fsi::proto::FluidInput& in);
  const fsi::proto::FluidInput& part(int r) const { return m_parts[r]; }
  fsi::proto::FluidOutput& answer(int r) { return m_answers[r]; }
  // The answers to the parts of the last split, in the order of its input; the diagnostics
  // (CFL, divergence, energy: the whole grid's on every rank) from rank 0. Throws when an answer
  // does not have its part's length.
  void merge(fsi::proto::FluidOutput& out) const;
  // Entries sent to rank r in the last split (its share of the traffic).
  std::size_t part_values(int r) const;

 private:
  int of_row(int j) const;

  int m_nx, m_nu, m_ny, m_block;
  std::vector<fsi::proto::FluidInput> m_parts;
  std::vector<fsi::proto::FluidOutput> m_answers;
  // The rank of every entry of the last input's lists with answers: solid_u, solid_v, sample_u,
  // sample_v, sample_p.
  std::array<std::vector<int>, 5> m_rank;
};

}  // namespace coupler
