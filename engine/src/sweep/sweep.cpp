#include "phiq/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iomanip>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>

#include <unistd.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "solve/kinematics_internal.hpp"
#include "phiq/assembly.hpp"
#include "sweep/time_grid.hpp"
#include "sweep/warning_stretches.hpp"
#include "solve/tolerance_tests.hpp"

namespace phiq {

const char* to_string(Predictor p) {
  switch (p) {
    case Predictor::kAuto: return "auto";
    case Predictor::kPrevious: return "previous";
    case Predictor::kSecant: return "secant";
    case Predictor::kLinear: return "linear";
    case Predictor::kQuadratic: return "quadratic";
    case Predictor::kCubic: return "cubic";
    case Predictor::kParabolic: return "parabolic";
    case Predictor::kHermite: return "hermite";
  }
  return "?";
}

const std::vector<Predictor>& all_predictors() {
  static const std::vector<Predictor> all = {Predictor::kAuto,     Predictor::kPrevious, Predictor::kSecant,
                                             Predictor::kParabolic, Predictor::kLinear,   Predictor::kHermite,
                                             Predictor::kQuadratic, Predictor::kCubic};
  return all;
}

bool predictor_from_string(const std::string& name, Predictor* p) {
  for (Predictor k : all_predictors())
    if (name == to_string(k)) return *p = k, true;
  return false;
}

const char* predictor_names() {
  static const std::string names = [] {
    const std::vector<Predictor>& all = all_predictors();
    std::string s;
    for (std::size_t i = 0; i < all.size(); ++i)
      s += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + std::string(to_string(all[i]));
    return s;
  }();
  return names.c_str();
}

Predictor effective_predictor(Predictor p, bool velocities, bool accelerations) {
  if (p != Predictor::kAuto) return p;
  return accelerations ? Predictor::kCubic : velocities ? Predictor::kHermite : Predictor::kParabolic;
}

bool predictor_needs_velocities(Predictor p) {
  return p == Predictor::kLinear || p == Predictor::kHermite || predictor_needs_accelerations(p);
}

bool predictor_needs_accelerations(Predictor p) { return p == Predictor::kQuadratic || p == Predictor::kCubic; }

namespace {

struct State {
  double t = 0.0;
  Eigen::VectorXd q, qd, qdd;
};

// A sign of det Φq is ±1 at a regular position and 0 at a singular one; kSignUnknown where no factorisation tells
// it (positions only, a start accepted from its prediction).
constexpr int kSignUnknown = 2;

// Which way Φq is oriented at a factorisation: det Φq's sign, and at a regular position the fingerprint of the
// signs of its diagonal blocks' determinants (SparseLuNumeric::block_signs(): KLU factorises a chain loop by
// loop). Along a branch it changes exactly where the motion passes a singular position: det Φq's sign alone misses
// an even number of loops crossing at once (nfourbar of even N through its flat position), the blocks do not.
struct Orientation {
  int sign = kSignUnknown;
  std::uint64_t blocks = 0;
  bool regular() const { return sign == 1 || sign == -1; }
  bool operator==(const Orientation& o) const { return sign == o.sign && blocks == o.blocks; }
  bool operator!=(const Orientation& o) const { return !(*this == o); }
};
Orientation orientation_of(const SparseLuNumeric& lu) {
  const int sign = lu.determinant_sign();
  return {sign, sign == 1 || sign == -1 ? lu.block_signs() : 0};
}

class Sweeper {
 public:
  Sweeper(const Model& m, const SweepOptions& o, Workspace& ws, SweepSummary& sum)
      : model_(m), opt_(o), ws_(&ws), sum_(sum) {
    need_v_ = o.velocities || o.accelerations;  // q̈ needs q̇
    need_a_ = o.accelerations;
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
    switch (predictor_) {
      case Predictor::kPrevious: depth_ = 1; break;
      case Predictor::kSecant: depth_ = 2; break;
      case Predictor::kParabolic: depth_ = 3; break;
      case Predictor::kHermite: depth_ = 3; break;
      case Predictor::kLinear: depth_ = 1; break;
      case Predictor::kQuadratic: depth_ = 1; break;
      case Predictor::kCubic: depth_ = 2; break;
      case Predictor::kAuto: break;
    }
    // Every buffer the states rotate through has the workspace's size from the start, so that a swap never hands
    // the workspace an empty vector.
    const Index n = model_.num_coordinates();
    history_.assign(static_cast<std::size_t>(depth_), Eigen::VectorXd::Zero(n));
    history_t_.resize(static_cast<std::size_t>(depth_));
    history_error_.resize(static_cast<std::size_t>(depth_));
    current_.q = Eigen::VectorXd::Zero(n);
    if (need_v_) current_.qd = Eigen::VectorXd::Zero(n);
    if (need_a_) current_.qdd = Eigen::VectorXd::Zero(n);
  }

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
    if (!bracketing_ && ws_->lu &&
        (st == SolveStatus::kSingularJacobian ||
         (st == SolveStatus::kSuccess &&
          (ls.rcond < kSingularRcond || (linear && ls.rcond < detail::kLinearSingularRcond)))))
      return singular_point(t, ls.rcond);
    if (st != SolveStatus::kSuccess) return fail(st, ls.message);
    note_condition(t, ls.rcond);
    return true;
  }

  // The outputs of a delivered row beyond q, q̇, q̈, from the converged state in ws: the listed points' motions
  // (counted) and the condition estimate (Φ is ws.phi already). Only delivered rows pay for them: sub-steps and
  // the seam steps of parallel chunks do not.
  void row_outputs() {
    const double* qd = need_v_ ? current_.qd.data() : nullptr;
    const double* qdd = need_a_ ? current_.qdd.data() : nullptr;
    for (std::size_t i = 0; i < opt_.points.size(); ++i)
      points_[i] = evaluate_point(opt_.points[i], current_.q.data(), qd, qdd);
    ws_->counters.point_evaluations += static_cast<Index>(opt_.points.size());
    rcond_ = opt_.condition && ws_->lu ? ws_->lu->rcond() : 0.0;
    det_sign_ = current_row_sign_;
    det_sign_t_ = current_row_sign_t_;
  }
  // Orientation of Φq at the last delivered row (row_outputs()): sign ±1, 0 at a singular position, kSignUnknown
  // where no factorisation of this sweeper's tells it; and the time it holds at (det_sign_time(): the row's, or
  // with positions only that of the step whose Newton factorised last).
  Orientation det_sign() const { return det_sign_; }
  double det_sign_time() const { return det_sign_t_; }
  // The last converged state (q, and q̇, q̈ as computed), which the rows deliver.
  const State& state() const { return current_; }
  // Solves with `w` from now on: the state and the history are the sweeper's, a workspace holds only the solves'
  // scratch and an LU (whichever factorisation it holds is a start for modified Newton, which refreshes it when it
  // contracts badly). A parallel sweep's seeding pass takes whichever workspace is free for each seed.
  void bind(Workspace& w) {
    ws_ = &w;
    factorizations_before_ = factorizations_seen_ = w.counters.factorizations;
  }
  // Moves the last converged state out and frees the history: the sweeper is not used after this.
  State take_state() {
    history_.clear(), history_.shrink_to_fit();
    predicted_ = Eigen::VectorXd();
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
  const PointMotion* point_motions() const { return points_.empty() ? nullptr : points_.data(); }
  double rcond() const { return rcond_; }

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
    if (st != SolveStatus::kSuccess) return fail(st, ps.message);
    return converged(t, ps);
  }

  // The estimated error of state().q (units of the tolerance test; infinite when unknown).
  double state_error() const { return current_error_; }
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
    known_ = 0;
    current_sign_ = current_row_sign_ = Orientation{};
    row_error_ = INFINITY;  // how well the adopted state is known is not said: the next step checks it
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

  // Why Φq stays singular on both sides of the singular position qs at t: the model is short of drivers or
  // constraints all along its motion (": redundant or missing constraints"), or the position is singular by itself,
  // several loops folded or aligned at once and kept so by the drive (nfourbar started folded: every coupler on
  // its neighbour's crank, the far loops staying so as crank 0 turns), which a solution assembled near it, fully
  // driven, tells (detail::driven_dof_nearby).
  std::string singular_throughout(const Eigen::VectorXd& qs, double t) {
    const Index nearby = detail::driven_dof_nearby(model_, qs, t, assembly_options(opt_.newton));
    if (nearby > 0) return ": redundant or missing constraints";
    if (nearby < 0)
      return ": redundant or missing constraints, or several loops folded or aligned at once (no solution near it "
             "was assembled to tell which)";
    return std::string(" on the branch the drive follows from there, though a solution near it is regular: the "
                       "position is singular, several loops folded or aligned at once, rather than the model short "
                       "of drivers or constraints") +
           (has_current_ ? "" : "; start the drive off it");
  }

