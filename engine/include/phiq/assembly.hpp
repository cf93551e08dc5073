/// @file
/// The initial position problem for any model: square, redundant (more equations than the rank) or under-driven
/// (fewer equations than coordinates). Moves a rough placement q₀ as little as possible onto Φ(q, t) = 0 —
/// minimum-norm Gauss-Newton steps, Δq = −D Ãᵀ (Ã Ãᵀ + μ I)⁻¹ Φ̃, on a maximal independent set of the equations
/// (rank_analysis.hpp), with the factorisation of Ã Ãᵀ by CHOLMOD (analysed once per set of rows) — then checks the
/// redundant equations it left out: satisfied (consistent redundancy) or not (inconsistent: the constraints that
/// conflict are named).
///
/// Ã is the scaled Jacobian of the kept rows (rank_analysis.hpp), D the coordinate scales: the step is the smallest in
/// the norm that weighs a metre of the model's length scale like a radian. μ = ‖Φ̃‖ (Levenberg-Marquardt with the
/// regularisation of Fan & Yuan, 2005) keeps the steps bounded far from the solution and vanishes at it, where the
/// convergence is quadratic even if the kept rows lose rank on the way.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/kinematics.hpp"
#include "phiq/rank_analysis.hpp"

namespace phiq {

/// Settings of assemble().
struct AssemblyOptions {
  double tolerance = 1e-10;  ///< as NewtonOptions::tolerance, on every row (kept and redundant)
  int max_iterations = 100;  ///< Gauss-Newton steps in all
  int max_backtracks = 30;   ///< halvings of a step by the line search on ½‖Φ̃_kept‖²
  /// The independent set is chosen at the rough placement and checked at the solution (rank depends on the
  /// configuration); when it changed, the solve continues with the new set, at most this many times.
  int max_rank_updates = 4;
  RankOptions rank;  ///< rank tolerance and cross-checks
};

/// What assemble() did.
struct AssemblySummary {
  SolveStatus status = SolveStatus::kNotConverged;  ///< kSuccess, kInconsistent, kNotConverged, kNonFinite, ...
  int iterations = 0;      ///< Gauss-Newton steps
  int factorizations = 0;  ///< of Ã Ãᵀ (one per step)
  int rank_updates = 0;    ///< times the independent set was chosen again at a new configuration
  double residual = 0.0;   ///< max_i |Φ_i| / scale_i over all rows at the end
  /// How far the placement moved: max_j |q_j − q₀_j| / coordinate scale_j.
  double moved = 0.0;
  RankReport rank;         ///< at the final configuration
  /// False when redundant equations are not satisfied where the independent ones are: the model is inconsistent.
  bool consistent = true;
  std::vector<Index> violated_rows;    ///< the redundant rows not satisfied (inconsistent models)
  std::vector<std::string> conflicts;  ///< constraints that cannot hold together: each violated redundant row and the rows it is a combination of (empty when consistent)
  std::vector<std::pair<Index, double>> worst_rows;  ///< (row, |Φ_i| / scale_i), largest first, at most 3
  std::string message;     ///< one line; empty on a clean success
  /// One line: status, iterations, residual, rank, redundant and conflicting constraints.
  std::string BriefReport() const;
};

/// Assembles from `q` (the rough placement; on return the assembled position, or the last iterate) at time t.
/// Statuses: kSuccess (every row within tolerance; the summary's rank report names the redundant equations),
/// kInconsistent (the independent equations hold but some redundant ones cannot: summary.conflicts names the
/// constraints), kNotConverged (no assembly near this placement; the worst constraints are named), kNonFinite,
/// kOutsideTimeDomain. Throws phiq::Error for violated pre-conditions (q of the wrong size, bad options).
/// Thread-safe for distinct q.
SolveStatus assemble(const Model& model, double t, const AssemblyOptions& options, Eigen::VectorXd& q,
                     AssemblySummary* summary = nullptr);

/// Prepares any model for the square drive sweep (run_sweep): assembles from `q` at time t (assemble()), then
/// returns in `*solved` the model the square solves use — a copy of `model` that leaves the redundant rows found at
/// the assembled position out (Model::without_rows(); with none it is the full model) — with `q` assembled. Fails
/// with assemble()'s statuses, or kNotSquare when the drivers leave freedoms undriven (summary.rank.driven_dof > 0:
/// the message names the count). A workspace for the sweep is made for `**solved` and started from q.
SolveStatus prepare_square(const Model& model, double t, const AssemblyOptions& options, Eigen::VectorXd& q,
                           std::unique_ptr<Model>* solved, AssemblySummary* summary = nullptr);

}  // namespace phiq
