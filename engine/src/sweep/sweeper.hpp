// Sweeper: the sequential sweep's stepper, which follows one branch of the motion from row to row (its state, the
// predictor's history, the step subdivision and the singular-position checks), and the state and orientation of Φq
// it carries. A sweep runs one; a parallel sweep runs one per chunk and one for the seeds (parallel_sweep.cpp).
// Its members are defined by concept: the step loop in sweeper.cpp, the predictor formulas in predictors.cpp,
// singular positions and dead points in singular_positions.cpp, the other causes of a failed step in
// step_failures.cpp. The small members that run on every step are defined here, in the class, so that the step
// loop inlines them. Its state is held in the parts it falls into (sweeper_parts.hpp: the predictor's history, the
// accuracy of a row, the singular-position state, the orientation of Φq, the outputs' values and buffers).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "phiq/joint_reactions.hpp"
#include "phiq/sweep.hpp"
#include "solve/assembly_internal.hpp"
#include "solve/kinematics_internal.hpp"
#include "solve/minimum_norm.hpp"
#include "solve/sensitivity_internal.hpp"
#include "solve/tolerance_tests.hpp"
#include "sweep/sweeper_parts.hpp"

namespace phiq::detail {

// A converged row: its time, q, and q̇, q̈ where the sweep solves them.
struct State {
  double t = 0.0;
  Eigen::VectorXd q, qd, qdd;
};

// The motions of a row's outputs beyond q, q̇, q̈ (each null when none are asked for): the points', the joints'
// (angles wrapped; the delivery unwraps them), the orientations' and the sensitivities (SensitivityLayout).
struct RowMotions {
  const PointMotion* points = nullptr;
  const JointMotion* joints = nullptr;
  const OrientationMotion* orientations = nullptr;
  const double* sensitivities = nullptr;
  const double* efforts = nullptr;  // effort_values() values
};

// A delivered row's class and its estimated error (units of the tolerance test; infinite when no solve estimated it).
struct RowQuality {
  RowClass row_class = RowClass::kConverged;
  double error = INFINITY;
  const std::string* coordinate = nullptr;  // where `error` is reached (a name of the model's), null if not said
  double known_to = 0.0;                    // `error` in that coordinate's unit
  Unit unit = Unit::kNone;                  // that unit
};
// Adds a delivered row at t to the summary's accuracy.
inline void add_row_quality(SweepAccuracy& a, double t, const RowQuality& r) {
  RowClassAccuracy& c = r.row_class == RowClass::kConverged       ? a.converged
                        : r.row_class == RowClass::kRoundingLevel ? a.rounding_level
                                                                  : a.singular;
  ++c.rows;
  if (!std::isfinite(r.error))
    ++c.unestimated;
  else if (r.error > c.worst_error) {
    c.worst_error = r.error, c.worst_time = t;
    if (r.coordinate)
      c.worst_coordinate = *r.coordinate, c.worst_known_to = r.known_to, c.worst_unit = r.unit;
    else
      c.worst_coordinate.clear(), c.worst_known_to = 0.0, c.worst_unit = Unit::kNone;
  }
}

struct SingularSides;  // the regular points around a singular position (singular_positions.cpp)

// Follows one branch of the motion step by step from an assembled or adopted state (see the file comment).
class Sweeper {
 public:
  // Resolves the predictor (effective_predictor) and refuses one whose derivatives the options do not ask for;
  // sizes every buffer the states rotate through (sweeper.cpp).
  // `like`, when given, a sweeper of the same model and options (a sweep's first, which its chunks' sweepers run
  // next to): the efforts' set-up is copied from it rather than built again (8 chunks a sweep at 100 steps).
  Sweeper(const Model& m, const SweepOptions& o, Workspace& ws, SweepSummary& sum, const Sweeper* like = nullptr);

