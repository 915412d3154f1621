// Packing of the protocol messages: fields in declaration order (see protocol.hpp).
#include "protocol.hpp"

namespace fsi::proto {

const char* tag_name(Tag t) {
  switch (t) {
    case Tag::grid_info: return "grid_info";
    case Tag::body_meshes: return "body_meshes";
    case Tag::fiber_layout: return "fiber_layout";
    case Tag::effective_scene: return "effective_scene";
    case Tag::step_begin: return "step_begin";
    case Tag::fluid_input: return "fluid_input";
    case Tag::fluid_output: return "fluid_output";
    case Tag::solid_input: return "solid_input";
    case Tag::solid_state: return "solid_state";
    case Tag::fiber_input: return "fiber_input";
    case Tag::fiber_state: return "fiber_state";
    case Tag::final_report: return "final_report";
  }
  return "unknown";
}

void Writer::put(const std::string& s) {
  put(static_cast<std::int64_t>(s.size()));
  append(s.data(), s.size());
}

void Reader::get(std::string& s) {
  std::int64_t n = 0;
  get(n);
  if (n < 0 || static_cast<std::size_t>(n) > m_size - m_pos)
    fail("protocol error: string length {} does not fit the message", n);
  s.assign(reinterpret_cast<const char*>(m_data + m_pos), static_cast<std::size_t>(n));
  m_pos += static_cast<std::size_t>(n);
}

namespace {
// A list of vectors: its count, then each vector.
template <class T>
void put_list(Writer& w, const std::vector<std::vector<T>>& l) {
  w.put(static_cast<std::int64_t>(l.size()));
  for (const auto& v : l) w.put(v);
}
template <class T>
void get_list(Reader& r, std::vector<std::vector<T>>& l) {
  std::int64_t n = 0;
  r.get(n);
  if (n < 0 || n > (1 << 24)) fail("protocol error: list length {} out of range", n);
  l.resize(static_cast<std::size_t>(n));
  for (auto& v : l) r.get(v);
}
void put(Writer& w, const FaceSolid& f) {
  w.put(f.index), w.put(f.alpha), w.put(f.velocity), w.put(f.elastic), w.put(f.body);
}
void get(Reader& r, FaceSolid& f) {
  r.get(f.index), r.get(f.alpha), r.get(f.velocity), r.get(f.elastic), r.get(f.body);
  if (f.alpha.size() != f.index.size() || f.velocity.size() != f.index.size() ||
      (!f.elastic.empty() && f.elastic.size() != f.index.size()) ||
      (!f.body.empty() && f.body.size() != f.index.size()))
    fail("protocol error: face solid arrays of different lengths");
}
void put(Writer& w, const FaceForce& f) { w.put(f.index), w.put(f.force); }
void get(Reader& r, FaceForce& f) {
  r.get(f.index), r.get(f.force);
  if (f.force.size() != f.index.size()) fail("protocol error: face force arrays of different lengths");
}
}  // namespace

void GridInfo::pack(Writer& w) const {
  w.put(nx), w.put(ny), w.put(periodic_x), w.put(periodic_y), w.put(x_face), w.put(y_face);
  w.put(density), w.put(can_iterate);
}
void GridInfo::unpack(Reader& r) {
  r.get(nx), r.get(ny), r.get(periodic_x), r.get(periodic_y), r.get(x_face), r.get(y_face);
  r.get(density), r.get(can_iterate);
}

void BodyMeshes::pack(Writer& w) const {
  w.put(static_cast<std::int64_t>(bodies.size()));
  for (const auto& b : bodies)
    w.put(b.name), w.put(b.kind), w.put(b.x_ref), w.put(b.tri), w.put(b.edges), w.put(b.rigid);
  w.put(can_iterate);
}
void BodyMeshes::unpack(Reader& r) {
  std::int64_t n = 0;
  r.get(n);
  if (n < 0 || n > (1 << 20)) fail("protocol error: body count {} out of range", n);
  bodies.resize(static_cast<std::size_t>(n));
  for (auto& b : bodies) {
    r.get(b.name), r.get(b.kind), r.get(b.x_ref), r.get(b.tri), r.get(b.edges), r.get(b.rigid);
    const auto k = static_cast<std::int32_t>(b.kind);
    if (k < 0 || k > static_cast<std::int32_t>(BodyKind::rigid_moving))
      fail("protocol error: body '{}' has kind {}, not 0, 1 or 2", b.name, k);
    if (b.rigid != 0 && b.rigid != 1)
      fail("protocol error: body '{}' has rigid = {}, not 0 or 1", b.name, b.rigid);
  }
  r.get(can_iterate);
}

void FiberLayout::pack(Writer& w) const {
  w.put(static_cast<std::int64_t>(fibers.size()));
  for (const auto& f : fibers)
    w.put(f.name), w.put(f.markers), w.put(f.ds), w.put(f.root), w.put(f.body), w.put(f.edge),
        w.put(f.edge_s), w.put(f.root_x), w.put(f.root_y), w.put(f.line_density);
}
void FiberLayout::unpack(Reader& r) {
  std::int64_t n = 0;
  r.get(n);
  if (n < 0 || n > (1 << 20)) fail("protocol error: fiber count {} out of range", n);
  fibers.resize(static_cast<std::size_t>(n));
  for (auto& f : fibers)
    r.get(f.name), r.get(f.markers), r.get(f.ds), r.get(f.root), r.get(f.body), r.get(f.edge),
        r.get(f.edge_s), r.get(f.root_x), r.get(f.root_y), r.get(f.line_density);
}

void Text::pack(Writer& w) const { w.put(text); }
void Text::unpack(Reader& r) { r.get(text); }

void StepBegin::pack(Writer& w) const {
  w.put(step), w.put(time), w.put(dt), w.put(action), w.put(iteration), w.put(may_repeat);
  w.put(checkpoint);
}
void StepBegin::unpack(Reader& r) {
  r.get(step), r.get(time), r.get(dt), r.get(action), r.get(iteration), r.get(may_repeat);
  r.get(checkpoint);
}

void FluidInput::pack(Writer& w) const {
  put(w, solid_u), put(w, solid_v), put(w, force_u), put(w, force_v);
  w.put(sample_u), w.put(sample_v), w.put(sample_p);
}
void FluidInput::unpack(Reader& r) {
  get(r, solid_u), get(r, solid_v), get(r, force_u), get(r, force_v);
  r.get(sample_u), r.get(sample_v), r.get(sample_p);
  // The elastic part is sent for every face of both families or for none.
  const bool some = !solid_u.elastic.empty() || !solid_v.elastic.empty();
  for (const FaceSolid* f : {&solid_u, &solid_v})
    if (some && f->elastic.size() != f->index.size())
      fail("protocol error: the elastic part of alpha sent for some faces only");
  // So are the faces' bodies.
  const bool marked = !solid_u.body.empty() || !solid_v.body.empty();
  for (const FaceSolid* f : {&solid_u, &solid_v})
    if (marked && f->body.size() != f->index.size())
      fail("protocol error: the faces' bodies sent for some faces only");
}

void FluidOutput::pack(Writer& w) const {
  w.put(fs_u), w.put(fs_v), w.put(u_sample), w.put(v_sample), w.put(p_sample);
  w.put(cfl), w.put(max_div), w.put(kinetic_energy);
}
void FluidOutput::unpack(Reader& r) {
  r.get(fs_u), r.get(fs_v), r.get(u_sample), r.get(v_sample), r.get(p_sample);
  r.get(cfl), r.get(max_div), r.get(kinetic_energy);
}

void SolidInput::pack(Writer& w) const {
  put_list(w, force), put_list(w, velocity), put_list(w, root_mass);
}
void SolidInput::unpack(Reader& r) {
  get_list(r, force), get_list(r, velocity), get_list(r, root_mass);
}

void SolidState::pack(Writer& w) const { w.put(time), put_list(w, x), put_list(w, v); }
void SolidState::unpack(Reader& r) { r.get(time), get_list(r, x), get_list(r, v); }

void FiberInput::pack(Writer& w) const { put_list(w, force), put_list(w, root_pose); }
void FiberInput::unpack(Reader& r) { get_list(r, force), get_list(r, root_pose); }

void FiberState::pack(Writer& w) const {
  w.put(time), put_list(w, x), put_list(w, x_old), w.put(root_load), w.put(root_mass),
      w.put(root_accel);
}
void FiberState::unpack(Reader& r) {
  r.get(time), get_list(r, x), get_list(r, x_old), r.get(root_load), r.get(root_mass),
      r.get(root_accel);
}

}  // namespace fsi::proto
