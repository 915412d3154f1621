// MPMD start-up, handshake, links and the error funnel (see runtime.hpp).
#include "runtime.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "checkpoint.hpp"

namespace fsi {

namespace {

constexpr const char* kRoleNames[kRoleCount] = {"fluid", "solid", "fiber", "coupler"};

// What every process announces at start-up, over MPI_COMM_WORLD. Fixed size and layout so that
// even a process of another protocol version can be read and refused with a clear message.
struct Announce {
  std::uint32_t magic;
  std::int32_t version;
  std::int32_t role;
  std::int32_t appnum;
  std::int32_t local_size;
  std::int32_t world_rank;
  std::uint64_t scene_hash;
  std::int32_t needed;
  std::int32_t pad;
  std::uint64_t options_hash;  // the output options: every program must be given the same
};

// The first word of every announcement ("FSI1"): a process that is not a program of this
// project is refused by name.
constexpr std::uint32_t kAnnounceMagic = 0x31495346u;
// MPI tag of the intercommunicator between the coupler and a solver: this base plus the
// solver's role number.
constexpr int kLinkTagBase = 7100;
// t_end / dt within this relative distance of an integer is that many steps (round-off of the
// division); further away, the step count rounds up.
constexpr double kStepCountTolerance = 1e-9;
// The most steps a run may have: 2^53, the last integer a double counts exactly.
constexpr double kMaxSteps = 9007199254740992.0;

// How long a program waits for a message before it calls its peer stalled (runtime.hpp,
// output.stall_timeout): a fixed limit when the scene gives one (> 0), else automatic.
double g_stall_fixed = 0;
// Automatic: no message waited for longer than kStallFactor times the longest wait that ended so
// far (which holds the peers' longest step), and never less than kStallFloor seconds; before the
// first wait has ended (the set-up: meshing, factorising) kStallSetup seconds.
constexpr double kStallFactor = 20, kStallFloor = 60, kStallSetup = 600;
double g_longest_wait = -1;

double stall_limit() {
  if (g_stall_fixed > 0) return g_stall_fixed;
  return g_longest_wait < 0 ? kStallSetup : std::max(kStallFloor, kStallFactor * g_longest_wait);
}

std::string stall_rule() {
  if (g_stall_fixed > 0) return fmt::format("output.stall_timeout = {:g} s", g_stall_fixed);
  return g_longest_wait < 0
             ? fmt::format("automatic limit during set-up: {:g} s; output.stall_timeout sets one",
                           kStallSetup)
             : fmt::format("automatic limit: {:g} x the longest wait so far ({:.3g} s), at least "
                           "{:g} s; output.stall_timeout sets one",
                           kStallFactor, g_longest_wait, kStallFloor);
}

// Set by SIGUSR1 (./fsi sends it when it is asked to stop; mpirun forwards it to every program).
volatile std::sig_atomic_t g_stop_signal = 0;
extern "C" void on_stop_signal(int) { g_stop_signal = 1; }

// A waiting program tests its request and yields the core between tests: with more programs
// than cores it hands the core to a program ready to run there, and picks its message up at the
// next test; a sleep would hand the core over no sooner and wake late (`./fsi bench protocol`,
// common/PROTOCOL.md). Every 256 tests it looks at the clock: a wait beyond stall_limit() is a
// stalled peer, reported through the funnel with `what` (which message, which peer).
// A solver waits on the coupler half as long again as the limit: the coupler, which waits on the
// program that is really stuck, reports first and names it.
template <class Test>
void wait_until(Test&& test, const std::function<std::string()>& what, double scale) {
  if (test()) return;
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  for (unsigned k = 1;; ++k) {
    std::this_thread::yield();
    if (test()) break;
    if (k % 256 == 0) {
      const double waited = std::chrono::duration<double>(clock::now() - t0).count();
      if (waited > scale * stall_limit())
        fail("no {} after waiting {:.1f} s: that program is stopped or hung ({}{}); ending the job",
             what(), waited, stall_rule(), scale != 1 ? fmt::format(", x {:g} for a solver", scale) : "");
    }
  }
  g_longest_wait = std::max(g_longest_wait,
                            std::chrono::duration<double>(clock::now() - t0).count());
}

// /proc/PID/stat: the state letter and the start time (field 22) of a process; state 0 when
// there is no such process.
std::pair<char, unsigned long long> process_stat(long pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(f, line)) return {0, 0};
  const auto close = line.rfind(')');
  if (close == std::string::npos) return {0, 0};
  std::istringstream rest(line.substr(close + 2));
  char state = 0;
  rest >> state;
  std::string skip;
  for (int field = 4; field < 22; ++field) rest >> skip;
  unsigned long long start = 0;
  rest >> start;
  return {state, start};
}

// The launcher's watch: ./fsi exports its PID as FSI_LAUNCHER_PID; a thread of every program
// looks twice a second whether that process still lives (not gone, not a zombie, not a new
// process under a reused PID). When it is gone (killed, even by SIGKILL, which it cannot
// trap), the program says so and exits; mpirun, left with dead programs, ends the rest. It
// starts before MPI_Init, and a launcher already gone when it starts (killed while the job was
// starting; its zombie waits for its own parent) ends the program at once: the watch used to
// start after MPI_Init and took such a launcher for none, and the job ran on, unwatched.
void watch_launcher(const char* role) {
  const char* env = std::getenv("FSI_LAUNCHER_PID");
  if (!env || !*env) return;
  char* end = nullptr;
  const long pid = std::strtol(env, &end, 10);
  if (*end != 0 || pid <= 1) return;
  auto gone = [role, pid] {
    // Not MPI_Abort: MPI is not ours to call from this thread. Every program watches and
    // exits on its own within the same half second.
    std::fprintf(stderr, "[%s] ERROR: the launcher ./fsi (pid %ld) is gone (killed?): ending "
                 "the job\n", role, pid);
    std::fflush(stderr);
    std::_Exit(1);
  };
  const auto first = process_stat(pid);
  if (first.first == 0 || first.first == 'Z' || first.first == 'X') gone();
  const unsigned long long start = first.second;
  std::thread([gone, pid, start] {
    for (;;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      const auto [s, t] = process_stat(pid);
      if (s == 0 || s == 'Z' || s == 'X' || t != start) gone();
    }
  }).detach();
}

// The output folder's lock: an flock on DIR/.lock held by the first process of the job for as
// long as it lives (the kernel drops it when the process ends, however it ends, so a lock left
// by a dead run is simply taken). The file says who holds it.
constexpr const char* kLockFile = ".lock";

void lock_out_dir(const std::filesystem::path& dir, const std::string& scene) {
  const auto file = dir / kLockFile;
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0)
    throw InputError(fmt::format("cannot create the lock file '{}' of the output folder: {}",
                                 file.string(), std::strerror(errno)));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    std::string holder;
    std::ifstream in(file);
    std::getline(in, holder);
    ::close(fd);
    throw InputError(fmt::format(
        "output folder '{}' is in use by another run that is still running ({}); wait for it to "
        "end, or give this run another folder",
        dir.string(), holder.empty() ? "holder unknown" : holder));
  }
  char host[256] = "?";
  ::gethostname(host, sizeof host - 1);
  const std::string who = fmt::format("pid {} on {}, scene {}\n", ::getpid(), host, scene);
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, who.data(), who.size(), 0) < 0) {
    // The lock holds without its text; only the message of a refused run is poorer.
  }
  // fd stays open (and locked) until this process ends.
}

