// A whole drive sweep: the initial position problem (assembly from the rough placement) at the first time, then
// successive positions, each started from a prediction of the previous solution, with velocities and
// accelerations when asked for.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "phiq/kinematics.hpp"

namespace phiq {

// How successive positions are started.
enum class Predictor {
  kAuto,       // the best the computed quantities allow: quadratic with q̇ and q̈, linear with q̇, else secant
  kPrevious,   // the previous solution, as in the notes
  kSecant,     // linear extrapolation from the two previous solutions (free: needs no velocity)
  kLinear,     // q + h q̇            (needs velocities)
  kQuadratic,  // q + h q̇ + h²/2 q̈   (needs accelerations)
};
const char* to_string(Predictor p);

struct SweepOptions {
  double t_begin = 0.0, t_end = 1.0;
  Index steps = 100;  // intervals: steps + 1 time points, t_k = t_begin + k (t_end − t_begin) / steps
  bool velocities = true;
  bool accelerations = true;
  Predictor predictor = Predictor::kAuto;
  NewtonOptions newton;                                      // successive positions
  NewtonOptions assembly{1e-10, 100, true, 30};              // initial position from the rough placement
  int max_subdivisions = 8;  // a failed step is retried as 2, 4, … sub-steps, down to h / 2^max_subdivisions
};

// What the step callback sees. qd / qdd are null when not computed.
struct StepView {
  Index step;
  double t;
  const Eigen::VectorXd& q;
  const Eigen::VectorXd* qd;
  const Eigen::VectorXd* qdd;
};

// Something the caller should know about a delivered row (the row itself is within tolerance).
struct SweepWarning {
  double t;
  std::string kind;  // "slow_convergence": Newton converged only linearly (singular position nearby)
  std::string message;
};

struct SweepSummary {
  SolveStatus status = SolveStatus::kSuccess;
  std::string message;       // one line naming the step, time, cause and constraints; empty on success
  Index steps_completed = 0; // rows delivered to the callback
  Index failed_step = -1;
  double failed_time = 0.0;
  PositionSummary assembly;  // the initial position problem
  WorkCounters counters;
  Index subdivisions = 0;    // sub-steps inserted after Newton failures
  double min_rcond = 0.0;    // smallest reciprocal condition estimate seen (0 if none)
  double min_rcond_time = 0.0;
  std::vector<SweepWarning> warnings;
  double solve_seconds = 0.0;
  std::string BriefReport() const;
};

// Runs the sweep from ws.q (the rough placement; the model's initial positions for a fresh workspace), calling
// on_step once per time point, in order; on_step returns false to stop (status kCancelled). On failure nothing
// more is delivered and the summary says where and why. Pre-condition: ws made for model.
SolveStatus run_sweep(const Model& model, const SweepOptions& options, Workspace& ws,
                      const std::function<bool(const StepView&)>& on_step, SweepSummary* summary);

}  // namespace phiq
