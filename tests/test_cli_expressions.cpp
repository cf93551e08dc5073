// Scenes with expressions through `phiq run`: powers whose base passes through exactly 0 against their closed
// forms, and the same CSV bytes in every process (GiNaC's hash-ordered terms). Separate from test_cli_run.cpp:
// these are the audit's findings about the expression engine seen from the command, several processes each.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>

#include "phiq/csv_compare.hpp"

#include "cli_test_support.hpp"
#include "test_support.hpp"

namespace {

using phiq::test::Cli;
using phiq::test::Result;
using phiq::test::slurp;
namespace fs = std::filesystem;

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
  - {name: motor, coordinate: theta2, law: {type: expression, f: ")" +
                                             law + R"("}}
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

}  // namespace
