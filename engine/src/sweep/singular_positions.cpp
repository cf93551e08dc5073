// Singular positions, where Φq loses rank: a bifurcation the sweep passes (Sweeper::singular_point() reports the
// branch's own velocity, extrapolated from both sides, with a warning), a model singular all along its motion
// (singular_throughout()), and a dead point, where the drive cannot go on (dead_point(), lined_up_equations():
// which equations line up there). Apart from the step loop (sweeper.cpp) because they run only where Φq is
// singular or a step has failed.
#include "sweep/sweeper.hpp"

#include <iomanip>

#include "phiq/assembly.hpp"
#include "phiq/text.hpp"
#include "solve/block_triangular.hpp"

namespace phiq::detail {

namespace {
constexpr int kSides = 6;            // the regular points a singular row's derivatives are extrapolated from
constexpr double kSideOffset = 0.6;  // δ, as a fraction of the step: the sides are t ± δ, ± 2δ, ± 3δ
// δ where the sweep starts at the singular position and its first side is reached by the least-squares assembly from
// the singular position itself (a single loop: no block-triangular form to solve it by), with nothing of the motion
// to predict from: kept as close as before the sides moved out, and the start's derivatives are known the less well
// for it.
constexpr double kStartSideOffset = 0.05;
// δ at a start reached block by block (assemble_by_blocks). Not kSideOffset: from a flat start the chain adds up the
// sides' rounding, divided by Φq's smallest singular value, O(δ), twice. nfourbar N = 10⁴ started flat at rate 3π/4,
// steps of 0.01: q̈ at the start 7e-9 relative off the exact with 0.45, 1.2e-7 with 0.6, 0.39 with 0.05.
constexpr double kBlockStartSideOffset = 0.45;
}  // namespace

// The regular points around a singular position (singular_point()): their offset δ, whether the sweep's start was
// solved block by block, and their states at t − 3δ, t − 2δ, t − δ, t + δ, t + 2δ, t + 3δ.
struct SingularSides {
  double d = 0.0;
  bool by_blocks = false;
  State side[kSides];
};

// Why Φq stays singular on both sides of the singular position qs at t: the model is short of drivers or
// constraints all along its motion (": redundant or missing constraints"), or the position is singular by itself,
// several loops folded or aligned at once and kept so by the drive (nfourbar started folded: every coupler on
// its neighbour's crank, the far loops staying so as crank 0 turns), which a solution assembled near it, fully
// driven, tells (detail::driven_dof_nearby).
std::string Sweeper::singular_throughout(const Eigen::VectorXd& qs, double t) {
  RankReport rank;
  const Index nearby = detail::driven_dof_nearby(model_, qs, t, assembly_options(opt_.newton), &rank);
  if (nearby > 0) {  // square, and short of rank everywhere near: as many redundant rows as freedoms not driven
    std::string names;
    for (const std::string& n : rank.redundant) names += (names.empty() ? "'" : ", '") + n + "'";
    return ": redundant or missing constraints: " + std::to_string(nearby) + " degree(s) of freedom not driven" +
           (names.empty() ? std::string()
                          : ", the equations as many as the coordinates only by the redundant " + names);
  }
  if (nearby < 0)
    return ": redundant or missing constraints, or several loops folded or aligned at once (no solution near it "
           "was assembled to tell which)";
  return std::string(
             " on the branch the drive follows from there, though a solution near it is regular: the "
             "position is singular, several loops folded or aligned at once, rather than the model short "
             "of drivers or constraints") +
         (has_current_ ? "" : "; start the drive off it");
}

// Φq is singular at the converged position ws.q at t (rcond below kSingularRcond, or a zero pivot): a
// bifurcation, where branches of the motion cross and the mechanism momentarily gains degrees of freedom
// (nfourbar at its horizontal positions, a change-point four-bar). The velocity there is not unique, and the
// LU's answer is rounding noise in the directions Φq no longer constrains. The branch the sweep follows has its
// own velocity, the limit from both sides: reported is the Richardson extrapolation of the symmetric means of
// the derivatives at t ± δ, t ± 2δ and t ± 3δ (δ = kSideOffset of the step, all six regular), which differs from
// that limit by O(δ⁶), with a warning. The sides' own errors ε (their positions are solved to rounding level) grow
// to ε/δ in q̇ and ε/δ² in q̈ (Φq's smallest singular value is O(δ) there), so δ is not small: nfourbar N = 100
// through its flat positions (1440 steps over two turns), relative to the exact q̈: 2e-6 with four sides at 5 % of
// the step, 1e-8 at 30 %. Six sides, on its four flat rows of 1712 steps: 2.0–2.4e-8 at 30 %, 0.6–1.2e-8 at 45 %,
// 1.1–2.7e-9 at 60 %, 0.5–1.2e-9 at 80 % (q̇ 2–7e-12 from 60 %); the estimate of the truncation below grows from
// 9e-10 at 45 % to 2–3e-10 and 2e-10 on that fine grid, and on the change-point four-bar's one-degree steps
// (models/hard/change_point_exact.yaml) from 6e-10 to 2e-9 at 60 %, where ψ2's q̈ (exactly 0) went from
// −6.5e-9 to −3.6e-9. 60 % keeps the sides within 1.8 steps. The truncation grows as the step's sixth power, so a
// coarse grid's singular rows are known less well, and their warning says how well. The warning states how far the
// O(δ⁴) extrapolation from the inner four sides differs from the reported one: the truncation left, at most. The
// plus side is reached straight through from the minus side, so the sweep keeps its branch. When there is no
// position beyond (a dead point: the drive cannot go on) or the sides are singular too (the model is singular
// on an interval: redundant or missing constraints), the step fails with that diagnosis.
// `have_position`: false when Newton could not converge at t itself (a zero pivot exactly at the singular
// point); the position is then extrapolated the same way, to O(δ⁴), and checked against the tolerance.
bool Sweeper::singular_point(double t, double rc, bool have_position) {
  struct Guard {
    bool& b;
    ~Guard() { b = false; }
  } guard{singular_.bracketing = true};
  const Eigen::VectorXd qs = ws_->q;
  // named now, from Φq factorised at the singular position itself, in case it is a dead point
  const std::string lined_up = ws_->has_factorization ? lined_up_equations() : "";
  double step = has_current_ ? t - current_.t : default_step_;
  if (step == 0.0) step = 1e-3;
  // The sides are solved to rounding level: their derivatives divide O(δ) quantities by Φq's smallest
  // singular value, O(δ), so a position error ε_q becomes a velocity error ε_q/δ (and worse in q̈).
  NewtonOptions tight = opt_.newton;
  tight.tolerance = std::max(1e-4 * opt_.newton.tolerance, 1e-15);
  tight.known_to = 0.0;  // a level in units of the sweep's tolerance: not this one's, and these reach rounding
  tight.jacobian_update = JacobianUpdate::kEveryIteration;
  tight.max_iterations = std::max(tight.max_iterations, 30);
  SingularSides sides;
  sides.by_blocks = !has_current_ && start_by_blocks(t, step, qs, tight);
  sides.d = (has_current_ ? kSideOffset : sides.by_blocks ? kBlockStartSideOffset : kStartSideOffset) * step;
  if (!solve_sides(t, rc, qs, lined_up, tight, sides)) return false;
  return take_branch_values(t, rc, have_position, qs, sides);
}

// The sweep starts at the singular position: no past motion tells the branch, and Newton cannot start from a
// singular Φq. A model whose Φq pattern falls into blocks (a chain of loops) is solved block by block
// (assemble_by_blocks), at the first side's time: each loop then starts with its input already moved, and one
// singular at the start moves the least it must. (Whole-system Newton moves one loop per iteration: nfourbar
// started flat has its far cranks leave the flat position one loop per least-squares step, so no chain longer
// than the iteration budget would be reached.) Leaves ws.q at that first side when it succeeds, at qs otherwise.
bool Sweeper::start_by_blocks(double t, double step, const Eigen::VectorXd& qs, const NewtonOptions& tight) {
  ws_->q = qs;
  detail::BlockAssemblySummary bs;
  const bool by_blocks = detail::assemble_by_blocks(model_, t - 3 * kBlockStartSideOffset * step, tight.tolerance,
                                                    tight.max_iterations, ws_->q, &bs) == SolveStatus::kSuccess;
  if (!by_blocks) ws_->q = qs;
  return by_blocks;
}

// Six regular points t ± δ, t ± 2δ, t ± 3δ, each predicted from the one before (the first from the last state of
// the sweep), so the plus side is reached straight through the singular point. Fails (summary filled, ws.q = qs)
// where a side cannot be reached or is singular too, saying which.
bool Sweeper::solve_sides(double t, double rc, const Eigen::VectorXd& qs, const std::string& lined_up,
                          const NewtonOptions& tight, SingularSides& s) {
  const double d = s.d;
  const double offset[kSides] = {-3 * d, -2 * d, -d, d, 2 * d, 3 * d};
  LinearSummary ls;
  PositionSummary ps;
  for (int k = 0; k < kSides; ++k) {
    const double ts = t + offset[k];
    if (k == 0) {
      if (has_current_)
        predict(ts);
      else if (!reach_first_side(t, ts, rc, qs, s.by_blocks, tight, ps))
        return false;
    } else {
      const double h = offset[k] - offset[k - 1];
      ws_->q = s.side[k - 1].q + h * s.side[k - 1].qd + (0.5 * h * h) * s.side[k - 1].qdd;
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
      if (k >= kSides / 2 && !position_found)
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
    s.side[k].t = ts, s.side[k].q = ws_->q, s.side[k].qd = ws_->qd, s.side[k].qdd = ws_->qdd;
  }
  return true;
}

// The first side of a sweep that starts at the singular position qs: (unless solved block by block already) the
// assembly (least squares, then the solution nearest the placement) finds the side's position nearest the start,
// and Newton (regular at ts) finishes from wherever it got, converged or not. Fails (ws.q = qs) where neither
// reaches the branch.
bool Sweeper::reach_first_side(double t, double ts, double rc, const Eigen::VectorXd& qs, bool by_blocks,
                               const NewtonOptions& tight, PositionSummary& ps) {
  AssemblyOptions ao;
  ao.tolerance = opt_.newton.tolerance;
  AssemblySummary as;
  const SolveStatus assembled = by_blocks ? SolveStatus::kSuccess : phiq::assemble(model_, ts, ao, ws_->q, &as);
  if (assembled != SolveStatus::kSuccess && ws_->q.allFinite() &&
      solve_position(model_, ts, tight, *ws_, &ps) != SolveStatus::kSuccess) {
    // Not a model short of constraints (the placement assembled and is square): the start is singular and the
    // least squares from it did not reach the branch beyond it. Said as such, with the assembly's account, rather
    // than as a zero pivot that the rank analysis of the singular position would blame on missing drivers.
    ws_->q = qs;
    return fail(SolveStatus::kSingularJacobian,
                "the sweep starts at a singular position (t = " + format_time(t) + ", Φq rcond " + scientific(rc, 2) +
                    "), and no regular position of the branch near it was reached at t = " + format_time(ts) +
                    " from it (" + as.BriefReport() +
                    "): the position is singular, not the model short of drivers or constraints; start the drive off "
                    "it");
  }
  if (!ws_->q.allFinite()) {
    ws_->q = qs;
    return fail(SolveStatus::kSingularJacobian, "the sweep starts at a singular position (t = " + format_time(t) +
                                                    "), and no position near it at t = " + format_time(ts) +
                                                    " was found: " + as.message);
  }
  return true;
}

// The branch's values at the singular position t from its six sides: ws.q (qs, or extrapolated where Newton met a
// zero pivot at t itself, then checked against the tolerance), ws.qd and ws.qdd, the row marked singular, and the
// bifurcation warning that says how well they are known.
bool Sweeper::take_branch_values(double t, double rc, bool have_position, const Eigen::VectorXd& qs,
                                 const SingularSides& s) {
  const State* side = s.side;
  const double d = s.d;
  // Symmetric means m(kδ) over ±δ, ±2δ, ±3δ, combined by Richardson extrapolation, 1.5 m(δ) − 0.6 m(2δ) + 0.1 m(3δ)
  // (the weights cancel the δ² and δ⁴ terms): the branch's value at t to O(δ⁶).
  auto at_t = [&](const Eigen::VectorXd State::*x) -> Eigen::VectorXd {
    return 0.75 * (side[2].*x + side[3].*x) - 0.3 * (side[1].*x + side[4].*x) + 0.05 * (side[0].*x + side[5].*x);
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
  // the O(δ⁴) extrapolation from ±δ, ±2δ alone: how far from it the reported values are bounds their truncation
  auto inner = [&](const Eigen::VectorXd State::*x) -> Eigen::VectorXd {
    return (2.0 / 3.0) * (side[2].*x + side[3].*x) - (1.0 / 6.0) * (side[1].*x + side[4].*x);
  };
  auto relative_spread = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    const double scale = a.cwiseAbs().maxCoeff();
    return scale > 0.0 ? (a - b).cwiseAbs().maxCoeff() / scale : 0.0;
  };
  ws_->qd = at_t(&State::qd);
  const double qd_spread = relative_spread(ws_->qd, inner(&State::qd));
  double qdd_spread = 0.0;
  if (need_a_) ws_->qdd = at_t(&State::qdd), qdd_spread = relative_spread(ws_->qdd, inner(&State::qdd));
  if (!need_v_) {  // positions only: the branch's tangent for the next prediction (predict())
    singular_.branch_qd = ws_->qd, singular_.branch_qdd = at_t(&State::qdd);
    singular_.branch_t = t;
  }
  ++sum_.singular_positions;
  singular_.at_row = true;
  std::ostringstream m;
  m.precision(3);
  m << (has_current_ ? "bifurcation passed" : "the sweep starts at a bifurcation") << ": Φq is singular here (rcond "
    << rc << "), so the velocity is not unique; " << (need_v_ ? "reported is" : "the next step follows")
    << " the branch's own (extrapolated from t ± " << d << ", ± " << 2 * d << " and ± " << 3 * d;
  if (need_v_) {
    m << "; it differs from the extrapolation from ± " << d << " and ± " << 2 * d << " by " << qd_spread << " in q̇";
    if (need_a_) m << " and " << qdd_spread << " in q̈";
    m << ", relative";
  }
  m << ")"
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

// Why the sweep cannot go on from the last converged state (current_) towards t1, when it is a dead point (a
// turning point of the motion: the drive asks for positions that do not exist): Φq is near-singular there and
// the speed grows like 1/√(t* − t). Then q̈ ≈ q̇ / (2 (t* − t)) along q̇, so t* − t ≈ |q̇|² / (2 q̇·q̈), and the
// equations that line up are the support of Φq's left near-null vector, found by inverse iteration on Φqᵀ
// with the LU. Returns "" when the last state does not look like one (then the cause is left open).
std::string Sweeper::dead_point(double t1) {
  ws_->q = current_.q;
  LinearSummary ls;
  DerivativeOptions converged;  // current_.q is a row the sweep converged to (at its own tolerance): not tested again
  converged.tolerance = INFINITY;
  if (solve_velocity(model_, current_.t, converged, *ws_, &ls) != SolveStatus::kSuccess ||
      solve_acceleration(model_, current_.t, converged, *ws_, &ls) != SolveStatus::kSuccess)
    return "";
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
std::string Sweeper::lined_up_equations() {
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

}  // namespace phiq::detail
