// The coupling protocol: every message that travels between the coupler and a solver, its
// layout, units and sign, and the version. common/PROTOCOL.md is the prose version of this file
// (message order per step, who sends what). Messages are packed into a byte buffer: a header
// (magic, version, tag, step) then the fields in declaration order; a vector is its length
// (int64) followed by its elements; a string is its length then its bytes.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "error.hpp"

namespace fsi::proto {

// Bump on any change of a message's layout or of the message order.
inline constexpr std::int32_t kVersion = 9;
inline constexpr std::uint32_t kMagic = 0x4d495346;  // "FSIM"

// The fluid on several ranks: its ny cell rows in blocks of this many, rank r holding rows
// [r b, min((r + 1) b, ny)) (FFTW's split; PROTOCOL.md, "The fluid on several ranks"). One rank
// changes nothing of the protocol, so its version stays: a program of an older version refuses
// a fluid of several ranks at the handshake.
inline int fluid_row_block(int ny, int ranks) { return (ny + ranks - 1) / ranks; }

// 64-bit FNV-1a of bytes: the handshake's scene and output-options hashes (PROTOCOL.md,
// start-up), so that a program in any language computes the same (since version 6).
inline std::uint64_t fnv1a(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

enum class Tag : std::int32_t {
  // set-up, once, in this order
  grid_info = 1,     // fluid  -> coupler
  body_meshes = 2,   // solid  -> coupler
  fiber_layout = 3,  // fiber  -> coupler
  effective_scene = 4,  // solver -> coupler
  // every step
  step_begin = 10,   // coupler -> each solver
  fluid_input = 11,  // coupler -> fluid
  fluid_output = 12, // fluid   -> coupler
  solid_input = 13,  // coupler -> solid
  solid_state = 14,  // solid   -> coupler (also once at set-up: the initial state)
  fiber_input = 15,  // coupler -> fiber
  fiber_state = 16,  // fiber   -> coupler (also once at set-up: the initial state)
  // end
  final_report = 20, // solver -> coupler
};
const char* tag_name(Tag t);

// ---- byte buffer ------------------------------------------------------------------------------

// Writes a message into a caller's buffer from its start. The buffer keeps its size between
// messages (a link packs every message of a step into the same one), so that steady traffic
// allocates, zero-fills and faults in its pages once; size() is the message's length, which may
// be less than the buffer's.
class Writer {
 public:
  explicit Writer(std::vector<std::byte>& buffer) : m_bytes(buffer) {}
  template <class T>
  void put(const T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    append(&x, sizeof(T));
  }
  template <class T>
  void put(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(static_cast<std::int64_t>(v.size()));
    append(v.data(), v.size() * sizeof(T));
  }
  void put(const std::string& s);
  std::size_t size() const { return m_size; }

 private:
  void append(const void* p, std::size_t n) {
    if (m_size + n > m_bytes.size()) m_bytes.resize(std::max(m_size + n, 2 * m_bytes.size()));
    if (n) std::memcpy(m_bytes.data() + m_size, p, n);
    m_size += n;
  }
  std::vector<std::byte>& m_bytes;
  std::size_t m_size = 0;
};

class Reader {
 public:
  Reader(const std::byte* data, std::size_t size) : m_data(data), m_size(size) {}
  template <class T>
  void get(T& x) {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    std::memcpy(&x, m_data + m_pos, sizeof(T));
    m_pos += sizeof(T);
  }
  template <class T>
  void get(std::vector<T>& v) {
    std::int64_t n = 0;
    get(n);
    if (n < 0 || static_cast<std::size_t>(n) > (m_size - m_pos) / sizeof(T))
      fail("protocol error: vector length {} does not fit the message", n);
    v.resize(static_cast<std::size_t>(n));
    if (n > 0) std::memcpy(v.data(), m_data + m_pos, v.size() * sizeof(T));
    m_pos += v.size() * sizeof(T);
  }
  void get(std::string& s);
  bool done() const { return m_pos == m_size; }

 private:
  void need(std::size_t n) const {
    if (m_size - m_pos < n) fail("protocol error: message truncated");
  }
  const std::byte* m_data;
  std::size_t m_size;
  std::size_t m_pos = 0;
};

// ---- messages -----------------------------------------------------------------------------------
// Index conventions on the fluid's MAC grid with nx x ny cells: a u-face (i, j) lies at
// (x_face[i], y_centre[j]), i in [0, nu) with nu = nx if x is periodic else nx + 1, flat index
// i + nu*j; a v-face (i, j) lies at (x_centre[i], y_face[j]), j in [0, nv) with nv = ny if y is
// periodic else ny + 1, flat index i + nx*j. Vectors of points are interleaved (x0, y0, x1, y1, ...).
// All quantities are in the scene's units.

struct GridInfo {  // fluid -> coupler, once
  static constexpr Tag tag = Tag::grid_info;
  std::int32_t nx = 0, ny = 0;
  std::int32_t periodic_x = 0, periodic_y = 0;
  std::vector<double> x_face;  // nx + 1 face coordinates (cell i spans x_face[i]..x_face[i+1])
  std::vector<double> y_face;  // ny + 1
  double density = 0;          // rho_f
  std::int32_t can_iterate = 0;  // 1: the fluid can repeat a step (StepBegin::iteration > 0)
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

// How a body moves, as the coupler needs it: an elastic body's nodes move and carry velocities; a
// rigid fixed body is clipped once; a rigid body with prescribed motion moves but takes no load.
// On the wire an int32 (the values below).
enum class BodyKind : std::int32_t { elastic = 0, rigid_fixed = 1, rigid_moving = 2 };

struct BodyMesh {
  std::string name;
  BodyKind kind = BodyKind::elastic;
  std::vector<double> x_ref;       // reference node coordinates, 2 per node
  std::vector<std::int32_t> tri;   // 3 node indices per triangle, counter-clockwise
  std::vector<std::int32_t> edges; // surface edges, 2 node indices each, body on the left
  // Since version 8: 1 when the body moves without strain (a free rigid body, which is kind 0
  // for the coupler); bodies of kind 1 and 2 are rigid whatever it says. A rigid body keeps the
  // fluid's viscosity under fluid.body_viscosity = "none" (FaceSolid::elastic).
  std::int32_t rigid = 0;
};

struct BodyMeshes {  // solid -> coupler, once
  static constexpr Tag tag = Tag::body_meshes;
  std::vector<BodyMesh> bodies;
  std::int32_t can_iterate = 0;  // 1: the solid can repeat a step (StepBegin::iteration > 0)
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct FiberLayout1 {
  std::string name;
  std::int32_t markers = 0;      // marker count (segments + 1)
  double ds = 0;                 // arclength spacing
  std::int32_t root = 0;         // 0 free/clamped/hinged at a fixed point, 1 attached to a body
  std::string body;              // attached: body name
  std::int32_t edge = -1;        // attached: surface edge index of that body, or −1: the coupler
  double edge_s = 0;             //   finds the edge nearest to root_ref; parameter along it, 0..1
  double root_x = 0, root_y = 0; // attached: the root's point in the body's reference configuration
  double line_density = 0;       // ρ' (excess mass per unit length); <= 0: prescribed motion
};

struct FiberLayout {  // fiber -> coupler, once
  static constexpr Tag tag = Tag::fiber_layout;
  std::vector<FiberLayout1> fibers;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct Text {  // effective_scene, final_report: a TOML or JSON document
  Tag tag = Tag::effective_scene;
  std::string text;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

enum class Action : std::int32_t { step = 0, stop = 1 };

struct StepBegin {  // coupler -> each solver, every step
  static constexpr Tag tag = Tag::step_begin;
  std::int64_t step = 0;  // n: the step advances t^n -> t^n + dt
  double time = 0;        // t^n
  double dt = 0;
  Action action = Action::step;
  // Coupled iterations: 0 for the first pass of step n; k > 0 asks the fluid and the solid to
  // redo the same step from its start with new input (sub-iteration k). A step is committed
  // (the solver may write its output) when step n + 1 begins with iteration 0, or at stop.
  std::int32_t iteration = 0;
  // 1 when coupled iterations are on, so that this step may be redone: a solver keeps what a
  // redo needs only then (the fluid's predictor fields, three copies of the grid per step).
  std::int32_t may_repeat = 0;
  // 1: once this step is committed, write a checkpoint of the state at t^(n+1) (common/driver.hpp,
  // SolverPort::save) before any work ahead of the next step.
  std::int32_t checkpoint = 0;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

// Solid on faces: for each listed face, the solid volume fraction alpha in [0, 1] of its
// control volume and the mean solid velocity component over the solid part of it. Since
// version 8, elastic: the part of alpha that belongs to elastic bodies (kind 0, not rigid), in
// the same order, which is where the fluid takes its viscosity out of the bodies
// (fluid.body_viscosity = "none"); empty in both families when every body of the scene is
// elastic (then it is alpha), else one value per face in both. Since version 9, body: the index
// of the one body whose pieces are in the face's control volume, or -1 where pieces of more than
// one body are (its velocity is their mean, whose divergence is their approach, not a volume
// change: fluid.body_divergence takes a body's divergence only in cells whose four faces name
// the same body); empty in both families when the scene has one body, else one value per face
// in both.
struct FaceSolid {
  std::vector<std::int32_t> index;
  std::vector<double> alpha;
  std::vector<double> velocity;
  std::vector<double> elastic;
  std::vector<std::int32_t> body;
};

// A sparse body force per unit volume on faces (force on the fluid).
struct FaceForce {
  std::vector<std::int32_t> index;
  std::vector<double> force;
};

struct FluidInput {  // coupler -> fluid, every step
  static constexpr Tag tag = Tag::fluid_input;
  FaceSolid solid_u, solid_v;   // immersed solid: alpha, mean solid velocity
  FaceForce force_u, force_v;   // fibers' spread force f_f, applied in the predictor
  std::vector<std::int32_t> sample_u, sample_v;  // faces whose u^(n+1) the coupler wants back
  std::vector<std::int32_t> sample_p;  // cells (i + nx j) whose p^(n+1) it wants (version 7)
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct FluidOutput {  // fluid -> coupler, every step
  static constexpr Tag tag = Tag::fluid_output;
  // f_s = rho_f alpha (u_s - u~)/dt (Eq. 21; the fluid's forcing options change the target:
  // fluid/forcing.cpp) on solid_u / solid_v's faces, same order: force per unit
  // volume ON THE FLUID.
  std::vector<double> fs_u, fs_v;
  std::vector<double> u_sample, v_sample;  // u^(n+1) on sample_u / sample_v
  std::vector<double> p_sample;            // p^(n+1) in sample_p's cells (since version 7)
  double cfl = 0, max_div = 0, kinetic_energy = 0;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct SolidInput {  // coupler -> solid, every step
  static constexpr Tag tag = Tag::solid_input;
  // per body: nodal forces ON THE SOLID (2 per node), the exact reaction of f_s plus the
  // fibers' root loads as equivalent nodal forces. Empty for rigid bodies.
  std::vector<std::vector<double>> force;
  // Coupled iterations only (empty in the explicit step): per body, the nodal velocities at
  // t^(n+1) whose footprint average u_s the fluid's forcing of this pass used (the first
  // estimate 2v^n - v^(n-1) at iteration 0, the coupler's accelerated estimate after). The reaction depends on them as dF/dv ~ -M_f/dt (M_f the
  // mass matrix of the fluid inside the body); a solid may use them to linearise it.
  std::vector<std::vector<double>> velocity;
  // Since version 7, per body: the fibers' root inertia at the nodes of the edges that hold them,
  // (m_xx, m_xy, m_yy) per node [3 per node], or empty (no rooted fiber on the body). The root
  // loads in `force` then come without that inertia: the solid adds -m a^(n+1) at each node,
  // a its own acceleration of the node over this step (PROTOCOL.md, "Fiber roots").
  std::vector<std::vector<double>> root_mass;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct SolidState {  // solid -> coupler, at set-up and after every step
  static constexpr Tag tag = Tag::solid_state;
  double time = 0;
  std::vector<std::vector<double>> x, v;  // per body: current node positions, velocities
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct FiberInput {  // coupler -> fiber, every step
  static constexpr Tag tag = Tag::fiber_input;
  // per fiber: feedback force per unit length ON THE FIBER at each marker (2 per marker)
  std::vector<std::vector<double>> force;
  // per fiber: root pose at t^(n+1) for attached fibers (x, y, dx, dy: position, unit
  // direction into the fiber); empty for others
  std::vector<std::vector<double>> root_pose;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

struct FiberState {  // fiber -> coupler, at set-up and after every step
  static constexpr Tag tag = Tag::fiber_state;
  double time = 0;
  std::vector<std::vector<double>> x, x_old;  // per fiber: X^n, X^(n-1)
  // per fiber: load the fiber exerts ON ITS SUPPORT at the root: (fx, fy, moment about the root)
  std::vector<double> root_load;
  // Since version 7, per fiber: the root load's response to the root's acceleration a,
  // root_load ~ root_load_0 - mass a: (m_xx, m_xy, m_yy) [3 per fiber], and the acceleration
  // (a_x, a_y) it was taken at [2 per fiber]; zeros for fibers without a supported root.
  std::vector<double> root_mass, root_accel;
  void pack(Writer& w) const;
  void unpack(Reader& r);
};

// Whole-message packing with the header into `buffer` (from its start; returns the message's
// length); unpack checks magic, version, tag, and that every byte was read.
template <class M>
std::size_t pack_message(const M& m, std::int64_t step, std::vector<std::byte>& buffer);
template <class M>
void unpack_message(const std::byte* bytes, std::size_t size, M& m, std::int64_t* step = nullptr);
// The same with a buffer of the message's own length.
template <class M>
std::vector<std::byte> pack_message(const M& m, std::int64_t step) {
  std::vector<std::byte> bytes;
  bytes.resize(pack_message(m, step, bytes));
  return bytes;
}
template <class M>
void unpack_message(const std::vector<std::byte>& bytes, M& m, std::int64_t* step = nullptr) {
  unpack_message(bytes.data(), bytes.size(), m, step);
}

struct Header {
  std::uint32_t magic = kMagic;
  std::int32_t version = kVersion;
  Tag tag{};
  std::int32_t pad = 0;
  std::int64_t step = 0;
};

template <class M>
Tag message_tag(const M& m) {
  if constexpr (std::is_same_v<M, Text>) return m.tag;
  else return M::tag;
}

template <class M>
std::size_t pack_message(const M& m, std::int64_t step, std::vector<std::byte>& buffer) {
  Writer w(buffer);
  Header h;
  h.tag = message_tag(m);
  h.step = step;
  w.put(h);
  m.pack(w);
  return w.size();
}

template <class M>
void unpack_message(const std::byte* bytes, std::size_t size, M& m, std::int64_t* step) {
  Reader r(bytes, size);
  Header h;
  r.get(h);
  if (h.magic != kMagic) fail("protocol error: bad message magic {:#x}", h.magic);
  if (h.version != kVersion)
    fail("protocol error: message of version {}, expected {}", h.version, kVersion);
  if (h.tag != message_tag(m))
    fail("protocol error: expected message '{}', got '{}'", tag_name(message_tag(m)), tag_name(h.tag));
  m.unpack(r);
  if (!r.done()) fail("protocol error: message '{}' has trailing bytes", tag_name(h.tag));
  if (step) *step = h.step;
}

}  // namespace fsi::proto
