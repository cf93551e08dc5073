// A sweep gives the same bits on every run and every thread count: the rows (q, q̇, q̈, Φ, points, rcond), the
// summary's counts and its warnings, for every scene under models/ and for the two-turn sweep of nfourbar through
// its flat positions (with a chunk starting exactly on one). Regression suites compare results byte for byte; the
// chunk layout is a function of the scene and the options only (sweep/resources.hpp), and a chunk computes the same
// rows whichever thread and workspace run it (Workspace::start_afresh).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

namespace fs = std::filesystem;

// Everything a sweep delivers and reports but its timings and thread count, as bytes.
struct Record {
  std::string rows;     // every delivered row's numbers, as their bytes
  std::string summary;  // status, message, counts, accuracy, warnings
};

void append(std::string& out, const double* v, std::size_t n) {
  out.append(reinterpret_cast<const char*>(v), n * sizeof(double));
}

Record record(const Model& model, SweepOptions opt, int threads, Workspace* reuse = nullptr,
              const Eigen::VectorXd* start = nullptr) {
  opt.threads = threads;
  Record r;
  Workspace local(model);
  Workspace& ws = reuse ? *reuse : local;
  if (start) ws.q = *start;
  SweepSummary sum;
  const SolveStatus st = run_sweep(
      model, opt, ws,
      [&](const StepView& s) {
        const double head[3] = {static_cast<double>(s.step), s.t, s.rcond};
        append(r.rows, head, 3);
        append(r.rows, s.q.data(), static_cast<std::size_t>(s.q.size()));
        if (s.qd) append(r.rows, s.qd->data(), static_cast<std::size_t>(s.qd->size()));
        if (s.qdd) append(r.rows, s.qdd->data(), static_cast<std::size_t>(s.qdd->size()));
        if (s.phi) append(r.rows, s.phi->data(), static_cast<std::size_t>(s.phi->size()));
        if (s.points) append(r.rows, s.points[0].r.data(), 9 * opt.points.size());
        if (s.efforts)  // efforts, powers, reactions and their sensitivities
          append(r.rows, s.efforts, static_cast<std::size_t>(effort_values(opt.efforts, opt.sensitivities.size())));
        return true;
      },
      &sum);
  std::ostringstream o;
  o.precision(17);
  const WorkCounters& c = sum.counters;
  o << to_string(st) << '|' << sum.message << '|' << sum.steps_completed << '|' << sum.failed_step << '|'
    << sum.subdivisions << '|' << sum.singular_positions << '|' << sum.min_rcond << '@' << sum.min_rcond_time << '|'
    << sum.parallel_chunks << '|' << c.newton_iterations << ' ' << c.residual_evaluations << ' '
    << c.jacobian_evaluations << ' ' << c.factorizations << ' ' << c.pivoting_factorizations << ' ' << c.velocity_solves
    << ' ' << c.acceleration_solves << ' ' << c.phi_t_evaluations << ' ' << c.gamma_evaluations << ' '
    << c.point_evaluations;
  for (const RowClassAccuracy* a : {&sum.accuracy.converged, &sum.accuracy.rounding_level, &sum.accuracy.singular})
    o << '|' << a->rows << ' ' << a->worst_error << '@' << a->worst_time << ' ' << a->unestimated << ' '
      << a->worst_coordinate << ' ' << a->worst_known_to;
  for (const SweepWarning& w : sum.warnings) o << '\n' << w.t << ' ' << w.kind << ' ' << w.message;
  r.summary = o.str();
  return r;
}

// The same record for 1, 2, 3 and 8 threads, and for a repeated run on 2 threads in a workspace that has swept
// before (its factorisation and pivot order are another sweep's).
void expect_deterministic(const Model& model, const SweepOptions& opt, const std::string& what,
                          const Eigen::VectorXd* start = nullptr) {
  const Record one = record(model, opt, 1, nullptr, start);
  ASSERT_FALSE(one.rows.empty()) << what;
  for (int threads : {2, 3, 8}) {
    const Record r = record(model, opt, threads, nullptr, start);
    EXPECT_EQ(r.summary, one.summary) << what << ", " << threads << " threads";
    EXPECT_TRUE(r.rows == one.rows) << what << ": the rows on " << threads << " threads differ from one thread's";
  }
  Workspace used(model);
  record(model, opt, 2, &used, start);
  const Record again = record(model, opt, 2, &used, start ? start : &model.initial_positions());
  EXPECT_EQ(again.summary, one.summary) << what << ", repeated in a used workspace";
  EXPECT_TRUE(again.rows == one.rows) << what << ": the rows repeated in a used workspace differ";
}

