// Triplets → fixed CSC pattern with a slot map.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <random>

#include "phiq/sparse_pattern.hpp"

namespace phiq {
namespace {

TEST(SparsePattern, SortedUniqueAndSlotsAccumulateDuplicates) {
  // 3 x 3 with (1,0) given twice and columns out of order
  std::vector<Index> r = {2, 1, 0, 1, 2, 0}, c = {2, 0, 1, 0, 0, 0};
  std::vector<Index> slot;
  CscPattern p = build_csc_pattern(3, 3, r, c, &slot);
  EXPECT_EQ(p.col_ptr, (std::vector<Index>{0, 3, 4, 5}));
  EXPECT_EQ(p.row_idx, (std::vector<Index>{0, 1, 2, 0, 2}));
  EXPECT_EQ(slot, (std::vector<Index>{4, 1, 3, 1, 2, 0}));
}

TEST(SparsePattern, RandomTripletsReproduceTheDenseMatrix) {
  std::mt19937 rng(7);
  const Index rows = 40, cols = 30;
  std::uniform_int_distribution<Index> R(0, rows - 1), C(0, cols - 1);
  std::uniform_real_distribution<double> V(-1, 1);
  std::vector<Index> r, c;
  std::vector<double> v;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(rows, cols);
  for (int k = 0; k < 500; ++k) {
    r.push_back(R(rng)), c.push_back(C(rng)), v.push_back(V(rng));
    dense(r.back(), c.back()) += v.back();
  }
  std::vector<Index> slot;
  CscPattern p = build_csc_pattern(rows, cols, r, c, &slot);
  std::vector<double> vals(static_cast<std::size_t>(p.nnz()), 0.0);
  for (std::size_t k = 0; k < v.size(); ++k) vals[slot[k]] += v[k];
  Eigen::MatrixXd back = Eigen::MatrixXd::Zero(rows, cols);
  for (Index j = 0; j < cols; ++j) {
    for (Index k = p.col_ptr[j]; k < p.col_ptr[j + 1]; ++k) {
      if (k > p.col_ptr[j]) {
        EXPECT_LT(p.row_idx[k - 1], p.row_idx[k]);
      }
      back(p.row_idx[k], j) = vals[k];
    }
  }
  EXPECT_LT((back - dense).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(SparsePattern, OutOfRangeTripletIsAProgrammingError) {
  std::vector<Index> slot;
  EXPECT_THROW(build_csc_pattern(2, 2, {0, 2}, {0, 0}, &slot), Error);
}

}  // namespace
}  // namespace phiq
