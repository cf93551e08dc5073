// Sensitivities of the motion to design parameters (sensitivity.hpp): the right-hand sides by the fourth-order
// central difference along the parameter, each solved with the row's own factorisation of Φq.
#include "phiq/sensitivity.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "phiq/evaluation.hpp"  // JacobianView: Φq over values held here
#include "phiq/text.hpp"
#include "solve/factorisation.hpp"
#include "solve/sensitivity_internal.hpp"

namespace phiq {

namespace {

// The shifts of the four models, in units of h, and the weights of D f = Σ w_k f(k h) / (12 h).
constexpr std::array<double, 4> kShift = {-2.0, -1.0, 1.0, 2.0};
constexpr std::array<double, 4> kWeight = {1.0, -8.0, 8.0, -1.0};

}  // namespace

double default_sensitivity_step(double p) { return p == 0.0 ? 1e-3 : 1e-3 * std::fabs(p); }

std::string check_sensitivity_models(const Model& model, const OutputSensitivity& s) {
  const std::string who = "sensitivity to '" + s.name + "': ";
  if (!(s.step > 0.0) || !std::isfinite(s.step)) return who + "the difference step must be positive and finite";
  for (std::size_t k = 0; k < s.models.size(); ++k) {
    const Model* m = s.models[k].get();
    if (!m) return who + "a model along the parameter is missing";
    const CscPattern& a = m->jacobian_pattern();
    const CscPattern& b = model.jacobian_pattern();
    if (m->num_coordinates() != model.num_coordinates() || m->num_equations() != model.num_equations() ||
        a.col_ptr != b.col_ptr || a.row_idx != b.row_idx)
      return who + "the model at " + s.name + " = " + shortest(s.value + kShift[k] * s.step) +
             " has other coordinates, constraints or Jacobian entries than at " + shortest(s.value) +
             ": a parameter that changes the model's structure (a count, a family's range, a switch) has no "
             "derivative";
  }
  return "";
}

bool detail::sensitivities_with_factors(const Model& model, const std::vector<OutputSensitivity>& parameters,
                                        double t, const double* q, const double* qd, const double* qdd, int order,
                                        SparseLuNumeric& lu, Workspace& ws, SensitivityScratch& sc, double* out) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  const SensitivityLayout layout{n};
  for (auto& f : sc.f) f.resize(m);
  sc.d.resize(m), sc.qk.resize(n), sc.vk.resize(n);
  const CscPattern& pattern = model.jacobian_pattern();  // (every model along a parameter has it: checked)
  if (order >= 1)
    for (auto& values : sc.jacobian) values.resize(static_cast<std::size_t>(pattern.nnz()));
  auto jacobian = [&](std::size_t k) {
    return JacobianView(pattern.rows, pattern.cols, pattern.nnz(), pattern.col_ptr.data(), pattern.row_idx.data(),
                        sc.jacobian[k].data());
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::fill(out, out + layout.size(parameters.size()), nan);
  const Eigen::Map<const Eigen::VectorXd> qv(q, n);
  for (std::size_t j = 0; j < parameters.size(); ++j) {
    const OutputSensitivity& p = parameters[j];
    const double h = p.step;
    double* s = out + layout.offset(j, 0);
    double* sd = out + layout.offset(j, 1);
    double* sdd = out + layout.offset(j, 2);
    // −D f solved with Φq into x: the sensitivity of one order.
    auto solve_difference = [&](double* x) {
      sc.d.setZero();
      for (std::size_t k = 0; k < 4; ++k) sc.d += kWeight[k] * sc.f[k];
      sc.d *= -1.0 / (12.0 * h);
      ++ws.counters.sensitivity_solves;
      return lu.solve(solve_rhs(model, ws, sc.d), x);
    };
    // Position: Φp from the residuals of the four models at q.
    for (std::size_t k = 0; k < 4; ++k) p.models[k]->residual(q, t, sc.f[k].data());
    if (!solve_difference(s)) return false;
    if (order < 1) continue;
    // Velocity: Φq q̇ + Φt along (q, p) ← (s, 1). Each model's Φq at its shifted q is kept for the acceleration,
    // which reads it at the same point.
    const Eigen::Map<const Eigen::VectorXd> sv(s, n), qdv(qd, n);
    for (std::size_t k = 0; k < 4; ++k) {
      const Model& mk = *p.models[k];
      sc.qk = qv + (kShift[k] * h) * sv;
      mk.jacobian(sc.qk.data(), t, sc.jacobian[k].data());
      sc.f[k].noalias() = jacobian(k) * qdv;
      mk.phi_t(sc.qk.data(), t, sc.d.data());
      sc.f[k] += sc.d;
    }
    if (!solve_difference(sd)) return false;
    if (order < 2) continue;
    // Acceleration: Φq q̈ − γ along (q, q̇, p) ← (s, ṡ, 1), q̈ held.
    const Eigen::Map<const Eigen::VectorXd> sdv(sd, n), qddv(qdd, n);
    for (std::size_t k = 0; k < 4; ++k) {
      const Model& mk = *p.models[k];
      sc.qk = qv + (kShift[k] * h) * sv;
      sc.vk = qdv + (kShift[k] * h) * sdv;
      sc.f[k].noalias() = jacobian(k) * qddv;
      mk.gamma(sc.qk.data(), sc.vk.data(), t, sc.d.data());
      sc.f[k] -= sc.d;
    }
    if (!solve_difference(sdd)) return false;
  }
  return true;
}

SolveStatus solve_sensitivities(const Model& model, const std::vector<OutputSensitivity>& parameters, double t,
                                int order, Workspace& ws, double* out, LinearSummary* summary) {
  detail::check_workspace(model, ws);
  if (order < 0 || order > 2) throw Error("solve_sensitivities: order must be 0, 1 or 2");
  if (!out && !parameters.empty()) throw Error("solve_sensitivities: out must not be null");
  for (const OutputSensitivity& p : parameters)
    if (const std::string why = check_sensitivity_models(model, p); !why.empty()) throw Error(why);
  LinearSummary local;
  LinearSummary& sum = summary ? *summary : local;
  sum = LinearSummary{};
  if (!ws.lu) {
    sum.message = detail::not_square_message(model);
    return sum.status = SolveStatus::kNotSquare;
  }
  const SensitivityLayout layout{model.num_coordinates()};
  std::fill(out, out + layout.size(parameters.size()), std::numeric_limits<double>::quiet_NaN());
  const SolveStatus st = detail::ensure_factorized(model, t, ws, &sum.rcond, &sum.message);
  if (st != SolveStatus::kSuccess) return sum.status = st;
  // Below this reciprocal condition a solve keeps fewer than six digits: Φq has no useful inverse here (the sweep's
  // singular-position threshold, Sweeper::kSingularRcond).
  if (sum.rcond < 1e-10) {
    sum.message = "Φq is singular here (rcond " + scientific(sum.rcond, 2) + "): the sensitivities are not defined";
    return sum.status = SolveStatus::kSingularJacobian;
  }
  detail::SensitivityScratch scratch;
  if (!detail::sensitivities_with_factors(model, parameters, t, ws.q.data(), order >= 1 ? ws.qd.data() : nullptr,
                                          order >= 2 ? ws.qdd.data() : nullptr, order, *ws.lu, ws, scratch, out)) {
    sum.message = "sparse LU solve failed: " + ws.lu->last_message();
    return sum.status = SolveStatus::kLinearSolverFailed;
  }
  return SolveStatus::kSuccess;
}

}  // namespace phiq
