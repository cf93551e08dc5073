#include "phiq/sweep.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

namespace phiq {

const char* to_string(Predictor p) {
  switch (p) {
    case Predictor::kAuto: return "auto";
    case Predictor::kPrevious: return "previous";
    case Predictor::kSecant: return "secant";
    case Predictor::kLinear: return "linear";
    case Predictor::kQuadratic: return "quadratic";
  }
  return "?";
}

namespace {

std::string fmt_t(double t) {
  std::ostringstream s;
  s.precision(10);
  s << t;
  return s.str();
}

struct State {
  double t = 0.0;
  Eigen::VectorXd q, qd, qdd;
};

class Sweeper {
 public:
  Sweeper(const Model& m, const SweepOptions& o, Workspace& ws, SweepSummary& sum)
      : model_(m), opt_(o), ws_(ws), sum_(sum) {
    need_v_ = o.velocities || o.accelerations;  // q̈ needs q̇
    need_a_ = o.accelerations;
    predictor_ = o.predictor;
    if (predictor_ == Predictor::kAuto)
      predictor_ = need_a_ ? Predictor::kQuadratic : need_v_ ? Predictor::kLinear : Predictor::kSecant;
    if (predictor_ == Predictor::kQuadratic && !need_a_)
      throw Error("the quadratic predictor needs accelerations (SweepOptions::accelerations)");
    if (predictor_ == Predictor::kLinear && !need_v_)
      throw Error("the linear predictor needs velocities (SweepOptions::velocities)");
  }

  // Derivatives at the converged ws.q, as asked for. Returns false (summary filled) on failure.
  bool derivatives(double t) {
    LinearSummary ls;
    if (need_v_ && solve_velocity(model_, t, ws_, &ls) != SolveStatus::kSuccess) return fail(ls.status, ls.message);
    if (need_a_ && solve_acceleration(model_, t, ws_, &ls) != SolveStatus::kSuccess)
      return fail(ls.status, ls.message);
    if (need_v_ && ws_.lu) {
      double rc = ws_.lu->rcond();
      if (sum_.min_rcond == 0.0 || rc < sum_.min_rcond) sum_.min_rcond = rc, sum_.min_rcond_time = t;
    }
    return true;
  }

  // Records the cause; run_sweep prefixes the step and its grid time (the sub-step time, if any, is in `why`).
  bool fail(SolveStatus st, const std::string& why) {
    sum_.status = st;
    sum_.message = why;
    return false;
  }

  // Initial position problem from the rough placement in ws.q.
  bool assemble(double t) {
    SolveStatus st = solve_position(model_, t, opt_.assembly, ws_, &sum_.assembly);
    if (st != SolveStatus::kSuccess) return fail(st, "initial assembly failed: " + sum_.assembly.message);
    note(t, sum_.assembly);
    if (!derivatives(t)) return false;
    remember(t);
    return true;
  }

  // From the converged state at current_.t to t1, subdividing on failure. current_ (and prev_) change only on
  // success, so a failed attempt restores from them without copying any state on the way.
  bool advance(double t1, int depth) {
    predict(t1);
    PositionSummary ps;
    SolveStatus st = solve_position(model_, t1, opt_.newton, ws_, &ps);
    if (st == SolveStatus::kSuccess) {
      note(t1, ps);
      if (!derivatives(t1)) return false;
      remember(t1);
      return true;
    }
    // Retry as two half steps from the last good state; a singular or non-finite point is not cured by that
    // unless the sub-steps avoid it, so all statuses are retried.
    if (depth >= opt_.max_subdivisions) {
      return fail(st, "no assembly beyond t = " + fmt_t(current_.t) + " (sub-steps down to t = " + fmt_t(t1) +
                          " tried: the drive leaves the reachable range, or the mechanism passes a singular "
                          "position): " + ps.message);
    }
    restore();
    ++sum_.subdivisions;
    const double tm = 0.5 * (current_.t + t1);
    return advance(tm, depth + 1) && advance(t1, depth + 1);
  }

 private:
  void note(double t, const PositionSummary& ps) {
    if (ps.slow_convergence) sum_.warnings.push_back({t, "slow_convergence", ps.message});
  }
  void predict(double t1) {
    const double h = t1 - current_.t;
    switch (predictor_) {
      case Predictor::kQuadratic: ws_.q = current_.q + h * current_.qd + (0.5 * h * h) * current_.qdd; break;
      case Predictor::kLinear: ws_.q = current_.q + h * current_.qd; break;
      case Predictor::kSecant:
        if (has_prev_ && current_.t != prev_.t)
          ws_.q = current_.q + (h / (current_.t - prev_.t)) * (current_.q - prev_.q);
        else
          ws_.q = current_.q;
        break;
      default: ws_.q = current_.q; break;
    }
  }
  void remember(double t) {
    // Only a state that was really converged becomes the secant's previous point (the default-constructed one
    // has no q: found by the fuzzer with a sweep starting away from t = 0).
    if (predictor_ == Predictor::kSecant && has_current_) {
      std::swap(prev_, current_);  // current_ now holds prev's buffers: assigned below without allocating
      has_prev_ = true;
    }
    has_current_ = true;
    current_.t = t;
    current_.q = ws_.q;
    if (need_v_) current_.qd = ws_.qd;
    if (need_a_) current_.qdd = ws_.qdd;
  }
  void restore() {
    ws_.q = current_.q;
    if (need_v_) ws_.qd = current_.qd;
    if (need_a_) ws_.qdd = current_.qdd;
  }

