// The block-triangular assembly (block_triangular.hpp): BTF's ordering of Φq's pattern, and Newton one block at a
// time, evaluating only the constraints that own the block's rows.
#include "solve/block_triangular.hpp"

#include <btf.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "phiq/constraint_block.hpp"
#include "phiq/text.hpp"
#include "solve/tolerance_tests.hpp"

namespace phiq::detail {

bool triangular_blocks(const Model& model, TriangularBlocks* out) {
  const CscPattern& p = model.solve_pattern();
  const Index n = model.num_coordinates();
  if (p.rows != n || p.cols != n || n == 0) return false;
  // BTF's long interface takes the pattern as it is stored (Index is 64-bit); it only reads Ap and Ai.
  static_assert(sizeof(Index) == sizeof(SuiteSparse_long));
  std::vector<SuiteSparse_long> P(static_cast<std::size_t>(n)), Q(P.size()), R(P.size() + 1), work(5 * P.size());
  double matching_work = 0.0;
  SuiteSparse_long matched = 0;
  const SuiteSparse_long blocks =
      btf_l_order(n, const_cast<SuiteSparse_long*>(reinterpret_cast<const SuiteSparse_long*>(p.col_ptr.data())),
                  const_cast<SuiteSparse_long*>(reinterpret_cast<const SuiteSparse_long*>(p.row_idx.data())),
                  /*maxwork=*/0.0, &matching_work, P.data(), Q.data(), R.data(), &matched, work.data());
  if (matched != n) return false;
  TriangularBlocks& tb = *out;
  tb.rows.resize(P.size()), tb.cols.resize(P.size());
  const std::vector<Index>& solve_rows = model.solve_rows();
  for (std::size_t k = 0; k < P.size(); ++k) {
    const Index r = P[k];
    tb.rows[k] = solve_rows.empty() ? r : solve_rows[static_cast<std::size_t>(r)];
    tb.cols[k] = BTF_UNFLIP(Q[k]);
  }
  tb.start.assign(R.begin(), R.begin() + blocks + 1);
  tb.largest = 0;
  for (SuiteSparse_long b = 0; b < blocks; ++b) tb.largest = std::max<Index>(tb.largest, R[b + 1] - R[b]);
  return true;
}

namespace {

// Where each constraint is evaluated: its block and its index within it (a constraint's rows are evaluated
// through ConstraintBlock's range functions, which take a block's local indices).
struct Place {
  const ConstraintBlock* block = nullptr;
  std::size_t index = 0;
};

std::vector<Place> constraint_places(const Model& model) {
  std::vector<Place> places(model.constraints().size());
  for (const auto& b : model.blocks())
    for (std::size_t i = 0; i < b->size(); ++i) {
      if (b->rows_per_constraint() == 0) continue;
      places[static_cast<std::size_t>(model.constraint_of_row(b->first_row(i)))] = {b.get(), i};
    }
  return places;
}

}  // namespace

SolveStatus assemble_by_blocks(const Model& model, double t, double tolerance, int max_iterations, Eigen::VectorXd& q,
                               BlockAssemblySummary* summary) {
  BlockAssemblySummary local;
  BlockAssemblySummary& sum = summary ? *summary : local;
  sum = BlockAssemblySummary{};
  TriangularBlocks tb;
  if (!triangular_blocks(model, &tb)) {
    sum.status = SolveStatus::kNotSquare;
    sum.message = "Φq's pattern has no block-triangular form (not square, or structurally singular)";
    return sum.status;
  }
  sum.blocks = tb.count(), sum.largest = tb.largest;
  if (tb.count() < 2 || tb.largest > kLargestDenseBlock) {
    sum.status = SolveStatus::kNotSquare;
    sum.message =
        tb.count() < 2 ? "Φq's pattern is one block" : "a block of Φq's pattern is too large to solve densely";
    return sum.status;
  }
  const CscPattern& pattern = model.jacobian_pattern();
  // Φq by rows: each row's entries (coordinate, and position in the value array), to zero a constraint's values
  // before its block accumulates them and to gather a block's dense matrix.
  std::vector<Index> value_of;
  const CscPattern by_rows = transpose_pattern(pattern, &value_of);
  const std::vector<Place> places = constraint_places(model);
  const EntryIndex* slots = model.slot_of_entry().data();
  const ToleranceScales& scales = model.tolerance_scales();
  const Index n = model.num_coordinates();

  Eigen::VectorXd phi = Eigen::VectorXd::Zero(model.num_equations());
  std::vector<double> values(static_cast<std::size_t>(pattern.nnz()), 0.0);
  std::vector<Index> local_col(static_cast<std::size_t>(n), -1);  // a coordinate's column in the current block
  std::vector<Index> owners;                                      // the constraints owning the block's rows
  Eigen::MatrixXd jb;
  Eigen::VectorXd rb, dx;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;

  // Φ and Φq of the block's owners at q; returns whether every row of the block is within the tolerance.
  auto evaluate = [&](Index b0, Index b1) {
    for (Index c : owners) {
      const ConstraintInfo& info = model.constraints()[static_cast<std::size_t>(c)];
      for (Index r = info.first_row; r < info.first_row + info.rows; ++r)
        for (Index e = by_rows.col_ptr[r]; e < by_rows.col_ptr[r + 1]; ++e)
          values[static_cast<std::size_t>(value_of[static_cast<std::size_t>(e)])] = 0.0;
      const Place& pl = places[static_cast<std::size_t>(c)];
      pl.block->residual_and_jacobian(pl.index, pl.index + 1, q.data(), t, phi.data(), slots, values.data(), false);
    }
    const Index m = b1 - b0;
    jb.setZero(m, m);
    rb.resize(m);
    bool within = true;
    for (Index k = 0; k < m; ++k) {
      const Index r = tb.rows[static_cast<std::size_t>(b0 + k)];
      for (Index e = by_rows.col_ptr[r]; e < by_rows.col_ptr[r + 1]; ++e)
        if (const Index l = local_col[static_cast<std::size_t>(by_rows.row_idx[static_cast<std::size_t>(e)])]; l >= 0)
          jb(k, l) = values[static_cast<std::size_t>(value_of[static_cast<std::size_t>(e)])];
      rb[k] = phi[r];
      // the tolerance test of every solve (tol · scale, and above it the row's rounding floor)
      within = within && row_within(model, r, std::fabs(phi[r]) / scales.row_scale[r], tolerance, q, t);
    }
    return within;
  };

  // Last block first: each reads only its own coordinates and those of the blocks already solved.
  for (Index b = tb.count() - 1; b >= 0; --b) {
    const Index b0 = tb.start[static_cast<std::size_t>(b)], b1 = tb.start[static_cast<std::size_t>(b) + 1];
    owners.clear();
    for (Index k = b0; k < b1; ++k) {
      local_col[static_cast<std::size_t>(tb.cols[static_cast<std::size_t>(k)])] = k - b0;
      const Index c = model.constraint_of_row(tb.rows[static_cast<std::size_t>(k)]);
      if (std::find(owners.begin(), owners.end(), c) == owners.end()) owners.push_back(c);
    }
    int it = 0;
    bool within = evaluate(b0, b1);
    while (!within && it < max_iterations) {
      if (!rb.allFinite() || !jb.allFinite()) break;
      cod.compute(jb);
      dx = cod.solve(rb);
      for (Index k = b0; k < b1; ++k) q[tb.cols[static_cast<std::size_t>(k)]] -= dx[k - b0];
      ++it;
      within = evaluate(b0, b1);
    }
    for (Index k = b0; k < b1; ++k) local_col[static_cast<std::size_t>(tb.cols[static_cast<std::size_t>(k)])] = -1;
    sum.iterations += it;
    sum.most_iterations = std::max(sum.most_iterations, it);
    if (!within) {
      const bool finite = rb.allFinite() && jb.allFinite();
      sum.status = finite ? SolveStatus::kNotConverged : SolveStatus::kNonFinite;
      std::ostringstream m;
      m << "block " << tb.count() - b << " of " << tb.count() << " ('"
        << model.constraints()[static_cast<std::size_t>(owners.front())].name << "'"
        << (owners.size() > 1 ? " and " + std::to_string(owners.size() - 1) + " more" : std::string()) << ") "
        << (finite ? "did not converge in " + std::to_string(it) + " iterations" : "is not finite");
      sum.message = m.str();
      return sum.status;
    }
  }
  sum.status = SolveStatus::kSuccess;
  return sum.status;
}

}  // namespace phiq::detail