// Whether DIR holds anything but its lock file.
bool has_contents(const std::filesystem::path& dir) {
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename() != kLockFile) return true;
  return false;
}

void clear_contents(const std::filesystem::path& dir) {
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename() != kLockFile) std::filesystem::remove_all(e.path());
}

}  // namespace

const char* role_name(Role r) { return kRoleNames[static_cast<int>(r)]; }

std::optional<Role> role_from_name(std::string_view name) {
  for (int i = 0; i < kRoleCount; ++i)
    if (name == kRoleNames[i]) return static_cast<Role>(i);
  return std::nullopt;
}

std::string RoleSet::names() const {
  std::string s;
  for (int i = 0; i < kRoleCount; ++i)
    if (need[i]) s += (s.empty() ? "" : ", ") + std::string(kRoleNames[i]);
  return s.empty() ? "none" : s;
}

RoleSet roles_needed(const SceneTable& root) {
  RoleSet r;
  r.need[0] = root.has("fluid");
  r.need[1] = root.has("solid");
  r.need[2] = root.has("fiber");
  r.need[3] = r.solver_count() >= 2;
  if (r.solver_count() == 0)
    root.fail_table("the scene has none of the tables [fluid], [solid], [fiber]: nothing to run");
  if (root.has("coupler") && r.solver_count() < 2)
    root.fail("coupler", "is given, but the scene has only one solver ([" + r.names() +
                             "]): nothing to couple");
  return r;
}

