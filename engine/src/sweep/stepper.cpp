// Stepper (phiq/stepper.hpp): the sweep's Sweeper driven by the caller's clock instead of a time grid. Each step is
// what a sequential run_sweep does for one time point (the assembly at the first, Sweeper::advance at the others,
// then the row's outputs and its bifurcation check in Run::count_row), so that over a sweep's grid the rows are the
// same bits; what the stepper adds is what a grid does not need: times in any order, a step of zero length, the
// time domain checked per step, and a failed step undone.
#include "phiq/stepper.hpp"

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include "phiq/text.hpp"
#include "sweep/limit_watch.hpp"
#include "sweep/sweep_run.hpp"
#include "sweep/sweeper.hpp"

namespace phiq {

using detail::Sweeper;

struct Stepper::Impl {
  Impl(const Model& m, StepperOptions o) : model(&m), options(std::move(o)), ws(m) {}

  const Model* model;
  StepperOptions options;
  // The sweep options the Sweeper reads: the stepper's settings, a grid of one step from the start (its time
  // matters only at a start on a singular position: StepperOptions::expected_step), every row written.
  SweepOptions sweep;
  Workspace ws;
  SweepSummary sum;
  const std::function<bool(const StepView&)> no_callback;
  detail::Run run{sweep, no_callback, sum};  // the bifurcation check between rows and the rows' accuracy
  std::optional<Sweeper> sweeper;            // made anew at every start (construction, restart())
  // The sweeper as it stood before the current step's first subdivision (Sweeper::before_subdividing): the state
  // to return to when the sub-steps fail after some of them converged.
  std::optional<Sweeper> before_subdividing;
  bool started = false;
  double previous_t = NAN;  // the time of the row before the current one; NaN when the history holds none
  std::optional<detail::LimitWatch> limits;  // the options' limits, since the last start

  // The current state against the limits: a stretch begun here warned; `out` lists those outside.
  void check_limits(StepSummary& out) {
    if (!limits) return;
    const Sweeper& sw = *sweeper;
    if (sum.steps_completed > checked_steps) {
      limits->row(sw.state().t, sw.state().q.data(), sw.state().qd.size() ? sw.state().qd.data() : nullptr,
                  sw.motions().efforts);
      checked_steps = sum.steps_completed;
      for (std::size_t i = 0; i < options.limits.size(); ++i)
        if (limits->began(i)) sum.warnings.push_back(limits->beginning(i)), out.warnings.push_back(sum.warnings.back());
    }
    for (std::size_t i = 0; i < options.limits.size(); ++i)
      if (limits->outside(i)) out.limits.push_back(options.limits[i].name);
  }
  Index checked_steps = 0;  // steps_completed when the limits last read a row

  // A Sweeper for a start at t (the placement in ws.q).
  void make_sweeper(double t) {
    sweep.t_begin = t, sweep.t_end = t + options.expected_step, sweep.steps = 1;
    before_subdividing.reset();
    sweeper.reset();
    sweeper.emplace(*model, sweep, ws, sum);
    sweeper->before_subdividing = [this](const Sweeper& s) { before_subdividing.emplace(s); };
  }

