// The progress line: what it shows, when it prints (driven by step counts or by intervals so long
// or so short that the outcome does not depend on the machine's speed), terminal vs plain mode.
#include <catch2/catch.hpp>

#include <cstdio>
#include <string>
#include <thread>

#include "progress.hpp"

using fsi::Progress;

namespace {
// Collects what a Progress prints into a temporary file.
struct Capture {
  std::FILE* f = std::tmpfile();
  ~Capture() { std::fclose(f); }
  std::string text() {
    std::fflush(f);
    std::rewind(f);
    std::string s;
    for (int c; (c = std::fgetc(f)) != EOF;) s += char(c);
    return s;
  }
};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("durations read as a person reads them", "[progress]") {
  CHECK(fsi::format_duration(0.42) == "0.4 s");
  CHECK(fsi::format_duration(12.4) == "12 s");
  CHECK(fsi::format_duration(245) == "4m05s");
  CHECK(fsi::format_duration(7380) == "2h03m");
  CHECK(fsi::format_duration(-1) == "?");
}

TEST_CASE("a line every N steps shows step, time, dt, rate, ETA and the caller's fields", "[progress]") {
  Capture cap;
  Progress::Options o;
  o.out = cap.f;
  o.is_tty = false;
  o.every_steps = 10;
  Progress p("[fluid]", 100, 1.0, o);
  for (long n = 1; n <= 30; ++n) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // a nonzero rate
    p.update(n, 0.01 * n, 0.01, {{"CFL", 0.3125}, {"A.ux", -1.5e-3}});
  }
  p.finish(30, 0.3);
  std::string text = cap.text();
  INFO(text);
  CHECK(p.lines() == 4);
  CHECK(count(text, "\n") == 4);
  CHECK(text.find("\r") == std::string::npos);
  CHECK(text.find("[fluid] step 10/100  t 0.1/1  dt 0.01  ") == 0);
  CHECK(text.find("[fluid] step 30/100  t 0.3/1") != std::string::npos);
  CHECK(count(text, "steps/s  ETA ") == 3);
  CHECK(count(text, "CFL 0.312  A.ux -0.0015") == 3);
  CHECK(text.find("[fluid] done: step 30, t 0.3") != std::string::npos);
}

TEST_CASE("time-driven: nothing before the interval, the final line always", "[progress]") {
  Capture cap;
  Progress::Options o;
  o.out = cap.f;
  o.is_tty = false;
  o.plain_interval = 3600;  // never due within this test
  Progress p("[solid]", 0, 0.0, o);
  for (long n = 1; n <= 100000; ++n) p.update(n, 1e-3 * n, 1e-3);
  CHECK(p.lines() == 0);
  p.finish(100000, 100.0, "iterations 3");
  std::string text = cap.text();
  CHECK(p.lines() == 1);
  CHECK(text.find("[solid] done: step 100000, t 100") == 0);
  CHECK(text.find("iterations 3\n") != std::string::npos);
}

TEST_CASE("time-driven with a zero interval prints every call; extra text is built only then", "[progress]") {
  Capture cap;
  Progress::Options o;
  o.out = cap.f;
  o.is_tty = false;
  o.plain_interval = 0;
  Progress p("[fiber]", 5, 0.5, o);
  int built = 0;
  for (long n = 1; n <= 5; ++n)
    p.update(n, 0.1 * n, 0.1, [&] {
      ++built;
      return std::string("stretch 1e-06");
    });
  CHECK(built == 5);
  CHECK(count(cap.text(), "stretch 1e-06\n") == 5);

  Progress::Options quiet = o;
  quiet.plain_interval = 3600;
  Progress q("[fiber]", 5, 0.5, quiet);
  q.update(1, 0.1, 0.1, [&] {
    ++built;
    return std::string();
  });
  CHECK(built == 5);  // not due: the text was never built
}

TEST_CASE("terminal mode redraws one line and ends it at finish", "[progress]") {
  Capture cap;
  Progress::Options o;
  o.out = cap.f;
  o.is_tty = true;
  o.every_steps = 1;
  Progress p("[fluid]", 3, 0.0, o);
  p.update(1, 0.1, 0.1, {{"probe-with-a-long-name", 1.0}});
  p.update(2, 0.2, 0.1);
  p.finish(2, 0.2);
  std::string text = cap.text();
  CHECK(count(text, "\r") == 3);
  CHECK(count(text, "\n") == 1);
  CHECK(text.back() == '\n');
  // The shorter second line is padded over the first.
  std::size_t second = text.find("\r", 1), third = text.find("\r", second + 1);
  CHECK(third - second == text.find("\r", 1));
}

TEST_CASE("disabled prints nothing", "[progress]") {
  Capture cap;
  Progress::Options o;
  o.out = cap.f;
  o.is_enabled = false;
  o.every_steps = 1;
  Progress p("[coupler]", 10, 1.0, o);
  p.update(1, 0.1, 0.1);
  p.finish(1, 0.1);
  CHECK(cap.text().empty());
}
