// Peers on the same workload: time per drive step of nfourbar N solved by
//   - a dense Eigen LU Newton, written the classic course way (BM_NFourBarStepDenseEigenLu),
//   - Simbody from Debian's libsimbody-dev (BM_NFourBarStepSimbody; peer_simbody.cpp, only when it was found),
//   - phiq's sweep with KLU (BM_NFourBarStepPhiqKlu),
// under the protocol of peers.hpp: the same model, start, time step and tolerance for all three; the row at t = 0
// (already on the exact solution) is not timed; only the drive steps after it are, and the check of each step
// against the exact solution is kept out of the timing. Arguments: N, and pred = where each step's Newton iteration
// starts (0: the previous solution, the classic course way; 1: the quadratic predictor, phiq's default). Every peer
// iteration also runs phiq over the very same steps with the same start in the same loop and reports the ratio
// (`per_phiq`), which is the figure that survives this noisy machine.
//
// Clock: the thread's CPU time (CLOCK_THREAD_CPUTIME_ID). All three run on one thread (Eigen without OpenMP, KLU,
// Simbody's matter subsystem over Debian's reference BLAS/LAPACK), and on this shared 2-core machine the wall clock
// also counts the time the process waits for a core (wall ÷ CPU was 1.2–1.5 in a run at load 4). The wall-clock
// figure is reported too (wall_us_per_step); phiq_bench uses the wall clock (equal on an idle machine).
//
//   build/bench/phiq_bench_peers --benchmark_out=bench/results/peers.json --benchmark_out_format=json
//
// Counters: us_per_step (CPU µs per drive step; the figure bench/README.md and tools/plot/plot_bench.py use),
// wall_us_per_step, steps (timed per iteration), newton_per_step (Newton iterations; Simbody: projectQ iterations),
// max_position_error, max_velocity_error, max_acceleration_error (against P_i = (i + cos θ, sin θ); a peer above
// 1e-8 fails the benchmark), phiq_us_per_step and per_phiq (phiq on the same steps in the same loop, and the peer's
// time ÷ phiq's); Simbody also us_per_step_without_acceleration, mobilities, constraint_equations.
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <time.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <string>

#include "nfourbar_model.hpp"
#include "peers.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq_bench;
using Clock = std::chrono::steady_clock;

// Both clocks at once: the thread's CPU time, the one the figures use, and the wall clock.
struct Stamp {
  Clock::time_point wall;
  double cpu;
};
Stamp now() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return {Clock::now(), static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec)};
}
struct Elapsed {
  double cpu = 0.0, wall = 0.0;
  void add(const Stamp& from, const Stamp& to) {
    cpu += to.cpu - from.cpu;
    wall += std::chrono::duration<double>(to.wall - from.wall).count();
  }
  Elapsed& operator+=(const Elapsed& o) { return cpu += o.cpu, wall += o.wall, *this; }
};

// ---------------------------------------------------------------------------------------------------------------
// The classic course approach: Φ(q, t) and Φq(q, t) as dense matrices, a Newton loop with an LU of Φq per iteration
// (Eigen::PartialPivLU), then the velocity Φq q̇ = −Φt and the acceleration Φq q̈ = γ with one LU of Φq at the
// converged position. Same equations (and row units) as phiq's nfourbar: distances (|b − a|² − L²) / 2L, crank 0's
// segment angle x0 sin θ − y0 cos θ, the driver θ − θ(t). Same convergence test as phiq's NewtonOptions: every
// |Φ_i| ≤ tol and the last step every |Δq_j| ≤ tol (L = 1), and the same starts (Start).
class DenseNFourBar {
 public:
  DenseNFourBar(int n, Start start)
      : n_(n),
        size_(2 * n + 3),
        start_(start),
        q_(size_),
        qd_(size_),
        qdd_(size_),
        phi_(size_),
        rhs_(size_),
        dq_(size_),
        jac_(size_, size_) {
    reset();
  }

  void reset() {
    for (int i = 0; i <= n_; ++i) q_[2 * i] = i + std::cos(kTheta0), q_[2 * i + 1] = std::sin(kTheta0);
    q_[th()] = kTheta0;
    t_ = 0.0;
    solve(0.0);
  }

  void step(double t) {
    const double h = t - t_;
    if (start_ == Start::kQuadratic) q_ += h * qd_ + (0.5 * h * h) * qdd_;
    solve(t);
  }