  // Φq is singular at the converged position ws.q at t (rcond below kSingularRcond, or a zero pivot): a
  // bifurcation, where branches of the motion cross and the mechanism momentarily gains degrees of freedom
  // (nfourbar at its horizontal positions, a change-point four-bar). The velocity there is not unique, and the
  // LU's answer is rounding noise in the directions Φq no longer constrains. The branch the sweep follows has its
  // own velocity, the limit from both sides: reported is the Richardson extrapolation of the symmetric means of
  // the derivatives at t ± δ and t ± 2δ (δ = 5 % of the step, all four regular), which differs from that limit
  // by O(δ⁴), with a warning. The plus side is reached straight through from the minus side, so the sweep keeps
  // its branch. When there is no
  // position beyond (a dead point: the drive cannot go on) or the sides are singular too (the model is singular
  // on an interval: redundant or missing constraints), the step fails with that diagnosis.
  // `have_position`: false when Newton could not converge at t itself (a zero pivot exactly at the singular
  // point); the position is then extrapolated the same way, to O(δ⁴), and checked against the tolerance.
  bool singular_point(double t, double rc, bool have_position = true) {
    struct Guard {
      bool& b;
      ~Guard() { b = false; }
    } guard{bracketing_ = true};
    const Eigen::VectorXd qs = ws_->q;
    // named now, from Φq factorised at the singular position itself, in case it is a dead point
    const std::string lined_up = ws_->has_factorization ? lined_up_equations() : "";
    double step = has_current_ ? t - current_.t : default_step_;
    if (step == 0.0) step = 1e-3;
    const double d = 0.05 * step;
    // Four regular points t − 2δ, t − δ, t + δ, t + 2δ, each predicted from the one before (the first from the
    // last state of the sweep), so the plus side is reached straight through the singular point.
    const double offset[4] = {-2 * d, -d, d, 2 * d};
    State side[4];
    LinearSummary ls;
    PositionSummary ps;
    // The sides are solved to rounding level: their derivatives divide O(δ) quantities by Φq's smallest
    // singular value, O(δ), so a position error ε_q becomes a velocity error ε_q/δ (and worse in q̈).
    NewtonOptions tight = opt_.newton;
    tight.tolerance = std::max(1e-4 * opt_.newton.tolerance, 1e-15);
    tight.known_to = 0.0;  // a level in units of the sweep's tolerance: not this one's, and these reach rounding
    tight.jacobian_update = JacobianUpdate::kEveryIteration;
    tight.max_iterations = std::max(tight.max_iterations, 30);
    for (int k = 0; k < 4; ++k) {
      const double ts = t + offset[k];
      if (k == 0) {
        if (has_current_) {
          predict(ts);
        } else {
          // The sweep starts at the singular position: no past motion tells the branch, and Newton cannot
          // start from a singular Φq. The assembly (least squares, then the solution nearest the placement)
          // finds the side's position nearest the start.
          ws_->q = qs;
          AssemblyOptions ao;
          ao.tolerance = opt_.newton.tolerance;
          // Newton (regular at ts) finishes from wherever the assembly got, converged or not. Known limit: on
          // a chain of N loops all flat at once (nfourbar starting at θ = 0), the least-squares steps move the
          // far cranks off the flat position one loop per iteration, so beyond N ≈ 90 the start is not resolved
          // and the sweep stops at t0 with the diagnosis.
          AssemblySummary as;
          phiq::assemble(model_, ts, ao, ws_->q, &as);
          if (!ws_->q.allFinite()) {
            ws_->q = qs;
            return fail(SolveStatus::kSingularJacobian, "the sweep starts at a singular position (t = " +
                                                            format_time(t) + "), and no position near it at t = " +
                                                            format_time(ts) + " was found: " + as.message);
          }
        }
      } else {
        const double h = offset[k] - offset[k - 1];
        ws_->q = side[k - 1].q + h * side[k - 1].qd + (0.5 * h * h) * side[k - 1].qdd;
      }
      SolveStatus st = solve_position(model_, ts, tight, *ws_, &ps);
      const bool position_found = st == SolveStatus::kSuccess;
      if (position_found) st = lu_derivatives(ts, true, &ls);
      if (st != SolveStatus::kSuccess || ls.rcond < kSingularRcond) {
        ws_->q = qs;
        std::ostringstream m;
        m << "singular position at t = " << format_time(t) << " (Φq rcond " << rc << "): ";
        // (a side whose position was found but whose velocity solve met a zero pivot is singular too)
        const bool side_singular =
            position_found && (st == SolveStatus::kSuccess || st == SolveStatus::kSingularJacobian);
        if (k >= 2 && !position_found)
          m << "no position beyond it on this branch (a dead point: the drive cannot go on, and the speed it asks "
               "for there is unbounded)"
            << (lined_up.empty() ? "" : ", where these equations line up:" + lined_up);
        else if (side_singular)
          m << "Φq stays singular around it (rcond " << ls.rcond << " at t = " << format_time(ts) << ")"
            << singular_throughout(qs, t);
        else
          m << "the branch cannot be followed to it: " << (position_found ? ls.message : ps.message);
        return fail(SolveStatus::kSingularJacobian, m.str());
      }
      side[k].t = ts, side[k].q = ws_->q, side[k].qd = ws_->qd, side[k].qdd = ws_->qdd;
    }
    // Symmetric means over ±δ and ±2δ, combined by Richardson extrapolation: the branch's value at t to O(δ⁴).
    auto at_t = [&](const Eigen::VectorXd State::*x) -> Eigen::VectorXd {
      return (2.0 / 3.0) * (side[1].*x + side[2].*x) - (1.0 / 6.0) * (side[0].*x + side[3].*x);
    };
    ws_->q = have_position ? qs : at_t(&State::q);
    if (!have_position) {
      model_.residual(ws_->q.data(), t, ws_->phi.data());
      ++ws_->counters.residual_evaluations;
      if (!(scaled_residual(model_, ws_->phi) <= opt_.newton.tolerance)) {
        std::ostringstream m;
        m << "singular position at t = " << format_time(t) << ": Newton meets a zero pivot there, and the position "
          << "interpolated from t ± " << d << " misses the tolerance (residual " << scaled_residual(model_, ws_->phi)
          << ")";
        return fail(SolveStatus::kSingularJacobian, m.str());
      }
    }
    ws_->qd = at_t(&State::qd);
    if (need_a_) ws_->qdd = at_t(&State::qdd);
    ++sum_.singular_positions;
    singular_row_ = true;
    std::ostringstream m;
    m.precision(3);
    m << (has_current_ ? "bifurcation passed" : "the sweep starts at a bifurcation")
      << ": Φq is singular here (rcond " << rc
      << "), so the velocity is not unique; reported is the branch's own (extrapolated from t ± " << d
      << " and t ± " << 2 * d << ")"
      << (has_current_ ? ", and the sweep kept the branch it was on"
                       : "; the branch followed is the one nearest the placement");
    sum_.warnings.push_back({t, "bifurcation", m.str()});
    note_min_rcond(t, rc);
    ill_conditioned_ = false;
    // The factorisation left is of a side, next to the singular position: a poor Newton matrix for the next step,
    // whose contraction the last solves (full Newton, to rounding level) did not measure. The next step factorises.
    ws_->has_factorization = false;
    return true;
  }

  // Why the sweep cannot go on towards t1, when a driver's law or a rheonomic equation is not defined there
  // (√(1 − t) beyond t = 1, exp(t) past the largest double): at the last converged position, whose rows were all
  // finite, only rows that depend on t can turn non-finite at t1; the first is named. "" otherwise (ws.phi is
  // scratch).
  std::string undefined_at(double t1) {
    model_.residual(current_.q.data(), t1, ws_->phi.data());
    for (Index i = 0; i < ws_->phi.size(); ++i)
      if (!std::isfinite(ws_->phi(i)))
        return "'" + model_.row_name(i) + "' is not finite at t = " + format_time(t1) +
               " (its law or equation is not defined there, or overflows)";
    return "";
  }

  // Why the sweep cannot go on towards t1, when it is redundant equations that stop holding: the model is solved on
  // its independent rows (Model::without_rows), chosen where it was assembled, and the rows left out, consistent
  // there, are checked at every step. Two drivers of one coordinate at different rates, or two joint drivers of
  // one door, agree at the start and part at once. Newton on the independent rows alone, from the last state (full
  // steps with the square LU, a few iterations), tells: where they hold and some left-out row does not, those rows
  // are named. "" otherwise. A diagnosis after the sub-steps failed: it leaves ws.q, ws.qd as scratch.
  std::string conflicting_redundancy(double t1) {
    const std::vector<Index>& dropped = model_.dropped_rows();
    if (dropped.empty() || !ws_->lu) return "";
    const double tol = opt_.newton.tolerance;
    const Eigen::VectorXd& rs = model_.tolerance_scales().row_scale;
    const std::vector<Index>& kept = model_.solve_rows();
    auto holds = [&](Index i) {
      return detail::row_within(model_, i, std::fabs(ws_->phi(i)) / rs(i), tol, ws_->q, t1);
    };
    ws_->q = current_.q;
    Eigen::VectorXd rhs(static_cast<Index>(kept.size())), step(model_.num_coordinates());
    bool kept_hold = false;
    for (int it = 0; it < 10 && !kept_hold; ++it) {
      model_.residual(ws_->q.data(), t1, ws_->phi.data());
      if (!ws_->phi.allFinite()) return "";
      kept_hold = std::all_of(kept.begin(), kept.end(), holds);
      if (kept_hold) break;
      LinearSummary ls;  // the factorisation at ws.q (the velocity it solves is not used)
      if (solve_velocity(model_, t1, *ws_, &ls) != SolveStatus::kSuccess) return "";
      for (std::size_t k = 0; k < kept.size(); ++k) rhs(static_cast<Index>(k)) = ws_->phi(kept[k]);
      if (!ws_->lu->solve(rhs.data(), step.data()) || !step.allFinite()) return "";
      ws_->q -= step;
    }
    if (!kept_hold) return "";
    std::vector<std::string> names;
    for (Index i : dropped)
      if (!holds(i)) {
        const std::string name = model_.row_name(i);
        if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
      }
    if (names.empty()) return "";
    std::ostringstream m;
    m << "redundant equations, consistent where the model was assembled, stop holding where the others hold (";
    for (std::size_t k = 0; k < names.size() && k < 8; ++k) m << (k ? ", '" : "'") << names[k] << "'";
    if (names.size() > 8) m << " and " << names.size() - 8 << " more";
    m << "): the redundant constraints are inconsistent from here on";
    return m.str();
  }

  // Why the sweep cannot go on from the last converged state (current_) towards t1, when it is a dead point (a
  // turning point of the motion: the drive asks for positions that do not exist): Φq is near-singular there and
  // the speed grows like 1/√(t* − t). Then q̈ ≈ q̇ / (2 (t* − t)) along q̇, so t* − t ≈ |q̇|² / (2 q̇·q̈), and the
  // equations that line up are the support of Φq's left near-null vector, found by inverse iteration on Φqᵀ
  // with the LU. Returns "" when the last state does not look like one (then the cause is left open).
  std::string dead_point(double t1) {
    ws_->q = current_.q;
    LinearSummary ls;
    if (lu_derivatives(current_.t, true, &ls, /*just_solved=*/false) != SolveStatus::kSuccess) return "";
    const double vv = ws_->qd.squaredNorm(), va = ws_->qd.dot(ws_->qdd);
    const double tau = va != 0.0 ? vv / (2.0 * va) : 0.0;  // t* − t, signed like the drive direction
    if (!(std::isfinite(tau) && tau * (t1 - current_.t) > 0 && std::fabs(tau) <= 2.0 * std::fabs(t1 - current_.t)))
      return "";
    const std::string lined_up = lined_up_equations();
    if (lined_up.empty()) return "";
    std::ostringstream s;
    s.precision(6);
    s << "a dead point near t = " << current_.t + tau << " (the drive asks for positions that do not exist; Φq rcond "
      << std::setprecision(2) << ls.rcond << " at t = " << std::setprecision(10) << current_.t
      << ", speed growing as 1/√(t* − t)), where these equations line up:" << lined_up;
    return s.str();
  }

