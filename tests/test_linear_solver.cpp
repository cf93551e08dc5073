// Sparse LU (UMFPACK) against the dense reference; singular kept apart from failure; symbolic shared; unusable
// patterns reported in the model's terms.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>

#include <klu.h>

#include "generate.hpp"
#include "linear/klu_lu.hpp"
#include "phiq/kinematics.hpp"
#include "phiq/linear_solver.hpp"
#include "phiq/min_norm_solver.hpp"
#include "phiq/scene.hpp"

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

class SparseLu : public ::testing::TestWithParam<LinearSolverKind> {};

TEST_P(SparseLu, MatchesDenseLuAndReusesTheSymbolicAnalysis) {
  Sys s = random_system(200, 3);
  auto sym = analyse(GetParam(), s.p);
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
  // refactorising the first object with new values
  ASSERT_EQ(a->factorize(v2.data()), FactorStatus::kOk);
  ASSERT_TRUE(a->solve(rhs.data(), x.data()));
  EXPECT_LT((x - ref / 1.5).cwiseAbs().maxCoeff(), 1e-12);
}

TEST_P(SparseLu, TransposedSolveAndDeterminantSignMatchDenseLu) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    Sys s = random_system(60, seed);
    // flip the sign of a random number of rows: det changes sign with each, whatever the pivot order
    std::mt19937 rng(seed);
    const int flips = static_cast<int>(rng() % 7);
    for (int f = 0; f < flips; ++f) {
      const Index row = static_cast<Index>(rng() % 60);
      for (Index k = 0; k < s.p->nnz(); ++k)
        if (s.p->row_idx[static_cast<std::size_t>(k)] == row) s.values[static_cast<std::size_t>(k)] *= -1;
      s.dense.row(row) *= -1;
    }
    auto lu = analyse(GetParam(), s.p)->make_numeric();
    ASSERT_EQ(lu->factorize(s.values.data()), FactorStatus::kOk);
    const double det = s.dense.partialPivLu().determinant();
    EXPECT_EQ(lu->determinant_sign(), det > 0 ? 1 : -1) << "seed " << seed;
    // entries scaled by 10⁻⁹: the determinant (10⁻⁵⁴⁰ times det) underflows a double, its sign must not
    std::vector<double> tiny = s.values;
    for (double& v : tiny) v *= 1e-9;
    auto small = analyse(GetParam(), s.p)->make_numeric();
    ASSERT_EQ(small->factorize(tiny.data()), FactorStatus::kOk);
    EXPECT_EQ(small->determinant_sign(), det > 0 ? 1 : -1) << "seed " << seed << ", entries scaled by 1e-9";
    Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(60, -1, 2), x(60);
    ASSERT_TRUE(lu->solve_transposed(rhs.data(), x.data()));
    EXPECT_LT((s.dense.transpose() * x - rhs).cwiseAbs().maxCoeff(), 1e-12) << "seed " << seed;
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, SparseLu,
                         ::testing::Values(LinearSolverKind::kUmfpack, LinearSolverKind::kKlu,
                                           LinearSolverKind::kDense),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(LinearSolver, KluRefactorisesWithTheOldPivotsWhileTheyHold) {
  Sys s = random_system(300, 5);
  auto n = analyse(LinearSolverKind::kKlu, s.p)->make_numeric();
  Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(300, 1, 2), x(300);
  ASSERT_EQ(n->factorize(s.values.data()), FactorStatus::kOk);
  for (int k = 1; k <= 5; ++k) {  // small changes of values, as between Newton iterations
    std::vector<double> v = s.values;
    for (std::size_t i = 0; i < v.size(); ++i) v[i] *= 1.0 + 0.01 * k * std::sin(static_cast<double>(i));
    ASSERT_EQ(n->factorize(v.data()), FactorStatus::kOk);
    ASSERT_TRUE(n->solve(rhs.data(), x.data()));
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(300, 300);
    for (Index c = 0; c < 300; ++c)
      for (Index i = s.p->col_ptr[c]; i < s.p->col_ptr[c + 1]; ++i) dense(s.p->row_idx[i], c) = v[i];
    EXPECT_LT((dense * x - rhs).cwiseAbs().maxCoeff(), 1e-12);
  }
  EXPECT_EQ(n->pivoting_factorizations(), 1);  // five refactorisations, no new pivot search
}

