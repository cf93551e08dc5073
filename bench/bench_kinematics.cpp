// Time per drive step (position + velocity + acceleration) and the cost of the engine around the sparse kernel.
//
//   ./build/bench/phiq_bench --benchmark_format=console
//
// Models are built in code (no scene loading in the timed region).
#include <benchmark/benchmark.h>

#include <klu.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <thread>
#include <tuple>
#include <vector>

#include <tbb/task_arena.h>

#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::nfourbar;

Model crank_slider() {
  ModelBuilder b;
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3), ya = b.add_coordinate("yA", 0.0),
        xb = b.add_coordinate("xB", 1.3);
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("motor", th, MotionLaw::linear(0.0, 2.0));
  return std::move(b).build();
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// One sweep of `m` from its initial positions, timed: its wall time in seconds (the summary in *sum).
double timed_sweep(const Model& m, const SweepOptions& opt, Workspace& ws,
                   const std::function<bool(const StepView&)>& on_step, SweepSummary* sum) {
  ws.q = m.initial_positions();
  const auto t0 = Clock::now();
  run_sweep(m, opt, ws, on_step, sum);
  return seconds_since(t0);
}

// The bare kernel: one numeric factorisation + solve of the Jacobian at ws.q with a separate numeric object (same
// symbolic analysis). Timed by the caller right next to the engine work, so that their ratio is measured in one
// run on this shared, noisy machine.
struct Kernel {
  explicit Kernel(const Model& m)
      : lu(m.symbolic()->make_numeric()), values(m.jacobian_pattern().nnz()), b(m.num_equations()),
        x(m.num_coordinates()) {
    b.setOnes();
  }
  double time_one(const Model& m, const Eigen::VectorXd& q) {
    m.jacobian(q.data(), 0.0, values.data());
    const auto t0 = Clock::now();
    lu->factorize(values.data());
    lu->solve(b.data(), x.data());
    benchmark::DoNotOptimize(x.data());
    return seconds_since(t0);
  }
  std::unique_ptr<SparseLuNumeric> lu;
  std::vector<double> values;
  Eigen::VectorXd b, x;
};

// Sweeps `steps` steps per benchmark iteration (manual time: the sweep only); reports the time per step, the work
// per step, and step_per_kernel = time per step / one bare factorise+solve at the same states, interleaved.
void run_steps(benchmark::State& state, const Model& m, Index steps, double t_end) {
  SweepOptions opt;
  opt.t_begin = 0.0;
  opt.t_end = t_end;
  opt.steps = steps;
  Workspace ws(m);
  Kernel kernel(m);
  SweepSummary sum;
  Index rows = 0;
  double sweep_s = 0.0, kernel_s = 0.0;
  Index kernels = 0;
  for (auto _ : state) {
    ws.q = m.initial_positions();
    const auto t0 = Clock::now();
    double in_kernel = 0.0;
    run_sweep(m, opt, ws, [&](const StepView& s) {
      // every 10th row, one bare kernel at this very state (its time is taken out of the sweep's)
      if (s.step % 10 == 0) {
        const auto k0 = Clock::now();
        kernel_s += kernel.time_one(m, s.q), ++kernels;
        in_kernel += seconds_since(k0);
      }
      return true;
    }, &sum);
    const double t = seconds_since(t0) - in_kernel;
    state.SetIterationTime(t);
    sweep_s += t;
    if (sum.status != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    rows += sum.steps_completed;
  }
  state.SetItemsProcessed(rows);
  state.counters["us_per_step"] = 1e6 * sweep_s / static_cast<double>(rows);
  state.counters["step_per_kernel"] = (sweep_s / static_cast<double>(rows)) / (kernel_s / static_cast<double>(kernels));
  state.counters["newton_per_step"] = static_cast<double>(sum.counters.newton_iterations) / (steps + 1);
  state.counters["factorizations_per_step"] = static_cast<double>(sum.counters.factorizations) / (steps + 1);
  state.counters["pivoting_per_step"] = static_cast<double>(ws.lu->pivoting_factorizations()) /
                                        static_cast<double>(state.iterations() * (steps + 1));
  state.counters["coordinates"] = static_cast<double>(m.num_coordinates());
}

void BM_CrankSliderSweepStep(benchmark::State& state) {
  Model m = crank_slider();
  run_steps(state, m, 180, M_PI);
}
BENCHMARK(BM_CrankSliderSweepStep)->UseManualTime();

// Second benchmark argument: the sparse LU.
LinearSolverKind kind_arg(const benchmark::State& state) { return static_cast<LinearSolverKind>(state.range(1)); }
void solver_args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"N", "lu"});
  for (int64_t n = 10; n <= 100000; n *= 10)
    for (LinearSolverKind k : {LinearSolverKind::kKlu, LinearSolverKind::kUmfpack}) b->Args({n, static_cast<int64_t>(k)});
}

