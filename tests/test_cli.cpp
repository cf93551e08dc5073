// The phiq command: exit status, CSV header and rows, no output file on failure, one-line errors.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>
#include <tuple>

#include "phiq/csv_compare.hpp"

#include "test_support.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int code;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("phiq_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) { return run_prefixed("", args); }
  Result run_prefixed(const std::string& prefix, const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = prefix + std::string(PHIQ_CLI) + " " + args + " >" + out.string() + " 2>" + err.string();
    const int st = std::system(cmd.c_str());
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(out), slurp(err)};
  }
  fs::path write(const std::string& name, const std::string& text) {
    fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
  // The directory holds nothing but the named files (no partial or temporary output).
  std::vector<std::string> files() const {
    std::vector<std::string> v;
    for (auto& e : fs::directory_iterator(dir_)) v.push_back(e.path().filename().string());
    std::sort(v.begin(), v.end());
    return v;
  }
  fs::path dir_;
};

TEST_F(Cli, RunWritesTheCsvWithTheDocumentedColumns) {
  const fs::path out = dir_ / "cs.csv";
  Result r = run("run " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "t,theta2,xA,yA,xB,theta2.v,xA.v,yA.v,xB.v,theta2.a,xA.a,yA.a,xB.a");
  int rows = 0;
  std::string last;
  while (std::getline(in, line)) ++rows, last = line;
  EXPECT_EQ(rows, 181);
  // last row: t = π, θ2 = 2π, x_B = L2 + L3
  std::stringstream ls(last);
  std::vector<double> v;
  for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::stod(cell));
  ASSERT_EQ(v.size(), 13u);
  EXPECT_DOUBLE_EQ(v[0], M_PI);
  EXPECT_NEAR(v[1], 2 * M_PI, 1e-12);
  EXPECT_NEAR(v[4], 1.3, 1e-10);  // the Newton tolerance (1e-10 × the rod's 1 m)
  EXPECT_NE(r.err.find("181 steps"), std::string::npos) << r.err;
  const std::string all = slurp(out);
  EXPECT_EQ(all.find(",-0,"), std::string::npos) << "negative zeros are written as 0";
  // first row at t = 0: exact zeros are written as 0, the rest to the last digit of the solution (x_B'' = -1.56
  // to rounding: velocity and acceleration reuse the last Newton factorisation, 1e-16 away from the solution)
  const std::size_t row0 = all.find('\n') + 1;
  EXPECT_EQ(all.compare(row0, 36, "0,0,0.3,0,1.3,2,0,0.6,0,0,-1.2,0,-1."), 0) << all.substr(row0, 60);
  std::stringstream first(all.substr(row0, all.find('\n', row0) - row0));
  std::vector<double> f;
  for (std::string cell; std::getline(first, cell, ',');) f.push_back(std::stod(cell));
  ASSERT_EQ(f.size(), 13u);
  EXPECT_NEAR(f[12], -1.56, 1e-12);
}

