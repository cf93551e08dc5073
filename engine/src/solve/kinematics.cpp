// The position solve: Newton's method on Φ(q, t) = 0 with its step and residual tests, backtracking, the reuse
// of a factorisation while it contracts, and the stop at the rounding level; with the Workspace's constructor (the
// statuses' names, the check of NewtonOptions and how well q is known: position_report.cpp). Φq's factorisation,
// shared with the velocity and acceleration solves (derivatives.cpp), is in factorisation.cpp.
#include "phiq/kinematics.hpp"
#include "phiq/text.hpp"

#include "solve/factorisation.hpp"
#include "solve/kinematics_internal.hpp"
#include "solve/rounding_rows.hpp"
#include "solve/tolerance_tests.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

namespace phiq {

Workspace::Workspace(const Model& model) : anchor_(model.anchor_) {
  if (!anchor_) throw Error("a Workspace of a Model that was moved from (it has no data)");
  const Index n = model.num_coordinates(), m = model.num_equations();
  q = model.initial_positions();
  qd = Eigen::VectorXd::Zero(n);
  qdd = Eigen::VectorXd::Zero(n);
  phi.resize(m);
  rhs.resize(m);
  step.resize(n);
  trial.resize(n);
  trial_phi.resize(m);
  jacobian_values.assign(static_cast<std::size_t>(model.jacobian_pattern().nnz()), 0.0);
  if (!model.dropped_rows().empty()) {
    solve_values.assign(model.solve_entries().size(), 0.0);
    solve_rhs.resize(model.num_solve_rows());
  }
  if (model.symbolic()) lu = model.symbolic()->make_numeric();
}

void Workspace::start_afresh() {
  has_factorization = false;
  factorized_at_solution = false;
  factorized_solves_to = std::numeric_limits<double>::quiet_NaN();
  has_jacobian = false;
  newton_contraction = -1.0;
  if (lu && !lu->restore_pinned_pivot_order()) lu->forget_pivot_order();  // (a parallel sweep's pinned order)
}

namespace {

using detail::check_workspace;
using detail::describe_rows;
using detail::factorize_at_q;
using detail::factors_at_q;
using detail::kQuietRoundingLevel;
using detail::kUlpFloor;
using detail::non_finite_jacobian_at;
using detail::not_square_message;
using detail::residual_within;
using detail::solve_rhs;
using detail::worst_rows;

// max_j |Δq_j| / (tol · scale_j + floor_j): ≤ 1 when the step is within the tolerance (NaN propagates as > 1).
// With tol = 1 it is the size of the step in the tolerance-scaled norm (the floor is then negligible). `worst`,
// when given, receives the j of the maximum.
template <class Step>
double step_ratio(const Model& model, const Step& dq, const Eigen::VectorXd& q, double tol, Index* worst = nullptr) {
  if (q.size() == 0) return 0.0;
  Index j = 0;
  const double r =
      (dq.array().abs() / (tol * model.tolerance_scales().coordinate_scale.array() + kUlpFloor * q.array().abs()))
          .maxCoeff(&j);
  if (worst) *worst = j;
  return std::isnan(r) ? std::numeric_limits<double>::infinity() : r;
}

// max_i |Φ_i| / scale_i, NaN rows ignored (they are reported by the finiteness check).
double max_scaled(const Model& model, const Eigen::VectorXd& phi) {
  const Eigen::VectorXd& rs = model.tolerance_scales().row_scale;
  double m = 0.0;
  for (Index i = 0; i < phi.size(); ++i) m = std::max(m, std::fabs(phi(i)) / rs(i));
  return m;
}

// factor · step_ratio(dq, q, tol) ≤ 1, without a division per coordinate (false on NaN).
template <class Step>
bool step_within(const Model& model, const Step& dq, const Eigen::VectorXd& q, double tol, double factor) {
  const ToleranceScales& s = model.tolerance_scales();
  return ((factor * dq.array().abs()) <= (tol * s.coordinate_scale.array() + kUlpFloor * q.array().abs())).all();
}

bool all_finite(const Eigen::VectorXd& v) { return v.allFinite(); }

// What the Newton loop needs of Φ at each iterate, from one pass over it instead of three: the merit
// ½ Σ (Φ_i / scale_i)², whether Φ is finite, and whether every row is within the tolerance (residual_within).
struct ResidualCheck {
  double merit = 0.0;
  double worst = 0.0;       // max_i |Φ_i| / scale_i
  double kept_worst = 0.0;  // and over the rows Newton corrects (those of merit: not at their rounding)
  bool finite = true;
  bool within = false;
};
// The passes' reductions run in kLanes independent accumulators: one chain would wait for each addition's latency
// (a pass ran at a third of the speed of memory on models that fit in cache). in_lanes(n, f) calls f(lane, i) for
// every i < n, lanes taking consecutive i in turn; lanes_max() joins the lanes' maxima.
constexpr int kLanes = 4;
template <class F>
void in_lanes(Index n, F&& f) {
  Index i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (int k = 0; k < kLanes; ++k) f(k, i + k);
  for (int k = 0; i < n; ++i, ++k) f(k, i);
}
double lanes_max(const double (&v)[kLanes]) { return std::max(std::max(v[0], v[1]), std::max(v[2], v[3])); }

ResidualCheck check_residual(const Model& model, const Eigen::VectorXd& phi, double tol, const Eigen::VectorXd& q,
                             double t) {
  const double* p = phi.data();
  const double* inv = model.tolerance_scales().inverse_row_scale.data();
  double sums[kLanes] = {}, worsts[kLanes] = {};
  in_lanes(phi.size(), [&](int k, Index r) {
    const double s = std::fabs(p[r]) * inv[r];
    sums[k] += s * s;
    worsts[k] = worsts[k] < s ? s : worsts[k];  // NaN rows are caught by `finite`
  });
  const double sum = (sums[0] + sums[1]) + (sums[2] + sums[3]);
  const double worst = lanes_max(worsts);
  ResidualCheck c;
  c.merit = 0.5 * sum;
  c.worst = c.kept_worst = worst;
  c.finite = std::isfinite(sum) || phi.allFinite();  // a sum that overflowed is still a finite Φ
  // rows above tol are held to tol · scale_i plus their rounding floor, looked at only then
  c.within = c.finite && (worst <= tol || residual_within(model, phi, tol, q, t));
  return c;
}

// trial = q − α·dx (dx = Φq⁻¹Φ, so that −α·dx is the Newton step), in one pass with what the loop needs of the
// step: its size in the tolerance test, step_ratio(α·dx, trial, tol) (≤ 1 when within the tolerance; +∞ on NaN),
// and for the full step its scaled norm max_j |dx_j| / scale_j (the contraction estimate's measure) and whether
// it is finite.
struct StepPass {
  double size = 0.0;
  double norm = 0.0;
  bool finite = true;
};
StepPass take_step(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& dx, double alpha, double tol,
                   Eigen::VectorXd& trial) {
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  const double* inv = model.tolerance_scales().inverse_coordinate_scale.data();
  const double* x = q.data();
  const double* d = dx.data();
  double* out = trial.data();
  detail::WorstRatio worst;  // |step| / allowed, divided only where it may exceed the largest so far
  double norms[kLanes] = {};
  in_lanes(q.size(), [&](int k, Index j) {
    const double step = alpha * d[j];
    const double v = x[j] - step;
    out[j] = v;
    worst.add(std::fabs(step), tol * cs[j] + kUlpFloor * std::fabs(v));
    const double s = std::fabs(d[j]) * inv[j];
    norms[k] = norms[k] < s ? s : norms[k];  // a NaN is lost here, not in `worst`; an infinity is kept
  });
  StepPass p;
  p.size = worst.worst;
  p.norm = lanes_max(norms);
  // A NaN in dx makes the worst ratio infinite (WorstRatio), an infinity makes the norm infinite: only then (or on
  // an overflow of either) is dx itself looked at.
  p.finite = (std::isfinite(p.norm) && std::isfinite(p.size)) || dx.allFinite();
  return p;
}

}  // namespace

double scaled_residual(const Model& model, const Eigen::VectorXd& phi) { return max_scaled(model, phi); }

double scaled_step(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& dq, const Eigen::VectorXd& q,
                   double tol) {
  return step_ratio(model, dq, q, tol);
}

namespace {

// One position solve, in the parts of a Newton iteration: the start, the tests before a step, the factorisation,
// the step with the test of a reused matrix, the line search, the stop at the rounding level and the acceptance of
// a step. The members are what an iteration hands to the next.
class PositionSolve {
 public:
  PositionSolve(const Model& model, double t, const NewtonOptions& opt, Workspace& ws, PositionSummary& sum)
      : model_(model), t_(t), opt_(opt), ws_(ws), sum_(sum), carried_theta_(ws.newton_contraction) {}
  SolveStatus run();

