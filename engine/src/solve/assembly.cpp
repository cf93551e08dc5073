#include "phiq/assembly.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <sstream>

#include "solve/assembly_internal.hpp"
#include "solve/kinematics_internal.hpp"
#include "phiq/min_norm_solver.hpp"
#include "solve/tolerance_tests.hpp"

namespace phiq {

using detail::scaled_rows_within;

std::string AssemblySummary::BriefReport() const {
  std::ostringstream s;
  s.precision(3);
  s << "assembly: " << to_string(status) << ", " << iterations << " iterations, scaled residual " << std::scientific
    << residual << std::defaultfloat << "; " << rank.BriefReport();
  if (!conflicts.empty()) {
    s << "; conflicting:";
    for (std::size_t k = 0; k < conflicts.size(); ++k) s << (k ? ", " : " ") << conflicts[k];
  }
  if (!message.empty()) s << " (" << message << ")";
  return s.str();
}

namespace {

// Scaled residual |Φ_i| / scale_i of every row, NaN as +inf.
Eigen::VectorXd scaled_rows(const Model& model, const Eigen::VectorXd& phi) {
  Eigen::VectorXd r = phi.cwiseAbs().cwiseQuotient(model.tolerance_scales().row_scale);
  for (Index i = 0; i < r.size(); ++i)
    if (std::isnan(r(i))) r(i) = std::numeric_limits<double>::infinity();
  return r;
}

// Backtracking (Armijo) along d from q on ½‖b‖², b = rows(Φ) scaled by `rows`: halves α until the merit decreases
// enough or the budget runs out. Leaves the last trial point in `trial`, its scaled rows in `bt`, its merit in *ft;
// returns whether it decreased.
template <class Rows>
bool backtrack(const Model& model, double t, const AssemblyOptions& opt, const Eigen::VectorXd& q,
               const Eigen::VectorXd& d, double f, const Rows& rows, Eigen::VectorXd& phi, Eigen::VectorXd& trial,
               Eigen::VectorXd& bt, double* alpha, double* ft) {
  *alpha = 1.0;
  for (int count = 0;; ++count) {
    trial = q + *alpha * d;
    model.residual(trial.data(), t, phi.data());
    rows(phi, bt);
    *ft = 0.5 * bt.squaredNorm();
    if (*ft <= (1.0 - 1e-4 * *alpha) * f) return true;
    if (count >= opt.max_backtracks) return false;
    *alpha *= 0.5;
  }
}

// Gauss-Newton on all rows at once, in least squares: Δ = −D (J̃ᵀJ̃ + μI)⁻¹ J̃ᵀ Φ̃ (CHOLMOD on J̃ᵀJ̃, analysed once),
// backtracking on ½‖Φ̃‖². It needs no choice of rows, so redundant equations and drivers are treated alike from a
// rough placement, where which rows are redundant is not yet known (a braced chain off its motion is a locked
// structure). μ is 1e-10 (relative to the O(1) scaled entries: the step tends to the minimum-norm least-squares step
// J̃⁺Φ̃, through rank-deficient and under-driven models) and grows tenfold from ‖Φ̃‖∞ while steps fail to decrease the
// merit (Levenberg-Marquardt). Returns kSuccess when every row holds, kNotConverged at a least-squares minimum that
// is not a solution (inconsistent or impossible: the caller finds out which).
SolveStatus solve_all_rows(const Model& model, double t, const AssemblyOptions& opt, Eigen::VectorXd& q,
                           AssemblySummary& sum, std::string* why, std::vector<double>& worst) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  if (m == 0) return SolveStatus::kSuccess;
  const ToleranceScales& sc = model.tolerance_scales();
  std::vector<Index> all(static_cast<std::size_t>(m));
  for (Index i = 0; i < m; ++i) all[static_cast<std::size_t>(i)] = i;
  ScaledJacobianRows jac(model, std::move(all));  // pattern once; values per iteration
  std::vector<double> jv, tv;
  std::vector<Index> from;
  auto at = std::make_shared<CscPattern>(transpose_pattern(*jac.pattern(), &from));  // J̃ᵀ: CHOLMOD factorises J̃ᵀ J̃ + μI
  MinNormSolver normal(at);
  Eigen::VectorXd phi(m), b(m), bt(m), g(n), d(n), trial(n);
  auto scaled = [&](const Eigen::VectorXd& full, Eigen::VectorXd& out) { out = full.cwiseQuotient(sc.row_scale); };
  model.residual(q.data(), t, phi.data());
  scaled(phi, b);
  double f = 0.5 * b.squaredNorm(), mu = 0.0;
  // the worst scaled row at each iteration: where it crawls (less than halved in kSlowSpan iterations) within
  // kNearSolution tolerances, the Jacobian is vanishing at a solution (a multiple root), where μ's floor, larger than
  // its squared entries there, shortens every step; the kept rows' Gauss-Newton (μ = 0) finishes instead
  constexpr std::size_t kSlowSpan = 5;
  constexpr double kNearSolution = 1e3;
  while (sum.iterations < opt.max_iterations) {
    if (!b.allFinite()) return *why = "constraint residual is not finite", SolveStatus::kNonFinite;
    if (scaled_rows_within(model, b, nullptr, opt.tolerance, q, t)) return SolveStatus::kSuccess;
    worst.push_back(b.cwiseAbs().maxCoeff());
    if (worst.size() > kSlowSpan && worst.back() <= kNearSolution * opt.tolerance &&
        worst.back() > 0.5 * worst[worst.size() - 1 - kSlowSpan])
      return *why = "converging slowly near a solution", SolveStatus::kNotConverged;
    jac.evaluate(q, t, jv);
    tv.resize(from.size());
    for (std::size_t k = 0; k < from.size(); ++k) tv[k] = jv[static_cast<std::size_t>(from[k])];
    const FactorStatus fs = normal.factorize(tv.data(), std::max(mu, 1e-10));
    ++sum.factorizations;
    if (fs != FactorStatus::kOk) return *why = normal.last_message(), SolveStatus::kLinearSolverFailed;
    g.setZero();
    normal.multiply_add(b.data(), g.data());  // g = J̃ᵀ b
    if (!normal.solve(g.data(), d.data())) return *why = normal.last_message(), SolveStatus::kLinearSolverFailed;
    d = -d.cwiseProduct(sc.coordinate_scale);
    if (!d.allFinite()) return *why = "Gauss-Newton step is not finite", SolveStatus::kNonFinite;
    ++sum.iterations;
    double alpha = 1.0, ft = 0.0;
    const bool decreased = backtrack(model, t, opt, q, d, f, scaled, phi, trial, bt, &alpha, &ft);
    const bool tiny = scaled_step(model, alpha * d, trial, opt.tolerance) <= 1.0;
    if (decreased) q.swap(trial), b.swap(bt), f = ft;
    if (decreased && !tiny) {
      if (alpha == 1.0) mu *= 0.1;
      continue;
    }
    if (scaled_rows_within(model, b, nullptr, opt.tolerance, q, t)) return SolveStatus::kSuccess;
    if (mu < 1e6) {  // regularise more, then give up: a least-squares minimum
      mu = mu == 0.0 ? std::max(b.cwiseAbs().maxCoeff(), 1e-8) : 10.0 * mu;
      continue;
    }
    *why = "no assembly near this placement: the residual stopped decreasing";
    return SolveStatus::kNotConverged;
  }
  *why = "did not converge in " + std::to_string(opt.max_iterations) + " iterations";
  return SolveStatus::kNotConverged;
}

// Minimum-norm Gauss-Newton on the rows `kept` from q, in two phases.
//  1. Correction (while the kept rows are not within tolerance): Δ = −D Ãᵀ (Ã Ãᵀ + μI)⁻¹ Φ̃, backtracking on
//     ½‖Φ̃‖². μ = 0 (Gauss-Newton: quadratic convergence, and no damping of the soft modes of long chains, whose
//     smallest singular values are ~1/N) while it works; μ = ‖Φ̃‖∞ and growing (Levenberg-Marquardt) when the kept
//     rows lose rank on the way or a step does not decrease the merit. Stops when even that fails: a least-squares
//     minimum that is not a solution (kNotConverged).
//  2. Projection (once they are): the step of the linearised problem min ‖D⁻¹(q + Δ − q₀)‖ s.t. Φ + Φq Δ = 0,
//     Δ = D (p − Ãᵀ (Ã Ãᵀ)⁻¹ (Φ̃ + Ã p)) with p = D⁻¹(q₀ − q): a correction plus the pull back towards the
//     placement along the mechanism's free motion. Its fixed point is the assembled position nearest to q₀
//     (q₀ − q ∈ range(D² Φqᵀ)), and converging it drives Φ to rounding level, so that redundant rows are checked
//     against kept rows that hold far below the tolerance. It converges linearly (at a rate set by the curvature
//     of the constraints times the distance moved); steps are taken in full, the correction phase resumes if one
//     leaves the tolerance.
SolveStatus solve_kept(const Model& model, double t, const AssemblyOptions& opt, const std::vector<Index>& kept,
                       const Eigen::VectorXd& q0, Eigen::VectorXd& q, AssemblySummary& sum, std::string* why,
                       std::vector<double>& worst) {
  worst.clear();
  const Index n = model.num_coordinates(), k = static_cast<Index>(kept.size());
  if (k == 0) return SolveStatus::kSuccess;  // nothing to satisfy (a model without equations)
  const ToleranceScales& sc = model.tolerance_scales();
  Eigen::VectorXd phi(model.num_equations()), b(k), bt(k), rhs(k), d(n), trial(n), pull(n);
  auto kept_scaled = [&](const Eigen::VectorXd& full, Eigen::VectorXd& out) {
    for (Index i = 0; i < k; ++i) out(i) = full(kept[i]) / sc.row_scale(kept[i]);
  };
  ScaledJacobianRows jac(model, kept);  // pattern once; values per iteration
  std::vector<double> values;
  MinNormSolver solver_of_kept(jac.pattern());
  MinNormSolver* solver = &solver_of_kept;
  auto kept_within = [&] { return scaled_rows_within(model, b, &kept, opt.tolerance, q, t); };

  model.residual(q.data(), t, phi.data());
  kept_scaled(phi, b);
  double f = 0.5 * b.squaredNorm();
  double mu = 0.0;            // Levenberg-Marquardt regularisation, only while plain Gauss-Newton fails
  Eigen::VectorXd assembled;  // the last iterate at which the kept rows held (empty if none yet)
  while (sum.iterations < opt.max_iterations) {
    if (!b.allFinite()) return *why = "constraint residual is not finite", SolveStatus::kNonFinite;
    worst.push_back(b.cwiseAbs().maxCoeff());
    const bool within = kept_within();
    if (within) assembled = q;
    jac.evaluate(q, t, values);
    if (within) mu = 0.0;
    FactorStatus fs = solver->factorize(values.data(), mu);
    if (fs == FactorStatus::kSingular) {  // the kept rows lost rank here: regularise
      mu = within ? 1e-14 : std::max(b.cwiseAbs().maxCoeff(), 1e-14);
      fs = solver->factorize(values.data(), mu);
    }
    ++sum.factorizations;
    if (fs != FactorStatus::kOk)
      return *why = solver->last_message(),
             fs == FactorStatus::kFailed ? SolveStatus::kLinearSolverFailed : SolveStatus::kSingularJacobian;
    ++sum.iterations;
    if (within) {
      pull = (q0 - q).cwiseQuotient(sc.coordinate_scale);
      rhs = b;
      solver->multiply_add(pull.data(), rhs.data());  // Φ̃ + Ã p
      if (!solver->min_norm(rhs.data(), d.data()))
        return *why = solver->last_message(), SolveStatus::kLinearSolverFailed;
      d = (pull - d).cwiseProduct(sc.coordinate_scale);
      if (!d.allFinite()) return *why = "projection step is not finite", SolveStatus::kNonFinite;
      q += d;
      model.residual(q.data(), t, phi.data());
      kept_scaled(phi, b);
      f = 0.5 * b.squaredNorm();
      if (scaled_step(model, d, q, opt.tolerance) <= 1.0 && kept_within()) return SolveStatus::kSuccess;
      continue;
    }

    if (!solver->min_norm(b.data(), d.data())) return *why = solver->last_message(), SolveStatus::kLinearSolverFailed;
    d = -d.cwiseProduct(sc.coordinate_scale);
    if (!d.allFinite()) return *why = "Gauss-Newton step is not finite", SolveStatus::kNonFinite;
    double alpha = 1.0, ft = 0.0;
    const bool decreased = backtrack(model, t, opt, q, d, f, kept_scaled, phi, trial, bt, &alpha, &ft);
    const bool tiny = scaled_step(model, alpha * d, trial, opt.tolerance) <= 1.0;
    if (decreased && !tiny) {
      q.swap(trial), b.swap(bt), f = ft;
      mu = alpha == 1.0 ? 0.0 : mu;  // a full step: plain Gauss-Newton again
      continue;
    }
    // No decrease, or steps below the tolerance while the residual is not. With plain Gauss-Newton, try the
    // regularised step (far from a solution, or near a rank loss of the kept rows); if that fails too, this is a
    // least-squares minimum of the kept rows that is not a solution.
    if (decreased) q.swap(trial), b.swap(bt), f = ft;
    if (mu < b.cwiseAbs().maxCoeff()) {
      mu = std::max(10.0 * mu, b.cwiseAbs().maxCoeff());
      continue;
    }
    *why = "no assembly near this placement: the residual stopped decreasing";
    return SolveStatus::kNotConverged;
  }
  // The projection phase converges linearly: if its budget ran out with the rows within tolerance, the position is
  // assembled, only not the nearest one to the last digit. Near a singular position (a change point) its steps may
  // leave the tolerance and come back again and again: the last iterate that held is then the answer, rather than
  // wherever the budget happened to end.
  if (kept_within()) return SolveStatus::kSuccess;
  if (assembled.size() == n) {
    q = assembled;
    return SolveStatus::kSuccess;
  }
  *why = "did not converge in " + std::to_string(opt.max_iterations) + " iterations";
  return SolveStatus::kNotConverged;
}

}  // namespace