// phiq batch: one CSV per case, each the closed form of its own crank length; a case that cannot run writes
// nothing and makes the exit status 1, without stopping the others.
TEST_F(Cli, BatchSweepsEveryParameterSetInParallel) {
  const fs::path cases = write("cases.csv", "L2,L3\n0.2,1.0\n0.3,1.0\n0.4,1.2\n1.5,1.0\n");
  const fs::path out = dir_ / "out";
  Result r = run("batch " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " + cases.string() + " -o " +
                 out.string() + " --threads 2");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("case 3: step "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3 of 4 cases"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4 cases on one symbolic analysis"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "case3.csv"));
  const double l2[] = {0.2, 0.3, 0.4}, l3[] = {1.0, 1.0, 1.2};
  for (int k = 0; k < 3; ++k) {
    const phiq::CsvTable t = phiq::read_csv_table((out / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.rows.size(), 181u);
    ASSERT_EQ(t.columns[1], "theta2");
    ASSERT_EQ(t.columns[4], "xB");
    double worst = 0;
    for (const auto& row : t.rows) {
      const double th = row[1], s = std::sin(th);
      worst = std::max(worst, std::fabs(row[4] - (l2[k] * std::cos(th) + std::sqrt(l3[k] * l3[k] - l2[k] * l2[k] * s * s))));
    }
    EXPECT_LT(worst, 1e-9) << "case " << k;
  }
  // a column that is not a parameter of the scene: one line naming it and the case, nothing written
  const fs::path bad = write("bad.csv", "L2,L9\n0.2,1\n");
  r = run("batch " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " + bad.string() + " -o " +
          (dir_ / "bad").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("'L9' (given for this run) is not a parameter of the scene (case 0 of"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

// phiq batch holds no descriptor per case between writes: 150 cases under a limit of 64 open files all run, each
// ending at its own closed form (θ2 = 2π: x_B = L2 + L3).
TEST_F(Cli, BatchRunsMoreCasesThanTheOpenFileLimit) {
  std::string text = "L2\n";
  const int cases = 150;
  for (int k = 0; k < cases; ++k) text += std::to_string(0.2 + 0.001 * k) + "\n";
  const fs::path list = write("cases.csv", text);
  const fs::path out = dir_ / "out";
  Result r = run_prefixed("ulimit -n 64; ", "batch -q " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " " +
                                                list.string() + " -o " + out.string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  int files = 0;
  for (auto& e : fs::directory_iterator(out)) files += e.path().extension() == ".csv";
  EXPECT_EQ(files, cases) << "no temporaries left beside the case files";
  for (int k = 0; k < cases; ++k) {
    const phiq::CsvTable t = phiq::read_csv_table((out / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.rows.size(), 181u) << k;
    EXPECT_NEAR(t.rows.back()[4], 0.2 + 0.001 * k + 1.0, 1e-9) << k;
  }
}

// phiq batch on a redundant scene: each case is assembled and swept on its independent rows, as `phiq run` does
// (the door on three hinges, the third hinge's ground point moved by a parameter): on the axis, or 1e-12 off it,
// the door turns about z as driven; 1 cm off, the hinges cannot all hold and that case alone fails, naming hinge3.
TEST_F(Cli, BatchSweepsRedundantScenesOnTheirIndependentRows) {
  std::string text = slurp(phiq::test::model_path("redundant/door_three_hinges.yaml"));
  text.replace(text.find("dimension: 3"), 12, "dimension: 3\nparameters: {off: 0}");
  text.replace(text.find("at: [0, 0, 2]}, {body: door"), 13, "at: [off, 0, 2]");
  const fs::path scene = write("door.yaml", text);
  const fs::path cases = write("cases.csv", "off\n0\n1e-12\n0.01\n");
  const fs::path out = dir_ / "out";
  Result r = run("batch " + scene.string() + " " + cases.string() + " -o " + out.string() + " --threads 2");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("case 2: t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("hinge3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("2 of 3 cases"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "case2.csv"));
  for (int k = 0; k < 2; ++k) {
    const phiq::CsvTable t = phiq::read_csv_table((out / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.rows.size(), 31u);
    ASSERT_EQ(t.columns[4], "door_e0");
    ASSERT_EQ(t.columns[7], "door_e3");
    double worst = 0;
    for (const auto& row : t.rows)  // a turn by t about z: e0 = cos(t/2), e3 = sin(t/2)
      worst = std::max({worst, std::fabs(row[4] - std::cos(row[0] / 2)), std::fabs(row[7] - std::sin(row[0] / 2))});
    EXPECT_LT(worst, 1e-9) << "case " << k;
  }
}

TEST_F(Cli, RunWithoutOutputFileWritesToStandardOutput) {
  Result r = run("run -q " + phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("t,theta2,xA,yA,xB,", 0), 0u);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 182);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(Cli, BadSceneExitsNonZeroWithOneLineAndNoFile) {
  fs::path scene = write("bad.yaml", "coordinates: {x: 0}\ntime: {start: 0, end: 1, steps: 2}\nbogus: 1\n");
  Result r = run("run " + scene.string() + " -o " + (dir_ / "out.csv").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("bad.yaml:3:1: bogus: unknown field 'bogus'"), std::string::npos) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"bad.yaml", "stderr.txt", "stdout.txt"}));
}

TEST_F(Cli, UnreachableDriveRangeFailsWithoutTouchingAnExistingFile) {
  // The crank-slider driven by its slider beyond L2 + L3: no assembly past x_B = 1.3.
  fs::path scene = write("reach.yaml", R"(coordinates: {theta2: 0.5, xA: 0.26, yA: 0.14, xB: 1.2}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: 0.3, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: 1.0}
drivers:
  - {name: slide, coordinate: xB, law: {type: linear, initial: 1.2, rate: 0.2}}
time: {start: 0, end: 1, steps: 10}
)");
  const fs::path out = dir_ / "keep.csv";
  write("keep.csv", "previous good result\n");
  Result r = run("run " + scene.string() + " -o " + out.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  // x_B = 1.3 at t = 0.5 is the dead point, still assembled (slowly: a double root); t = 0.6 is beyond reach
  EXPECT_NE(r.err.find("step 6, t = 0.6: no assembly beyond t = 0.5"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no output written"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(out), "previous good result\n");
  EXPECT_EQ(files(), (std::vector<std::string>{"keep.csv", "reach.yaml", "stderr.txt", "stdout.txt"}));
}

TEST_F(Cli, CheckReportsCountsAndAssembly) {
  Result r = run("check " + phiq::test::model_path("seed/fourbar_reference_point.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("coordinates   9"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("equations     9 (8 kinematic, 1 rheonomic)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("assembly      success"), std::string::npos) << r.out;
}

TEST_F(Cli, CheckJsonIsOneVersionedObject) {
  Result r = run("check --json " + phiq::test::model_path("seed/fourbar_natural.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  // key order and values, without a JSON library in the test: the format is documented line by line
  for (const char* part : {"\"format\": 1", "\"coordinates\": 5", "\"equations\": 5", "\"kinematic_equations\": 4",
                           "\"driver_equations\": 1", "\"status\": \"success\"", "\"worst\": []"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_EQ(r.out.front(), '{');
  EXPECT_EQ(r.out.substr(r.out.size() - 2), "}\n");
}

TEST_F(Cli, CheckJsonNamesTheWorstConstraintsWhenAssemblyFails) {
  // a coupler too short to close the loop: no assembly exists
  std::string scene = slurp(phiq::test::model_path("seed/fourbar_natural.yaml"));
  scene.replace(scene.find("L3: 1.2"), 7, "L3: 0.1");
  fs::path p = write("open.yaml", scene);
  Result r = run("check --json " + p.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("\"status\": \"not converged\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"constraint\": \""), std::string::npos) << r.out;
}

TEST_F(Cli, InterruptStopsCleanlyWithoutOutput) {
  // a sweep of 10^7 steps runs for minutes; SIGINT after half a second
  std::string scene = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  scene.replace(scene.find("steps: 180"), 10, "steps: 10000000");
  fs::path p = write("long.yaml", scene);
  const auto t0 = std::chrono::steady_clock::now();
  Result r = run_prefixed("timeout --preserve-status -s INT 0.5 ", "run " + p.string() + " -o " + (dir_ / "out.csv").string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.code, 130) << r.err;
  EXPECT_LT(seconds, 5.0);
  EXPECT_NE(r.err.find("interrupted (SIGINT); no output written"), std::string::npos) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"long.yaml", "stderr.txt", "stdout.txt"}));
}

TEST_F(Cli, CompareExitStatusAndWorstCell) {
  const std::string ref = phiq::test::model_path("seed/reference/crank_slider_mixed.csv");
  const fs::path out = dir_ / "cs.csv";
  ASSERT_EQ(run("run -q " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " -o " + out.string()).code, 0);
  Result same = run("compare " + ref + " " + out.string());
  EXPECT_EQ(same.code, 0) << same.err;
  // perturb one acceleration cell by 1e-6 relative
  std::string text = slurp(out);
  const std::size_t row = text.find("\n0.5061454830783556,");
  ASSERT_NE(row, std::string::npos);
  const std::size_t last = text.find('\n', row + 1), comma = text.rfind(',', last);
  const double v = std::stod(text.substr(comma + 1, last - comma - 1));
  std::ostringstream nv;
  nv.precision(17);
  nv << v * (1 + 1e-6);
  text.replace(comma + 1, last - comma - 1, nv.str());
  fs::path bad = write("bad.csv", text);
  Result diff = run("compare " + ref + " " + bad.string());
  EXPECT_EQ(diff.code, 1);
  EXPECT_NE(diff.err.find("xB.a"), std::string::npos) << diff.err;
  EXPECT_NE(diff.err.find("0.5061454830783556"), std::string::npos) << diff.err;  // the time of the worst row
  EXPECT_EQ(run("compare --rtol 1e-5 " + ref + " " + bad.string()).code, 0);
  EXPECT_EQ(run("compare " + ref + " /nonexistent.csv").code, 2);
  Result missing = run("compare --columns t,nope " + ref + " " + out.string());
  EXPECT_EQ(missing.code, 2);
  // one line naming the command and the option, as every command-line error does
  EXPECT_EQ(missing.err, "phiq: compare: --columns: column 'nope' is not in " + ref + "\n");
}

// Reads a CSV written by phiq into columns by name.
std::map<std::string, std::vector<double>> columns_of(const std::string& text) {
  std::stringstream in(text);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) names.push_back(c);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::size_t k = 0;
    for (std::string c; std::getline(ls, c, ','); ++k) cols[names.at(k)].push_back(std::stod(c));
  }
  return cols;
}

TEST_F(Cli, GeneratedNFourBarStaysOnTheParallelogramBranch) {
  // N = 6 four-bars over the default quarter turn: every crank stays parallel to crank 0 at θ(t) = π/4 + π/2 t
  for (const char* coords : {"natural", "reference-point"}) {
    const fs::path scene = dir_ / (std::string(coords) + ".yaml"), out = dir_ / (std::string(coords) + ".csv");
    ASSERT_EQ(run(std::string("generate nfourbar 6 --steps 40 --coords ") + coords + " -o " + scene.string()).code, 0);
    Result r = run("run -q " + scene.string() + " -o " + out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    auto c = columns_of(slurp(out));
    ASSERT_EQ(c["t"].size(), 41u) << coords;
    double worst = 0.0;
    for (std::size_t k = 0; k < c["t"].size(); ++k) {
      const double th = M_PI / 4 + M_PI / 2 * c["t"][k];
      for (int i = 0; i <= 6; ++i) {
        const std::string n = std::to_string(i);
        if (std::string(coords) == "natural") {
          worst = std::max(worst, std::fabs(c["x" + n][k] - (i + std::cos(th))));
          worst = std::max(worst, std::fabs(c["y" + n][k] - std::sin(th)));
        } else {
          worst = std::max(worst, std::fabs(c["psi" + n][k] - th));
          worst = std::max(worst, std::fabs(c["xc" + n][k] - (i + 0.5 * std::cos(th))));
        }
      }
    }
    EXPECT_LT(worst, 1e-9) << coords;
  }
}

// The nfourbar scenes as `phiq generate` wrote them before families: every coordinate, point, body and
// constraint listed one by one (the generator's former code, kept here as the reference of the compact form).
std::string shortest(double v) {
  if (v == 0.0) v = 0.0;
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, p);
}
std::string explicit_nfourbar(std::int64_t n, const std::string& coords, double from, double to) {
  const double c = std::cos(from), sn = std::sin(from);
  std::string s = "phiq: 1\n";
  if (coords == "natural") {
    s += "coordinates:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      s += "  x" + std::to_string(i) + ": " + shortest(static_cast<double>(i) + c) + "\n";
      s += "  y" + std::to_string(i) + ": " + shortest(sn) + "\n";
    }
    s += "  theta: " + shortest(from) + "\n";
    s += "points:\n  O: [0, 0]\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  P" + k + ": [x" + k + ", y" + k + "]\n";
    }
    s += "constraints:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  - {name: crank" + k + ", type: distance, points: [[" + k + ", 0], P" + k + "], length: 1}\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i), k1 = std::to_string(i + 1);
      s += "  - {name: coupler" + k + ", type: distance, points: [P" + k + ", P" + k1 + "], length: 1}\n";
    }
    s += "  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n";
  } else {
    s += "coordinates:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  xc" + k + ": " + shortest(static_cast<double>(i) + 0.5 * c) + "\n  yc" + k + ": " + shortest(0.5 * sn) +
           "\n  psi" + k + ": " + shortest(from) + "\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i);
      s += "  xk" + k + ": " + shortest(static_cast<double>(i) + 0.5 + c) + "\n  yk" + k + ": " + shortest(sn) +
           "\n  phi" + k + ": 0\n";
    }
    s += "bodies:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  crank" + k + ": [xc" + k + ", yc" + k + ", psi" + k + "]\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i);
      s += "  coupler" + k + ": [xk" + k + ", yk" + k + ", phi" + k + "]\n";
    }
    s += "constraints:\n";
    for (std::int64_t i = 0; i <= n; ++i) {
      const std::string k = std::to_string(i);
      s += "  - {name: pivot" + k + ", type: revolute, between: [{body: crank" + k +
           ", at: [-0.5, 0]}, {body: ground, at: [" + k + ", 0]}]}\n";
    }
    for (std::int64_t i = 0; i < n; ++i) {
      const std::string k = std::to_string(i), k1 = std::to_string(i + 1);
      s += "  - {name: left" + k + ", type: revolute, between: [{body: crank" + k + ", at: [0.5, 0]}, {body: coupler" +
           k + ", at: [-0.5, 0]}]}\n";
      s += "  - {name: right" + k + ", type: revolute, between: [{body: crank" + k1 +
           ", at: [0.5, 0]}, {body: coupler" + k + ", at: [0.5, 0]}]}\n";
    }
  }
  const std::string driven = coords == "natural" ? "theta" : "psi0";
  s += "drivers:\n  - {name: motor, coordinate: " + driven + ", law: {type: linear, initial: " + shortest(from) +
       ", rate: " + shortest(to - from) + "}}\n";
  s += "time: {start: 0, end: 1, steps: 10}\n";
  return s;
}

TEST_F(Cli, GeneratedFamiliesAreTheModelListedOneByOne) {
  // the same coordinates (names, order, initial values bit for bit), constraints, pattern, Φ, Φq, Φt and γ
  for (const char* coords : {"natural", "reference-point"}) {
    for (const auto& [n, from, to] : {std::tuple<int, double, double>{3, 0.7853981633974483, 2.356194490192345},
                                      std::tuple<int, double, double>{37, 0.3, 1.1}}) {
      const fs::path p = dir_ / "compact.yaml";
      std::ostringstream args;
      args.precision(17);
      args << "generate nfourbar " << n << " --steps 10 --coords " << coords << " --from " << from << " --to " << to
           << " -o " << p.string();
      ASSERT_EQ(run(args.str()).code, 0) << args.str();
      phiq::Scene compact = phiq::load_scene(p.string());
      phiq::Scene listed = phiq::parse_scene(explicit_nfourbar(n, coords, from, to), "listed.yaml");
      SCOPED_TRACE(std::string(coords) + " N = " + std::to_string(n));
      phiq::test::expect_same_model(*compact.model, *listed.model);
      EXPECT_EQ(compact.model->time_domain_end(), listed.model->time_domain_end());
    }
  }
}

TEST_F(Cli, GeneratedSceneSizeDoesNotDependOnN) {
  for (const char* coords : {"natural", "reference-point"}) {
    const fs::path small = dir_ / "small.yaml", large = dir_ / "large.yaml";
    ASSERT_EQ(run(std::string("generate nfourbar 10 --coords ") + coords + " -o " + small.string()).code, 0);
    ASSERT_EQ(run(std::string("generate nfourbar 1000000 --coords ") + coords + " -o " + large.string()).code, 0);
    // N is written three times (comment, name, parameter), and the counts of coordinates, kinematic equations and
    // equations once each: 5 more digits each
    EXPECT_EQ(fs::file_size(large), fs::file_size(small) + 30) << coords;
    EXPECT_LT(fs::file_size(large), 4096u) << coords;
  }
}

TEST_F(Cli, SummaryJsonCountsWhatWasComputed) {
  const fs::path scene = dir_ / "p.yaml", sum = dir_ / "sum.json";
  ASSERT_EQ(run("generate nfourbar 3 --steps 10 --outputs q -o " + scene.string()).code, 0);
  Result r = run("run -q " + scene.string() + " -o " + (dir_ / "p.csv").string() + " --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string j = slurp(sum);
  for (const char* part : {"\"steps\": 11", "\"threads\": 1", "\"velocity_solves\": 0", "\"acceleration_solves\": 0",
                           "\"gamma_evaluations\": 0", "\"phi_t_evaluations\": 0", "\"load_seconds\": ",
                           "\"solve_seconds\": ", "\"write_seconds\": ", "\"linear_solver\": \"klu\"", "\"warnings\": []",
                           "\"min_rcond\": null"})
    EXPECT_NE(j.find(part), std::string::npos) << part << "\n" << j;
  // the sweep's wall time holds the solve and the writing done in the sweep (the final flush comes after it)
  auto number = [&](const std::string& key) {
    const std::size_t at = j.find("\"" + key + "\": ");
    return at == std::string::npos ? -1.0 : std::strtod(j.c_str() + at + key.size() + 4, nullptr);
  };
  EXPECT_GT(number("sweep_seconds"), 0.0) << j;
  EXPECT_GE(number("sweep_seconds"), number("solve_seconds")) << j;
  EXPECT_GE(number("solve_seconds"), 0.0) << j;
  // with velocities and accelerations: one of each per row
  ASSERT_EQ(run("generate nfourbar 3 --steps 10 -o " + scene.string()).code, 0);
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + (dir_ / "p.csv").string() + " --summary " + sum.string()).code, 0);
  const std::string j2 = slurp(sum);
  EXPECT_NE(j2.find("\"velocity_solves\": 11"), std::string::npos) << j2;
  EXPECT_NE(j2.find("\"acceleration_solves\": 11"), std::string::npos) << j2;
  EXPECT_EQ(j2.find("\"min_rcond\": null"), std::string::npos) << "measured at every row's solution\n" << j2;
}

