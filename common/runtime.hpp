// The MPMD runtime every program starts with. run_program() initialises MPI, reads the scene,
// finds the programs of the job by name (never by position), checks the protocol version and the
// scene's identity on every process, picks the output folder, links the coupler to each solver
// with an intercommunicator, runs the program's body, and funnels every error into
// "[role] ERROR: ..." on stderr followed by MPI_Abort(MPI_COMM_WORLD, 1).
#pragma once

#include <mpi.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "protocol.hpp"
#include "scene.hpp"

namespace fsi {

enum class Role : int { fluid = 0, solid = 1, fiber = 2, coupler = 3 };
inline constexpr int kRoleCount = 4;
const char* role_name(Role r);
std::optional<Role> role_from_name(std::string_view name);

// Which programs a scene needs: a solver when its top-level table is present, the coupler when
// two or more solvers are.
struct RoleSet {
  std::array<bool, kRoleCount> need{};
  bool operator[](Role r) const { return need[static_cast<int>(r)]; }
  int solver_count() const { return need[0] + need[1] + need[2]; }
  std::string names() const;  // "fluid, solid"
};
RoleSet roles_needed(const SceneTable& root);

// Command line shared by all programs: PROGRAM SCENE.toml [--out DIR] [--overwrite]
struct Options {
  std::filesystem::path scene;
  std::filesystem::path out_root = "out";
  std::optional<std::filesystem::path> out_dir;  // --out-dir: exactly this folder
  bool overwrite = false;
  // --restart DIR: resume the run in DIR from its newest complete checkpoint (output continues
  // there); excludes --out, --out-dir and --overwrite.
  std::optional<std::filesystem::path> restart;
  double time_limit = 0;  // --time-limit SECONDS: checkpoint and stop after this wall time (0: none)
};
Options parse_options(int argc, char** argv, const char* role);

// The sections every program reads: [scene], [time], [output], [test].
struct CommonSettings {
  std::string name;         // scene.name: names the output folder
  double dt = 0;            // time.dt > 0
  double t_end = 0;         // time.t_end > 0
  long steps = 0;           // number of steps: t_end / dt rounded up
  double output_interval = 0;  // output.interval: field output every this much time; 0 = none
  long progress_every = 0;     // output.progress: 0 = automatic
  double checkpoint_interval = 0;  // output.checkpoint_interval: checkpoint every this much time
  // output.stall_timeout: seconds a program waits for a message before it reports its peer
  // stalled and ends the job; 0 = automatic (20 x the longest wait so far, at least 60 s; 600 s
  // before the first message has arrived)
  double stall_timeout = 0;
  // [test]: fault switches used by the test suite only
  std::string fail_role;    // test.fail_role: this program fails ...
  long fail_step = -1;      // ... at the start of this step
  std::string hang_role;     // test.hang_role: this program hangs (sleeps forever) ...
  long hang_step = -1;       // ... at the start of this step
  std::string bad_version_role;  // test.bad_protocol_version: this program announces a wrong version
  bool work_ahead = true;   // test.work_ahead = false: the solvers do no work ahead of their input
};
CommonSettings read_common(const SceneTable& root);

// A point-to-point link to one process of another program over their intercommunicator: its
// rank `remote` there (0 unless that program runs on several ranks: the fluid's).
// send/recv wait by testing and yielding the core between tests, so that a program waiting for a
// message leaves the core to the one that computes.
class Link {
 public:
  Link(MPI_Comm inter, Role peer, int remote = 0) : m_comm(inter), m_peer(peer), m_remote(remote) {}
  Role peer() const { return m_peer; }
  // The first `size` bytes of m_out; a received message into m_in, returning its length.
  void send_bytes(std::size_t size, proto::Tag tag);
  std::size_t recv_bytes(proto::Tag expected);
  template <class M>
  void send(const M& m, std::int64_t step = 0) {
    send_bytes(proto::pack_message(m, step, m_out), proto::message_tag(m));
  }
  template <class M>
  void recv(M& m, std::int64_t* step = nullptr) {
    const std::size_t size = recv_bytes(proto::message_tag(m));
    proto::unpack_message(m_in.data(), size, m, step);
  }
  std::uint64_t bytes_sent() const { return m_sent; }
  std::uint64_t bytes_received() const { return m_received; }