  // Below this reciprocal condition estimate of Φq (KLU: min/max |U_ii|, UMFPACK alike) the position is taken
  // as singular: a linear solve there loses more than ten digits, so the velocity the LU gives is rounding noise
  // in the directions Φq no longer constrains. Regular positions of the models in models/ stay above 1e-6 at any
  // size (nfourbar: 2.5e-4 … 2.5e-6 from N = 10 to 10^5, size-independent); the exactly singular ones of nfourbar
  // fall to 1e-13.
  static constexpr double kSingularRcond = 1e-10;
  // Below this (and above kSingularRcond) the position is near-singular (a toggle position nearby): the results
  // hold, but with fewer digits; a warning says so, once per stretch of such steps.
  static constexpr double kIllConditionedRcond = 1e-7;
  // A step across which det Φq changes sign is halved, and halved again, to see whether the change stays (a
  // singular position crossed) or goes (another branch reached): see advance().
  static constexpr int kBranchCheckDepth = 2;

  // Derivatives at the converged ws.q, as asked for. Returns false (summary filled) on failure. At a singular
  // position they are not unique: see singular_point(). `linear`: Newton converged only linearly to ws.q (its full
  // steps contracting by ½ or worse), the mark of a singular Φq at the solution. It then stopped within the
  // tolerance of Φ but only about √tol from the singular position itself (Φ is quadratic along the direction Φq
  // loses), so rcond stays near √tol, far above kSingularRcond, while q̇ from that Φq is dominated by the position's
  // error: a row landing on a dead point (a drive range ending where coupler and rocker align) gave |q̇| = 5e6 with
  // the exact speed unbounded. Such a row, when Φq is also ill-conditioned, is examined as a singular one.
  bool derivatives(double t, bool linear = false) {
    if (!need_v_) return true;
    LinearSummary ls;
    const SolveStatus st = lu_derivatives(t, need_a_, &ls);
    if (!singular_.bracketing && ws_->lu &&
        (st == SolveStatus::kSingularJacobian ||
         (st == SolveStatus::kSuccess &&
          (ls.rcond < kSingularRcond || (linear && ls.rcond < detail::kLinearSingularRcond)))))
      return singular_point(t, ls.rcond);
    if (st != SolveStatus::kSuccess) return fail(st, ls.message);
    note_condition(t, ls.rcond);
    row_factors_.derivatives = {ws_, ws_->counters.factorizations, t};
    return true;
  }