// A KLU numeric object for the full 2 × 2 pattern (values column-major).
std::unique_ptr<SparseLuNumeric> full_2x2_klu() {
  auto p = std::make_shared<CscPattern>();
  std::vector<Index> slot;
  *p = build_csc_pattern(2, 2, {0, 1, 0, 1}, {0, 0, 1, 1}, &slot);
  return analyse(LinearSolverKind::kKlu, p)->make_numeric();
}

TEST(LinearSolver, KluSearchesPivotsAgainWhenTheOldOnesDegrade) {
  // full 2 x 2: first diagonally dominant (diagonal pivots), then with a tiny (1,1) entry, where the old pivot
  // order would divide by 1e-14
  auto n = full_2x2_klu();
  std::vector<double> a = {2, 1, 1, 2}, b = {1e-14, 1, 1, 1};  // column-major
  ASSERT_EQ(n->factorize(a.data()), FactorStatus::kOk);
  ASSERT_EQ(n->factorize(b.data()), FactorStatus::kOk);
  EXPECT_EQ(n->pivoting_factorizations(), 2);
  double rhs[2] = {1, 2}, x[2];
  ASSERT_TRUE(n->solve(rhs, x));
  EXPECT_NEAR(1e-14 * x[0] + x[1], 1.0, 1e-14);
  EXPECT_NEAR(x[0] + x[1], 2.0, 1e-14);
}

TEST(LinearSolver, KluChecksALowPivotRatioWithAPivotSearchBeforeReportingIt) {
  // Pivots chosen at [[0.002, 1], [1, 1]]: KLU keeps the diagonal 0.002 (above 1e-3 of its column), ratio
  // 0.002 / 499 = 4e-6. At [[1e-4, 1], [1, 1]] (det −1: well conditioned) the old order gives 1e-4 / 1e4 = 1e-8,
  // within the degradation allowed (1e-3 of 4e-6), which a sweep reported as a near-singular position (below 1e-7).
  // Below 1e-6 a pivot search measures again: the ratio is that of the matrix's own pivots, about 1.
  auto n = full_2x2_klu();
  std::vector<double> a = {0.002, 1, 1, 1}, b = {1e-4, 1, 1, 1};  // column-major
  ASSERT_EQ(n->factorize(a.data()), FactorStatus::kOk);
  EXPECT_NEAR(n->rcond(), 0.002 / 499.0, 1e-9);
  ASSERT_EQ(n->factorize(b.data()), FactorStatus::kOk);
  EXPECT_EQ(n->pivoting_factorizations(), 2);
  EXPECT_GT(n->rcond(), 0.5);
  EXPECT_EQ(n->determinant_sign(), -1);
  // and where the matrix itself is that close to singular, the search's ratio is the new reference: refactorised
  // at a matrix half as good, no further search (a pivot search only where the ratio falls tenfold below it)
  std::vector<double> c = {1, 1, 1, 1 + 1e-8}, d = {1, 1, 1, 1 + 0.5e-8};  // rows nearly parallel: 1e-8, 5e-9
  ASSERT_EQ(n->factorize(c.data()), FactorStatus::kOk);
  const std::int64_t searches = n->pivoting_factorizations();
  ASSERT_EQ(n->factorize(d.data()), FactorStatus::kOk);
  EXPECT_EQ(n->pivoting_factorizations(), searches);
  EXPECT_LT(n->rcond(), 1e-6);
}