  Deviation deviation() const {
    Deviation d;
    for (int i = 0; i <= n_; ++i) {
      const ExactTip e = exact_tip(i, t_);
      d.position = std::max({d.position, std::abs(q_[2 * i] - e.x), std::abs(q_[2 * i + 1] - e.y)});
      d.velocity = std::max({d.velocity, std::abs(qd_[2 * i] - e.vx), std::abs(qd_[2 * i + 1] - e.vy)});
      d.acceleration = std::max({d.acceleration, std::abs(qdd_[2 * i] - e.ax), std::abs(qdd_[2 * i + 1] - e.ay)});
    }
    return d;
  }
  long long newton_iterations() const { return iterations_; }

 private:
  int th() const { return 2 * n_ + 2; }
  double x(int i) const { return q_[2 * i]; }
  double y(int i) const { return q_[2 * i + 1]; }

  void solve(double t) {
    t_ = t;
    for (int it = 0;; ++it) {
      residual(t);
      if (phi_.lpNorm<Eigen::Infinity>() <= kTolerance && (it == 0 || dq_.lpNorm<Eigen::Infinity>() <= kTolerance))
        break;
      if (it >= 20) throw std::runtime_error("dense Newton did not converge at t = " + std::to_string(t));
      jacobian();
      lu_.compute(jac_);
      dq_ = lu_.solve(-phi_);
      q_ += dq_;
      ++iterations_;
    }
    jacobian();
    lu_.compute(jac_);
    rhs_.setZero();
    rhs_[th()] = kRate;  // −Φt: only the driver row depends on t, Φt = −θ̇
    qd_ = lu_.solve(rhs_);
    gamma();
    qdd_ = lu_.solve(rhs_);
  }

  // rows: cranks 0..N, couplers 0..N−1, crank 0's angle, driver
  void residual(double t) {
    for (int i = 0; i <= n_; ++i) phi_[i] = 0.5 * ((x(i) - i) * (x(i) - i) + y(i) * y(i) - 1.0);
    for (int i = 0; i < n_; ++i) {
      const double dx = x(i + 1) - x(i), dy = y(i + 1) - y(i);
      phi_[n_ + 1 + i] = 0.5 * (dx * dx + dy * dy - 1.0);
    }
    const double s = std::sin(q_[th()]), c = std::cos(q_[th()]);
    phi_[2 * n_ + 1] = x(0) * s - y(0) * c;
    phi_[2 * n_ + 2] = q_[th()] - theta_at(t);
  }

  void jacobian() {
    jac_.setZero();
    for (int i = 0; i <= n_; ++i) jac_(i, 2 * i) = x(i) - i, jac_(i, 2 * i + 1) = y(i);
    for (int i = 0; i < n_; ++i) {
      const int r = n_ + 1 + i;
      const double dx = x(i + 1) - x(i), dy = y(i + 1) - y(i);
      jac_(r, 2 * i) = -dx, jac_(r, 2 * i + 1) = -dy, jac_(r, 2 * i + 2) = dx, jac_(r, 2 * i + 3) = dy;
    }
    const int r = 2 * n_ + 1;
    const double s = std::sin(q_[th()]), c = std::cos(q_[th()]);
    jac_(r, 0) = s, jac_(r, 1) = -c, jac_(r, th()) = x(0) * c + y(0) * s;
    jac_(r + 1, th()) = 1.0;
  }

  // γ = −(Φq q̇)q q̇ − 2Φqt q̇ − Φtt into rhs_
  void gamma() {
    for (int i = 0; i <= n_; ++i) rhs_[i] = -(qd_[2 * i] * qd_[2 * i] + qd_[2 * i + 1] * qd_[2 * i + 1]);
    for (int i = 0; i < n_; ++i) {
      const double dvx = qd_[2 * i + 2] - qd_[2 * i], dvy = qd_[2 * i + 3] - qd_[2 * i + 1];
      rhs_[n_ + 1 + i] = -(dvx * dvx + dvy * dvy);
    }
    const double s = std::sin(q_[th()]), c = std::cos(q_[th()]), w = qd_[th()];
    rhs_[2 * n_ + 1] = -2.0 * w * (qd_[0] * c + qd_[1] * s) + w * w * (x(0) * s - y(0) * c);
    rhs_[2 * n_ + 2] = 0.0;
  }

