// Probe CSV: the header, exact round trip of every double, flushing per row, resuming after a
// restart, and errors.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "probes.hpp"

namespace fs = std::filesystem;
using fsi::ProbeCsv;

namespace {
fs::path fresh_dir(const std::string& name) {
  fs::path dir = fs::current_path() / "output_probes_files" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}
}  // namespace

TEST_CASE("probe columns are probe-major", "[probes]") {
  CHECK(fsi::probe_columns({"A", "B"}, {"ux", "uy"}) == std::vector<std::string>{"A.ux", "A.uy", "B.ux", "B.uy"});
}

TEST_CASE("header and rows, readable while the file is open", "[probes]") {
  fs::path file = fresh_dir("rows") / "probes.csv";
  ProbeCsv csv(file, fsi::probe_columns({"A"}, {"ux", "uy"}));
  CHECK(lines_of(file) == std::vector<std::string>{"time,A.ux,A.uy"});
  csv.write(0.0, {1.0, -2.5});
  csv.write(0.1, {1e-20, 3.0});
  // Flushed: another reader sees both rows before the writer is closed.
  CHECK(lines_of(file) == std::vector<std::string>{"time,A.ux,A.uy", "0,1,-2.5", "0.1,1e-20,3"});
  CHECK(csv.rows() == 2);
  CHECK_THROWS_WITH(csv.write(0.2, {1.0}), Catch::Contains("probes.csv") && Catch::Contains("1 values for 2"));
}

TEST_CASE("every double reads back bit for bit", "[probes]") {
  fs::path file = fresh_dir("exact") / "p.csv";
  std::vector<double> values = {M_PI, -1.0 / 3.0, 1.0e-308, 4.9e-324, 1.7976931348623157e308, 0.1 + 0.2,
                                -0.0, std::numeric_limits<double>::infinity()};
  {
    std::vector<std::string> columns;
    for (std::size_t k = 0; k < values.size(); ++k) columns.push_back("P.q" + std::to_string(k));
    ProbeCsv csv(file, columns);
    for (int n = 0; n < 100; ++n) {
      std::vector<double> row = values;
      for (double& v : row) v *= std::exp(0.01 * n);
      csv.write(1e-3 * n, row);
    }
    csv.write(0.5, {std::nan(""), 0, 0, 0, 0, 0, 0, 0});
  }
  fsi::ProbeTable t = fsi::read_probe_csv(file);
  REQUIRE(t.values.size() == 101);
  REQUIRE(t.columns.size() == values.size());
  CHECK(t.columns[3] == "P.q3");
  for (int n = 0; n < 100; ++n) {
    CHECK(t.time[n] == 1e-3 * n);
    for (std::size_t k = 0; k < values.size(); ++k) CHECK(t.values[n][k] == values[k] * std::exp(0.01 * n));
  }
  CHECK(std::signbit(t.values[0][6]));
  CHECK(std::isnan(t.values[100][0]));
}

TEST_CASE("resume keeps rows up to the restart time and drops a cut row", "[probes]") {
  fs::path file = fresh_dir("resume") / "p.csv";
  {
    ProbeCsv csv(file, {"A.p"});
    for (int n = 0; n < 5; ++n) csv.write(0.1 * n, {double(n)});
  }
  {
    std::ofstream cut(file, std::ios::app);
    cut << "0.5";  // a row cut short by a crash
  }
  {
    ProbeCsv csv = ProbeCsv::resume(file, {"A.p"}, 0.25);
    CHECK(csv.rows() == 3);
    csv.write(0.3, {30.0});
  }
  CHECK(lines_of(file) == std::vector<std::string>{"time,A.p", "0,0", "0.1,1", "0.2,2", "0.3,30"});
  CHECK_THROWS_WITH(ProbeCsv::resume(file, {"B.p"}, 1.0), Catch::Contains("time,A.p") && Catch::Contains("p.csv"));
  // No earlier file: a fresh one.
  ProbeCsv fresh = ProbeCsv::resume(file.parent_path() / "new.csv", {"A.p"}, 1.0);
  CHECK(fresh.rows() == 0);
  CHECK(lines_of(file.parent_path() / "new.csv") == std::vector<std::string>{"time,A.p"});
}

TEST_CASE("bad column names and unwritable files are errors naming the file", "[probes]") {
  fs::path dir = fresh_dir("errors");
  CHECK_THROWS_WITH(ProbeCsv(dir / "a.csv", {"A,ux"}), Catch::Contains("a.csv") && Catch::Contains("'A,ux'"));
  CHECK_THROWS_AS(ProbeCsv(dir / "b.csv", {""}), fsi::Error);
  CHECK_THROWS_WITH(ProbeCsv(dir / "no" / "c.csv", {"A.p"}), Catch::Contains("c.csv"));
  {
    std::ofstream bad(dir / "d.csv");
    bad << "time,A.p\n0,1\n0.1,x\n";
  }
  CHECK_THROWS_WITH(fsi::read_probe_csv(dir / "d.csv"), Catch::Contains("d.csv:3"));
}