TEST(SweepDeterminism, EveryModelsSceneGivesTheSameBitsOnEveryThreadCount) {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::recursive_directory_iterator(PHIQ_MODELS_DIR))
    if (e.path().extension() == ".yaml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 20u);
  for (const fs::path& p : scenes) {
    const Scene sc = load_scene(p.string());
    // prepared as `phiq run` prepares it: redundant rows dropped, from the assembled position
    Eigen::VectorXd q = sc.model->initial_positions();
    std::unique_ptr<Model> solved;
    AssemblySummary assembly;
    // a failure leaves `solved` null, checked next
    (void)prepare_square(*sc.model, sc.sweep.t_begin, {}, q, &solved, &assembly);
    if (!solved) continue;  // (an inconsistent model by design: no sweep)
    SweepOptions opt = sc.sweep;
    opt.steps = std::min<Index>(opt.steps, 400);  // (the scene's own step; short of its end on the longest)
    opt.t_end = opt.t_begin + (sc.sweep.t_end - sc.sweep.t_begin) * static_cast<double>(opt.steps) /
                                  static_cast<double>(std::max<Index>(sc.sweep.steps, 1));
    expect_deterministic(*solved, opt, p.filename().string(), &q);
  }
}

// Efforts and every joint's reaction of a natural nfourbar with masses (its joints' sums, the rigid bars' Q, shared by
// the chunks), as run_sweep delivers them: the same bytes on every thread count.
TEST(SweepDeterminism, NaturalJointsReactionsGiveTheSameBitsOnEveryThreadCount) {
  const std::string bar = "mass: 1, center_of_mass: [0.5, 0.1], inertia: 0.08}\n";
  const Scene s = parse_scene(
      "phiq: 1\nparameters: {N: 60}\ncoordinates:\n  for i in 0..N:\n    x{i}: i + 0.7071067811865476\n"
      "    y{i}: 0.7071067811865475\n  theta: 0.7853981633974483\npoints:\n  O: [0, 0]\n  for i in 0..N:\n"
      "    P{i}: [\"x{i}\", \"y{i}\"]\nconstraints:\n  - for i in 0..N:\n      - {name: \"crank{i}\", type: distance, "
      "points: [[i, 0], \"P{i}\"], length: 1}\n  - for i in 0..N-1:\n      - {name: \"coupler{i}\", type: distance, "
      "points: [\"P{i}\", \"P{i+1}\"], length: 1}\n  - {name: crank0_angle, type: segment_angle, segment: [O, P0], "
      "angle: theta}\ndrivers:\n  - {name: motor, coordinate: theta, law: {type: linear, initial: "
      "0.7853981633974483, rate: 1.5707963267948966}}\ntime: {start: 0, end: 1, steps: 600}\nparts:\n"
      "  for i in 0..N:\n    \"crank{i}\": {frame: {origin: [i, 0], x: \"P{i}\"}, " +
          bar + "  for i in 0..N-1:\n    \"coupler{i}\": {frame: {origin: \"P{i}\", x: \"P{i+1}\"}, " + bar +
          "loads: {gravity: [0.3, -9.81]}\n"
          "output: {velocities: true, accelerations: true, efforts: all, power: true, reactions: all}\n",
      "nfourbar_reactions.yaml");
  ASSERT_EQ(s.sweep.efforts.reactions.size(), 62u);  // O (crank 0's pivot) and P0 … P60, each on its crank
  SweepSummary sum;
  SweepOptions two = s.sweep;
  two.threads = 2;
  Workspace ws(*s.model);
  ASSERT_EQ(run_sweep(
                *s.model, two, ws, [](const StepView&) { return true; }, &sum),
            SolveStatus::kSuccess);
  EXPECT_GT(sum.parallel_chunks, 1);  // (the chunks' sweepers share the set-up)
  expect_deterministic(*s.model, s.sweep, "natural nfourbar 60 with reactions");
}