  int n_, size_;
  Start start_;
  double t_ = 0.0;
  Eigen::VectorXd q_, qd_, qdd_, phi_, rhs_, dq_;
  Eigen::MatrixXd jac_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  long long iterations_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------
// phiq: run_sweep over the same steps (h = 1/50 s from t = 0, Newton tolerance 1e-10, KLU), the start as asked:
// Predictor::kPrevious or kQuadratic (what kAuto, the default, chooses when accelerations are computed).
// Times each drive step from the end of the previous row's callback to the start of its own; the check of each row
// against the exact solution is outside the timing. Row 0 (the assembly at t = 0, already exact, and the first
// factorisation with its pivot search) is not timed, as for the peers.
class PhiqNFourBar {
 public:
  PhiqNFourBar(int n, Start start)
      : n_(n),
        predictor_(start == Start::kPrevious ? phiq::Predictor::kPrevious : phiq::Predictor::kQuadratic),
        model_(nfourbar(n, kTheta0, kRate)),
        ws_(model_) {}

  // Runs `steps` drive steps from t = 0; returns the time of the drive steps and merges into dev.
  Elapsed run(int steps, Deviation& dev) {
    phiq::SweepOptions opt;
    opt.t_begin = 0.0;
    opt.t_end = steps * kStep;
    opt.steps = steps;
    opt.newton.tolerance = kTolerance;
    opt.predictor = predictor_;
    ws_.q = model_.initial_positions();
    Elapsed timed;
    Stamp mark{};
    phiq::SweepSummary sum;
    (void)phiq::run_sweep(
        model_, opt, ws_,
        [&](const phiq::StepView& s) {  // its status is sum.status, checked below
          if (s.step > 0) timed.add(mark, now());
          Deviation d;
          for (int i = 0; i <= n_; ++i) {
            const ExactTip e = exact_tip(i, s.t);
            d.position = std::max({d.position, std::abs(s.q[2 * i] - e.x), std::abs(s.q[2 * i + 1] - e.y)});
            d.velocity = std::max({d.velocity, std::abs((*s.qd)[2 * i] - e.vx), std::abs((*s.qd)[2 * i + 1] - e.vy)});
            d.acceleration =
                std::max({d.acceleration, std::abs((*s.qdd)[2 * i] - e.ax), std::abs((*s.qdd)[2 * i + 1] - e.ay)});
          }
          dev.merge(d);
          mark = now();
          return true;
        },
        &sum);
    if (sum.status != phiq::SolveStatus::kSuccess) throw std::runtime_error("phiq: " + sum.message);
    newton_ += sum.counters.newton_iterations;
    return timed;
  }
  long long newton_iterations() const { return newton_; }