// A pinned pivot order (what each workspace of a parallel sweep holds, pinned at row 0):
// restore_pinned_pivot_order() returns to it, even after a search replaced it, so that the factors of a matrix depend
// on that matrix and the pinned order only, bit for bit, whatever was factorised in between. A pin needs factors.
TEST(LinearSolver, KluReturnsToAPinnedPivotOrderWhateverWasFactorisedSince) {
  Sys s = random_system(300, 7);
  auto sym = analyse(LinearSolverKind::kKlu, s.p);
  auto scaled = [&](double k) {
    std::vector<double> v = s.values;
    for (std::size_t i = 0; i < v.size(); ++i) v[i] *= 1.0 + k * std::sin(static_cast<double>(i));
    return v;
  };
  const std::vector<double> at_pin = scaled(0.0), target = scaled(0.05), other = scaled(0.02);
  Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(300, 1, 2), fresh_x(300), x(300);
  // reference: pinned, then straight to the target
  auto fresh = sym->make_numeric();
  EXPECT_FALSE(fresh->pin_pivot_order());  // nothing factorised: nothing to pin
  ASSERT_EQ(fresh->factorize(at_pin.data()), FactorStatus::kOk);
  ASSERT_TRUE(fresh->pin_pivot_order());
  ASSERT_TRUE(fresh->restore_pinned_pivot_order());
  ASSERT_EQ(fresh->factorize(target.data()), FactorStatus::kOk);
  ASSERT_TRUE(fresh->solve(rhs.data(), fresh_x.data()));
  EXPECT_EQ(fresh->pivoting_factorizations(), 1);  // the target refactorised with the pinned order

  // pinned, then refactorised elsewhere, then a pivot search on a matrix whose diagonal (the pinned pivots) is
  // nearly gone, then back: the target's factors are the reference's, to the bit
  auto used = sym->make_numeric();
  ASSERT_EQ(used->factorize(at_pin.data()), FactorStatus::kOk);
  ASSERT_TRUE(used->pin_pivot_order());
  ASSERT_EQ(used->factorize(other.data()), FactorStatus::kOk);
  std::vector<double> no_diagonal = at_pin;
  for (Index c = 0; c < 300; ++c)
    for (Index k = s.p->col_ptr[c]; k < s.p->col_ptr[c + 1]; ++k)
      if (s.p->row_idx[static_cast<std::size_t>(k)] == c) no_diagonal[static_cast<std::size_t>(k)] *= 1e-12;
  ASSERT_EQ(used->factorize(no_diagonal.data()), FactorStatus::kOk);
  ASSERT_EQ(used->pivoting_factorizations(), 2);  // the pinned order degraded there: searched again
  const std::int64_t before = used->pivoting_factorizations();
  ASSERT_TRUE(used->restore_pinned_pivot_order());
  ASSERT_EQ(used->factorize(target.data()), FactorStatus::kOk);
  EXPECT_EQ(used->pivoting_factorizations(), before);
  ASSERT_TRUE(used->solve(rhs.data(), x.data()));
  for (Index i = 0; i < 300; ++i) ASSERT_EQ(x(i), fresh_x(i)) << "entry " << i;
  EXPECT_EQ(used->rcond(), fresh->rcond());
  EXPECT_EQ(used->determinant_sign(), fresh->determinant_sign());
  EXPECT_EQ(used->block_signs(), fresh->block_signs());
  // forget_pivot_order() still searches (pinned or not); unpinned, there is nothing to restore
  used->forget_pivot_order();
  ASSERT_EQ(used->factorize(target.data()), FactorStatus::kOk);
  EXPECT_EQ(used->pivoting_factorizations(), before + 1);
  ASSERT_TRUE(used->restore_pinned_pivot_order());
  ASSERT_EQ(used->factorize(target.data()), FactorStatus::kOk);
  EXPECT_EQ(used->pivoting_factorizations(), before + 1);
  used->unpin_pivot_order();
  EXPECT_FALSE(used->restore_pinned_pivot_order());
  // libraries that always pivot pin nothing
  auto umfpack = analyse(LinearSolverKind::kUmfpack, s.p)->make_numeric();
  ASSERT_EQ(umfpack->factorize(at_pin.data()), FactorStatus::kOk);
  EXPECT_FALSE(umfpack->pin_pivot_order());
}

