/// @file
/// Per-thread data for the algorithms of kinematics.hpp: the state (q, q̇, q̈), the Jacobian values, the numeric LU
/// factorisation and scratch vectors. A Workspace belongs to one thread at a time; the Model it was made for is
/// shared: the workspace follows it when it moves, and refuses to work (phiq::Error) once it is destroyed.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <vector>

#include "phiq/model.hpp"

namespace phiq {

/// Work done, counted where it happens (for summaries and for tests that the engine computes only what is asked).
struct WorkCounters {
  Index newton_iterations = 0;     ///< Newton steps (each one factorisation)
  Index residual_evaluations = 0;  ///< evaluations of Φ (including line-search trials)
  Index jacobian_evaluations = 0;  ///< evaluations of Φq values
  Index factorizations = 0;        ///< numeric LU factorisations
  /// Those of them that searched for pivots (KLU: not a refactorisation with the pivot order of an earlier one)
  Index pivoting_factorizations = 0;
  Index velocity_solves = 0;      ///< solves of Φq q̇ = −Φt
  Index acceleration_solves = 0;  ///< solves of Φq q̈ = γ
  Index phi_t_evaluations = 0;    ///< evaluations of Φt (velocity right-hand sides)
  Index gamma_evaluations = 0;    ///< evaluations of γ (acceleration right-hand sides)
  Index point_evaluations = 0;    ///< output point motions evaluated (one per point and delivered row)
  /// Solves for sensitivities to design parameters (sensitivity.hpp): one per parameter, derivative order and
  /// delivered row, each with the row's factorisation
  Index sensitivity_solves = 0;
  /// Rows of an adjoint-form sweep solved in the direct form instead, because Φq is not smooth along the motion
  /// within the adjoint's difference (a spline's knot: SensitivityForm)
  Index sensitivity_direct_rows = 0;
  /// Transposed solves for driver efforts (OutputPlan::efforts): one per written row, with the row's factorisation
  Index effort_solves = 0;
};

/// Per-thread data of the algorithms in kinematics.hpp and sweep.hpp. Not thread-safe: one thread at a time.
/// What it keeps between calls (the LU's pivot order, newton_contraction, a factorisation still valid at its point)
/// changes the next call's work and the last bits of its results, within the tolerance; start_afresh() forgets it
/// (run_sweep does, so a sweep's results depend on its model, options and starting q only).
class Workspace {
 public:
  /// Sized for `model`, with q at its initial positions and its own numeric LU object (sharing the model's
  /// symbolic analysis). The workspace follows the model where it moves (Model's move constructor and assignment),
  /// so that a std::vector<Model> may grow while workspaces of its models exist. Throws phiq::Error for a model
  /// that was moved from.
  explicit Workspace(const Model& model);
  /// The model it was made for, where it is now. Throws phiq::Error "the Model this Workspace was made for no
  /// longer exists" once that model is destroyed (or assigned another), as every solve with the workspace does.
  const Model& model() const { return detail::model_of(anchor_.get(), "Workspace"); }
  /// Forgets what the last calls left for the next (the factorisation, its pivot order, Φq values not yet
  /// factorised, newton_contraction): the next call computes, to the bit, what it would in a fresh workspace
  /// with the same q (q̇, q̈ and the counters are kept; the memory of the factors too).
  void start_afresh();

  /// Generalized coordinates. Starts at the model's initial positions; algorithms read and write it, and so may
  /// the caller (e.g. to give a better starting guess). Keep its size.
  Eigen::VectorXd q;
  Eigen::VectorXd qd;     ///< velocities q̇ (written by solve_velocity; starts at zero)
  Eigen::VectorXd qdd;    ///< accelerations q̈ (written by solve_acceleration; starts at zero)
  WorkCounters counters;  ///< work done with this workspace so far (never reset by the algorithms)

  /// @name Scratch of the algorithms (src/solve/); callers need not touch it
  /// Its values may be read; a vector resized by the caller makes every solve refuse the workspace (phiq::Error).
  ///@{
  Eigen::VectorXd phi;        ///< Φ at q
  Eigen::VectorXd rhs;        ///< right-hand side of the last velocity or acceleration solve
  Eigen::VectorXd step;       ///< Φq⁻¹Φ of the last Newton iteration (its step was −α times this)
  Eigen::VectorXd trial;      ///< line-search trial point
  Eigen::VectorXd trial_phi;  ///< Φ at the trial point
  /// Φq values in jacobian_pattern() order. The Newton loop evaluates Φq together with Φ at its trial points
  /// where it will factorise (NewtonOptions::jacobian_with_residual); a solve that ends with such values at its
  /// solution, not yet factorised, records their point (jacobian_q, jacobian_t) and sets has_jacobian, for the
  /// velocity solve that follows.
  std::vector<double> jacobian_values;
  Eigen::VectorXd jacobian_q;  ///< see jacobian_values
  double jacobian_t = 0.0;     ///< see jacobian_q
  bool has_jacobian = false;   ///< jacobian_values hold Φq at (jacobian_q, jacobian_t), not yet factorised
  /// Models with dropped rows (Model::without_rows()): the values of the kept rows in solve_pattern() order, and
  /// the right-hand side of the kept rows; empty otherwise.
  std::vector<double> solve_values;
  Eigen::VectorXd solve_rhs;            ///< see solve_values
  std::unique_ptr<SparseLuNumeric> lu;  ///< numeric factors; null for non-square models
  /// The point (q, t) of the current factorisation, so that velocity and acceleration reuse it exactly when it is
  /// still valid and refactorise otherwise.
  Eigen::VectorXd factorized_q;
  double factorized_t = 0.0;       ///< see factorized_q
  bool has_factorization = false;  ///< lu holds valid factors at (factorized_q, factorized_t)
  /// The factors are of Φq at the solution the last solve_position converged to (set by that solve when its last
  /// factorisation is within the tolerance of the solution — or, at a stop at the rounding level, was made where
  /// the last step, a rounding-level one, started: q is known no better than that step — and by the sweep's
  /// derivative solves after they factorise there); cleared by every solve_position at its start.
  bool factorized_at_solution = false;
  /// The factors' point (factorized_q, factorized_t) passed the position test of solve_velocity() at this
  /// tolerance (DerivativeOptions::tolerance; NaN when not tested), so that solve_acceleration() there does not
  /// evaluate Φ again. Cleared with each new factorisation and by every solve_position at its start.
  double factorized_solves_to = std::numeric_limits<double>::quiet_NaN();
  /// Buffers of num_coordinates() entries for the rows a parallel sweep holds until it delivers them in order (its
  /// chunks' q, q̇, q̈), kept for the next parallel sweep with this workspace: writing rows into memory the process
  /// already has, rather than into pages the system must map in and clear, made a repeated 2-thread sweep of
  /// nfourbar N = 10³ 7 % faster (bench/README.md). At most kSpareRowBytes are kept after a sweep; clearing the
  /// vector (with shrink_to_fit) gives the memory back.
  std::vector<Eigen::VectorXd> spare_rows;
  static constexpr double kSpareRowBytes = 64.0 * 1024 * 1024;  ///< see spare_rows
  /// Contraction of modified Newton last observed with a reused factorisation (kept by the solves that observe
  /// none, −1 before any and after a failed solve): the error estimate of the next solve's first step.
  double newton_contraction = -1.0;
  ///@}

 private:
  std::shared_ptr<const detail::ModelAnchor> anchor_;  // where the model is now (null once this was moved from)
};

}  // namespace phiq
