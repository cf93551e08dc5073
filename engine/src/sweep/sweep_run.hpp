// The bookkeeping of one run of a sweep that the sequential path (run_sweep.cpp) and the parallel one
// (parallel_sweep.cpp) share: the time grid, the delivery of rows in order (with the bifurcation check between
// them), a failed step's message, the drive steps in order, and the sum of work counters. Defined in the header,
// so that both paths may inline deliver() and sequential(), which run on every row.
#pragma once

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "phiq/sweep.hpp"
#include "phiq/text.hpp"
#include "sweep/limit_watch.hpp"
#include "sweep/sweeper.hpp"

namespace phiq::detail {

// The per-run bookkeeping shared by the sequential and parallel paths.
struct Run {
  // A constructor, not aggregate initialisation: the members below start as their initialisers say.
  Run(const SweepOptions& o, const std::function<bool(const StepView&)>& f, SweepSummary& s, RowWriter* w = nullptr)
      : opt(o), on_step(f), writer(w), sum(s) {}
  const SweepOptions& opt;
  const std::function<bool(const StepView&)>& on_step;
  RowWriter* writer;  // in place of on_step: rows encoded, then written in order (RowWriter)
  SweepSummary& sum;
  LimitWatch* limits = nullptr;  // the plan's limits, checked in delivery order (null or empty: none)

  // Whether the delivery itself reads every row's q, q̇ and outputs, written or not: limits are checked there (a
  // limit's stretch runs on from the row before, which only the delivery in order knows).
  bool delivery_reads_rows() const { return !opt.limits.empty(); }
  // Whether a parallel chunk encodes its rows itself, for write_encoded(): with a writer, unless joint angles are
  // written (each row's is unwrapped from the row before) or the delivery reads the rows.
  bool chunks_encode() const {
    return writer && !delivery_reads_rows() &&
           std::none_of(opt.joints.begin(), opt.joints.end(),
                        [](const OutputJoint& j) { return j.measure == JointMeasure::kAngle; });
  }

  double time_of(Index k) const { return opt.time_of(k); }  // TimeGrid::time_of
  // Sign of det Φq at the last delivered regular row whose sign is known, its time, and whether a singular row
  // (bracketed, with its own warning) was delivered since.
  Orientation last_sign{0, 0};
  double last_sign_t = 0.0;
  bool singular_since = false;