// KLU factorises a block triangular form block by block; block_signs() tells the signs of the blocks'
// determinants apart where det A's sign cannot: two blocks turning negative at once leave det A's sign as it was.
// Three 2 × 2 blocks [[a, 1], [1, d]] coupled above the diagonal, rows and columns scrambled. The fingerprint must
// depend on the blocks' signs only, not on the pivots chosen (a = d = 1e4 makes KLU pivot on other rows of a
// block whose sign is the same) nor on the path (a fresh pivot search and a refactorisation
// of the same values agree).
TEST(LinearSolver, KluBlockSignsSeeBlocksThatTurnNegativeTogether) {
  const Index row_of[6] = {3, 0, 5, 1, 4, 2}, col_of[6] = {1, 4, 0, 5, 2, 3};
  std::vector<Index> r, c;
  for (Index b = 0; b < 3; ++b)
    for (Index i = 0; i < 2; ++i)
      for (Index j = 0; j < 2; ++j) r.push_back(row_of[2 * b + i]), c.push_back(col_of[2 * b + j]);
  r.push_back(row_of[0]), c.push_back(col_of[2]);  // couplings above the diagonal blocks
  r.push_back(row_of[2]), c.push_back(col_of[4]);
  auto p = std::make_shared<CscPattern>();
  std::vector<Index> slot;
  *p = build_csc_pattern(6, 6, r, c, &slot);
  auto sym = analyse(LinearSolverKind::kKlu, p);
  ASSERT_EQ(detail::describe_klu(*sym).blocks, 3);
  auto running = sym->make_numeric();
  // (det sign, block signs), the same from the running object (refactorisation) and a fresh one (pivot search)
  auto signs = [&](std::array<double, 3> a, std::array<double, 3> d) {
    std::vector<double> v(static_cast<std::size_t>(p->nnz()), 0.0);
    std::size_t k = 0;
    for (int b = 0; b < 3; ++b)
      for (const double x : {a[b], 1.0, 1.0, d[b]}) v[static_cast<std::size_t>(slot[k++])] += x;
    v[static_cast<std::size_t>(slot[k++])] += 0.5;
    v[static_cast<std::size_t>(slot[k++])] += 0.5;
    auto fresh = sym->make_numeric();
    EXPECT_EQ(fresh->factorize(v.data()), FactorStatus::kOk);
    EXPECT_EQ(running->factorize(v.data()), FactorStatus::kOk);
    EXPECT_EQ(running->determinant_sign(), fresh->determinant_sign());
    EXPECT_EQ(running->block_signs(), fresh->block_signs());
    return std::make_pair(fresh->determinant_sign(), fresh->block_signs());
  };
  const auto all_positive = signs({2, 2, 2}, {3, 3, 3});  // det 5 each
  // pivots on the blocks' 1s, except where a = d = 1e4 (the 1s then below 1e-3 of their columns): the same
  // signs, other pivot rows
  const auto two_swapped = signs({1e4, 1e4, 2}, {1e4, 1e4, 3});
  const auto two_negative = signs({1e-4, 1e-4, 2}, {1e-4, 1e-4, 3});  // det −1 in blocks 0 and 1
  const auto third_negative = signs({2, 2, 0.01}, {3, 3, 0.01});
  EXPECT_EQ(two_negative.first, all_positive.first);    // det A keeps its sign ...
  EXPECT_NE(two_negative.second, all_positive.second);  // ... the blocks do not
  EXPECT_EQ(two_swapped, all_positive);
  EXPECT_EQ(third_negative.first, -all_positive.first);
  EXPECT_NE(third_negative.second, two_negative.second);
  EXPECT_NE(third_negative.second, all_positive.second);
  EXPECT_EQ(signs({2, 2, 2}, {3, 3, 3}), all_positive);  // back again
  // a library that factorises A whole has no blocks to tell
  auto dense = analyse(LinearSolverKind::kUmfpack, p)->make_numeric();
  std::vector<double> v(static_cast<std::size_t>(p->nnz()), 1.0);
  for (Index i = 0; i < 6; ++i)
    v[static_cast<std::size_t>(slot[static_cast<std::size_t>(4 * (i / 2) + 3 * (i % 2))])] = 3.0;
  ASSERT_EQ(dense->factorize(v.data()), FactorStatus::kOk);
  EXPECT_EQ(dense->block_signs(), 0u);
}

