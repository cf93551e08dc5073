// The block-triangular assembly: Φ(q, t) = 0 solved one strongly connected block of Φq's pattern at a time. A chain
// of loops (nfourbar, a scissor lift) is a sequence of small blocks, each reading only the coordinates of the blocks
// solved before it. Started on a position where every loop is singular at once, Newton on the whole system
// resolves one loop per iteration (each loop's singular direction is moved only by the second-order effect of the
// loop before it, which a linear step does not see), so a chain longer than the iteration budget is never
// assembled; block by block, each loop sees its input already moved and converges in a few steps of its own.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "phiq/kinematics.hpp"
#include "phiq/model.hpp"
#include "phiq/types.hpp"

namespace phiq::detail {

/// The square system's Φq pattern (the model's solve rows × its coordinates) in upper block-triangular form
/// (SuiteSparse BTF: a maximum transversal, then the strongly connected components): the rows of block b read only
/// the coordinates of blocks b, b + 1, …, so the blocks are solved last to first, each for its own coordinates with
/// those of the blocks after it fixed.
struct TriangularBlocks {
  std::vector<Index> rows;   ///< rows of Φ (the model's numbering), block by block
  std::vector<Index> cols;   ///< coordinates, block by block; cols[k] is matched with rows[k]
  std::vector<Index> start;  ///< block b holds rows[start[b]] … rows[start[b + 1] − 1] and the same cols
  Index largest = 0;         ///< rows in the largest block
  Index count() const { return static_cast<Index>(start.size()) - 1; }
};

/// The block-triangular form of `model`'s square system, or false when there is none: solve rows ≠ coordinates,
/// or the pattern is structurally singular (no perfect matching of rows to coordinates). O(nnz) (BTF's matching is
/// O(n · nnz) at worst; Jacobian patterns of mechanisms are matched in near-linear time).
bool triangular_blocks(const Model& model, TriangularBlocks* out);

/// What assemble_by_blocks() did.
struct BlockAssemblySummary {
  SolveStatus status = SolveStatus::kNotConverged;
  Index blocks = 0;         ///< strongly connected blocks of Φq's pattern
  Index largest = 0;        ///< rows in the largest
  Index iterations = 0;     ///< Newton steps, over all blocks
  int most_iterations = 0;  ///< the most any one block took
  std::string message;      ///< one line on a failure (which block, why); empty on success
};

/// Blocks larger than this are not solved densely: assemble_by_blocks() declines them (kNotSquare).
constexpr Index kLargestDenseBlock = 400;

/// Solves Φ(q, t) = 0 from `q` block by block in the order of triangular_blocks(): Newton on each block's rows in
/// its own coordinates, the step the minimum-norm least-squares solution of the block's dense Jacobian (a complete
/// orthogonal decomposition), so that a block still singular where it starts moves the least it must. A block is
/// done when each of its rows is within `tolerance` (row scale and rounding floor as NewtonOptions::tolerance).
/// Only the constraints owning a block's rows are evaluated for it, so a chain of n small blocks costs O(n) in all.
/// On return `q` holds the solution, or the blocks solved so far and the failing block's last iterate.
/// Statuses: kSuccess; kNotSquare when the method does not apply (no triangular form, a single block, or a block
/// over kLargestDenseBlock rows: the caller's whole-system solver is the better tool); kNotConverged (a block
/// did not converge in `max_iterations`) or kNonFinite, with the block's first constraint named in the message.
/// Pre-conditions: q has num_coordinates() entries. Not thread-safe on one `q`; the model is read only.
SolveStatus assemble_by_blocks(const Model& model, double t, double tolerance, int max_iterations, Eigen::VectorXd& q,
                               BlockAssemblySummary* summary);

}  // namespace phiq::detail