// nfourbar, a quarter turn (π/4 → 3π/4) in 50 steps per iteration. lu: 0 UMFPACK, 1 KLU.
void BM_NFourBarSweepStep(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2, kind_arg(state));
  run_steps(state, m, 50, 1.0);
}
BENCHMARK(BM_NFourBarSweepStep)->Apply(solver_args)->Unit(benchmark::kMillisecond)->UseManualTime();

// KLU as it comes: klu_analyze, klu_factor once, then each time klu_refactor + klu_solve with KLU's defaults (its
// row scaling at every refactorisation), 32-bit, on the same matrix. The kernel a user calling the library gets,
// beside the one phiq configures (Kernel: refactorisations without scaling, its rcond and sign scan).
struct KluAsItComes {
  explicit KluAsItComes(const Model& m) : ap(m.jacobian_pattern().col_ptr.begin(), m.jacobian_pattern().col_ptr.end()),
                                          ai(m.jacobian_pattern().row_idx.begin(), m.jacobian_pattern().row_idx.end()),
                                          values(static_cast<std::size_t>(m.jacobian_pattern().nnz())),
                                          b(m.num_equations()), x(m.num_coordinates()) {
    klu_defaults(&common);
    symbolic = klu_analyze(static_cast<int>(x.size()), ap.data(), ai.data(), &common);
    b.setOnes();
  }
  ~KluAsItComes() {
    if (numeric) klu_free_numeric(&numeric, &common);
    klu_free_symbolic(&symbolic, &common);
  }
  double time_one(const Model& m, const Eigen::VectorXd& q) {
    m.jacobian(q.data(), 0.0, values.data());
    if (!numeric) numeric = klu_factor(ap.data(), ai.data(), values.data(), symbolic, &common);
    x = b;
    const auto t0 = Clock::now();
    klu_refactor(ap.data(), ai.data(), values.data(), symbolic, numeric, &common);
    klu_solve(symbolic, numeric, static_cast<int>(x.size()), 1, x.data(), &common);
    benchmark::DoNotOptimize(x.data());
    return seconds_since(t0);
  }
  std::vector<int> ap, ai;
  std::vector<double> values;
  Eigen::VectorXd b, x;
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
};

// Engine cost around the kernel: the engine's time per full-Newton iteration (Jacobian in place, factorise,
// solve, residual, convergence tests, line search) over a solve that takes several iterations from a perturbed
// start, against one bare factorise+solve of the same matrix, interleaved in the same loop. Reports both times and
// iteration_per_kernel; with KLU also the ratio to KLU as it comes (iteration_per_klu_defaults).
void BM_NFourBarNewtonIterationVsKernel(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2, kind_arg(state));
  Workspace ws(m);
  Kernel kernel(m);
  const bool klu = kind_arg(state) == LinearSolverKind::kKlu;
  KluAsItComes bare(m);
  Eigen::VectorXd start = m.initial_positions();
  for (Index j = 0; j < start.size(); ++j) start(j) += 1e-4 * std::sin(1.7 * static_cast<double>(j));
  NewtonOptions full;  // every iteration factorises (JacobianUpdate::kEveryIteration)
  double engine_s = 0.0, kernel_s = 0.0, bare_s = 0.0;
  Index iterations = 0;
  for (auto _ : state) {
    ws.q = start;
    ws.has_factorization = false;
    PositionSummary ps;
    const auto t0 = Clock::now();
    solve_position(m, 0.0, full, ws, &ps);
    const double e = seconds_since(t0);
    engine_s += e;
    iterations += ps.iterations;
    kernel_s += kernel.time_one(m, start);
    if (klu) bare_s += bare.time_one(m, start);
    state.SetIterationTime(e / std::max(1, ps.iterations));
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["newton_iterations"] = static_cast<double>(iterations) / it;
  state.counters["iteration_us"] = 1e6 * engine_s / static_cast<double>(iterations);
  state.counters["kernel_us"] = 1e6 * kernel_s / it;
  state.counters["iteration_per_kernel"] = (engine_s / static_cast<double>(iterations)) / (kernel_s / it);
  if (klu) {
    state.counters["klu_defaults_us"] = 1e6 * bare_s / it;
    state.counters["iteration_per_klu_defaults"] = (engine_s / static_cast<double>(iterations)) / (bare_s / it);
  }
}
BENCHMARK(BM_NFourBarNewtonIterationVsKernel)->Apply(solver_args)->Unit(benchmark::kMicrosecond)->UseManualTime();