  // The outputs of time point k beyond q, q̇, q̈, from the converged state in ws: the listed points' motions
  // (counted) and the condition estimate (Φ is ws.phi already), for a row the output plan writes
  // (OutputPlan::writes_row); the orientation of Φq for every time point (the bifurcation check between rows).
  // Only written rows pay for the outputs: sub-steps, the seam steps of parallel chunks and the rows between
  // written ones do not.
  // Joint measures are evaluated at every time point, written or not: the delivery unwraps angles row to row.
  // False, with the cause (fail()), where the efforts overflow (row_efforts()): the row is no result.
  bool row_outputs(Index k) {
    const double* qd = need_v_ ? current_.qd.data() : nullptr;
    const double* qdd = need_a_ ? current_.qdd.data() : nullptr;
    for (std::size_t i = 0; i < opt_.joints.size(); ++i)
      outputs_.joints[i] = evaluate_joint(opt_.joints[i], current_.q.data(), qd, qdd);
    if (opt_.writes_row(k, current_.t)) {
      for (std::size_t i = 0; i < opt_.points.size(); ++i)
        outputs_.points[i] = evaluate_point(opt_.points[i], current_.q.data(), qd, qdd);
      for (std::size_t i = 0; i < opt_.orientations.size(); ++i)
        outputs_.orientations[i] =
            evaluate_orientation(opt_.orientations[i], opt_.orientation_form, current_.q.data(), qd, qdd);
      ws_->counters.point_evaluations += static_cast<Index>(opt_.points.size());
      outputs_.rcond = opt_.condition && ws_->lu ? ws_->lu->rcond() : 0.0;
      if (!opt_.sensitivities.empty()) row_sensitivities();
      if (opt_.efforts.active() && !row_efforts()) return false;
    }
    signs_.delivered = signs_.current_row;
    signs_.delivered_t = signs_.current_row_t;
    return true;
  }
  // Orientation of Φq at the last delivered row (row_outputs()): sign ±1, 0 at a singular position, kSignUnknown
  // where no factorisation of this sweeper's tells it; and the time it holds at (det_sign_time(): the row's, or
  // with positions only that of the step whose Newton factorised last).
  Orientation det_sign() const { return signs_.delivered; }
  double det_sign_time() const { return signs_.delivered_t; }
  // The last converged state (q, and q̇, q̈ as computed), which the rows deliver.
  const State& state() const { return current_; }
  // Solves with `w` from now on: the state and the history are the sweeper's, a workspace holds only the solves'
  // scratch and an LU (whichever factorisation it holds is a start for modified Newton, which refreshes it when it
  // contracts badly). A parallel sweep's seeding pass takes whichever workspace is free for each seed.
  void bind(Workspace& w) {
    ws_ = &w;
    factorizations_before_ = factorizations_seen_ = w.counters.factorizations;
  }
  // Takes the branch tangent `from` found at a singular position where its state is (positions only: what the next
  // step predicts along, singular_point()), for a sweeper that adopts that state: a chunk that continues row 0.
  void take_branch_tangent(Sweeper& from) {
    singular_.branch_qd.swap(from.singular_.branch_qd), singular_.branch_qdd.swap(from.singular_.branch_qdd);
    singular_.branch_t = from.singular_.branch_t;
  }
  // Moves the last converged state out and frees the history: the sweeper is not used after this.
  State take_state() {
    history_.rows.clear(), history_.rows.shrink_to_fit();
    prediction_.q = Eigen::VectorXd();
    return std::move(current_);
  }
  // Leaves the last converged state in the workspace too, as a sweep ends (the caller's workspace ends at the
  // last delivered row).
  void leave_state_in_workspace() {
    if (!has_current_) return;
    ws_->q = current_.q;
    if (need_v_) ws_->qd = current_.qd;
    if (need_a_) ws_->qdd = current_.qdd;
  }
  // The largest PositionSummary::rounding_level of the positions converged since the last call (0: none stopped
  // at the rounding level): how far from the exact solution, in tolerances, they may be.
  double take_rounding_level() { return std::exchange(rounding_level_, 0.0); }
  const PointMotion* point_motions() const { return outputs_.points.empty() ? nullptr : outputs_.points.data(); }
  // The motions row_outputs() evaluated, for the delivery.
  RowMotions motions() const {
    return {point_motions(), outputs_.joints.empty() ? nullptr : outputs_.joints.data(),
            outputs_.orientations.empty() ? nullptr : outputs_.orientations.data(),
            outputs_.sensitivities.empty() ? nullptr : outputs_.sensitivities.data(),
            outputs_.efforts.empty() ? nullptr : outputs_.efforts.data()};
  }
  double rcond() const { return outputs_.rcond; }

  // Records the cause; run_sweep prefixes the step and its grid time (the sub-step time, if any, is in `why`).
  bool fail(SolveStatus st, const std::string& why) {
    sum_.status = st;
    sum_.message = why;
    return false;
  }

  // First row of a parallel chunk: the position at t from a seed that solves it (up to the seeding pass's
  // tolerance), then the derivatives, as any converged step.
  // `seed_error`: the seed's own estimated error (the seeding pass's PositionSummary::error_estimate; infinite if
  // unknown), so that a seed found to the tolerance is taken without a Newton step, as a predicted start is. The
  // seam check (the previous chunk, continued in order, must arrive at this row) guards the chunk either way.
  bool start_from(double t, const Eigen::VectorXd& seed, double seed_error) {
    ws_->q = seed;
    newton_.start_error = seed_error;
    PositionSummary ps;
    SolveStatus st = solve_position(model_, t, newton_, *ws_, &ps);
    if (st != SolveStatus::kSuccess) {
      sum_.worst_rows = ps.worst_rows;
      return fail(st, ps.message);
    }
    return converged(t, ps);
  }

  // Whether Φq was near-singular (rcond below kIllConditionedRcond) where the last position converged, as far as
  // the last Newton factorisation of it tells (false when it made none).
  bool near_singular() const { return last_rcond_ > 0.0 && last_rcond_ < kIllConditionedRcond; }