  // The step to t: true on success (sum.message holds the cause otherwise). *assembled / *moved as in StepSummary.
  bool step_to(double t, bool* assembled, bool* moved);
  // Returns to the state before a step that failed.
  void undo(std::size_t warnings, Index singular_positions);
};

Stepper::Stepper(const Model& model, StepperOptions options)
    : impl_(std::make_unique<Impl>(model, std::move(options))) {
  const StepperOptions& o = impl_->options;
  detail::check_solver_settings(model, o, o.points, o.sensitivities, "StepperOptions");
  if (!std::isfinite(o.expected_step) || o.expected_step == 0.0)
    throw Error("StepperOptions: expected_step must be finite and non-zero");
  SweepOptions& s = impl_->sweep;
  static_cast<SolverSettings&>(s) = o;
  s.velocities = o.velocities, s.accelerations = o.accelerations, s.points = o.points;
  if (o.sensitivity_form != SensitivityForm::kAuto && o.sensitivity_form != SensitivityForm::kDirect)
    throw Error(
        "StepperOptions: sensitivity_form must be auto or direct (a stepper writes no coordinate columns for "
        "the adjoint form to solve for)");
  s.sensitivities = o.sensitivities, s.sensitivity_form = o.sensitivity_form;
  // each parameter's reach found once here, as run_sweep() does, not again at every step
  for (OutputSensitivity& p : s.sensitivities)
    if (!p.reach) p.reach = std::make_shared<const ParameterReach>(parameter_reach(model, p));
  s.efforts = o.efforts;
  detail::check_efforts(model, s, "StepperOptions");
  s.limits = o.limits;
  detail::check_limits(model, s, "StepperOptions");
  if (!o.limits.empty()) impl_->limits.emplace(impl_->options.limits);
  s.threads = 1;
  impl_->make_sweeper(0.0);  // refuses a predictor whose derivatives are not solved, before any step
}

Stepper::~Stepper() = default;
Stepper::Stepper(Stepper&&) noexcept = default;
Stepper& Stepper::operator=(Stepper&&) noexcept = default;

bool Stepper::Impl::step_to(double t, bool* assembled, bool* moved) {
  if (t < model->time_domain_begin() || t > model->time_domain_end()) {
    sum.message = "driver '" + model->time_domain_limiter() + "' is defined on [" +
                  format_time(model->time_domain_begin()) + ", " + format_time(model->time_domain_end()) + "] only";
    sum.status = SolveStatus::kOutsideTimeDomain;
    return false;
  }
  *moved = true;
  if (!started) {
    *assembled = true;
    ws.start_afresh();  // the results depend on the model, the options and the placement only, as a sweep's
    const Eigen::VectorXd placement = ws.q;
    make_sweeper(t);
    if (!sweeper->assemble(t)) {
      ws.q = placement;  // (Newton's last iterate otherwise): a retry starts from the placement again
      return false;
    }
    started = true;
    previous_t = NAN;
  } else {
    Sweeper& sw = *sweeper;
    const double now = sw.state().t;
    // A predictor's nodes are the times of the rows before, which must be distinct: where time turns back, the
    // next one could be a time already in the history. The history is forgotten there (the first step back
    // predicts from the current row alone, as after adopt()).
    if ((t - now) * (now - previous_t) < 0.0) {
      sw.leave_state_in_workspace();
      sw.adopt(now);
      previous_t = NAN;
    }
    before_subdividing.reset();
    if (!sw.advance(t, 0)) return false;
    before_subdividing.reset();
    previous_t = now;
  }
  Sweeper& s = *sweeper;
  // (every row is written: the points' motions, the orientation of Φq; a Stepper has no efforts, which alone fail)
  (void)s.row_outputs(sum.steps_completed);
  run.count_row(t, s.det_sign(), s.det_sign_time(), s.row_quality());
  return true;
}

void Stepper::Impl::undo(std::size_t warnings, Index singular_positions) {
  if (before_subdividing) {
    // sub-steps converged before one failed: the sweeper stands at the last of them, not where the step began
    sweeper.reset();
    sweeper.emplace(std::move(*before_subdividing));
    before_subdividing.reset();
  }
  if (started) sweeper->leave_state_in_workspace();
  // (the warnings of converged sub-steps are of rows never delivered)
  sum.warnings.resize(warnings);
  sum.singular_positions = singular_positions;
}

SolveStatus Stepper::step(double t, StepSummary* summary) {
  Impl& s = *impl_;
  if (!std::isfinite(t)) throw Error("Stepper::step: t = " + format_time(t) + " is not finite");
  const auto start = std::chrono::steady_clock::now();
  StepSummary local;
  StepSummary& out = summary ? *summary : local;
  out = StepSummary{};
  out.t = t;
  if (s.started) {
    const double now = s.sweeper->state().t;
    if (t == now) return s.check_limits(out), SolveStatus::kSuccess;  // the current state, re-delivered
    const double rounding = 8.0 * std::numeric_limits<double>::epsilon() * std::max(std::fabs(t), std::fabs(now));
    if (std::fabs(t - now) <= rounding)
      throw Error("Stepper::step: t = " + format_time(t) + " is within 8 ulps of the current time " + format_time(now) +
                  ", not equal: the step would not move time");
  }
  SweepSummary& sum = s.sum;
  const WorkCounters before = s.ws.counters;
  const std::size_t warnings = sum.warnings.size();
  const Index subdivisions = sum.subdivisions, singular_positions = sum.singular_positions;
  sum.status = SolveStatus::kSuccess;
  sum.message.clear(), sum.worst_rows.clear();
  sum.failed_step = -1, sum.failed_time = 0.0;
  if (!s.step_to(t, &out.assembled, &out.moved)) {
    s.undo(warnings, singular_positions);
    sum.failed_step = sum.steps_completed;
    sum.failed_time = t;
    sum.message = "t = " + format_time(t) + ": " + sum.message;
  }
  sum.counters = s.ws.counters;  // the stepper's own workspace: all its work is the steps'
  detail::add_counters(out.counters, s.ws.counters, before);
  out.status = sum.status;
  out.message = sum.message;
  out.worst_rows = sum.worst_rows;
  out.subdivisions = sum.subdivisions - subdivisions;
  out.warnings.assign(sum.warnings.begin() + static_cast<std::ptrdiff_t>(warnings), sum.warnings.end());
  if (out.status == SolveStatus::kSuccess) s.check_limits(out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sum.solve_seconds += out.seconds;
  return out.status;
}

void Stepper::restart(const Eigen::VectorXd& placement) {
  Impl& s = *impl_;
  if (placement.size() != s.model->num_coordinates())
    throw Error("Stepper::restart: the placement has " + std::to_string(placement.size()) + " entries, the model " +
                std::to_string(s.model->num_coordinates()) + " coordinates");
  s.ws.q = placement;
  s.started = false;
  if (s.limits) s.limits.emplace(s.options.limits);  // (a jump: no stretch goes on across it)
  s.previous_t = NAN;
  // a jump: no crossing is reported between the rows before it and those after
  s.run.last_sign = detail::Orientation{0, 0};
  s.run.singular_since = false;
}

bool Stepper::started() const { return impl_->started; }
double Stepper::time() const { return impl_->started ? impl_->sweeper->state().t : NAN; }
const Eigen::VectorXd& Stepper::q() const { return impl_->started ? impl_->sweeper->state().q : impl_->ws.q; }
const Eigen::VectorXd& Stepper::qd() const { return impl_->started ? impl_->sweeper->state().qd : impl_->ws.qd; }
const Eigen::VectorXd& Stepper::qdd() const { return impl_->started ? impl_->sweeper->state().qdd : impl_->ws.qdd; }
const PointMotion* Stepper::point_motions() const { return impl_->started ? impl_->sweeper->point_motions() : nullptr; }
const double* Stepper::sensitivities() const {
  return impl_->started ? impl_->sweeper->motions().sensitivities : nullptr;
}
const double* Stepper::efforts() const { return impl_->started ? impl_->sweeper->motions().efforts : nullptr; }
const SweepSummary& Stepper::summary() const { return impl_->sum; }
const Workspace& Stepper::workspace() const { return impl_->ws; }
const Model& Stepper::model() const { return *impl_->model; }
const StepperOptions& Stepper::options() const { return impl_->options; }

}  // namespace phiq
