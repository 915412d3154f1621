// summary.json builder, the phase timer, and the atomic file write they and the XDMF side files
// use.
#include "summary.hpp"

#include <ctime>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <system_error>

namespace fsi {

void write_file_atomically(const std::filesystem::path& path, std::string_view text) {
  // The temporary lives in the target's folder so that the rename stays on one file system.
  std::filesystem::path tmp = path;
  tmp += fmt::format(".tmp{}", static_cast<long>(::getpid()));
  {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw Error(fmt::format("cannot write {}: cannot create {}", path.string(), tmp.string()));
    bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    ok = std::fclose(f) == 0 && ok;
    if (!ok) {
      std::filesystem::remove(tmp);
      throw Error(fmt::format("cannot write {} (disk full?)", path.string()));
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw Error(fmt::format("cannot write {}: rename failed: {}", path.string(), ec.message()));
  }
}

// ---- Metric ----

namespace {
bool finite_pass(double value, double error, double tolerance) {
  return std::isfinite(value) && std::isfinite(error) && error <= tolerance;
}
}  // namespace

Metric Metric::relative(double value, double reference, double tolerance) {
  double diff = std::abs(value - reference);
  double error = reference != 0.0 ? diff / std::abs(reference) : diff;
  return {value, reference, error, tolerance, finite_pass(value, error, tolerance)};
}

Metric Metric::absolute(double value, double reference, double tolerance) {
  double error = std::abs(value - reference);
  return {value, reference, error, tolerance, finite_pass(value, error, tolerance)};
}

Metric Metric::with_error(double value, double reference, double error, double tolerance) {
  return {value, reference, error, tolerance, finite_pass(value, error, tolerance)};
}

// ---- PhaseTimer ----

PhaseTimer::Id PhaseTimer::phase(std::string_view name) {
  for (Id k = 0; k < m_entries.size(); ++k)
    if (m_entries[k].name == name) return k;
  m_entries.push_back(Entry{std::string(name)});
  return m_entries.size() - 1;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

void PhaseTimer::start(Id id) {
  Entry& e = m_entries.at(id);
  if (e.is_running) fail("phase timer: '{}' started twice", e.name);
  e.is_running = true;
  e.started = Clock::now();
  e.cpu_started = thread_cpu_seconds();
}

void PhaseTimer::stop(Id id) {
  auto now = Clock::now();
  Entry& e = m_entries.at(id);
  if (!e.is_running) fail("phase timer: '{}' stopped but not running", e.name);
  e.is_running = false;
  e.seconds += std::chrono::duration<double>(now - e.started).count();
  e.cpu_seconds += thread_cpu_seconds() - e.cpu_started;
  ++e.calls;
}

const PhaseTimer::Entry* PhaseTimer::find(std::string_view name) const {
  for (const Entry& e : m_entries)
    if (e.name == name) return &e;
  return nullptr;
}

double PhaseTimer::seconds(std::string_view name) const {
  const Entry* e = find(name);
  return e ? e->seconds : 0.0;
}

long PhaseTimer::calls(std::string_view name) const {
  const Entry* e = find(name);
  return e ? e->calls : 0;
}

double PhaseTimer::total_seconds() const {
  double sum = 0.0;
  for (const Entry& e : m_entries) sum += e.seconds;
  return sum;
}

std::vector<std::string> PhaseTimer::names() const {
  std::vector<std::string> out;
  for (const Entry& e : m_entries) out.push_back(e.name);
  return out;
}

nlohmann::ordered_json PhaseTimer::to_json() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const Entry& e : m_entries)
    j[e.name] = {{"seconds", e.seconds},
                 {"calls", e.calls},
                 {"seconds_per_call", e.calls > 0 ? e.seconds / double(e.calls) : 0.0},
                 {"cpu_seconds", e.cpu_seconds},
                 {"cpu_seconds_per_call", e.calls > 0 ? e.cpu_seconds / double(e.calls) : 0.0}};
  return j;
}

// ---- Summary ----

Summary::Summary(std::string_view scene_name) {
  m_doc["scene"] = std::string(scene_name);
  m_doc["steps"] = 0;
  m_doc["processes"] = nlohmann::ordered_json::object();
  m_doc["metrics"] = nlohmann::ordered_json::object();
}

Summary Summary::from_json(nlohmann::ordered_json document) {
  if (!document.is_object()) throw Error("summary: the document is not a JSON object");
  Summary s("");
  s.m_doc = std::move(document);
  if (!s.m_doc.contains("processes")) s.m_doc["processes"] = nlohmann::ordered_json::object();
  if (!s.m_doc.contains("metrics")) s.m_doc["metrics"] = nlohmann::ordered_json::object();
  return s;
}

void Summary::set_steps(long steps) { m_doc["steps"] = steps; }

void Summary::set_process(std::string_view role, double wall_seconds, const PhaseTimer& phases, long steps) {
  nlohmann::ordered_json p;
  p["wall_time"] = wall_seconds;
  if (steps >= 0) p["steps"] = steps;
  p["phases"] = phases.to_json();
  m_doc["processes"][std::string(role)] = std::move(p);
}

void Summary::add_metric(std::string_view name, const Metric& metric) {
  m_doc["metrics"][std::string(name)] = metric;
}

Metric Summary::metric(std::string_view name) const {
  const auto& metrics = m_doc.at("metrics");
  auto it = metrics.find(std::string(name));
  if (it == metrics.end()) fail("summary: no metric '{}'", name);
  return it->get<Metric>();
}

bool Summary::pass() const {
  const auto& metrics = m_doc.at("metrics");
  if (metrics.empty()) return false;
  for (const auto& m : metrics)
    if (!m.at("pass").get<bool>()) return false;
  return true;
}

void Summary::merge(const Summary& other) {
  for (const auto& [key, value] : other.m_doc.items()) {
    if (key == "processes" || key == "metrics") {
      for (const auto& [name, entry] : value.items()) m_doc[key][name] = entry;
    } else if (!m_doc.contains(key)) {
      m_doc[key] = value;
    }
  }
}

std::string Summary::dump() const {
  nlohmann::ordered_json doc = m_doc;
  if (doc.at("metrics").empty())
    doc.erase("pass");
  else
    doc["pass"] = pass();
  return doc.dump(2) + "\n";
}

void Summary::write(const std::filesystem::path& path) const { write_file_atomically(path, dump()); }

Summary Summary::read(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(fmt::format("cannot read {}", path.string()));
  try {
    return from_json(nlohmann::ordered_json::parse(in));
  } catch (const nlohmann::json::exception& e) {
    throw Error(fmt::format("cannot parse {}: {}", path.string(), e.what()));
  }
}

}  // namespace fsi
