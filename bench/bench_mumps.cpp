// MUMPS (the distributed multifrontal LU of Debian's libmumps-dev, on MPI ranks) against phiq's KLU on the same
// Jacobian: the nfourbar model of N loops (2N + 3 coordinates) at its first position, the matrix every drive step
// of a sweep factorises. What engine/README.md's note on one model larger than one machine is grounded on.
//
//   mpirun -np R build/bench/phiq_bench_mumps N [REPEATS]
//
// Rank 0 times phiq's KLU (as a sweep uses it: the analysis once, then per step a refactorisation with the pivots
// kept and a solve); then every rank runs MUMPS on the matrix given centrally on rank 0 (ICNTL(5) = 0, ICNTL(18) =
// 0): its analysis (job 1) once, then REPEATS factorisations (job 2) and solves (job 3). Printed by rank 0, one
// line per solver: the times (median of the repeats), MUMPS's memory (INFOG(21) the largest rank's, INFOG(22) all
// ranks', MB), and the largest difference between the two solutions relative to the largest entry.
// Not a Google Benchmark: MUMPS's calls are collective, every rank must make each of them in the same order.
#include <mpi.h>

#include <dmumps_c.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "nfourbar_model.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const long n_loops = argc > 1 ? std::atol(argv[1]) : 0;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
  if (n_loops < 1 || repeats < 1) {
    if (rank == 0) std::fprintf(stderr, "usage: mpirun -np R phiq_bench_mumps N [REPEATS]\n");
    MPI_Finalize();
    return 2;
  }

  // Rank 0: the matrix, and KLU on it.
  std::vector<MUMPS_INT> irn, jcn;
  std::vector<double> a, rhs, x_klu;
  MUMPS_INT n = 0;
  if (rank == 0) {
    const auto t_build = Clock::now();
    const phiq::Model m = phiq_bench::nfourbar(n_loops, 0.7853981633974483, 1.0);
    const double build_s = since(t_build);  // includes phiq's analysis of the pattern (KLU's symbolic)
    const phiq::CscPattern& p = m.jacobian_pattern();
    const Eigen::VectorXd& q = m.initial_positions();  // on the parallelogram: an assembled position
    std::vector<double> values(static_cast<std::size_t>(p.nnz()));
    m.jacobian(q.data(), 0.0, values.data());
    n = static_cast<MUMPS_INT>(p.cols);
    for (phiq::Index c = 0; c < p.cols; ++c)
      for (phiq::Index k = p.col_ptr[c]; k < p.col_ptr[c + 1]; ++k) {
        irn.push_back(static_cast<MUMPS_INT>(p.row_idx[k] + 1));  // MUMPS counts from 1
        jcn.push_back(static_cast<MUMPS_INT>(c + 1));
        a.push_back(values[static_cast<std::size_t>(k)]);
      }
    rhs.resize(static_cast<std::size_t>(n));
    for (MUMPS_INT i = 0; i < n; ++i) rhs[static_cast<std::size_t>(i)] = std::sin(0.1 * i) + 1.0;
    std::unique_ptr<phiq::SparseLuNumeric> lu = m.symbolic()->make_numeric();
    auto t0 = Clock::now();
    if (lu->factorize(values.data()) != phiq::FactorStatus::kOk) {
      std::fprintf(stderr, "phiq_bench_mumps: KLU could not factorise the Jacobian\n");
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    const double first_s = since(t0);
    std::vector<double> refactor, solve;
    x_klu.resize(static_cast<std::size_t>(n));
    for (int r = 0; r < repeats; ++r) {
      t0 = Clock::now();
      (void)lu->factorize(values.data());
      refactor.push_back(since(t0));
      t0 = Clock::now();
      (void)lu->solve(rhs.data(), x_klu.data());
      solve.push_back(since(t0));
    }
    std::printf("N = %ld loops, n = %d coordinates, nnz = %zu, %d MPI rank(s)\n", n_loops, n, a.size(), ranks);
    std::printf(
        "KLU (phiq, rank 0): model and analysis %.4g ms, first factorisation %.4g ms, refactorisation "
        "%.4g ms, solve %.4g ms\n",
        1e3 * build_s, 1e3 * first_s, 1e3 * median(refactor), 1e3 * median(solve));
  }

  // Every rank: MUMPS.
  DMUMPS_STRUC_C id{};
  id.comm_fortran = static_cast<MUMPS_INT>(MPI_Comm_c2f(MPI_COMM_WORLD));
  id.par = 1;  // rank 0 works too
  id.sym = 0;  // unsymmetric
  id.job = -1;
  dmumps_c(&id);
  id.icntl[0] = id.icntl[1] = id.icntl[2] = -1, id.icntl[3] = 0;  // ICNTL(1–4): quiet
  if (rank == 0) {
    id.n = n;
    id.nnz = static_cast<MUMPS_INT8>(a.size());
    id.irn = irn.data();
    id.jcn = jcn.data();
    id.a = a.data();
  }
  auto run = [&](int job) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto t0 = Clock::now();
    id.job = job;
    dmumps_c(&id);
    const double s = since(t0);
    if (id.infog[0] < 0) {
      if (rank == 0)
        std::fprintf(stderr, "phiq_bench_mumps: MUMPS job %d: INFOG(1) = %d, INFOG(2) = %d\n", job, id.infog[0],
                     id.infog[1]);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    return s;
  };
  const double analysis_s = run(1);
  std::vector<double> factor, solve;
  std::vector<double> x(rank == 0 ? rhs.size() : 0);
  for (int r = 0; r < repeats; ++r) {
    factor.push_back(run(2));
    if (rank == 0) {
      x = rhs;
      id.rhs = x.data();  // overwritten with the solution
    }
    solve.push_back(run(3));
  }
  if (rank == 0) {
    double diff = 0, biggest = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      diff = std::max(diff, std::abs(x[i] - x_klu[i]));
      biggest = std::max(biggest, std::abs(x_klu[i]));
    }
    std::printf(
        "MUMPS %s (%d rank(s)): analysis %.4g ms, factorisation %.4g ms, solve %.4g ms, memory %d MB "
        "largest rank, %d MB all; |x_MUMPS - x_KLU| / |x|max = %.1e\n",
        MUMPS_VERSION, ranks, 1e3 * analysis_s, 1e3 * median(factor), 1e3 * median(solve), id.infog[20], id.infog[21],
        diff / biggest);
  }
  id.job = -2;
  dmumps_c(&id);
  MPI_Finalize();
  return 0;
}
