// Strict scene reading: see scene.hpp. The parsed document is kept read-only; a deep copy of it
// receives the defaults that readers fill in and becomes the effective scene.
#include "scene.hpp"

#include "protocol.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <toml.hpp>

namespace fsi {

using Value = toml::basic_value<toml::discard_comments, std::map, std::vector>;

struct SceneDoc {
  std::filesystem::path file;
  std::string contents;
  Value root;
  Value effective;
  std::map<std::string, std::set<std::string>> asked;  // table path -> keys asked for
  // table path -> keys whose presence was checked (has()): read only when given, so absent
  // from the effective scene otherwise; not "asked" (a check alone does not make a key known).
  std::map<std::string, std::set<std::string>> checked;
};

namespace {

const Value& as_value(const void* p) { return *static_cast<const Value*>(p); }

std::string type_name(const Value& v) {
  switch (v.type()) {
    case toml::value_t::boolean: return "boolean";
    case toml::value_t::integer: return "integer";
    case toml::value_t::floating: return "float";
    case toml::value_t::string: return "string";
    case toml::value_t::array: return "array";
    case toml::value_t::table: return "table";
    default: return "date/time";
  }
}

// Short text of a value for error messages.
std::string show(const Value& v) {
  std::string s = toml::format(v, 0);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

std::string where(const SceneDoc& doc, const Value* v) {
  if (v) {
    const auto loc = v->location();
    if (loc.line() > 0 && loc.file_name() != "unknown file")
      return fmt::format("in {}:{}", doc.file.string(), loc.line());
  }
  return fmt::format("in {}", doc.file.string());
}

std::string fmt_number(double x) { return fmt::format("{}", x); }

// A double as a TOML float literal (shortest round trip, always with a '.' or exponent).
std::string toml_float(double x) {
  std::string s = fmt::format("{}", x);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

}  // namespace

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

// ---------------------------------------------------------------------------------------------
// Scene

Scene::Scene(const std::filesystem::path& file) : m_doc(std::make_shared<SceneDoc>()) {
  m_doc->file = file;
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw InputError(fmt::format("scene file '{}' does not exist", file.string()));
  if (std::filesystem::is_directory(file, ec))
    throw InputError(fmt::format("scene file '{}' is a directory, not a TOML file", file.string()));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read scene file '{}'", file.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  m_doc->contents = ss.str();
  try {
    std::istringstream is(m_doc->contents);
    m_doc->root = toml::parse<toml::discard_comments, std::map, std::vector>(is, file.string());
  } catch (const toml::syntax_error& e) {
    throw InputError(fmt::format("TOML syntax error in scene file {}:\n{}", file.string(), e.what()));
  } catch (const std::exception& e) {
    throw InputError(fmt::format("cannot parse scene file {}: {}", file.string(), e.what()));
  }
  m_doc->effective = m_doc->root;
}

SceneTable Scene::root() const { return SceneTable(m_doc, &m_doc->root, ""); }
const std::filesystem::path& Scene::file() const { return m_doc->file; }
const std::string& Scene::contents() const { return m_doc->contents; }

// The handshake's scene hash (PROTOCOL.md, start-up): 64-bit FNV-1a of the file's bytes.
std::uint64_t Scene::hash() const { return proto::fnv1a(m_doc->contents); }

std::string Scene::effective_toml() const { return toml::format(m_doc->effective); }

bool Scene::reads(const std::string& table, const std::string& key) const {
  for (const auto* record : {&m_doc->asked, &m_doc->checked}) {
    const auto it = record->find(table);
    if (it != record->end() && it->second.count(key)) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// SceneTable

SceneTable::SceneTable(std::shared_ptr<SceneDoc> doc, const void* value, std::string path)
    : m_doc(std::move(doc)), m_value(value), m_path(std::move(path)) {
  m_doc->asked[m_path];  // a table that was opened exists in the record even if no key is read
}

const std::filesystem::path& SceneTable::file() const { return m_doc->file; }

std::string SceneTable::key_path(std::string_view key) const {
  return m_path.empty() ? std::string(key) : m_path + "." + std::string(key);
}

const void* SceneTable::lookup(std::string_view key) const {
  m_doc->asked[m_path].insert(std::string(key));
  const auto& table = as_value(m_value).as_table();
  auto it = table.find(std::string(key));
  return it == table.end() ? nullptr : &it->second;
}

bool SceneTable::has(std::string_view key) const {
  m_doc->checked[m_path].insert(std::string(key));
  const auto& table = as_value(m_value).as_table();
  return table.count(std::string(key)) != 0;
}

void SceneTable::skip(std::string_view key) const { m_doc->asked[m_path].insert(std::string(key)); }

// The effective scene mirrors the document; a path "a.b[2].c" is resolved in the copy.
void SceneTable::record(std::string_view key, const std::string& toml_text) const {
  Value* node = &m_doc->effective;
  std::string path = m_path;
  std::size_t pos = 0;
  while (pos < path.size()) {
    std::size_t end = path.find('.', pos);
    if (end == std::string::npos) end = path.size();
    std::string part = path.substr(pos, end - pos);
    long index = -1;
    if (auto b = part.find('['); b != std::string::npos) {
      index = std::stol(part.substr(b + 1));
      part = part.substr(0, b);
    }
    node = &node->as_table()[part];
    if (index >= 0) node = &node->as_array().at(static_cast<std::size_t>(index));
    pos = end + 1;
  }
  auto& table = node->as_table();
  if (table.count(std::string(key))) return;  // given in the file: already there
  std::istringstream is("v = " + toml_text);
  const Value parsed = toml::parse<toml::discard_comments, std::map, std::vector>(is, "default");
  table[std::string(key)] = parsed.as_table().at("v");
}

void SceneTable::fail(std::string_view key, const std::string& message) const {
  const Value* v = static_cast<const Value*>(
      as_value(m_value).as_table().count(std::string(key))
          ? &as_value(m_value).as_table().at(std::string(key))
          : nullptr);
  throw InputError(fmt::format("{} {} ({})", key_path(key), message, where(*m_doc, v)));
}

void SceneTable::fail_table(const std::string& message) const {
  const std::string name = m_path.empty() ? "scene" : "[" + m_path + "]";
  throw InputError(fmt::format("{}: {} ({})", name, message, where(*m_doc, &as_value(m_value))));
}

void SceneTable::finish() const {
  const auto& asked = m_doc->asked[m_path];
  for (const auto& [key, value] : as_value(m_value).as_table()) {
    if (asked.count(key)) continue;
    std::string best;
    std::size_t best_d = 1000;
    for (const auto& k : asked) {
      const std::size_t d = edit_distance(key, k);
      if (d < best_d) best_d = d, best = k;
    }
    std::string hint;
    if (!best.empty() && best_d <= std::max<std::size_t>(2, key.size() / 3))
      hint = fmt::format("; did you mean '{}'?", best);
    else if (!asked.empty()) {
      std::vector<std::string> keys(asked.begin(), asked.end());
      hint = fmt::format("; known keys here: {}", fmt::join(keys, ", "));
    }
    throw InputError(
        fmt::format("unknown key '{}' ({}){}", key_path(key), where(*m_doc, &value), hint));
  }
}

void SceneTable::missing(std::string_view key, const char* what) const {
  std::string hint;
  const auto& asked = m_doc->asked[m_path];
  for (const auto& [k, v] : as_value(m_value).as_table()) {
    if (asked.count(k) && k != key) continue;
    if (edit_distance(k, key) <= std::max<std::size_t>(2, key.size() / 3)) {
      hint = fmt::format("; did you mean '{}' instead of '{}'?", key, k);
      break;
    }
  }
  const std::string name = std::string_view(what) == "table" ? "[" + key_path(key) + "]"
                                                             : "'" + key_path(key) + "'";
  fail_table(fmt::format("missing required {} {}{}", what, name, hint));
}

// --- typed accessors ---------------------------------------------------------------------------

namespace {
bool is_number(const Value& v) { return v.is_floating() || v.is_integer(); }
double to_double(const Value& v) {
  return v.is_floating() ? v.as_floating() : static_cast<double>(v.as_integer());
}
}  // namespace

double SceneTable::number(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) missing(key, "key");
  if (!is_number(*v)) fail(key, fmt::format("must be a number, got {} ({})", show(*v), type_name(*v)));
  const double x = to_double(*v);
  if (!std::isfinite(x)) fail(key, fmt::format("must be finite, got {}", show(*v)));
  return x;
}

double SceneTable::number(std::string_view key, double fallback) const {
  if (!lookup(key)) {
    record(key, toml_float(fallback));
    return fallback;
  }
  return number(key);
}

double SceneTable::positive(std::string_view key) const {
  const double x = number(key);
  if (!(x > 0)) fail(key, fmt::format("must be > 0, got {}", fmt_number(x)));
  return x;
}
double SceneTable::positive(std::string_view key, double fallback) const {
  return has(key) ? positive(key) : number(key, fallback);
}
double SceneTable::non_negative(std::string_view key) const {
  const double x = number(key);
  if (!(x >= 0)) fail(key, fmt::format("must be >= 0, got {}", fmt_number(x)));
  return x;
}
double SceneTable::non_negative(std::string_view key, double fallback) const {
  return has(key) ? non_negative(key) : number(key, fallback);
}

double SceneTable::in_range(std::string_view key, double lo, double hi, bool open,
                            std::optional<double> fallback) const {
  if (!has(key) && fallback) return number(key, *fallback);
  const double x = number(key);
  const bool ok = open ? (x > lo && x < hi) : (x >= lo && x <= hi);
  if (!ok)
    fail(key, fmt::format("must be in {}{}, {}{}, got {}", open ? "(" : "[", fmt_number(lo),
                          fmt_number(hi), open ? ")" : "]", fmt_number(x)));
  return x;
}

long SceneTable::integer(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) missing(key, "key");
  if (!v->is_integer())
    fail(key, fmt::format("must be an integer, got {} ({})", show(*v), type_name(*v)));
  return static_cast<long>(v->as_integer());
}
long SceneTable::integer(std::string_view key, long fallback) const {
  if (!lookup(key)) {
    record(key, fmt::format("{}", fallback));
    return fallback;
  }
  return integer(key);
}
long SceneTable::positive_integer(std::string_view key) const {
  const long n = integer(key);
  if (n < 1) fail(key, fmt::format("must be >= 1, got {}", n));
  return n;
}
long SceneTable::positive_integer(std::string_view key, long fallback) const {
  return has(key) ? positive_integer(key) : integer(key, fallback);
}

bool SceneTable::boolean(std::string_view key, bool fallback) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) {
    record(key, fallback ? "true" : "false");
    return fallback;
  }
  if (!v->is_boolean())
    fail(key, fmt::format("must be true or false, got {} ({})", show(*v), type_name(*v)));
  return v->as_boolean();
}

std::string SceneTable::string(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) missing(key, "key");
  if (!v->is_string())
    fail(key, fmt::format("must be a string, got {} ({})", show(*v), type_name(*v)));
  return v->as_string().str;
}
std::string SceneTable::string(std::string_view key, std::string_view fallback) const {
  if (!lookup(key)) {
    record(key, toml::format(Value(std::string(fallback))));
    return std::string(fallback);
  }
  return string(key);
}