// The model's passes over its constraints, as the Newton loop makes them: Φ and Φq fused (each iterate that will be
// factorised), Φ alone (the last trial point), Φq alone (a factorisation where no Φ is needed). cold 1: before each
// pass a 16 MB buffer is written, which evicts the constraints from the caches as a factorisation does between two
// iterates; cold 0: the passes run back to back on cached data. Reports each pass's time per call and per row.
void BM_NFourBarConstraintPasses(benchmark::State& state) {
  Model m = nfourbar(state.range(0), M_PI / 4, M_PI / 2);
  const bool cold = state.range(1) != 0;
  const Eigen::VectorXd q = m.initial_positions();
  Eigen::VectorXd phi(m.num_equations());
  std::vector<double> values(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  std::vector<double> evict(std::size_t{1} << 21, 1.0);
  auto flush = [&] {
    if (!cold) return;
    for (double& x : evict) x += 1.0;
    benchmark::DoNotOptimize(evict.data());
  };
  double fused_s = 0.0, residual_s = 0.0, jacobian_s = 0.0;
  for (auto _ : state) {
    flush();
    auto t0 = Clock::now();
    m.residual_and_jacobian(q.data(), 0.0, phi.data(), values.data());
    const double f = seconds_since(t0);
    flush();
    t0 = Clock::now();
    m.residual(q.data(), 0.0, phi.data());
    const double r = seconds_since(t0);
    flush();
    t0 = Clock::now();
    m.jacobian(q.data(), 0.0, values.data());
    const double j = seconds_since(t0);
    benchmark::DoNotOptimize(phi.data());
    benchmark::DoNotOptimize(values.data());
    fused_s += f, residual_s += r, jacobian_s += j;
    state.SetIterationTime(f);
  }
  const double it = static_cast<double>(state.iterations()), rows = static_cast<double>(m.num_equations());
  state.counters["fused_us"] = 1e6 * fused_s / it;
  state.counters["residual_us"] = 1e6 * residual_s / it;
  state.counters["jacobian_us"] = 1e6 * jacobian_s / it;
  state.counters["fused_ns_per_row"] = 1e9 * fused_s / it / rows;
}
BENCHMARK(BM_NFourBarConstraintPasses)
    ->ArgsProduct({{10, 1000, 10000, 100000}, {0, 1}})  // 10: the CI smoke size
    ->ArgNames({"N", "cold"})
    ->Unit(benchmark::kMicrosecond)
    ->UseManualTime();

// ---- The bare loop: hand-written Newton over KLU refactor -----------------------------------------------
//
// What a careful user writes by hand for nfourbar without phiq: Φ, Φq (CSC, pattern and klu_analyze once, values
// in place), Newton from the previous position until max |Δq| ≤ 1e-10 (2–3 iterations), then one more refactor at
// the converged position for velocity (Φq q̇ = −Φt) and acceleration (Φq q̈ = γ). Coordinates as nfourbar():
// x0, y0, …, xN, yN, θ; rows: crank i, coupler i, the crank-0 angle, the driver. Unscaled equations (‖·‖² − 1).
// KLU with 32-bit indices, as phiq uses it at these sizes (klu_lu.cpp), so that the two differ in the loop around
// the kernel, not in the kernel.
class BareLoop {
 public:
  BareLoop(Index n, double theta0, double rate) : n_(n), theta0_(theta0), rate_(rate) {
    const Index nc = 2 * (n + 1) + 1;
    dim_ = nc;
    // pattern: column-wise lists of (row) built from the row structure
    std::vector<std::vector<Index>> rows_of_col(static_cast<std::size_t>(nc));
    auto put = [&](Index r, Index c) { rows_of_col[static_cast<std::size_t>(c)].push_back(r); };
    Index r = 0;
    for (Index i = 0; i <= n; ++i, ++r) put(r, 2 * i), put(r, 2 * i + 1);                       // cranks
    for (Index i = 0; i < n; ++i, ++r) put(r, 2 * i), put(r, 2 * i + 1), put(r, 2 * i + 2), put(r, 2 * i + 3);  // couplers
    put(r, 0), put(r, 1), put(r, nc - 1), ++r;  // angle of crank 0
    put(r, nc - 1);                              // driver
    colp_.assign(static_cast<std::size_t>(nc + 1), 0);
    for (Index c = 0; c < nc; ++c) {
      std::sort(rows_of_col[static_cast<std::size_t>(c)].begin(), rows_of_col[static_cast<std::size_t>(c)].end());
      colp_[static_cast<std::size_t>(c + 1)] = colp_[static_cast<std::size_t>(c)] +
                                               static_cast<int>(rows_of_col[static_cast<std::size_t>(c)].size());
      for (Index rr : rows_of_col[static_cast<std::size_t>(c)]) rowi_.push_back(static_cast<int>(rr));
    }
    val_.assign(rowi_.size(), 0.0);
    klu_defaults(&common_);
    symbolic_ = klu_analyze(static_cast<int>(nc), colp_.data(), rowi_.data(), &common_);
    q_.resize(static_cast<std::size_t>(nc)), qd_ = q_, qdd_ = q_, phi_ = q_, dq_ = q_;
    reset();
  }
  ~BareLoop() {
    if (numeric_) klu_free_numeric(&numeric_, &common_);
    klu_free_symbolic(&symbolic_, &common_);
  }
  void reset() {
    for (Index i = 0; i <= n_; ++i) q_[2 * i] = static_cast<double>(i) + std::cos(theta0_), q_[2 * i + 1] = std::sin(theta0_);
    q_[static_cast<std::size_t>(dim_ - 1)] = theta0_;
  }
  // One drive step to time t: Newton from the previous position, then velocity and acceleration. Returns the
  // Newton iterations.
  int step(double t) {
    int it = 0;
    for (; it < 20; ++it) {
      residual(t);
      factor();
      for (Index i = 0; i < dim_; ++i) dq_[i] = -phi_[i];
      klu_solve(symbolic_, numeric_, dim(), 1, dq_.data(), &common_);
      double m = 0;
      for (Index i = 0; i < dim_; ++i) q_[i] += dq_[i], m = std::max(m, std::fabs(dq_[i]));
      if (m <= 1e-10) break;
    }
    factor();  // at the converged position
    for (Index i = 0; i < dim_; ++i) qd_[i] = 0.0;
    qd_[static_cast<std::size_t>(dim_ - 1)] = rate_;  // −Φt: only the driver row depends on t
    klu_solve(symbolic_, numeric_, dim(), 1, qd_.data(), &common_);
    gamma();
    klu_solve(symbolic_, numeric_, dim(), 1, qdd_.data(), &common_);
    return it + 1;
  }
  double position_error(double t) const {  // against the parallelogram solution
    const double th = theta0_ + rate_ * t;
    double e = 0;
    for (Index i = 0; i <= n_; ++i)
      e = std::max({e, std::fabs(q_[2 * i] - static_cast<double>(i) - std::cos(th)), std::fabs(q_[2 * i + 1] - std::sin(th))});
    return e;
  }

 private:
  void residual(double t) {
    Index r = 0;
    const double th = q_[static_cast<std::size_t>(dim_ - 1)];
    for (Index i = 0; i <= n_; ++i, ++r) {
      const double dx = q_[2 * i] - static_cast<double>(i), dy = q_[2 * i + 1];
      phi_[r] = dx * dx + dy * dy - 1.0;
    }
    for (Index i = 0; i < n_; ++i, ++r) {
      const double dx = q_[2 * i + 2] - q_[2 * i], dy = q_[2 * i + 3] - q_[2 * i + 1];
      phi_[r] = dx * dx + dy * dy - 1.0;
    }
    phi_[r++] = q_[0] * std::sin(th) - q_[1] * std::cos(th);
    phi_[r] = th - (theta0_ + rate_ * t);
  }
  // Φq values in place (column by column, rows ascending as in the pattern), then factor: refactor after the first.
  void factor() {
    std::vector<double>& v = val_;
    const double th = q_[static_cast<std::size_t>(dim_ - 1)], s = std::sin(th), c = std::cos(th);
    const Index angle_row = 2 * n_ + 1;
    for (Index col = 0; col < dim_; ++col) {
      for (Index k = colp_[col]; k < colp_[col + 1]; ++k) {
        const Index r = rowi_[k];
        double d;
        if (col == dim_ - 1) {
          d = r == angle_row ? q_[0] * c + q_[1] * s : 1.0;
        } else if (r == angle_row) {
          d = col == 0 ? s : -c;
        } else if (r <= n_) {  // crank r: 2 (P_r − (r, 0))
          d = 2.0 * (col % 2 == 0 ? q_[col] - static_cast<double>(r) : q_[col]);
        } else {  // coupler i = r − n − 1 between P_i and P_{i+1}
          const Index i = r - n_ - 1, node = col / 2;
          const Index comp = col % 2;
          const double diff = q_[2 * (i + 1) + comp] - q_[2 * i + comp];
          d = 2.0 * (node == i + 1 ? diff : -diff);
        }
        v[k] = d;
      }
    }
    if (!numeric_) numeric_ = klu_factor(colp_.data(), rowi_.data(), v.data(), symbolic_, &common_);
    else klu_refactor(colp_.data(), rowi_.data(), v.data(), symbolic_, numeric_, &common_);
  }
  void gamma() {
    Index r = 0;
    for (Index i = 0; i <= n_; ++i, ++r) qdd_[r] = -2.0 * (qd_[2 * i] * qd_[2 * i] + qd_[2 * i + 1] * qd_[2 * i + 1]);
    for (Index i = 0; i < n_; ++i, ++r) {
      const double dx = qd_[2 * i + 2] - qd_[2 * i], dy = qd_[2 * i + 3] - qd_[2 * i + 1];
      qdd_[r] = -2.0 * (dx * dx + dy * dy);
    }
    const double th = q_[static_cast<std::size_t>(dim_ - 1)], w = qd_[static_cast<std::size_t>(dim_ - 1)];
    const double s = std::sin(th), c = std::cos(th);
    qdd_[r++] = -(2.0 * qd_[0] * c * w + 2.0 * qd_[1] * s * w - q_[0] * s * w * w + q_[1] * c * w * w);
    qdd_[r] = 0.0;  // linear drive
  }

  int dim() const { return static_cast<int>(dim_); }
  Index n_, dim_ = 0;
  double theta0_, rate_;
  std::vector<int> colp_, rowi_;
  std::vector<double> val_, q_, qd_, qdd_, phi_, dq_;
  klu_common common_;
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
};

// phiq's full step (modified Newton, the default; and full Newton) against the bare loop on the same nfourbar
// quarter turn in `steps` steps (50: coarse, 1000: the generator's default), interleaved in one benchmark loop.
// Tolerance 1e-10 for all (phiq: residual and error estimate; bare: max |Δq|). Every row of each is checked against
// the parallelogram solution (sin θ of 64 tips, outside the timed regions: phiq's rows are kept and checked after
// the sweep, the bare loop's step by step), so that the counters *_error say what accuracy each delivered: the bare
// loop iterates until the last Newton step is below 1e-10, which with quadratic convergence lands far below it;
// phiq's default stops when its error estimate is within 1e-10 (the cubic predictor: most steps need no Newton
// step), and so does full Newton when no step is needed; `tight` is phiq asked for 1e-13, about what the bare loop
// delivers.
void BM_NFourBarStepVsBareLoop(benchmark::State& state) {
  const Index n = state.range(0), steps = state.range(1);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  BareLoop bare(n, M_PI / 4, M_PI / 2);
  SweepOptions modified, full, tight;
  modified.steps = full.steps = tight.steps = steps;
  full.newton.jacobian_update = JacobianUpdate::kEveryIteration;
  tight.newton.tolerance = 1e-13;  // the bare loop's accuracy (its last step overshoots 1e-10 by orders)
  double phiq_s = 0, full_s = 0, tight_s = 0, bare_s = 0, phiq_err = 0, full_err = 0, tight_err = 0, bare_err = 0;
  Index bare_it = 0, phiq_fact = 0, full_fact = 0, phiq_newton = 0;
  const Index stride = std::max<Index>(1, n / 64);
  std::vector<double> kept;  // sin θ and the tips' y of every row, checked after the timed sweep
  auto keep = [&](const StepView& v) {
    kept.push_back(v.q(2 * (n + 1)));
    for (Index i = 0; i <= n; i += stride) kept.push_back(v.q(2 * i + 1));
    return true;
  };
  auto check = [&](double& err) {
    const std::size_t per_row = 1 + static_cast<std::size_t>(n / stride + 1);
    for (std::size_t r = 0; r + per_row <= kept.size(); r += per_row)
      for (std::size_t k = 1; k < per_row; ++k) err = std::max(err, std::fabs(kept[r + k] - std::sin(kept[r])));
    kept.clear();
  };
  kept.reserve(static_cast<std::size_t>((steps + 1) * (n / stride + 2)));
  for (auto _ : state) {
    SweepSummary sum;
    ws.q = m.initial_positions();
    auto t0 = Clock::now();
    run_sweep(m, modified, ws, keep, &sum);
    const double e = seconds_since(t0);
    check(phiq_err);
    phiq_s += e, phiq_fact += sum.counters.factorizations, phiq_newton += sum.counters.newton_iterations;
    ws.q = m.initial_positions();
    t0 = Clock::now();
    run_sweep(m, full, ws, keep, &sum);
    full_s += seconds_since(t0), full_fact += sum.counters.factorizations;
    check(full_err);
    ws.q = m.initial_positions();
    t0 = Clock::now();
    run_sweep(m, tight, ws, keep, &sum);
    tight_s += seconds_since(t0);
    check(tight_err);
    bare.reset();
    for (Index k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / static_cast<double>(steps);
      t0 = Clock::now();
      bare_it += bare.step(t);
      bare_s += seconds_since(t0);
      bare_err = std::max(bare_err, bare.position_error(t));
    }
    state.SetIterationTime(e);
  }
  const double rows = static_cast<double>(state.iterations() * (steps + 1));
  state.counters["phiq_us"] = 1e6 * phiq_s / rows;
  state.counters["phiq_full_us"] = 1e6 * full_s / rows;
  state.counters["bare_us"] = 1e6 * bare_s / rows;
  state.counters["phiq_per_bare"] = phiq_s / bare_s;
  state.counters["full_per_bare"] = full_s / bare_s;
  state.counters["phiq_tight_us"] = 1e6 * tight_s / rows;
  state.counters["tight_per_bare"] = tight_s / bare_s;
  state.counters["tight_error"] = tight_err;
  state.counters["phiq_newton_per_step"] = static_cast<double>(phiq_newton) / rows;
  state.counters["phiq_fact_per_step"] = static_cast<double>(phiq_fact) / rows;
  state.counters["full_fact_per_step"] = static_cast<double>(full_fact) / rows;
  state.counters["bare_fact_per_step"] = static_cast<double>(bare_it) / rows + 1.0;
  state.counters["phiq_error"] = phiq_err;
  state.counters["full_error"] = full_err;
  state.counters["bare_error"] = bare_err;
}
BENCHMARK(BM_NFourBarStepVsBareLoop)->ArgNames({"N", "steps"})->ArgsProduct({{1000, 10000, 100000}, {50, 1000}})->Unit(benchmark::kMillisecond)->UseManualTime();

// Symbolic reuse: one factorisation as phiq does it (refactor with the pivots of the once-analysed pattern) against
// re-analysing the pattern and factorising with pivoting, at the same matrix, interleaved. The sweep needs
// `factorizations_per_step` of them per step (measured), so re-analysing would cost (reanalyse − refactor) ×
// that per step more: reported as step_speedup = (step + extra) / step.
void BM_NFourBarSymbolicReuse(benchmark::State& state) {
  const Index n = state.range(0);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  SweepOptions opt;
  opt.steps = 50;
  SweepSummary sum;
  const auto s0 = Clock::now();
  run_sweep(m, opt, ws, nullptr, &sum);
  const double step_s = seconds_since(s0) / static_cast<double>(opt.steps + 1);
  const double fact_per_step = static_cast<double>(sum.counters.factorizations) / static_cast<double>(opt.steps + 1);
  std::vector<double> values(static_cast<std::size_t>(m.jacobian_pattern().nnz()));
  m.jacobian(ws.q.data(), 1.0, values.data());
  auto reuse = m.symbolic()->make_numeric();
  reuse->factorize(values.data());
  double reuse_s = 0, fresh_s = 0;
  for (auto _ : state) {
    auto t0 = Clock::now();
    reuse->factorize(values.data());
    reuse_s += seconds_since(t0);
    t0 = Clock::now();
    auto sym = analyse(LinearSolverKind::kKlu, std::make_shared<CscPattern>(m.jacobian_pattern()));
    auto num = sym->make_numeric();
    num->factorize(values.data());
    const double f = seconds_since(t0);
    fresh_s += f;
    state.SetIterationTime(f);
  }
  const double it = static_cast<double>(state.iterations());
  state.counters["refactor_us"] = 1e6 * reuse_s / it;
  state.counters["analyse_factor_us"] = 1e6 * fresh_s / it;
  state.counters["factor_ratio"] = fresh_s / reuse_s;
  state.counters["step_us"] = 1e6 * step_s;
  state.counters["step_speedup"] = (step_s + fact_per_step * (fresh_s - reuse_s) / it) / step_s;
}
BENCHMARK(BM_NFourBarSymbolicReuse)->ArgName("N")->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond)->UseManualTime();