 private:
  // One iteration's step from the current iterate to its trial point (ws.trial, ws.trial_phi).
  struct Step {
    StepPass full;        // the full step's measures
    double theta = -1.0;  // contraction θ = ‖Δq_k‖ / ‖Δq_k−1‖ in the tolerance-scaled norm (−1: unknown)
    double eta = 1.0;     // error of the new iterate per unit of the step: θ/(1−θ) where θ is known
    double alpha = 1.0;   // the line search's fraction of the full step
    double size = 0.0;    // the step in units of the tolerance test
    double error = 0.0;   // the trial's estimated error, min(η, 1) times that
    ResidualCheck trial;  // of the trial point
    bool with_jacobian = false;  // Φq evaluated at the trial
    bool known_ok = false;       // a full step whose error is within NewtonOptions::known_to
    bool refresh = false;        // a reused matrix to be replaced at this iterate
  };

  SolveStatus finish(SolveStatus st, std::string msg);
  std::optional<SolveStatus> start();
  std::optional<SolveStatus> stop_before_step(int it);
  std::optional<SolveStatus> factorize_unless_reused();
  std::optional<SolveStatus> newton_step(Step& s);
  std::optional<SolveStatus> line_search(Step& s);
  SolveStatus stop_at_rounding_level(bool known_before, const Step& s, int it);
  bool step_corrected_error(const Step& s);
  bool accept(const Step& s);
  void refresh_matrix() { reuse_ = false, prev_norm_ = -1.0; }
  // Φ as Newton corrects it: without the rows at the rounding of their own terms (rounding_rows.hpp)
  const Eigen::VectorXd& corrected(const Eigen::VectorXd& phi) {
    return rounding_rows_.empty() ? phi : rounding_rows_.without(phi);
  }

