// No allocation inside the Newton loop (issue 4): every heap allocation of the process is counted while a solve or
// a sweep runs on a workspace that has solved before, and a step must add none. This file is its own executable
// (phiq_allocation_tests): it replaces malloc and its kin for the whole process, forwarding to glibc's, which the
// other suites do not need and which the sanitizer builds, whose runtime replaces malloc itself, cannot have.
//
// What a workspace does allocate, and is allowed to: its first factorisation (KLU's pivot search allocates per
// block) and its first refactorisation (the row scales it keeps), a sweep's own buffers (the predictor's history,
// once per sweep), a full KLU factorisation where the refactorisation's pivots degraded, the text of a warning.
// None of these grows with the number of steps.
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "phiq/phiq.hpp"
#include "../bench/nfourbar_model.hpp"

#if !defined(__GLIBC__)
#error "phiq_allocation_tests counts allocations through glibc's __libc_malloc family"
#endif

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};
void count() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

// Every thread's allocations (a large model evaluates its constraints on TBB's threads). operator new reaches
// malloc through libstdc++, Eigen's vectors too.
extern "C" {
void* malloc(std::size_t n) {
  count();
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) {
  count();
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) {
  count();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) {
  count();
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {
  count();
  return __libc_memalign(a, n);
}
int posix_memalign(void** p, std::size_t a, std::size_t n) {
  count();
  *p = __libc_memalign(a, n);
  return *p ? 0 : ENOMEM;
}
void free(void* p) { __libc_free(p); }
}

namespace phiq {
namespace {

// The allocations made while f() runs, on every thread.
template <class F>
long allocations_of(F&& f) {
  g_allocations = 0;
  g_counting = true;
  f();
  g_counting = false;
  return g_allocations.load();
}

// The counter itself counts: an Eigen vector, a std::string and a std::vector each allocate once.
TEST(Allocations, TheCounterSeesEigenAndTheStandardLibrary) {
  static volatile double sink = 0;
  EXPECT_EQ(allocations_of([] {
              const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(1000, 0.0, 1.0);
              const std::string s(100, 'x');
              const std::vector<int> w(10, 1);
              sink = v.sum() + static_cast<double>(s.size()) + w[3];
            }),
            3);
  EXPECT_GT(sink, 0.0);
}

struct Sweep {
  long allocations;
  WorkCounters work;
  SolveStatus status, warm_status;  // of the counted sweep and of the one before it
};

// A sweep of `steps` steps on one thread from `start`, counted, on a workspace that has swept the same from there
// before (its first factorisation and KLU's pivot search behind it).
Sweep counted_sweep_from(const Model& m, SweepOptions opt, Index steps, const Eigen::VectorXd& start) {
  Workspace ws(m);
  opt.steps = steps;
  opt.threads = 1;
  if (opt.chunk_steps == 0) opt.chunk_steps = steps;  // one chunk, in order (a chunk's pivot search allocates)
  ws.q = start;
  SweepSummary warm, sum;
  const SolveStatus warm_status = run_sweep(m, opt, ws, nullptr, &warm);
  ws.q = start;
  SolveStatus st = SolveStatus::kSuccess;
  const long a = allocations_of([&] { st = run_sweep(m, opt, ws, nullptr, &sum); });
  return {a, sum.counters, st, warm_status};
}

// The same from the model's initial positions (nfourbar over a quarter turn), both sweeps succeeding.
Sweep counted_sweep(const Model& m, const SweepOptions& opt, Index steps) {
  const Sweep s = counted_sweep_from(m, opt, steps, m.initial_positions());
  EXPECT_EQ(s.warm_status, SolveStatus::kSuccess);
  EXPECT_EQ(s.status, SolveStatus::kSuccess);
  return s;
}

// What one pivot search of KLU allocates on `m` (its numeric object), from a workspace that has factorised before:
// every sweep makes one as it starts afresh (Workspace::start_afresh), and so does every chunk and seed.
long pivot_search_allocations(const Model& m) {
  Workspace ws(m);
  LinearSummary ls;
  EXPECT_EQ(solve_velocity(m, 0.0, ws, &ls), SolveStatus::kSuccess) << ls.message;
  return allocations_of([&] {
    ws.start_afresh();
    EXPECT_EQ(solve_velocity(m, 0.0, ws, &ls), SolveStatus::kSuccess) << ls.message;
  });
}

// With KLU (the default) a step allocates nothing: sweeps of 100, 200 and 400 steps make the same allocations
// (the sweep's own buffers, a handful, and the pivot search of its first factorisation), whatever the predictor and
// the outputs, while their factorisations and Newton steps grow with the steps.
TEST(Allocations, AStepAllocatesNothing) {
  const Model m = phiq_bench::nfourbar(100, M_PI / 4, M_PI / 2);
  const long pivot_search = pivot_search_allocations(m);
  SweepOptions qva, previous, positions;
  previous.predictor = Predictor::kPrevious;  // several full Newton steps a row
  positions.velocities = positions.accelerations = false;
  for (const auto& [name, opt] : {std::pair{"q, q̇, q̈", qva}, {"previous", previous}, {"positions", positions}}) {
    const Sweep s100 = counted_sweep(m, opt, 100), s200 = counted_sweep(m, opt, 200), s400 = counted_sweep(m, opt, 400);
    // (KLU searches for pivots again where the pivots degrade: 2 or 3 times over this quarter turn)
    auto besides = [&](const Sweep& s) { return s.allocations - pivot_search * s.work.pivoting_factorizations; };
    EXPECT_EQ(besides(s200), besides(s100)) << name;
    EXPECT_EQ(besides(s400), besides(s100)) << name;
    EXPECT_LE(besides(s100), 16) << name << ": " << s100.allocations << " allocations, "
                                 << s100.work.pivoting_factorizations << " pivot searches of " << pivot_search;
    EXPECT_GT(s400.work.residual_evaluations + s400.work.factorizations,
              s100.work.residual_evaluations + s100.work.factorizations + 250)
        << name;
  }
  EXPECT_GT(counted_sweep(m, previous, 400).work.newton_iterations, 1000);
  EXPECT_EQ(counted_sweep(m, qva, 400).work.factorizations, 401);
}

// The public solves on a workspace that has solved: a position by Newton from the previous one, its velocity and
// its acceleration allocate nothing, also where the model is large enough to be evaluated on TBB's threads (more
// than 65536 constraints).
// In chunks (the layout every thread count shares), what allocates is a chunk's start — the pivot searches of its
// and its seed's fresh factorisations (Workspace::start_afresh), its stepper's buffers — and a pivot search where
// the pivots degraded, never a step: with four chunks, sweeps of 100, 200 and 400 steps make the same allocations
// besides their pivot searches.
TEST(Allocations, InChunksAChunkAllocatesAndAStepNothing) {
  const Model m = phiq_bench::nfourbar(100, M_PI / 4, M_PI / 2);
  const long pivot_search = pivot_search_allocations(m);
  long first = -1;
  for (Index steps : {Index{100}, Index{200}, Index{400}}) {
    SweepOptions opt;
    opt.chunk_steps = steps / 4;
    const Sweep s = counted_sweep(m, opt, steps);
    const long besides = s.allocations - pivot_search * s.work.pivoting_factorizations;
    if (first < 0) first = besides;
    EXPECT_EQ(besides, first) << steps << " steps: " << s.allocations << " allocations, "
                              << s.work.pivoting_factorizations << " pivot searches of " << pivot_search;
  }
}

TEST(Allocations, PositionVelocityAndAccelerationSolvesAllocateNothing) {
  for (Index n : {Index{100}, Index{33000}}) {
    const Model m = phiq_bench::nfourbar(n, M_PI / 4, M_PI / 2);
    Workspace ws(m);
    NewtonOptions newton;
    PositionSummary ps;
    LinearSummary ls;
    // Warming up: the initial positions solve t = 0 exactly, so the velocity there makes the first factorisation
    // (KLU's pivot search), and the first refactorisation after it keeps KLU's row scales.
    ASSERT_EQ(solve_position(m, 0.0, newton, ws, &ps), SolveStatus::kSuccess) << ps.message;
    ASSERT_EQ(solve_velocity(m, 0.0, ws, &ls), SolveStatus::kSuccess) << ls.message;
    ASSERT_EQ(solve_position(m, 0.01, newton, ws, &ps), SolveStatus::kSuccess) << ps.message;
    for (double t : {0.02, 0.04, 0.06}) {
      SolveStatus sp = SolveStatus::kSuccess, sv = SolveStatus::kSuccess, sa = SolveStatus::kSuccess;
      const long a = allocations_of([&] {
        sp = solve_position(m, t, newton, ws, &ps);
        sv = solve_velocity(m, t, ws, &ls);
        sa = solve_acceleration(m, t, ws, &ls);
      });
      ASSERT_EQ(sp, SolveStatus::kSuccess) << ps.message;
      ASSERT_EQ(sv, SolveStatus::kSuccess) << ls.message;
      ASSERT_EQ(sa, SolveStatus::kSuccess) << ls.message;
      EXPECT_GE(ps.iterations, 2) << "N = " << n << ", t = " << t;
      EXPECT_EQ(a, 0) << "N = " << n << ", t = " << t;
    }
  }
}

// UMFPACK has no refactorisation in place: umfpack_dl_numeric allocates its Numeric object at every numeric
// factorisation (one reason KLU is the default, bench/README.md). Nothing else does: a sweep's allocations are a
// constant plus the same number per factorisation, exactly.
TEST(Allocations, WithUmfpackOnlyItsNumericFactorisationAllocates) {
  const Model m = phiq_bench::nfourbar(100, M_PI / 4, M_PI / 2, LinearSolverKind::kUmfpack);
  const SweepOptions opt;
  const Sweep s1 = counted_sweep(m, opt, 100), s2 = counted_sweep(m, opt, 200), s4 = counted_sweep(m, opt, 400);
  const long f1 = s1.work.factorizations, f2 = s2.work.factorizations, f4 = s4.work.factorizations;
  ASSERT_GT(f2, f1);
  ASSERT_EQ((s2.allocations - s1.allocations) % (f2 - f1), 0);
  const long per_factorisation = (s2.allocations - s1.allocations) / (f2 - f1);
  EXPECT_GT(per_factorisation, 0);
  EXPECT_EQ(s4.allocations - s1.allocations, per_factorisation * (f4 - f1));
  EXPECT_LE(s1.allocations - per_factorisation * f1, 16);  // the sweep's own buffers, as with KLU
}

// Every scene of models/ (prepared as `phiq run` prepares it): four times the steps over the same motion add fewer
// allocations than steps (a full refactorisation where the pivots degraded, a warning's text; not one per step).
// Two scenes are errors by design and are expected to stay so: an inconsistent redundant door, and a drive that
// runs into a dead point.
TEST(Allocations, EveryModelsSceneAllocatesLessThanOncePerStep) {
  const std::set<std::string> errors_by_design = {"door_misaligned.yaml", "crank_rocker_rocker_driven.yaml"};
  std::vector<std::filesystem::path> scenes;
  for (const auto& e : std::filesystem::recursive_directory_iterator(PHIQ_MODELS_DIR))
    if (e.path().extension() == ".yaml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 20u);
  Index swept = 0;
  for (const std::filesystem::path& path : scenes) {
    const std::string rel = path.lexically_relative(PHIQ_MODELS_DIR).string();
    const bool error_by_design = errors_by_design.count(path.filename().string()) > 0;
    const Scene sc = load_scene(path.string());
    Eigen::VectorXd q = sc.model->initial_positions();
    std::unique_ptr<Model> solved;
    AssemblySummary assembly;
    // a failure leaves `solved` null, checked next
    (void)prepare_square(*sc.model, sc.sweep.t_begin, {}, q, &solved, &assembly);
    if (!solved) {
      EXPECT_TRUE(error_by_design) << rel << ": " << assembly.BriefReport();
      continue;
    }
    long a[2] = {0, 0};
    bool ok = true;
    for (int k = 0; k < 2 && ok; ++k) {
      const Sweep r = counted_sweep_from(*solved, sc.sweep, sc.sweep.steps * (k == 0 ? 1 : 4), q);
      ok = r.warm_status == SolveStatus::kSuccess;
      a[k] = r.allocations;
      EXPECT_EQ(r.status, r.warm_status) << rel;
    }
    EXPECT_EQ(ok, !error_by_design) << rel;
    if (!ok) continue;
    ++swept;
    EXPECT_LT(a[1] - a[0], 3 * sc.sweep.steps) << rel << ": " << a[0] << " and " << a[1] << " allocations";
  }
  EXPECT_EQ(swept, static_cast<Index>(scenes.size()) - 2);
}

}  // namespace
}  // namespace phiq
