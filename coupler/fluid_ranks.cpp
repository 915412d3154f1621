// Split and merge of the fluid's per-step messages over its ranks (fluid_ranks.hpp).
#include "fluid_ranks.hpp"

#include <algorithm>

#include "error.hpp"

namespace coupler {

namespace proto = fsi::proto;

FluidRanks::FluidRanks(const proto::GridInfo& g, int ranks)
    : m_nx(g.nx),
      m_nu(g.periodic_x ? g.nx : g.nx + 1),
      m_ny(g.ny),
      m_block(proto::fluid_row_block(g.ny, ranks)),
      m_parts(ranks),
      m_answers(ranks) {}

int FluidRanks::of_row(int j) const {
  return std::clamp(j / m_block, 0, ranks() - 1);
}

namespace {

// Entries of `index` (and of the value lists beside it) by rank, in order; `rank` records each
// entry's rank.
template <class RankOf>
void split_list(const std::vector<std::int32_t>& index, RankOf rank_of, std::vector<int>& rank,
                std::vector<std::vector<std::int32_t>*> out_index) {
  rank.resize(index.size());
  for (auto* o : out_index) o->clear();
  for (std::size_t q = 0; q < index.size(); ++q) {
    const int r = rank_of(index[q]);
    rank[q] = r;
    out_index[r]->push_back(index[q]);
  }
}

template <class T>
void split_values(const std::vector<T>& values, const std::vector<int>& rank,
                  std::vector<std::vector<T>*> out) {
  for (auto* o : out) o->clear();
  for (std::size_t q = 0; q < values.size(); ++q) out[rank[q]]->push_back(values[q]);
}

}  // namespace

void FluidRanks::split(const proto::FluidInput& in) {
  const int P = ranks();
  auto ptrs = [&](auto member) {
    std::vector<std::remove_reference_t<decltype(m_parts[0].*member)>*> v(P);
    for (int r = 0; r < P; ++r) v[r] = &(m_parts[r].*member);
    return v;
  };
  auto u = [&](std::int32_t i) { return rank_of_u(i); };
  auto v = [&](std::int32_t i) { return rank_of_v(i); };
  auto c = [&](std::int32_t i) { return rank_of_cell(i); };
  for (int comp = 0; comp < 2; ++comp) {
    const proto::FaceSolid& s = comp == 0 ? in.solid_u : in.solid_v;
    std::vector<proto::FaceSolid*> parts(P);
    for (int r = 0; r < P; ++r) parts[r] = comp == 0 ? &m_parts[r].solid_u : &m_parts[r].solid_v;
    std::vector<std::vector<std::int32_t>*> idx(P);
    std::vector<std::vector<double>*> alpha(P), vel(P), elastic(P);
    for (int r = 0; r < P; ++r) {
      idx[r] = &parts[r]->index, alpha[r] = &parts[r]->alpha, vel[r] = &parts[r]->velocity;
      elastic[r] = &parts[r]->elastic;
    }
    if (comp == 0) split_list(s.index, u, m_rank[0], idx);
    else split_list(s.index, v, m_rank[1], idx);
    split_values(s.alpha, m_rank[comp], alpha);
    split_values(s.velocity, m_rank[comp], vel);
    split_values(s.elastic, m_rank[comp], elastic);  // empty stays empty on every rank
    std::vector<std::vector<std::int32_t>*> body(P);
    for (int r = 0; r < P; ++r) body[r] = &parts[r]->body;
    split_values(s.body, m_rank[comp], body);  // likewise
    // The fibers' force: no answer, its ranks are not kept.
    const proto::FaceForce& f = comp == 0 ? in.force_u : in.force_v;
    std::vector<int> frank;
    std::vector<std::vector<std::int32_t>*> fidx(P);
    std::vector<std::vector<double>*> fval(P);
    for (int r = 0; r < P; ++r) {
      proto::FaceForce& pf = comp == 0 ? m_parts[r].force_u : m_parts[r].force_v;
      fidx[r] = &pf.index, fval[r] = &pf.force;
    }
    if (comp == 0) split_list(f.index, u, frank, fidx);
    else split_list(f.index, v, frank, fidx);
    split_values(f.force, frank, fval);
  }
  split_list(in.sample_u, u, m_rank[2], ptrs(&proto::FluidInput::sample_u));
  split_list(in.sample_v, v, m_rank[3], ptrs(&proto::FluidInput::sample_v));
  split_list(in.sample_p, c, m_rank[4], ptrs(&proto::FluidInput::sample_p));
}

void FluidRanks::merge(proto::FluidOutput& out) const {
  const int P = ranks();
  using List = std::vector<double> proto::FluidOutput::*;
  const List lists[5] = {&proto::FluidOutput::fs_u, &proto::FluidOutput::fs_v,
                         &proto::FluidOutput::u_sample, &proto::FluidOutput::v_sample,
                         &proto::FluidOutput::p_sample};
  for (int l = 0; l < 5; ++l) {
    const std::vector<int>& rank = m_rank[l];
    std::vector<double>& o = out.*lists[l];
    o.resize(rank.size());
    std::vector<std::size_t> next(P, 0), asked(P, 0);
    for (int x : rank) ++asked[x];
    for (int r = 0; r < P; ++r)
      if ((m_answers[r].*lists[l]).size() != asked[r])
        fsi::fail("protocol error: fluid rank {} answered {} values of list {} for {} asked", r,
                  (m_answers[r].*lists[l]).size(), l, asked[r]);
    for (std::size_t q = 0; q < rank.size(); ++q) o[q] = (m_answers[rank[q]].*lists[l])[next[rank[q]]++];
  }
  out.cfl = m_answers[0].cfl;
  out.max_div = m_answers[0].max_div;
  out.kinetic_energy = m_answers[0].kinetic_energy;
}

std::size_t FluidRanks::part_values(int r) const {
  const proto::FluidInput& p = m_parts[r];
  return p.solid_u.index.size() + p.solid_v.index.size() + p.force_u.index.size() +
         p.force_v.index.size() + p.sample_u.size() + p.sample_v.size() + p.sample_p.size();
}

}  // namespace coupler