Options parse_options(int argc, char** argv, const char* role) {
  Options o;
  const std::string usage =
      fmt::format("usage: {} SCENE.toml [--out ROOT | --out-dir DIR] [--overwrite] "
                  "[--restart DIR] [--time-limit SECONDS]", role);
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--overwrite") o.overwrite = true;
    else if (a == "--restart") {
      if (i + 1 >= argc) throw InputError(fmt::format("--restart needs the folder of the run; {}", usage));
      o.restart = std::filesystem::path(argv[++i]);
    } else if (a == "--time-limit") {
      if (i + 1 >= argc) throw InputError(fmt::format("--time-limit needs a number of seconds; {}", usage));
      const std::string v = argv[++i];
      char* end = nullptr;
      o.time_limit = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !(o.time_limit > 0) || !std::isfinite(o.time_limit))
        throw InputError(fmt::format("--time-limit must be a number of seconds > 0, got '{}'", v));
    } else if (a == "--out" || a == "--out-dir") {
      if (i + 1 >= argc) throw InputError(fmt::format("{} needs a folder; {}", a, usage));
      if (a == "--out") o.out_root = argv[++i];
      else o.out_dir = std::filesystem::path(argv[++i]);
    } else if (a == "--help" || a == "-h") throw InputError(usage);
    else if (a.starts_with("--")) throw InputError(fmt::format("unknown option '{}'; {}", a, usage));
    else positional.push_back(a);
  }
  if (positional.size() != 1)
    throw InputError(fmt::format("expected one scene file, got {}; {}", positional.size(), usage));
  o.scene = positional[0];
  if (o.restart && (o.out_dir || o.overwrite || o.out_root != "out"))
    throw InputError(fmt::format("--restart resumes in its own folder: it takes no --out, --out-dir "
                                 "or --overwrite; {}", usage));
  return o;
}