SolveStatus assemble(const Model& model, double t, const AssemblyOptions& opt, Eigen::VectorXd& q,
                     AssemblySummary* summary) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  if (q.size() != n) throw Error("assemble: q must have " + std::to_string(n) + " entries");
  if (!(opt.tolerance > 0.0) || opt.max_iterations < 0 || opt.max_backtracks < 0 || opt.max_rank_updates < 0)
    throw Error("AssemblyOptions: tolerance must be > 0 and the limits ≥ 0");
  AssemblySummary local;
  AssemblySummary& sum = summary ? *summary : local;
  sum = AssemblySummary{};
  const Eigen::VectorXd q0 = q;
  Eigen::VectorXd phi(m);

  // `among`: the rows the worst are named from (all when null).
  auto finish = [&](SolveStatus st, std::string msg, const std::vector<Index>* among = nullptr) {
    sum.status = st;
    model.residual(q.data(), t, phi.data());
    const Eigen::VectorXd scaled = scaled_rows(model, phi);
    sum.residual = m ? scaled.maxCoeff() : 0.0;
    sum.moved = n ? ((q - q0).cwiseAbs().cwiseQuotient(model.tolerance_scales().coordinate_scale)).maxCoeff() : 0.0;
    if (st != SolveStatus::kSuccess) {
      // outside the time domain the drivers' values, and so the residuals, mean nothing: no worst rows
      if (st != SolveStatus::kOutsideTimeDomain) sum.worst_rows = detail::worst_rows(model, phi, 3, among);
      if (msg.empty()) msg = to_string(st);
      if (!sum.worst_rows.empty() && st != SolveStatus::kInconsistent)
        msg += "; worst constraints: " + detail::describe_rows(model, sum.worst_rows);
    }
    sum.message = std::move(msg);
    return st;
  };

  // A time that is not a number, or infinite, is outside every domain (tabulated laws or not); no driver to name.
  if (!std::isfinite(t))
    return finish(SolveStatus::kOutsideTimeDomain, "t = " + format_time(t) + " is not a finite time");
  if (t < model.time_domain_begin() || t > model.time_domain_end())
    return finish(SolveStatus::kOutsideTimeDomain,
                  "driver '" + model.time_domain_limiter() + "' is not defined at t = " + format_time(t));
  if (!q.allFinite()) return finish(SolveStatus::kNonFinite, "starting point has non-finite coordinates");

  // 1. All rows in least squares from the placement (no choice of rows needed), 2. the rank analysis where that
  // ends, 3. its independent rows solved to rounding level and moved to the nearest assembled position, 4. the
  // redundant rows checked.
  std::string why;
  std::vector<double> all_worst, kept_worst;  // each phase's worst scaled row, iteration by iteration
  const SolveStatus first = solve_all_rows(model, t, opt, q, sum, &why, all_worst);
  if (first == SolveStatus::kNonFinite || first == SolveStatus::kLinearSolverFailed) return finish(first, why);
  if (!q.allFinite()) return finish(SolveStatus::kNonFinite, "non-finite coordinates");
  sum.rank = analyse_rank(model, q, t, opt.rank);
  for (;;) {
    const std::vector<Index> kept = sum.rank.independent_rows;
    const SolveStatus st = solve_kept(model, t, opt, kept, q0, q, sum, &why, kept_worst);
    if (!q.allFinite()) return finish(SolveStatus::kNonFinite, "non-finite coordinates");
    // Rank belongs to the configuration: choose the independent rows again where the solve ended.
    sum.rank = analyse_rank(model, q, t, opt.rank);
    model.residual(q.data(), t, phi.data());
    const Eigen::VectorXd scaled = scaled_rows(model, phi);
    auto within = [&](Index r) { return detail::row_within(model, r, scaled(r), opt.tolerance, q, t); };
    const bool all_within = detail::residual_within(model, phi, opt.tolerance, q, t);
    if (st == SolveStatus::kSuccess && all_within) return finish(SolveStatus::kSuccess, "");
    if (st == SolveStatus::kNonFinite || st == SolveStatus::kLinearSolverFailed) return finish(st, why);
    // The independent equations now hold (or stall) but others do not. If the rows found independent here differ
    // from those just solved, solve again with them; otherwise the violated redundant rows conflict.
    if (sum.rank.independent_rows != kept && sum.rank_updates < opt.max_rank_updates) {
      ++sum.rank_updates;
      continue;
    }
    const std::vector<Index>& ind = sum.rank.independent_rows;
    bool kept_within = true;
    for (Index r : ind) kept_within = kept_within && within(r);
    for (Index r : sum.rank.redundant_rows)
      if (!within(r)) sum.violated_rows.push_back(r);
    // The independent equations themselves have no solution near here (a fifth bar of the wrong length locks a
    // parallelogram where no position exists): whether the redundant ones conflict is not known, and the worst
    // rows are named among the independent ones — a redundant driver's row, far off at a least-squares minimum
    // of the others, says nothing about the cause.
    // Unless the iterations ran out while the residual still fell (at least halved in the last phase's last ten
    // iterations; a least-squares minimum that is not a solution levels off): Gauss-Newton converges linearly
    // where Φq is singular at the solution (a multiple root), so that the budget, not the equations, may be the
    // cause; what a longer run would find is not known.
    const std::vector<double>& last = kept_worst.size() > 10 ? kept_worst : all_worst;
    const bool still_falling =
        sum.iterations >= opt.max_iterations && last.size() > 10 && last.back() <= 0.5 * last[last.size() - 11];
    if (!kept_within && still_falling)
      return finish(SolveStatus::kNotConverged,
                    "the independent equations did not reach the tolerance in " + std::to_string(opt.max_iterations) +
                        " iterations, their residual still falling (slowly: Φq nearly singular, as at a multiple "
                        "root or a singular position, or no solution near here): raise "
                        "solver.assembly_max_iterations, or start nearer",
                    &kept);
    if (!kept_within) {
      sum.consistent = false;
      return finish(SolveStatus::kNotConverged,
                    "the independent equations have no common solution near this placement (" + why + ")", &kept);
    }
    if (sum.violated_rows.empty()) return finish(SolveStatus::kNotConverged, why);

    // Inconsistent: each violated redundant row is a combination of independent rows, which it contradicts.
    sum.consistent = false;
    std::vector<Index> involved = sum.violated_rows;
    for (const RowCombination& c : combinations_of(model, q, t, ind, sum.violated_rows))
      involved.insert(involved.end(), c.basis.begin(), c.basis.end());
    std::vector<Index> cons;
    for (Index r : involved) cons.push_back(model.constraint_of_row(r));
    std::sort(cons.begin(), cons.end());
    cons.erase(std::unique(cons.begin(), cons.end()), cons.end());
    for (Index c : cons) sum.conflicts.push_back(model.constraints()[static_cast<std::size_t>(c)].name);
    const auto w = detail::worst_rows(model, phi, 3, &sum.violated_rows);
    std::string msg = "inconsistent redundant constraints: " + detail::describe_rows(model, w) +
                      " cannot hold where the independent equations do; conflicting constraints:";
    for (std::size_t k = 0; k < sum.conflicts.size(); ++k) msg += (k ? ", " : " ") + sum.conflicts[k];
    return finish(SolveStatus::kInconsistent, msg);
  }
}

