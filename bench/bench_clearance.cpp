// Clearance along the motion (issue 50, "Measure"): nfourbar N with a capsule (radius 0.05) along each of its
// 2N + 1 links, `pairs: all, skip: adjacent`, threshold 0.01: the clearance pass over a sweep's rows (broad phase,
// distances, refinement, the bound between rows) per row, against the kinematic step that made the rows (q, q̇, q̈).
// The target: clearance per row ≤ 2 kinematic steps. And 100 meshed parts of 10⁴ triangles each (BM_ClearanceMeshes):
// the same links as ellipsoids, triangulated, with the threshold wide enough that every neighbour's mesh distance is
// measured at every row, against the same links as capsules (FCL's primitives).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

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

// An ellipsoid of semi-axes (0.5, r, r) about (0.5, 0, 0), as a closed mesh of `slices` × 2 (`stacks` − 1) triangles
// (a fan at each pole): 100 slices and 51 stacks make 10⁴.
std::shared_ptr<const TriangleMesh> clearance_ellipsoid(double r, int slices, int stacks) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->vertices.push_back({0.0, 0, 0});  // the pole at x = 0
  for (int i = 1; i < stacks; ++i) {
    const double a = M_PI * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double b = 2 * M_PI * j / slices;
      mesh->vertices.push_back({0.5 - 0.5 * std::cos(a), r * std::sin(a) * std::cos(b), r * std::sin(a) * std::sin(b)});
    }
  }
  mesh->vertices.push_back({1.0, 0, 0});  // the pole at x = 1
  const int last = static_cast<int>(mesh->vertices.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * slices + (j % slices); };
  for (int j = 0; j < slices; ++j) {
    mesh->triangles.push_back({0, ring(1, j + 1), ring(1, j)});
    for (int i = 1; i + 1 < stacks; ++i) {
      mesh->triangles.push_back({ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)});
      mesh->triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)});
    }
    mesh->triangles.push_back({last, ring(stacks - 1, j), ring(stacks - 1, j + 1)});
  }
  return mesh;
}

// 100 links of nfourbar 50 (cranks 0–49, couplers 0–49), each an ellipsoid mesh of 10⁴ triangles (range 1) or a
// capsule (range 0), threshold 1 m: the broad phase keeps the neighbours (about 1 m apart), whose distances FCL
// measures at every one of 11 rows.
void BM_ClearanceMeshes(benchmark::State& state) {
  const bool meshes = state.range(0) == 1;
  const Index n = 50;
  const Model model = phiq_bench::nfourbar(n, M_PI / 4, M_PI / 2);
  std::vector<Part> parts = clearance_links(n);
  parts.erase(parts.begin() + n);  // crank 50: 100 parts
  const std::shared_ptr<const TriangleMesh> mesh = clearance_ellipsoid(0.05, 100, 51);
  if (meshes)
    for (Part& p : parts) {
      Shape& s = p.shapes[0];
      s = Shape{};
      s.kind = ShapeKind::kMesh;
      s.mesh = mesh;
    }
  SweepOptions o = clearance_sweep_options();
  o.steps = 10;
  Workspace ws(model);
  const ClearanceRows rows = sweep_rows(model, o, ws);
  ClearancePlan plan;
  plan.requested = plan.all = plan.skip_adjacent = true;
  plan.threshold = 1.0;
  ClearanceReport report;
  for (auto _ : state) report = clearance_along(model, parts, plan, rows);
  state.counters["per_row_ms"] =
      benchmark::Counter(static_cast<double>(o.steps + 1) * 1e-3,
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["triangles_per_part"] = meshes ? static_cast<double>(mesh->triangles.size()) : 0;
  state.counters["pairs_measured"] = static_cast<double>(report.pairs_measured);
  state.counters["pairs_reported"] = static_cast<double>(report.pairs.size());
  state.counters["positions_solved"] = static_cast<double>(report.positions_solved);
}
BENCHMARK(BM_ClearanceMeshes)->ArgName("meshes")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