std::string SceneTable::choice(std::string_view key, const std::vector<std::string>& choices,
                               std::optional<std::string> fallback) const {
  const std::string s = (!has(key) && fallback) ? string(key, *fallback) : string(key);
  if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
  std::string best;
  std::size_t best_d = 1000;
  for (const auto& c : choices)
    if (std::size_t d = edit_distance(s, c); d < best_d) best_d = d, best = c;
  const std::string hint =
      best_d <= std::max<std::size_t>(2, s.size() / 3) ? fmt::format(" (did you mean '{}'?)", best) : "";
  fail(key, fmt::format("must be one of {}, got \"{}\"{}", fmt::join(choices, ", "), s, hint));
}

std::vector<double> SceneTable::numbers(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) missing(key, "key");
  if (!v->is_array())
    fail(key, fmt::format("must be an array of numbers, got {} ({})", show(*v), type_name(*v)));
  std::vector<double> out;
  for (const auto& e : v->as_array()) {
    if (!is_number(e))
      fail(key, fmt::format("must be an array of numbers, got {} with a {} element", show(*v),
                            type_name(e)));
    out.push_back(to_double(e));
  }
  return out;
}
std::vector<double> SceneTable::numbers(std::string_view key, std::vector<double> fallback) const {
  if (!lookup(key)) {
    std::vector<std::string> items;
    for (double x : fallback) items.push_back(toml_float(x));
    record(key, fmt::format("[{}]", fmt::join(items, ", ")));
    return fallback;
  }
  return numbers(key);
}