namespace {

// q moved by up to a tenth of each coordinate's tolerance scale (the length scale, or a radian), in a fixed
// pseudo-random direction (Knuth's MMIX generator with a fixed seed: the same in every run): a placement off a
// singular position, from which to assemble a solution near it (driven_dof_nearby).
Eigen::VectorXd nearby_placement(const Model& model, const Eigen::VectorXd& q) {
  std::linear_congruential_engine<std::uint64_t, 6364136223846793005ull, 1442695040888963407ull, 0> mmix(
      0x9E3779B97F4A7C15ull);
  Eigen::VectorXd out = q;
  const Eigen::VectorXd& scale = model.tolerance_scales().coordinate_scale;
  for (Index j = 0; j < out.size(); ++j)
    out(j) += 0.1 * scale(j) * (static_cast<double>(mmix() >> 11) * 0x1.0p-53 * 2.0 - 1.0);
  return out;
}

}  // namespace

// Of the model, or of this position only? A position where several loops are folded or aligned at once (nfourbar
// started folded, every coupler on its neighbour's crank) loses rank there only; a model short of drivers or
// constraints, all along its motion. The rank is taken at a solution assembled from q moved off it
// (nearby_placement), not at the moved placement itself, where an overconstrained linkage (Bricard's,
// a braced parallelogram) has full rank though it loses it on every solution.
Index detail::driven_dof_nearby(const Model& model, const Eigen::VectorXd& q, double t, const AssemblyOptions& options,
                                RankReport* report) {
  Eigen::VectorXd nearby = nearby_placement(model, q);
  AssemblySummary as;
  try {
    if (assemble(model, t, options, nearby, &as) != SolveStatus::kSuccess) return -1;
  } catch (const Error&) {  // a placement outside an expression's domain can upset the rank analysis
    return -1;
  }
  if (report) *report = as.rank;
  return as.rank.driven_dof;
}