CommonSettings read_common(const SceneTable& root) {
  CommonSettings s;
  const auto scene = root.optional_table("scene");
  const std::string stem = root.file().stem().string();
  if (scene) {
    s.name = scene->string("name", stem);
    scene->string("description", "");
    scene->finish();
  } else {
    s.name = stem;
  }
  if (s.name.empty() || s.name.find_first_of("/\\ ") != std::string::npos || s.name[0] == '.')
    root.table("scene").fail("name", fmt::format("must be a plain folder name, got \"{}\"", s.name));

  const auto time = root.table("time");
  s.dt = time.positive("dt");
  s.t_end = time.positive("t_end");
  const double n = s.t_end / s.dt;
  // The step counter is a long and t^n = n dt; beyond 2^53 steps n itself is no longer exact in
  // double precision (nor lround defined near the long's end): refused, not wrapped.
  if (!(n <= kMaxSteps))
    time.fail("t_end", fmt::format("= {:g} is {:.3g} steps of time.dt = {:g}, more than the {:.3g} "
                                   "steps a run can count; shorten t_end or lengthen dt",
                                   s.t_end, n, s.dt, kMaxSteps));
  s.steps = std::lround(n);
  if (std::abs(static_cast<double>(s.steps) - n) > kStepCountTolerance * n) s.steps = static_cast<long>(std::ceil(n));
  if (s.steps < 1) s.steps = 1;
  time.finish();

  if (const auto out = root.optional_table("output")) {
    s.output_interval = out->non_negative("interval", 0.0);
    s.progress_every = out->integer("progress", 0);
    s.checkpoint_interval = out->non_negative("checkpoint_interval", 0.0);
    if (s.progress_every < 0) out->fail("progress", fmt::format("must be >= 0, got {}", s.progress_every));
    s.stall_timeout = out->non_negative("stall_timeout", 0.0);
    out->finish();
  }
  if (const auto test = root.optional_table("test")) {
    const std::vector<std::string> roles(kRoleNames, kRoleNames + kRoleCount);
    if (test->has("fail_role")) {
      s.fail_role = test->choice("fail_role", roles);
      s.fail_step = test->integer("fail_step");
      if (s.fail_step < 0) test->fail("fail_step", fmt::format("must be >= 0, got {}", s.fail_step));
    }
    if (test->has("hang_role")) {
      s.hang_role = test->choice("hang_role", roles);
      s.hang_step = test->integer("hang_step");
      if (s.hang_step < 0) test->fail("hang_step", fmt::format("must be >= 0, got {}", s.hang_step));
    }
    if (test->has("bad_protocol_version"))
      s.bad_version_role = test->choice("bad_protocol_version", roles);
    s.work_ahead = test->boolean("work_ahead", true);
    test->finish();
  }
  return s;
}

std::filesystem::path choose_out_dir(const std::filesystem::path& root, const std::string& name,
                                     bool overwrite) {
  namespace fs = std::filesystem;
  fs::create_directories(root);
  fs::path dir = root / name;
  if (overwrite) {
    fs::create_directories(dir);
    return dir;
  }
  // create_directory is one mkdir: of two runs racing for a name, exactly one gets it.
  for (int k = 2; !fs::create_directory(dir); ++k) dir = root / fmt::format("{}-{}", name, k);
  return dir;
}

// ---- Link -------------------------------------------------------------------------------------

void Link::send_bytes(std::size_t size, proto::Tag tag) {
  MPI_Request req;
  MPI_Isend(m_out.data(), static_cast<int>(size), MPI_BYTE, m_remote, static_cast<int>(tag), m_comm,
            &req);
  wait_until(
      [&] {
        int done = 0;
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        return done != 0;
      },
      [&] { return fmt::format("delivery of message '{}' to {}", proto::tag_name(tag), role_name(m_peer)); },
      m_peer == Role::coupler ? 1.5 : 1.0);
  m_sent += size;
}

std::size_t Link::recv_bytes(proto::Tag expected) {
  int flag = 0;
  MPI_Message msg;
  MPI_Status status;
  wait_until(
      [&] {
        MPI_Improbe(m_remote, MPI_ANY_TAG, m_comm, &flag, &msg, &status);
        return flag != 0;
      },
      [&] { return fmt::format("message '{}' from {}", proto::tag_name(expected), role_name(m_peer)); },
      m_peer == Role::coupler ? 1.5 : 1.0);
  if (status.MPI_TAG != static_cast<int>(expected))
    fail("protocol error: expected message '{}' from {}, got '{}'", proto::tag_name(expected),
         role_name(m_peer), proto::tag_name(static_cast<proto::Tag>(status.MPI_TAG)));
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  const auto size = static_cast<std::size_t>(count);
  if (m_in.size() < size) m_in.resize(std::max(size, 2 * m_in.size()));
  MPI_Mrecv(m_in.data(), count, MPI_BYTE, &msg, MPI_STATUS_IGNORE);
  m_received += size;
  return size;
}

