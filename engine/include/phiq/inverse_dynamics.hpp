/// @file
/// Inverse dynamics of a driven mechanism (kinetostatics): with its motion known from the drivers (q, q̇, q̈ at a
/// row), the constraints' multipliers λ follow from one transposed solve with Φq,
///
///     Φqᵀ λ = Q(q, q̇, q̈, t),   Q_k = Σ_b [ ∂r_b/∂q_k · (m_b (g − a_b)) + ∂θ_b/∂q_k · (−I_b α_b − ω_b × I_b ω_b) ],
///
/// b over the parts with mass (phiq/parts.hpp), r_b a part's centre of mass and a_b its acceleration, ω_b, α_b its
/// angular velocity and acceleration, I_b its inertia about the centre in world axes, ∂/∂q_k from part_jacobian():
/// the virtual work of gravity and of the inertia forces, in any coordinate family, plus the applied loads'
/// (phiq/applied_loads.hpp). A driver's effort (the torque
/// or force its motor applies, conjugate to what it drives) is −λ of its row, and its power −λ (Φq q̇) = λ Φt.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

#include "phiq/kinematics.hpp"
#include "phiq/parts.hpp"
#include "phiq/workspace.hpp"

namespace phiq {

struct NaturalJoints;  // natural_joints.hpp

/// Adds to `Q` (one entry per coordinate) the generalized forces of `loads` and of the parts' inertia at (q, q̇, q̈,
/// t) (file comment). Parts without mass contribute nothing. Pre-condition: Q has a size the parts' coordinates fit.
void add_generalized_forces(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd,
                            const double* qdd, double t, Eigen::VectorXd& Q);

/// Why add_generalized_forces() gave a Q that is not finite at (q, q̇, q̈, t), as one phrase for a message: the first
/// part with mass, then the first applied load, whose own generalized force is not finite, named, with what of it is
/// not (a frame of points without a direction, a load's value, an overflow of doubles). Empty when each is finite
/// alone. Pre-conditions as add_generalized_forces(), Q's size `num_coordinates`. Evaluates every contribution
/// once more, alone: for the failure path, not for every row.
std::string nonfinite_force_source(const std::vector<Part>& parts, const Loads& loads, Index num_coordinates,
                                   const double* q, const double* qd, const double* qdd, double t);

/// The constraints' multipliers at the motion in `ws` (q, q̇, q̈ solved at t): λ (one per equation) with Φqᵀ λ = Q,
/// by the transposed solve of the model's LU of Φq at (q, t), factorised there if it is not already. A model with
/// dropped (redundant) rows gives λ = 0 on them: one of the many λ then, not the minimum-norm one. Returns what the
/// factorisation returns (kNotSquare for a model without a square solve); `message` says why on failure.
SolveStatus constraint_multipliers(const Model& model, double t, Workspace& ws, const Eigen::VectorXd& Q,
                                   Eigen::VectorXd& lambda, std::string* message = nullptr);

/// λ with Φqᵀ λ = Q by a transposed solve with `lu`, factors of Φq's kept rows (Model::solve_rows(); all rows when
/// none are dropped) at the motion's q: λ on the kept rows, 0 on the dropped ones; `kept` is scratch, used only
/// with dropped rows. What constraint_multipliers() and a sweep's efforts (OutputPlan::efforts) solve with. False
/// when the solve fails.
bool multipliers_with_factors(const Model& model, SparseLuNumeric& lu, const Eigen::VectorXd& Q, Eigen::VectorXd& kept,
                              Eigen::VectorXd& lambda);

/// The constraints that depend on time (the drivers, and equations in t), in model order: whose efforts
/// driver_efforts() gives.
std::vector<Index> rheonomic_constraints(const Model& model);

/// Whether constraint `c` has an effort a sweep may write (OutputEfforts::constraints): a driver's (it depends on
/// time), or a transmission's (is_transmission_kind(), phiq/kinds/registry.hpp: what it applies to its first member).
bool has_effort(const ConstraintInfo& c);

/// The effort of each of rheonomic_constraints() at the motion in `ws` (q, q̇, q̈ at t) under `loads`: −λ of its
/// first row, the torque or force its motor applies, conjugate to what it drives (a coordinate, a joint's angle or
/// distance, an expression). As constraint_multipliers() for the status and `message`; kNonFinite, with the part or
/// load nonfinite_force_source() names, where Q or λ is not finite. With bearings' friction (BearingFriction) λ is
/// solved with it; kNotConverged, its message naming the bearing, where it does not settle (the mechanism jams).
/// `natural`: as DriverEfforts' (a bearing at a natural point names one of its joints). One motion: its losses' set-up
/// is found at each call, which DriverEfforts does once for many.
SolveStatus driver_efforts(const Model& model, const std::vector<Part>& parts, const Loads& loads, double t,
                           Workspace& ws, std::vector<double>& efforts, std::string* message = nullptr,
                           std::shared_ptr<const NaturalJoints> natural = nullptr);

/// driver_efforts() at many motions of one model, its parts and loads (a loop over a sweep's rows: Python's
/// phiq.driver_efforts): what the losses that read the multipliers need (their joints, their reactions' sites) is
/// found once, at construction, rather than at every call. `natural`, when not null, holds the natural joints a
/// bearing may name (a scene's OutputEfforts::natural, phiq/natural_joints.hpp). The model, parts and loads must
/// outlive it; one per thread.
class DriverEfforts {
 public:
  /// Throws phiq::Error where driver_efforts() would for a loss (its joint unknown, or not one to carry it).
  DriverEfforts(const Model& model, const std::vector<Part>& parts, const Loads& loads,
                std::shared_ptr<const NaturalJoints> natural = nullptr);
  ~DriverEfforts();
  DriverEfforts(const DriverEfforts&) = delete;
  DriverEfforts& operator=(const DriverEfforts&) = delete;
  /// As driver_efforts() at the motion in `ws` (q, q̇, q̈ at t).
  SolveStatus operator()(double t, Workspace& ws, std::vector<double>& efforts, std::string* message = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace phiq