 private:
  int n_;
  phiq::Predictor predictor_;
  phiq::Model model_;
  phiq::Workspace ws_;
  long long newton_ = 0;
};

// Simbody's messages span lines: one line, runs of white space collapsed.
std::string one_line(const char* what) {
  std::string out;
  for (const char* c = what; *c; ++c) {
    const bool space = *c == ' ' || *c == '\n' || *c == '\t' || *c == '\r';
    if (!space)
      out += *c;
    else if (!out.empty() && out.back() != ' ')
      out += ' ';
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// Drive steps timed per iteration: the whole quarter turn where a peer is fast enough, a few steps at N = 1000 where
// a dense step takes a second and more (the time per step does not depend on where in the quarter turn it is).
int steps_for(int n) { return n >= 1000 ? 4 : kStepsPerSweep; }
// phiq's runs per peer iteration: at least a quarter turn of steps, so that its side of the ratio is not 4 steps.
int phiq_repeats(int n) { return (kStepsPerSweep + steps_for(n) - 1) / steps_for(n); }

Start start_arg(const benchmark::State& state) { return static_cast<Start>(state.range(1)); }

// peer: its timed drive steps (`steps` in all); phiq: phiq's on the same steps (`phiq_steps` in all), or none.
void report(benchmark::State& state, int n, long long steps, const Elapsed& peer, long long phiq_steps,
            const Elapsed& phiq, long long newton, const Deviation& dev) {
  state.counters["us_per_step"] = 1e6 * peer.cpu / static_cast<double>(steps);
  state.counters["wall_us_per_step"] = 1e6 * peer.wall / static_cast<double>(steps);
  state.counters["steps"] = static_cast<double>(steps_for(n));
  state.counters["newton_per_step"] = static_cast<double>(newton) / static_cast<double>(steps);
  state.counters["max_position_error"] = dev.position;
  state.counters["max_velocity_error"] = dev.velocity;
  state.counters["max_acceleration_error"] = dev.acceleration;
  state.counters["coordinates"] = 2.0 * n + 3.0;
  if (phiq_steps > 0) {
    const double phiq_step = phiq.cpu / static_cast<double>(phiq_steps);
    state.counters["phiq_us_per_step"] = 1e6 * phiq_step;
    state.counters["per_phiq"] = (peer.cpu / static_cast<double>(steps)) / phiq_step;
  }
  if (!(dev.worst() <= kCheckTolerance)) {
    const std::string msg = "deviates from the exact solution by " + std::to_string(dev.worst()) + " > 1e-8";
    state.SkipWithError(msg.c_str());
  }
}

// One benchmark iteration: phiq over the steps (repeated up to a quarter turn of steps), then the peer over the same
// steps (its reset is not timed).
template <class Peer, class Newton>
void run_peer(benchmark::State& state, Peer& peer, Newton newton_of) {
  const int n = static_cast<int>(state.range(0)), steps = steps_for(n);
  PhiqNFourBar phiq(n, start_arg(state));
  Deviation dev, phiq_dev;
  Elapsed peer_t, phiq_t;
  long long total = 0, phiq_total = 0;
  const long long newton0 = newton_of(peer);
  try {
    for (auto _ : state) {
      for (int r = 0; r < phiq_repeats(n); ++r) phiq_t += phiq.run(steps, phiq_dev), phiq_total += steps;
      peer.reset();
      Elapsed e;
      for (int k = 1; k <= steps; ++k) {
        const Stamp t0 = now();
        peer.step(k * kStep);
        e.add(t0, now());
        dev.merge(peer.deviation());
      }
      state.SetIterationTime(e.cpu);
      peer_t += e;
      total += steps;
    }
  } catch (const std::exception& e) {
    state.SkipWithError(one_line(e.what()).c_str());
    return;
  }
  if (!(phiq_dev.worst() <= kCheckTolerance)) return state.SkipWithError("phiq deviates from the exact solution");
  report(state, n, total, peer_t, phiq_total, phiq_t, newton_of(peer) - newton0, dev);
}

void sizes(benchmark::internal::Benchmark* b) {
  b->ArgNames({"N", "pred"});
  for (int64_t pred : {0, 1})
    for (int64_t n : {10, 100, 1000}) b->Args({n, pred});
}

void BM_NFourBarStepDenseEigenLu(benchmark::State& state) {
  DenseNFourBar peer(static_cast<int>(state.range(0)), start_arg(state));
  run_peer(state, peer, [](const DenseNFourBar& p) { return p.newton_iterations(); });
}
BENCHMARK(BM_NFourBarStepDenseEigenLu)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime();

#ifdef PHIQ_HAVE_SIMBODY
void BM_NFourBarStepSimbody(benchmark::State& state) {
  std::unique_ptr<SimbodyNFourBar> peer;
  try {
    peer = std::make_unique<SimbodyNFourBar>(static_cast<int>(state.range(0)), start_arg(state));
  } catch (const std::exception& e) {  // Simbody's exceptions (a failed projection) derive from std::exception
    state.SkipWithError(one_line(e.what()).c_str());
    return;
  }
  run_peer(state, *peer, [](const SimbodyNFourBar& p) { return p.projection_iterations(); });
  if (state.error_occurred()) return;
  // the Simbody figure is positions and velocities only: the same step without the acceleration stage
  const double steps = static_cast<double>(state.iterations()) * steps_for(static_cast<int>(state.range(0)));
  state.counters["us_per_step_without_acceleration"] =
      state.counters["us_per_step"] - 1e6 * peer->acceleration_seconds() / steps;
  state.counters["mobilities"] = peer->mobilities();
  state.counters["constraint_equations"] = peer->constraint_equations();
}
BENCHMARK(BM_NFourBarStepSimbody)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime();
#endif

// phiq alone over the whole quarter turn (50 steps per iteration), the curve of the figure.
void BM_NFourBarStepPhiqKlu(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  PhiqNFourBar phiq(n, start_arg(state));
  Deviation dev;
  Elapsed total;
  long long steps = 0;
  try {
    for (auto _ : state) {
      const Elapsed e = phiq.run(kStepsPerSweep, dev);
      state.SetIterationTime(e.cpu);
      total += e;
      steps += kStepsPerSweep;
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  report(state, n, steps, total, 0, Elapsed{}, phiq.newton_iterations(), dev);
  state.counters["steps"] = kStepsPerSweep;
}
BENCHMARK(BM_NFourBarStepPhiqKlu)->Apply(sizes)->Unit(benchmark::kMillisecond)->UseManualTime();

}  // namespace

BENCHMARK_MAIN();