// ---- Runtime ----------------------------------------------------------------------------------

Link& Runtime::coupler_link() {
  if (!has_link(Role::coupler)) fail("no coupler in this run");
  return *m_links[static_cast<int>(Role::coupler)][0];
}

Link& Runtime::link(Role solver) {
  if (!has_link(solver)) fail("no link to the {}", role_name(solver));
  return *m_links[static_cast<int>(solver)][0];
}

std::vector<std::unique_ptr<Link>>& Runtime::links(Role solver) {
  if (!has_link(solver)) fail("no link to the {}", role_name(solver));
  return m_links[static_cast<int>(solver)];
}

double Runtime::wall_seconds() const { return MPI_Wtime() - m_t0; }

bool Runtime::stop_requested() const {
  int stop = g_stop_signal != 0 || (m_time_limit > 0 && wall_seconds() > m_time_limit);
  if (m_program_size > 1)
    MPI_Allreduce(MPI_IN_PLACE, &stop, 1, MPI_INT, MPI_LOR, m_program_comm);
  return stop != 0;
}

void Runtime::check_fault(long step) const {
  if (m_settings.fail_role == name() && step == m_settings.fail_step)
    fail("test fault injected at step {} (test.fail_role = \"{}\")", step, name());
  if (m_settings.hang_role == name() && step == m_settings.hang_step) {
    std::fprintf(stderr, "[%s] test hang injected at step %ld (test.hang_role): waiting forever\n",
                 name(), step);
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
  }
}

namespace {
const Scene* g_scene = nullptr;  // this process's scene, for extreme_constants_hint()
}

std::string extreme_constants_hint() {
  // 1e9: beyond any coefficient of a scene in its users' units (moduli in Pa reach 1e12 only
  // for diamond; the hint says "likely", and only when a check has already tripped).
  constexpr double kExtreme = 1e9;
  if (!g_scene) return {};
  const auto found = g_scene->extreme_numbers(kExtreme);
  if (found.empty()) return {};
  return fmt::format("; the scene has extreme values, a likelier cause: {}", fmt::join(found, ", "));
}

void abort_job(const char* role, const std::string& message) {
  std::fprintf(stderr, "[%s] ERROR: %s\n", role, message.c_str());
  std::fflush(stderr);
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (initialized && !finalized) MPI_Abort(MPI_COMM_WORLD, 1);
  std::_Exit(1);
}

namespace {

// Start-up checks on what every process announced; the same verdict on every process.
void check_job(const Runtime& rt, const std::vector<Announce>& all, const RoleSet& need,
               std::uint64_t my_hash) {
  std::array<int, kRoleCount> appnum;
  appnum.fill(-1);
  for (const auto& a : all) {
    if (a.magic != kAnnounceMagic)
      fail("process {} of the job is not a program of this project", a.world_rank);
    if (a.role < 0 || a.role >= kRoleCount) fail("process {} announced an unknown role", a.world_rank);
    const char* who = kRoleNames[a.role];
    if (a.version != proto::kVersion)
      fail("protocol version mismatch: {} speaks version {}, {} speaks version {}; rebuild the "
           "programs from one source tree",
           who, a.version, rt.name(), proto::kVersion);
    if (a.scene_hash != my_hash)
      fail("scene mismatch: {} read a scene file with different contents than {} (same path on "
           "every process, same file?)",
           who, rt.name());
    if (a.options_hash != all[0].options_hash)
      fail("{} and {} were given different output options (--out, --out-dir, --overwrite, --restart) "
           "or found different checkpoints to resume from; give every program of the job the same "
           "arguments",
           who, kRoleNames[all[0].role]);
    if (appnum[a.role] >= 0 && appnum[a.role] != a.appnum)
      fail("role '{}' was launched twice (programs {} and {} of the mpirun line); launch each "
           "program once",
           who, appnum[a.role], a.appnum);
    appnum[a.role] = a.appnum;
    // The fluid may run on several ranks (its grid split in slabs); the others on one.
    if (a.local_size != 1 && a.role != static_cast<int>(Role::fluid))
      fail("{} was launched on {} ranks; it runs on 1 rank (-n 1); only the fluid may run on "
           "several",
           who, a.local_size);
  }
  std::vector<std::string> missing, launched;
  for (int r = 0; r < kRoleCount; ++r) {
    if (appnum[r] >= 0) launched.push_back(kRoleNames[r]);
    if (need.need[r] && appnum[r] < 0) missing.push_back(kRoleNames[r]);
  }
  if (!missing.empty())
    fail("the scene needs the program(s) {}, which were not launched (launched: {}; the scene "
         "needs: {})",
         fmt::join(missing, ", "), fmt::join(launched, ", "), need.names());
}

}  // namespace

