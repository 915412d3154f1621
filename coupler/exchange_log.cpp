// Diagnostics of the coupler's exchanges (see exchange_log.hpp and README.md).
#include "exchange_log.hpp"

#include <fmt/format.h>

#include <cmath>

#include "immersed.hpp"

namespace coupler {

namespace {

const std::vector<std::string> kColumns = {
    "step",    "area_u",    "area_v",   "body_area", "reaction_x", "reaction_y", "fluid_x",
    "fluid_y", "fluid_abs", "spread_x", "spread_y",  "marker_x",   "marker_y",   "marker_abs",
    "root_fx", "root_fy",   "root_m",   "nodal_fx",  "nodal_fy",   "nodal_m"};

// Σ_k |V_k| α_k over the faces of a message, and Σ_k |V_k| f_k, Σ_k |V_k| |f_k|.
double weighted_sum(const std::vector<std::int32_t>& idx, const std::vector<double>& a,
                    const std::vector<double>& volume, bool absolute = false) {
  double s = 0;
  for (std::size_t k = 0; k < idx.size() && k < a.size(); ++k)
    s += volume[idx[k]] * (absolute ? std::abs(a[k]) : a[k]);
  return s;
}

// The control volumes of one face family as a flat array (index i + ni j).
std::vector<double> volumes(const FaceBoxes& b) {
  std::vector<double> v(static_cast<std::size_t>(b.ni) * b.nj);
  for (int j = 0; j < b.nj; ++j)
    for (int i = 0; i < b.ni; ++i) v[i + static_cast<std::size_t>(b.ni) * j] = b.volume(i, j);
  return v;
}

// A marker's share of its fiber's arclength: ds inside, ds/2 at the two ends (the weight of the
// fiber's integral of its loads and of the coupler's spreading).
double marker_weight(std::size_t m, std::size_t markers, double ds) {
  return m == 0 || m + 1 == markers ? 0.5 * ds : ds;
}

}  // namespace

ExchangeLog::ExchangeLog(const std::filesystem::path& out_dir, const proto::GridInfo& grid,
                         const proto::BodyMeshes& meshes, const proto::FiberLayout& layout,
                         double dt, bool csv, long dump_every)
    : m_grid(grid), m_meshes(meshes), m_layout(layout), m_dump_every(dump_every) {
  if (!grid.x_face.empty()) {
    m_volume.u = volumes(FaceBoxes::u_faces(grid));
    m_volume.v = volumes(FaceBoxes::v_faces(grid));
    m_cell = (grid.x_face[1] - grid.x_face[0]) * (grid.y_face[1] - grid.y_face[0]);
  }
  if (csv) {
    m_csv = std::make_unique<fsi::ProbeCsv>(out_dir / "coupler_exchange.csv", kColumns);
    m_row.assign(kColumns.size(), 0.0);
  }
  if (dump_every > 0) {
    m_h5 =
        std::make_unique<fsi::H5File>(out_dir / "coupler_exchange.h5", fsi::H5File::Mode::truncate);
    auto& h = *m_h5;
    h.set_attribute("/", "dt", dt);
    h.set_attribute("/", "dump_every", static_cast<std::int64_t>(dump_every));
    h.write("grid/x_face", grid.x_face);
    h.write("grid/y_face", grid.y_face);
    h.set_attribute("grid", "periodic_x", grid.periodic_x);
    h.set_attribute("grid", "periodic_y", grid.periodic_y);
    h.set_attribute("grid", "density", grid.density);
    for (const auto& b : meshes.bodies) {
      const std::string g = "body_" + b.name;
      h.write(g + "/x_ref", b.x_ref, {b.x_ref.size() / 2, 2});
      h.write(g + "/triangles", std::span<const int>(b.tri), {b.tri.size() / 3, 3});
      h.set_attribute(g, "kind", static_cast<int>(b.kind));
    }
    for (const auto& f : layout.fibers) {
      const std::string g = "fiber_" + f.name;
      h.create_group(g);
      h.set_attribute(g, "ds", f.ds);
      h.set_attribute(g, "markers", f.markers);
    }
  }
}

void ExchangeLog::inputs(long n, double t, const proto::SolidState& solid,
                         const proto::FiberState& fiber, const proto::FluidInput& fluid_in,
                         const proto::FiberInput& fiber_in, const FeedbackIB* ib,
                         bool have_samples) {
  m_step = n, m_time = t;
  m_solid = solid;
  m_fiber = fiber;
  m_in = fluid_in;
  m_fiber_force = fiber_in.force;
  m_u_markers.assign(fiber.x.size(), {});
  // U(Xⁿ) exactly as the feedback force used it: the same interpolation of the same samples.
  if (ib && have_samples)
    for (std::size_t k = 0; k < fiber.x.size(); ++k) ib->interpolate(fiber.x[k], m_u_markers[k]);
  m_reaction.clear(), m_root_nodal.clear(), m_poses.clear(), m_root_load.clear();
}

void ExchangeLog::reaction(const proto::FluidInput& fluid_in, const proto::FluidOutput& fluid_out,
                           const std::vector<std::vector<double>>& force) {
  m_out = fluid_out;
  m_reaction = force;
  // The samples of u^(n+1) just returned are the ones U(X^(n+1)) will use next step.
  m_prev_sample_u = m_sample_u, m_prev_sample_v = m_sample_v;
  m_prev_value_u = m_value_u, m_prev_value_v = m_value_v;
  m_sample_u = fluid_in.sample_u, m_sample_v = fluid_in.sample_v;
  m_value_u = fluid_out.u_sample, m_value_v = fluid_out.v_sample;
}

void ExchangeLog::before_root_loads(const std::vector<std::vector<double>>& force) {
  m_root_nodal = force;
}

// The root loads as nodal forces: what add_root_loads() changed, per body and node.
void ExchangeLog::root_loads(const std::vector<std::vector<double>>& force,
                             const std::vector<double>& root_load,
                             const std::vector<std::vector<double>>& poses,
                             const std::vector<double>& root_mass,
                             const std::vector<std::vector<double>>& nodal_root_mass) {
  m_root_mass = root_mass;
  m_nodal_root_mass = nodal_root_mass;
  for (std::size_t b = 0; b < force.size() && b < m_root_nodal.size(); ++b) {
    auto& d = m_root_nodal[b];
    if (d.empty()) d.assign(force[b].size(), 0.0);
    for (std::size_t k = 0; k < d.size() && k < force[b].size(); ++k) d[k] = force[b][k] - d[k];
  }
  m_root_load = root_load;
  m_poses = poses;
}

void ExchangeLog::end_step() {
  if (m_csv) {
    auto& r = m_row;
    std::fill(r.begin(), r.end(), 0.0);
    r[0] = static_cast<double>(m_step);
    // Σ α|V| per family, and the bodies' area Σ_T |T| in the state the footprint came from.
    r[1] = weighted_sum(m_in.solid_u.index, m_in.solid_u.alpha, m_volume.u);
    r[2] = weighted_sum(m_in.solid_v.index, m_in.solid_v.alpha, m_volume.v);
    for (std::size_t b = 0; b < m_meshes.bodies.size() && b < m_solid.x.size(); ++b) {
      const auto& tri = m_meshes.bodies[b].tri;
      const auto& x = m_solid.x[b];
      for (std::size_t e = 0; e + 2 < tri.size(); e += 3) {
        const int i = tri[e], j = tri[e + 1], k = tri[e + 2];
        r[3] += 0.5 * ((x[2 * j] - x[2 * i]) * (x[2 * k + 1] - x[2 * i + 1]) -
                       (x[2 * k] - x[2 * i]) * (x[2 * j + 1] - x[2 * i + 1]));
      }
    }
    // Action and reaction of the immersed solid: Σ_a F_a (on the solids) against Σ f_s |V| (on
    // the fluid); their sum is zero.
    for (const auto& f : m_reaction)
      for (std::size_t k = 0; k < f.size(); ++k) r[4 + k % 2] += f[k];
    r[6] = weighted_sum(m_in.solid_u.index, m_out.fs_u, m_volume.u);
    r[7] = weighted_sum(m_in.solid_v.index, m_out.fs_v, m_volume.v);
    r[8] = weighted_sum(m_in.solid_u.index, m_out.fs_u, m_volume.u, true) +
           weighted_sum(m_in.solid_v.index, m_out.fs_v, m_volume.v, true);
    // Fibers: Σ f_f h_x h_y (on the fluid) against Σ F w (on the fibers); their sum is zero.
    for (std::size_t i = 0; i < m_in.force_u.force.size(); ++i)
      r[9] += m_in.force_u.force[i] * m_cell;
    for (std::size_t i = 0; i < m_in.force_v.force.size(); ++i)
      r[10] += m_in.force_v.force[i] * m_cell;
    for (std::size_t k = 0; k < m_fiber_force.size() && k < m_layout.fibers.size(); ++k) {
      const auto& F = m_fiber_force[k];
      const std::size_t markers = F.size() / 2;
      for (std::size_t m = 0; m < markers; ++m) {
        const double w = marker_weight(m, markers, m_layout.fibers[k].ds);
        r[11] += F[2 * m] * w, r[12] += F[2 * m + 1] * w;
        r[13] += (std::abs(F[2 * m]) + std::abs(F[2 * m + 1])) * w;
      }
    }
    // Root loads (force, moment about the origin: M + p × F) against the nodal forces that carry
    // them to the solid (resultant, Σ x_a × f_a).
    for (std::size_t k = 0; k < m_poses.size() && 3 * k + 2 < m_root_load.size(); ++k) {
      if (m_poses[k].size() < 2) continue;
      const double fx = m_root_load[3 * k], fy = m_root_load[3 * k + 1];
      r[14] += fx, r[15] += fy;
      r[16] += m_root_load[3 * k + 2] + m_poses[k][0] * fy - m_poses[k][1] * fx;
    }
    for (std::size_t b = 0; b < m_root_nodal.size() && b < m_solid.x.size(); ++b) {
      const auto& f = m_root_nodal[b];
      const auto& x = m_solid.x[b];
      for (std::size_t k = 0; k + 1 < f.size() && k + 1 < x.size(); k += 2) {
        r[17] += f[k], r[18] += f[k + 1];
        r[19] += x[k] * f[k + 1] - x[k + 1] * f[k];
      }
    }
    m_csv->write(m_time, r);
  }
  if (m_h5 && m_step % m_dump_every == 0) dump();
}

// One step's exchanged quantities, under /step_NNNNNN (datasets that would be empty are left out).
void ExchangeLog::dump() {
  auto& h = *m_h5;
  const std::string s = fsi::h5_step_group(m_step);
  h.create_group(s);
  h.set_attribute(s, "time", m_time);
  h.set_attribute(s, "step", static_cast<std::int64_t>(m_step));
  auto put = [&](const std::string& name, const auto& v) {
    if (!v.empty()) h.write(s + "/" + name, std::span(v));
  };
  for (auto [fam, sol, fs] :
       {std::tuple{"u", &m_in.solid_u, &m_out.fs_u}, std::tuple{"v", &m_in.solid_v, &m_out.fs_v}}) {
    const std::string g = std::string("solid_") + fam;
    put(g + "/index", sol->index);
    put(g + "/alpha", sol->alpha);
    put(g + "/velocity", sol->velocity);
    put(g + "/fs", *fs);
  }
  put("spread_u/index", m_in.force_u.index);
  put("spread_u/force", m_in.force_u.force);
  put("spread_v/index", m_in.force_v.index);
  put("spread_v/force", m_in.force_v.force);
  put("samples_u/index", m_prev_sample_u);
  put("samples_u/value", m_prev_value_u);
  put("samples_v/index", m_prev_sample_v);
  put("samples_v/value", m_prev_value_v);
  for (std::size_t b = 0; b < m_meshes.bodies.size() && b < m_solid.x.size(); ++b) {
    const std::string g = "body_" + m_meshes.bodies[b].name + "/";
    put(g + "x", m_solid.x[b]);
    put(g + "v", m_solid.v[b]);
    if (b < m_reaction.size()) put(g + "reaction", m_reaction[b]);
    if (b < m_root_nodal.size()) put(g + "root_force", m_root_nodal[b]);
    if (b < m_nodal_root_mass.size()) put(g + "root_mass", m_nodal_root_mass[b]);
  }
  for (std::size_t k = 0; k < m_layout.fibers.size() && k < m_fiber.x.size(); ++k) {
    const std::string g = "fiber_" + m_layout.fibers[k].name + "/";
    put(g + "x", m_fiber.x[k]);
    put(g + "x_old", m_fiber.x_old[k]);
    if (k < m_u_markers.size()) put(g + "u", m_u_markers[k]);
    if (k < m_fiber_force.size()) put(g + "force", m_fiber_force[k]);
    if (k < m_poses.size()) put(g + "root_pose", m_poses[k]);
    if (3 * k + 2 < m_root_load.size())
      h.write(s + "/" + g + "root_load", std::span(m_root_load).subspan(3 * k, 3));
    if (3 * k + 2 < m_root_mass.size())
      h.write(s + "/" + g + "root_mass", std::span(m_root_mass).subspan(3 * k, 3));
  }
}

}  // namespace coupler
