/// @file
/// The initial position problem for any model: square, redundant (more equations than the rank) or under-driven
/// (fewer equations than coordinates). Moves a rough placement q₀ as little as possible onto Φ(q, t) = 0 —
/// minimum-norm Gauss-Newton steps, Δq = −D Ãᵀ (Ã Ãᵀ + μ I)⁻¹ Φ̃, on a maximal independent set of the equations
/// (rank_analysis.hpp), with the factorisation of Ã Ãᵀ by CHOLMOD (analysed once per set of rows) — then checks the
/// redundant equations it left out: satisfied (consistent redundancy) or not (inconsistent: the constraints that
/// conflict are named).
///
/// Ã is the scaled Jacobian of the kept rows (rank_analysis.hpp), D the coordinate scales (ToleranceScales): the
/// step is the smallest in the norm that weighs each coordinate's tolerance scale like a radian. μ = 0
/// (Gauss-Newton) while its steps decrease ‖Φ̃‖; μ > 0 (Levenberg-Marquardt) only when they do not or the kept rows
/// lose rank on the way. Once the equations hold, projection steps move to the assembled position nearest to q₀
/// (assembly.cpp); if the iteration budget runs out before they settle (near a singular position they may leave
/// the tolerance and come back repeatedly), the last iterate at which the equations held is the result.
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

/// The assembly settings of a Newton solve's settings (tolerance and iteration budget; the rest as defaults): the
/// minimum-norm assembly of a scene uses its `solver` section as the square assembly does (SweepOptions::assembly).
AssemblyOptions assembly_options(const NewtonOptions& newton);

/// What assemble() did.
struct AssemblySummary {
  SolveStatus status = SolveStatus::kNotConverged;  ///< kSuccess, kInconsistent, kNotConverged, kNonFinite, ...
  int iterations = 0;                               ///< Gauss-Newton steps
  int factorizations = 0;                           ///< of Ã Ãᵀ (one per step)
  int rank_updates = 0;   ///< times the independent set was chosen again at a new configuration
  double residual = 0.0;  ///< max_i |Φ_i| / scale_i over all rows at the end
  /// How far the placement moved: max_j |q_j − q₀_j| / coordinate scale_j.
  double moved = 0.0;
  RankReport rank;  ///< at the final configuration
  /// False when redundant equations are not satisfied where the independent ones are (the model is inconsistent:
  /// status kInconsistent), or when the independent equations themselves could not be satisfied (kNotConverged:
  /// nothing is known of the redundant ones).
  bool consistent = true;
  std::vector<Index> violated_rows;    ///< the redundant rows not satisfied (inconsistent models)
  std::vector<std::string> conflicts;  ///< constraints that cannot hold together: each violated redundant row and the
                                       ///< rows it is a combination of (empty when consistent)
  /// (row, |Φ_i| / scale_i), largest first, at most 3; empty on success and for kOutsideTimeDomain (t outside the
  /// drivers' domain, or not finite: Φ means nothing there)
  std::vector<std::pair<Index, double>> worst_rows;
  std::string message;  ///< one line; empty on a clean success
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

/// The model a scene's sweep solves and where it starts, as `phiq run` prepares it.
struct SquareScene {
  std::unique_ptr<Model> reduced;  ///< the model without its redundant rows, when the scene's model is not square
  Eigen::VectorXd start;           ///< the rough placement, or the assembled position when `reduced` was made
  AssemblySummary assembly;        ///< the minimum-norm assembly, when it ran
  /// The model to sweep: `reduced`, else the scene's own `model`.
  const Model& model(const Model& scene_model) const { return reduced ? *reduced : scene_model; }
};

/// Prepares a scene's model for the square sweep: a square model is swept as it is, from its rough placement (the
/// sweep assembles it); any other is assembled by minimum norm with the scene's assembly settings
/// (`assembly`, SweepOptions::assembly) and reduced to its independent rows (prepare_square()). Returns kSuccess or
/// prepare_square()'s failure (the summary's message names the constraints or the count).
SolveStatus prepare_scene(const Model& model, double t_begin, const NewtonOptions& assembly, SquareScene* out);

}  // namespace phiq
