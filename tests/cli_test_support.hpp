// What the tests of the `phiq` command (test_cli_*.cpp) share: the Cli fixture, which runs the binary in a
// directory of its own and captures its exit status and output, and the scenes and checks several of them use; and
// TestFolder, that directory with the files a test writes into it, which the import tests (test_import_*.cpp) use
// for their models, includes and resource folders.
// Not in an anonymous namespace: every file's TEST_F(Cli, ...) must derive from this one fixture class.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "scratch_path.hpp"

namespace phiq::test {

namespace fs = std::filesystem;

struct Result {
  int code;
  std::string out, err;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A directory of the test's own (phiq_SUITE_TEST in the temporary directory), empty at the start and removed at the
// end, with the files write() puts in it; environment variables set_env() sets are put back as they were.
class TestFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = scratch_path("phiq_" + std::string(info->test_suite_name()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    for (const auto& [name, old] : saved_env_)
      if (old)
        setenv(name.c_str(), old->c_str(), 1);
      else
        unsetenv(name.c_str());
    fs::remove_all(dir_);
  }
  // `text` written to the file `name` (a path relative to the directory; its folders made as needed).
  fs::path write(const std::string& name, const std::string& text) {
    fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  // The environment variable `name` set to `value` for the rest of the test.
  void set_env(const std::string& name, const std::string& value) {
    if (!saved_env_.count(name)) {
      const char* old = std::getenv(name.c_str());
      saved_env_[name] = old ? std::optional<std::string>(old) : std::nullopt;
    }
    setenv(name.c_str(), value.c_str(), 1);
  }
  fs::path dir_;

 private:
  std::map<std::string, std::optional<std::string>> saved_env_;
};

class Cli : public TestFolder {
 protected:
  Result run(const std::string& args) { return run_prefixed("", args); }
  Result run_prefixed(const std::string& prefix, const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = prefix + std::string(PHIQ_CLI) + " " + args + " >" + out.string() + " 2>" + err.string();
    const int st = std::system(cmd.c_str());
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(out), slurp(err)};
  }
  // The directory holds nothing but the named files (no partial or temporary output).
  std::vector<std::string> files() const {
    std::vector<std::string> v;
    for (auto& e : fs::directory_iterator(dir_)) v.push_back(e.path().filename().string());
    std::sort(v.begin(), v.end());
    return v;
  }
};

// How many times `what` occurs in `s` (an SVG's or a page's elements, counted by their text).
// Every match of group 1 of `re` in `s` (an SVG's data-column attributes, say).
inline std::vector<std::string> captures(const std::string& s, const std::string& re) {
  std::vector<std::string> v;
  const std::regex r(re);
  for (auto it = std::sregex_iterator(s.begin(), s.end(), r); it != std::sregex_iterator(); ++it) v.push_back((*it)[1]);
  return v;
}

inline std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

// The result CSV `csv` with xA, the second field of its second data row, made NaN (the natural four-bar's results,
// whose columns start t, xA).
inline std::string with_nan_xA(std::string csv) {
  const std::size_t line = csv.find('\n', csv.find('\n') + 1) + 1;  // the second data row
  const std::size_t comma = csv.find(',', line);                    // its second field
  EXPECT_EQ(csv.substr(0, 5), "t,xA,");
  csv.replace(comma + 1, csv.find(',', comma + 1) - comma - 1, "nan");
  return csv;
}

// One line on stderr, "phiq: " first.
inline ::testing::AssertionResult one_phiq_line(const std::string& err) {
  if (std::count(err.begin(), err.end(), '\n') == 1 && err.rfind("phiq: ", 0) == 0)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "not one 'phiq: ' line: " << err;
}

// The four-bar of models/seed/fourbar_mixed.yaml with every kind of output: two points (B, natural; P on the
// coupler body), the driver, residuals and rcond.
inline constexpr const char* kFourbarOutputs = R"(phiq: 1
name: fourbar_outputs
parameters: {L1: 1.0, L2: 0.4, L3: 1.2, L4: 1.0}
coordinates: {theta2: 0.0, xA: 0.4, yA: 0.0, x3: 0.7, y3: 0.5, psi3: 1.0, xB: 1.1, yB: 1.0}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [L1, 0]}
bodies: {coupler: [x3, y3, psi3]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: A, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: B, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 2*pi, steps: 72}
output:
  velocities: true
  points: [B, {name: P, body: coupler, at: [0, 0.3]}]
  drivers: [motor]
  residuals: [rocker]
  max_residual: true
  rcond: true
)";

}  // namespace phiq::test
