// Sensitivities of the drivers' efforts to design parameters (phiq/effort_sensitivity.hpp): dτ/dp = λᵀ (dΦq/dp) w −
// wᵀ dQ/dp, w = Φq⁻¹ e_r, with the row's own factors and its sensitivities in the direct form.
#include "phiq/effort_sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "phiq/inverse_dynamics.hpp"
#include "phiq/kinds/kind_support.hpp"  // detail::central_difference
#include "phiq/parts.hpp"
#include "phiq/sensitivity.hpp"
#include "phiq/text.hpp"
#include "parts/force_rate.hpp"
#include "solve/factorisation.hpp"
#include "solve/friction_losses.hpp"
#include "solve/models_along.hpp"
#include "solve/sensitivity_internal.hpp"

namespace phiq {

namespace {

using detail::kShift;

// The effort's row among the rows the factors hold (Model::solve_rows()), or −1 where the model dropped it.
Index factored_row(const Model& model, Index row) {
  const std::vector<Index>& kept = model.solve_rows();
  if (kept.empty()) return row;
  const auto it = std::lower_bound(kept.begin(), kept.end(), row);
  return it != kept.end() && *it == row ? static_cast<Index>(it - kept.begin()) : -1;
}

// Q at (q, q̇, q̈) under `parts` and `loads`, into `out` (zeroed first).
void generalized_forces(const std::vector<Part>& parts, const Loads& loads, const double* q, const double* qd,
                        const double* qdd, double t, Index n, Eigen::VectorXd& out) {
  out.setZero(n);
  add_generalized_forces(parts, loads, q, qd, qdd, t, out);
}

// dQ/dp into sc.dq: along p at fixed (q̂-moved q, q̇, q̈) with the parts and loads along p, plus along the motion
// (v = s − q̂, ṡ, s̈) at fixed p, each by the fourth-order central difference.
void total_force_rate(const Model& model, const OutputEfforts& efforts, const OutputSensitivity& p,
                      const ParameterReach& reach, const double* q, const double* qd, const double* qdd,
                      const double* sd, const double* sdd, double t, detail::EffortSensitivityScratch& sc) {
  const Index n = model.num_coordinates();
  const Eigen::Map<const Eigen::VectorXd> qv(q, n), qdv(qd, n), qddv(qdd, n), sdv(sd, n), sddv(sdd, n);
  Eigen::VectorXd* f = sc.forces;
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  const double rate = detail::fastest_coordinate(sc.v.data(), cs, n);
  const double e = 1e-3 / std::max(rate, 1e-3);  // the direct sensitivities' step (sensitivity.cpp)
  for (std::size_t k = 0; k < 4; ++k) {
    sc.qk = qv + (kShift[k] * e) * sc.v;
    sc.vk = qdv + (kShift[k] * e) * sdv;
    sc.ak = qddv + (kShift[k] * e) * sddv;
    generalized_forces(*efforts.parts, *efforts.loads, sc.qk.data(), sc.vk.data(), sc.ak.data(), t, n, f[k]);
  }
  sc.dq = ((f[0] - f[3]) + 8.0 * (f[2] - f[1])) / (12.0 * e);
  // Nothing but the constraints reads p, and no coordinate moves with it: Q along p is Q itself four times, its
  // difference exactly zero (what the evaluations below would give, bit for bit).
  if (std::none_of(p.parts_along.begin(), p.parts_along.end(), [](const auto& x) { return x != nullptr; }) &&
      std::none_of(p.loads_along.begin(), p.loads_along.end(), [](const auto& x) { return x != nullptr; }) &&
      reach.comotion.empty())
    return;
  for (std::size_t k = 0; k < 4; ++k) {
    sc.qf = qv;
    for (const ParameterReach::Comotion& c : reach.comotion)
      sc.qf[c.coordinate] = q[c.coordinate] * (1.0 + kShift[k] * p.step * c.rate);
    const std::vector<Part>& parts = p.parts_along[k] ? *p.parts_along[k] : *efforts.parts;
    const Loads& loads = p.loads_along[k] ? *p.loads_along[k] : *efforts.loads;
    generalized_forces(parts, loads, sc.qf.data(), qd, qdd, t, n, f[k]);
  }
  sc.dq += ((f[0] - f[3]) + 8.0 * (f[2] - f[1])) / (12.0 * p.step);
}

// dQ_f/dp at fixed λ into sc.friction_rate: the losses along the motion (v = s − q̂, with the difference step of
// the forces') and along p by the loads' copies and the bearings' joints along p (FrictionLosses::force_rate()).
void losses_force_rate(const Model& model, const OutputSensitivity& p, const ParameterReach& reach, const double* q,
                       double t, const Eigen::VectorXd& lambda, const double* sd, const double* sdd,
                       detail::EffortSensitivityScratch& sc) {
  const Index n = model.num_coordinates();
  const double rate = detail::fastest_coordinate(sc.v.data(), model.tolerance_scales().coordinate_scale.data(), n);
  std::array<const AppliedLoads*, 4> along{};
  for (std::size_t k = 0; k < 4; ++k) along[k] = p.loads_along[k] ? p.loads_along[k]->applied.get() : nullptr;
  if (!reach.comotion.empty())
    for (std::size_t k = 0; k < 4; ++k) {
      sc.moved[k] = Eigen::Map<const Eigen::VectorXd>(q, n);
      for (const ParameterReach::Comotion& c : reach.comotion)
        sc.moved[k][c.coordinate] = q[c.coordinate] * (1.0 + kShift[k] * p.step * c.rate);
    }
  sc.losses->force_rate(q, t, lambda, sc.v, 1e-3 / std::max(rate, 1e-3), along, sc.losses->joints_along(model, p),
                        reach.comotion.empty() ? nullptr : &sc.moved, p.step, sc.friction_rate, sd, sdd);
}

// H(v, w) = (Φq v)_q w over every row into sc.plus, from γ at q by polarisation (exact: γ is quadratic in q̇).
void second_derivative(const Model& model, const double* q, const Eigen::VectorXd& v, const Eigen::VectorXd& w,
                       double qd_rate, double t, detail::EffortSensitivityScratch& sc) {
  const Index n = model.num_coordinates();
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  const double rv = detail::fastest_coordinate(v.data(), cs, n), rw = detail::fastest_coordinate(w.data(), cs, n);
  sc.plus.setZero(model.num_equations());
  if (rv == 0.0 || rw == 0.0) return;
  // a and b as fast as q̇ (at least 1/s of the scales), which keeps the four γ's rounding near that of γ itself
  const double alpha = std::max(qd_rate, 1.0) / rv, beta = std::max(qd_rate, 1.0) / rw;
  const double sign[4][2] = {{1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
  for (int k = 0; k < 4; ++k) {
    sc.vk = (sign[k][0] * alpha) * v + (sign[k][1] * beta) * w;
    sc.g[k].resize(model.num_equations());
    model.gamma(q, sc.vk.data(), t, sc.g[k].data());
  }
  sc.plus = ((sc.g[2] - sc.g[0]) + (sc.g[3] - sc.g[1])) / (8.0 * alpha * beta);
}

// dΦt/dp over every row into sc.dphit: along p at fixed q (over the reach, with the co-moving coordinates) plus
// Φqt (s − q̂), from γ at ±a (exact: γ(a) − γ(−a) = −4 Φqt a, its quadratic and constant parts cancel).
void time_rate_along(const Model& model, const OutputSensitivity& p, const ParameterReach& reach, const double* q,
                     double t, detail::EffortSensitivityScratch& sc) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  sc.dphit.setZero(m);
  sc.qk.setZero(n);
  detail::along_parameter(model, p, reach, detail::AlongParameter::kVelocityTerm, q, sc.qk.data(), nullptr, t, n,
                          sc.along, sc.dphit);
  const double rate = detail::fastest_coordinate(sc.v.data(), model.tolerance_scales().coordinate_scale.data(), n);
  if (rate == 0.0) return;
  const double alpha = 1.0 / rate;  // a as fast as 1/s of the scales
  sc.vk = alpha * sc.v;
  sc.g[0].resize(m), sc.g[1].resize(m);
  model.gamma(q, sc.vk.data(), t, sc.g[0].data());
  sc.vk = -sc.vk;
  model.gamma(q, sc.vk.data(), t, sc.g[1].data());
  sc.dphit -= (sc.g[0] - sc.g[1]) / (4.0 * alpha);
}

}  // namespace

bool detail::effort_sensitivities_with_factors(const Model& model, const OutputEfforts& efforts,
                                               const std::vector<OutputSensitivity>& parameters, double t,
                                               const double* q, const double* qd, const double* qdd,
                                               const Eigen::VectorXd& lambda, const double* sensitivities,
                                               SparseLuNumeric& lu, EffortSensitivityScratch& sc, double* out) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  const std::size_t ne = efforts.constraints.size(), np = parameters.size();
  const EffortSensitivityLayout layout{ne};
  std::fill(out, out + layout.size(np), std::numeric_limits<double>::quiet_NaN());
  if (ne == 0 || np == 0) return true;
  for (auto& f : sc.along.f) f.resize(m);
  sc.along.along.resize(m);
  // w = Φq⁻¹ e_r for every kept row r of each driver: how the motion answers a unit change of the row (λ_r = wᵀ Q).
  // A dropped row's load is shared with the rows it repeats: NaN for the effort where it is the first, for the
  // power where it is any.
  sc.rows.clear();
  sc.all_kept.assign(ne, true);
  std::size_t used = 0;
  for (std::size_t i = 0; i < ne; ++i) {
    const ConstraintInfo& c = model.constraints()[static_cast<std::size_t>(efforts.constraints[i])];
    for (Index r = c.first_row; r < c.first_row + c.rows; ++r) {
      if (factored_row(model, r) < 0) {
        sc.all_kept[i] = false;
        continue;
      }
      if (sc.w.size() <= used) sc.w.resize(used + 1);
      sc.rhs.setZero(n);
      sc.rhs[factored_row(model, r)] = 1.0;
      sc.w[used].resize(n);
      if (!lu.solve(sc.rhs.data(), sc.w[used].data())) return false;
      if (sc.losses && !sc.losses->adjoint(lu, sc.w[used])) return false;  // (w̃: the losses' adjoint)
      sc.rows.push_back({i, r, used++});
    }
  }
  sc.phit.setZero(m);  // at the drivers' rows: a power reads no other
  for (const Index c : efforts.constraints) {
    const auto [block, index] = model.constraint_block(c);
    block->phi_t(index, index + 1, q, t, sc.phit.data());
  }
  const SensitivityLayout sl{n};
  const double qd_rate = detail::fastest_coordinate(qd, model.tolerance_scales().coordinate_scale.data(), n);
  for (std::size_t j = 0; j < np; ++j) {
    const OutputSensitivity& p = parameters[j];
    if (!p.reach) throw Error("effort_sensitivities_with_factors: the reach of '" + p.name + "' is not known");
    const ParameterReach& reach = *p.reach;
    const double* s = sensitivities + sl.offset(j, 0);
    sc.v = Eigen::Map<const Eigen::VectorXd>(s, n);  // s − q̂: the part along the motion
    for (const ParameterReach::Comotion& c : reach.comotion) sc.v[c.coordinate] -= q[c.coordinate] * c.rate;
    detail::ForcesAlong along{{}, {}, p.step};
    for (std::size_t k = 0; k < 4; ++k)
      along.parts[k] = p.parts_along[k].get(), along.loads[k] = p.loads_along[k].get();
    sc.dq.resize(n);
    if (sc.difference_forces ||
        !detail::generalized_force_rate(*efforts.parts, *efforts.loads, along, q, qd, qdd, s,
                                        sensitivities + sl.offset(j, 1), sensitivities + sl.offset(j, 2), t, sc.dq)) {
      total_force_rate(model, efforts, p, reach, q, qd, qdd, sensitivities + sl.offset(j, 1),
                       sensitivities + sl.offset(j, 2), t, sc);
      ++sc.differenced;
    }
    if (sc.losses)
      losses_force_rate(model, p, reach, q, t, lambda, sensitivities + sl.offset(j, 1), sensitivities + sl.offset(j, 2),
                        sc);
    time_rate_along(model, p, reach, q, t, sc);
    sc.power.assign(ne, 0.0);
    for (const EffortSensitivityScratch::DriverRow& dr : sc.rows) {
      const Eigen::VectorXd& w = sc.w[dr.w];
      // ∂(Φq w)/∂p at fixed q: the velocity term's derivative along p at q̇ = w and −w (Φt's cancels), over the reach
      sc.minus.setZero(m);
      sc.qk = -w;
      along_parameter(model, p, reach, AlongParameter::kVelocityTerm, q, sc.qk.data(), nullptr, t, n, sc.along,
                      sc.minus);
      Eigen::VectorXd& at_w = sc.along.d;
      at_w.setZero(m);
      along_parameter(model, p, reach, AlongParameter::kVelocityTerm, q, w.data(), nullptr, t, n, sc.along, at_w);
      double along_p = 0.0;
      for (const Index r : reach.rows) along_p += lambda[r] * 0.5 * (at_w[r] - sc.minus[r]);
      second_derivative(model, q, sc.v, w, qd_rate, t, sc);
      // −dλ_r/dp: the effort's rate where r is the driver's first row
      const double minus_rate =
          along_p + lambda.dot(sc.plus) - w.dot(sc.dq) - (sc.losses ? w.dot(sc.friction_rate) : 0.0);
      const ConstraintInfo& c = model.constraints()[static_cast<std::size_t>(efforts.constraints[dr.effort])];
      if (dr.row == c.first_row) out[layout.offset(j, dr.effort)] = minus_rate;
      // P = Σ λ_r Φt_r over the driver's rows
      sc.power[dr.effort] += -minus_rate * sc.phit[dr.row] + lambda[dr.row] * sc.dphit[dr.row];
    }
    for (std::size_t i = 0; i < ne; ++i)
      if (sc.all_kept[i]) out[layout.power_offset(np, j, i)] = sc.power[i];
  }
  return true;
}

SolveStatus solve_effort_sensitivities(const Model& model, const OutputEfforts& efforts,
                                       const std::vector<OutputSensitivity>& parameters, double t, Workspace& ws,
                                       std::vector<double>& out, std::string* message) {
  if (!efforts.parts || !efforts.loads) throw Error("solve_effort_sensitivities: the efforts need parts and loads");
  const std::size_t ne = efforts.constraints.size();
  out.assign(EffortSensitivityLayout{ne}.size(parameters.size()), std::numeric_limits<double>::quiet_NaN());
  // each parameter's reach found once, for the sensitivities and the efforts' alike (each would find it again)
  std::vector<OutputSensitivity> with_reach = parameters;
  for (OutputSensitivity& p : with_reach)
    if (!p.reach) p.reach = std::make_shared<const ParameterReach>(parameter_reach(model, p));
  std::vector<double> sens(
      static_cast<std::size_t>(SensitivityLayout{model.num_coordinates()}.size(parameters.size())));
  LinearSummary sum;
  const SolveStatus st = solve_sensitivities(model, with_reach, t, 2, ws, sens.data(), &sum);
  if (st != SolveStatus::kSuccess) {
    if (message) *message = sum.message;
    return st;
  }
  // (factorised at ws.q by solve_sensitivities(): the multipliers and w solve with the same factors)
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(model.num_coordinates()), kept, lambda;
  add_generalized_forces(*efforts.parts, *efforts.loads, ws.q.data(), ws.qd.data(), ws.qdd.data(), t, Q);
  detail::EffortSensitivityScratch sc;
  if (!multipliers_with_factors(model, *ws.lu, Q, kept, lambda)) {
    if (message) *message = "sparse LU solve failed: " + ws.lu->last_message();
    return SolveStatus::kLinearSolverFailed;
  }
  // the losses that read the multipliers, solved with them as a sweep solves them (row_efforts.cpp)
  std::optional<detail::FrictionLosses> losses;
  if (detail::FrictionLosses::any(efforts.loads->applied.get())) {
    losses.emplace(model, *efforts.loads->applied, &efforts);
    for (const OutputSensitivity& p : with_reach)
      if (const std::string why = losses->sensitivity_refusal(model, p); !why.empty())
        throw Error("solve_effort_sensitivities: " + why);
    if (!losses->solve(model, *ws.lu, ws.q.data(), ws.qd.data(), ws.qdd.data(), t, Q, lambda, kept))
      return losses->failure(*ws.lu, message);
    sc.losses = &*losses;
  }
  if (!detail::effort_sensitivities_with_factors(model, efforts, with_reach, t, ws.q.data(), ws.qd.data(),
                                                 ws.qdd.data(), lambda, sens.data(), *ws.lu, sc, out.data())) {
    std::fill(out.begin(), out.end(), std::numeric_limits<double>::quiet_NaN());
    if (message) *message = "sparse LU solve failed: " + ws.lu->last_message();
    return SolveStatus::kLinearSolverFailed;
  }
  return SolveStatus::kSuccess;
}

}  // namespace phiq