  // The estimated error of state().q (units of the tolerance test; infinite when unknown).
  double state_error() const { return current_accuracy_.error; }
  // What the delivered row of state() says of its accuracy (SweepAccuracy): its class and estimated error.
  RowQuality row_quality() const {
    if (current_accuracy_.coordinate < 0) return {current_accuracy_.row_class, current_accuracy_.error};
    return {current_accuracy_.row_class, current_accuracy_.error,
            &model_.coordinate_names()[static_cast<std::size_t>(current_accuracy_.coordinate)],
            current_accuracy_.known_to, model_.coordinate_unit(current_accuracy_.coordinate)};
  }
  // One more step to t1 for its position only (a parallel chunk's seam, compared with the next chunk's first row):
  // no derivatives, no outputs.
  bool advance_position(double t1) {
    position_only_ = true;
    const bool ok = advance(t1, 0);
    position_only_ = false;
    return ok;
  }

  // Continues from the converged state in ws (q, and q̇, q̈ where asked for) at t, as if this sweeper had reached
  // it (the secant predictor's history starts anew).
  void adopt(double t) {
    has_current_ = false;
    history_.known = 0;
    signs_.current = signs_.current_row = Orientation{};
    row_accuracy_.error = INFINITY;  // how well the adopted state is known is not said: the next step checks it
    row_accuracy_.coordinate = -1;
    remember(t);
  }

  // The LU's q̇ (and q̈) at ws.q: the position the last solve_position converged to (`just_solved`: its factorisation
  // or Jacobian values are taken as they are, detail::derivatives_at_solution), or any other (the public solves,
  // which compare points).
  SolveStatus lu_derivatives(double t, bool accelerations, LinearSummary* ls, bool just_solved = true) {
    if (just_solved) return detail::derivatives_at_solution(model_, t, *ws_, accelerations, ls);
    SolveStatus st = solve_velocity(model_, t, *ws_, ls);
    if (st == SolveStatus::kSuccess && accelerations) st = solve_acceleration(model_, t, *ws_, ls);
    return st;
  }

  void note_min_rcond(double t, double rc) {
    if (sum_.min_rcond == 0.0 || rc < sum_.min_rcond) sum_.min_rcond = rc, sum_.min_rcond_time = t;
  }
  void note_condition(double t, double rc) {
    note_min_rcond(t, rc);
    const bool ill = rc < kIllConditionedRcond;
    if (ill && !ill_conditioned_) {
      std::ostringstream m;
      m.precision(2);
      m << "Φq is near-singular (rcond " << rc << " < " << kIllConditionedRcond
        << "): a toggle or singular position is near; velocities and accelerations keep about "
        << static_cast<int>(std::floor(std::log10(rc / 2.2e-16))) << " digits";
      sum_.warnings.push_back({t, "ill_conditioned", m.str()});
    }
    ill_conditioned_ = ill;
  }

  // Initial position problem from the rough placement in ws.q.
  // The placement is taken only after a Newton step from it is within the tolerance (start_error unknown becomes
  // infinite): a residual within tolerance alone does not bound the error of q where the scales of the rows differ
  // by orders of magnitude (a 10⁶ m coupler's row holds to 10⁻⁴ m, more than a 10⁻⁶ m crank it carries). Where
  // no step can be taken (a placement exactly on a singular position: a zero pivot) the placement is judged on its
  // residual, as given, and the singular start is examined as such (converged()).
  bool assemble(double t) {
    NewtonOptions o = opt_.assembly;
    SolveStatus st = SolveStatus::kSingularJacobian;
    if (o.start_error < 0.0) {
      const Eigen::VectorXd placement = ws_->q;
      o.start_error = INFINITY;
      st = solve_position(model_, t, o, *ws_, &sum_.assembly);
      if (st == SolveStatus::kSingularJacobian) ws_->q = placement, o.start_error = opt_.assembly.start_error;
    }
    if (st == SolveStatus::kSingularJacobian) st = solve_position(model_, t, o, *ws_, &sum_.assembly);
    if (st != SolveStatus::kSuccess) {
      sum_.worst_rows = sum_.assembly.worst_rows;
      return fail(st, "initial assembly failed: " + sum_.assembly.message);
    }
    return converged(t, sum_.assembly);
  }

