// Checkpoint files: where they live, how they are written safely, which one a restart takes.
#include "checkpoint.hpp"

#include "driver.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <map>
#include <sstream>
#include <toml.hpp>

namespace fsi {

namespace {

constexpr const char* kStepPrefix = "step_";

// The step of a folder named step_<n>, or -1.
long folder_step(const std::filesystem::path& p) {
  const std::string name = p.filename().string();
  if (!name.starts_with(kStepPrefix)) return -1;
  const std::string digits = name.substr(std::string(kStepPrefix).size());
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stol(digits);
}

// Make the file's data durable before it is renamed into place.
void sync_file(const std::filesystem::path& p) {
  const int fd = ::open(p.c_str(), O_RDONLY);
  if (fd < 0) fail("cannot reopen checkpoint {} to flush it to disk", p.string());
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) fail("cannot flush checkpoint {} to disk (no space left on device?)", p.string());
}

using Toml = toml::basic_value<toml::discard_comments, std::map, std::vector>;

Toml parse_toml(const std::string& text, const std::string& name) {
  std::istringstream is(text);
  return toml::parse<toml::discard_comments, std::map, std::vector>(is, name);
}

// Keys a restart may change: the run's length, its output, the test switches and the fluid's
// rank count (a checkpoint holds the whole grid).
bool may_change(const std::string& path) {
  return path == "time.t_end" || path == "output" || path.starts_with("output.") ||
         path == "scene.description" || path == "test" || path.starts_with("test.") ||
         path == "fluid.ranks";
}

// A key that only one side has is a difference unless `reads` says this program does not read
// it: an effective scene holds the defaults its own program filled in, so the scene.effective.toml
// a run writes (every program's defaults) has keys that another program's checkpoint lacks, with
// the values that program used. The program that reads such a key compares it itself. `side`
// says where a key only one side has is: 1 before only, 2 now only (0: a value that differs).
std::string first_difference(const Toml& a, const Toml& b, const std::string& path, const ReadsKey& reads,
                             int& side) {
  if (!path.empty() && may_change(path)) return {};
  auto one_sided = [&](const std::string& k, const std::string& p) {
    return !may_change(p) && (!reads || reads(path, k));
  };
  if (a.is_table() && b.is_table()) {
    for (const auto& [k, v] : a.as_table()) {
      const std::string p = path.empty() ? k : path + "." + k;
      if (!b.as_table().count(k)) {
        if (one_sided(k, p)) return side = 1, p;
        continue;
      }
      if (auto d = first_difference(v, b.as_table().at(k), p, reads, side); !d.empty()) return d;
    }
    for (const auto& [k, v] : b.as_table()) {
      const std::string p = path.empty() ? k : path + "." + k;
      if (!a.as_table().count(k) && one_sided(k, p)) return side = 2, p;
    }
    return {};
  }
  if (a.is_array() && b.is_array()) {
    const auto& x = a.as_array();
    const auto& y = b.as_array();
    if (x.size() != y.size()) return path;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (auto d = first_difference(x[i], y[i], fmt::format("{}[{}]", path, i), reads, side); !d.empty())
        return d;
    return {};
  }
  return a == b ? std::string() : path;
}

}  // namespace

std::filesystem::path checkpoint_folder(const std::filesystem::path& out_dir, long step) {
  return out_dir / "checkpoint" / fmt::format("{}{:08d}", kStepPrefix, step);
}

std::filesystem::path checkpoint_file(const std::filesystem::path& out_dir, long step, Role role) {
  return checkpoint_folder(out_dir, step) / fmt::format("{}.h5", role_name(role));
}

void write_checkpoint(const Runtime& rt, long step, const std::function<void(H5File&)>& fill,
                      const std::function<void()>& others) {
  if (!rt.is_root()) {
    if (others) others();
    return;
  }
  const auto folder = checkpoint_folder(rt.out_dir(), step);
  std::filesystem::create_directories(folder);
  const auto path = checkpoint_file(rt.out_dir(), step, rt.role());
  auto tmp = path;
  tmp += ".tmp";
  {
    H5File h5(tmp, H5File::Mode::truncate);
    h5.set_attribute("/", "step", static_cast<std::int64_t>(step));
    h5.set_attribute("/", "time", step_time(rt.settings(), step));
    h5.set_attribute("/", "scene", rt.scene().effective_toml());
    h5.set_attribute("/", "protocol_version", static_cast<std::int64_t>(proto::kVersion));
    fill(h5);
    h5.flush();
  }
  sync_file(tmp);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) fail("cannot put checkpoint {} in place: {}", path.string(), ec.message());
  // Older checkpoints: keep this one and this program's previous one.
  std::vector<long> mine;
  for (const auto& e : std::filesystem::directory_iterator(rt.out_dir() / "checkpoint")) {
    const long s = folder_step(e.path());
    if (s >= 0 && s < step && std::filesystem::exists(checkpoint_file(rt.out_dir(), s, rt.role())))
      mine.push_back(s);
  }
  std::sort(mine.begin(), mine.end());
  for (std::size_t k = 0; k + 1 < mine.size(); ++k) {
    std::filesystem::remove(checkpoint_file(rt.out_dir(), mine[k], rt.role()), ec);
    std::filesystem::remove(checkpoint_folder(rt.out_dir(), mine[k]), ec);  // only when empty
  }
}

