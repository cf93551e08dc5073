// `phiq run`: the CSV it writes (header, rows, digits), standard output without -o, a bad or unreachable scene
// failing in one line without touching an existing file, the summary's counts, the memory budget and thread cap,
// the listed outputs, the progress bar, and a first position that Newton cannot reach. Separate from the other
// commands' files (test_cli_*.cpp), which share the Cli fixture of cli_test_support.hpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "phiq/csv_compare.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::kFourbarOutputs;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

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

TEST_F(Cli, SummaryJsonCountsWhatWasComputed) {
  const fs::path scene = dir_ / "p.yaml", sum = dir_ / "sum.json";
  ASSERT_EQ(run("generate nfourbar 3 --steps 10 --outputs q -o " + scene.string()).code, 0);
  Result r = run("run -q " + scene.string() + " -o " + (dir_ / "p.csv").string() + " --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string j = slurp(sum);
  for (const char* part :
       {"\"steps\": 11", "\"threads\": 1", "\"velocity_solves\": 0", "\"acceleration_solves\": 0",
        "\"gamma_evaluations\": 0", "\"phi_t_evaluations\": 0", "\"load_seconds\": ", "\"solve_seconds\": ",
        "\"write_seconds\": ", "\"linear_solver\": \"klu\"", "\"warnings\": []", "\"min_rcond\": null"})
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
  ASSERT_EQ(run("run -q " + scene.string() + " -o " + (dir_ / "p.csv").string() + " --summary " + sum.string()).code,
            0);
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

TEST_F(Cli, RunWritesTheListedOutputsAndCountsThem) {
  const fs::path scene = write("f.yaml", kFourbarOutputs), csv = dir_ / "f.csv", sum = dir_ / "sum.json";
  Result r = run("run -q --threads 1 " + scene.string() + " -o " + csv.string() + " --summary " + sum.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const phiq::CsvTable t = phiq::read_csv_table(csv.string());
  const std::vector<std::string> tail = {
      "B.x",      "B.y",  "B.vx", "B.vy", "P.x", "P.y", "P.vx", "P.vy", "motor.f", "motor.df", "rocker.residual",
      "residual", "rcond"};
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

namespace {

// `--set NAME=VALUE`: the run takes the parameters' values from the command line. The crank-slider's slider then
// follows the closed form of those lengths, x_B = L2 cos θ + √(L3² − L2² sin² θ) and its rate; `phiq plot` of a
// result that lacks coordinates (it sweeps the scene again for them) recognises it as the scene's only with the same
// --set.
TEST_F(Cli, SetGivesTheScenesParametersTheirValuesForTheRun) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  const fs::path csv = dir_ / "set.csv";
  Result r = run("run -q " + scene + " --set L2=0.25 --set L3=1.1 -o " + csv.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const phiq::CsvTable t = phiq::read_csv_table(csv.string());
  auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(t.columns.begin(), t.columns.end(), name) - t.columns.begin());
  };
  const std::size_t th = col("theta2"), thd = col("theta2.v"), xb = col("xB"), xbd = col("xB.v");
  ASSERT_EQ(t.rows.size(), 181u);
  const double l2 = 0.25, l3 = 1.1;
  for (const auto& row : t.rows) {
    const double s = std::sin(row[th]), c = std::cos(row[th]), root = std::sqrt(l3 * l3 - l2 * l2 * s * s);
    EXPECT_NEAR(row[xb], l2 * c + root, 1e-9) << "t = " << row[0];
    EXPECT_NEAR(row[xbd], (-l2 * s - l2 * l2 * s * c / root) * row[thd], 1e-8) << "t = " << row[0];
  }
  // a result that writes the slider alone: the plot sweeps the scene again for the crank's position, and checks
  // the slider's column against its own sweep
  const fs::path slider = dir_ / "slider.yaml", slider_csv = dir_ / "slider.csv", svg = dir_ / "set.svg";
  std::ofstream(slider) << phiq::test::replace_first(slurp(scene), "output: {velocities: true, accelerations: true}",
                                                     "output: {coordinates: [xB]}");
  ASSERT_EQ(run("run -q " + slider.string() + " --set L2=0.25 --set L3=1.1 -o " + slider_csv.string()).code, 0);
  Result without = run("plot " + slider.string() + " " + slider_csv.string() + " -o " + svg.string());
  EXPECT_EQ(without.code, 2) << "the file's lengths do not give these rows";
  EXPECT_NE(without.err.find("is not the result of"), std::string::npos) << without.err;
  Result with = run("plot " + slider.string() + " " + slider_csv.string() + " -o " + svg.string() +
                    " --set L3=1.1 --set L2=0.25");
  EXPECT_EQ(with.code, 0) << with.err;
}

}  // namespace

namespace {

// `--sensitivity NAME[=STEP]`: the run delivers the sensitivities a scene's output.sensitivities would, the same
// columns and bytes, here with --set's L2 kept when the scene is read again along L3; refused in one line (exit 2,
// no output) for a name that is no parameter, one asked for twice and a step that is not a number.
TEST_F(Cli, SensitivityOptionDeliversWhatTheScenesOutputWould) {
  const std::string scene = phiq::test::model_path("seed/crank_slider_mixed.yaml");
  const fs::path listed = dir_ / "listed.yaml", by_text = dir_ / "text.csv", by_option = dir_ / "option.csv";
  std::ofstream(listed) << phiq::test::replace_first(
      slurp(scene), "output: {velocities: true, accelerations: true}",
      "output: {velocities: true, accelerations: true, sensitivities: [L2, {parameter: L3, step: 0.01}]}");
  ASSERT_EQ(run("run -q " + listed.string() + " --set L2=0.25 -o " + by_text.string()).code, 0);
  const Result r =
      run("run -q " + scene + " --set L2=0.25 --sensitivity L2 --sensitivity L3=0.01 -o " + by_option.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string text = slurp(by_option);
  EXPECT_EQ(text, slurp(by_text));
  EXPECT_NE(text.find(",xB.d_L2,"), std::string::npos);
  EXPECT_NE(text.find(",xB.a.d_L3\n"), std::string::npos);
  const phiq::CsvTable t = phiq::read_csv_table(by_option.string());
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(t.columns.begin(), t.columns.end(), name) - t.columns.begin());
  };
  const double l2 = 0.25, l3 = 1.0;
  for (const auto& row : t.rows) {  // ∂x_B/∂L3 = L3 / √(L3² − L2² sin² θ)
    const double s = std::sin(row[col("theta2")]);
    EXPECT_NEAR(row[col("xB.d_L3")], l3 / std::sqrt(l3 * l3 - l2 * l2 * s * s), 1e-9) << "t = " << row[0];
  }
  const fs::path none = dir_ / "none.csv";
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--sensitivity L9", "--sensitivity: 'L9' is not a parameter of " + scene + " (its parameters: L2, L3"},
           {"--sensitivity L2 --sensitivity L2=0.1", "--sensitivity: parameter 'L2' is asked for twice"},
           {"--sensitivity L2=fast", "--sensitivity L2=fast: 'fast' is not a number"},
           {"--sensitivity L2=-1", "--sensitivity: the step of 'L2' must be a positive finite number"}}) {
    const Result bad = run("run -q " + scene + " " + args + " -o " + none.string());
    EXPECT_EQ(bad.code, 2) << args;
    EXPECT_NE(bad.err.find(says), std::string::npos) << bad.err;
    EXPECT_TRUE(phiq::test::one_phiq_line(bad.err)) << bad.err;
    EXPECT_FALSE(fs::exists(none)) << args;
  }
}

}  // namespace