  // One drive step from the current state to t1 (`depth`: how many times it has been halved), subdividing on
  // failure, with the branch and singular-position checks (sweeper.cpp).
  bool advance(double t1, int depth);
  // Called in advance() once per drive step, before its first subdivision, with the sweeper as it stands then (at
  // the last good state, the failed attempt's diagnosis noted): a Stepper keeps a copy to return to should the
  // sub-steps fail too, after some of them converged (stepper.cpp). Empty in sweeps, which stop at a failure.
  std::function<void(const Sweeper&)> before_subdividing;

 private:
  // A position converged at t becomes the current state (sweeper.cpp).
  bool converged(double t, const PositionSummary& ps, bool* left_branch = nullptr);
  // Orientation of Φq at the position just converged (ws.q): from the LU when it was factorised there (velocities
  // are solved at every row; positions only, when Newton's last factorisation is at the solution), sign 0 at a
  // singular position, else kSignUnknown.
  Orientation sign_at_solution() const {
    if (singular_.at_row) return {0, 0};
    if (!ws_->lu || !ws_->has_factorization) return {};
    const bool at_solution = (need_v_ && !position_only_) || ws_->factorized_at_solution;
    return at_solution ? orientation_of(*ws_->lu) : Orientation{};
  }
  // Whether the converged ws.q is farther from the prediction than the prediction is from the last state (in
  // tolerance units, beyond a floor of 1000 tolerances): a predictor errs by a higher order of h than the O(h)
  // move, so a correction as large as the move means another solution was found. Runs every drive step: one pass
  // for the correction, and one for the move only when the correction is large at all.
  bool jumped() {
    if (!prediction_.moved) return false;  // the previous position: nothing predicted
    const double tol = opt_.newton.tolerance;
    const double correction = detail::scaled_distance(model_, ws_->q.data(), prediction_.q.data(), ws_->q.data(), tol);
    if (!(correction > 1000.0)) return false;
    return correction >
           0.5 * detail::scaled_distance(model_, prediction_.q.data(), current_.q.data(), current_.q.data(), tol);
  }

  // ws.q = the predictor's guess at t1, newton_.start_error = its error estimate (predictors.cpp).
  void predict(double t1);
  // The converged state in ws becomes current_, the one before enters the history (sweeper.cpp).
  void remember(double t);
  // ws = the current state again, after a failed attempt (sweeper.cpp).
  void restore();