TEST(LinearSolver, SingularIsAWarningNotAFailure) {
  // [[1, 2], [2, 4]]
  auto p = std::make_shared<CscPattern>();
  std::vector<Index> slot;
  *p = build_csc_pattern(2, 2, {0, 1, 0, 1}, {0, 0, 1, 1}, &slot);
  std::vector<double> v = {1, 2, 2, 4};
  for (LinearSolverKind k : {LinearSolverKind::kUmfpack, LinearSolverKind::kKlu, LinearSolverKind::kDense}) {
    auto n = analyse(k, p)->make_numeric();
    EXPECT_EQ(n->factorize(v.data()), FactorStatus::kSingular) << to_string(k);
    EXPECT_EQ(n->rcond(), 0.0) << to_string(k);
  }
  std::vector<double> ok = {1, 2, 2, 5};
  auto n = analyse(LinearSolverKind::kUmfpack, p)->make_numeric();
  EXPECT_EQ(n->factorize(ok.data()), FactorStatus::kOk);
}

// Φq of a generated scene at its first position, with the dense matrix (not for `sparse_only`).
struct GeneratedJacobian {
  std::shared_ptr<CscPattern> pattern;
  std::vector<double> values;
  Eigen::MatrixXd dense;
};
GeneratedJacobian generated_jacobian(const char* kind, std::int64_t n, const char* coords = "natural",
                                     bool sparse_only = false) {
  tools::GenerateOptions g;
  g.kind = kind, g.n = n, g.coords = coords;
  Scene scene = parse_scene(tools::generate_scene(g), std::string(kind) + ".yaml");
  const Model& m = *scene.model;
  Workspace ws(m);
  EXPECT_EQ(solve_position(m, scene.sweep.t_begin, scene.sweep.assembly, ws), SolveStatus::kSuccess);
  GeneratedJacobian j;
  j.pattern = std::make_shared<CscPattern>(m.jacobian_pattern());
  j.values.assign(static_cast<std::size_t>(j.pattern->nnz()), 0.0);
  m.jacobian(ws.q.data(), scene.sweep.t_begin, j.values.data());
  if (sparse_only) return j;
  j.dense = Eigen::MatrixXd::Zero(j.pattern->rows, j.pattern->cols);
  for (Index c = 0; c < j.pattern->cols; ++c)
    for (Index k = j.pattern->col_ptr[c]; k < j.pattern->col_ptr[c + 1]; ++k)
      j.dense(j.pattern->row_idx[k], c) = j.values[static_cast<std::size_t>(k)];
  return j;
}

