// Probe CSV writer and reader.
#include "probes.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace fsi {

namespace {

std::vector<std::string> split_commas(const std::string& line) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    std::size_t comma = line.find(',', start);
    parts.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return parts;
}

std::string strip_cr(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

double parse_number(const std::string& text, const std::filesystem::path& path, long line) {
  errno = 0;
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size())
    throw Error(fmt::format("{}:{}: '{}' is not a number", path.string(), line, text));
  return v;
}

}  // namespace

std::vector<std::string> probe_columns(const std::vector<std::string>& probes,
                                       const std::vector<std::string>& quantities) {
  std::vector<std::string> columns;
  for (const auto& p : probes)
    for (const auto& q : quantities) columns.push_back(p + "." + q);
  return columns;
}

ProbeCsv::ProbeCsv(const std::filesystem::path& path, std::vector<std::string> columns, bool)
    : m_path(path), m_columns(std::move(columns)) {
  for (const auto& c : m_columns)
    if (c.empty() || c.find_first_of(",\"\r\n") != std::string::npos)
      throw Error(fmt::format("probe file {}: bad column name '{}' (empty, or holds a comma, quote "
                              "or line break)", m_path.string(), c));
}

std::string ProbeCsv::header() const {
  std::string h = "time";
  for (const auto& c : m_columns) {
    h += ',';
    h += c;
  }
  return h;
}

ProbeCsv::ProbeCsv(const std::filesystem::path& path, std::vector<std::string> columns)
    : ProbeCsv(path, std::move(columns), true) {
  m_file.reset(std::fopen(m_path.c_str(), "w"));
  if (!m_file) throw Error(fmt::format("cannot create probe file {}: {}", m_path.string(), std::strerror(errno)));
  std::string h = header() + "\n";
  if (std::fputs(h.c_str(), m_file.get()) < 0 || std::fflush(m_file.get()) != 0)
    throw Error(fmt::format("cannot write probe file {}", m_path.string()));
}

ProbeCsv ProbeCsv::resume(const std::filesystem::path& path, std::vector<std::string> columns,
                          double t_last) {
  if (!std::filesystem::exists(path)) return ProbeCsv(path, std::move(columns));
  ProbeCsv csv(path, std::move(columns), true);
  std::string kept;
  {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    if (strip_cr(line) != csv.header())
      throw Error(fmt::format("cannot resume probe file {}: its header '{}' differs from '{}' "
                              "(a build with other columns wrote it): resume with that build, "
                              "or run the scene again",
                              path.string(), strip_cr(line), csv.header()));
    kept = csv.header() + "\n";
    long number = 1;
    while (std::getline(in, line)) {
      ++number;
      line = strip_cr(line);
      if (line.empty()) continue;
      // A last row cut short by a crash has fewer fields: drop it with the rows after t_last.
      if (split_commas(line).size() != csv.m_columns.size() + 1) continue;
      if (parse_number(line.substr(0, line.find(',')), path, number) > t_last) continue;
      kept += line + "\n";
      ++csv.m_rows;
    }
  }
  csv.m_file.reset(std::fopen(path.c_str(), "w"));
  if (!csv.m_file) throw Error(fmt::format("cannot rewrite probe file {}: {}", path.string(), std::strerror(errno)));
  if (std::fputs(kept.c_str(), csv.m_file.get()) < 0 || std::fflush(csv.m_file.get()) != 0)
    throw Error(fmt::format("cannot write probe file {}", path.string()));
  return csv;
}

void ProbeCsv::write(double time, std::span<const double> values) {
  if (values.size() != m_columns.size())
    throw Error(fmt::format("probe file {}: {} values for {} columns", m_path.string(), values.size(),
                            m_columns.size()));
  m_line.clear();
  // "{}" is the shortest representation that reads back to the same double.
  fmt::format_to(std::back_inserter(m_line), "{}", time);
  for (double v : values) fmt::format_to(std::back_inserter(m_line), ",{}", v);
  m_line.push_back('\n');
  if (std::fwrite(m_line.data(), 1, m_line.size(), m_file.get()) != m_line.size() ||
      std::fflush(m_file.get()) != 0)
    throw Error(fmt::format("cannot write probe file {} (disk full?)", m_path.string()));
  ++m_rows;
}

ProbeTable read_probe_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(fmt::format("cannot read probe file {}", path.string()));
  ProbeTable table;
  std::string line;
  if (!std::getline(in, line)) throw Error(fmt::format("probe file {} is empty", path.string()));
  std::vector<std::string> header = split_commas(strip_cr(line));
  if (header.empty() || header[0] != "time")
    throw Error(fmt::format("probe file {}: the header must start with 'time', got '{}'", path.string(), line));
  table.columns.assign(header.begin() + 1, header.end());
  long number = 1;
  while (std::getline(in, line)) {
    ++number;
    line = strip_cr(line);
    if (line.empty()) continue;
    std::vector<std::string> fields = split_commas(line);
    if (fields.size() != header.size())
      throw Error(fmt::format("{}:{}: {} fields, the header has {}", path.string(), number, fields.size(),
                              header.size()));
    table.time.push_back(parse_number(fields[0], path, number));
    std::vector<double> row;
    for (std::size_t k = 1; k < fields.size(); ++k) row.push_back(parse_number(fields[k], path, number));
    table.values.push_back(std::move(row));
  }
  return table;
}

}  // namespace fsi