  // The sensitivities of the current state to the plan's parameters (outputs_.sensitivities), solved with the factors
  // of Φq at its position: the workspace's when the row's velocity solve used them, else a factorisation of its own
  // (positions only), which leaves the workspace's, and so the next steps' bits, as they are (sweeper.cpp).
  void row_sensitivities();
  // The plan's driver efforts and powers at the current state (outputs_.efforts), by one transposed solve with the same
  // factors as row_sensitivities() (row_efforts.cpp); NaN at a singular position. False, with the cause (fail()),
  // where the parts' forces or the multipliers are not finite away from one (masses or loads that overflow).
  bool row_efforts();
  // The efforts (indices into OutputEfforts::constraints) of drivers the model dropped as redundant: NaN at every
  // row, found once (row_efforts.cpp).
  std::vector<std::size_t> dropped_efforts() const;
  // The joints whose reactions are written (none when none are), with `like`'s set-up when it has one.
  std::optional<JointReactions> written_reactions(const Sweeper* like) const;
  // Whether `like` (may be null) sweeps this sweeper's model with its options: its set-up is this one's.
  bool same_sweep(const Sweeper* like) const;
  // Whether Q takes rigid bars' constant mass matrices (solve/part_forces.hpp): unless ∂τ/∂p is asked, whose formula
  // holds with the frames' motion's Q alone. Q and the reactions read it alike.
  // (not with a natural point's bearing either: its reaction, solved with λ in passes, reads Q in the frames'
  // motion's form, FrictionLosses::at_points())
  bool rigid_bars() const {
    return opt_.sensitivities.empty() &&
           !FrictionLosses::at_points(model_, opt_.efforts.loads ? opt_.efforts.loads->applied.get() : nullptr);
  }
  // The reactions of the row (after the efforts) from effort_work_.lambda: minimum-norm multipliers first where rows
  // were dropped, and at the sweep's first row a warning naming the joints whose share that makes up.
  void row_reactions(SparseLuNumeric& lu);
  // The warnings about the meshes: at every row, the first of found.working (gear_centres) and of found.slack
  // (belt_slack); at the first row, the meshes whose bearings carry none of their push (unloaded_bearings).
  void warn_meshes(const MeshFindings& found, bool first_row);
  // The factors of Φq at the current row: the workspace's when the row's velocity solve has just used them, else
  // those of row_factors_.own, factorised at the row; null where Φq is singular or cannot be factorised.
  Workspace* row_factors();
  // Singular positions (singular_positions.cpp): the branch's own derivatives at one, and why Φq stays singular
  // around one or no position lies beyond it (a dead point).
  std::string singular_throughout(const Eigen::VectorXd& qs, double t);
  bool singular_point(double t, double rc, bool have_position = true);
  // singular_point()'s phases: the first side solved block by block at a singular start, the six sides, the
  // first of them from a singular start, and the branch's values at t from them with the warning.
  bool start_by_blocks(double t, double step, const Eigen::VectorXd& qs, const NewtonOptions& tight);
  bool solve_sides(double t, double rc, const Eigen::VectorXd& qs, const std::string& lined_up,
                   const NewtonOptions& tight, SingularSides& s);
  bool reach_first_side(double t, double ts, double rc, const Eigen::VectorXd& qs, bool by_blocks,
                        const NewtonOptions& tight, PositionSummary& ps);
  bool take_branch_values(double t, double rc, bool have_position, const Eigen::VectorXd& qs, const SingularSides& s);
  std::string dead_point(double t1);
  std::string lined_up_equations();
  // The other causes of a step that failed at every subdivision (step_failures.cpp).
  std::string undefined_at(double t1);
  std::string conflicting_redundancy(double t1);

  const Model& model_;
  const SweepOptions& opt_;
  Workspace* ws_;  // the workspace the solves use (bind())
  SweepSummary& sum_;
  bool need_v_ = false, need_a_ = false;
  NewtonOptions newton_;  // opt_.newton, with jacobian_with_residual when velocities follow
  Predictor predictor_;
  State current_;  // the last converged state
  bool has_current_ = false;
  PredictorHistory history_;                // the rows before current_ that predict() extrapolates from
  LastPrediction prediction_;               // and what it predicted last (for jumped())
  RowAccuracy current_accuracy_;            // how well current_.q is known (remember(): a singular row is kSingular)
  RowAccuracy row_accuracy_;                // that of the row being converged, until remember() makes it current
  bool position_only_ = false;              // inside advance_position()
  RowOutputValues outputs_{model_, opt_};   // what row_outputs() evaluated, for the delivery
  SensitivityWork sensitivity_work_{opt_};  // row_sensitivities()'s own, as a thread's sweeper holds them
  // row_efforts()' and row_reactions()'
  EffortWork effort_work_;
  RowFactorCache row_factors_;  // the factors those solve with (row_factors())
  double last_rcond_ = 0.0;     // PositionSummary::rcond of the last converged position (near_singular())
  SingularState singular_;      // singular_point()'s
  BranchOrientation signs_;     // of Φq along the branch (det_sign(), converged())
  // The workspace's factorisation count when this sweeper took it: the ones after it are its own (converged()).
  Index factorizations_before_ = ws_->counters.factorizations;
  Index factorizations_seen_ = factorizations_before_;  // the count at the last converged state
  double factorized_step_t_ = 0.0;  // the time of the last step whose solves factorised (converged())
  double rounding_level_ = 0.0;     // see take_rounding_level()
  double known_to_ = 0.0;           // the rounding level carried to the next solves (converged())
  bool ill_conditioned_ = false;    // the last delivered state was near-singular (one warning per stretch)
  double default_step_ = (opt_.t_end - opt_.t_begin) / static_cast<double>(std::max<Index>(opt_.steps, 1));
};

}  // namespace phiq::detail