  // " 'crank', 'coupler'": the equations in the support of the left near-null vector of the near-singular Φq
  // factorised in ws.lu (inverse iteration on Φqᵀ, 4 solves), up to 8 named; "" when a solve fails.
  std::string lined_up_equations() {
    const Index m = model_.num_solve_rows();
    Eigen::VectorXd y = Eigen::VectorXd::Ones(m), z(m);
    for (int it = 0; it < 4; ++it) {
      if (!ws_->lu->solve_transposed(y.data(), z.data()) || !z.allFinite()) return "";
      y = z / z.cwiseAbs().maxCoeff();
    }
    std::vector<std::string> names;
    for (Index i = 0; i < m; ++i) {
      if (std::fabs(y[i]) < 0.05) continue;
      const Index row = model_.dropped_rows().empty() ? i : model_.solve_rows()[static_cast<std::size_t>(i)];
      const std::string name = model_.row_name(row);
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
    std::ostringstream s;
    for (std::size_t k = 0; k < names.size() && k < 8; ++k) s << (k ? ", '" : " '") << names[k] << "'";
    if (names.size() > 8) s << " and " << names.size() - 8 << " more";
    return s.str();
  }

  // Initial position problem from the rough placement in ws.q.
  bool assemble(double t) {
    SolveStatus st = solve_position(model_, t, opt_.assembly, *ws_, &sum_.assembly);
    if (st != SolveStatus::kSuccess) return fail(st, "initial assembly failed: " + sum_.assembly.message);
    return converged(t, sum_.assembly);
  }

  // From the converged state at current_.t to t1, subdividing on failure. current_ (and prev_) change only on
  // success, so a failed attempt restores from them without copying any state on the way.
  bool advance(double t1, int depth) {
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
    if (st == SolveStatus::kSingularJacobian && has_current_ && !bracketing_) {
      // a zero pivot exactly at a singular position: bracket it (position interpolated from both sides)
      if (singular_point(t1, 0.0, /*have_position=*/false)) {
        row_error_ = INFINITY;  // interpolated: the next step checks it
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
      const std::string beyond = "no assembly beyond t = " + format_time(current_.t) + " (sub-steps down to t = " +
                                 format_time(t1) + " tried";
      if (const std::string undefined = undefined_at(t1); !undefined.empty())
        return fail(SolveStatus::kNonFinite, beyond + "): " + undefined);
      if (const std::string conflict = conflicting_redundancy(t1); !conflict.empty())
        return fail(SolveStatus::kInconsistent, beyond + "): " + conflict);
      const std::string dead = dead_point(t1);
      // (a derivative that does not exist says so itself: no guess at another cause)
      const bool no_derivative = st == SolveStatus::kNonFinite && why.rfind(detail::kNonFiniteJacobian, 0) == 0;
      return fail(st, beyond +
                          (no_derivative   ? "): "
                           : dead.empty() ? ": the drive leaves the reachable range, or the mechanism "
                                            "passes a singular position): "
                                          : "): " + dead + "; ") +
                          why);
    }
    restore();
    ++sum_.subdivisions;
    const double tm = 0.5 * (current_.t + t1);
    return advance(tm, depth + 1) && advance(t1, depth + 1);
  }

 private:
  // A position converged at t: its warning, the derivatives asked for, and it becomes the current state. With
  // `left_branch`, a position where det Φq has the other sign than at the current state (both regular, both
  // factorised at their position) is refused instead, with *left_branch set and nothing of it kept: no warning,
  // no count, no condition noted.
  bool converged(double t, const PositionSummary& ps, bool* left_branch = nullptr) {
    struct Noted {
      std::size_t warnings;
      Index singular_positions;
      double min_rcond, min_rcond_time, rounding_level, known_to;
      bool ill_conditioned;
    } const noted{sum_.warnings.size(), sum_.singular_positions, sum_.min_rcond, sum_.min_rcond_time,
                  rounding_level_, known_to_, ill_conditioned_};
    singular_row_ = false;
    row_error_ = ps.error_estimate < 0.0 ? INFINITY : ps.error_estimate;
    rounding_level_ = std::max(rounding_level_, ps.rounding_level);
    // How well the positions can be known here (NewtonOptions::known_to): the largest rounding level the rows
    // measured since the last one that converged to the tolerance (a step from a point Newton reached, not the
    // first step from a prediction, which corrects the prediction's own error too; nor a row that ended within
    // it). Dropped again as soon as a row converges to the tolerance.
    known_to_ = ps.rounding_measured                              ? std::max(known_to_, ps.rounding_level)
                : ps.rounding_level == 0.0 && ps.error_estimate <= 1.0 ? 0.0
                                                                     : known_to_;
    if (ps.slow_convergence) sum_.warnings.push_back({t, "slow_convergence", ps.message});
    if (!need_v_ && ps.rcond > 0.0 && ps.rcond < kSingularRcond) {
      // positions only: nothing is computed from Φq here, but the user is told where the motion branches
      ++sum_.singular_positions;
      singular_row_ = true;
      std::ostringstream m;
      m.precision(3);
      m << "singular position (Φq rcond " << ps.rcond << "): a bifurcation, velocities would not be unique here";
      if (!has_current_) m << " (the sweep starts here: the branch is the one nearest the placement)";
      sum_.warnings.push_back({t, "bifurcation", m.str()});
    }
    if (!position_only_ && !derivatives(t, ps.linear_convergence)) return false;
    const Orientation sign = sign_at_solution();
    if (left_branch && has_current_ && sign.regular() && current_sign_.regular() && sign != current_sign_) {
      sum_.warnings.resize(noted.warnings);
      sum_.singular_positions = noted.singular_positions;
      sum_.min_rcond = noted.min_rcond, sum_.min_rcond_time = noted.min_rcond_time;
      rounding_level_ = noted.rounding_level, known_to_ = noted.known_to, ill_conditioned_ = noted.ill_conditioned;
      *left_branch = true;
      return false;
    }
    if (ws_->counters.factorizations != factorizations_seen_)  // this step's solves factorised
      factorizations_seen_ = ws_->counters.factorizations, factorized_step_t_ = t;
    current_sign_ = sign;
    // the row's sign: the one at the solution, else (positions only) that of the last factorisation this sweeper
    // made, at an iterate a few steps back on its own path, so that a change is seen a row or two late rather than
    // not at all, with the time of the step that made it; never that of a factorisation the workspace held before
    // (another chunk's, or another sweep's: the sign of another place)
    const bool own = ws_->counters.factorizations != factorizations_before_;
    current_row_sign_ = sign.sign != kSignUnknown || !own ? sign : orientation_of(*ws_->lu);
    current_row_sign_t_ = sign.sign != kSignUnknown ? t : factorized_step_t_;
    remember(t);
    return true;
  }
  // Orientation of Φq at the position just converged (ws.q): from the LU when it was factorised there (velocities
  // are solved at every row; positions only, when Newton's last factorisation is at the solution), sign 0 at a
  // singular position, else kSignUnknown.
  Orientation sign_at_solution() const {
    if (singular_row_) return {0, 0};
    if (!ws_->lu || !ws_->has_factorization) return {};
    const bool at_solution = (need_v_ && !position_only_) || ws_->factorized_at_solution;
    return at_solution ? orientation_of(*ws_->lu) : Orientation{};
  }
  // Whether the converged ws.q is farther from the prediction than the prediction is from the last state (in
  // tolerance units, beyond a floor of 1000 tolerances): a predictor errs by a higher order of h than the O(h)
  // move, so a correction as large as the move means another solution was found. Runs every drive step: one pass
  // for the correction, and one for the move only when the correction is large at all.
  bool jumped() {
    if (!extrapolated_) return false;  // the previous position: nothing predicted
    const double tol = opt_.newton.tolerance;
    const double correction = detail::scaled_distance(model_, ws_->q.data(), predicted_.data(), ws_->q.data(), tol);
    if (!(correction > 1000.0)) return false;
    return correction >
           0.5 * detail::scaled_distance(model_, predicted_.data(), current_.q.data(), current_.q.data(), tol);
  }

  // ws.q = the predictor's guess at t1 from the current state and the history (kept in predicted_ for jumped()),
  // and newton_.start_error = the size of the next term of the extrapolation in units of the tolerance test — its
  // error estimate, from one more row of history than the prediction needs (infinite until there is one, so that
  // Newton then takes a step). One pass over the vectors.
  void predict(double t1) {
    const Index n = current_.q.size();
    const double h = t1 - current_.t, tc = current_.t;
    const double tol = opt_.newton.tolerance;
    const double* cs = model_.tolerance_scales().coordinate_scale.data();
    ws_->q.resize(n);
    predicted_.resize(n);
    double* out = ws_->q.data();
    double* kept = predicted_.data();
    const double* q = current_.q.data();
    const int k = known_;
    auto x = [&](int i) { return history_[static_cast<std::size_t>(i)].data(); };
    auto th = [&](int i) { return history_t_[static_cast<std::size_t>(i)]; };
    detail::WorstRatio worst;
    bool estimated = true;
    double inherited = current_error_;  // the error of the rows extrapolated from, carried into the prediction
    // f(j, &error) returns the prediction of coordinate j and sets its error estimate.
    auto each = [&](auto&& f) {
      for (Index j = 0; j < n; ++j) {
        double e = 0.0;
        const double p = f(j, e);
        out[j] = kept[j] = p;
        worst.add(std::fabs(e), tol * cs[j] + ToleranceScales::kUlpFloor * std::fabs(p));
      }
    };
    // The nodes of the divided-difference predictors: tc, t_0, t_1, t_2 (the current row, then the history; the
    // current row again where the history is shorter), their rows, and the reciprocals of their spacings, once per
    // step, so that the passes below multiply (no division per coordinate).
    struct Nodes {
      double T[4];
      const double* xs[3];
      double i01, i12, i23, i02, i13, i03;
    };
    auto nodes = [&] {
      auto inv = [](double d) { return d != 0.0 ? 1.0 / d : 0.0; };
      Nodes nd{{tc, k > 0 ? th(0) : tc, k > 1 ? th(1) : tc, k > 2 ? th(2) : tc},
               {k > 0 ? x(0) : q, k > 1 ? x(1) : q, k > 2 ? x(2) : q}, 0, 0, 0, 0, 0, 0};
      const double* T = nd.T;
      nd.i01 = inv(T[0] - T[1]), nd.i12 = inv(T[1] - T[2]), nd.i23 = inv(T[2] - T[3]);
      nd.i02 = inv(T[0] - T[2]), nd.i13 = inv(T[1] - T[3]), nd.i03 = inv(T[0] - T[3]);
      return nd;
    };
    switch (predictor_) {
      case Predictor::kPrevious:
      case Predictor::kSecant:
      case Predictor::kParabolic: {
        // Newton's divided differences of q over tc, t_0, t_1, t_2 (the current row, then the history): the
        // polynomial of the predictor's order through the last rows, and its next term as the error
        const int order = std::min(predictor_ == Predictor::kPrevious ? 0 : predictor_ == Predictor::kSecant ? 1 : 2, k);
        estimated = k > order;
        const int terms = order + (estimated ? 1 : 0);
        inherited = 0.0;
        const Nodes nd = nodes();
        const double* T = nd.T;
        const double* const* xs = nd.xs;
        const double i01 = nd.i01, i12 = nd.i12, i23 = nd.i23, i02 = nd.i02, i13 = nd.i13, i03 = nd.i03;
        const double w1 = h, w2 = w1 * (t1 - T[1]), w3 = w2 * (t1 - T[2]);
        // the rows' own errors carry over with the weights of Lagrange's polynomial through them at t1
        for (int i = 0; i <= order; ++i) {
          double w = 1.0;
          for (int l = 0; l <= order; ++l)
            if (l != i) w *= (t1 - T[l]) / (T[i] - T[l]);
          inherited += std::fabs(w) * (i == 0 ? current_error_ : history_error_[static_cast<std::size_t>(i - 1)]);
        }
        each([&](Index j, double& e) {
          const double v0 = q[j];
          if (terms == 0) return v0;
          const double d01 = (v0 - xs[0][j]) * i01;
          double p = v0, next = w1 * d01;
          if (terms >= 2) {
            const double d12 = (xs[0][j] - xs[1][j]) * i12;
            const double d012 = (d01 - d12) * i02;
            p += w1 * d01, next = w2 * d012;
            if (terms >= 3) {
              const double d23 = (xs[1][j] - xs[2][j]) * i23;
              const double d123 = (d12 - d23) * i13;
              p += w2 * d012, next = w3 * (d012 - d123) * i03;
            }
          }
          if (estimated) e = next;
          else p += next;  // the highest term is the prediction's own, with no estimate beyond it
          return p;
        });
        extrapolated_ = order > 0;
        break;
      }
      case Predictor::kHermite: {
        // Hermite divided differences over the nodes tc, tc, t_0, t_1, t_2 (f[tc] = q, f[tc, tc] = q̇): the cubic
        // through the current row (position and velocity) and the two rows before, and its next term as the error
        const double* v = current_.qd.data();
        const int order = std::min(3, k + 1);  // Newton terms after q: (t − tc) q̇, then one per row of history
        estimated = k > 2;
        const int terms = order + (estimated ? 1 : 0);
        const Nodes nd = nodes();
        const double* T = nd.T;
        const double* const* xs = nd.xs;
        const double i01 = nd.i01, i12 = nd.i12, i23 = nd.i23, i02 = nd.i02, i13 = nd.i13, i03 = nd.i03;
        const double w1 = h, w2 = w1 * h, w3 = w2 * (t1 - T[1]), w4 = w3 * (t1 - T[2]);
        // Each term as a function of the positions q, q_0, q_1, q_2 (and q̇), so that the rows' own errors carry
        // over with the weights the prediction gives them: found by evaluating it on unit values.
        auto eval = [&](const double* f, double fd, double* next) {
          double p = f[0] + w1 * fd, nx = 0.0;
          if (terms >= 2) {
            const double a1 = (f[0] - f[1]) * i01;  // f[tc, t_0]
            const double b0 = (fd - a1) * i01;      // f[tc, tc, t_0]
            double add = w2 * b0;
            if (terms >= 3) {
              const double a2 = (f[1] - f[2]) * i12;  // f[t_0, t_1]
              const double b1 = (a1 - a2) * i02;      // f[tc, t_0, t_1]
              const double c0 = (b0 - b1) * i02;      // f[tc, tc, t_0, t_1]
              p += add, add = w3 * c0;
              if (terms >= 4) {
                const double a3 = (f[2] - f[3]) * i23;  // f[t_1, t_2]
                const double b2 = (a2 - a3) * i13;      // f[t_0, t_1, t_2]
                const double c1 = (b1 - b2) * i03;      // f[tc, t_0, t_1, t_2]
                const double d0 = (c0 - c1) * i03;      // f[tc, tc, t_0, t_1, t_2]
                p += add, add = w4 * d0;
              }
            }
            if (estimated) nx = add;
            else p += add;  // the highest term is the prediction's own, with no estimate beyond it
          }
          if (next) *next = nx;
          return p;
        };
        inherited = 0.0;
        for (int i = 0; i <= std::min(k, 2); ++i) {
          double unit[4] = {0.0, 0.0, 0.0, 0.0};
          unit[i] = 1.0;
          inherited += std::fabs(eval(unit, 0.0, nullptr)) *
                       (i == 0 ? current_error_ : history_error_[static_cast<std::size_t>(i - 1)]);
        }
        each([&](Index j, double& e) {
          const double f[4] = {q[j], xs[0][j], xs[1][j], xs[2][j]};
          return eval(f, v[j], &e);
        });
        extrapolated_ = true;
        break;
      }
      case Predictor::kLinear: {
        const double* v = current_.qd.data();
        estimated = k > 0;
        const double c = estimated ? 0.5 * h * h / (tc - th(0)) : 0.0;
        const double* v0 = estimated ? x(0) : v;
        each([&](Index j, double& e) {
          e = c * (v[j] - v0[j]);  // h²/2 q̈, q̈ from the last two q̇
          return q[j] + h * v[j];
        });
        extrapolated_ = true;
        break;
      }
      case Predictor::kQuadratic:
      case Predictor::kCubic: {
        const double* v = current_.qd.data();
        const double* a = current_.qdd.data();
        const bool cubic = predictor_ == Predictor::kCubic && k > 0;
        estimated = k > (cubic ? 1 : 0);
        const double hh = 0.5 * h * h, h3 = h * h * h / 6.0;
        const double dt0 = k > 0 ? tc - th(0) : 1.0, i_dt0 = 1.0 / dt0;
        const double i_dt1 = k > 1 ? 1.0 / (th(0) - th(1)) : 1.0;
        const double* a0 = k > 0 ? x(0) : a;
        const double* a1 = k > 1 ? x(1) : a;
        // cubic: q⃛ ≈ (q̈ − q̈_0) / (tc − t_0), which errs by (tc − t_0)/2 q⁗; with the Taylor remainder the
        // prediction errs by h³ (h/24 + (tc − t_0)/12) q⁗, q⁗ ≈ 2 q̈[tc, t_0, t_1] (Newton's divided difference)
        const double ce = h * h * h * (h / 24.0 + dt0 / 12.0) * 2.0 / (tc - (k > 1 ? th(1) : tc - 1.0));
        each([&](Index j, double& e) {
          double p = q[j] + h * v[j] + hh * a[j];
          if (k > 0) {
            const double jerk = (a[j] - a0[j]) * i_dt0;
            if (cubic) {
              p += h3 * jerk;
              if (estimated) e = ce * (jerk - (a0[j] - a1[j]) * i_dt1);
            } else {
              e = h3 * jerk;
            }
          }
          return p;
        });
        extrapolated_ = true;
        break;
      }
      case Predictor::kAuto: break;
    }
    // The prediction is as far from the solution as the rows it extrapolates (how well each was solved) plus the
    // extrapolation's own error; accepted without a Newton step, its error becomes the next row's to carry. So the
    // error budget adds up over steps taken without Newton until it exceeds the tolerance, and a step resets it.
    newton_.start_error = estimated ? inherited + worst.worst : INFINITY;
  }
  void remember(double t) {
    // The quantity the predictor extrapolates, at the current row, moves into the history (by buffer swaps: the
    // oldest entry's buffer becomes current_'s, assigned below without allocating). Only a state that was really
    // converged enters it (the default-constructed one has no q: found by the fuzzer with a sweep starting away
    // from t = 0).
    if (depth_ > 0 && has_current_) {
      std::rotate(history_.rbegin(), history_.rbegin() + 1, history_.rend());
      std::rotate(history_t_.rbegin(), history_t_.rbegin() + 1, history_t_.rend());
      Eigen::VectorXd& x = predictor_ == Predictor::kLinear                                        ? current_.qd
                           : predictor_ == Predictor::kQuadratic || predictor_ == Predictor::kCubic ? current_.qdd
                                                                                                   : current_.q;
      history_[0].swap(x);
      history_t_[0] = current_.t;
      std::rotate(history_error_.rbegin(), history_error_.rbegin() + 1, history_error_.rend());
      history_error_[0] = current_error_;
      known_ = std::min(known_ + 1, depth_);
    }
    has_current_ = true;
    current_.t = t;
    current_error_ = row_error_;
    // The converged state moves into current_ by swaps too: ws keeps the buffers of the state before, which the
    // next step overwrites (predict() writes q, the solves q̇ and q̈). Rows are delivered from state().
    current_.q.swap(ws_->q);
    if (need_v_) current_.qd.swap(ws_->qd);
    if (need_a_) current_.qdd.swap(ws_->qdd);
  }
  void restore() {
    ws_->q = current_.q;
    if (need_v_) ws_->qd = current_.qd;
    if (need_a_) ws_->qdd = current_.qdd;
  }

  const Model& model_;
  const SweepOptions& opt_;
  Workspace* ws_;  // the workspace the solves use (bind())
  SweepSummary& sum_;
  bool need_v_ = false, need_a_ = false;
  NewtonOptions newton_;  // opt_.newton, with jacobian_with_residual when velocities follow
  Predictor predictor_;
  State current_;  // the last converged state
  bool has_current_ = false;
  // What the predictor extrapolates from (q for the position predictors, q̇ for linear, q̈ for quadratic and
  // cubic) at the converged rows before current_, newest first, and their times: depth_ rows, known_ of them valid.
  std::vector<Eigen::VectorXd> history_;
  std::vector<double> history_t_;
  std::vector<double> history_error_;  // the estimated error of q at those rows (units of the tolerance test)
  int depth_ = 0, known_ = 0;
  double current_error_ = INFINITY;  // the estimated error of current_.q (PositionSummary::error_estimate)
  double row_error_ = INFINITY;      // that of the row being converged, until remember() makes it current
  bool extrapolated_ = false;  // the last prediction moved from current_ (jumped() has something to compare)
  bool position_only_ = false;  // inside advance_position()
  std::vector<PointMotion> points_ = std::vector<PointMotion>(opt_.points.size());
  double rcond_ = 0.0;
  Eigen::VectorXd predicted_;       // the last prediction (for jumped())
  bool bracketing_ = false;         // inside singular_point(): no nested bracketing
  bool singular_row_ = false;       // the current state is a singular position (its derivatives bracketed)
  Orientation det_sign_{0, 0};      // of Φq at the last delivered row (det_sign())
  Orientation current_sign_;         // and at current_ (sign_at_solution() when it converged)
  Orientation current_row_sign_;     // what current_'s row reports (converged()), and at which time
  double current_row_sign_t_ = 0.0, det_sign_t_ = 0.0;
  // The workspace's factorisation count when this sweeper took it: the ones after it are its own (converged()).
  Index factorizations_before_ = ws_->counters.factorizations;
  Index factorizations_seen_ = factorizations_before_;  // the count at the last converged state
  double factorized_step_t_ = 0.0;  // the time of the last step whose solves factorised (converged())
  double rounding_level_ = 0.0;     // see take_rounding_level()
  double known_to_ = 0.0;           // the rounding level carried to the next solves (converged())
  bool ill_conditioned_ = false;    // the last delivered state was near-singular (one warning per stretch)
  double default_step_ = (opt_.t_end - opt_.t_begin) / static_cast<double>(std::max<Index>(opt_.steps, 1));
};

}  // namespace

std::string SweepSummary::BriefReport() const {
  std::ostringstream s;
  s << to_string(status) << ": " << steps_completed << " steps, " << counters.newton_iterations
    << " Newton iterations, " << counters.factorizations << " factorizations, " << counters.velocity_solves
    << " velocity and " << counters.acceleration_solves << " acceleration solves";
  if (counters.point_evaluations) s << ", " << counters.point_evaluations << " point evaluations";
  if (subdivisions) s << ", " << subdivisions << " step subdivisions";
  if (singular_positions) s << ", " << singular_positions << " singular positions passed";
  if (threads > 1)
    s << ", " << threads << " threads (" << parallel_chunks << " parallel chunk" << (parallel_chunks == 1 ? ")" : "s)");
  if (!warnings.empty())
    s << ", " << warnings.size() << (warnings.size() == 1 ? " warning" : " warnings") << " (first at t = "
      << warnings[0].t << ")";
  s.precision(3);
  s << ", " << std::scientific << solve_seconds << " s";
  if (!message.empty()) s << " — " << message;
  return s.str();
}

namespace {

// The per-run bookkeeping shared by the sequential and parallel paths.
struct Run {
  const SweepOptions& opt;
  const std::function<bool(const StepView&)>& on_step;
  SweepSummary& sum;
  double h = 0.0;

