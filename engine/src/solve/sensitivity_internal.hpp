// Internal: the sensitivities of one converged row with factors of Φq already at its position (sensitivity.hpp):
// what solve_sensitivities() does after it has factorised, and what the sweep does at each written row with the
// factors its velocity solve made there.
#pragma once

#include <array>
#include <vector>

#include "phiq/output_plan.hpp"
#include "phiq/sensitivity.hpp"

namespace phiq::detail {

// The form a sweep with `plan` solves its sensitivities in, for `outputs` written coordinates
// (OutputPlan::sensitivity_outputs()): effective_sensitivity_form() at the plan's derivative order. run_sweep reports
// it, each Sweeper solves in it (the direct form when no coordinate is written: on_step reads them all).
// With efforts, whose sensitivities read every coordinate's (phiq/effort_sensitivity.hpp), the direct form.
inline SensitivityForm sweep_sensitivity_form(const OutputPlan& plan, std::size_t outputs) {
  if (!plan.efforts.constraints.empty()) return SensitivityForm::kDirect;
  return effective_sensitivity_form(plan.sensitivity_form, plan.sensitivities.size(), outputs,
                                    plan.accelerations ? 2
                                    : plan.velocities  ? 1
                                                       : 0);
}

// The vectors one row's sensitivities are computed in, kept between rows (no allocation per row).
struct SensitivityScratch {
  std::array<Eigen::VectorXd, 4> f;  // the function at the four shifted points (one entry per row of Φ)
  Eigen::VectorXd d;                 // its difference quotient: the right-hand side, negated
  Eigen::VectorXd along;             // Φt or γ on the way (evaluate_over_reach)
  Eigen::VectorXd qk, vk;            // the shifted q and q̇ (the adjoint form: q along the motion)
  // The adjoint form: per parameter, a_j, b_j, c_j at fixed (q, q̇) (sensitivity.hpp); Φq at the points along the
  // motion (q + kεq̇, t + kε: k = −2, −1, 1, 2 for the first difference, −3 … 3 at a larger ε for the second) and
  // along q̈ (q + kεq̈); the adjoint vectors (over Φ's rows: zero at rows the square solves leave out) and the
  // solves' right-hand sides and results.
  std::vector<Eigen::VectorXd> a, b, c;
  std::vector<const ParameterReach*> reaches;  // each parameter's (the adjoint form's dot products)
  std::array<std::vector<double>, 4> first_along_motion;
  std::array<std::vector<double>, 7> along_motion;
  std::array<std::vector<double>, 4> along_acceleration;
  Eigen::VectorXd lambda, mu, tau, nu, rhs, solved;
  // q with the co-moving coordinates moved along p (ParameterReach::comotion); s − q̂ (the direct form)
  Eigen::VectorXd moved, sprime;
};

// The functions differentiated along a parameter, at fixed (q, q̇, q̈) (sensitivity.hpp: a, b and c).
enum class AlongParameter {
  kResidual,         // Φ(q, t)
  kVelocityTerm,     // Φq(q, t) q̇ + Φt(q, t)
  kAccelerationTerm  // Φq(q, t) q̈ − γ(q, q̇, t)
};

// `which` of model `m` (one along the parameter, or the swept model) over the constraints of `reach` only, or, with
// `reached` set, of model k's copies of them (ReachedConstraints; `m` unread): their rows of `f` are written, every
// other row is left as it is. `scratch` (one entry per row of Φ, like `f`) holds Φt or γ on the way. `qd` is read
// by kVelocityTerm and kAccelerationTerm, `qdd` by kAccelerationTerm (else null). With `skip_rated`, the spans whose
// data's rates `reached` holds are not evaluated (their kind gives their derivatives: the rows may hold anything).
void evaluate_over_reach(const ParameterReach& reach, const Model* m, const ReachedConstraints* reached, std::size_t k,
                         AlongParameter which, const double* q, const double* qd, const double* qdd, double t,
                         double* f, double* scratch, bool skip_rated = false);

// The derivative along the parameter `p` of `which` over the rows of `reach`, into `d` (its other rows untouched),
// at fixed (q, q̇, q̈), or along (q, p) ← (q̂, 1) where p moves co-moving coordinates (sensitivity.cpp). Reads
// scratch.f (4 vectors of m), scratch.along (m) and scratch.moved.
void along_parameter(const Model& model, const OutputSensitivity& p, const ParameterReach& reach, AlongParameter which,
                     const double* q, const double* qd, const double* qdd, double t, Index n,
                     SensitivityScratch& scratch, Eigen::VectorXd& d);

// The largest |v_j| / scale_j over the n coordinates: how fast v moves its fastest coordinate, in their scales.
double fastest_coordinate(const double* v, const double* scale, Index n);

// The efforts' and powers' sensitivities of one row (phiq/effort_sensitivity.hpp) into `out`
// (EffortSensitivityLayout): `lambda` the row's multipliers (Φqᵀ λ = Q, zero on dropped rows:
// multipliers_with_factors()), `sensitivities` the row's in the direct form (SensitivityLayout, order 2), `lu` the
// factors of Φq at q. NaN for an effort whose first row the model dropped, for a power with any row dropped.
// Pre-condition: every parameter's reach is set (run_sweep(), the Stepper and solve_effort_sensitivities() find it
// once); else phiq::Error. Returns false when a solve fails.
class FrictionLosses;  // solve/friction_losses.hpp

struct EffortSensitivityScratch {
  SensitivityScratch along;        // along_parameter()'s
  std::vector<Eigen::VectorXd> w;  // Φq⁻¹ e_r per row of a driver (rows)
  struct DriverRow {
    std::size_t effort = 0;  // in OutputEfforts::constraints
    Index row = 0;           // the model's row
    std::size_t w = 0;       // its Φq⁻¹ e_r in w
  };
  std::vector<DriverRow> rows;                 // every row of each driver none of whose rows the model dropped
  std::vector<bool> all_kept;                  // per driver: none of its rows dropped (its power defined)
  std::vector<double> power;                   // per driver: dP/dp on the way
  Eigen::VectorXd phit, dphit;                 // Φt and dΦt/dp over the rows (the powers')
  Eigen::VectorXd rhs, v, dq, qk, vk, ak, qf;  // over the coordinates
  Eigen::VectorXd plus, minus, g[4];           // over the rows
  Eigen::VectorXd forces[4];                   // Q at the four points of a difference
  // dQ/dp exactly (parts/force_rate.hpp) unless set, or where that form does not reach: then Q differenced along
  // p and the motion, and `differenced` counts it (the tests compare the two)
  bool difference_forces = false;
  std::size_t differenced = 0;
  // The row's losses that read the multipliers, solved with them (FrictionLosses::solve()), or null: then each w is
  // the adjoint's w̃ and dQ_f/dp at fixed λ (`friction_rate`) joins dQ/dp (FrictionLosses::adjoint(), force_rate())
  FrictionLosses* losses = nullptr;
  Eigen::VectorXd friction_rate;
  std::array<Eigen::VectorXd, 4> moved;  // q with the co-moving coordinates moved along p
};
bool effort_sensitivities_with_factors(const Model& model, const OutputEfforts& efforts,
                                       const std::vector<OutputSensitivity>& parameters, double t, const double* q,
                                       const double* qd, const double* qdd, const Eigen::VectorXd& lambda,
                                       const double* sensitivities, SparseLuNumeric& lu, EffortSensitivityScratch& sc,
                                       double* out);

// Writes the sensitivities of (q, q̇, q̈) at t to every parameter into `out` (SensitivityLayout; derivatives above
// `order` are NaN), solving with `lu`, the factors of the swept model's Φq at q. `ws` lends the right-hand side
// of the kept rows (models with dropped rows) and counts the solves. Returns false when a solve fails (then the
// values are NaN).
bool sensitivities_with_factors(const Model& model, const std::vector<OutputSensitivity>& parameters, double t,
                                const double* q, const double* qd, const double* qdd, int order, SparseLuNumeric& lu,
                                Workspace& ws, SensitivityScratch& scratch, double* out);

// The same in the adjoint form (SensitivityForm::kAdjoint), for the coordinates `outputs` only; every other entry
// of `out` is NaN.
bool adjoint_sensitivities_with_factors(const Model& model, const std::vector<OutputSensitivity>& parameters,
                                        const std::vector<Index>& outputs, double t, const double* q, const double* qd,
                                        const double* qdd, int order, SparseLuNumeric& lu, Workspace& ws,
                                        SensitivityScratch& scratch, double* out);

}  // namespace phiq::detail