// Parallel drive steps: a 1000-step sweep (q, q̇, q̈) on 1 thread and on 2, interleaved; speedup = t1 / t2, and
// the share of the 2-thread run spent in the sequential seeding pass (for the projection to more cores in
// bench/README.md). In the same loop, the machine's own ceiling for this work: two independent copies of the
// 1-thread sweep run at once on two threads (own model, own workspace, nothing shared), pair_throughput =
// 2 t1 / t_pair. A machine whose two cores are fully available gives 2; the engine's schedule is judged by
// schedule_efficiency = speedup / pair_throughput (1 when splitting one sweep costs nothing over running two).
// The machine is shared: a burst of load on the host stalls a 2-thread sweep more than a 1-thread one, and one
// such burst moves a mean of three. So the three ratios are the medians of their per-iteration values over 9
// iterations; speedup_of_totals is the ratio of the summed times (what sessions 14–19 reported as speedup).
// These sweeps have no callback, so the parallel one holds only the rows it reads again itself. A caller that reads
// every row (a writer) makes it hold them all until their turn: speedup_rows_read is the same ratio with a callback
// that reads every value of q, q̇ and q̈ on both sides (median too).
void BM_NFourBarParallelSweep(benchmark::State& state) {
  const Index n = state.range(0);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Model m_copy = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m), ws_copy(m_copy);
  SweepOptions one, two;
  one.steps = two.steps = 1000;
  two.threads = 2;
  double t1 = 0, t2 = 0, pair = 0, seed = 0;
  std::vector<double> speedups, pairs, efficiencies, read_speedups;  // per iteration
  double checksum = 0;
  auto read = [&](const StepView& s) {  // every value of the row, as a writer reads them
    checksum += s.q.sum() + s.qd->sum() + s.qdd->sum();
    return true;
  };
  for (auto _ : state) {
    SweepSummary sum;
    const double e1 = timed_sweep(m, one, ws, nullptr, &sum);
    t1 += e1;
    const double e = timed_sweep(m, two, ws, nullptr, &sum);
    t2 += e, seed += sum.seed_seconds;
    if (sum.parallel_chunks == 0) state.SkipWithError("no parallel chunks");
    state.SetIterationTime(e);
    ws.q = m.initial_positions();
    ws_copy.q = m_copy.initial_positions();
    const auto t0 = Clock::now();
    std::thread other([&] {
      SweepSummary s2;
      run_sweep(m_copy, one, ws_copy, nullptr, &s2);
    });
    SweepSummary s1;
    run_sweep(m, one, ws, nullptr, &s1);
    other.join();
    const double ep = seconds_since(t0);
    pair += ep;
    speedups.push_back(e1 / e), pairs.push_back(2.0 * e1 / ep), efficiencies.push_back((e1 / e) / (2.0 * e1 / ep));
    const double r1 = timed_sweep(m, one, ws, read, &sum);
    read_speedups.push_back(r1 / timed_sweep(m, two, ws, read, &sum));
  }
  benchmark::DoNotOptimize(checksum);
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  state.counters["one_thread_ms"] = 1e3 * t1 / static_cast<double>(state.iterations());
  state.counters["two_threads_ms"] = 1e3 * t2 / static_cast<double>(state.iterations());
  state.counters["speedup"] = median(speedups);
  state.counters["speedup_of_totals"] = t1 / t2;
  state.counters["seed_share"] = seed / t2;
  state.counters["pair_throughput"] = median(pairs);
  state.counters["schedule_efficiency"] = median(efficiencies);
  state.counters["speedup_rows_read"] = median(read_speedups);
}
BENCHMARK(BM_NFourBarParallelSweep)->ArgName("N")->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(9);

