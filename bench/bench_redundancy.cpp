// Redundant constraints at scale (issue 3): the rank analysis (SuiteSparseQR), the minimum-norm assembly (CHOLMOD)
// and the square solve through consistent redundancy, on the braced nfourbar (N − 1 redundant bars), against the
// plain nfourbar; and the choice of dropping redundant rows against solving the normal equations Φqᵀ Φq (CHOLMOD)
// per Newton iteration. Figures and commands: bench/README.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "nfourbar_model.hpp"
#include "phiq/phiq.hpp"

namespace {

using namespace phiq;
constexpr double kTheta0 = M_PI / 4;

std::unique_ptr<Model> braced(Index n) {
  return std::make_unique<Model>(phiq_bench::nfourbar(n, kTheta0, 1.0, LinearSolverKind::kKlu, true));
}

// The exact parallelogram position of the nfourbar builder: P_i = (i + cos θ, sin θ), θ last.
Eigen::VectorXd exact(const Model& m, Index n, double th) {
  Eigen::VectorXd q(m.num_coordinates());
  for (Index i = 0; i <= n; ++i) q(2 * i) = static_cast<double>(i) + std::cos(th), q(2 * i + 1) = std::sin(th);
  q(2 * n + 2) = th;
  return q;
}

// The braced model assembled at its exact position, and the model its square solves use (redundant rows left out).
struct Solved {
  std::unique_ptr<Model> full, solved;
  Eigen::VectorXd q;
};
Solved solved_braced(Index n) {
  Solved s{braced(n), nullptr, {}};
  s.q = exact(*s.full, n, kTheta0);
  AssemblySummary a;
  if (prepare_square(*s.full, 0.0, {}, s.q, &s.solved, &a) != SolveStatus::kSuccess) s.solved.reset();
  return s;
}

void BM_RankAnalysisBraced(benchmark::State& st) {
  const Index n = st.range(0);
  auto m = braced(n);
  const Eigen::VectorXd q = exact(*m, n, kTheta0);
  RankOptions o;
  o.ordering = st.range(1) == 0 ? RankOrdering::kModelOrder : RankOrdering::kFillReducing;
  RankReport r;
  for (auto _ : st) r = analyse_rank(*m, q, 0.0, o);
  if (static_cast<Index>(r.redundant_rows.size()) != n - 1 || r.dof != 1) st.SkipWithError("wrong redundancy count");
  st.counters["redundant"] = static_cast<double>(r.redundant_rows.size());
  st.counters["equations"] = static_cast<double>(m->num_equations());
}

void BM_AssembleBraced(benchmark::State& st) {
  const Index n = st.range(0);
  auto m = braced(n);
  Eigen::VectorXd rough = exact(*m, n, kTheta0);
  for (Index i = 0; i <= n; ++i) rough(2 * i + 1) += (i % 2 ? 0.01 : -0.01);  // a rough placement
  AssemblySummary a;
  std::unique_ptr<Model> solved;
  for (auto _ : st) {
    Eigen::VectorXd q = rough;
    if (prepare_square(*m, 0.0, {}, q, &solved, &a) != SolveStatus::kSuccess) st.SkipWithError(a.message.c_str());
  }
  st.counters["iterations"] = a.iterations;
}

// Time per drive step of a 200-step sweep (q, q̇, q̈) on the model the square solve uses: braced (redundant rows left
// out) against plain (nothing to leave out), same motion.
void sweep_steps(benchmark::State& st, const Model& m) {
  SweepOptions o;
  o.t_begin = 0.0, o.t_end = 0.2, o.steps = 200;
  o.threads = 1;
  double seconds = 0.0;
  for (auto _ : st) {
    Workspace ws(m);
    SweepSummary s;
    if (run_sweep(
            m, o, ws, [](const StepView&) { return true; }, &s) != SolveStatus::kSuccess)
      st.SkipWithError(s.message.c_str());
    seconds += s.solve_seconds;
  }
  st.counters["us_per_step"] = 1e6 * seconds / static_cast<double>(st.iterations() * (o.steps + 1));
}
void BM_StepBracedReduced(benchmark::State& st) {
  const Solved s = solved_braced(st.range(0));
  if (!s.solved) return st.SkipWithError("the braced model did not assemble");
  sweep_steps(st, *s.solved);
}
void BM_StepPlain(benchmark::State& st) {
  const Model m = phiq_bench::nfourbar(st.range(0), kTheta0, 1.0);
  sweep_steps(st, m);
}

// One Newton iteration on the braced model, two ways: (a) the kept rows' Jacobian (values gathered from the full
// evaluation) refactorised by KLU and solved; (b) the normal equations Φqᵀ Φq Δ = −Φqᵀ Φ of all rows, factorised
// by CHOLMOD (analysis once) and solved. Both give the same step on a consistent position.
void BM_IterationDropRowsKlu(benchmark::State& st) {
  const Index n = st.range(0);
  const Solved s = solved_braced(n);
  if (!s.solved) return st.SkipWithError("the braced model did not assemble");
  const Model* solved = s.solved.get();
  Workspace ws(*solved);
  ws.q = s.q;
  ws.q(2 * n + 2) += 1e-3;  // off the solution, so that the step is not zero
  // a Newton iteration's factorisation and solve, timed through solve_velocity at a q off the solution on purpose:
  // its test that q solves the position problem is off (it would add a second evaluation of Φ)
  DerivativeOptions unchecked;
  unchecked.tolerance = INFINITY;
  for (auto _ : st) {
    ws.has_factorization = false;
    LinearSummary ls;
    solved->residual(ws.q.data(), 0.0, ws.phi.data());
    if (solve_velocity(*solved, 0.0, unchecked, ws, &ls) != SolveStatus::kSuccess) st.SkipWithError(ls.message.c_str());
    benchmark::DoNotOptimize(ws.qd.data());
  }
}
void BM_IterationNormalEquationsCholmod(benchmark::State& st) {
  const Index n = st.range(0);
  auto m = braced(n);
  Eigen::VectorXd q = exact(*m, n, kTheta0);
  q(2 * n + 2) += 1e-3;
  // Φqᵀ as a CSC pattern (n × m) and where each of its entries comes from in Φq's value array: fixed once.
  std::vector<Index> from;
  auto at = std::make_shared<CscPattern>(transpose_pattern(m->jacobian_pattern(), &from));
  MinNormSolver normal(at);  // A = Φqᵀ: CHOLMOD factorises A Aᵀ = Φqᵀ Φq
  std::vector<double> values(from.size()), tv(values.size());
  Eigen::VectorXd phi(m->num_equations()), rhs(m->num_coordinates()), step(m->num_coordinates());
  for (auto _ : st) {
    m->jacobian(q.data(), 0.0, values.data());
    for (std::size_t k = 0; k < tv.size(); ++k) tv[k] = values[static_cast<std::size_t>(from[k])];
    if (normal.factorize(tv.data()) != FactorStatus::kOk) st.SkipWithError("normal equations singular");
    m->residual(q.data(), 0.0, phi.data());
    rhs.setZero();
    normal.multiply_add(phi.data(), rhs.data());  // Φqᵀ Φ (the step is minus its solve: the sign costs nothing here)
    normal.solve(rhs.data(), step.data());
    benchmark::DoNotOptimize(step.data());
  }
  st.counters["rcond"] = normal.rcond();
}

#define SIZES ->ArgName("N")->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)
// ordering 0: model order (quadratic fill on a chain: stopped at 10^4), 1: fill-reducing
BENCHMARK(BM_RankAnalysisBraced)
    ->ArgNames({"N", "fill"})
    ->Args({1000, 0})
    ->Args({3000, 0})
    ->Args({10000, 0})
    ->Args({1000, 1})
    ->Args({10000, 1})
    ->Args({100000, 1})
    ->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AssembleBraced) SIZES;
BENCHMARK(BM_StepBracedReduced) SIZES;
BENCHMARK(BM_StepPlain) SIZES;
BENCHMARK(BM_IterationDropRowsKlu) SIZES;
BENCHMARK(BM_IterationNormalEquationsCholmod) SIZES;

}  // namespace

BENCHMARK_MAIN();
