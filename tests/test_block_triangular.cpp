// The block-triangular assembly (engine/src/solve/block_triangular.*): BTF's blocks of Φq's pattern, solved last to
// first, each evaluating only its own constraints. Checked against the exact parallelogram of nfourbar, against the
// triangular property itself, and against whole-system Newton, which cannot assemble a long chain started flat.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "solve/block_triangular.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

using detail::assemble_by_blocks;
using detail::BlockAssemblySummary;
using detail::TriangularBlocks;

// Every entry of Φq's pattern in a row of block b lies in a column of block b or after it (upper triangular), and
// the rows and columns are each a permutation.
void expect_upper_triangular(const Model& model, const TriangularBlocks& tb) {
  const Index n = model.num_coordinates();
  ASSERT_EQ(static_cast<Index>(tb.rows.size()), n);
  ASSERT_EQ(static_cast<Index>(tb.cols.size()), n);
  std::vector<Index> block_of_row(static_cast<std::size_t>(model.num_equations()), -1), block_of_col(n, -1);
  for (Index b = 0; b < tb.count(); ++b)
    for (Index k = tb.start[static_cast<std::size_t>(b)]; k < tb.start[static_cast<std::size_t>(b) + 1]; ++k) {
      ASSERT_EQ(block_of_row[static_cast<std::size_t>(tb.rows[static_cast<std::size_t>(k)])], -1);
      ASSERT_EQ(block_of_col[static_cast<std::size_t>(tb.cols[static_cast<std::size_t>(k)])], -1);
      block_of_row[static_cast<std::size_t>(tb.rows[static_cast<std::size_t>(k)])] = b;
      block_of_col[static_cast<std::size_t>(tb.cols[static_cast<std::size_t>(k)])] = b;
    }
  const CscPattern& p = model.jacobian_pattern();
  Index entries = 0;
  for (Index j = 0; j < p.cols; ++j)
    for (Index e = p.col_ptr[j]; e < p.col_ptr[j + 1]; ++e) {
      const Index rb = block_of_row[static_cast<std::size_t>(p.row_idx[static_cast<std::size_t>(e)])];
      EXPECT_LE(rb, block_of_col[static_cast<std::size_t>(j)]) << "row " << p.row_idx[e] << ", column " << j;
      ++entries;
    }
  EXPECT_EQ(entries, p.nnz());
}

// nfourbar of N loops: the drive's angle, crank 0's tip (its crank and angle rows) and each further tip P_i (crank i
// and coupler i − 1) are blocks of their own, N + 2 in all, none larger than 2.
TEST(BlockTriangular, AChainOfLoopsFallsIntoOneBlockPerTip) {
  for (Index n : {1, 7, 50}) {
    const Model model = test::nfourbar_model(n, 0.3, 1.0);
    TriangularBlocks tb;
    ASSERT_TRUE(detail::triangular_blocks(model, &tb));
    EXPECT_EQ(tb.count(), n + 2);
    EXPECT_EQ(tb.largest, 2);
    expect_upper_triangular(model, tb);
    // the last block, solved first, is the driven angle alone
    EXPECT_EQ(model.coordinate_names()[static_cast<std::size_t>(tb.cols.back())], "theta");
  }
}

// Started exactly flat (every crank, coupler and the ground collinear: Φq singular in every loop at once), the chain
// is assembled at θ = 0.01 block by block, every tip on the parallelogram, each block in a few iterations however
// long the chain. Whole-system Newton (assemble(), least squares) moves one loop per iteration and does not.
TEST(BlockTriangular, AChainStartedFlatIsAssembledBlockByBlock) {
  const double rate = 1.0, t = 0.01;
  for (Index n : {150, 10000}) {
    const Model model = test::nfourbar_model(n, 0.0, rate);
    Eigen::VectorXd q = model.initial_positions();
    BlockAssemblySummary bs;
    ASSERT_EQ(assemble_by_blocks(model, t, 1e-14, 30, q, &bs), SolveStatus::kSuccess) << bs.message;
    EXPECT_EQ(bs.blocks, n + 2);
    EXPECT_EQ(bs.largest, 2);
    EXPECT_LE(bs.most_iterations, 6);
    EXPECT_GE(bs.iterations, n + 1);  // every tip moved
    const auto exact = test::nfourbar_exact(model, 0.0, rate);
    tools::ClosedFormErrors err(*exact);
    err.add(t, q.data(), nullptr, nullptr);
    // to rounding: the far tips are at x ≈ 10⁴, where 64 ulps are 1e-10 (the rows' rounding floor)
    EXPECT_LT(err.q_error, 1e-9);
    Eigen::VectorXd phi(model.num_equations());
    model.residual(q.data(), t, phi.data());
    EXPECT_LE(scaled_residual(model, phi), 1e-11);
  }
  const Model model = test::nfourbar_model(150, 0.0, rate);
  Eigen::VectorXd q = model.initial_positions();
  AssemblySummary as;
  EXPECT_NE(assemble(model, t, {}, q, &as), SolveStatus::kSuccess);
  EXPECT_EQ(as.iterations, 100);
}

// A block that does not converge is named by its first constraint, with the blocks before it solved and kept.
TEST(BlockTriangular, ABlockThatDoesNotConvergeIsNamed) {
  const Model model = test::nfourbar_model(3, 0.0, 1.0);
  Eigen::VectorXd q = model.initial_positions();
  BlockAssemblySummary bs;
  EXPECT_EQ(assemble_by_blocks(model, 0.5, 1e-14, 1, q, &bs), SolveStatus::kNotConverged);
  EXPECT_HAS(bs.message, "of 5 ('");
  EXPECT_HAS(bs.message, "did not converge in 1 iterations");
  EXPECT_DOUBLE_EQ(q[model.coordinate_index("theta")], 0.5);  // the driver's block, linear, was solved
}

// A system that is one block (a single loop closed on itself) is declined: whole-system Newton is the tool there.
TEST(BlockTriangular, OneBlockIsDeclined) {
  const Scene sc = parse_scene(R"(phiq: 1
coordinates: {x: 0.7, y: 0.7}
constraints:
  - {name: circle, type: equation, expr: "x^2 + y^2 - 1"}
  - {name: diagonal, type: equation, expr: "x - y"}
time: {start: 0, end: 0, steps: 0}
)",
                               "one_block.yaml");
  TriangularBlocks tb;
  ASSERT_TRUE(detail::triangular_blocks(*sc.model, &tb));
  EXPECT_EQ(tb.count(), 1);
  Eigen::VectorXd q = sc.model->initial_positions();
  BlockAssemblySummary bs;
  EXPECT_EQ(assemble_by_blocks(*sc.model, 0.0, 1e-12, 30, q, &bs), SolveStatus::kNotSquare);
  EXPECT_HAS(bs.message, "one block");
  EXPECT_EQ(q, sc.model->initial_positions());
}

}  // namespace
}  // namespace phiq