  // Delivers row k; false when the caller stops the sweep (status and message set). A change of det Φq's sign
  // since the last regular row is a singular position passed between the two: warned here, in row order, so that
  // sequential and parallel sweeps report it alike.
  bool deliver(Index k, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
               const RowMotions& motions, const Eigen::VectorXd& phi, double rcond, Orientation det_sign,
               double det_sign_t, const RowQuality& quality) {
    count_row(time_of(k), det_sign, det_sign_t, quality);
    unwrap_joints(k, motions.joints);
    const bool written_row = opt.writes_row(k, time_of(k));
    if (limits && delivery_reads_rows())
      limits->row(time_of(k), q.data(), opt.solves_velocities() ? qd.data() : nullptr,
                  written_row ? motions.efforts : nullptr);
    if (!written_row) return true;  // solved, not written (OutputPlan::every, window)
    const StepView view = view_of(k, q, qd, qdd, motions, phi, rcond, joints.empty() ? nullptr : joints.data());
    return written(writer ? writer->write_row(view) : !on_step || on_step(view), k);
  }
  // What the caller sees of row k (the joints' measures unwrapped already).
  StepView view_of(Index k, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
                   const RowMotions& motions, const Eigen::VectorXd& phi, double rcond,
                   const JointMotion* joint_measures) const {
    return {k,
            time_of(k),
            q,
            opt.velocities ? &qd : nullptr,
            opt.accelerations ? &qdd : nullptr,
            motions.points,
            opt.residuals ? &phi : nullptr,
            opt.condition ? rcond : 0.0,
            joint_measures,
            motions.orientations,
            motions.sensitivities,
            motions.efforts};
  }
  // Rows a parallel chunk encoded (chunks_encode()), `rows` of them up to time point k, each counted already
  // (count_row()): written. False when the caller stops the sweep.
  bool write_encoded(const std::string& text, Index rows, Index k) {
    return rows == 0 || written(writer->write(text, rows, k), k);
  }
  // The caller's answer to the rows up to time point k: false stops the sweep, as cancelled.
  bool written(bool go_on, Index k) {
    if (go_on) return true;
    sum.status = SolveStatus::kCancelled;
    sum.message = "stopped by the caller after step " + std::to_string(k);
    return false;
  }
  // The joint measures of the rows delivered so far, angles unwrapped: each row's angle is the 2π-multiple of its
  // wrapped value nearest to the last row's plus the rates' trapezoid over the step (every time point is
  // delivered here, written or not, so a joint is followed turn by turn).
  std::vector<JointMotion> joints;
  void unwrap_joints(Index k, const JointMotion* now) {
    if (!now) return;
    const bool first = joints.empty();
    if (first) joints.resize(opt.joints.size());
    const double dt = first ? 0.0 : time_of(k) - time_of(k - 1);
    for (std::size_t i = 0; i < joints.size(); ++i) {
      JointMotion m = now[i];
      if (opt.joints[i].measure == JointMeasure::kAngle && !first)
        m.value = unwrap_angle(m.value, joints[i].value, 0.5 * (joints[i].rate + m.rate) * dt);
      joints[i] = m;
    }
  }
  // A row delivered at t (deliver(); a Stepper's step): the bifurcation check against the last regular row, and
  // the row counted in the summary with its accuracy.
  void count_row(double t, Orientation det_sign, double det_sign_t, const RowQuality& quality) {
    if (det_sign.sign == 0) {
      singular_since = true;
    } else if (det_sign.sign != kSignUnknown) {
      // (a change between two steps of a sweep that solves velocities was found at the finest sub-step: no branch
      // was left there)
      if (last_sign.sign != 0 && det_sign != last_sign && !singular_since)
        sum.warnings.push_back(
            {t, "bifurcation",
             std::string(det_sign.sign != last_sign.sign
                             ? "det Φq changed sign"
                             : "the determinants of an even number of Φq's diagonal blocks (loops that Φq factorises "
                               "one by one) changed sign, det Φq's not,") +
                 " between t = " + format_time(last_sign_t) + " and t = " + format_time(det_sign_t) +
                 ": the motion passed a singular position there (a bifurcation, where branches cross); the sweep "
                 "kept the branch it was on"});
      last_sign = det_sign;
      last_sign_t = det_sign_t;
      singular_since = false;
    }
    ++sum.steps_completed;
    add_row_quality(sum.accuracy, t, quality);
  }
  // A failed step: the summary names the step, its grid time and the cause (already in sum.message).
  void failed(Index k) {
    sum.failed_step = k;
    sum.failed_time = time_of(k);
    sum.message = "step " + std::to_string(k) + ", t = " + format_time(time_of(k)) + ": " + sum.message;
  }
  // Steps k0 … steps in order with `sw`, whose state in ws is row k0 − 1. False on failure or cancellation.
  bool sequential(Sweeper& sw, Workspace& ws, Index k0) {
    for (Index k = k0; k <= opt.steps; ++k) {
      if (!sw.advance(time_of(k), 0)) {
        failed(k);
        return false;
      }
      if (!sw.row_outputs(k)) {
        failed(k);
        return false;
      }
      const State& s = sw.state();
      if (!deliver(k, s.q, s.qd, s.qdd, sw.motions(), ws.phi, sw.rcond(), sw.det_sign(), sw.det_sign_time(),
                   sw.row_quality()))
        return false;
    }
    return true;
  }
};

// Throws phiq::Error, naming `who`, for efforts (OutputPlan::efforts) the model or the plan cannot give: a constraint
// it does not have or that does not depend on time, no parts or loads, no accelerations solved (run_sweep.cpp).
void check_efforts(const Model& model, const OutputPlan& plan, const std::string& who);

// Throws phiq::Error for solver settings no step can honour, for output points that read a coordinate `model`
// does not have and for sensitivities whose models do not stand for `model` (check_sensitivity_models()), naming
// `who` (the options' type) in the message: run_sweep's checks, and a Stepper's.
void check_solver_settings(const Model& model, const SolverSettings& s, const std::vector<OutputPoint>& points,
                           const std::vector<OutputSensitivity>& sensitivities, const std::string& who);

// Adds the work counted in `now` since `before` to `into`.
inline void add_counters(WorkCounters& into, const WorkCounters& now, const WorkCounters& before) {
  into.newton_iterations += now.newton_iterations - before.newton_iterations;
  into.residual_evaluations += now.residual_evaluations - before.residual_evaluations;
  into.jacobian_evaluations += now.jacobian_evaluations - before.jacobian_evaluations;
  into.factorizations += now.factorizations - before.factorizations;
  into.pivoting_factorizations += now.pivoting_factorizations - before.pivoting_factorizations;
  into.velocity_solves += now.velocity_solves - before.velocity_solves;
  into.acceleration_solves += now.acceleration_solves - before.acceleration_solves;
  into.phi_t_evaluations += now.phi_t_evaluations - before.phi_t_evaluations;
  into.gamma_evaluations += now.gamma_evaluations - before.gamma_evaluations;
  into.point_evaluations += now.point_evaluations - before.point_evaluations;
  into.sensitivity_solves += now.sensitivity_solves - before.sensitivity_solves;
  into.sensitivity_direct_rows += now.sensitivity_direct_rows - before.sensitivity_direct_rows;
  into.effort_solves += now.effort_solves - before.effort_solves;
}

}  // namespace phiq::detail