  // t_k computed from k, not accumulated, so that the last point is t_end exactly (steps = 0: one row, at t_begin)
  double time_of(Index k) const {
    return k == opt.steps && k > 0 ? opt.t_end : opt.t_begin + static_cast<double>(k) * h;
  }
  // Sign of det Φq at the last delivered regular row whose sign is known, its time, and whether a singular row
  // (bracketed, with its own warning) was delivered since.
  Orientation last_sign{0, 0};
  double last_sign_t = 0.0;
  bool singular_since = false;

  // Delivers row k; false when the caller stops the sweep (status and message set). A change of det Φq's sign
  // since the last regular row is a singular position passed between the two: warned here, in row order, so that
  // sequential and parallel sweeps report it alike.
  bool deliver(Index k, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
               const PointMotion* points, const Eigen::VectorXd& phi, double rcond, Orientation det_sign,
               double det_sign_t) {
    if (det_sign.sign == 0) {
      singular_since = true;
    } else if (det_sign.sign != kSignUnknown) {
      // (a change between two steps of a sweep that solves velocities was found at the finest sub-step: no branch
      // was left there)
      if (last_sign.sign != 0 && det_sign != last_sign && !singular_since)
        sum.warnings.push_back(
            {time_of(k), "bifurcation",
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
    StepView view{k, time_of(k), q, opt.velocities ? &qd : nullptr, opt.accelerations ? &qdd : nullptr,
                  points, opt.residuals ? &phi : nullptr, opt.condition ? rcond : 0.0};
    ++sum.steps_completed;
    if (on_step && !on_step(view)) {
      sum.status = SolveStatus::kCancelled;
      sum.message = "stopped by the caller after step " + std::to_string(k);
      return false;
    }
    return true;
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
      sw.row_outputs();
      const State& s = sw.state();
      if (!deliver(k, s.q, s.qd, s.qdd, sw.point_motions(), ws.phi, sw.rcond(), sw.det_sign(), sw.det_sign_time()))
        return false;
    }
    return true;
  }
};

// Adds the work counted in `now` since `before` to `into`.
void add_counters(WorkCounters& into, const WorkCounters& now, const WorkCounters& before) {
  into.newton_iterations += now.newton_iterations - before.newton_iterations;
  into.residual_evaluations += now.residual_evaluations - before.residual_evaluations;
  into.jacobian_evaluations += now.jacobian_evaluations - before.jacobian_evaluations;
  into.factorizations += now.factorizations - before.factorizations;
  into.velocity_solves += now.velocity_solves - before.velocity_solves;
  into.acceleration_solves += now.acceleration_solves - before.acceleration_solves;
  into.phi_t_evaluations += now.phi_t_evaluations - before.phi_t_evaluations;
  into.gamma_evaluations += now.gamma_evaluations - before.gamma_evaluations;
  into.point_evaluations += now.point_evaluations - before.point_evaluations;
}

// Two solutions of the same position problem are the same one if they differ by less than `limit` tolerances in
// every coordinate (each is within about one of the exact root, or of its rounding level; another branch is a
// finite distance away).
bool same_solution(const Model& model, const Eigen::VectorXd& a, const double* b, double tol, double limit) {
  return detail::scaled_distance(model, a.data(), b, a.data(), tol) <= limit;
}

// One parallel chunk: rows k0 … k1 computed from a seed at t_k0 (chunk 0: from row 0), then the sweep continued
// in order one step further (the seam), which the next chunk's first row must match.
// The shortest chunk the automatic choice makes. A chunk costs about three steps besides its own (its seed, the
// start from it, the seam step), so shorter chunks cost more than a second thread gains: 10⁶ scissor stages, 100
// steps on 2 threads, ran slower in chunks of 5 rows (solve 82 s) than in order, and took 12 GB in chunks of 1
// (q, q̇, q̈: rows of 144 MB); chunks of 12 steps still gave 1.5× (chain3d N = 10⁴). Where the rows held for
// delivery leave room for fewer steps per chunk than this, the sweep runs on fewer threads, or in order.
constexpr Index kMinChunkSteps = 8;
// Sub-steps of a positions-only sweep's first seed (see seed_one).
constexpr int kFirstSeedParts = 4;

// to = from (to has from's size), with stores that bypass the caches where the processor has them (SSE2): a
// parallel chunk's rows are read again only when they are delivered, long after, and writing them through the
// caches evicted the chunk's own LU factors and constraints (nfourbar N = 10⁴, 2 threads: 2–3 % of the sweep).
void stream_copy(const Eigen::VectorXd& from, Eigen::VectorXd& to) {
  const Index n = from.size();
  const double* src = from.data();
  double* dst = to.data();
#if defined(__SSE2__)
  Index i = 0;
  if (n > 0 && reinterpret_cast<std::uintptr_t>(dst) % 16 != 0) dst[0] = src[0], i = 1;  // (Eigen aligns to 16)
  for (; i + 2 <= n; i += 2) _mm_stream_pd(dst + i, _mm_loadu_pd(src + i));
  for (; i < n; ++i) dst[i] = src[i];
#else
  std::copy(src, src + n, dst);
#endif
}

// Orders the stores of every stream_copy before it ahead of the stores after it. Once per chunk, not per row: a
// fence waits until the streamed stores have reached memory, which the computation otherwise overlaps (nfourbar
// N = 10³, 2 threads: 0.5 % of the sweep).
void stream_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

// A row computed by a parallel chunk, held until it is delivered in order. Its vectors are delivered as they are
// (no copy into the caller's state per row: on a model whose steps are cheap, copying rows in and out cost a fifth
// of a chunk's time).
struct Row {
  Eigen::VectorXd q, qd, qdd, phi;  // q̇, q̈ as solved, Φ when asked (only what is read again: see keeps_vectors)
  double rcond = 0.0;
  Orientation det_sign{0, 0};
  double det_sign_t = 0.0;  // where det_sign holds (Sweeper::det_sign_time())
  std::vector<PointMotion> points;
};

struct Chunk {
  Index k0 = 0, k1 = 0;
  std::vector<Row> rows;     // rows k0 … k1
  SweepSummary sum;          // status, message, warnings, subdivisions, rcond and work of this chunk
  bool ok = false;
  bool has_seam = false;
  Eigen::VectorXd seam_q;    // the position at t_{k1+1} reached by continuing in order
  double rounding = 0.0;  // largest rounding level (Sweeper::take_rounding_level) of its solves, seed included
};

// What one more thread of a parallel sweep of `ws`'s model takes: the LU (measured, ws has factorised: KLU's peak),
// Φq's values, and the vectors of a workspace and of a sweeper's predictor history, about 16 of n and 4 of m.
// (10⁶ scissor stages: 2.2 GB measured per extra thread; this says 10 × its 0.22 GB at 10⁵.)
double workspace_bytes(const Workspace& ws) {
  const double n = static_cast<double>(ws.q.size()), m = static_cast<double>(ws.phi.size());
  const double lu = ws.lu ? static_cast<double>(ws.lu->memory_bytes()) : 0.0;
  return lu + 8.0 * (static_cast<double>(ws.jacobian_values.size() + ws.solve_values.size()) + 16.0 * n + 4.0 * m);
}

// The memory the system reports available (Linux: MemAvailable), 0 when it reports none.
double available_memory() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return 0.0;
  char line[256];
  double kb = 0.0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "MemAvailable: %lf kB", &kb) == 1) break;
  std::fclose(f);
  return 1024.0 * kb;
}

// The process's resident memory (Linux: /proc/self/statm), 0 when unknown.
double resident_memory() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0.0;
  double size = 0.0, resident = 0.0;
  const bool ok = std::fscanf(f, "%lf %lf", &size, &resident) == 2;
  std::fclose(f);
  return ok ? resident * static_cast<double>(sysconf(_SC_PAGESIZE)) : 0.0;
}

// All cores (threads = 0), as many as fit: each thread beyond the first needs a workspace like the caller's `ws`
// (which has factorised at row 0; the caller's own serves one thread, and the seeding pass shares them), beside the
// rows held for delivery (SweepOptions::row_buffer_bytes at most). memory_budget is the whole process's: what it
// holds already (the model, the caller's workspace) is spent. Fewer threads than `threads` come with a
// "threads_reduced" warning at `t0`.
int threads_that_fit(const SweepOptions& opt, const Workspace& ws, int threads, double t0,
                     std::vector<SweepWarning>& warnings) {
  const double budget =
      opt.memory_budget > 0 ? static_cast<double>(opt.memory_budget) - resident_memory() : available_memory();
  const double per = workspace_bytes(ws);
  if (!(budget > 0.0 || opt.memory_budget > 0) || !(per > 0.0)) return threads;
  const double room =
      std::floor((budget - static_cast<double>(opt.row_buffer_bytes)) / per) + 1.0;  // the caller's is one of them
  if (room >= threads) return threads;
  const int fit = std::max(1, static_cast<int>(std::max(room, 1.0)));
  std::ostringstream m;
  m.precision(3);
  m << "the drive steps run on " << fit << (fit == 1 ? " thread" : " threads") << " instead of " << threads
    << ": each needs a workspace of " << per / 1e9 << " GB (its LU of Φq and its vectors), and ";
  if (opt.memory_budget > 0)
    m << "the budget of " << static_cast<double>(opt.memory_budget) / 1e9 << " GB (memory_budget) leaves "
      << std::max(budget, 0.0) / 1e9 << " GB beside what the run holds";
  else
    m << budget / 1e9 << " GB are available";
  warnings.push_back({t0, "threads_reduced", m.str()});
  return fit;
}

// SweepOptions::chunk_steps = 0: the chunk of a parallel sweep on `threads` threads whose rows take `row_bytes`
// each (held until delivered when `caller_reads_rows`). 64 steps (a chunk costs a seed, a start from it and a seam
// step), but at least 4 chunks per thread, down to 16 steps (so a sweep of 16 steps or fewer runs in order): the
// seed of a chunk is one step over the chunk's whole span, and on a large model long spans are expensive (Newton
// from far away, sub-steps). Measured, 100 steps on 2 threads against 1 thread: chain3d N = 10⁴ positions only 1.5×
// with 9 chunks of 12 steps, 0.9–1.0× with 2 of 50; nfourbar N = 10³ with q̇, q̈ 1.45× either way. More chunks also
// balance more threads (tools/simulate_schedule.py). Fewer steps when the rows a chunk per thread holds would
// exceed row_buffer_bytes, and none below kMinChunkSteps: `threads` is then lowered to as many as have room for
// such chunks, the rest of the cores left to the model's parallel evaluation (1: in order), with a
// "threads_reduced" warning at `t0` (only where the sweep could run in parallel chunks: `parallel`).
Index automatic_chunk_steps(const SweepOptions& opt, double row_bytes, bool caller_reads_rows, bool parallel,
                            double t0, int& threads, std::vector<SweepWarning>& warnings) {
  const Index balanced = std::max<Index>(16, opt.steps / (4 * static_cast<Index>(threads)));
  Index chunk = std::min<Index>(64, balanced);
  const double rows_fit = static_cast<double>(opt.row_buffer_bytes) / row_bytes;  // rows the buffer holds
  if (!caller_reads_rows || rows_fit >= static_cast<double>(chunk * threads)) return chunk;
  const int room = static_cast<int>(std::min<double>(threads, std::floor(rows_fit / kMinChunkSteps)));
  if (room < threads && opt.steps > kMinChunkSteps && parallel) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "the drive steps run "
        << (room >= 2 ? "in parallel chunks on " + std::to_string(room) + " threads instead of "
                      : std::string("in order, not in parallel chunks on "))
        << threads << " threads: a row of the outputs is " << row_bytes / 1e6
        << " MB, and the rows held for delivery in order (SweepOptions::row_buffer_bytes, "
        << static_cast<double>(opt.row_buffer_bytes) / 1e6 << " MB) hold " << static_cast<long long>(rows_fit)
        << " rows: chunks of " << kMinChunkSteps << " steps, the fewest that pay for a chunk's seed, for "
        << (room >= 2 ? "only " + std::to_string(room) + " threads" : std::string("no more than one thread"))
        << "; the other threads still serve the model's parallel evaluation";
    warnings.push_back({t0, "threads_reduced", msg.str()});
    threads = std::max(room, 1);
  }
  return std::max<Index>(1, std::min<Index>(chunk, static_cast<Index>(rows_fit / threads)));
}