SolveStatus prepare_square(const Model& model, double t, const AssemblyOptions& options, Eigen::VectorXd& q,
                           std::unique_ptr<Model>* solved, AssemblySummary* summary) {
  if (!solved) throw Error("prepare_square: solved must not be null");
  AssemblySummary local;
  AssemblySummary& sum = summary ? *summary : local;
  const SolveStatus st = assemble(model, t, options, q, &sum);
  if (st != SolveStatus::kSuccess) return st;
  if (sum.rank.driven_dof > 0) {
    sum.status = SolveStatus::kNotSquare;
    sum.message = std::to_string(sum.rank.driven_dof) + " degree(s) of freedom not driven: the mechanism has " +
                  std::to_string(sum.rank.dof) + " and the drivers fix " +
                  std::to_string(sum.rank.driven_rank - sum.rank.rank);
    const Index nearby = detail::driven_dof_nearby(model, q, t, options);
    if (nearby >= 0 && nearby < sum.rank.driven_dof)
      sum.message += " at this position only (at a solution near it " + std::to_string(nearby) +
                     ": a singular position, not a model short of drivers or constraints)";
    return sum.status;
  }
  *solved = std::make_unique<Model>(model.without_rows(sum.rank.redundant_rows));
  return SolveStatus::kSuccess;
}

AssemblyOptions assembly_options(const NewtonOptions& newton) {
  AssemblyOptions o;
  o.tolerance = newton.tolerance;
  o.max_iterations = newton.max_iterations;
  return o;
}

SolveStatus prepare_scene(const Model& model, double t_begin, const NewtonOptions& assembly, SquareScene* out) {
  if (!out) throw Error("prepare_scene: out must not be null");
  out->reduced.reset();
  out->assembly = AssemblySummary{};
  out->start = model.initial_positions();
  if (model.num_equations() == model.num_coordinates()) return SolveStatus::kSuccess;
  return prepare_square(model, t_begin, assembly_options(assembly), out->start, &out->reduced, &out->assembly);
}

}  // namespace phiq