int run_program(Role role, int argc, char** argv, const std::function<void(Runtime&)>& body) {
  watch_launcher(role_name(role));
  MPI_Init(&argc, &argv);
  Runtime rt;
  rt.m_role = role;
  rt.m_t0 = MPI_Wtime();
  try {
    int world_rank = 0, world_size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    int* appnum_attr = nullptr;
    int flag = 0;
    MPI_Comm_get_attr(MPI_COMM_WORLD, MPI_APPNUM, &appnum_attr, &flag);
    const int appnum = flag ? *appnum_attr : 0;
    MPI_Comm local;
    MPI_Comm_split(MPI_COMM_WORLD, appnum, world_rank, &local);
    int local_size = 1;
    MPI_Comm_size(local, &local_size);
    rt.m_program_comm = local;
    rt.m_program_size = local_size;
    MPI_Comm_rank(local, &rt.m_program_rank);

    const Options opts = parse_options(argc, argv, rt.name());
    rt.m_scene = std::make_unique<Scene>(opts.scene);
    g_scene = rt.m_scene.get();
    const SceneTable root = rt.m_scene->root();
    rt.m_roles = roles_needed(root);
    rt.m_settings = read_common(root);
    g_stall_fixed = rt.m_settings.stall_timeout;
    for (const char* k : {"fluid", "solid", "fiber", "coupler"}) root.skip(k);
    root.finish();
    rt.m_time_limit = opts.time_limit;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGUSR1, &sa, nullptr);
    // A restart resumes from the newest step that every program of the scene completed; each
    // program finds it alone, and the handshake checks that they agree.
    if (opts.restart) {
      if (!std::filesystem::is_directory(*opts.restart))
        throw InputError(fmt::format("--restart {}: no such folder", opts.restart->string()));
      rt.m_restart_step = newest_checkpoint(*opts.restart, rt.m_roles);
      if (!rt.m_restart_step)
        throw InputError(fmt::format(
            "--restart {}: no complete checkpoint in {} (a checkpoint is written every "
            "output.checkpoint_interval and when a run is asked to stop)",
            opts.restart->string(), (*opts.restart / "checkpoint").string()));
      check_checkpoint_version(*opts.restart, *rt.m_restart_step, role, opts.scene);
    }

    // Handshake: who is here, which protocol, which scene.
    Announce me{kAnnounceMagic,
                rt.m_settings.bad_version_role == rt.name() ? proto::kVersion + 1000 : proto::kVersion,
                static_cast<int>(role),
                appnum,
                local_size,
                world_rank,
                rt.m_scene->hash(),
                rt.m_roles[role] ? 1 : 0,
                0,
                // FNV-1a of "ROOT|DIR|true/false|RESTART|STEP" (PROTOCOL.md, start-up), not
                // std::hash: a program in another language computes the same.
                proto::fnv1a(fmt::format(
                    "{}|{}|{}|{}|{}", opts.out_root.string(), opts.out_dir ? opts.out_dir->string() : "-",
                    opts.overwrite, opts.restart ? opts.restart->string() : "-",
                    rt.m_restart_step.value_or(-1)))};
    std::vector<Announce> all(static_cast<std::size_t>(world_size));
    MPI_Allgather(&me, sizeof(Announce), MPI_BYTE, all.data(), sizeof(Announce), MPI_BYTE,
                  MPI_COMM_WORLD);
    if (me.version != proto::kVersion)
      fail("protocol version {} announced (test.bad_protocol_version); this build speaks {}",
           me.version, proto::kVersion);
    check_job(rt, all, rt.m_roles, rt.m_scene->hash());

    // The processes the scene needs carry on in `job`; the others leave cleanly.
    MPI_Comm job;
    MPI_Comm_split(MPI_COMM_WORLD, rt.m_roles[role] ? 0 : MPI_UNDEFINED, world_rank, &job);
    if (!rt.m_roles[role]) {
      std::fprintf(stderr, "[%s] not needed by scene '%s' (it needs %s): exiting\n", rt.name(),
                   rt.m_settings.name.c_str(), rt.m_roles.names().c_str());
      MPI_Finalize();
      return 0;
    }
    int job_rank = 0;
    MPI_Comm_rank(job, &job_rank);

    // Output folder: chosen by the first process of the job, the same for all.
    std::string dir;
    if (job_rank == 0) {
      const std::filesystem::path d =
          opts.restart  ? *opts.restart
          : opts.out_dir ? *opts.out_dir
                         : choose_out_dir(opts.out_root, rt.m_settings.name, opts.overwrite);
      std::filesystem::create_directories(d);
      // Locked before anything in it is looked at or removed: a live run's folder is refused
      // (a restart resumes in its folder and keeps what it holds).
      lock_out_dir(d, opts.scene.string());
      if (opts.overwrite) clear_contents(d);
      else if (opts.out_dir && has_contents(d))
        throw InputError(fmt::format(
            "output folder '{}' exists and is not empty; pass --overwrite to replace it", d.string()));
      dir = d.string();
    }
    long len = static_cast<long>(dir.size());
    MPI_Bcast(&len, 1, MPI_LONG, 0, job);
    dir.resize(static_cast<std::size_t>(len));
    MPI_Bcast(dir.data(), static_cast<int>(len), MPI_CHAR, 0, job);
    rt.m_out_dir = dir;

    // Intercommunicators: the coupler with each solver, in the order fluid, solid, fiber.
    if (rt.coupled()) {
      std::array<int, kRoleCount> job_rank_of;
      job_rank_of.fill(-1);
      std::vector<int> ranks(static_cast<std::size_t>(world_size), -1);
      MPI_Allgather(&role, 1, MPI_INT, ranks.data(), 1, MPI_INT, job);
      int job_size = 0;
      MPI_Comm_size(job, &job_size);
      for (int k = 0; k < job_size; ++k)
        if (job_rank_of[ranks[k]] < 0) job_rank_of[ranks[k]] = k;
      if (role == Role::coupler) {
        for (Role s : {Role::fluid, Role::solid, Role::fiber}) {
          if (!rt.m_roles[s]) continue;
          MPI_Comm inter;
          MPI_Intercomm_create(local, 0, job, job_rank_of[static_cast<int>(s)],
                               kLinkTagBase + static_cast<int>(s), &inter);
          int remote = 1;
          MPI_Comm_remote_size(inter, &remote);
          for (int r = 0; r < remote; ++r)
            rt.m_links[static_cast<int>(s)].push_back(std::make_unique<Link>(inter, s, r));
        }
      } else {
        MPI_Comm inter;
        MPI_Intercomm_create(local, 0, job, job_rank_of[static_cast<int>(Role::coupler)],
                             kLinkTagBase + static_cast<int>(role), &inter);
        rt.m_links[static_cast<int>(Role::coupler)].push_back(
            std::make_unique<Link>(inter, Role::coupler));
      }
    }

    body(rt);
  } catch (const std::exception& e) {
    abort_job(rt.name(), e.what());
  } catch (...) {
    abort_job(rt.name(), "unknown exception");
  }
  MPI_Finalize();
  return 0;
}

}  // namespace fsi