  const Model& model_;
  const double t_;
  const NewtonOptions& opt_;
  Workspace& ws_;
  PositionSummary& sum_;
  // The contraction last observed with a reused factorisation, if any: it estimates the error of the first step of
  // this solve (same age of the matrix in a sweep). It is kept until a solve measures it again — a solve accepted
  // without a step, or one that refactorised at once, says nothing new about it — and dropped on a failure.
  const double carried_theta_;
  // Whether ws.jacobian_values hold Φq at the current iterate (evaluated with Φ at the accepted trial point and
  // not yet factorised): the loop knows it without comparing points; the point is recorded once, at the end.
  bool jacobian_at_q_ = false;
  bool factorized_here_ = false;  // this solve factorised (at an iterate whose point is not recorded)
  double drift_ = 0.0;            // sum of the steps' sizes (tolerance units) since that factorisation
  // The solve stopped at its rounding level after a step from a point within the tolerance of that factorisation:
  // the step is the rounding itself, q is known no better than its size, and the factorisation is Φq at the
  // solution to that accuracy (see stop_at_rounding_level).
  bool factorized_at_rounding_level_ = false;
  ResidualCheck check_;  // of the current iterate (its worst row is the residual reported on success)
  bool step_ok_ = false;
  // Modified Newton reuses the workspace's factorisation until it contracts badly; then (and always for full
  // Newton) every iteration factorises at its iterate.
  bool reuse_ = false;
  double prev_norm_ = -1.0;   // scaled size of the previous step taken with the same kind of matrix
  double theta_seen_ = -1.0;  // largest contraction observed with the reused matrix in this solve
  int reused_steps_ = 1;      // steps taken with the reused matrix once a contraction is known
  static constexpr int kMaxReusedSteps = 4;
  int stagnant_ = 0;              // consecutive fresh-matrix steps that contracted by ½ or worse
  double accepted_error_ = -1.0;  // newton_step's error estimate of the current iterate (units of the tolerance test)
  int corrections_ = 0;           // steps step_corrected_error() kept from a stop at the rounding level
  static constexpr int kMaxCorrections = 3;
  static constexpr double kCorrectedContraction = 0.25;
  detail::RoundingRows rounding_rows_;  // at the current iterate, left out of its step and of the merit
};

SolveStatus PositionSolve::finish(SolveStatus st, std::string msg) {
  sum_.status = st;
  if (st != SolveStatus::kSuccess) ws_.newton_contraction = -1.0;
  if (st == SolveStatus::kSuccess) {
    sum_.residual = check_.worst;  // max_i |Φ_i| / scale_i, from the pass that tested it
    // an error above the quiet level, or rows left at their rounding, told in the coordinate's own unit
    // (position_report.cpp)
    const bool rounding_rows = rounding_rows_.seen() && sum_.iterations > 0;
    if (rounding_rows ||
        (sum_.error_estimate > kQuietRoundingLevel && sum_.iterations + (sum_.error_coordinate >= 0) > 0)) {
      Index j = sum_.error_coordinate;
      if (j < 0) (void)step_ratio(model_, ws_.step, ws_.q, opt_.tolerance, &j);
      detail::locate_error(model_, opt_.tolerance, std::max(sum_.error_estimate, 0.0), j, ws_, &sum_.error_coordinate,
                           &sum_.error_size);
      if (rounding_rows) detail::report_rounding_rows(model_, opt_.tolerance, rounding_rows_.named(), ws_.q, sum_);
    }
    // A factorisation made within the tolerance of the solution (the last step was below it) is Φq at the
    // solution to the accuracy q itself has: velocity and acceleration reuse it instead of refactorising.
    // Otherwise they factorise at the solution, from the Jacobian evaluated there with Φ if there is one.
    if (factorized_here_ ? ws_.has_factorization && (drift_ <= 1.0 || factorized_at_rounding_level_)
                         : ws_.has_factorization && ws_.factorized_t == t_ && ws_.factorized_q.size() == ws_.q.size() &&
                               step_within(model_, ws_.q - ws_.factorized_q, ws_.q, opt_.tolerance, 1.0)) {
      ws_.factorized_q = ws_.q;
      ws_.factorized_t = t_;
      ws_.factorized_at_solution = true;
    } else if (jacobian_at_q_) {
      ws_.jacobian_q = ws_.q;
      ws_.jacobian_t = t_;
      ws_.has_jacobian = true;
    }
    return st;
  }
  sum_.worst_rows = worst_rows(model_, ws_.phi, 3);
  sum_.residual = sum_.worst_rows.empty() ? 0.0 : sum_.worst_rows[0].second;
  sum_.message = std::move(msg);
  if (!sum_.worst_rows.empty()) sum_.message += "; worst constraints: " + describe_rows(model_, sum_.worst_rows);
  return st;
}

// The start point: Φ there (and Φq where it will be factorised), or the solve's end when it cannot start.
std::optional<SolveStatus> PositionSolve::start() {
  ws_.has_jacobian = false;
  ws_.factorized_at_solution = false;
  ws_.factorized_solves_to = std::numeric_limits<double>::quiet_NaN();
  if (!ws_.lu) {
    model_.residual(ws_.q.data(), t_, ws_.phi.data());
    return finish(SolveStatus::kNotSquare, not_square_message(model_));
  }
  if (!all_finite(ws_.q)) {
    ws_.phi.setConstant(std::numeric_limits<double>::quiet_NaN());
    return finish(SolveStatus::kNonFinite, "starting point has non-finite coordinates");
  }
  // Φq comes with Φ (one pass over the constraints instead of two) at every point where it will be factorised: the
  // start and each trial when the next iteration factorises at its iterate (full Newton; modified Newton once it
  // has refreshed), unless the trial's step already passes the tolerance (it is then expected to be the solution);
  // and the expected solution when the caller factorises there next (NewtonOptions::jacobian_with_residual:
  // velocities follow). A wrong guess costs one separate Jacobian evaluation, or one wasted. The trial's Φq goes
  // straight into jacobian_values: once the iterate's own Φq is factorised nothing needs it, and where it is not
  // (jacobian_at_q, a reused matrix) a rejected trial only costs its evaluation again — no second array of Φq.
  reuse_ = opt_.jacobian_update == JacobianUpdate::kWhenSlow && ws_.has_factorization;
  // The start point too: where its first iteration will factorise there anyway, Φq comes with Φ; and where the
  // caller factorises next (velocities follow) at a start its estimate expects to be accepted as it is.
  const bool start_expected = opt_.jacobian_with_residual && opt_.start_error >= 0.0 && opt_.start_error <= 1.0;
  if (!reuse_ || start_expected) {
    model_.residual_and_jacobian(ws_.q.data(), t_, ws_.phi.data(), ws_.jacobian_values.data());
    ++ws_.counters.jacobian_evaluations;
    jacobian_at_q_ = true;
  } else {
    model_.residual(ws_.q.data(), t_, ws_.phi.data());
  }
  ++ws_.counters.residual_evaluations;
  check_ = check_residual(model_, ws_.phi, opt_.tolerance, ws_.q, t_);
  return std::nullopt;
}

// The tests at an iterate before its step: accepted, converging too slowly to go on, or out of iterations. The
// iteration limit counts steps taken; a step discarded to refresh a reused factorisation does not count.
std::optional<SolveStatus> PositionSolve::stop_before_step(int it) {
  if (!check_.finite) return finish(SolveStatus::kNonFinite, "constraint residual is not finite");
  const bool within = check_.within;
  if (within && (it == 0 ? !(opt_.start_error > 1.0) : step_ok_)) {
    if (theta_seen_ >= 0.0) ws_.newton_contraction = theta_seen_;
    sum_.error_estimate = it == 0 ? opt_.start_error : accepted_error_;
    return finish(SolveStatus::kSuccess, "");
  }
  // The residual holds but the steps have stopped shrinking fast: full-Newton steps contracting by ½ or worse
  // twice in a row (linear convergence at a singular position, or steps at the rounding level of an
  // ill-conditioned Φq), or the iteration limit reached. More iterations would not make q more accurate.
  if (it > 0 && (it >= opt_.max_iterations || stagnant_ >= 2) && within) {
    sum_.slow_convergence = sum_.linear_convergence = true;
    sum_.error_estimate = accepted_error_;
    (void)finish(SolveStatus::kSuccess, "");  // (returned below, after its message)
    sum_.message =
        "residual within tolerance but the Newton steps stopped converging quadratically (a singular "
        "position, or Φq too ill-conditioned for this tolerance)";
    return SolveStatus::kSuccess;
  }
  if (it >= opt_.max_iterations)
    return finish(SolveStatus::kNotConverged,
                  "Newton did not converge in " + std::to_string(opt_.max_iterations) + " iterations");
  return std::nullopt;
}

// Φq factorised at this iterate unless a reused matrix serves or its factors are there already. Its point is not
// copied per iteration: the loop counts how far it has moved since (drift), and records it once, at the end, if
// that is the solution.
std::optional<SolveStatus> PositionSolve::factorize_unless_reused() {
  if (reuse_) {
    sum_.rcond = ws_.lu->rcond();
    return std::nullopt;
  }
  std::string msg;
  SolveStatus st = SolveStatus::kSuccess;
  if (!factors_at_q(ws_, t_)) {
    st = factorize_at_q(model_, t_, ws_, &sum_.rcond, &msg, jacobian_at_q_);
    ws_.factorized_t = std::numeric_limits<double>::quiet_NaN();  // point not recorded (yet)
    if (st == SolveStatus::kSuccess) ++sum_.factorizations;
  } else {
    sum_.rcond = ws_.lu->rcond();
  }
  jacobian_at_q_ = false;  // factorised (or failed): jacobian_values are no longer news
  if (st != SolveStatus::kSuccess) return finish(st, msg);
  factorized_here_ = true;
  drift_ = 0.0;
  return std::nullopt;
}

// The Newton step and its full trial point, with the test of a reused matrix (s.refresh: replace it here).
std::optional<SolveStatus> PositionSolve::newton_step(Step& s) {
  // ws.step = Φq⁻¹Φ: the Newton step is −ws.step (no negated copy of Φ; the LU's rounding is sign-symmetric)
  if (!ws_.lu->solve(solve_rhs(model_, ws_, corrected(ws_.phi)), ws_.step.data()))
    return finish(SolveStatus::kLinearSolverFailed, "sparse solve failed: " + ws_.lu->last_message());
  // the full step's trial point and measures in one pass (the trial is wasted when the matrix is refreshed)
  s.full = take_step(model_, ws_.q, ws_.step, 1.0, opt_.tolerance, ws_.trial);
  if (!s.full.finite) {
    if (reuse_) {  // an old factorisation may be singular where the current iterate is not
      s.refresh = true;
      return std::nullopt;
    }
    std::string why = non_finite_jacobian_at(model_, ws_.q.data(), t_);
    if (!why.empty()) return finish(SolveStatus::kNonFinite, why);
    return finish(SolveStatus::kSingularJacobian, "Newton step is not finite (Jacobian numerically singular)");
  }
  // A reused matrix that contracts worse than max_contraction is replaced by a fresh one at this iterate (the step
  // just computed is discarded).
  s.theta =
      prev_norm_ > 0.0 ? s.full.norm / prev_norm_ : (reuse_ && carried_theta_ >= 0.0 ? 2.0 * carried_theta_ : -1.0);
  if (reuse_ && prev_norm_ > 0.0) {
    theta_seen_ = std::max(theta_seen_, s.theta);
    // Refresh on a slow contraction, or when the steps left (the iteration limit, or kMaxReusedSteps: a
    // factorisation costs about two solves) cannot reach the tolerance at this rate: after j more steps the
    // error is about θ^(j+1)/(1−θ)·|Δq| (Hairer & Wanner IV.8), or the level q is known to (known_to).
    ++reused_steps_;
    const int left = std::min(opt_.max_iterations - sum_.iterations - 1, kMaxReusedSteps - reused_steps_);
    if (s.theta > opt_.max_contraction || left < 0 ||
        !(std::pow(s.theta, left + 1) / (1.0 - s.theta) * s.full.size <= std::max(1.0, opt_.known_to)))
      s.refresh = true;
  }
  // Error of the new iterate: θ/(1−θ)·|Δq| where a contraction is known, else the step itself.
  s.eta = (s.theta >= 0.0 && s.theta < 1.0) ? s.theta / (1.0 - s.theta) : 1.0;
  return std::nullopt;
}

// Backtracking on the scaled merit: a full step whenever it helps, a shorter one from a rough placement. A reused
// matrix whose full step does not decrease the merit is refreshed rather than backtracked along (s.refresh).
std::optional<SolveStatus> PositionSolve::line_search(Step& s) {
  for (int bt = 0;; ++bt) {
    s.size = bt == 0 ? s.full.size : take_step(model_, ws_.q, ws_.step, s.alpha, opt_.tolerance, ws_.trial).size;
    s.error = std::min(s.eta, 1.0) * s.size;
    step_ok_ = s.error <= 1.0;
    s.known_ok = bt == 0 && s.error <= opt_.known_to;
    s.with_jacobian = step_ok_ || s.known_ok ? opt_.jacobian_with_residual : !reuse_;
    if (s.with_jacobian) {
      model_.residual_and_jacobian(ws_.trial.data(), t_, ws_.trial_phi.data(), ws_.jacobian_values.data());
      jacobian_at_q_ = false;  // the values are the trial's now
      ++ws_.counters.jacobian_evaluations;
    } else {
      model_.residual(ws_.trial.data(), t_, ws_.trial_phi.data());
    }
    ++ws_.counters.residual_evaluations;
    s.trial = check_residual(model_, ws_.trial_phi, opt_.tolerance, ws_.trial, t_);
    if (!rounding_rows_.empty())
      rounding_rows_.kept_measures(model_, ws_.trial_phi, &s.trial.merit, &s.trial.kept_worst);
    if (!opt_.line_search || s.trial.merit <= (1.0 - 1e-4 * s.alpha) * check_.merit || s.trial.within ||
        rounding_rows_.decrease_apart_from_rounding(model_, ws_.phi, ws_.trial_phi, ws_.trial, opt_.tolerance, t_,
                                                    1.0 - 1e-4 * s.alpha))
      return std::nullopt;
    if (reuse_) {
      s.refresh = true;
      return std::nullopt;
    }
    if (bt >= opt_.max_backtracks) {
      return finish(SolveStatus::kNotConverged,
                    "no decrease of the residual along the Newton direction (the constraints may have no "
                    "solution near this guess)");
    }
    s.alpha *= 0.5;
    ++sum_.backtracks;
  }
}

// The solve ends at the rounding level of q: `known_before`, the step ended the solve within
// NewtonOptions::known_to. Its error is then the larger of min(η, 1) × its size (η from a contraction observed)
// and of its size up to known_to: a step that is mostly rounding does not contract, however well the steps before
// it did, and q is known no better than that level.
SolveStatus PositionSolve::stop_at_rounding_level(bool known_before, const Step& s, int it) {
  Index worst = 0;
  const double size = step_ratio(model_, ws_.step, ws_.q, opt_.tolerance, &worst);
  const double worst_ratio = known_before ? std::max(std::min(s.eta, 1.0) * size, std::min(size, opt_.known_to)) : size;
  sum_.rounding_level = worst_ratio;
  sum_.rounding_measured = !known_before && it > 0;
  sum_.error_estimate = worst_ratio;
  sum_.error_coordinate = worst;
  // The contraction seen with a reused matrix: the rounding in its last step makes it an overestimate, which
  // the next solve's first step may use as such (kept, as a success's).
  if (theta_seen_ >= 0.0) ws_.newton_contraction = theta_seen_;
  (void)finish(SolveStatus::kSuccess, "");  // (its status is returned below, with the message set)
  // Known to within twice the tolerance: as good as the tolerance test's own estimate promises (it is an
  // estimate, not a bound), nothing to warn about. A 2000-stage scissor lift sits there at the default
  // tolerance (its top joints, 600 m up, are known to 1.2 tolerances).
  if (worst_ratio <= kQuietRoundingLevel) return SolveStatus::kSuccess;
  sum_.slow_convergence = true;
  const std::string known =
      known_to_text(model_, sum_.error_coordinate, sum_.error_size) + ", which is how well q is known there";
  sum_.message = known_before ? "the Newton step is within the level q can be known to here (NewtonOptions::known_to, "
                                "which a sweep measures at its previous rows: the rounding of Φ amplified by Φq⁻¹, a "
                                "long chain or Φq ill-conditioned): " +
                                    known
                              : "the residual is at its rounding level and the Newton steps no longer reduce it: they "
                                "are the rounding of Φ amplified by Φq⁻¹ (a long chain, or Φq ill-conditioned): " +
                                    known;
  return SolveStatus::kSuccess;
}

// Whether the full step just tried, though it did not halve the merit, corrected a real error of q: the next
// (simplified) Newton step from its trial point, with the same factors, is at most a quarter of it in the
// tolerance test's units (each coordinate in its own unit). The merit weighs rows by their scales, not by what
// their residuals do to q: on a four-bar of a 10⁶ m coupler and a 10⁻⁶ m crank, a coupler pin's residual of
// 10⁻⁷ m (10⁻¹³ of its scale) puts the rocker 0.1 rad off, while the merit is the rocker row's rounding (10⁻¹⁰ m
// of 1.5·10⁻⁶ m). At the rounding level the next step is more rounding, as large as this one (θ ≈ 1); a step that
// corrected an error leaves one far smaller. One solve with the factors at hand, only where the merit alone would
// stop; at most kMaxCorrections per solve, so that rounding that happens to contract cannot run on, and not for a
// step within the level the rows before measured (NewtonOptions::known_to: that is rounding already known).
bool PositionSolve::step_corrected_error(const Step& s) {
  if (corrections_ >= kMaxCorrections || s.known_ok || !s.trial.finite) return false;
  double* next = ws_.rhs.data();  // (scratch of the derivative solves: at least n entries where Φq is square)
  if (!ws_.lu->solve(solve_rhs(model_, ws_, corrected(ws_.trial_phi)), next)) return false;
  const Eigen::Map<const Eigen::VectorXd> next_step(next, ws_.q.size());
  if (!(step_ratio(model_, next_step, ws_.trial, opt_.tolerance) <= kCorrectedContraction * s.full.size)) return false;
  ++corrections_;
  return true;
}

// The trial point becomes the iterate; returns whether the step started within the tolerance of the
// factorisation's point.
bool PositionSolve::accept(const Step& s) {
  ++ws_.counters.newton_iterations;
  ++sum_.iterations;
  stagnant_ = (!reuse_ && s.alpha == 1.0 && prev_norm_ > 0.0 && s.theta >= 0.5) ? stagnant_ + 1 : 0;
  prev_norm_ = s.alpha == 1.0 ? s.full.norm : -1.0;  // a shortened step says nothing about the contraction
  ws_.q.swap(ws_.trial);
  ws_.phi.swap(ws_.trial_phi);
  const bool step_from_factorization = drift_ <= 1.0;
  drift_ += s.size;  // max-norm distance from the factorisation's point, by the triangle inequality
  // The error reported (and carried by a sweep to the rows it extrapolates): the contraction estimate, or the
  // step's size times the residual's reduction when that is the larger — the size of the next step, were it
  // taken. Where the steps are the rounding of Φ amplified along a long chain, the residual no longer falls and
  // θ measured on the previous solve's steps says nothing of it: the error is then about the step itself.
  accepted_error_ =
      std::max(s.error, check_.kept_worst > 0.0 ? s.size * (s.trial.kept_worst / check_.kept_worst) : 0.0);
  jacobian_at_q_ = s.with_jacobian;
  check_ = s.trial;
  return step_from_factorization;
}

SolveStatus PositionSolve::run() {
  if (const auto done = start()) return *done;
  for (;;) {
    const int it = sum_.iterations;
    if (const auto done = stop_before_step(it)) return *done;
    if (const auto done = factorize_unless_reused()) return *done;
    if (rounding_rows_.find(model_, ws_.phi, ws_.jacobian_values, ws_.q, opt_.tolerance, ws_.rhs.data(), it))
      rounding_rows_.kept_measures(model_, ws_.phi, &check_.merit, &check_.kept_worst);
    Step s;
    if (const auto done = newton_step(s)) return *done;
    if (s.refresh) {
      refresh_matrix();
      continue;
    }
    if (const auto done = line_search(s)) return *done;
    const bool within = check_.within;
    // At the rounding level: the residual already holds, and a full Newton step above the tolerance does not even
    // halve the merit (a step that corrects a real error of q shrinks a residual within tolerance by orders of
    // magnitude, stale matrix or not), nor leaves a next step a quarter its size (step_corrected_error: where the
    // merit is other rows' rounding). The step is then the rounding of Φ amplified by Φq⁻¹ — on a long chain
    // (10⁵ scissor stages) it exceeds the tolerance however often Newton repeats it — and it says how well q is
    // known. Stop at the better point of the two, with a warning, instead of refactorising in search of a
    // contraction that cannot come.
    const bool rounding_level =
        within && !step_ok_ && s.alpha == 1.0 && !(s.trial.merit < 0.5 * check_.merit) && !step_corrected_error(s);
    if (rounding_level && !(s.trial.within && s.trial.merit < check_.merit))
      return stop_at_rounding_level(false, s, it);
    // Within the level the previous positions are known to: the step is taken and ends the solve, as at a stop at
    // the rounding level (below), without the iterations that would only measure the rounding again.
    // Not where Φq is ill-conditioned: linear convergence there marks a singular position (a dead point), which
    // the sweep must still see.
    const bool within_known = s.known_ok && !step_ok_ && s.alpha == 1.0 && s.trial.within && !rounding_level &&
                              sum_.rcond >= detail::kLinearSingularRcond;
    if (s.refresh && !rounding_level && !within_known) {
      refresh_matrix();
      continue;
    }
    const bool step_from_factorization = accept(s);
    if (rounding_level || within_known) {
      // The step just taken is the rounding of Φ amplified by Φq⁻¹ (within known_to: that, and the start's own
      // error up to that level): it moved q by about as much as q is known, so the factorisation made where it
      // started is Φq at the solution to the accuracy q has. Velocities and accelerations reuse it rather than
      // refactorise (on a 10⁵-stage scissor lift a quarter of the rows stop here, and each paid a second
      // factorisation).
      factorized_at_rounding_level_ = step_from_factorization;
      return stop_at_rounding_level(within_known, s, it);
    }
  }
}

}  // namespace

SolveStatus solve_position(const Model& model, double t, const NewtonOptions& opt, Workspace& ws,
                           PositionSummary* summary) {
  check_workspace(model, ws);
  detail::check_newton_options(opt);
  PositionSummary local;
  PositionSummary& sum = summary ? *summary : local;
  sum = PositionSummary{};
  return PositionSolve(model, t, opt, ws, sum).run();
}

}  // namespace phiq