// Parallel drive steps of a positions-only sweep of 100 steps (chunks of 16, 7 of them): the short sweep of a large
// model, where a chunk's start-up is a larger share than in the 1000-step sweep above and where the first seed,
// without derivatives at row 0, is extrapolated from one position over a whole chunk (session 21: found in
// sub-steps). 1 thread and 2, interleaved; speedup is the median of the per-iteration ratios.
void BM_NFourBarParallelPositions(benchmark::State& state) {
  const Index n = state.range(0);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  SweepOptions one, two;
  one.steps = two.steps = 100;
  one.velocities = one.accelerations = two.velocities = two.accelerations = false;
  two.threads = 2;
  double t1 = 0, t2 = 0, seed = 0;
  std::vector<double> speedups;
  for (auto _ : state) {
    SweepSummary sum;
    const double e1 = timed_sweep(m, one, ws, nullptr, &sum);
    const double e2 = timed_sweep(m, two, ws, nullptr, &sum);
    if (sum.parallel_chunks == 0) state.SkipWithError("no parallel chunks");
    state.SetIterationTime(e2);
    t1 += e1, t2 += e2, seed += sum.seed_seconds;
    speedups.push_back(e1 / e2);
  }
  std::sort(speedups.begin(), speedups.end());
  state.counters["one_thread_ms"] = 1e3 * t1 / static_cast<double>(state.iterations());
  state.counters["two_threads_ms"] = 1e3 * t2 / static_cast<double>(state.iterations());
  state.counters["speedup"] = speedups[speedups.size() / 2];
  state.counters["seed_share"] = seed / t2;
}
BENCHMARK(BM_NFourBarParallelPositions)->ArgName("N")->Arg(10)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(5);

