// The sequential sweep's step loop: a Sweeper's construction, one drive step (advance(): predict, solve, check the
// branch, subdivide on failure) and the bookkeeping of a converged row (converged(), remember()). The predictor
// formulas it calls are in predictors.cpp, the singular-position checks in singular_positions.cpp.
#include "sweep/sweeper.hpp"

#include "phiq/text.hpp"
#include "solve/factorisation.hpp"
#include "sweep/predictors.hpp"

namespace phiq::detail {

Sweeper::Sweeper(const Model& m, const SweepOptions& o, Workspace& ws, SweepSummary& sum, const Sweeper* like)
    : model_(m), opt_(o), ws_(&ws), sum_(sum), effort_work_(dropped_efforts(), written_reactions(like)) {
  // Q's parts, gathered once a sweep and shared by its chunks' sweepers (`like`'s: set in its constructor, never
  // written after, so safe to share while it runs on another thread)
  if (opt_.efforts.active() && opt_.efforts.parts)
    effort_work_.forces =
        same_sweep(like) && like->effort_work_.forces
            ? like->effort_work_.forces
            : std::make_shared<const PartForces>(
                  *opt_.efforts.parts, model_,
                  rigid_bars() && (!effort_work_.reactions || effort_work_.reactions->rigid_bars()),
                  effort_work_.reactions ? effort_work_.reactions->planar_parts_read(opt_.efforts.parts->size())
                                         : std::vector<char>{});
  if (opt_.efforts.active() && opt_.efforts.loads && FrictionLosses::any(opt_.efforts.loads->applied.get())) {
    const bool copied = same_sweep(like) && like->effort_work_.losses;
    if (copied)  // (its set-up, as the reactions' and Q's parts are shared; its parameters checked there)
      effort_work_.losses.emplace(FrictionLosses::with_set_up_of(*like->effort_work_.losses));
    else
      effort_work_.losses.emplace(model_, *opt_.efforts.loads->applied, &opt_.efforts);
    // the efforts' ∂τ/∂p follow the losses along p where the constraints they read can be moved there
    if (!opt_.efforts.constraints.empty() && !copied)
      for (const OutputSensitivity& p : opt_.sensitivities)
        if (const std::string why = effort_work_.losses->sensitivity_refusal(model_, p); !why.empty()) throw Error(why);
  }
  // what Q's planar parts add, kept for the natural joints' reactions to read (row_reactions())
  if (effort_work_.reactions && opt_.efforts.natural && opt_.efforts.parts)
    effort_work_.planar.resize(opt_.efforts.parts->size());
  need_v_ = o.solves_velocities();  // (q̈ needs q̇)
  need_a_ = o.solves_accelerations();
  // With velocities every step factorises at its solution: Φq there comes with the residual that accepts it.
  newton_ = o.newton;
  newton_.jacobian_with_residual = o.newton.jacobian_with_residual || need_v_;
  predictor_ = effective_predictor(o.predictor, need_v_, need_a_);
  if (predictor_needs_accelerations(predictor_) && !need_a_)
    throw Error(std::string("the ") + to_string(predictor_) +
                " predictor needs accelerations (SweepOptions::accelerations)");
  if (predictor_needs_velocities(predictor_) && !need_v_)
    throw Error(std::string("the ") + to_string(predictor_) + " predictor needs velocities (SweepOptions::velocities)");
  // The rows before the current one that the predictor extrapolates from, and one more for its error estimate.
  // Every buffer the states rotate through has the workspace's size from the start, so that a swap never hands
  // the workspace an empty vector.
  const Index n = model_.num_coordinates();
  history_.size(predictor_history_depth(predictor_), n);
  current_.q = Eigen::VectorXd::Zero(n);
  if (need_v_) current_.qd = Eigen::VectorXd::Zero(n);
  if (need_a_) current_.qdd = Eigen::VectorXd::Zero(n);
}

// From the converged state at current_.t to t1, subdividing on failure. current_ (and the history) change only
// on success, so a failed attempt restores from them without copying any state on the way.
bool Sweeper::advance(double t1, int depth) {
  predict(t1);
  newton_.known_to = std::max(opt_.newton.known_to, known_to_);  // the caller's as a floor
  PositionSummary ps;
  SolveStatus st = solve_position(model_, t1, newton_, *ws_, &ps);
  // (a start accepted without a Newton step is the prediction itself: nothing moved off it)
  if (st == SolveStatus::kSuccess && depth < opt_.max_subdivisions && ps.iterations > 0 && jumped()) {
    // Newton went much farther than the step itself: it has left the branch (near a toggle or a bifurcation
    // a coarse step can land in the other branch's basin). Retried as half steps, as a failure is.
    st = SolveStatus::kNotConverged;
    ps.message = "Newton moved off the predicted path (another branch?)";
  }
  if (st == SolveStatus::kSuccess) {
    bool left_branch = false;
    if (converged(t1, ps, depth < std::min(kBranchCheckDepth, opt_.max_subdivisions) ? &left_branch : nullptr))
      return true;
    if (!left_branch) return false;
    // det Φq changed sign between two regular positions: the step crossed a singular position, or Newton landed
    // on another branch (a Cardan joint near its singular angle swings its output shaft so fast that the
    // extrapolation lands nearer the mode turned by π). Half steps tell them apart: they follow the branch, and
    // a crossing stays between two of them. It is accepted at the second level of halving, with a warning:
    // bisecting on towards it would only feed the predictor positions next to a singular Φq, whose q̈ are
    // rounding noise.
    st = SolveStatus::kNotConverged;
    ps.message = "det Φq changed sign with Φq regular at both ends (another branch?)";
  }
  if (st == SolveStatus::kSingularJacobian && has_current_ && !singular_.bracketing) {
    // a zero pivot exactly at a singular position: bracket it (position interpolated from both sides)
    if (singular_point(t1, 0.0, /*have_position=*/false)) {
      row_accuracy_.error = INFINITY;  // interpolated: the next step checks it
      row_accuracy_.coordinate = -1;
      remember(t1);
      return true;
    }
    ps.message = sum_.message;  // the diagnosis, should the sub-steps fail too
    sum_.status = SolveStatus::kSuccess, sum_.message.clear();
    restore();
  }
  // Retry as two half steps from the last good state; a singular or non-finite point is not cured by that
  // unless the sub-steps avoid it, so all statuses are retried.
  if (depth >= opt_.max_subdivisions) {
    const std::string why = ps.message;
    const std::string beyond =
        "no assembly beyond t = " + format_time(current_.t) + " (sub-steps down to t = " + format_time(t1) + " tried";
    if (const std::string undefined = undefined_at(t1); !undefined.empty())
      return fail(SolveStatus::kNonFinite, beyond + "): " + undefined);
    if (const std::string conflict = conflicting_redundancy(t1); !conflict.empty())
      return fail(SolveStatus::kInconsistent, beyond + "): " + conflict);
    const std::string dead = dead_point(t1);
    // (a derivative that does not exist says so itself: no guess at another cause)
    const bool no_derivative = st == SolveStatus::kNonFinite && why.rfind(detail::kNonFiniteJacobian, 0) == 0;
    sum_.worst_rows = ps.worst_rows;  // the last sub-step's position, the one `why` describes
    return fail(st, beyond +
                        (no_derivative  ? "): "
                         : dead.empty() ? ": the drive leaves the reachable range, or the mechanism "
                                          "passes a singular position): "
                                        : "): " + dead + "; ") +
                        why);
  }
  restore();
  if (depth == 0 && before_subdividing) before_subdividing(*this);
  ++sum_.subdivisions;
  const double tm = 0.5 * (current_.t + t1);
  return advance(tm, depth + 1) && advance(t1, depth + 1);
}

// A position converged at t: its warning, the derivatives asked for, and it becomes the current state. With
// `left_branch`, a position where det Φq has the other sign than at the current state (both regular, both
// factorised at their position) is refused instead, with *left_branch set and nothing of it kept: no warning,
// no count, no condition noted.
bool Sweeper::converged(double t, const PositionSummary& ps, bool* left_branch) {
  struct Noted {
    std::size_t warnings;
    Index singular_positions;
    double min_rcond, min_rcond_time, rounding_level, known_to;
    bool ill_conditioned;
  } const noted{sum_.warnings.size(), sum_.singular_positions, sum_.min_rcond,
                sum_.min_rcond_time,  rounding_level_,         known_to_,
                ill_conditioned_};
  // A position beyond the end of an open curve solves its equations (the end piece continues), but is no
  // position of the mechanism: the slot or profile ends there. (The sweep names the step and its time.)
  if (std::string off = model_.outside_domain(ws_->q.data()); !off.empty())
    return fail(SolveStatus::kOutsideDomain, off);
  singular_.at_row = false;
  last_rcond_ = ps.rcond;
  row_accuracy_.error = ps.error_estimate < 0.0 ? INFINITY : ps.error_estimate;
  row_accuracy_.coordinate = ps.error_coordinate, row_accuracy_.known_to = ps.error_size;
  // (a row accepted within NewtonOptions::known_to, the rounding level rows before it measured, is at that
  // level too, though its own Newton did not stop there: known to its estimate, not to the tolerance)
  row_accuracy_.row_class = ps.linear_convergence ? RowClass::kSingular
                            : ps.slow_convergence || row_accuracy_.error > kQuietRoundingLevel
                                ? RowClass::kRoundingLevel
                                : RowClass::kConverged;
  rounding_level_ = std::max(rounding_level_, ps.rounding_level);
  // How well the positions can be known here (NewtonOptions::known_to): the largest rounding level the rows
  // measured since the last one that converged to the tolerance (a step from a point Newton reached, not the
  // first step from a prediction, which corrects the prediction's own error too; nor a row that ended within
  // it). Dropped again as soon as a row converges to the tolerance.
  known_to_ = ps.rounding_measured                                   ? std::max(known_to_, ps.rounding_level)
              : ps.rounding_level == 0.0 && ps.error_estimate <= 1.0 ? 0.0
                                                                     : known_to_;
  if (ps.slow_convergence) sum_.warnings.push_back({t, "slow_convergence", ps.message});
  // Positions only: Φq is factorised at the solution where nothing else would tell the row's state, the first row
  // (a sweep that starts on a singular position; an assembly accepted as placed factorises nowhere) and the last
  // (a crossing in the last step: the rows before it reuse a factorisation made before it).
  double rcond = ps.rcond;
  const bool first = !has_current_;
  if (!need_v_ && !singular_.bracketing && !position_only_ && ws_->lu && (first || t == opt_.t_end)) {
    if (!factors_at_q(*ws_, t)) {
      std::string why;
      const SolveStatus st = ensure_factorized(model_, t, *ws_, &rcond, &why);
      if (st != SolveStatus::kSuccess && st != SolveStatus::kSingularJacobian) return fail(st, why);
      if (st == SolveStatus::kSingularJacobian) rcond = 0.0;
      ws_->factorized_q = ws_->q;
    } else {
      rcond = ws_->lu->rcond();
    }
    ws_->factorized_at_solution = true;
  }
  if (!need_v_ && first && !singular_.bracketing && ws_->lu && rcond < kSingularRcond) {
    // positions only, starting on a singular position: no past rows tell the next step where the branch goes, and
    // Newton from the singular position itself meets a zero pivot. The branch's q̇ and q̈ there are found as with
    // velocities (singular_point(), with its warning) and kept for the first prediction only.
    if (!singular_point(t, rcond)) return false;
  } else if (!need_v_ && rcond > 0.0 && rcond < kSingularRcond) {
    // positions only: nothing is computed from Φq here, but the user is told where the motion branches
    ++sum_.singular_positions;
    singular_.at_row = true;
    std::ostringstream m;
    m.precision(3);
    m << "singular position (Φq rcond " << rcond << "): a bifurcation, velocities would not be unique here";
    if (!has_current_) m << " (the sweep starts here: the branch is the one nearest the placement)";
    sum_.warnings.push_back({t, "bifurcation", m.str()});
  }
  if (!position_only_ && !derivatives(t, ps.linear_convergence)) return false;
  const Orientation sign = sign_at_solution();
  if (left_branch && has_current_ && sign.regular() && signs_.current.regular() && sign != signs_.current) {
    sum_.warnings.resize(noted.warnings);
    sum_.singular_positions = noted.singular_positions;
    sum_.min_rcond = noted.min_rcond, sum_.min_rcond_time = noted.min_rcond_time;
    rounding_level_ = noted.rounding_level, known_to_ = noted.known_to, ill_conditioned_ = noted.ill_conditioned;
    *left_branch = true;
    return false;
  }
  if (ws_->counters.factorizations != factorizations_seen_)  // this step's solves factorised
    factorizations_seen_ = ws_->counters.factorizations, factorized_step_t_ = t;
  signs_.current = sign;
  // the row's sign: the one at the solution, else (positions only) that of the last factorisation this sweeper
  // made, at an iterate a few steps back on its own path, so that a change is seen a row or two late rather than
  // not at all, with the time of the step that made it; never that of a factorisation the workspace held before
  // (another chunk's, or another sweep's: the sign of another place)
  const bool own = ws_->counters.factorizations != factorizations_before_;
  signs_.current_row = sign.sign != kSignUnknown || !own ? sign : orientation_of(*ws_->lu);
  signs_.current_row_t = sign.sign != kSignUnknown ? t : factorized_step_t_;
  remember(t);
  return true;
}

void Sweeper::remember(double t) {
  // The quantity the predictor extrapolates, at the current row, moves into the history (by buffer swaps: the
  // oldest entry's buffer becomes current_'s, assigned below without allocating). Only a state that was really
  // converged enters it (the default-constructed one has no q: found by the fuzzer with a sweep starting away
  // from t = 0).
  if (has_current_) {
    Eigen::VectorXd& x = predictor_ == Predictor::kLinear                                         ? current_.qd
                         : predictor_ == Predictor::kQuadratic || predictor_ == Predictor::kCubic ? current_.qdd
                                                                                                  : current_.q;
    history_.push(x, current_.t, current_accuracy_.error);
  }
  has_current_ = true;
  current_.t = t;
  current_accuracy_.error = row_accuracy_.error;
  current_accuracy_.coordinate = row_accuracy_.coordinate, current_accuracy_.known_to = row_accuracy_.known_to;
  current_accuracy_.row_class = singular_.at_row ? RowClass::kSingular : row_accuracy_.row_class;
  // The converged state moves into current_ by swaps too: ws keeps the buffers of the state before, which the
  // next step overwrites (predict() writes q, the solves q̇ and q̈). Rows are delivered from state().
  current_.q.swap(ws_->q);
  if (need_v_) current_.qd.swap(ws_->qd);
  if (need_a_) current_.qdd.swap(ws_->qdd);
}

void Sweeper::restore() {
  ws_->q = current_.q;
  if (need_v_) ws_->qd = current_.qd;
  if (need_a_) ws_->qdd = current_.qdd;
}

Workspace* Sweeper::row_factors() {
  const double t = current_.t;
  Workspace* w = ws_;
  // With velocities the row's velocity solve has just used the workspace's factors (of Φq at this row's solution,
  // or at Newton's last iterate within the tolerance of it): the row's other solves use the same ones.
  if (!(ws_->lu && row_factors_.derivatives.ws == ws_ && row_factors_.derivatives.t == t &&
        row_factors_.derivatives.factorizations == ws_->counters.factorizations)) {
    if (!row_factors_.own) row_factors_.own = std::make_shared<Workspace>(model_);
    w = row_factors_.own.get();
    if (!w->lu) return nullptr;
    w->q = current_.q;  // (factorised again only if its factors are not at this row already: sensitivities')
    const WorkCounters before = w->counters;
    double rc = 0.0;
    std::string why;
    const SolveStatus st = ensure_factorized(model_, t, *w, &rc, &why);
    ws_->counters.jacobian_evaluations += w->counters.jacobian_evaluations - before.jacobian_evaluations;
    ws_->counters.factorizations += w->counters.factorizations - before.factorizations;
    if (st != SolveStatus::kSuccess) return nullptr;
  }
  return w->lu->rcond() >= kSingularRcond ? w : nullptr;
}

void Sweeper::row_sensitivities() {
  // NaN where they are not defined (sensitivities_with_factors() writes every value itself otherwise).
  auto not_defined = [&] {
    std::fill(outputs_.sensitivities.begin(), outputs_.sensitivities.end(), std::numeric_limits<double>::quiet_NaN());
  };
  // At a singular position Φq has no inverse (the row's bifurcation warning says where).
  if (singular_.at_row) return not_defined();
  Workspace* w = row_factors();
  if (!w) return not_defined();
  const double t = current_.t;
  const int order = need_a_ ? 2 : need_v_ ? 1 : 0;
  const Index solves_before = w->counters.sensitivity_solves, direct_before = w->counters.sensitivity_direct_rows;
  const double* qd = order >= 1 ? current_.qd.data() : nullptr;
  const double* qdd = order >= 2 ? current_.qdd.data() : nullptr;
  const bool ok =
      sensitivity_work_.form == SensitivityForm::kAdjoint
          ? adjoint_sensitivities_with_factors(model_, opt_.sensitivities, sensitivity_work_.outputs, t,
                                               current_.q.data(), qd, qdd, order, *w->lu, *w, sensitivity_work_.scratch,
                                               outputs_.sensitivities.data())
          : sensitivities_with_factors(model_, opt_.sensitivities, t, current_.q.data(), qd, qdd, order, *w->lu, *w,
                                       sensitivity_work_.scratch, outputs_.sensitivities.data());
  if (w != ws_) {
    ws_->counters.sensitivity_solves += w->counters.sensitivity_solves - solves_before;
    ws_->counters.sensitivity_direct_rows += w->counters.sensitivity_direct_rows - direct_before;
  }
  if (!ok) not_defined();
}

}  // namespace phiq::detail
