// Output selection (OutputPlan: coordinate, velocity and acceleration columns by name and shell pattern, every k-th
// row, a time window): the columns are exactly those selected, the rows written are the same bits as in the sweep
// that writes every row, and the rows not written cost no output evaluations (exact counts).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// A four-bar in mixed coordinates whose names share prefixes (x1, x10, x2 …), so that patterns have something
// to tell apart. Crank tip A = 0.4 (cos θ, sin θ).
std::string scene(const std::string& output, int steps = 24) {
  return R"(
phiq: 1
parameters: {L1: 1.0, L2: 0.4, L3: 1.2, L4: 1.0}
coordinates: {theta: 0.0, x1: 0.4, y1: 0.0, x10: 1.1, y10: 1.0, x2: 0.7, y2: 0.5, psi: 1.0}
points: {O: [0, 0], A: [x1, y1], B: [x10, y10], C: [L1, 0]}
bodies: {coupler: [x2, y2, psi]}
constraints:
  - {name: crank, type: polar, point: A, origin: O, length: L2, angle: theta}
  - {name: pinA, type: revolute, between: [{body: coupler, at: [-L3/2, 0]}, {point: A}]}
  - {name: pinB, type: revolute, between: [{body: coupler, at: [L3/2, 0]}, {point: B}]}
  - {name: rocker, type: distance, points: [C, B], length: L4}
drivers:
  - {name: motor, coordinate: theta, law: {type: linear, initial: 0, rate: 3}}
time: {start: 0, end: 2, steps: )" +
         std::to_string(steps) + R"(}
output: )" +
         output + "\n";
}

std::string refusal_of(const std::string& output) {
  try {
    parse_scene(scene(output), "sel.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(OutputSelection, NamesAndPatternsSelectColumnsInSceneOrder) {
  const Scene s = parse_scene(
      scene("{coordinates: ['x1*', theta, '?2'], velocities: ['y?'], accelerations: [psi, 'x1']}"), "sel.yaml");
  EXPECT_EQ(CsvFormat(*s.model, s.sweep).header(), "t,x1,x10,theta,x2,y2,y1.v,y2.v,psi.a,x1.a\n");
  // a coordinate a pattern selects again is not repeated; `true` writes the coordinates' derivatives
  const Scene t = parse_scene(scene("{coordinates: [theta, 'th*', 'y[12]'], velocities: true}"), "sel.yaml");
  EXPECT_EQ(CsvFormat(*t.model, t.sweep).header(), "t,theta,y1,y2,theta.v,y1.v,y2.v\n");
  // derivatives solved for the points, none written for the coordinates
  const Scene u = parse_scene(scene("{coordinates: [theta], velocities: [], points: [B]}"), "sel.yaml");
  EXPECT_EQ(CsvFormat(*u.model, u.sweep).header(), "t,theta,B.x,B.y,B.vx,B.vy\n");
  EXPECT_TRUE(u.sweep.velocities);
}

TEST(OutputSelection, BadSelectionsAreOneLineErrorsNamingTheField) {
  EXPECT_NE(refusal_of("{coordinates: ['z*']}").find("output.coordinates[0]: pattern 'z*' selects no coordinate"),
            std::string::npos)
      << refusal_of("{coordinates: ['z*']}");
  EXPECT_NE(refusal_of("{velocities: [theta, 'q?']}").find("output.velocities[1]: pattern 'q?' selects no coordinate"),
            std::string::npos)
      << refusal_of("{velocities: [theta, 'q?']}");
  EXPECT_NE(refusal_of("{accelerations: [nope]}").find("unknown coordinate 'nope'"), std::string::npos);
  EXPECT_NE(refusal_of("{coordinates: [x1, x1]}").find("listed twice"), std::string::npos);
  EXPECT_NE(refusal_of("{every: 0}").find("output.every"), std::string::npos) << refusal_of("{every: 0}");
  EXPECT_NE(refusal_of("{window: [1, 0.5]}").find("output.window: begin must not be above end"), std::string::npos)
      << refusal_of("{window: [1, 0.5]}");
  EXPECT_NE(refusal_of("{window: [1]}").find("output.window: must be [begin, end] (s)"), std::string::npos);
}

struct SweptRows {
  std::vector<Index> steps;
  std::vector<Eigen::VectorXd> q, qd;
  std::vector<double> bx;  // the output point B's x
  SweepSummary sum;
};

SweptRows sweep(const Scene& s, int threads, Index chunk) {
  SweptRows w;
  SweepOptions opt = s.sweep;
  opt.threads = threads;
  opt.chunk_steps = chunk;
  Workspace ws(*s.model);
  const SolveStatus st = run_sweep(
      *s.model, opt, ws,
      [&](const StepView& v) {
        w.steps.push_back(v.step);
        w.q.push_back(v.q);
        w.qd.push_back(*v.qd);
        w.bx.push_back(v.points[0].r[0]);
        return true;
      },
      &w.sum);
  EXPECT_EQ(st, SolveStatus::kSuccess) << w.sum.message;
  return w;
}

// Every 4th row within t ∈ [0.5, 1.5] of 24 steps over [0, 2] (h = 1/12): k = 8, 12, 16 (t = 2/3, 1, 4/3; k = 4
// is t = 1/3 and k = 20 is t = 5/3, outside). The same bits as those rows of the sweep that writes all, on one and
// two threads, in one chunk and in chunks of 5; points evaluated at the written rows only; every time point solved and
// counted.
TEST(OutputSelection, EveryKthRowInAWindowIsTheFullSweepsRowsAndCostsOnlyThem) {
  const Scene all = parse_scene(scene("{velocities: true, points: [B]}"), "sel.yaml");
  const Scene some = parse_scene(scene("{velocities: true, points: [B], every: 4, window: [0.5, 1.5]}"), "sel.yaml");
  for (Index chunk : {Index{24}, Index{5}}) {  // (the same chunk layout: rows are the same bits for each)
    const SweptRows full = sweep(all, 1, chunk);
    ASSERT_EQ(full.steps.size(), 25u);
    EXPECT_EQ(full.sum.counters.point_evaluations, 25);
    for (int threads : {1, 2}) {
      const SweptRows w = sweep(some, threads, chunk);
      ASSERT_EQ(w.steps, (std::vector<Index>{8, 12, 16})) << threads << " threads, chunk " << chunk;
      for (std::size_t i = 0; i < w.steps.size(); ++i) {
        const std::size_t k = static_cast<std::size_t>(w.steps[i]);
        EXPECT_EQ(w.q[i], full.q[k]);
        EXPECT_EQ(w.qd[i], full.qd[k]);
        EXPECT_EQ(w.bx[i], full.bx[k]);
        EXPECT_NEAR(w.q[i](0), 3.0 * static_cast<double>(k) / 12.0, 1e-12);  // θ = 3t
      }
      EXPECT_EQ(w.sum.steps_completed, 25);
      EXPECT_EQ(w.sum.counters.point_evaluations, 3);
      EXPECT_EQ(w.sum.accuracy.converged.rows + w.sum.accuracy.rounding_level.rows + w.sum.accuracy.singular.rows, 25);
    }
  }
}

}  // namespace
}  // namespace phiq