// --memory: with all cores (--threads 0, the default) and no room for a second thread's workspace, the run goes
// in order and says why; the rows are the same.
TEST_F(Cli, MemoryBudgetFitsTheThreads) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one core: all cores is one thread anyway";
  const fs::path scene = dir_ / "m.yaml", sum = dir_ / "m.json", a = dir_ / "a.csv", b = dir_ / "b.csv";
  ASSERT_EQ(run("generate nfourbar 50 --steps 200 -o " + scene.string()).code, 0);
  Result r = run("run " + scene.string() + " -o " + a.string() + " --memory 0.000001 --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string j = slurp(sum);
  EXPECT_NE(j.find("\"threads\": 1"), std::string::npos) << j;
  EXPECT_NE(j.find("threads_reduced"), std::string::npos) << j;
  EXPECT_NE(r.err.find("(memory_budget) leaves 0 GB beside what the run holds"), std::string::npos) << r.err;
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + b.string() + " --threads 1").code, 0);
  EXPECT_EQ(slurp(a), slurp(b));  // one thread either way: the same rows, digit for digit
  EXPECT_NE(run("run -q " + scene.string() + " --memory -1").code, 0);
}

// The four-bar of models/seed/fourbar_mixed.yaml with every kind of output: two points (B, natural; P on the
// coupler body), the driver, residuals and rcond.
const char* kFourbarOutputs = R"(phiq: 1
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