  const Model& model_;
  const SweepOptions& opt_;
  Workspace& ws_;
  SweepSummary& sum_;
  bool need_v_ = false, need_a_ = false;
  Predictor predictor_;
  State current_, prev_;
  bool has_current_ = false, has_prev_ = false;
};

}  // namespace

std::string SweepSummary::BriefReport() const {
  std::ostringstream s;
  s << to_string(status) << ": " << steps_completed << " steps, " << counters.newton_iterations
    << " Newton iterations, " << counters.factorizations << " factorizations, " << counters.velocity_solves
    << " velocity and " << counters.acceleration_solves << " acceleration solves";
  if (subdivisions) s << ", " << subdivisions << " step subdivisions";
  if (!warnings.empty()) s << ", " << warnings.size() << " warnings (first at t = " << warnings[0].t << ")";
  s.precision(3);
  s << ", " << std::scientific << solve_seconds << " s";
  if (!message.empty()) s << " — " << message;
  return s.str();
}

SolveStatus run_sweep(const Model& model, const SweepOptions& opt, Workspace& ws,
                      const std::function<bool(const StepView&)>& on_step, SweepSummary* summary) {
  if (&ws.model() != &model) throw Error("workspace was made for another model");
  if (opt.steps < 0) throw Error("SweepOptions: steps must be >= 0");
  if (!std::isfinite(opt.t_begin) || !std::isfinite(opt.t_end)) throw Error("SweepOptions: times must be finite");
  SweepSummary local;
  SweepSummary& sum = summary ? *summary : local;
  sum = SweepSummary{};
  const auto start = std::chrono::steady_clock::now();
  const WorkCounters before = ws.counters;
  auto done = [&](SolveStatus st) {
    sum.status = st;
    const WorkCounters& c = ws.counters;
    sum.counters = WorkCounters{c.newton_iterations - before.newton_iterations,
                                c.residual_evaluations - before.residual_evaluations,
                                c.jacobian_evaluations - before.jacobian_evaluations,
                                c.factorizations - before.factorizations,
                                c.velocity_solves - before.velocity_solves,
                                c.acceleration_solves - before.acceleration_solves,
                                c.phi_t_evaluations - before.phi_t_evaluations,
                                c.gamma_evaluations - before.gamma_evaluations};
    sum.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return st;
  };

  const double lo = std::min(opt.t_begin, opt.t_end), hi = std::max(opt.t_begin, opt.t_end);
  if (lo < model.time_domain_begin() || hi > model.time_domain_end()) {
    const double bad = lo < model.time_domain_begin() ? lo : hi;
    sum.failed_step = lo < model.time_domain_begin() ? (opt.t_begin <= opt.t_end ? 0 : opt.steps)
                                                     : (opt.t_begin <= opt.t_end ? opt.steps : 0);
    sum.failed_time = bad;
    sum.message = "t = " + fmt_t(bad) + ": driver '" + model.time_domain_limiter() + "' is defined on [" +
                  fmt_t(model.time_domain_begin()) + ", " + fmt_t(model.time_domain_end()) +
                  "] only; the sweep runs over [" + fmt_t(lo) + ", " + fmt_t(hi) + "]";
    return done(SolveStatus::kOutsideTimeDomain);
  }

  Sweeper sw(model, opt, ws, sum);
  const double h = opt.steps > 0 ? (opt.t_end - opt.t_begin) / static_cast<double>(opt.steps) : 0.0;
  for (Index k = 0; k <= opt.steps; ++k) {
    // t_k computed from k, not accumulated, so that the last point is t_end exactly
    const double t = k == opt.steps ? opt.t_end : opt.t_begin + static_cast<double>(k) * h;
    const bool ok = k == 0 ? sw.assemble(t) : sw.advance(t, 0);
    if (!ok) {
      sum.failed_step = k;
      sum.failed_time = t;
      sum.message = "step " + std::to_string(k) + ", t = " + fmt_t(t) + ": " + sum.message;
      return done(sum.status);
    }
    StepView view{k, t, ws.q, opt.velocities ? &ws.qd : nullptr, opt.accelerations ? &ws.qdd : nullptr};
    ++sum.steps_completed;
    if (on_step && !on_step(view)) {
      sum.message = "stopped by the caller after step " + std::to_string(k);
      return done(SolveStatus::kCancelled);
    }
  }
  return done(SolveStatus::kSuccess);
}

}  // namespace phiq
