// phiq's drive step against the bare loop: a hand-written Newton over KLU refactor for nfourbar, the loop
// a careful user writes without phiq, interleaved with phiq's sweep on the same quarter turn. Part of phiq_bench
// (BENCHMARK_MAIN is in bench_kinematics.cpp); separate because the bare loop is a program of its own.
#include <benchmark/benchmark.h>

#include <klu.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "bench_kinematics_timing.hpp"
#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
using phiq_bench::Clock;
using phiq_bench::nfourbar;
using phiq_bench::seconds_since;

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
    for (Index i = 0; i <= n; ++i, ++r) put(r, 2 * i), put(r, 2 * i + 1);  // cranks
    for (Index i = 0; i < n; ++i, ++r)
      put(r, 2 * i), put(r, 2 * i + 1), put(r, 2 * i + 2), put(r, 2 * i + 3);  // couplers
    put(r, 0), put(r, 1), put(r, nc - 1), ++r;                                 // angle of crank 0
    put(r, nc - 1);                                                            // driver
    colp_.assign(static_cast<std::size_t>(nc + 1), 0);
    for (Index c = 0; c < nc; ++c) {
      std::sort(rows_of_col[static_cast<std::size_t>(c)].begin(), rows_of_col[static_cast<std::size_t>(c)].end());
      colp_[static_cast<std::size_t>(c + 1)] =
          colp_[static_cast<std::size_t>(c)] + static_cast<int>(rows_of_col[static_cast<std::size_t>(c)].size());
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
    for (Index i = 0; i <= n_; ++i)
      q_[2 * i] = static_cast<double>(i) + std::cos(theta0_), q_[2 * i + 1] = std::sin(theta0_);
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
      e = std::max(
          {e, std::fabs(q_[2 * i] - static_cast<double>(i) - std::cos(th)), std::fabs(q_[2 * i + 1] - std::sin(th))});
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
    if (!numeric_)
      numeric_ = klu_factor(colp_.data(), rowi_.data(), v.data(), symbolic_, &common_);
    else
      klu_refactor(colp_.data(), rowi_.data(), v.data(), symbolic_, numeric_, &common_);
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
// delivers. `in_order` is the default in one chunk, as the bare loop runs: the default cuts the sweep into the chunks
// that give the same bits on every thread count even on one thread (SweepOptions::chunk_steps), each a seed, a seam
// step and a factorisation more.
void BM_NFourBarStepVsBareLoop(benchmark::State& state) {
  const Index n = state.range(0), steps = state.range(1);
  Model m = nfourbar(n, M_PI / 4, M_PI / 2);
  Workspace ws(m);
  BareLoop bare(n, M_PI / 4, M_PI / 2);
  SweepOptions modified, full, tight, in_order;
  modified.steps = full.steps = tight.steps = in_order.steps = steps;
  in_order.chunk_steps = steps;  // one chunk: no seeds, no seams (the default cuts chunks even on one thread)
  full.newton.jacobian_update = JacobianUpdate::kEveryIteration;
  tight.newton.tolerance = 1e-13;  // the bare loop's accuracy (its last step overshoots 1e-10 by orders)
  double phiq_s = 0, full_s = 0, tight_s = 0, bare_s = 0, phiq_err = 0, full_err = 0, tight_err = 0, bare_err = 0;
  double order_s = 0, order_err = 0;
  Index bare_it = 0, phiq_fact = 0, full_fact = 0, phiq_newton = 0, order_newton = 0, order_fact = 0;
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
  // one sweep from the start, its time added to `seconds` and its deviation from the closed form to `err`
  auto timed = [&](const SweepOptions& o, double& seconds, double& err) {
    SweepSummary sum;
    ws.q = m.initial_positions();
    const auto t0 = Clock::now();
    (void)run_sweep(m, o, ws, keep, &sum);
    const double e = seconds_since(t0);
    if (sum.status != SolveStatus::kSuccess) state.SkipWithError(sum.message.c_str());
    check(err);
    seconds += e;
    return std::pair{e, sum.counters};
  };
  for (auto _ : state) {
    const auto [e, work] = timed(modified, phiq_s, phiq_err);
    phiq_fact += work.factorizations, phiq_newton += work.newton_iterations;
    full_fact += timed(full, full_s, full_err).second.factorizations;
    (void)timed(tight, tight_s, tight_err);
    const WorkCounters in_order_work = timed(in_order, order_s, order_err).second;
    order_newton += in_order_work.newton_iterations, order_fact += in_order_work.factorizations;
    bare.reset();
    for (Index k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / static_cast<double>(steps);
      const auto t0 = Clock::now();
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
  state.counters["in_order_per_bare"] = order_s / bare_s;
  state.counters["in_order_newton_per_step"] = static_cast<double>(order_newton) / rows;
  state.counters["in_order_fact_per_step"] = static_cast<double>(order_fact) / rows;
  state.counters["in_order_error"] = order_err;
  state.counters["phiq_error"] = phiq_err;
  state.counters["full_error"] = full_err;
  state.counters["bare_error"] = bare_err;
}
BENCHMARK(BM_NFourBarStepVsBareLoop)
    ->ArgNames({"N", "steps"})
    ->ArgsProduct({{1000, 10000, 100000}, {50, 1000}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

}  // namespace
