/// @file
/// A whole drive sweep: the initial position problem (assembly from the rough placement) at the first time, then
/// successive positions, each started from a prediction of the previous solution, with velocities and
/// accelerations when asked for.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "phiq/kinematics.hpp"

namespace phiq {

/// How successive positions are started.
enum class Predictor {
  kAuto,       ///< the best the computed quantities allow: quadratic with q̇ and q̈, linear with q̇, else secant
  kPrevious,   ///< the previous solution, as in the notes
  kSecant,     ///< linear extrapolation from the two previous solutions (free: needs no velocity)
  kLinear,     ///< q + h q̇            (needs velocities)
  kQuadratic,  ///< q + h q̇ + h²/2 q̈   (needs accelerations)
};
/// "auto", "previous", "secant", "linear" or "quadratic".
const char* to_string(Predictor p);

/// What run_sweep computes and how.
struct SweepOptions {
  double t_begin = 0.0;   ///< first time point (s)
  double t_end = 1.0;     ///< last time point (s); may be below t_begin
  Index steps = 100;      ///< intervals: steps + 1 time points, t_k = t_begin + k (t_end − t_begin) / steps
  bool velocities = true;     ///< solve and deliver q̇ at every time point
  bool accelerations = true;  ///< solve and deliver q̈ (q̇ is then solved too, but delivered only if asked)
  Predictor predictor = Predictor::kAuto;  ///< start of each successive position
  NewtonOptions newton;                                      ///< successive positions
  NewtonOptions assembly{1e-10, 100, true, 30};              ///< initial position from the rough placement
  int max_subdivisions = 8;  ///< a failed step is retried as 2, 4, … sub-steps, down to h / 2^max_subdivisions
};

/// What the step callback sees. qd / qdd are null when not computed.
struct StepView {
  Index step;                  ///< k, from 0
  double t;                    ///< t_k
  const Eigen::VectorXd& q;    ///< positions (valid during the callback only)
  const Eigen::VectorXd* qd;   ///< velocities, or null when not asked for
  const Eigen::VectorXd* qdd;  ///< accelerations, or null when not asked for
};

/// Something the caller should know about a delivered row (the row itself is within tolerance).
struct SweepWarning {
  double t;             ///< time of the row concerned
  std::string kind;     ///< "slow_convergence": Newton converged only linearly (singular position nearby)
  std::string message;  ///< one line
};

/// What run_sweep did (Ceres-style summary).
struct SweepSummary {
  SolveStatus status = SolveStatus::kSuccess;  ///< the outcome; kSuccess when every time point was delivered
  std::string message;       ///< one line naming the step, time, cause and constraints; empty on success
  Index steps_completed = 0; ///< rows delivered to the callback
  Index failed_step = -1;    ///< k of the step that failed, or -1
  double failed_time = 0.0;  ///< t_k of the step that failed
  PositionSummary assembly;  ///< the initial position problem
  WorkCounters counters;     ///< work done by this sweep
  Index subdivisions = 0;    ///< sub-steps inserted after Newton failures
  double min_rcond = 0.0;    ///< smallest reciprocal condition estimate seen (0 if none)
  double min_rcond_time = 0.0;         ///< where min_rcond was seen
  std::vector<SweepWarning> warnings;  ///< in time order
  double solve_seconds = 0.0;          ///< wall time of the sweep, the callback's own work included
  /// One line: status, steps, iterations, factorisations, solves, subdivisions, warnings, time, message.
  std::string BriefReport() const;
};

/// Runs the sweep from ws.q (the rough placement; the model's initial positions for a fresh workspace), calling
/// on_step once per time point, in order; on_step returns false to stop (status kCancelled). On failure nothing
/// more is delivered and the summary says where and why. Pre-condition: ws made for model.
SolveStatus run_sweep(const Model& model, const SweepOptions& options, Workspace& ws,
                      const std::function<bool(const StepView&)>& on_step, SweepSummary* summary);

}  // namespace phiq