std::vector<std::string> SceneTable::strings(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) missing(key, "key");
  if (!v->is_array())
    fail(key, fmt::format("must be an array of strings, got {} ({})", show(*v), type_name(*v)));
  std::vector<std::string> out;
  for (const auto& e : v->as_array()) {
    if (!e.is_string())
      fail(key, fmt::format("must be an array of strings, got {} with a {} element", show(*v),
                            type_name(e)));
    out.push_back(e.as_string().str);
  }
  return out;
}
std::vector<std::string> SceneTable::strings(std::string_view key,
                                             std::vector<std::string> fallback) const {
  if (!lookup(key)) {
    std::vector<std::string> items;
    for (const auto& x : fallback) items.push_back(toml::format(Value(x)));
    record(key, fmt::format("[{}]", fmt::join(items, ", ")));
    return fallback;
  }
  return strings(key);
}

std::array<double, 2> SceneTable::vec2(std::string_view key) const {
  const auto v = numbers(key);
  if (v.size() != 2) fail(key, fmt::format("must have 2 components, got {}", v.size()));
  return {v[0], v[1]};
}
std::array<double, 2> SceneTable::vec2(std::string_view key, std::array<double, 2> fallback) const {
  const auto v = numbers(key, {fallback[0], fallback[1]});
  if (v.size() != 2) fail(key, fmt::format("must have 2 components, got {}", v.size()));
  return {v[0], v[1]};
}