std::optional<long> newest_checkpoint(const std::filesystem::path& out_dir, const RoleSet& roles) {
  std::optional<long> best;
  const auto root = out_dir / "checkpoint";
  if (!std::filesystem::is_directory(root)) return best;
  for (const auto& e : std::filesystem::directory_iterator(root)) {
    const long s = folder_step(e.path());
    if (s < 0 || (best && s <= *best)) continue;
    bool complete = true;
    for (int r = 0; r < kRoleCount; ++r)
      if (roles.need[r] && !std::filesystem::exists(checkpoint_file(out_dir, s, static_cast<Role>(r))))
        complete = false;
    if (complete) best = s;
  }
  return best;
}

void write_vectors(H5File& h5, const std::string& name, const std::vector<std::vector<double>>& v) {
  std::vector<double> values;
  std::vector<std::int64_t> sizes;
  for (const auto& x : v) {
    values.insert(values.end(), x.begin(), x.end());
    sizes.push_back(static_cast<std::int64_t>(x.size()));
  }
  h5.write(name + "/values", values);
  h5.write(name + "/sizes", sizes);
}

std::vector<std::vector<double>> read_vectors(const H5File& h5, const std::string& name) {
  const std::vector<double> values = h5.read_doubles(name + "/values");
  const std::vector<std::int64_t> sizes = h5.read_int64s(name + "/sizes");
  std::vector<std::vector<double>> v;
  std::size_t at = 0;
  for (std::int64_t n : sizes) {
    if (n < 0 || at + static_cast<std::size_t>(n) > values.size())
      fail("checkpoint {}: {} is damaged (sizes and values disagree)", h5.path().string(), name);
    v.emplace_back(values.begin() + at, values.begin() + at + n);
    at += static_cast<std::size_t>(n);
  }
  return v;
}

double restart_time(const Runtime& rt) { return step_time(rt.settings(), rt.first_step()); }

namespace {
// The last step whose fields a restarted run keeps: the restart step when the resumed scene
// outputs it, else the one before (a run that ended there wrote it as its last).
long last_kept_fields_step(const Runtime& rt) {
  const long n = rt.first_step();
  return is_output_step(rt.settings(), n) ? n : n - 1;
}
}  // namespace

double restart_fields_time(const Runtime& rt) { return step_time(rt.settings(), last_kept_fields_step(rt)); }

H5File output_h5(const Runtime& rt, const std::filesystem::path& path) {
  if (!rt.restart_step() || !std::filesystem::exists(path)) return H5File(path, H5File::Mode::truncate);
  H5File h5(path, H5File::Mode::read_write);
  const long keep = last_kept_fields_step(rt);
  for (const std::string& name : h5.children("/"))
    if (folder_step(name) > keep) h5.remove("/" + name);
  return h5;
}

ProbeCsv output_csv(const Runtime& rt, const std::filesystem::path& path, std::vector<std::string> columns) {
  if (!rt.restart_step()) return ProbeCsv(path, std::move(columns));
  return ProbeCsv::resume(path, std::move(columns), restart_time(rt));
}

std::string changed_physics_key(const std::string& before, const std::string& now, const ReadsKey& reads,
                                int* side) {
  int s = 0;
  std::string key = first_difference(parse_toml(before, "checkpoint"), parse_toml(now, "scene"), "", reads, s);
  if (side) *side = s;
  return key;
}

// Checked by every program on its own file before anything of the run is opened (runtime.cpp),
// so that a refused restart leaves the output as it was.
void check_checkpoint_version(const std::filesystem::path& out_dir, long step, Role role,
                              const std::filesystem::path& scene_file) {
  const H5File h5(checkpoint_file(out_dir, step, role), H5File::Mode::read_only);
  // A build of another protocol version may compute other physics from the same scene (version
  // 8: rigid bodies keep the fluid's viscosity under fluid.body_viscosity = "none").
  const long version = h5.has_attribute("/", "protocol_version")
                           ? std::lround(h5.attribute_number("/", "protocol_version"))
                           : 0;
  if (version != proto::kVersion)
    throw InputError(fmt::format(
        "--restart {}: the checkpoint of step {} was written by a build of protocol version {}, "
        "this build speaks {}: its coupling may differ (version 8: rigid bodies keep the fluid's "
        "viscosity under fluid.body_viscosity = \"none\"; version 9: under "
        "fluid.body_divergence = \"solid\" or \"coupled_step\", cells whose faces name more "
        "than one body take none of their divergence); run the scene from the start, or "
        "resume with the build that wrote the checkpoint (scene {})",
        out_dir.string(), step,
        version ? std::to_string(version) : "none recorded (a build before this check)",
        proto::kVersion, scene_file.string()));
}

H5File open_restart(const Runtime& rt) {
  const long step = *rt.restart_step();
  H5File h5(checkpoint_file(rt.out_dir(), step, rt.role()), H5File::Mode::read_only);
  const Scene& scene = rt.scene();
  int side = 0;
  const std::string key = changed_physics_key(
      h5.attribute_string("/", "scene"), scene.effective_toml(),
      [&](const std::string& t, const std::string& k) { return scene.reads(t, k); }, &side);
  if (!key.empty())
    throw InputError(fmt::format(
        "{} {} (checkpoint of step {} in {}): a restart may change time.t_end and [output] only "
        "(in {})",
        key,
        side == 1   ? "is set in the run being resumed and not in this scene"
        : side == 2 ? "is set in this scene and not in the run being resumed"
                    : "differs from the run being resumed",
        step, rt.out_dir().string(), rt.scene().file().string()));
  return h5;
}

}  // namespace fsi
