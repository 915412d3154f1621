// summary.json round trip, metric pass/fail rules, merging two programs' summaries, the atomic
// write, and the phase timer's accounting.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>

#include "summary.hpp"

namespace fs = std::filesystem;
using fsi::Metric;
using fsi::PhaseTimer;
using fsi::Summary;

namespace {
fs::path fresh_dir(const std::string& name) {
  fs::path dir = fs::current_path() / "output_summary_files" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
}  // namespace

TEST_CASE("metrics: relative and absolute errors and the pass rule", "[summary]") {
  Metric drag = Metric::relative(14.5, 14.29, 0.02);
  CHECK(drag.error == Approx(0.21 / 14.29).epsilon(1e-12));
  CHECK(drag.pass);
  Metric lift = Metric::relative(1.2, 1.0, 0.1);
  CHECK(lift.error == Approx(0.2));
  CHECK_FALSE(lift.pass);
  Metric zero = Metric::relative(1e-3, 0.0, 1e-2);  // reference 0: absolute difference
  CHECK(zero.error == Approx(1e-3));
  CHECK(zero.pass);
  CHECK(Metric::absolute(-2.0, 1.0, 3.0).error == 3.0);
  CHECK(Metric::absolute(-2.0, 1.0, 3.0).pass);  // error == tolerance passes
  double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(Metric::relative(nan, 1.0, 1e9).pass);
  CHECK_FALSE(Metric::with_error(1.0, 1.0, nan, 1.0).pass);
}

TEST_CASE("summary round trip through the file", "[summary]") {
  fs::path file = fresh_dir("roundtrip") / "summary.json";
  PhaseTimer timer;
  auto predictor = timer.phase("predictor");
  timer.start(predictor);
  timer.stop(predictor);
  timer.start("poisson");
  timer.stop("poisson");
  Summary s("turek-hron-fsi2");
  s.set_steps(1200);
  s.set_process("fluid", 12.5, timer, 1200);
  s.add_metric("drag", Metric::relative(215.0, 208.83, 0.05));
  s.add_metric("lift", Metric::relative(200.0, 149.78, 0.05));
  s.json()["settings"] = {{"dt", 1e-3}};
  s.write(file);
  CHECK_FALSE(fs::exists(file.string() + ".tmp"));

  Summary back = Summary::read(file);
  CHECK(back.json().at("scene") == "turek-hron-fsi2");
  CHECK(back.json().at("steps") == 1200);
  CHECK(back.json().at("processes").at("fluid").at("wall_time") == 12.5);
  CHECK(back.json().at("processes").at("fluid").at("steps") == 1200);
  CHECK(back.json().at("processes").at("fluid").at("phases").at("predictor").at("calls") == 1);
  CHECK(back.json().at("settings").at("dt") == 1e-3);
  Metric drag = back.metric("drag");
  CHECK(drag.value == 215.0);
  CHECK(drag.reference == 208.83);
  CHECK(drag.error == s.metric("drag").error);  // shortest round-trip: bitwise equal
  CHECK(drag.pass);
  CHECK_FALSE(back.metric("lift").pass);
  CHECK(back.json().at("pass") == false);
  CHECK_FALSE(back.pass());
  CHECK_THROWS_AS(back.metric("nothing"), fsi::Error);

  // The key order is the order written: scene first, as a reader expects.
  std::ifstream in(file);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  CHECK(second.find("\"scene\"") != std::string::npos);
}

TEST_CASE("summary: pass needs every metric, and no metric is no pass", "[summary]") {
  Summary s("x");
  CHECK_FALSE(s.pass());
  CHECK(s.dump().find("\"pass\"") == std::string::npos);
  s.add_metric("a", Metric::absolute(1.0, 1.0, 0.0));
  CHECK(s.pass());
  CHECK(nlohmann::json::parse(s.dump()).at("pass") == true);
  double inf = std::numeric_limits<double>::infinity();
  s.add_metric("b", Metric::absolute(inf, 1.0, 1.0));
  CHECK_FALSE(s.pass());
  // Non-finite numbers become null in JSON and read back as NaN.
  Summary back = Summary::from_json(nlohmann::ordered_json::parse(s.dump()));
  CHECK(std::isnan(back.metric("b").value));
  CHECK_FALSE(back.metric("b").pass);
}

TEST_CASE("summaries of two programs merge", "[summary]") {
  PhaseTimer none;
  Summary fluid("case");
  fluid.set_steps(10);
  fluid.set_process("fluid", 1.0, none);
  Summary solid("case");
  solid.set_process("solid", 2.0, none);
  solid.add_metric("tip", Metric::absolute(0.1, 0.1, 1e-3));
  solid.json()["solid_only"] = 3;
  fluid.merge(solid);
  CHECK(fluid.json().at("processes").size() == 2);
  CHECK(fluid.json().at("processes").at("solid").at("wall_time") == 2.0);
  CHECK(fluid.json().at("steps") == 10);  // own keys win
  CHECK(fluid.json().at("solid_only") == 3);
  CHECK(fluid.pass());
}

TEST_CASE("reading a bad summary names the file", "[summary]") {
  fs::path dir = fresh_dir("bad");
  CHECK_THROWS_WITH(Summary::read(dir / "none.json"), Catch::Contains("none.json"));
  fsi::write_file_atomically(dir / "broken.json", "{\"scene\": ");
  CHECK_THROWS_WITH(Summary::read(dir / "broken.json"), Catch::Contains("broken.json"));
  CHECK_THROWS_WITH(fsi::write_file_atomically(dir / "no" / "dir.json", "{}"), Catch::Contains("dir.json"));
}

TEST_CASE("atomic write replaces the whole content", "[summary]") {
  fs::path file = fresh_dir("atomic") / "f.txt";
  fsi::write_file_atomically(file, "a long first content\n");
  fsi::write_file_atomically(file, "short\n");
  std::ifstream in(file);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(all == "short\n");
  CHECK(std::distance(fs::directory_iterator(file.parent_path()), fs::directory_iterator()) == 1);
}

TEST_CASE("phase timer accumulates per phase, in registration order", "[summary]") {
  PhaseTimer timer;
  auto a = timer.phase("a");
  auto b = timer.phase("b");
  CHECK(timer.phase("a") == a);
  for (int k = 0; k < 3; ++k) {
    auto scope = timer.scope(a);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  timer.start(b);
  std::this_thread::sleep_for(std::chrono::milliseconds(1));
  timer.stop(b);
  CHECK(timer.calls("a") == 3);
  CHECK(timer.calls("b") == 1);
  CHECK(timer.calls("never") == 0);
  CHECK(timer.seconds("a") >= 0.006);  // sleep_for sleeps at least as long as asked
  CHECK(timer.seconds("b") >= 0.001);
  CHECK(timer.total_seconds() == Approx(timer.seconds("a") + timer.seconds("b")));
  CHECK(timer.names() == std::vector<std::string>{"a", "b"});
  auto j = timer.to_json();
  CHECK(j.begin().key() == "a");
  CHECK(j.at("a").at("seconds_per_call").get<double>() == Approx(timer.seconds("a") / 3));
  CHECK_THROWS_AS(timer.stop(b), fsi::Error);
  timer.start(b);
  CHECK_THROWS_AS(timer.start(b), fsi::Error);
}