// nfourbar N = 100 over two turns from θ = π/4, positions only: 1440 steps put the four flat positions on rows 270,
// 630, 990 and 1350; 1712 steps put the first one on row 321, where a chunk of 64 steps would start.
TEST(SweepDeterminism, TwoTurnsThroughTheFlatPositionsGiveTheSameBitsOnEveryThreadCount) {
  const double th0 = M_PI / 4, rate = 4 * M_PI;
  const Model m = test::nfourbar_model(100, th0, rate);
  for (Index steps : {Index{1440}, Index{1712}}) {
    SweepOptions opt;
    opt.steps = steps;
    opt.velocities = opt.accelerations = false;
    expect_deterministic(m, opt, std::to_string(steps) + " steps, positions only");
  }
  SweepOptions opt;
  opt.steps = 1712;
  expect_deterministic(m, opt, "1712 steps with q̇ and q̈");
}

// A row exactly on a singular position is solved in order inside a chunk, never as a chunk's first row: the
// chunk that would start there starts a row later. Its q is as accurate as on any other row, and its q̇ and q̈
// (extrapolated from both sides) equal the parallelogram branch's to 1e-8 relative.
TEST(SweepDeterminism, ARowOnASingularPositionIsAsAccurateWhereAChunkWouldStart) {
  const double th0 = M_PI / 4, rate = 4 * M_PI;
  const Model m = test::nfourbar_model(100, th0, rate);
  const auto exact = test::nfourbar_exact(m, th0, rate);
  SweepOptions opt;
  opt.steps = 1712;
  opt.threads = 2;
  test::Trace tr;
  SweepSummary sum;
  ASSERT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  EXPECT_EQ(sum.singular_positions, 4);
  EXPECT_EQ(sum.parallel_chunks, (opt.steps + 63) / 64) << "every chunk continues the one before";
  const Index n = m.num_coordinates();
  Eigen::VectorXd q(n), v(n), a(n);
  for (Index k : {Index{321}, Index{749}, Index{1177}, Index{1605}}) {  // θ = π, 2π, 3π, 4π
    const auto i = static_cast<std::size_t>(k);
    exact->evaluate(tr.t[i], q.data(), v.data(), a.data());
    EXPECT_LT((tr.q[i] - q).cwiseAbs().maxCoeff(), 1e-9) << "row " << k;
    EXPECT_LT((tr.qd[i] - v).cwiseAbs().maxCoeff(), 1e-8 * v.cwiseAbs().maxCoeff()) << "row " << k;
    EXPECT_LT((tr.qdd[i] - a).cwiseAbs().maxCoeff(), 1e-8 * a.cwiseAbs().maxCoeff()) << "row " << k;
  }
}

// The chunks and seeds refactorise with one pivot order, that of Φq at row 0, pinned in every workspace, instead of
// each searching for pivots afresh (which cost 7–17 % of a 2-thread sweep): away from singular positions the
// searches counted are row 0's and those where its order degraded. The rows stay those of one thread (above).
TEST(SweepDeterminism, ChunksRefactoriseWithRowZerosPivotOrder) {
  const double th0 = M_PI / 4, rate = 4 * M_PI;
  const Model m = test::nfourbar_model(100, th0, rate);
  SweepOptions opt;
  opt.steps = 640;
  opt.t_end = 0.1;  // θ from 45° to 117°: no flat position
  for (int threads : {1, 2}) {
    opt.threads = threads;
    SweepSummary sum;
    test::Trace tr;
    ASSERT_EQ(test::sweep(m, opt, &tr, &sum), SolveStatus::kSuccess) << sum.message;
    ASSERT_GE(sum.parallel_chunks, 8) << threads << " threads";
    // row 0's search, and a few where row 0's order degraded (5 of 16 chunks), not one or two per chunk
    EXPECT_LT(sum.counters.pivoting_factorizations, sum.parallel_chunks / 2) << threads << " threads";
    EXPECT_GT(sum.counters.factorizations, 640) << threads << " threads";
  }
}

}  // namespace
}  // namespace phiq