TEST_F(Cli, RunWritesTheListedOutputsAndCountsThem) {
  const fs::path scene = write("f.yaml", kFourbarOutputs), csv = dir_ / "f.csv", sum = dir_ / "sum.json";
  Result r = run("run -q --threads 1 " + scene.string() + " -o " + csv.string() + " --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const phiq::CsvTable t = phiq::read_csv_table(csv.string());
  const std::vector<std::string> tail = {"B.x", "B.y", "B.vx", "B.vy", "P.x", "P.y", "P.vx", "P.vy", "motor.f",
                                         "motor.df", "rocker.residual", "residual", "rcond"};
  ASSERT_EQ(t.columns.size(), 1 + 16 + tail.size());
  EXPECT_TRUE(std::equal(tail.begin(), tail.end(), t.columns.end() - static_cast<long>(tail.size())));
  ASSERT_EQ(t.rows.size(), 73u);
  for (const auto& row : t.rows) {
    EXPECT_EQ(row[17], row[7]);   // B.x is xB
    EXPECT_EQ(row[19], row[15]);  // B.vx is xB.v
    EXPECT_EQ(row[25], row[0]);   // motor.f = t
    EXPECT_EQ(row[26], 1.0);      // motor.df
    EXPECT_LE(row[28], 1e-10);    // residual within the tolerance
    EXPECT_GT(row[29], 0.0);      // rcond
  }
  const std::string j = slurp(sum);
  for (const char* part : {"\"steps\": 73", "\"velocity_solves\": 73", "\"phi_t_evaluations\": 73",
                           "\"acceleration_solves\": 0", "\"gamma_evaluations\": 0", "\"point_evaluations\": 146"})
    EXPECT_NE(j.find(part), std::string::npos) << part << "\n" << j;
}

// Batch cases each get their own output points: a point placed by a parameter moves with it.
TEST_F(Cli, BatchCasesWriteTheirOwnOutputPoints) {
  std::string text = kFourbarOutputs;
  text.replace(text.find("parameters: {"), 13, "parameters: {h: 0.3, ");
  text.replace(text.find("at: [0, 0.3]"), 12, "at: [0, h]");
  const fs::path scene = write("f.yaml", text), cases = write("cases.csv", "h\n0.1\n0.5\n");
  Result r = run("batch -q " + scene.string() + " " + cases.string() + " -o " + (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  for (int k = 0; k < 2; ++k) {
    const double h = k == 0 ? 0.1 : 0.5;
    const phiq::CsvTable t = phiq::read_csv_table((dir_ / "out" / ("case" + std::to_string(k) + ".csv")).string());
    ASSERT_EQ(t.columns[21], "P.x");
    for (const auto& row : t.rows) {  // P = r3 + R(ψ3) (0, h)
      EXPECT_NEAR(row[21], row[4] - std::sin(row[6]) * h, 1e-12) << "case " << k;
      EXPECT_NEAR(row[22], row[5] + std::cos(row[6]) * h, 1e-12) << "case " << k;
    }
  }
}

TEST_F(Cli, ProgressBarOnlyOnATerminalOrWhenAsked) {
  const fs::path scene = dir_ / "p.yaml";
  ASSERT_EQ(run("generate nfourbar 20 --steps 400 --outputs q -o " + scene.string()).code, 0);
  // stderr is a file here: no bar, only the summary line
  Result r = run("run " + scene.string() + " -o " + (dir_ / "p.csv").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("rows,"), std::string::npos) << r.err;
  // forced: drawn from the first row, erased before the summary
  r = run("run --progress always " + scene.string() + " -o " + (dir_ / "p.csv").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("\rphiq: ["), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("100% 401/401 rows"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\r\033[Kphiq: "), std::string::npos) << "the summary starts on an erased line";
  EXPECT_EQ(run("run --progress sometimes " + scene.string()).code, 2);
  // on a terminal (a pseudo-terminal from util-linux's script), a sweep longer than the bar's delay shows it
  if (std::system("command -v script >/dev/null 2>&1") == 0) {
    ASSERT_EQ(run("generate nfourbar 100 --steps 12000 --outputs q -o " + scene.string()).code, 0);
    const fs::path log = dir_ / "tty.txt";
    const std::string cmd = "script -qec \"" + std::string(PHIQ_CLI) + " run --threads 1 " + scene.string() + " -o " +
                            (dir_ / "p.csv").string() + "\" /dev/null >" + log.string() + " 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_NE(slurp(log).find("rows,"), std::string::npos) << slurp(log);
  }
}

TEST_F(Cli, PlotDrawsTheMechanismTracesAndColumns) {
  const fs::path scene = write("f.yaml", kFourbarOutputs), csv = dir_ / "f.csv", svg = dir_ / "f.svg";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  Result r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string() + " --columns theta2,P.x,P.vx");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string s = slurp(svg);
  EXPECT_EQ(s.rfind("<?xml", 0), 0u);
  EXPECT_NE(s.find("<svg xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  EXPECT_EQ(s.substr(s.size() - 7), "</svg>\n");
  auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
  };
  // 5 positions × 4 lines (crank O–A, the coupler's two arms, rocker C–B); 2 traced points; 3 columns
  EXPECT_EQ(count("<polyline class=\"mechanism\""), 20u);
  EXPECT_EQ(count("<polyline class=\"trace\""), 2u);
  EXPECT_EQ(count("<polyline class=\"series\""), 3u);
  EXPECT_EQ(count("<polyline"), 25u);
  EXPECT_EQ(count("<g"), count("</g>"));
  // each trace has a vertex per row
  const std::size_t p = s.find("data-point=\"P\" points=\"");
  ASSERT_NE(p, std::string::npos);
  const std::string pts = s.substr(p, s.find('"', p + 23) - p);
  EXPECT_EQ(static_cast<std::size_t>(std::count(pts.begin(), pts.end(), ',')), 73u);
  // default columns: the coordinates (at most 6)
  ASSERT_EQ(run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string() + " --positions 3").code, 0);
  const std::string d = slurp(svg);
  std::size_t series = 0, mech = 0;
  for (std::size_t q = d.find("class=\"series\""); q != std::string::npos; q = d.find("class=\"series\"", q + 1)) ++series;
  for (std::size_t q = d.find("class=\"mechanism\""); q != std::string::npos; q = d.find("class=\"mechanism\"", q + 1)) ++mech;
  EXPECT_EQ(series, 6u);
  EXPECT_EQ(mech, 12u);
  // a redundant scene writing only its crank angle: drawn from a sweep solved as `phiq run` solves it
  std::string red = slurp(phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  red.replace(red.find("output:"), std::string::npos, "output: {coordinates: [psi1], residuals: [A3]}\n");
  const fs::path red_scene = write("red.yaml", red), red_csv = dir_ / "red.csv";
  ASSERT_EQ(run("run -q " + red_scene.string() + " -o " + red_csv.string()).code, 0);
  Result rr = run("plot " + red_scene.string() + " " + red_csv.string() + " -o " + svg.string());
  ASSERT_EQ(rr.code, 0) << rr.err;
  const std::string rs = slurp(svg);
  std::size_t red_lines = 0;
  for (std::size_t q = rs.find("class=\"mechanism\""); q != std::string::npos; q = rs.find("class=\"mechanism\"", q + 1))
    ++red_lines;
  EXPECT_EQ(red_lines, 25u);  // 5 rows × (3 crank arms + 2 coupler arms)
  // the left-out redundant row is still within the tolerance, evaluated on the whole scene model
  const phiq::CsvTable rt = phiq::read_csv_table(red_csv.string());
  ASSERT_EQ(rt.columns.back(), "A3.residual");
  for (const auto& row : rt.rows) EXPECT_LE(row.back(), 1e-10);
}

// A scene whose mechanism draws nothing (dimension 3: `phiq generate chain3d`) got an empty panel without a word.
TEST_F(Cli, PlotSaysWhenThereIsNothingOfTheMechanismToDraw) {
  const fs::path scene = dir_ / "c.yaml", csv = dir_ / "c.csv", svg = dir_ / "c.svg";
  ASSERT_EQ(run("generate chain3d 3 --steps 10 -o " + scene.string()).code, 0);
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  Result r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.rfind("phiq: plot: " + scene.string() + ": nothing of the mechanism to draw (", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const std::string drawn = slurp(svg);
  EXPECT_EQ(drawn.find("class=\"mechanism\""), std::string::npos);
  EXPECT_NE(drawn.find("class=\"series\""), std::string::npos);
  // a planar generated scene draws its bars, silently
  ASSERT_EQ(run("generate nfourbar 3 --steps 10 -o " + scene.string()).code, 0);
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  r = run("plot " + scene.string() + " " + csv.string() + " -o " + svg.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(slurp(svg).find("class=\"mechanism\""), std::string::npos);
}

TEST_F(Cli, PlotRefusesBadInputWithOneLineAndNoFile) {
  const fs::path scene = write("f.yaml", kFourbarOutputs), csv = dir_ / "f.csv", svg = dir_ / "f.svg";
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + csv.string()).code, 0);
  auto one_line_failure = [&](const std::string& args, const std::string& says) {
    Result r = run("plot " + args + " -o " + svg.string());
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(svg)) << args;
  };
  one_line_failure(scene.string() + " " + csv.string() + " --columns theta2,nope", "no column 'nope'");
  // a CSV of another scene (here: positions only, the coordinates alone)
  std::string other = kFourbarOutputs;
  other = other.substr(0, other.find("output:")) + "output: {coordinates: [theta2]}\n";
  const fs::path other_scene = write("g.yaml", other), other_csv = dir_ / "g.csv";
  ASSERT_EQ(run("run -q " + other_scene.string() + " -o " + other_csv.string()).code, 0);
  one_line_failure(scene.string() + " " + other_csv.string(), "its columns are not the output of");
  // a CSV without the coordinates the drawing needs: the positions are solved again, and checked against the
  // columns it has
  Result ok = run("plot " + other_scene.string() + " " + other_csv.string() + " -o " + svg.string());
  ASSERT_EQ(ok.code, 0) << ok.err;
  const std::string drawn = slurp(svg);
  std::size_t lines = 0;
  for (std::size_t q = drawn.find("class=\"mechanism\""); q != std::string::npos; q = drawn.find("class=\"mechanism\"", q + 1))
    ++lines;
  EXPECT_EQ(lines, 20u);
  fs::remove(svg);
  std::string tampered = slurp(other_csv);
  const std::size_t row3 = tampered.find('\n', tampered.find('\n', tampered.find('\n') + 1) + 1) + 1;
  tampered.replace(tampered.find(',', row3) + 1, tampered.find('\n', row3) - tampered.find(',', row3) - 1, "0.5");
  const fs::path bad_csv = write("bad.csv", tampered);
  one_line_failure(other_scene.string() + " " + bad_csv.string(), "is not the result of");
  one_line_failure(scene.string() + " " + (dir_ / "missing.csv").string(), "missing.csv");
  one_line_failure((dir_ / "missing.yaml").string() + " " + csv.string(), "missing.yaml");
}

TEST_F(Cli, GenerateRefusesBadOptions) {
  EXPECT_EQ(run("generate gears 5 -o " + (dir_ / "x.yaml").string()).code, 2);
  EXPECT_EQ(run("generate nfourbar 0 -o " + (dir_ / "x.yaml").string()).code, 2);
  EXPECT_EQ(run("generate nfourbar 5 --coords polar -o " + (dir_ / "x.yaml").string()).code, 2);
  EXPECT_EQ(run("generate nfourbar 5 --outputs q,w -o " + (dir_ / "x.yaml").string()).code, 2);
  // a scene the loader would refuse: more family entries than SceneLimits::max_family_instances, or more steps
  // than time.steps takes (it was written, a kilobyte, and refused by `phiq check` only after minutes)
  Result r = run("generate nfourbar 1000000000000 -o " + (dir_ / "x.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: generate: N = 1000000000000: nfourbar in natural coordinates is at most N = 9999999 (its "
                   "families would make more entries than a scene may, SceneLimits::max_family_instances)\n");
  EXPECT_EQ(run("generate scissor 3333334 -o " + (dir_ / "x.yaml").string()).code, 2);
  // an item twice is most likely another one mistyped
  r = run("generate nfourbar 3 --outputs q,v,v -o " + (dir_ / "x.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: generate: --outputs: 'v' given twice in 'q,v,v'\n");
  r = run("generate grid 3 --steps 1000000001 -o " + (dir_ / "x.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "phiq: generate: --steps must be at most 1000000000 (a scene's time.steps), got 1000000001\n");
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

TEST_F(Cli, GeneratedScissorAndGridRunOverTheirDefaultRanges) {
  // without --from/--to: the scissor's bars from 0.3 to 1.2 rad, the grid's rows between π/4 and 3π/4
  for (const char* kind : {"scissor", "grid"})
    for (const char* coords : {"natural", "reference-point"}) {
      const fs::path scene = dir_ / "s.yaml", out = dir_ / "s.csv";
      const std::string args = std::string(kind) + " 5 --steps 30 --coords " + coords;
      ASSERT_EQ(run("generate " + args + " -o " + scene.string()).code, 0);
      const std::string text = slurp(scene);
      const std::string law = std::string(kind) == "scissor" ? "initial: 0.3, rate: 0.8999999999999999"
                                                             : "initial: 0.7853981633974483, rate: 1.5707963267948966";
      EXPECT_NE(text.find(law), std::string::npos) << kind << "\n" << text;
      Result r = run("run -q " + scene.string() + " -o " + out.string());
      ASSERT_EQ(r.code, 0) << kind << " " << coords << ": " << r.err;
      EXPECT_EQ(columns_of(slurp(out))["t"].size(), 31u);
    }
  // an explicit range replaces the default
  const fs::path scene = dir_ / "s.yaml";
  ASSERT_EQ(run("generate scissor 2 --from 0.5 --to 1 -o " + scene.string()).code, 0);
  EXPECT_NE(slurp(scene).find("initial: 0.5, rate: 0.5"), std::string::npos);
}

TEST_F(Cli, GenerateScissorAndGridRefuseBadOptions) {
  const std::string x = " -o " + (dir_ / "x.yaml").string();
  for (const char* kind : {"scissor", "grid"}) {
    EXPECT_EQ(run(std::string("generate ") + kind + " 0" + x).code, 2);
    EXPECT_EQ(run(std::string("generate ") + kind + " 5 --coords polar" + x).code, 2);
    EXPECT_EQ(run(std::string("generate ") + kind + " 5 --outputs q,w" + x).code, 2);
    EXPECT_EQ(run(std::string("generate ") + kind + " 5 --steps -1" + x).code, 2);
    Result r = run(std::string("generate ") + kind + " 5 --from 0" + x);  // flat: singular
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("generate: --from and --to: "), std::string::npos) << r.err;
  }
  EXPECT_EQ(run("generate scissor 5 --to 1.6" + x).code, 2);  // beyond vertical
  EXPECT_NE(run("generate gears 5" + x).err.find("available: nfourbar, scissor, grid, chain3d"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

TEST_F(Cli, GeneratedChain3dRuns) {
  // the issue's command as written: N = 10 spatial loops, the default quarter turn in 1000 steps
  const fs::path scene = dir_ / "c.yaml", out = dir_ / "c.csv";
  ASSERT_EQ(run("generate chain3d 10 -o " + scene.string()).code, 0);
  Result r = run("run -q " + scene.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  auto c = columns_of(slurp(out));
  ASSERT_EQ(c["t"].size(), 1001u);
  ASSERT_EQ(c.size(), 1u + 3 * 34);  // t and x0, y0, z0, ..., z10, theta with their .v and .a
  // the last row: every crank at 3π/4 about u = (1, 2, 2)/3 from e1 = d = (2, 1, -2)/3, P_10 = 10 d + c(3π/4)
  const double th = 3 * M_PI / 4, e1[3] = {2. / 3, 1. / 3, -2. / 3}, e2[3] = {-2. / 3, 2. / 3, -1. / 3};
  const char* axes[3] = {"x10", "y10", "z10"};
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(c[axes[k]].back(), 10 * e1[k] + std::cos(th) * e1[k] + std::sin(th) * e2[k], 1e-9) << axes[k];
  // the twisted row in reference-point coordinates through a full turn, and the options it refuses
  ASSERT_EQ(run("generate chain3d 4 --coords reference-point --twist 2 --from 0 --to 6.3 --steps 100 -o " +
                scene.string()).code, 0);
  EXPECT_NE(slurp(scene).find("--coords reference-point --twist 2:"), std::string::npos);
  r = run("run -q " + scene.string() + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(columns_of(slurp(out))["t"].size(), 101u);
  const std::string x = " -o " + (dir_ / "x.yaml").string();
  EXPECT_EQ(run("generate chain3d 5 --from 0" + x).code, 2);            // the parallelogram row lies flat
  EXPECT_EQ(run("generate chain3d 5 --twist 3.1415926" + x).code, 2);   // neighbours opposite: singular
  EXPECT_EQ(run("generate nfourbar 5 --twist 1" + x).code, 2);          // chain3d only
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

TEST_F(Cli, UsageErrorsAndHelp) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate x").code, 2);
  EXPECT_EQ(run("run").code, 2);
  Result h = run("run --help");
  EXPECT_EQ(h.code, 0);
  EXPECT_NE(h.out.find("--output"), std::string::npos);
  EXPECT_EQ(run("--version").out, "phiq 0.1.0 (scene format 1, CSV format 1, check --json format 1)\n");
}


// ---- redundancy (issue 3): check, assemble, run through consistent redundancy, refuse inconsistent ----------------

const char* kPlanarDoorMisaligned = R"(phiq: 1
coordinates: {x: 0.01, y: -0.02, psi: 0.1}
bodies: {door: [x, y, psi]}
constraints:
  - {name: pin1, type: revolute, between: [{body: door, at: [0, 0]}, {body: ground, at: [0, 0]}]}
  - {name: pin2, type: revolute, between: [{body: door, at: [0, 0]}, {body: ground, at: [0.001, 0]}]}
drivers:
  - {name: motor, coordinate: psi, law: {type: linear, initial: 0.2, rate: 1}}
time: {start: 0, end: 1, steps: 10}
)";

TEST_F(Cli, CheckJsonReportsRankDofAndRedundantConstraints) {
  Result r = run("check --json " + phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  for (const char* part : {"\"coordinates\": 12", "\"equations\": 13", "\"rank\": 11", "\"dof\": 1",
                           "\"driven_dof\": 0", "\"grubler\": ", "\"redundant\": [\n    \"A3\"\n  ]",
                           "\"name\": \"A3[1]\"", "\"consistent\": true", "\"conflicts\": []",
                           "\"rank_uncertain\": false"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  Result text = run("check " + phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml"));
  EXPECT_NE(text.out.find("redundant     A3\n"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("dof           1 (0 not driven)\n"), std::string::npos) << text.out;
}

TEST_F(Cli, CheckNamesTheConflictsOfInconsistentRedundancy) {
  fs::path p = write("door.yaml", kPlanarDoorMisaligned);
  Result r = run("check --json " + p.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("\"consistent\": false"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"conflicts\": [\n    \"pin1\",\n    \"pin2\"\n  ]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"status\": \"inconsistent redundant constraints\""), std::string::npos) << r.out;
}

TEST_F(Cli, RunRefusesInconsistentRedundancyInOneLineAndWritesNothing) {
  fs::path p = write("door.yaml", kPlanarDoorMisaligned);
  Result r = run("run " + p.string() + " -o " + (dir_ / "out.csv").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("t = 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("conflicting constraints: pin1, pin2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no output written"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.csv"));
}

TEST_F(Cli, AssembleWritesTheAssembledCoordinatesAsOneCsvRow) {
  const fs::path out = dir_ / "q.csv";
  Result r = run("assemble " + phiq::test::model_path("redundant/parallelogram_fifth_bar.yaml") + " -o " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = slurp(out);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,x1,y1,psi1,x2,y2,psi2,x3,y3,psi3,xc,yc,psic");
  // the row: every crank at pi/3 (the motor at t = 0), the coupler's left end at (cos, sin) of it
  std::vector<double> v;
  std::stringstream row(text.substr(text.find('\n') + 1));
  for (std::string cell; std::getline(row, cell, ',');) v.push_back(std::stod(cell));
  ASSERT_EQ(v.size(), 13u);
  for (int k : {3, 6, 9}) EXPECT_NEAR(v[k], M_PI / 3, 1e-10);
  EXPECT_NEAR(v[10], 0.5, 1e-10);
  EXPECT_NEAR(v[11], std::sqrt(3.0) / 2, 1e-10);
  // an inconsistent model: exit 1, nothing written
  fs::path p = write("door.yaml", kPlanarDoorMisaligned);
  EXPECT_EQ(run("assemble " + p.string() + " -o " + (dir_ / "door.csv").string()).code, 1);
  EXPECT_FALSE(fs::exists(dir_ / "door.csv"));
}


TEST_F(Cli, CheckAnalysesTheConfigurationAtTheTimeAsked) {
  const std::string scene = phiq::test::model_path("redundant/parallelogram_change_point.yaml");
  Result normal = run("check --json " + scene);
  ASSERT_EQ(normal.code, 0) << normal.err;
  EXPECT_NE(normal.out.find("\"rank\": 8"), std::string::npos) << normal.out;
  EXPECT_NE(normal.out.find("\"rank_uncertain\": false"), std::string::npos) << normal.out;
  // the crank driven to 0: flat, a change point; assembled only to about 1e-6 there, which the analysis reports
  Result flat = run("check --json --time -1.0471975511965976 " + scene);
  EXPECT_NE(flat.out.find("\"time\": -1.0471975511965976"), std::string::npos) << flat.out;
  EXPECT_NE(flat.out.find("\"rank_uncertain\": true"), std::string::npos) << flat.out;
  EXPECT_NE(flat.out.find("singular value"), std::string::npos) << flat.out;
}

// Column `name` of a table (a failure, and column 0, if there is none).
std::size_t column(const phiq::CsvTable& t, const std::string& name) {
  const auto it = std::find(t.columns.begin(), t.columns.end(), name);
  EXPECT_NE(it, t.columns.end()) << name;
  return it == t.columns.end() ? 0 : static_cast<std::size_t>(it - t.columns.begin());
}

// Powers whose base passes through exactly 0 made `phiq run` fail on well-conditioned models (GiNaC's u^k·k·u^(-1),
// 0·∞ at u = 0): the audit's three scenes, now against their closed forms.
TEST_F(Cli, PowersThroughAZeroBaseRunAgainstTheirClosedForms) {
  // y = (2x)² + 1, x = t − 1 through 0 at t = 1 (step 2): ẏ = 8x, ÿ = 8. Failed: "velocity is not finite".
  const fs::path pow = write("pow.yaml", R"(phiq: 1
coordinates: {x: -1, y: 5, z: 0}
constraints:
  - {name: c, type: equation, expr: "y - (2*x)^2 - 1", unit: length}
  - {name: zfix, type: equation, expr: "z", unit: length}
drivers:
  - {name: m, coordinate: x, law: {type: linear, initial: -1, rate: 1}}
time: {start: 0, end: 2, steps: 4}
output: {velocities: true, accelerations: true}
)");
  Result r = run("run -q --threads 1 " + pow.string() + " -o " + (dir_ / "pow.csv").string());
  ASSERT_EQ(r.code, 0) << r.err;
  phiq::CsvTable t = phiq::read_csv_table((dir_ / "pow.csv").string());
  ASSERT_EQ(t.rows.size(), 5u);
  for (const auto& row : t.rows) {
    const double x = row[0] - 1;
    EXPECT_EQ(row[column(t, "x")], x);
    EXPECT_NEAR(row[column(t, "y")], 4 * x * x + 1, 1e-12);
    EXPECT_NEAR(row[column(t, "y.v")], 8 * x, 1e-12);
    EXPECT_NEAR(row[column(t, "y.a")], 8.0, 1e-12);
  }
  EXPECT_EQ(t.rows[2][column(t, "y.v")], 0.0);  // x = 0 exactly

  // The notes' crank-slider driven by the expression laws θ2 = 0.1 + (2t)² (f'(0) = 0, f'' = 8; failed at t = 0)
  // and θ2 = 0.1 + (t − ½)² (failed at t = ½ in most processes): θ2, θ̇2, θ̈2 and the slider against the closed form.
  for (const auto& [law, t_zero] : {std::pair<std::string, double>{"0.1 + (2*t)^2", 0.0}, {"0.1 + (t - 0.5)^2", 0.5}}) {
    const fs::path cs = write("cs.yaml", R"(phiq: 1
parameters: {L2: 0.3, L3: 1.0}
coordinates: {theta2: 0.1, xA: 0.28, yA: 0.03, xB: 1.25}
points: {O: [0, 0], A: [xA, yA], B: [xB, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta2}
  - {name: rod, type: distance, points: [A, B], length: L3}
drivers:
  - {name: motor, coordinate: theta2, law: {type: expression, f: ")" + law + R"("}}
time: {start: 0, end: 1, steps: 10}
output: {velocities: true, accelerations: true}
)");
    r = run("run -q --threads 1 " + cs.string() + " -o " + (dir_ / "cs.csv").string());
    ASSERT_EQ(r.code, 0) << law << ": " << r.err;
    t = phiq::read_csv_table((dir_ / "cs.csv").string());
    ASSERT_EQ(t.rows.size(), 11u);
    const double k = t_zero == 0.0 ? 2.0 : 1.0;  // θ2 = 0.1 + (k (t − t0))²
    for (const auto& row : t.rows) {
      const double u = k * (row[0] - t_zero), th = 0.1 + u * u;
      EXPECT_NEAR(row[column(t, "theta2")], th, 1e-14) << law;
      EXPECT_NEAR(row[column(t, "theta2.v")], 2 * k * u, 1e-13) << law;
      EXPECT_NEAR(row[column(t, "theta2.a")], 2 * k * k, 1e-12) << law;
      EXPECT_NEAR(row[column(t, "xB")], 0.3 * std::cos(th) + std::sqrt(1 - std::pow(0.3 * std::sin(th), 2)), 1e-9);
    }
    EXPECT_EQ(t.rows[t_zero == 0.0 ? 0 : 5][column(t, "theta2.v")], 0.0) << law;
  }

  // A parallelogram four-bar whose coupler is (xA − xB)² + (yA − yB)² − b², yA − yB = 0 to rounding or exactly:
  // a bogus "singular position ... rcond 0" or "velocity is not finite" in about one process in four. Each run is
  // a new process: A = 0.6 (cos θ, sin θ), θ = 0.3 + t, B = A + (1.5, 0).
  const fs::path par = write("par.yaml", R"(phiq: 1
parameters: {a: 0.6, b: 1.5, c: 0.6}
coordinates: {theta2: 0.33, xA: 0.5932, yA: 0.1573, xB: 2.0932, yB: 0.1973}
points: {O: [0, 0], A: [xA, yA], B: [xB, yB], C: [1.5, 0]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: a, angle: theta2}
  - {name: coupler, type: equation, expr: "(xA - xB)^2 + (yA - yB)^2 - b^2"}
  - {name: rocker, type: distance, points: [C, B], length: c}
drivers:
  - {name: motor, coordinate: theta2, law: {type: linear, initial: 0.3, rate: 1}}
time: {start: 0, end: 1, steps: 100}
output: {velocities: true, accelerations: true}
solver: {newton: full}
)");
  for (int run_k = 0; run_k < 8; ++run_k) {
    r = run("run -q --threads 1 " + par.string() + " -o " + (dir_ / "par.csv").string());
    ASSERT_EQ(r.code, 0) << "run " << run_k << ": " << r.err;
    t = phiq::read_csv_table((dir_ / "par.csv").string());
    ASSERT_EQ(t.rows.size(), 101u);
    for (const auto& row : t.rows) {
      const double th = 0.3 + row[0];
      EXPECT_NEAR(row[column(t, "xB")], 0.6 * std::cos(th) + 1.5, 1e-9);
      EXPECT_NEAR(row[column(t, "yB")], 0.6 * std::sin(th), 1e-9);
      EXPECT_NEAR(row[column(t, "yB.v")], 0.6 * std::cos(th), 1e-9);
      EXPECT_NEAR(row[column(t, "yB.a")], -0.6 * std::sin(th), 1e-9);
    }
  }
}

// The same scene run twice gave CSVs differing in their last bits (~1e-15) when it had expressions: GiNaC's term
// order, hence the order of the tape's operations, followed hash values seeded from addresses that address-space
// randomisation moves. Each run is a new process; the bytes must be the same.
TEST_F(Cli, ScenesWithExpressionsGiveTheSameBytesInEveryProcess) {
  const fs::path eq = write("eq.yaml", R"yaml(phiq: 1
parameters: {a: 0.4, b: 1.2, c: 1.0, Ox: 0.0, Oy: 0.0, Cx: 1.0, Cy: 0.0}
coordinates: {theta2: 0.1300, xA: 0.4180, yA: 0.0199, xB: 1.1489, yB: 1.0117}
constraints:
  - {name: cx, type: equation, expr: "xA - Ox - a*cos(theta2)", unit: length}
  - {name: cy, type: equation, expr: "yA - Oy - a*sin(theta2)", unit: length}
  - {name: coupler, type: equation, expr: "(xA - xB)^2 + (yA - yB)^2 - b^2"}
  - {name: rocker, type: equation, expr: "(Cx - xB)^2 + (Cy - yB)^2 - c^2"}
drivers:
  - {name: motor, coordinate: theta2, law: {type: expression, f: "0.1 + 2.5*t - 0.4*sin(3*t)"}}
time: {start: 0.0, end: 6.283185307179586, steps: 360}
output: {velocities: true, accelerations: true}
)yaml");
  for (const std::string& scene : {eq.string(), phiq::test::model_path("seed/crank_slider_equations.yaml")}) {
    std::string first;
    for (int k = 0; k < 6; ++k) {
      const fs::path csv = dir_ / ("run" + std::to_string(k) + ".csv");
      Result r = run("run -q --threads 1 " + scene + " -o " + csv.string());
      ASSERT_EQ(r.code, 0) << r.err;
      const std::string bytes = slurp(csv);
      if (k == 0) first = bytes;
      EXPECT_TRUE(bytes == first) << scene << ": run " << k << " differs from run 0";
    }
  }
}

// ---- the robustness audit: output paths, signals, standard output, the command line, messages ----------------

// One line on stderr, "phiq: " first.
::testing::AssertionResult one_phiq_line(const std::string& err) {
  if (std::count(err.begin(), err.end(), '\n') == 1 && err.rfind("phiq: ", 0) == 0)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "not one 'phiq: ' line: " << err;
}

// A device node (as /dev/null: character device 1, 3) given to -o is written in place and stays a device, as does
// a FIFO (its reader gets the whole CSV); several outputs may share a device. Creating the node needs root (mknod):
// skipped otherwise. The real /dev/null is never used: the node lives in the test's directory.
// "-" is standard output, as in most tools: run -o - gives the bytes run gives without -o (one thread: the same
// bytes in every run), generate -o - a scene that loads, plot -o - an SVG, --summary - the JSON; no file named "-"
// appears; batch refuses it for its directory.
TEST_F(Cli, ADashIsStandardOutput) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  struct Cwd {  // in dir_ (a file named "-" would land there), back however the test ends
    fs::path was = fs::current_path();
    explicit Cwd(const fs::path& to) { fs::current_path(to); }
    ~Cwd() { fs::current_path(was); }
  } in_dir(dir_);
  Result plain = run("run -q --threads 1 " + scene);
  Result dash = run("run -q --threads 1 " + scene + " -o -");
  ASSERT_EQ(dash.code, 0) << dash.err;
  EXPECT_EQ(dash.out, plain.out);
  EXPECT_EQ(dash.out.rfind("t,theta2,", 0), 0u);
  Result gen = run("generate nfourbar 3 --steps 4 -o -");
  ASSERT_EQ(gen.code, 0) << gen.err;
  EXPECT_EQ(phiq::parse_scene(gen.out, "generated.yaml").model->num_coordinates(), 9);  // θ and 4 tips
  const fs::path csv = dir_ / "cs.csv";
  Result sum = run("run -q --threads 1 " + scene + " -o " + csv.string() + " --summary -");
  ASSERT_EQ(sum.code, 0) << sum.err;
  EXPECT_EQ(sum.out.rfind("{", 0), 0u) << sum.out;
  EXPECT_NE(sum.out.find("\"steps\": 181"), std::string::npos) << sum.out;
  Result svg = run("plot " + scene + " " + csv.string() + " -o -");
  ASSERT_EQ(svg.code, 0) << svg.err;
  EXPECT_NE(svg.out.find("<svg"), std::string::npos);
  Result batch = run("batch " + scene + " " + write("c.csv", "L2\n0.2\n").string() + " -o -");
  EXPECT_EQ(batch.code, 2);
  EXPECT_NE(batch.err.find("'-' (standard output) cannot hold the case files"), std::string::npos) << batch.err;
  EXPECT_FALSE(fs::exists(dir_ / "-"));
}

TEST_F(Cli, DeviceAndFifoOutputsAreWrittenInPlace) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  const fs::path fifo = dir_ / "fifo", copy = dir_ / "copy.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
  const std::string cmd = "cat " + fifo.string() + " > " + copy.string() + " & " + std::string(PHIQ_CLI) + " run -q " +
                          scene + " -o " + fifo.string() + " >" + out.string() + " 2>" + err.string() +
                          "; s=$?; wait; exit $s";
  const int st = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << slurp(err);
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(std::count_if(std::istreambuf_iterator<char>(*std::make_unique<std::ifstream>(copy)),
                          std::istreambuf_iterator<char>(), [](char c) { return c == '\n'; }),
            182);  // the header and 181 rows
  EXPECT_EQ(files(), (std::vector<std::string>{"copy.csv", "fifo", "stderr.txt", "stdout.txt"}));  // no temporary

  const fs::path null = dir_ / "null";
  if (::mknod(null.c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0) GTEST_SKIP() << "mknod needs root";
  Result r = run("run -q " + scene + " -o " + null.string() + " --summary " + null.string());
  EXPECT_EQ(r.code, 0) << r.err;
  struct stat sb;
  ASSERT_EQ(::stat(null.c_str(), &sb), 0);
  EXPECT_TRUE(S_ISCHR(sb.st_mode));
  EXPECT_EQ(::major(sb.st_rdev), 1u);
  EXPECT_EQ(::minor(sb.st_rdev), 3u);
  r = run("assemble -q " + scene + " -o " + null.string());
  EXPECT_EQ(r.code, 0) << r.err;
  r = run("generate nfourbar 3 -o " + null.string());
  EXPECT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(::stat(null.c_str(), &sb), 0);
  EXPECT_TRUE(S_ISCHR(sb.st_mode));
  EXPECT_EQ(files(), (std::vector<std::string>{"copy.csv", "fifo", "null", "stderr.txt", "stdout.txt"}));
}

// -o through a symbolic link (relative, into another directory) replaces the link's target and leaves the link;
// the temporary lives beside the target. /dev/stdout (one of the process's own descriptors) is written through the
// descriptor: appended to what the shell opened with >>, not replacing it.
TEST_F(Cli, SymlinkOutputsReplaceTheirTargetAndKeepTheLink) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  fs::create_directories(dir_ / "results");
  write("results/cs.csv", "old result\n");
  fs::create_symlink("results/cs.csv", dir_ / "latest.csv");
  Result r = run("run -q " + scene + " -o " + (dir_ / "latest.csv").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir_ / "latest.csv"));
  EXPECT_EQ(fs::read_symlink(dir_ / "latest.csv"), "results/cs.csv");
  EXPECT_EQ(slurp(dir_ / "results/cs.csv").rfind("t,theta2,", 0), 0u);
  std::vector<std::string> in_results;
  for (auto& e : fs::directory_iterator(dir_ / "results")) in_results.push_back(e.path().filename().string());
  EXPECT_EQ(in_results, std::vector<std::string>{"cs.csv"});
  // a dangling link: its target is created
  fs::create_symlink("results/new.csv", dir_ / "next.csv");
  ASSERT_EQ(run("assemble -q " + scene + " -o " + (dir_ / "next.csv").string()).code, 0);
  EXPECT_TRUE(fs::is_symlink(dir_ / "next.csv"));
  EXPECT_EQ(slurp(dir_ / "results/new.csv").rfind("t,theta2,", 0), 0u);

  write("log.txt", "before\n");
  const std::string cmd = std::string(PHIQ_CLI) + " assemble -q " + scene + " -o /dev/stdout >>" + (dir_ / "log.txt").string();
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(slurp(dir_ / "log.txt").rfind("before\nt,theta2,", 0), 0u) << slurp(dir_ / "log.txt");
  EXPECT_FALSE(fs::is_symlink(dir_ / "log.txt"));
}

// An output that is an input (the scene, through a link or a hard link too), or two outputs that are one file, are
// refused in one line before anything is solved; the files are untouched.
TEST_F(Cli, OutputsThatAreInputsOrEachOtherAreRefused) {
  const std::string original = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const fs::path scene = write("s.yaml", original);
  fs::create_symlink("s.yaml", dir_ / "link.yaml");
  fs::create_hard_link(scene, dir_ / "hard.yaml");
  const fs::path csv = write("r.csv", "t,theta2\n0,0\n");
  const std::string s = scene.string(), d = dir_.string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run " + s + " -o " + s, "run: -o " + s + ": the same file as the scene " + s},
      {"run " + s + " -o " + d + "/link.yaml", "the same file as the scene"},
      {"run " + s + " -o " + d + "/hard.yaml", "the same file as the scene"},
      {"run " + s + " -o " + d + "/./s.yaml", "the same file as the scene"},
      {"run " + s + " --summary " + s, "run: --summary " + s + ": the same file as the scene"},
      {"run " + s + " -o " + d + "/a.csv --summary " + d + "/a.csv", "-o " + d + "/a.csv and --summary " + d + "/a.csv are the same file"},
      {"assemble " + s + " -o " + d + "/link.yaml", "assemble: -o "},
      {"sweep-accuracy " + s + " -o " + d + "/x.csv --json " + d + "/x.csv", "are the same file"},
      {"sweep-accuracy " + s + " --json " + s, "the same file as the scene"},
      {"plot " + s + " " + csv.string() + " -o " + csv.string(), "plot: -o " + csv.string() + ": the same file as the result"},
      {"plot " + s + " " + csv.string() + " -o " + s, "the same file as the scene"},
  };
  for (const auto& [args, says] : cases) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_EQ(slurp(scene), original);
  EXPECT_EQ(slurp(csv), "t,theta2\n0,0\n");
  // batch: a case file that is the cases file
  fs::create_directories(dir_ / "out");
  const fs::path cases_csv = write("out/case0.csv", "L2\n0.2\n");
  Result r = run("batch " + s + " " + cases_csv.string() + " -o " + d + "/out");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("the same file as the cases"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(cases_csv), "L2\n0.2\n");
  EXPECT_EQ(files(), (std::vector<std::string>{"hard.yaml", "link.yaml", "out", "r.csv", "s.yaml", "stderr.txt", "stdout.txt"}));
}

// An empty output path is refused (it used to mean standard output); nothing goes to standard output.
TEST_F(Cli, EmptyOutputPathsAreRefused) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  for (const std::string& args : std::vector<std::string>{
           "run " + scene + " -o ''", "run " + scene + " --summary ''", "assemble " + scene + " -o ''",
           "generate nfourbar 3 -o ''", "sweep-accuracy " + scene + " --json ''", "batch " + scene + " x.csv -o ''",
           "plot " + scene + " x.csv -o ''"}) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_TRUE(one_phiq_line(r.err)) << args;
    EXPECT_NE(r.err.find("the path is empty"), std::string::npos) << args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

// A scene that sweeps for minutes (10^7 steps of the crank-slider).
std::string long_scene() {
  std::string scene = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  scene.replace(scene.find("steps: 180"), 10, "steps: 10000000");
  return scene;
}

// SIGTERM and SIGHUP stop a run as SIGINT does: exit 128 + the signal, one line naming it, no output and no
// temporary left (the CSV and the summary).
TEST_F(Cli, TermAndHangupStopARunLikeInterrupt) {
  const fs::path p = write("long.yaml", long_scene());
  for (const auto& [sig, status] : {std::pair<std::string, int>{"TERM", 143}, {"HUP", 129}, {"INT", 130}}) {
    const auto t0 = std::chrono::steady_clock::now();
    Result r = run_prefixed("timeout --preserve-status -s " + sig + " 0.5 ",
                            "run " + p.string() + " -o " + (dir_ / "out.csv").string() + " --summary " +
                                (dir_ / "s.json").string());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.code, status) << sig << ": " << r.err;
    EXPECT_LT(seconds, 5.0) << sig;
    EXPECT_TRUE(one_phiq_line(r.err)) << sig;
    EXPECT_NE(r.err.find("long.yaml: interrupted (SIG" + sig + "); no output written"), std::string::npos) << r.err;
    EXPECT_EQ(files(), (std::vector<std::string>{"long.yaml", "stderr.txt", "stdout.txt"})) << sig;
  }
}

// A signal while no sweep runs (here: waiting for a FIFO's reader, with another output's temporary already
// created) ends the command at once, removing the temporaries.
TEST_F(Cli, SignalOutsideTheSweepRemovesTheTemporaries) {
  const fs::path fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  Result r = run_prefixed("timeout --preserve-status -s TERM 0.5 ",
                          "sweep-accuracy " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " -o " +
                              (dir_ / "acc.csv").string() + " --json " + fifo.string());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(r.code, 143) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("interrupted (SIGTERM); no output written"), std::string::npos) << r.err;
  EXPECT_EQ(files(), (std::vector<std::string>{"fifo", "stderr.txt", "stdout.txt"}));
}

// Every output is created before the sweep: an unusable --summary fails at once (exit 3, the sweep of minutes not
// run) and no file appears, nor is an existing one replaced; the same for sweep-accuracy's two outputs.
TEST_F(Cli, UnwritableOutputsFailBeforeTheSweepAndNoneAppears) {
  const fs::path p = write("long.yaml", long_scene());
  write("a.csv", "previous\n");
  const auto t0 = std::chrono::steady_clock::now();
  Result r = run("run " + p.string() + " -o " + (dir_ / "a.csv").string() + " --summary " +
                 (dir_ / "nodir" / "s.json").string());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("nodir/s.json: cannot write: No such file or directory"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_ / "a.csv"), "previous\n");
  r = run("run " + p.string() + " -o " + dir_.string());  // a directory
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find(": cannot write: is a directory"), std::string::npos) << r.err;
  r = run("sweep-accuracy " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " --repeat 1 -o " +
          (dir_ / "acc.csv").string() + " --json " + (dir_ / "nodir" / "acc.json").string());
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_EQ(files(), (std::vector<std::string>{"a.csv", "long.yaml", "stderr.txt", "stdout.txt"}));
}

// What goes to standard output and is lost (a full device, a closed descriptor) is an error, exit 3 in one line:
// check, check --json, assemble, run.
TEST_F(Cli, LostStandardOutputIsAnError) {
  const std::string scene = phiq::test::model_path("seed/fourbar_natural.yaml");
  const fs::path err = dir_ / "err.txt";
  // the command with standard output redirected as given: its exit status, its stderr in err.txt
  auto status = [&](const std::string& args, const std::string& redirect) {
    const int st = std::system((std::string(PHIQ_CLI) + " " + args + " " + redirect + " 2>" + err.string()).c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  };
  if (fs::exists("/dev/full")) {
    for (const std::string& args :
         std::vector<std::string>{"check " + scene, "check --json " + scene, "assemble -q " + scene, "run -q " + scene}) {
      EXPECT_EQ(status(args, ">/dev/full"), 3) << args << ": " << slurp(err);
      EXPECT_TRUE(one_phiq_line(slurp(err))) << args;
      EXPECT_NE(slurp(err).find("standard output: cannot write: No space left on device"), std::string::npos) << slurp(err);
    }
  }
  for (const std::string& args : std::vector<std::string>{"run -q " + scene, "check " + scene, "assemble -q " + scene}) {
    EXPECT_EQ(status(args, ">&-"), 3) << args << ": " << slurp(err);
    EXPECT_TRUE(one_phiq_line(slurp(err))) << args;
    EXPECT_NE(slurp(err).find("standard output: cannot write: it is closed"), std::string::npos) << slurp(err);
  }
}

// Command-line errors are one line, "phiq: <command>: <what>", exit 2, with readable ranges.
TEST_F(Cli, CommandLineErrorsAreOneLineNamingTheCommand) {
  const std::string scene = phiq::test::model_path("seed/fourbar_natural.yaml");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run " + scene + " --threads -1",
       "phiq: run: --threads: expected a whole number from 0 (all cores) to 1000000, got '-1'"},
      {"run " + scene + " --threads abc", "phiq: run: --threads: expected a whole number"},
      {"run " + scene + " --memory -1", "phiq: run: --memory: expected a number of GB from 0"},
      {"run " + scene + " --memory nan", "phiq: run: --memory: expected a number of GB from 0"},
      {"run " + scene + " --frobnicate", "phiq: run: unknown option --frobnicate"},
      {"run " + scene + " " + scene, "phiq: run: unexpected argument"},
      {"run " + scene + " -o", "phiq: run: --output: a value is required"},
      {"run " + scene + " --progress sometimes",
       "phiq: run: --progress: expected auto, always or never, got 'sometimes'"},
      {"run", "phiq: run: scene is required"},
      {"frobnicate " + scene, "phiq: unknown command 'frobnicate' (commands: run, "},
      {"", "phiq: a command is required (run, "},
      {"--frobnicate", "phiq: unknown option --frobnicate"},
      {"plot " + scene + " x.csv -o x.svg --positions 0",
       "phiq: plot: --positions: expected a whole number from 1 to 50, got '0'"},
      {"batch " + scene + " x.csv -o out --threads -2", "phiq: batch: --threads: "},
      {"compare a.csv b.csv --rtol nan", "phiq: compare: --rtol: expected a number >= 0"},
      {"compare a.csv b.csv --atol -1", "phiq: compare: --atol: "},
      {"check " + scene + " --time inf", "phiq: check: --time: expected a finite number, got 'inf'"},
      {"check " + scene + " --time nan", "phiq: check: --time: expected a finite number, got 'nan'"},
      {"generate nfourbar many -o x.yaml", "phiq: generate: N: expected a whole number, got 'many'"},
      {"sweep-accuracy " + scene + " --repeat x",
       "phiq: sweep-accuracy: --repeat: expected a whole number from 1 to 1000"},
  };
  for (const auto& [args, says] : cases) {
    Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << args;
    EXPECT_EQ(r.err.rfind(says, 0), 0u) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("1797693134862315"), std::string::npos) << r.err;  // no 309-digit bound
    EXPECT_TRUE(r.out.empty()) << args;
  }
  EXPECT_FALSE(fs::exists("x.yaml"));
}

// More threads than the machine runs at once are capped to them, with a note, and the summary says how many ran
// (TBB would keep its limit, warn on several lines, and the summary claim the number asked for).
TEST_F(Cli, ThreadsBeyondTheCoresAreCapped) {
  const fs::path sum = dir_ / "s.json";
  Result r = run("run " + phiq::test::model_path("seed/crank_slider_mixed.yaml") + " -o " + (dir_ / "a.csv").string() +
                 " --threads 100000 --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("TBB"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("phiq: run: --threads 100000: "), std::string::npos) << r.err;
  const std::string j = slurp(sum);
  const std::size_t at = j.find("\"threads\": ");
  ASSERT_NE(at, std::string::npos);
  const int threads = std::atoi(j.c_str() + at + 11);
  EXPECT_GE(threads, 1);
  EXPECT_LE(threads, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
}

// Times in failures keep their digits: time.start 1e-7 is "t = 1e-07", not std::to_string's "t = 0.000000" (run's
// refusal of an inconsistent model at the start, assemble's failure).
TEST_F(Cli, FailureTimesKeepTheirDigits) {
  std::string text = kPlanarDoorMisaligned;
  text.replace(text.find("start: 0,"), 9, "start: 1e-7,");
  const fs::path p = write("door.yaml", text);
  for (const std::string cmd : {"run ", "assemble "}) {
    Result r = run(cmd + p.string() + " -o " + (dir_ / "out.csv").string());
    EXPECT_EQ(r.code, 1) << cmd << r.err;
    EXPECT_TRUE(one_phiq_line(r.err)) << cmd;
    EXPECT_NE(r.err.find("door.yaml: t = 1e-07: "), std::string::npos) << cmd << r.err;
    EXPECT_EQ(r.err.find("0.000000"), std::string::npos) << cmd << r.err;
  }
  Result c = run("check " + p.string());
  EXPECT_NE(c.out.find(" at t = 1e-07 in "), std::string::npos) << c.out;
}

// compare names its options, and its worst cell's line is the file's line (as its parse errors count them).
TEST_F(Cli, CompareCountsFileLinesAndNamesItsOptions) {
  const fs::path a = write("a.csv", "t,x\n0,1\n0.5,2\n1,3\n"), b = write("b.csv", "t,x\n0,1\n0.5,2.5\n1,3\n");
  Result r = run("compare " + a.string() + " " + b.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("worst x at line 3 (t = 0.5): 2 vs 2.5"), std::string::npos) << r.err;
  const fs::path bad = write("bad.csv", "t,x\n0,1\n0.5,abc\n");
  r = run("compare " + a.string() + " " + bad.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.csv:3: "), std::string::npos) << r.err;
  r = run("compare " + a.string() + " " + b.string() + " --rtol nan");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.find("compare_csv"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--rtol"), std::string::npos) << r.err;
}

// batch names the case only when the error comes from the case's parameters, not for an error of the scene itself.
TEST_F(Cli, BatchNamesTheCaseOnlyForItsOwnErrors) {
  const fs::path broken = write("broken.yaml", "parameters: {L2: 0.3}\ncoordinates: {x: [0\n");
  const fs::path cases = write("cases.csv", "L2\n0.2\n");
  Result r = run("batch " + broken.string() + " " + cases.string() + " -o " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("broken.yaml:"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("case 0"), std::string::npos) << r.err;
  // a value of the case that makes the scene invalid: named with the case
  std::string text = slurp(phiq::test::model_path("seed/crank_slider_mixed.yaml"));
  const fs::path scene = write("cs.yaml", text);
  const fs::path neg = write("neg.csv", "L2,L3\n0.2,1\n0.3,-1\n");
  r = run("batch " + scene.string() + " " + neg.string() + " -o " + (dir_ / "out").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("(case 1 of " + neg.string() + ", line 3)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// A square scene whose first position Newton cannot reach from the placement for want of a descent direction, not
// for a zero pivot: a Cardan joint at 90° placed at its singular angle, where the output shaft is free and the motor
// fixes nothing. The failure gets the minimum-norm assembly's rank analysis, as a singular Jacobian did, and so says
// what is wrong; before it ended on "no decrease of the residual along the Newton direction".
TEST_F(Cli, AFirstPositionNotReachedGetsTheRankAnalysis) {
  const fs::path p = write("cardan90.yaml", R"Y(phiq: 1
name: cardan_b90_refpoint
dimension: 3
parameters: {W: 1.5}
coordinates:
  x1: 0.2100
  y1: 0.0900
  z1: -0.3000
  p0: 0.9694
  p1: 0.1700
  p2: -0.1100
  p3: 0.3100
  x2: 0.2000
  y2: 0.1100
  z2: -0.3000
  q0: 0.7332
  q1: -0.1290
  q2: 0.5353
  q3: 0.2670
bodies:
  s1: [x1, y1, z1, p0, p1, p2, p3]
  s2: [x2, y2, z2, q0, q1, q2, q3]
constraints:
  - {name: hinge1, type: revolute, between: [{body: ground, at: [0.20000000000000001, 0.10000000000000001, -0.29999999999999999], axis: [-0.18461483192953382, -0.34138670707320812, 0.92161406242816279], ref: [0.8040351560704071, 0.48680857021682333, 0.34138670707320812]}, {body: s1, axis: [0, 0, 1], ref: [1, 0, 0]}]}
  - {name: cross, type: universal, between: [{body: s1, axis: [1, 0, 0]}, {body: s2, axis: [0, 1, 0]}]}
  - {name: axis2, type: point_on_line, between: [{body: ground, at: [0.20000000000000001, 0.10000000000000001, -0.29999999999999999], axis: [0.8040351560704071, 0.48680857021682333, 0.34138670707320817]}, {body: s2, at: [0, 0, 1]}]}
drivers:
  - {name: motor, joint: hinge1, measure: angle, law: {type: linear, initial: 0, rate: W}}
time: {start: 0.0, end: 4.1887902047863905, steps: 72}
output: {velocities: true, accelerations: true}
)Y");
  Result r = run("run " + p.string() + " -o " + (dir_ / "out.csv").string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("step 0, t = 0: initial assembly failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; rank analysis: 1 degree(s) of freedom not driven"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.csv"));
}

}  // namespace