// KLU refactorisations work on the unscaled matrix with the pivot order chosen on the row-scaled one (klu_lu.cpp):
// on a badly scaled matrix (rows multiplied by 10⁻⁶ … 10⁶, as a model mixing micrometres and kilometres would
// give) the refactorised factors solve as accurately as the pivoting factorisation's, transposed too, with the
// same determinant sign, and the reciprocal pivot ratio is still that of the scaled rows: the same as for the
// unscaled matrix, whichever factorisation made it. Values that move (a sweep) are refactorised without a new
// pivot search. Either index width.
TEST(LinearSolver, KluRefactorisationIsAsAccurateOnBadlyScaledRows) {
  const GeneratedJacobian j = generated_jacobian("grid", 100);
  const Index n = j.pattern->cols;
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1, 2);
  Eigen::VectorXd row_scale(n);
  for (Index i = 0; i < n; ++i) row_scale(i) = std::pow(10.0, static_cast<double>((i * 7) % 13) - 6.0);
  auto scaled = [&](const std::vector<double>& v) {
    std::vector<double> out(v);
    for (Index c = 0; c < n; ++c)
      for (Index k = j.pattern->col_ptr[c]; k < j.pattern->col_ptr[c + 1]; ++k)
        out[static_cast<std::size_t>(k)] *= row_scale(j.pattern->row_idx[k]);
    return out;
  };
  auto dense_of = [&](const std::vector<double>& v) {
    Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
    for (Index c = 0; c < n; ++c)
      for (Index k = j.pattern->col_ptr[c]; k < j.pattern->col_ptr[c + 1]; ++k)
        d(j.pattern->row_idx[k], c) = v[static_cast<std::size_t>(k)];
    return d;
  };
  // the matrix a sweep meets a few steps on: every value moved by up to 1e-3 of itself
  std::vector<double> moved(j.values);
  for (std::size_t k = 0; k < moved.size(); ++k) moved[k] *= 1.0 + 1e-3 * std::sin(0.37 * static_cast<double>(k));
  for (const std::vector<double>& base : {j.values, moved}) {
    auto plain_lu = analyse(LinearSolverKind::kKlu, j.pattern)->make_numeric();
    ASSERT_EQ(plain_lu->factorize(base.data()), FactorStatus::kOk);
    const double rcond_unscaled = plain_lu->rcond();
    const int sign = plain_lu->determinant_sign();
    const std::vector<double> values = scaled(base);
    const Eigen::MatrixXd a = dense_of(values);
    const Eigen::VectorXd b = row_scale.asDiagonal() * rhs;
    const Eigen::VectorXd x_ref = a.partialPivLu().solve(b), y_ref = a.transpose().partialPivLu().solve(rhs);
    for (auto [width, bits] : {std::pair{detail::KluIndexWidth::k32, 32}, std::pair{detail::KluIndexWidth::k64, 64}}) {
      auto lu = detail::analyse_klu(j.pattern, width)->make_numeric();
      ASSERT_EQ(lu->factorize(values.data()), FactorStatus::kOk);  // pivots chosen on the scaled rows
      EXPECT_NEAR(lu->rcond(), rcond_unscaled, 1e-12 * rcond_unscaled) << bits;
      for (int refactorisation = 0; refactorisation < 2; ++refactorisation) {
        Eigen::VectorXd x(n), y(n);
        ASSERT_TRUE(lu->solve(b.data(), x.data()));
        ASSERT_TRUE(lu->solve_transposed(rhs.data(), y.data()));
        EXPECT_LT((x - x_ref).cwiseAbs().maxCoeff(), 1e-11 * x_ref.cwiseAbs().maxCoeff()) << bits << refactorisation;
        EXPECT_LT((y - y_ref).cwiseAbs().maxCoeff(), 1e-11 * y_ref.cwiseAbs().maxCoeff()) << bits << refactorisation;
        EXPECT_EQ(lu->determinant_sign(), sign) << bits;
        const double before = lu->rcond();
        ASSERT_EQ(lu->factorize(values.data()), FactorStatus::kOk);  // the same values again: a refactorisation
        EXPECT_NEAR(lu->rcond(), before, 1e-12 * before) << bits << ": measured on the scaled rows either way";
      }
      EXPECT_EQ(lu->pivoting_factorizations(), 1) << bits << ": refactorised, not pivoted again";
    }
  }
}