// run_sweep's body, run inside a task arena of `threads` (run_sweep's count: opt.threads, or all cores for 0).
SolveStatus sweep_in_arena(const Model& model, const SweepOptions& opt, Workspace& ws,
                           const std::function<bool(const StepView&)>& on_step, SweepSummary* summary,
                           int threads) {
  if (&ws.model() != &model) throw Error("workspace was made for another model");
  if (opt.steps < 0) throw Error("SweepOptions: steps must be >= 0");
  if (!std::isfinite(opt.t_begin) || !std::isfinite(opt.t_end)) throw Error("SweepOptions: times must be finite");
  if (const std::string why = detail::time_grid_problem(opt.t_begin, opt.t_end, opt.steps); !why.empty())
    throw Error("SweepOptions: " + why);
  if (opt.chunk_steps < 0) throw Error("SweepOptions: chunk_steps must be >= 0 (0: automatic)");
  if (opt.row_buffer_bytes == 0) throw Error("SweepOptions: row_buffer_bytes must be > 0");
  if (opt.max_subdivisions < 0) throw Error("SweepOptions: max_subdivisions must be >= 0");
  const std::vector<Predictor>& predictors = all_predictors();
  if (std::find(predictors.begin(), predictors.end(), opt.predictor) == predictors.end())
    throw Error("SweepOptions: predictor is not a Predictor");
  detail::check_newton_options(opt.assembly, "SweepOptions::assembly");
  detail::check_newton_options(opt.newton, "SweepOptions::newton");
  for (const OutputPoint& p : opt.points)
    if (p.max_coordinate() >= model.num_coordinates())
      throw Error("SweepOptions: output point '" + p.name + "' reads a coordinate the model does not have");
  SweepSummary local;
  SweepSummary& sum = summary ? *summary : local;
  sum = SweepSummary{};
  const auto start = std::chrono::steady_clock::now();
  const WorkCounters before = ws.counters;
  WorkCounters others;  // work done in the seeding and chunk workspaces
  // Work done in the caller's workspace between these two counts is counted in `others` already (the parallel
  // part's chunks and seeds): left out of the workspace's share.
  WorkCounters counted_begin{}, counted_end{};
  auto done = [&](SolveStatus st) {
    detail::once_per_stretch(sum.warnings, "slow_convergence", opt);
    sum.status = st;
    sum.counters = others;
    add_counters(sum.counters, ws.counters, before);
    add_counters(sum.counters, counted_begin, counted_end);  // − (counted_end − counted_begin)
    sum.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return st;
  };

  const double lo = std::min(opt.t_begin, opt.t_end), hi = std::max(opt.t_begin, opt.t_end);
  if (lo < model.time_domain_begin() || hi > model.time_domain_end()) {
    const double bad = lo < model.time_domain_begin() ? lo : hi;
    sum.failed_step = lo < model.time_domain_begin() ? (opt.t_begin <= opt.t_end ? 0 : opt.steps)
                                                     : (opt.t_begin <= opt.t_end ? opt.steps : 0);
    sum.failed_time = bad;
    sum.message = "t = " + format_time(bad) + ": driver '" + model.time_domain_limiter() + "' is defined on [" +
                  format_time(model.time_domain_begin()) + ", " + format_time(model.time_domain_end()) +
                  "] only; the sweep runs over [" + format_time(lo) + ", " + format_time(hi) + "]";
    return done(SolveStatus::kOutsideTimeDomain);
  }

  Run run{opt, on_step, sum};
  run.h = opt.steps > 0 ? (opt.t_end - opt.t_begin) / static_cast<double>(opt.steps) : 0.0;
  Sweeper sw(model, opt, ws, sum);
  if (!sw.assemble(run.time_of(0))) {
    run.failed(0);
    return done(sum.status);
  }
  sw.row_outputs();
  if (!run.deliver(0, sw.state().q, sw.state().qd, sw.state().qdd, sw.point_motions(), ws.phi, sw.rcond(),
                   sw.det_sign(), sw.det_sign_time())) {
    sw.leave_state_in_workspace();
    return done(sum.status);
  }

  if (opt.threads == 0 && threads > 1 && ws.lu && opt.steps > 0)
    threads = threads_that_fit(opt, ws, threads, run.time_of(0), sum.warnings);
  const Index n = model.num_coordinates();
  // Rows keep q̇ whenever it is solved (q̈ needs it, and so does an ordered continuation's predictor).
  const bool need_v = opt.velocities || opt.accelerations, need_a = opt.accelerations;
  // a row's layout in the chunk buffers: q, q̇, q̈ as solved, then Φ, rcond and the point motions as asked
  const Index m = model.num_equations();
  const Index n_phi = opt.residuals ? m : 0, n_rcond = opt.condition ? 1 : 0;
  const Index n_points = static_cast<Index>(opt.points.size());
  constexpr Index kMotionDoubles = static_cast<Index>(sizeof(PointMotion) / sizeof(double));
  static_assert(sizeof(PointMotion) == 9 * sizeof(double), "PointMotion is stored as 9 doubles in chunk rows");
  const Index width = n * (1 + (need_v ? 1 : 0) + (need_a ? 1 : 0)) + n_phi + n_rcond + n_points * kMotionDoubles + 1;
  // Which of a chunk's rows keep their vectors: all of them for a caller that reads the rows. Without one (a sweep
  // for its summary and last state), only what the parallel sweep reads again itself: the first row's q (the seam
  // check) and the last row (the state an ordered continuation starts from). Copying the rows in between was 3 % of
  // a 2-thread sweep of nfourbar N = 10³ that nobody read.
  const bool caller_reads_rows = static_cast<bool>(on_step);
  auto keeps_vectors = [&](const std::vector<Row>& rows, std::size_t i) {
    return caller_reads_rows || i == 0 || i + 1 == rows.size();
  };
  const double row_bytes = 8.0 * static_cast<double>(std::max<Index>(width, 1));
  auto held_bytes = [&](Index rows) {  // what a chunk of `rows` rows holds until it is delivered (keeps_vectors)
    return row_bytes * static_cast<double>(caller_reads_rows ? rows : std::min<Index>(rows, 2));
  };
  Index chunk = opt.chunk_steps;
  if (chunk == 0)
    chunk = automatic_chunk_steps(opt, row_bytes, caller_reads_rows, ws.lu != nullptr, run.time_of(0), threads,
                                  sum.warnings);
  const Index n_chunks = (opt.steps + chunk - 1) / chunk;  // chunk c: rows 1 + c·chunk … min(steps, (c+1)·chunk)
  if (threads <= 1 || n_chunks < 2 || !ws.lu) {
    run.sequential(sw, ws, 1);
    sw.leave_state_in_workspace();
    return done(sum.status);
  }

  // ---- parallel drive steps ------------------------------------------------------------------------------
  sum.threads = threads;
  auto first_row = [&](Index c) { return 1 + c * chunk; };
  auto last_row = [&](Index c) { return std::min(opt.steps, (c + 1) * chunk); };

  // Workspaces, taken from a pool for the time of one chunk or one seed: the caller's own (idle otherwise) and as
  // many more as are in use at once, one per thread, since the seeding pass takes one only while it finds a seed.
  // On large models a workspace is mostly the LU of Φq (10⁶ scissor stages: 1.5 GB), so that is what the memory
  // of a parallel sweep grows by per thread. Not one per thread index: a thread waiting inside a nested parallel
  // evaluation (large models) may start other work meanwhile, which then needs a workspace of its own. The work
  // done in each is counted with the chunk or seed that did it; the caller's workspace's share is taken out of its
  // own count at the end (ws_in_parallel).
  std::vector<std::unique_ptr<Workspace>> owned;
  std::vector<Workspace*> pool{&ws};
  std::mutex pool_mutex;
  auto acquire = [&] {
    std::lock_guard<std::mutex> lock(pool_mutex);
    if (pool.empty()) {
      owned.push_back(std::make_unique<Workspace>(model));
      return owned.back().get();
    }
    Workspace* w = pool.back();
    pool.pop_back();
    w->newton_contraction = -1.0;  // measured by its last user, on other steps
    return w;
  };
  auto release = [&](Workspace* w) {
    std::lock_guard<std::mutex> lock(pool_mutex);
    pool.push_back(w);
  };
  counted_begin = ws.counters;

  // The last delivered row (the state an ordered continuation starts from) and the position the sweep reaches
  // one step after it when continued in order (the previous chunk's seam), if known. The caller's sweeper is not
  // used again: its state moves here and its history is freed.
  Index resume = 1;
  State row0 = sw.take_state();
  Eigen::VectorXd last_q = std::move(row0.q), last_qd = need_v ? std::move(row0.qd) : ws.qd,
                  last_qdd = need_a ? std::move(row0.qdd) : ws.qdd;
  bool seam_known = false;
  Eigen::VectorXd seam_q;
  double seam_rounding = 0.0;
  std::vector<Eigen::VectorXd> seeds(static_cast<std::size_t>(n_chunks));  // seeds[c]: chunk c's first row (not 0)
  std::vector<double> seed_rounding(static_cast<std::size_t>(n_chunks), 0.0);  // the seeder's rounding level there
  std::vector<double> seed_error(static_cast<std::size_t>(n_chunks), INFINITY);  // and its error estimate

  // Buffers for the rows' q, q̇, q̈: those of delivered rows, and those the workspace kept from its last parallel
  // sweep (Workspace::spare_rows), so that the rows are written into memory the process has already touched.
  std::mutex spare_mutex;
  std::vector<Eigen::VectorXd> spare;
  spare.swap(ws.spare_rows);
  const Index n_coords = model.num_coordinates();
  std::erase_if(spare, [&](const Eigen::VectorXd& v) { return v.size() != n_coords; });
  auto take_buffers = [&](std::vector<Row>& rows) {
    std::lock_guard<std::mutex> lock(spare_mutex);
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (Eigen::VectorXd* v : {&rows[i].q, need_v ? &rows[i].qd : nullptr, need_a ? &rows[i].qdd : nullptr}) {
        if (!v || !keeps_vectors(rows, i)) continue;
        if (spare.empty()) {
          v->resize(n_coords);
        } else {
          v->swap(spare.back());
          spare.pop_back();
        }
      }
  };
  auto give_buffers = [&](std::vector<Row>& rows) {
    std::lock_guard<std::mutex> lock(spare_mutex);
    for (Row& r : rows)
      for (Eigen::VectorXd* v : {&r.q, &r.qd, &r.qdd})
        if (v->size() == n_coords) spare.push_back(std::move(*v));
  };
  // Chunk c: its rows from its seed (chunk 0: in order from row 0), then the seam step.
  auto run_chunk = [&](Index c, Chunk& ch) {
    Workspace* held = acquire();
    Workspace& w = *held;
    const WorkCounters w0 = w.counters;
    ch.k0 = first_row(c), ch.k1 = last_row(c);
    Sweeper s(model, opt, w, ch.sum);
    ch.rows.resize(static_cast<std::size_t>(ch.k1 - ch.k0 + 1));
    take_buffers(ch.rows);
    std::size_t kept = 0;
    auto keep = [&] {
      const State& st = s.state();
      Row& r = ch.rows[kept];
      s.row_outputs();
      r.det_sign = s.det_sign(), r.det_sign_t = s.det_sign_time();  // (the bifurcation check reads every row's)
      if (!keeps_vectors(ch.rows, kept++)) return;
      stream_copy(st.q, r.q);
      if (need_v) stream_copy(st.qd, r.qd);
      if (need_a) stream_copy(st.qdd, r.qdd);
      if (n_phi) r.phi = w.phi;
      r.rcond = s.rcond();
      if (n_points) r.points.assign(s.point_motions(), s.point_motions() + n_points);
    };
    if (c == 0) {  // continues row 0 in order: the sequential sweep itself
      w.q = last_q, w.qd = last_qd, w.qdd = last_qdd;
      s.adopt(run.time_of(0));
      ch.ok = s.advance(run.time_of(ch.k0), 0);
    } else {
      ch.ok = s.start_from(run.time_of(ch.k0), seeds[static_cast<std::size_t>(c)],
                           seed_error[static_cast<std::size_t>(c)]);
    }
    if (ch.ok) keep();
    for (Index k = ch.k0 + 1; ch.ok && k <= ch.k1; ++k)
      if ((ch.ok = s.advance(run.time_of(k), 0))) keep();
    if (ch.ok && ch.k1 < opt.steps) {
      // the seam row belongs to the next chunk: its warnings and sub-steps are counted there
      const SweepSummary kept = ch.sum;
      if (s.advance_position(run.time_of(ch.k1 + 1))) {
        ch.has_seam = true;
        ch.seam_q = s.state().q;
      }
      ch.sum.warnings = kept.warnings;
      ch.sum.subdivisions = kept.subdivisions;
      ch.sum.singular_positions = kept.singular_positions;
      ch.sum.status = kept.status, ch.sum.message = kept.message;
      ch.sum.min_rcond = kept.min_rcond, ch.sum.min_rcond_time = kept.min_rcond_time;
    }
    ch.rounding = std::max(s.take_rounding_level(), c > 0 ? seed_rounding[static_cast<std::size_t>(c)] : 0.0);
    add_counters(ch.sum.counters, w.counters, w0);
    release(held);
    stream_fence();  // the chunk's streamed rows are complete before it is marked done for the delivering thread
  };

  // Accepts and delivers a computed chunk: 0 delivered, 1 rejected (the rest runs in order), 2 stopped by the
  // caller. A chunk is the sequential sweep's continuation if it starts where the sweep, continued in order from
  // the last delivered row, arrives (chunk 0 is that continuation by construction).
  auto deliver_chunk = [&](Chunk& ch) {
    add_counters(others, ch.sum.counters, WorkCounters{});
    // Two solutions of the same problem agree to 100 tolerances, or, where Newton stopped at the rounding level
    // (a long chain), to 10× how well that stop says q is known: another branch is a finite distance away.
    const double limit = std::max(100.0, 10.0 * std::max(seam_rounding, ch.rounding));
    const bool accept = ch.ok && (ch.k0 == 1 || (seam_known && same_solution(model, seam_q, ch.rows[0].q.data(),
                                                                             opt.newton.tolerance, limit)));
    if (!accept) return 1;
    for (Index k = ch.k0; k <= ch.k1; ++k) {
      const Row& r = ch.rows[static_cast<std::size_t>(k - ch.k0)];
      if (!run.deliver(k, r.q, r.qd, r.qdd, n_points ? r.points.data() : nullptr, r.phi, r.rcond, r.det_sign,
                       r.det_sign_t)) {
        last_q = r.q, last_qd = need_v ? r.qd : last_qd, last_qdd = need_a ? r.qdd : last_qdd;  // where it stopped
        return 2;
      }
    }
    // the state an ordered continuation starts from: the chunk's last row (it is freed once delivered)
    Row& last = ch.rows.back();
    last_q.swap(last.q);
    if (need_v) last_qd.swap(last.qd);
    if (need_a) last_qdd.swap(last.qdd);
    resume = ch.k1 + 1;
    seam_known = ch.has_seam;
    if (seam_known) seam_q.swap(ch.seam_q), seam_rounding = ch.rounding;
    sum.subdivisions += ch.sum.subdivisions;
    sum.singular_positions += ch.sum.singular_positions;
    sum.warnings.insert(sum.warnings.end(), ch.sum.warnings.begin(), ch.sum.warnings.end());
    if (ch.sum.min_rcond > 0.0 && (sum.min_rcond == 0.0 || ch.sum.min_rcond < sum.min_rcond))
      sum.min_rcond = ch.sum.min_rcond, sum.min_rcond_time = ch.sum.min_rcond_time;
    ++sum.parallel_chunks;
    return 0;
  };

  // How far the work may run ahead of the delivery: chunks seeded beyond the next one to deliver. As many as the
  // row buffer allows, at least one per thread, and at most 16 per thread so that rows are delivered (and Ctrl-C
  // seen) every few thousand steps however long the sweep.
  const Index ahead = std::max<Index>(
      threads,
      std::min<Index>(16 * threads, static_cast<Index>(static_cast<double>(opt.row_buffer_bytes) / held_bytes(chunk))));

  // Seeds: the position at each chunk's first row, found in order with the chunk's span as the step (positions
  // only, the parabolic predictor over the seeds before, subdivision on failure), one at a time, just ahead of the
  // chunks that need them.
  // A failure ends the seeding; the chunks after it run in order below, where the failure is reported as the
  // sequential sweep reports it.
  SweepOptions seed_options = opt;
  seed_options.velocities = seed_options.accelerations = false;
  seed_options.predictor = Predictor::kParabolic;
  seed_options.points.clear(), seed_options.residuals = seed_options.condition = false;  // seeds deliver no rows
  SweepSummary seed_summary;
  WorkCounters seed_work;  // done in pool workspaces by the seeding pass
  Workspace* sws = acquire();
  sws->q = last_q;
  Sweeper seeder(model, seed_options, *sws, seed_summary);
  seeder.adopt(run.time_of(0));
  release(sws);

  // The schedule. `threads` loops run the work as it becomes ready: the seeding (in order, one thread at a time,
  // first whenever fewer chunks are ready than threads, so that it stays ahead) and the seeded chunks (lowest
  // first). A chunk starts as soon as its seed is known, not in waves, so no thread waits for a wave's slowest
  // chunk. The calling thread alone delivers, in order, each chunk as soon as it and all before it are done: the
  // caller's on_step runs on the caller's thread, as in a sequential sweep, overlapped with the other threads'
  // chunks.
  std::mutex mutex;
  std::condition_variable wake;
  std::vector<Chunk> chunks(static_cast<std::size_t>(n_chunks));
  std::vector<char> chunk_done(static_cast<std::size_t>(n_chunks), 0);
  Index seeded = 1;            // chunks 0 … seeded − 1 have their seed (chunk 0 starts from row 0)
  Index claimed = 0;           // chunks 0 … claimed − 1 have been taken by a thread
  Index delivered = 0;         // chunks 0 … delivered − 1 have been delivered
  bool seeding_busy = false;   // a thread is finding a seed
  bool seeding_over = n_chunks <= 1;  // every seed found, or the seeding failed
  bool stop = false;           // a chunk was rejected (fallback) or the caller stopped the sweep
  bool cancelled = false;
  bool fallback = false;
  const std::thread::id caller = std::this_thread::get_id();

  auto seed_one = [&] {  // finds seed `seeded` (the lock is not held)
    const auto seed_start = std::chrono::steady_clock::now();
    const Index c = seeded;  // only the thread holding seeding_busy changes it
    Workspace* w = acquire();
    const WorkCounters w0 = w->counters;
    seeder.bind(*w);
    // Without derivatives at row 0 (positions only), the first seed is the one extrapolated from a single position
    // over a whole chunk's span: from that constant prediction its Newton failed on nfourbar N = 10⁵ and took 0.57 s
    // of a 1.66 s sweep. In sub-steps it gives the parabola through the seeds its first rows: 1.35 s.
    const int parts = c == 1 && !need_v ? kFirstSeedParts : 1;
    const double t0 = seeder.state().t, t1 = run.time_of(first_row(c));
    bool ok = true;
    for (int i = 1; ok && i <= parts; ++i)
      ok = seeder.advance(i == parts ? t1 : t0 + (t1 - t0) * static_cast<double>(i) / parts, 0);
    add_counters(seed_work, w->counters, w0);
    release(w);
    if (ok) {
      seeds[static_cast<std::size_t>(c)] = seeder.state().q;
      seed_error[static_cast<std::size_t>(c)] = seeder.state_error();
      seed_rounding[static_cast<std::size_t>(c)] = seeder.take_rounding_level();
    }
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - seed_start).count();
    std::lock_guard<std::mutex> lock(mutex);
    sum.seed_seconds += took;
    if (ok) ++seeded;
    seeding_over = !ok || seeded == n_chunks;
    seeding_busy = false;
    wake.notify_all();
  };
  // The caller's deliveries: every chunk done in order (the lock is held on entry and on return).
  auto deliver_ready = [&](std::unique_lock<std::mutex>& lock) {
    while (!stop && delivered < claimed && chunk_done[static_cast<std::size_t>(delivered)]) {
      Chunk& ch = chunks[static_cast<std::size_t>(delivered)];
      lock.unlock();
      const int d = deliver_chunk(ch);
      give_buffers(ch.rows);
      ch.rows = std::vector<Row>();  // delivered: free
      seeds[static_cast<std::size_t>(delivered)] = Eigen::VectorXd();
      lock.lock();
      if (d != 0) {
        stop = true, cancelled = d == 2, fallback = d == 1;
      } else {
        ++delivered;
      }
      wake.notify_all();
    }
  };
  auto work_loop = [&] {
    const bool is_caller = std::this_thread::get_id() == caller;
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      if (is_caller) deliver_ready(lock);
      if (stop) return;
      const Index ready = seeded - claimed;
      const bool can_seed = !seeding_busy && !seeding_over && seeded < std::min(n_chunks, delivered + ahead + 1);
      if (can_seed && ready < threads) {  // (with no chunk ready, always: threads ≥ 2 here)
        seeding_busy = true;
        lock.unlock();
        tbb::this_task_arena::isolate(seed_one);  // nested evaluations wait only for their own tasks
        lock.lock();
      } else if (ready > 0) {
        const Index c = claimed++;
        lock.unlock();
        tbb::this_task_arena::isolate([&] { run_chunk(c, chunks[static_cast<std::size_t>(c)]); });
        lock.lock();
        chunk_done[static_cast<std::size_t>(c)] = 1;
        wake.notify_all();
      } else if (seeding_over && !seeding_busy && claimed == seeded && (!is_caller || delivered == claimed)) {
        return;  // nothing more will become ready (the caller: and everything done is delivered)
      } else {
        wake.wait(lock);  // for a seed, a finished chunk (the caller) or a delivery (the window)
      }
    }
  };
  // An exception (the caller's on_step may throw) stops every loop, so that none waits for the thrower, and is
  // rethrown once they have all returned.
  std::exception_ptr failure;
  auto work = [&] {
    try {
      work_loop();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      stop = true;
      if (!failure) failure = std::current_exception();
      wake.notify_all();
    }
  };
  tbb::parallel_for(
      tbb::blocked_range<int>(0, threads, 1),
      [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k < r.end(); ++k) work();
      },
      tbb::simple_partitioner());
  // the row buffers go back to the workspace for its next parallel sweep, up to Workspace::kSpareRowBytes
  const std::size_t keep = static_cast<std::size_t>(Workspace::kSpareRowBytes / (8.0 * std::max<Index>(n_coords, 1)));
  if (spare.size() > keep) spare.resize(keep);
  ws.spare_rows.swap(spare);
  if (failure) std::rethrow_exception(failure);
  // chunks computed but not delivered (after a rejected one): their work was done all the same
  for (Index c = delivered + (stop ? 1 : 0); c < claimed; ++c)
    add_counters(others, chunks[static_cast<std::size_t>(c)].sum.counters, WorkCounters{});
  add_counters(others, seed_work, WorkCounters{});
  counted_end = ws.counters;  // the caller's workspace's work so far is the chunks' and seeds'
  // The caller's workspace ends at the last delivered row, as after a sequential sweep.
  ws.q = last_q;
  if (need_v) ws.qd = last_qd;
  if (need_a) ws.qdd = last_qdd;
  if (cancelled) return done(sum.status);
  if (resume <= opt.steps) {
    // In order from the last delivered row: the unseeded chunks, or everything after a chunk that did not
    // continue the sweep's branch or failed (the failure is then found, and reported, in order).
    if (fallback)
      sum.warnings.push_back({run.time_of(resume), "parallel_fallback",
                              "the parallel chunk starting at t = " + format_time(run.time_of(resume)) +
                                  " did not continue the sweep in order (another branch, or a failure); the "
                                  "remaining steps ran in order"});
    Sweeper rest(model, opt, ws, sum);
    rest.adopt(run.time_of(resume - 1));
    run.sequential(rest, ws, resume);
    rest.leave_state_in_workspace();
  }
  return done(sum.status);
}

}  // namespace

SolveStatus run_sweep(const Model& model, const SweepOptions& opt, Workspace& ws,
                      const std::function<bool(const StepView&)>& on_step, SweepSummary* summary) {
  if (opt.threads < 0) throw Error("SweepOptions: threads must be >= 0 (0: all cores)");
  // Everything the sweep runs, the model's parallel evaluation of large models included, stays on its threads:
  // threads = 1 is one thread.
  const int threads = opt.threads == 0 ? tbb::info::default_concurrency() : opt.threads;
  tbb::task_arena arena(threads);
  return arena.execute([&] { return sweep_in_arena(model, opt, ws, on_step, summary, threads); });
}

}  // namespace phiq