 private:
  MPI_Comm m_comm;
  Role m_peer;
  int m_remote = 0;
  std::uint64_t m_sent = 0, m_received = 0;
  // Kept between messages (see proto::Writer): a send completes before send() returns, and a
  // received message is unpacked before the next is received. Each keeps the size of the
  // largest message so far (up to twice that after a growth), set-up messages included.
  std::vector<std::byte> m_out, m_in;
};

class Runtime {
 public:
  Role role() const { return m_role; }
  const char* name() const { return role_name(m_role); }
  const Scene& scene() const { return *m_scene; }
  SceneTable root() const { return m_scene->root(); }
  const CommonSettings& settings() const { return m_settings; }
  const RoleSet& roles() const { return m_roles; }
  const std::filesystem::path& out_dir() const { return m_out_dir; }
  // True when a coupler runs: solvers then talk to it through coupler_link().
  bool coupled() const { return m_roles[Role::coupler]; }
  Link& coupler_link();
  // On the coupler: the link to a solver the scene needs (to its rank 0), and to each of its
  // ranks (the fluid may run on several).
  Link& link(Role solver);
  std::vector<std::unique_ptr<Link>>& links(Role solver);
  bool has_link(Role r) const { return !m_links[static_cast<int>(r)].empty(); }
  double wall_seconds() const;  // since start
  // A restarted run: the step of the checkpoint it resumes from (nullopt: a fresh run).
  std::optional<long> restart_step() const { return m_restart_step; }
  // First step this run computes: 0, or the restart step.
  long first_step() const { return m_restart_step.value_or(0); }
  // Whether the run was asked to stop (SIGUSR1, SIGTERM or SIGINT to this program, or the wall
  // time of --time-limit passed): checkpoint, then stop. Cheap; polled once a step. A program on
  // several ranks answers for all of them (collective: one reduction).
  bool stop_requested() const;
  // This program's own ranks (the fluid may run on several; the others on one): their
  // communicator, this one's rank among them, how many. Files of the program are written by its
  // rank 0 (is_root()).
  MPI_Comm program_comm() const { return m_program_comm; }
  int program_rank() const { return m_program_rank; }
  int program_size() const { return m_program_size; }
  bool is_root() const { return m_program_rank == 0; }
  // The test-only fault switch: throws when this program is told to fail at `step`.
  void check_fault(long step) const;

 private:
  friend int run_program(Role, int, char**, const std::function<void(Runtime&)>&);
  Role m_role{};
  std::unique_ptr<Scene> m_scene;
  CommonSettings m_settings;
  RoleSet m_roles;
  std::filesystem::path m_out_dir;
  std::array<std::vector<std::unique_ptr<Link>>, kRoleCount> m_links;
  double m_t0 = 0;
  MPI_Comm m_program_comm = MPI_COMM_NULL;
  int m_program_rank = 0, m_program_size = 1;
  std::optional<long> m_restart_step;
  double m_time_limit = 0;
};

// The body of a program's main. Returns the process exit code (0), or aborts the job on error.
int run_program(Role role, int argc, char** argv, const std::function<void(Runtime&)>& body);

// Print "[role] ERROR: message" and abort the whole job.
[[noreturn]] void abort_job(const char* role, const std::string& message);

// Choose and create the output folder under `root` for scene `name`: root/name, or root/name-2,
// -3, ... if that exists (never silently overwritten; each made by one mkdir, so two runs racing
// for a name get different folders), or root/name itself when `overwrite` (run_program empties
// it once it holds the folder's lock, DIR/.lock, which a live run keeps).
std::filesystem::path choose_out_dir(const std::filesystem::path& root, const std::string& name,
                                     bool overwrite);

}  // namespace fsi