// KLU's blocks put in the lattice's own order (klu_lu.cpp: resequence_blocks), with either index width: the same
// solutions, transposed solutions and determinant sign as the dense LU. A 20 x 20 lattice of parallelograms
// (phiq generate grid) is block triangular with two-coordinate blocks, which KLU's depth-first search leaves
// scattered; a chain of four-bars is already in order and keeps KLU's.
TEST(LinearSolver, KluBlocksFollowTheModelsOrderWithEitherIndexWidth) {
  const GeneratedJacobian grid = generated_jacobian("grid", 400);
  const Index n = grid.pattern->cols;
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1, 2);
  const Eigen::PartialPivLU<Eigen::MatrixXd> ref(grid.dense);
  const int ref_sign = ref.determinant() > 0 ? 1 : -1;
  // KLU itself, in its own order: the same blocks and pivots, so the same reciprocal pivot ratio (klu_lu.cpp
  // computes it with the determinant's sign in one pass over U's diagonal instead of calling klu_rcond)
  double klu_rcond_itself = 0.0;
  {
    std::vector<SuiteSparse_long> ap(grid.pattern->col_ptr.begin(), grid.pattern->col_ptr.end()),
        ai(grid.pattern->row_idx.begin(), grid.pattern->row_idx.end());
    std::vector<double> ax = grid.values;
    klu_l_common c;
    klu_l_defaults(&c);
    klu_l_symbolic* sym = klu_l_analyze(n, ap.data(), ai.data(), &c);
    klu_l_numeric* num = klu_l_factor(ap.data(), ai.data(), ax.data(), sym, &c);
    ASSERT_NE(num, nullptr);
    klu_l_rcond(sym, num, &c);
    klu_rcond_itself = c.rcond;
    klu_l_free_numeric(&num, &c);
    klu_l_free_symbolic(&sym, &c);
  }
  for (auto [width, bits] : {std::pair{detail::KluIndexWidth::k32, 32}, std::pair{detail::KluIndexWidth::k64, 64}}) {
    auto sym = detail::analyse_klu(grid.pattern, width);
    const detail::KluAnalysis a = detail::describe_klu(*sym);
    EXPECT_EQ(a.index_bits, bits);
    EXPECT_GT(a.blocks, n / 3);  // dyads: a block per node, a few larger ones per row
    EXPECT_TRUE(a.resequenced);
    EXPECT_GT(a.klu_jump, 10.0);
    EXPECT_LE(a.jump, 2.0);  // consecutive columns of the factorisation are neighbours in the model
    auto lu = sym->make_numeric();
    ASSERT_EQ(lu->factorize(grid.values.data()), FactorStatus::kOk);
    Eigen::VectorXd x(n), y(n);
    ASSERT_TRUE(lu->solve(rhs.data(), x.data()));
    ASSERT_TRUE(lu->solve_transposed(rhs.data(), y.data()));
    EXPECT_LT((grid.dense * x - rhs).cwiseAbs().maxCoeff(), 1e-12) << bits;
    EXPECT_LT((grid.dense.transpose() * y - rhs).cwiseAbs().maxCoeff(), 1e-12) << bits;
    EXPECT_EQ(lu->determinant_sign(), ref_sign) << bits;
    EXPECT_NEAR(lu->rcond(), klu_rcond_itself, 1e-15 * klu_rcond_itself) << bits;
    EXPECT_GT(lu->rcond(), 0.0);
    EXPECT_GT(lu->memory_bytes(), 0u);
  }
  // the default on a small model is 32-bit
  EXPECT_EQ(detail::describe_klu(*analyse(LinearSolverKind::kKlu, grid.pattern)).index_bits, 32);
  const GeneratedJacobian chain = generated_jacobian("nfourbar", 50);
  const detail::KluAnalysis c = detail::describe_klu(*detail::analyse_klu(chain.pattern));
  EXPECT_FALSE(c.resequenced);
  EXPECT_LE(c.klu_jump, 2.0);
}

