// Strict scene reading (TOML through toml11). A SceneTable is a view on one table of the scene
// file that records every key it is asked for: finish() then reports any key nobody asked for
// as unknown, with a "did you mean" among the keys that were asked for. Every accessor checks
// type and range and throws fsi::InputError naming the key path, the value and file:line.
// Values read (with defaults filled in) are recorded into the effective scene.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "error.hpp"

namespace fsi {

struct SceneDoc;  // parsed file plus the effective-scene record (scene.cpp)

class SceneTable {
 public:
  // Numbers (TOML integers are accepted where a float is asked for).
  double number(std::string_view key) const;
  double number(std::string_view key, double fallback) const;
  double positive(std::string_view key) const;                  // > 0
  double positive(std::string_view key, double fallback) const;
  double non_negative(std::string_view key) const;              // >= 0
  double non_negative(std::string_view key, double fallback) const;
  // lo < value < hi when open, lo <= value <= hi otherwise.
  double in_range(std::string_view key, double lo, double hi, bool open,
                  std::optional<double> fallback = std::nullopt) const;
  long integer(std::string_view key) const;
  long integer(std::string_view key, long fallback) const;
  long positive_integer(std::string_view key) const;           // >= 1
  long positive_integer(std::string_view key, long fallback) const;
  bool boolean(std::string_view key, bool fallback) const;
  std::string string(std::string_view key) const;
  std::string string(std::string_view key, std::string_view fallback) const;
  // One of `choices`; the error lists them.
  std::string choice(std::string_view key, const std::vector<std::string>& choices,
                     std::optional<std::string> fallback = std::nullopt) const;
  std::array<double, 2> vec2(std::string_view key) const;
  std::array<double, 2> vec2(std::string_view key, std::array<double, 2> fallback) const;
  std::vector<double> numbers(std::string_view key) const;
  std::vector<double> numbers(std::string_view key, std::vector<double> fallback) const;
  std::vector<std::string> strings(std::string_view key) const;
  std::vector<std::string> strings(std::string_view key, std::vector<std::string> fallback) const;
  // A file path relative to the scene file's folder; it must exist.
  std::filesystem::path existing_file(std::string_view key) const;

  bool has(std::string_view key) const;
  SceneTable table(std::string_view key) const;                  // required sub-table
  std::optional<SceneTable> optional_table(std::string_view key) const;
  // An array of tables ([[key]]); empty when absent.
  std::vector<SceneTable> tables(std::string_view key) const;

  // Error about this table's `key` (its current value and location are added).
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;
  // Error about the table itself.
  [[noreturn]] void fail_table(const std::string& message) const;
  // Unknown-key check: call once every key of this table has been read.
  void finish() const;
  // Mark `key` as known without reading it (a section another program reads).
  void skip(std::string_view key) const;

  const std::string& path() const { return m_path; }  // "fluid.bc", "" for the root
  const std::filesystem::path& file() const;

 private:
  friend class Scene;
  SceneTable(std::shared_ptr<SceneDoc> doc, const void* value, std::string path);
  const void* lookup(std::string_view key) const;  // toml value or nullptr; marks key as asked
  std::string key_path(std::string_view key) const;
  [[noreturn]] void missing(std::string_view key, const char* what) const;
  void record(std::string_view key, const std::string& toml_text) const;

  std::shared_ptr<SceneDoc> m_doc;
  const void* m_value;  // const toml::value*
  std::string m_path;
};

// A whole scene file. Construction parses it (missing file, syntax errors: InputError).
class Scene {
 public:
  explicit Scene(const std::filesystem::path& file);
  SceneTable root() const;
  const std::filesystem::path& file() const;
  const std::string& contents() const;   // raw bytes, for the identity check
  std::uint64_t hash() const;            // FNV-1a of the contents
  // The effective scene: every key read so far, with defaults filled in, as TOML text.
  std::string effective_toml() const;
  // Whether this program asked for `key` of the table at `table` ("" the top, "a.b[2]"), or
  // checked whether it is given (a key read only when given).
  bool reads(const std::string& table, const std::string& key) const;
  // Every number of the scene with |value| >= `threshold` (or not finite), as "key = value",
  // largest first: what a health check names as the likely cause of a blow-up.
  std::vector<std::string> extreme_numbers(double threshold) const;

 private:
  std::shared_ptr<SceneDoc> m_doc;
};

// The machine's memory in bytes (MemTotal of /proc/meminfo, or FSI_MEMORY_BYTES when set: a
// test's stand-in for a smaller machine); 0 when unknown.
double machine_memory();
// Before allocating what a scene asks for: fails at `key` of `t` when the estimated `bytes`
// (`what`: "2e+12 grid cells") exceed the machine's memory. Estimates are lower bounds (the
// large arrays only), so what is refused can never fit.
void check_memory(const SceneTable& t, std::string_view key, double bytes, const std::string& what);

// (runtime.cpp) For a health check that trips (CFL, singular matrix, NaN): the scene's extreme constants, the
// likelier cause than the check's own knob: "; the scene has extreme values, a likely cause:
// coupler.kappa = 1e12". Empty when the scene has none (|value| >= 1e9 or not finite) or in a
// process without a scene.
std::string extreme_constants_hint();

// Levenshtein distance, for "did you mean".
std::size_t edit_distance(std::string_view a, std::string_view b);

}  // namespace fsi