std::filesystem::path SceneTable::existing_file(std::string_view key) const {
  const std::string s = string(key);
  std::filesystem::path p(s);
  if (p.is_relative()) p = m_doc->file.parent_path() / p;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec))
    fail(key, fmt::format("names file '{}', which does not exist", p.string()));
  return p;
}

SceneTable SceneTable::table(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  if (!v) missing(key, "table");
  if (!v->is_table()) fail(key, fmt::format("must be a table, got {} ({})", show(*v), type_name(*v)));
  return SceneTable(m_doc, v, key_path(key));
}

std::optional<SceneTable> SceneTable::optional_table(std::string_view key) const {
  if (!has(key)) {
    lookup(key);
    return std::nullopt;
  }
  return table(key);
}

std::vector<SceneTable> SceneTable::tables(std::string_view key) const {
  const Value* v = static_cast<const Value*>(lookup(key));
  std::vector<SceneTable> out;
  if (!v) return out;
  if (!v->is_array())
    fail(key, fmt::format("must be an array of tables ([[{}]]), got {}", key_path(key), type_name(*v)));
  const auto& arr = v->as_array();
  for (std::size_t i = 0; i < arr.size(); ++i) {
    if (!arr[i].is_table())
      fail(key, fmt::format("must be an array of tables ([[{}]]), element {} is a {}", key_path(key),
                            i, type_name(arr[i])));
    out.push_back(SceneTable(m_doc, &arr[i], fmt::format("{}[{}]", key_path(key), i)));
  }
  return out;
}

namespace {

void collect_extremes(const Value& v, const std::string& path, double threshold,
                      std::vector<std::pair<double, std::string>>& out) {
  if (v.is_table()) {
    for (const auto& [k, x] : v.as_table()) collect_extremes(x, path.empty() ? k : path + "." + k, threshold, out);
  } else if (v.is_array()) {
    const auto& a = v.as_array();
    for (std::size_t i = 0; i < a.size(); ++i) {
      // Arrays of tables: body[0].material...; arrays of numbers: size[1].
      collect_extremes(a[i], fmt::format("{}[{}]", path, i), threshold, out);
    }
  } else if (v.is_floating() || v.is_integer()) {
    const double x = v.is_floating() ? v.as_floating() : static_cast<double>(v.as_integer());
    if (!std::isfinite(x) || std::abs(x) >= threshold)
      out.emplace_back(std::isfinite(x) ? std::abs(x) : HUGE_VAL, fmt::format("{} = {}", path, show(v)));
  }
}

}  // namespace

std::vector<std::string> Scene::extreme_numbers(double threshold) const {
  std::vector<std::pair<double, std::string>> found;
  collect_extremes(m_doc->root, "", threshold, found);
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> r;
  for (auto& f : found) r.push_back(std::move(f.second));
  return r;
}

double machine_memory() {
  if (const char* env = std::getenv("FSI_MEMORY_BYTES"); env && *env) return std::atof(env);
  std::ifstream in("/proc/meminfo");
  std::string name;
  double kib = 0;
  while (in >> name >> kib) {
    if (name == "MemTotal:") return kib * 1024.0;
    in.ignore(1 << 20, '\n');
  }
  return 0;
}

void check_memory(const SceneTable& t, std::string_view key, double bytes, const std::string& what) {
  const double have = machine_memory();
  if (have > 0 && !(bytes <= have))
    t.fail(key, fmt::format("asks for {}, which needs at least {:.3g} GB of memory; this machine "
                            "has {:.3g} GB (MemTotal)",
                            what, bytes / 1e9, have / 1e9));
}

}  // namespace fsi
