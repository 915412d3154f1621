// Probe time series as CSV: a header `time,<probe>.<quantity>,...` (e.g. `time,A.ux,A.uy`) and
// one row per call, every number in shortest round-trip form (reads back to the same double),
// each row flushed so that a crash or a reader during the run sees every completed row.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "error.hpp"

namespace fsi {

// {"A", "B"} x {"ux", "uy"} -> {"A.ux", "A.uy", "B.ux", "B.uy"} (probe-major).
std::vector<std::string> probe_columns(const std::vector<std::string>& probes,
                                       const std::vector<std::string>& quantities);

class ProbeCsv {
 public:
  // Creates (truncates) `path` and writes the header. Column names must be non-empty and hold
  // no comma, quote or line break. Throws fsi::Error naming the file.
  ProbeCsv(const std::filesystem::path& path, std::vector<std::string> columns);

  // Restart: an existing file with the same header keeps its rows with time <= t_last and new
  // rows follow them; without a file this is the constructor above. A different header is an
  // error (the probes changed between the runs).
  static ProbeCsv resume(const std::filesystem::path& path, std::vector<std::string> columns,
                         double t_last);

  // One row: `time` and one value per column, in column order. No allocation after the first
  // call; one write and one flush.
  void write(double time, std::span<const double> values);
  void write(double time, std::initializer_list<double> values) {
    write(time, std::span<const double>(values.begin(), values.size()));
  }

  const std::vector<std::string>& columns() const { return m_columns; }
  const std::filesystem::path& path() const { return m_path; }
  long rows() const { return m_rows; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  ProbeCsv(const std::filesystem::path& path, std::vector<std::string> columns, bool);
  std::string header() const;

  std::filesystem::path m_path;
  std::vector<std::string> m_columns;
  std::unique_ptr<std::FILE, Closer> m_file;
  fmt::memory_buffer m_line;
  long m_rows = 0;
};

// A probe file read back (tests, post-processing in C++): the header's column names (without
// "time") and the rows.
struct ProbeTable {
  std::vector<std::string> columns;
  std::vector<double> time;
  std::vector<std::vector<double>> values;  // values[row][column]
};
ProbeTable read_probe_csv(const std::filesystem::path& path);

}  // namespace fsi
