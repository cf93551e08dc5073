// Sparse LU (UMFPACK) against the dense reference; singular kept apart from failure; symbolic shared.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "phiq/linear_solver.hpp"

namespace phiq {
namespace {

struct Sys {
  std::shared_ptr<CscPattern> p = std::make_shared<CscPattern>();
  std::vector<double> values;
  Eigen::MatrixXd dense;
};

// Random sparse, diagonally dominant n x n matrix.
Sys random_system(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<Index> C(0, n - 1);
  std::uniform_real_distribution<double> V(-1, 1);
  std::vector<Index> r, c;
  std::vector<double> v;
  for (Index i = 0; i < n; ++i) {
    r.push_back(i), c.push_back(i), v.push_back(5.0 + V(rng));
    for (int k = 0; k < 3; ++k) r.push_back(i), c.push_back(C(rng)), v.push_back(V(rng));
  }
  Sys s;
  std::vector<Index> slot;
  *s.p = build_csc_pattern(n, n, r, c, &slot);
  s.values.assign(static_cast<std::size_t>(s.p->nnz()), 0.0);
  s.dense = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t k = 0; k < v.size(); ++k) s.values[slot[k]] += v[k], s.dense(r[k], c[k]) += v[k];
  return s;
}

TEST(LinearSolver, UmfpackMatchesDenseLuAndReusesTheSymbolicAnalysis) {
  Sys s = random_system(200, 3);
  auto sym = analyse(LinearSolverKind::kUmfpack, s.p);
  auto a = sym->make_numeric(), b = sym->make_numeric();  // two numeric objects share one symbolic
  Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(200, -1, 1), x(200), y(200);
  ASSERT_EQ(a->factorize(s.values.data()), FactorStatus::kOk);
  ASSERT_TRUE(a->solve(rhs.data(), x.data()));
  Eigen::VectorXd ref = s.dense.partialPivLu().solve(rhs);
  EXPECT_LT((x - ref).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GT(a->rcond(), 0.0);
  // new values, same pattern: the second numeric object, same symbolic analysis
  std::vector<double> v2 = s.values;
  for (double& v : v2) v *= 1.5;
  ASSERT_EQ(b->factorize(v2.data()), FactorStatus::kOk);
  ASSERT_TRUE(b->solve(rhs.data(), y.data()));
  EXPECT_LT((y - ref / 1.5).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(LinearSolver, SingularIsAWarningNotAFailure) {
  // [[1, 2], [2, 4]]
  auto p = std::make_shared<CscPattern>();
  std::vector<Index> slot;
  *p = build_csc_pattern(2, 2, {0, 1, 0, 1}, {0, 0, 1, 1}, &slot);
  std::vector<double> v = {1, 2, 2, 4};
  for (LinearSolverKind k : {LinearSolverKind::kUmfpack, LinearSolverKind::kDense}) {
    auto n = analyse(k, p)->make_numeric();
    EXPECT_EQ(n->factorize(v.data()), FactorStatus::kSingular) << to_string(k);
    EXPECT_EQ(n->rcond(), 0.0) << to_string(k);
  }
  std::vector<double> ok = {1, 2, 2, 5};
  auto n = analyse(LinearSolverKind::kUmfpack, p)->make_numeric();
  EXPECT_EQ(n->factorize(ok.data()), FactorStatus::kOk);
}

TEST(LinearSolver, NonSquarePatternIsRefused) {
  auto p = std::make_shared<CscPattern>();
  std::vector<Index> slot;
  *p = build_csc_pattern(2, 3, {0, 1}, {0, 2}, &slot);
  EXPECT_THROW(analyse(LinearSolverKind::kUmfpack, p), Error);
}

}  // namespace
}  // namespace phiq