// What outputs cost (issue 5, section 3): the same nfourbar sweep (a quarter turn in 200 steps) with the output
// lists a scene can have, timed interleaved in one loop, per step. The engine plans the work from the list, so the
// positions-only sweep solves no q̇ or q̈, and asking for residuals and rcond adds nothing but copying what the
// solve has. With the default (auto) predictor, derivatives also buy a better start for Newton: the `secant`
// variant is q, q̇, q̈ with the positions-only predictor, for the cost of the derivatives alone.
void BM_NFourBarOutputCost(benchmark::State& state) {
  const Index n = state.range(0), steps = 200;
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  struct Variant {
    const char* name;
    SweepOptions opt;
    double seconds = 0;
    Index newton = 0;
    std::vector<double> per_q;  // this variant's time ÷ the positions-only time, per iteration
  };
  auto make = [&](bool v, bool a) {
    SweepOptions o;
    o.steps = steps;
    o.velocities = v, o.accelerations = a;
    return o;
  };
  std::vector<Variant> variants;
  for (const auto& [name, v, a] : {std::tuple{"q", false, false}, {"q_res_rcond", false, false}, {"qv", true, false},
                                   {"qva", true, true}, {"qva_points", true, true}, {"qva_secant", true, true}})
    variants.push_back(Variant{name, make(v, a), 0.0, 0, {}});
  variants[1].opt.residuals = variants[1].opt.condition = true;
  for (Index i = 0; i <= n; ++i)  // every crank tip: an upper bound of what points cost
    variants[4].opt.points.push_back(
        planar_point(phiq_bench::indexed("P", i), Point2{Slot::coordinate(2 * i), Slot::coordinate(2 * i + 1)}));
  variants[5].opt.predictor = Predictor::kSecant;
  double checksum = 0;
  auto consume = [&](const StepView& s) {  // reads what was delivered, as a writer would
    checksum += s.q(0) + (s.points ? s.points[0].r[0] : 0.0) + (s.phi ? (*s.phi)(0) : 0.0) + s.rcond;
    return true;
  };
  // The machine is shared and noisy: all variants run back to back in every iteration, in an order rotated from one
  // iteration to the next, and the ratios reported are the medians of the per-iteration ratios.
  std::size_t rotation = 0;
  for (auto _ : state) {
    double total = 0;
    std::vector<double> t(variants.size());
    for (std::size_t r = 0; r < variants.size(); ++r) {
      const std::size_t k = (r + rotation) % variants.size();
      Variant& v = variants[k];
      SweepSummary sum;
      ws.q = m.initial_positions();
      ws.has_factorization = false;
      const auto t0 = Clock::now();
      run_sweep(m, v.opt, ws, consume, &sum);
      const double e = seconds_since(t0);
      if (sum.status != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
      v.seconds += e, total += e, t[k] = e;
      v.newton += sum.counters.newton_iterations;
    }
    ++rotation;
    for (std::size_t k = 0; k < variants.size(); ++k) variants[k].per_q.push_back(t[k] / t[0]);
    state.SetIterationTime(total);
  }
  benchmark::DoNotOptimize(checksum);
  const double it = static_cast<double>(state.iterations()), rows = static_cast<double>(steps + 1);
  for (Variant& v : variants) {
    state.counters[std::string(v.name) + "_us"] = 1e6 * v.seconds / (it * rows);
    state.counters[std::string(v.name) + "_newton"] = static_cast<double>(v.newton) / (it * rows);
    if (&v == &variants[0]) continue;
    std::sort(v.per_q.begin(), v.per_q.end());
    state.counters[std::string(v.name) + "_per_q"] = v.per_q[v.per_q.size() / 2];
  }
}
BENCHMARK(BM_NFourBarOutputCost)->ArgName("N")->Arg(10)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(7);

// Writing the result CSV (issue 4: a wide CSV must not dominate a large run): one row of q, q̇, q̈ of nfourbar formatted
// by CsvFormat::append_row (shortest round-trip text), in a task arena of 1 thread and of 2, interleaved, against the
// time of one drive step of the same model on one thread (a 200-step sweep, q, q̇, q̈). format_per_step_1t > 1 means
// that one thread writing the rows would take longer than one thread solving them.
void BM_CsvRowFormatting(benchmark::State& state) {
  const Index n = state.range(0), steps = 200;
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  SweepOptions o;
  o.steps = steps;
  o.threads = 1;
  Eigen::VectorXd q, qd, qdd;  // the last row: values as a run writes them
  const auto s0 = Clock::now();
  run_sweep(m, o, ws, [&](const StepView& s) {
    if (s.step == steps) q = s.q, qd = *s.qd, qdd = *s.qdd;
    return true;
  }, nullptr);
  const double step_s = seconds_since(s0) / static_cast<double>(steps);
  std::vector<Index> columns(static_cast<std::size_t>(m.num_coordinates()));
  for (std::size_t j = 0; j < columns.size(); ++j) columns[j] = static_cast<Index>(j);
  const CsvFormat csv(m, columns, true, true);
  const StepView row{steps, 1.0, q, &qd, &qdd};
  tbb::task_arena one(1), two(2);
  const int rows = std::max<int>(1, static_cast<int>(1000000 / (3 * n)));  // about 10⁶ numbers per pass
  std::string out;
  double t1 = 0, t2 = 0;
  std::size_t bytes = 0;
  auto pass = [&](tbb::task_arena& arena) {
    const auto t0 = Clock::now();
    arena.execute([&] {
      for (int r = 0; r < rows; ++r) {
        out.clear();
        csv.append_row(row, out);
      }
    });
    bytes = out.size();
    return seconds_since(t0);
  };
  for (auto _ : state) {
    t1 += pass(one);
    const double e = pass(two);
    t2 += e;
    state.SetIterationTime(e);
  }
  const double values = 3.0 * static_cast<double>(m.num_coordinates()) + 1.0;
  const double per_row_1 = t1 / (static_cast<double>(state.iterations()) * rows);
  const double per_row_2 = t2 / (static_cast<double>(state.iterations()) * rows);
  state.counters["ns_per_value_1t"] = 1e9 * per_row_1 / values;
  state.counters["ns_per_value_2t"] = 1e9 * per_row_2 / values;
  state.counters["speedup"] = t1 / t2;
  state.counters["bytes_per_value"] = static_cast<double>(bytes) / values;
  state.counters["step_us"] = 1e6 * step_s;
  state.counters["format_per_step_1t"] = per_row_1 / step_s;
  state.counters["format_per_step_2t"] = per_row_2 / step_s;
}
BENCHMARK(BM_CsvRowFormatting)->ArgName("N")->Arg(10)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
