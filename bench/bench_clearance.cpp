// Clearance along the motion (issue 50, "Measure"): nfourbar N with a capsule (radius 0.05) along each of its
// 2N + 1 links, `pairs: all, skip: adjacent`, threshold 0.01: the clearance pass over a sweep's rows (broad phase,
// distances, refinement, the bound between rows) per row, against the kinematic step that made the rows (q, q̇, q̈).
// The target: clearance per row ≤ 2 kinematic steps.
#include <benchmark/benchmark.h>

#include <cmath>

#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;

constexpr Index kClearanceSteps = 100;

// A link from the point `from` toward `to` (natural coordinates) carrying a capsule of radius 0.05 along it.
Part clearance_link(const std::string& name, Point2 from, Point2 to) {
  Part p;
  p.name = name;
  p.frame.kind = PartFrameKind::kPoints;
  p.frame.origin = Attachment3::natural(Point3{from.x, from.y, Slot::constant(0.0)});
  p.frame.x_toward = Attachment3::natural(Point3{to.x, to.y, Slot::constant(0.0)});
  Shape capsule;
  capsule.kind = ShapeKind::kCapsule;
  capsule.radius = 0.05;
  capsule.length = 1.0;
  capsule.at = {0.5, 0, 0};
  capsule.rotation = {0, 0, 1, 0, 1, 0, -1, 0, 0};  // the capsule's axis along the link
  p.shapes.push_back(capsule);
  return p;
}

// The cranks (pivot (i, 0) to tip P_i) and couplers (P_i to P_{i+1}) of bench/nfourbar_model.hpp's model.
std::vector<Part> clearance_links(Index n) {
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  std::vector<Part> parts;
  for (Index i = 0; i <= n; ++i)
    parts.push_back(
        clearance_link("crank" + std::to_string(i), {C(static_cast<double>(i)), C(0)}, {S(2 * i), S(2 * i + 1)}));
  for (Index i = 0; i < n; ++i)
    parts.push_back(
        clearance_link("coupler" + std::to_string(i), {S(2 * i), S(2 * i + 1)}, {S(2 * i + 2), S(2 * i + 3)}));
  return parts;
}

SweepOptions clearance_sweep_options() {
  SweepOptions o;
  o.t_begin = 0.0;
  o.t_end = 1.0;
  o.steps = kClearanceSteps;
  o.velocities = o.accelerations = true;
  return o;
}

ClearanceRows clearance_rows_of(const Model& model) {
  Workspace ws(model);
  return sweep_rows(model, clearance_sweep_options(), ws);
}

// The kinematic step: the sweep that makes the rows, per row.
void BM_ClearanceKinematicStep(benchmark::State& state) {
  const Model model = phiq_bench::nfourbar(state.range(0), M_PI / 4, M_PI / 2);
  for (auto _ : state) benchmark::DoNotOptimize(clearance_rows_of(model).t.size());
  state.counters["per_row_us"] =
      benchmark::Counter(static_cast<double>(kClearanceSteps + 1) * 1e-6,
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ClearanceKinematicStep)->ArgName("N")->Arg(1000)->Unit(benchmark::kMillisecond);

// The clearance pass over those rows, per row: every non-adjacent pair through the broad phase.
void BM_ClearancePerRow(benchmark::State& state) {
  const Index n = state.range(0);
  const Model model = phiq_bench::nfourbar(n, M_PI / 4, M_PI / 2);
  const std::vector<Part> parts = clearance_links(n);
  const ClearanceRows rows = clearance_rows_of(model);
  ClearancePlan plan;
  plan.requested = plan.all = plan.skip_adjacent = true;
  plan.threshold = 0.01;
  ClearanceReport report;
  for (auto _ : state) report = clearance_along(model, parts, plan, rows);
  state.counters["per_row_us"] =
      benchmark::Counter(static_cast<double>(kClearanceSteps + 1) * 1e-6,
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["pairs_selected"] = static_cast<double>(report.pairs_selected);
  state.counters["pairs_measured"] = static_cast<double>(report.pairs_measured);
  state.counters["pairs_reported"] = static_cast<double>(report.pairs.size());
  state.counters["bound_held"] = report.bound_held() ? 1 : 0;
}
BENCHMARK(BM_ClearancePerRow)->ArgName("N")->Arg(10)->Arg(1000)->Unit(benchmark::kMillisecond);

}  // namespace