// BTF's maximum transversal depends on the order it meets the columns in: on the reference-point grid it costs
// about nnz(Φq) per 100 cells in the model's order (N^1.8: 70 % of loading 10⁵ cells) and 0.04 nnz reversed
// (klu_lu.cpp, analyze_bounded). Past its bound of 8 nnz the analysis searches the reversed columns, and maps
// KLU's column order back; past it both ways, the model's order without a bound. Each analysis solves as UMFPACK
// does, with the same determinant sign (UMFPACK's is read from a mantissa and an exponent: the determinant of the
// 24 270-column matrix below underflows a double, and its sign read as 0, singular).
TEST(LinearSolver, KluTransversalSearchesTheColumnsInTheOrderThatStaysWithinItsBound) {
  auto check = [](const std::shared_ptr<CscPattern>& pattern, const std::vector<double>& values, int transversal) {
    const Index n = pattern->cols;
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n, -1, 2);
    auto residual = [&](const Eigen::VectorXd& x, bool transposed) {
      Eigen::VectorXd r = -rhs;
      for (Index c = 0; c < n; ++c)
        for (Index k = pattern->col_ptr[c]; k < pattern->col_ptr[c + 1]; ++k) {
          const double v = values[static_cast<std::size_t>(k)];
          const Index i = pattern->row_idx[k];
          if (transposed)
            r(c) += v * x(i);
          else
            r(i) += v * x(c);
        }
      return r.cwiseAbs().maxCoeff();
    };
    auto umf = analyse(LinearSolverKind::kUmfpack, pattern)->make_numeric();
    ASSERT_EQ(umf->factorize(values.data()), FactorStatus::kOk);
    Eigen::VectorXd x_ref(n);
    ASSERT_TRUE(umf->solve(rhs.data(), x_ref.data()));
    EXPECT_NE(umf->determinant_sign(), 0) << n;
    for (auto width : {detail::KluIndexWidth::k32, detail::KluIndexWidth::k64}) {
      auto sym = detail::analyse_klu(pattern, width);
      EXPECT_EQ(detail::describe_klu(*sym).transversal, transversal) << n;
      auto lu = sym->make_numeric();
      ASSERT_EQ(lu->factorize(values.data()), FactorStatus::kOk);
      for (int refactorisation = 0; refactorisation < 2; ++refactorisation) {
        Eigen::VectorXd x(n), y(n);
        ASSERT_TRUE(lu->solve(rhs.data(), x.data()));
        ASSERT_TRUE(lu->solve_transposed(rhs.data(), y.data()));
        EXPECT_LT(residual(x, false), 1e-11) << n;
        EXPECT_LT(residual(y, true), 1e-11) << n;
        EXPECT_LT((x - x_ref).cwiseAbs().maxCoeff(), 1e-9 * x_ref.cwiseAbs().maxCoeff()) << n;
        EXPECT_EQ(lu->determinant_sign(), umf->determinant_sign()) << n;
        ASSERT_EQ(lu->factorize(values.data()), FactorStatus::kOk);
      }
    }
  };
  // 400 cells: 7.1 nnz in the model's order, within the bound; 1000: 12.3, reversed (0.04)
  const GeneratedJacobian small = generated_jacobian("grid", 400, "reference-point", true);
  check(small.pattern, small.values, 0);
  const GeneratedJacobian grid = generated_jacobian("grid", 1000, "reference-point", true);
  check(grid.pattern, grid.values, 1);
  // The 2000-cell grid (21 nnz) beside itself with its columns reversed: each order meets one of them in its bad
  // order, about 10 nnz of the whole either way, so the search runs in the model's order without a bound.
  const GeneratedJacobian big = generated_jacobian("grid", 2000, "reference-point", true);
  const Index m = big.pattern->cols;
  std::vector<Index> rows, cols;
  std::vector<double> trip_values;
  for (int copy = 0; copy < 2; ++copy)
    for (Index c = 0; c < m; ++c)
      for (Index k = big.pattern->col_ptr[c]; k < big.pattern->col_ptr[c + 1]; ++k) {
        rows.push_back(big.pattern->row_idx[k] + copy * m);
        cols.push_back(copy == 0 ? c : 2 * m - 1 - c);
        trip_values.push_back(big.values[static_cast<std::size_t>(k)]);
      }
  std::vector<Index> slot;
  auto both = std::make_shared<CscPattern>(build_csc_pattern(2 * m, 2 * m, rows, cols, &slot));
  std::vector<double> values(static_cast<std::size_t>(both->nnz()));
  for (std::size_t k = 0; k < slot.size(); ++k) values[static_cast<std::size_t>(slot[k])] = trip_values[k];
  check(both, values, 2);
}

TEST(LinearSolver, NonSquarePatternIsRefused) {
  auto p = std::make_shared<CscPattern>();
  std::vector<Index> slot;
  *p = build_csc_pattern(2, 3, {0, 1}, {0, 2}, &slot);
  EXPECT_THROW(analyse(LinearSolverKind::kUmfpack, p), Error);
}

}  // namespace
}  // namespace phiq

namespace phiq {
namespace {

// A pattern a factorisation library cannot use is reported in the model's terms — what the Jacobian lacks — and
// never by the library's status number (KLU -3, UMFPACK -5 and CHOLMOD -4 for the same empty matrix).
TEST(LinearSolver, AnUnusablePatternIsDescribedNotGivenAsAStatus) {
  auto empty = std::make_shared<CscPattern>();
  empty->rows = empty->cols = 1;
  empty->col_ptr = {0, 0};
  for (LinearSolverKind kind : {LinearSolverKind::kKlu, LinearSolverKind::kUmfpack}) {
    SCOPED_TRACE(to_string(kind));
    try {
      (void)analyse(kind, empty);
      ADD_FAILURE() << "an empty 1 x 1 pattern was analysed";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.find("status"), std::string::npos) << m;
      EXPECT_NE(m.find("1 equation that involves no coordinate (empty rows) and 1 coordinate that no equation "
                       "involves (empty columns)"),
                std::string::npos)
          << m;
    }
  }
  MinNormSolver min_norm(empty);
  const double none[1] = {0.0};
  EXPECT_NE(min_norm.factorize(none, 0.0), FactorStatus::kOk);
  EXPECT_EQ(min_norm.last_message().find("status"), std::string::npos) << min_norm.last_message();
}

}  // namespace
}  // namespace phiq
