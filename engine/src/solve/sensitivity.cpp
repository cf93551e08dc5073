// Sensitivities of the motion to design parameters (sensitivity.hpp): the right-hand sides by the fourth-order
// central difference along the parameter, each solved with the row's own factorisation of Φq.
#include "phiq/sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "phiq/output_plan.hpp"
#include "phiq/evaluation.hpp"          // JacobianView: Φq over values held here
#include "phiq/kinds/kind_support.hpp"  // detail::central_difference
#include "phiq/text.hpp"
#include "solve/factorisation.hpp"
#include "solve/models_along.hpp"
#include "solve/sensitivity_internal.hpp"

namespace phiq {

namespace {

// The shifts of the four models, in units of h (detail::kShift), and the weights of D f = Σ w_k f(k h) / (12 h).
using detail::kShift;
constexpr std::array<double, 4> kWeight = {1.0, -8.0, 8.0, -1.0};

// D f over the rows of `reach` into `d` (its other rows untouched), as differences of the pairs: exactly zero where
// the four models agree.
double difference_at(const std::array<Eigen::VectorXd, 4>& f, Index r, double h) {
  return detail::central_difference(f[0][r], f[1][r], f[2][r], f[3][r], h);
}
void difference_on(const ParameterReach& reach, const std::array<Eigen::VectorXd, 4>& f, double h, Eigen::VectorXd& d) {
  for (const Index r : reach.rows) d[r] = difference_at(f, r, h);
}

double fastest(const double* v, const double* scale, Index n) { return detail::fastest_coordinate(v, scale, n); }

// The derivative of f = `which` along the parameter over the rows of `reach`, into `d` (its other rows untouched):
// at fixed (q, q̇, q̈), or, where the parameter moves the scale of coordinates that reached constraints add
// (ParameterReach::comotion: a curve's parameter), along (q, p) ← (q̂, 1), q̂ that move: the models then see one
// contact (at fixed s, a curve whose radius is the parameter turns under it s / ℓ times faster than p moves).
// Callers solve for s − q̂ (sensitivity.hpp): Φq (s − q̂) = −(Φp + Φq q̂), the higher orders alike.
//
// Where the kept constraints hold their data's rates (ReachedConstraints::rates: kinds that differentiate their own
// data), those spans are the swept model's own derivatives along the data instead, one evaluation, exact.
}  // namespace

void detail::along_parameter(const Model& model, const OutputSensitivity& p, const ParameterReach& reach,
                             detail::AlongParameter which, const double* q, const double* qd, const double* qdd,
                             double t, Index n, detail::SensitivityScratch& sc, Eigen::VectorXd& d) {
  const double h = p.step;
  const double* at = q;
  if (!reach.comotion.empty()) sc.moved = Eigen::Map<const Eigen::VectorXd>(q, n), at = sc.moved.data();
  // the constraints kept of the models (keep_reached_only()) when they hold this reach, else the models
  const ReachedConstraints* reached = p.reached && p.reached->reach.get() == &reach ? p.reached.get() : nullptr;
  const bool rated =
      reached && std::any_of(reached->rates.begin(), reached->rates.end(), [](const auto& r) { return r != nullptr; });
  const bool differenced =
      !rated || std::any_of(reached->rates.begin(), reached->rates.end(), [](const auto& r) { return !r; });
  if (differenced) {
    for (std::size_t k = 0; k < 4; ++k) {
      for (const ParameterReach::Comotion& c : reach.comotion)
        sc.moved[c.coordinate] = q[c.coordinate] * (1.0 + kShift[k] * h * c.rate);
      detail::evaluate_over_reach(reach, p.models[k].get(), reached, k, which, at, qd, qdd, t, sc.f[k].data(),
                                  sc.along.data(), rated);
    }
    if (!rated) return difference_on(reach, sc.f, h, d);
  }
  const int order = which == detail::AlongParameter::kResidual       ? 0
                    : which == detail::AlongParameter::kVelocityTerm ? 1
                                                                     : 2;
  for (std::size_t j = 0; j < reach.spans.size(); ++j) {
    const ParameterReach::Span& s = reach.spans[j];
    const ConstraintBlock& block = *model.blocks()[s.block];
    if (reached->rates[j]) {
      block.data_derivative(s.begin, s.end, *reached->rates[j], order, q, qd, qdd, t, d.data());
      continue;
    }
    const Index rows = block.rows_per_constraint();  // the span's rows, differenced as difference_on()
    for (std::size_t i = s.begin; i < s.end; ++i)
      for (Index r = block.first_row(i); r < block.first_row(i) + rows; ++r) d[r] = difference_at(sc.f, r, h);
  }
}

double detail::fastest_coordinate(const double* v, const double* scale, Index n) {
  double f = 0.0;
  for (Index j = 0; j < n; ++j) f = std::max(f, std::fabs(v[j]) / scale[j]);
  return f;
}

namespace {

using detail::along_parameter;

// v·w over the rows of `reach`.
double dot_on(const ParameterReach& reach, const Eigen::VectorXd& v, const Eigen::VectorXd& w) {
  double sum = 0.0;
  for (const Index r : reach.rows) sum += v[r] * w[r];
  return sum;
}

// Whether the second difference of Φq along the motion (its values at offsets −3 … 3, `at`) is smooth: the
// sixth-order estimate and the fourth-order one of the inner five points agree to 10⁻⁴ of the largest entry. On
// smooth motions they differ by the fourth-order one's truncation, at most 3·10⁻⁶ over every scene of models/
// (spatial joints; 10⁻⁹ on planar ones); a knot of a spline within the points, 2·10⁻³ to 2·10⁻² (the curved slot).
// Where Φq is linear in q (bars, linear drivers) both are rounding, about ε Σ|w| |Φq|: 10⁻¹² of Φq's largest
// entry is their floor.
bool smooth_along_motion(const std::array<std::vector<double>, 7>& at) {
  constexpr double kSixth[7] = {2.0 / 180, -27.0 / 180, 270.0 / 180, -490.0 / 180, 270.0 / 180, -27.0 / 180, 2.0 / 180};
  constexpr double kFourth[5] = {-1.0 / 12, 16.0 / 12, -30.0 / 12, 16.0 / 12, -1.0 / 12};
  double gap = 0.0, largest = 0.0, entry = 0.0;
  for (std::size_t i = 0; i < at[0].size(); ++i) {
    double d6 = 0.0, d4 = 0.0;
    for (std::size_t k = 0; k < 7; ++k) d6 += kSixth[k] * at[k][i];
    for (std::size_t k = 0; k < 5; ++k) d4 += kFourth[k] * at[k + 1][i];
    gap = std::max(gap, std::fabs(d6 - d4)), largest = std::max(largest, std::fabs(d6));
    entry = std::max(entry, std::fabs(at[3][i]));
  }
  return gap <= 1e-4 * largest + 1e-12 * entry;
}

// Φq over values held here, in the model's pattern (every model along a parameter has it: checked).
JacobianView jacobian_view(const CscPattern& pattern, std::vector<double>& values) {
  return JacobianView(pattern.rows, pattern.cols, pattern.nnz(), pattern.col_ptr.data(), pattern.row_idx.data(),
                      values.data());
}

}  // namespace

double default_sensitivity_step(double p) { return p == 0.0 ? 1e-3 : 1e-3 * std::fabs(p); }

std::string detail::check_model_along(const Model& model, const OutputSensitivity& s, std::size_t k, const Model& m) {
  const CscPattern& a = m.jacobian_pattern();
  const CscPattern& b = model.jacobian_pattern();
  if (m.num_coordinates() != model.num_coordinates() || m.num_equations() != model.num_equations() ||
      a.col_ptr != b.col_ptr || a.row_idx != b.row_idx)
    return "sensitivity to '" + s.name + "': the model at " + s.name + " = " + shortest(s.value + kShift[k] * s.step) +
           " has other coordinates, constraints or Jacobian entries than at " + shortest(s.value) +
           ": a parameter that changes the model's structure (a count, a family's range, a switch) has no "
           "derivative";
  return "";
}

std::string check_sensitivity_models(const Model& model, const OutputSensitivity& s) {
  const std::string who = "sensitivity to '" + s.name + "': ";
  if (!(s.step > 0.0) || !std::isfinite(s.step)) return who + "the difference step must be positive and finite";
  // released models (keep_reached_only()): the constraints kept of them stand for them, checked when kept
  if (s.reached && s.reached->reach && !s.reached->rates.empty() &&
      s.reached->rates.size() != s.reached->reach->spans.size())
    return who + "the rates of its kept constraints' data are not one for each span of their reach";
  if (detail::models_released(s)) {
    if (!s.reach || s.reach != s.reached->reach)
      return who + "its models were released, and its reach is not the one their constraints were kept for";
    const ReachedConstraints& r = *s.reached;
    if (r.coordinates != model.num_coordinates() || r.equations != model.num_equations() ||
        r.nonzeros != model.jacobian_pattern().nnz())
      return who + "its constraints were kept for a model of " + std::to_string(r.coordinates) + " coordinates, " +
             std::to_string(r.equations) + " rows and " + std::to_string(r.nonzeros) + " nonzeros, not this one's " +
             std::to_string(model.num_coordinates()) + ", " + std::to_string(model.num_equations()) + " and " +
             std::to_string(model.jacobian_pattern().nnz());
    const auto& blocks = model.blocks();
    for (std::size_t j = 0; j < s.reach->spans.size(); ++j) {
      const ParameterReach::Span& span = s.reach->spans[j];
      const ConstraintBlock* kept = j < r.rates.size() && r.rates[j] ? r.rates[j].get()
                                    : j < r.along[0].size()          ? r.along[0][j].get()
                                                                     : nullptr;
      if (span.block >= blocks.size() || span.end > blocks[span.block]->size() || span.begin >= span.end || !kept ||
          std::string_view(kept->kind()) != blocks[span.block]->kind())
        return who + "its kept constraints are not this model's (span " + std::to_string(j) + ")";
    }
    return "";
  }
  for (std::size_t k = 0; k < s.models.size(); ++k) {
    if (!s.models[k]) return who + "a model along the parameter is missing";
    if (std::string why = detail::check_model_along(model, s, k, *s.models[k]); !why.empty()) return why;
  }
  return "";
}

bool detail::sensitivities_with_factors(const Model& model, const std::vector<OutputSensitivity>& parameters, double t,
                                        const double* q, const double* qd, const double* qdd, int order,
                                        SparseLuNumeric& lu, Workspace& ws, SensitivityScratch& sc, double* out) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  const SensitivityLayout layout{n};
  for (auto& f : sc.f) f.resize(m);
  sc.d.resize(m), sc.along.resize(m), sc.qk.resize(n), sc.vk.resize(n);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::fill(out, out + layout.size(parameters.size()), nan);
  const Eigen::Map<const Eigen::VectorXd> qv(q, n);
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  const double qd_rate = order >= 1 ? fastest(qd, cs, n) : 0.0;  // the row's, for every parameter's α below
  // A parameter's reach when it comes without one: found here (parameter_reach(), O(constraints) comparisons, fewer
  // operations than evaluating every constraint in the four models).
  ParameterReach found;
  for (std::size_t j = 0; j < parameters.size(); ++j) {
    const OutputSensitivity& p = parameters[j];
    double* s = out + layout.offset(j, 0);
    double* sd = out + layout.offset(j, 1);
    double* sdd = out + layout.offset(j, 2);
    // sc.d, which holds −(D f), solved with Φq into x: the sensitivity of one order.
    auto solve_negated_difference = [&](double* x) {
      ++ws.counters.sensitivity_solves;
      return lu.solve(solve_rhs(model, ws, sc.d), x);
    };
    // sc.d (the part along p) plus the difference of sc.f along the motion's sensitivities with step e, negated
    // and solved.
    auto solve_difference = [&](double e, double* x) {
      // in pairs, as difference_on: exactly zero where s is (the four points are one)
      sc.d += ((sc.f[0] - sc.f[3]) + 8.0 * (sc.f[2] - sc.f[1])) / (12.0 * e);
      sc.d = -sc.d;
      return solve_negated_difference(x);
    };
    // The part along p at fixed (q, q̇, q̈) of `which`, over the constraints p reaches, into sc.d (zero elsewhere).
    const ParameterReach& reach = p.reach ? *p.reach : (found = parameter_reach(model, p));
    auto along_p = [&](detail::AlongParameter which) {
      sc.d.setZero();
      along_parameter(model, p, reach, which, q, qd, qdd, t, n, sc, sc.d);
    };
    // Position: Φp (the other rows of Φp are exactly 0).
    along_p(detail::AlongParameter::kResidual);
    sc.d = -sc.d;
    if (!solve_negated_difference(s)) return false;  // s − q̂, the move along q the higher orders difference
    Eigen::VectorXd& sv = sc.sprime;
    if (order >= 1) sv = Eigen::Map<const Eigen::VectorXd>(s, n);
    for (const ParameterReach::Comotion& c : reach.comotion) s[c.coordinate] += q[c.coordinate] * c.rate;  // + q̂
    if (order < 1) continue;
    // The higher orders' right-hand sides are derivatives along (q, q̇, p) ← (s, ṡ, 1), taken in two parts, as
    // the adjoint form takes them: along (q, p) ← (q̂, 1) at fixed q̇, with the models over the reach, and along
    // (s − q̂, ṡ) at fixed p, with the swept model: the velocity's exactly (below), the acceleration's at q + kε(s − q̂),
    // ε moving the coordinate that s − q̂ moves most by 10⁻³ of its scale. In one, with the models at q + khs, the
    // step would move q by h|s|, and s grows along a sweep (∂θ/∂ω = t for a crank at θ = ωt: ten turns of a cam
    // put ∂ẏ/∂ω off by 4·10⁻⁷, against 10⁻¹⁰ so).
    const Eigen::Map<const Eigen::VectorXd> qdv(qd, n);
    const double rate = fastest(sv.data(), cs, n);
    const double step = 1e-3 / std::max(rate, 1e-3);
    // Velocity: Φq q̇ + Φt. Along v = s − q̂ its derivative is B v = (Φq q̇)_q v + Φqt v, and γ = −(Φq q̇)_q q̇ −
    // 2 Φqt q̇ − Φtt is a quadratic in q̇ whose derivative along v is −2 B v: so B v = [γ(q̇ − αv) − γ(q̇ + αv)] / (4α)
    // exactly, for every α (no step to choose, and q stays where it is: no spline knot or curve end within reach).
    // α makes αv as fast as q̇ (their fastest coordinates, in their scales; at least 1/s of its scale), which
    // keeps the two γ's rounding near that of γ itself.
    along_p(detail::AlongParameter::kVelocityTerm);
    if (rate > 0.0) {
      const double alpha = std::max(qd_rate, 1.0) / rate;
      sc.vk = qdv - alpha * sv;
      model.gamma(q, sc.vk.data(), t, sc.f[0].data());
      sc.vk = qdv + alpha * sv;
      model.gamma(q, sc.vk.data(), t, sc.f[1].data());
      sc.d += (sc.f[0] - sc.f[1]) / (4.0 * alpha);
    }
    sc.d = -sc.d;
    if (!solve_negated_difference(sd)) return false;
    if (order < 2) continue;
    // Acceleration: Φq q̈ − γ, q̈ held, along (v, ṡ), by the fourth-order difference at q + kεv (γ's derivative
    // along q has Φ's third derivatives in it: no quadratic to read it from).
    const Eigen::Map<const Eigen::VectorXd> sdv(sd, n);
    along_p(detail::AlongParameter::kAccelerationTerm);
    for (std::size_t k = 0; k < 4; ++k) {
      sc.qk = qv + (kShift[k] * step) * sv;
      sc.vk = qdv + (kShift[k] * step) * sdv;
      model.gamma(sc.qk.data(), sc.vk.data(), t, sc.along.data());
      sc.f[k] = -sc.along;
      // + Φq q̈, constraint by constraint: no CSC values to fill and read back
      for (const auto& block : model.blocks())
        block->add_jacobian_product(0, block->size(), sc.qk.data(), t, qdd, sc.f[k].data());
    }
    if (!solve_difference(step, sdd)) return false;
  }
  return true;
}

SensitivityForm effective_sensitivity_form(SensitivityForm form, std::size_t parameters, std::size_t outputs,
                                           int order) {
  if (form != SensitivityForm::kAuto) return form;
  if (outputs == 0) return SensitivityForm::kDirect;  // the adjoint would solve for none: every coordinate's
  const int o = std::clamp(order, 0, 2);
  constexpr double kSolvesPerOutput[3] = {1.0, 2.0, 4.0};  // λ; μ; τ and ν
  constexpr double kEvaluations[3] = {0.0, 4.0, 15.0};     // Φq along the motion (and along q̈)
  // along the sensitivities, a parameter: 2 γ; with q̈, 4 Φq and 4 γ more, which cost what the 8 before them did
  // (4 Φq products with q̇ and 4 Φt gone: bench/README.md, "What sensitivities cost")
  constexpr double kDirectEvaluations[3] = {0.0, 2.0, 8.0};
  const double direct = static_cast<double>(parameters) * ((o + 1) + 0.5 * kDirectEvaluations[o]);
  const double adjoint = static_cast<double>(outputs) * kSolvesPerOutput[o] + 0.5 * kEvaluations[o];
  return adjoint < direct ? SensitivityForm::kAdjoint : SensitivityForm::kDirect;
}

bool detail::adjoint_sensitivities_with_factors(const Model& model, const std::vector<OutputSensitivity>& parameters,
                                                const std::vector<Index>& outputs, double t, const double* q,
                                                const double* qd, const double* qdd, int order, SparseLuNumeric& lu,
                                                Workspace& ws, SensitivityScratch& sc, double* out) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  const SensitivityLayout layout{n};
  const std::size_t np = parameters.size();
  std::fill(out, out + layout.size(np), std::numeric_limits<double>::quiet_NaN());
  if (outputs.empty() || np == 0) return true;
  const CscPattern& pattern = model.jacobian_pattern();
  const std::size_t nnz = static_cast<std::size_t>(pattern.nnz());
  auto view = [&](std::vector<double>& values) { return jacobian_view(pattern, values); };
  const Eigen::Map<const Eigen::VectorXd> qv(q, n);
  // Φq of the swept model along the motion, q + kεq̇ at t + kε, and along q̈: the transposed second-derivative
  // terms are their differences applied to a vector. ε moves the fastest coordinate by 10⁻³ of its scale for the
  // fourth-order first differences; the second difference, whose rounding grows as 1/ε², is of sixth order at
  // 2·10⁻² (rounding and truncation both near 10⁻¹² of the terms: at 5·10⁻³ and fourth order the crank-slider's
  // ∂ẍ_B/∂L3 was 10× less accurate than the direct form's). t moves by at most ε's cap (a body at rest moves in t
  // only).
  const double* cs = model.tolerance_scales().coordinate_scale.data();
  const double v_rate = order >= 1 ? fastest(qd, cs, n) : 0.0, a_rate = order >= 2 ? fastest(qdd, cs, n) : 0.0;
  const double e1 = 1e-3 / std::max(v_rate, 1e-3), e2 = 2e-2 / std::max(v_rate, 2e-2);
  const double e3 = 1e-3 / std::max(a_rate, 1e-3);
  constexpr double kSecond[7] = {2.0, -27.0, 270.0, -490.0, 270.0, -27.0, 2.0};  // f'' · 180 h², offsets −3 … 3
  if (order >= 1) {
    for (auto& v : sc.first_along_motion) v.resize(nnz);
    Eigen::VectorXd& qk = sc.qk;  // (kept between rows: no allocation per row)
    qk.resize(n);
    const Eigen::Map<const Eigen::VectorXd> qdv(qd, n);
    for (std::size_t k = 0; k < 4; ++k) {
      qk = qv + (kShift[k] * e1) * qdv;
      model.jacobian(qk.data(), t + kShift[k] * e1, sc.first_along_motion[k].data());
    }
    if (order >= 2) {
      for (auto& v : sc.along_motion) v.resize(nnz);
      for (auto& v : sc.along_acceleration) v.resize(nnz);
      for (std::size_t k = 0; k < 7; ++k) {
        const double shift = static_cast<double>(k) - 3.0;
        qk = qv + (shift * e2) * qdv;
        model.jacobian(qk.data(), t + shift * e2, sc.along_motion[k].data());
      }
      const Eigen::Map<const Eigen::VectorXd> qddv(qdd, n);
      for (std::size_t k = 0; k < 4; ++k) {
        qk = qv + (kShift[k] * e3) * qddv;
        model.jacobian(qk.data(), t, sc.along_acceleration[k].data());
      }
    }
    ws.counters.jacobian_evaluations += order >= 2 ? 15 : 4;
  }
  // Where Φq is not smooth along the motion within the second difference's seven points (a spline's knot, where
  // its third derivative jumps), the sixth-order difference is not the derivative at this row: there the row is
  // solved in the direct form, whose differences along p span h |s| only.
  if (order >= 2 && !smooth_along_motion(sc.along_motion)) {
    ++ws.counters.sensitivity_direct_rows;
    if (!sensitivities_with_factors(model, parameters, t, q, qd, qdd, order, lu, ws, sc, out)) return false;
    std::vector<char> written(static_cast<std::size_t>(n), 0);  // the adjoint form's contract: its outputs only
    for (const Index i : outputs) written[static_cast<std::size_t>(i)] = 1;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t j = 0; j < np; ++j)
      for (int o = 0; o < 3; ++o)
        for (Index i = 0; i < n; ++i)
          if (!written[static_cast<std::size_t>(i)]) out[layout.offset(j, o) + i] = nan;
    return true;
  }
  // (After the check above: a row solved in the direct form evaluates its own.) Per parameter, its derivatives at
  // fixed (q, q̇): a_j = ∂Φ/∂p, b_j = ∂(Φq q̇ + Φt)/∂p, c_j = ∂(Φq q̈ − γ)/∂p, by the same difference along p as
  // the direct form; with co-moving coordinates, along (q̂, 1): the formulas then give s − q̂ (the position's q̂ is
  // added back), ṡ and s̈ unchanged (sensitivity.hpp).
  sc.a.resize(np), sc.b.resize(np), sc.c.resize(np);
  for (auto& f : sc.f) f.resize(m);
  sc.d.resize(m), sc.along.resize(m);
  // The reaches of parameters that come without one, found here (none allocated when every parameter has one).
  const bool missing = std::any_of(parameters.begin(), parameters.end(), [](const auto& p) { return !p.reach; });
  std::vector<ParameterReach> found(missing ? np : 0);
  std::vector<const ParameterReach*>& reaches = sc.reaches;
  reaches.resize(np);
  for (std::size_t j = 0; j < np; ++j) {
    const OutputSensitivity& p = parameters[j];
    // over the constraints p reaches: a_j, b_j and c_j are read on their rows only (dot_on)
    reaches[j] = p.reach ? p.reach.get() : &(found[j] = parameter_reach(model, p));
    using detail::AlongParameter;
    const AlongParameter terms[3] = {AlongParameter::kResidual, AlongParameter::kVelocityTerm,
                                     AlongParameter::kAccelerationTerm};
    Eigen::VectorXd* into[3] = {&sc.a[j], &sc.b[j], &sc.c[j]};
    for (int o = 0; o <= order; ++o) {
      into[o]->resize(m);
      along_parameter(model, p, *reaches[j], terms[o], q, qd, qdd, t, n, sc, *into[o]);
    }
  }
  // Bᵀv, and ∂(Φq q̈ − γ)/∂qᵀ v, into sc.rhs (over the coordinates).
  auto b_transposed = [&](const Eigen::VectorXd& v) {
    sc.rhs.setZero(n);
    for (std::size_t k = 0; k < 4; ++k)
      sc.rhs.noalias() += (kWeight[k] / (12.0 * e1)) * (view(sc.first_along_motion[k]).transpose() * v);
  };
  auto c1_transposed = [&](const Eigen::VectorXd& v) {
    sc.rhs.setZero(n);
    for (std::size_t k = 0; k < 4; ++k)
      sc.rhs.noalias() += (kWeight[k] / (12.0 * e3)) * (view(sc.along_acceleration[k]).transpose() * v);
    for (std::size_t k = 0; k < 7; ++k)
      sc.rhs.noalias() += (kSecond[k] / (180.0 * e2 * e2)) * (view(sc.along_motion[k]).transpose() * v);
  };
  // Φqᵀ x = sc.rhs with the row's factors, x over Φ's rows (zero at the rows the square solves leave out).
  const std::vector<Index>& kept = model.solve_rows();
  auto solve_transposed = [&](Eigen::VectorXd& x) {
    sc.solved.resize(n);
    ++ws.counters.sensitivity_solves;
    if (!lu.solve_transposed(sc.rhs.data(), sc.solved.data())) return false;
    if (kept.empty()) {
      x = sc.solved;
    } else {
      x.setZero(m);
      for (std::size_t i = 0; i < kept.size(); ++i) x[kept[i]] = sc.solved[static_cast<Index>(i)];
    }
    return true;
  };
  for (const Index i : outputs) {
    sc.rhs.setZero(n);
    sc.rhs[i] = 1.0;
    if (!solve_transposed(sc.lambda)) return false;
    if (order >= 1) {
      b_transposed(sc.lambda);
      if (!solve_transposed(sc.mu)) return false;
    }
    if (order >= 2) {
      b_transposed(sc.mu);
      if (!solve_transposed(sc.tau)) return false;
      c1_transposed(sc.lambda);
      if (!solve_transposed(sc.nu)) return false;
    }
    if (order >= 2) sc.nu -= 2.0 * sc.tau;  // ν − 2τ
    for (std::size_t j = 0; j < np; ++j) {
      const ParameterReach& reach = *reaches[j];
      out[layout.offset(j, 0) + i] = -dot_on(reach, sc.lambda, sc.a[j]);  // s − q̂, and q̂:
      for (const ParameterReach::Comotion& c : reach.comotion)
        if (c.coordinate == i) out[layout.offset(j, 0) + i] += q[i] * c.rate;
      if (order >= 1) out[layout.offset(j, 1) + i] = dot_on(reach, sc.mu, sc.a[j]) - dot_on(reach, sc.lambda, sc.b[j]);
      if (order >= 2)
        out[layout.offset(j, 2) + i] =
            dot_on(reach, sc.nu, sc.a[j]) + 2.0 * dot_on(reach, sc.mu, sc.b[j]) - dot_on(reach, sc.lambda, sc.c[j]);
    }
  }
  return true;
}

namespace {

// solve_sensitivities() and solve_sensitivities_adjoint(): checks, the factorisation at ws.q, then the form's solves
// (`outputs` null: the direct form).
SolveStatus solve_sensitivities_in(const Model& model, const std::vector<OutputSensitivity>& parameters,
                                   const std::vector<Index>* outputs, double t, int order, Workspace& ws, double* out,
                                   LinearSummary* summary, const char* who) {
  detail::check_workspace(model, ws);
  const std::string name(who);
  if (order < 0 || order > 2) throw Error(name + ": order must be 0, 1 or 2");
  if (!out && !parameters.empty()) throw Error(name + ": out must not be null");
  for (const OutputSensitivity& p : parameters)
    if (const std::string why = check_sensitivity_models(model, p); !why.empty()) throw Error(why);
  if (outputs) {
    std::vector<char> seen(static_cast<std::size_t>(model.num_coordinates()), 0);
    for (Index i : *outputs) {
      if (i < 0 || i >= model.num_coordinates())
        throw Error(name + ": output coordinate " + std::to_string(i) + " out of range");
      if (seen[static_cast<std::size_t>(i)]++)
        throw Error(name + ": output coordinate " + std::to_string(i) + " repeated");
    }
  }
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
  const double* qd = order >= 1 ? ws.qd.data() : nullptr;
  const double* qdd = order >= 2 ? ws.qdd.data() : nullptr;
  const bool ok = outputs ? detail::adjoint_sensitivities_with_factors(model, parameters, *outputs, t, ws.q.data(), qd,
                                                                       qdd, order, *ws.lu, ws, scratch, out)
                          : detail::sensitivities_with_factors(model, parameters, t, ws.q.data(), qd, qdd, order,
                                                               *ws.lu, ws, scratch, out);
  if (!ok) {
    std::fill(out, out + layout.size(parameters.size()), std::numeric_limits<double>::quiet_NaN());
    sum.message = "sparse LU solve failed: " + ws.lu->last_message();
    return sum.status = SolveStatus::kLinearSolverFailed;
  }
  return SolveStatus::kSuccess;
}

}  // namespace

SolveStatus solve_sensitivities(const Model& model, const std::vector<OutputSensitivity>& parameters, double t,
                                int order, Workspace& ws, double* out, LinearSummary* summary) {
  return solve_sensitivities_in(model, parameters, nullptr, t, order, ws, out, summary, "solve_sensitivities");
}

SolveStatus solve_sensitivities_adjoint(const Model& model, const std::vector<OutputSensitivity>& parameters,
                                        const std::vector<Index>& outputs, double t, int order, Workspace& ws,
                                        double* out, LinearSummary* summary) {
  return solve_sensitivities_in(model, parameters, &outputs, t, order, ws, out, summary, "solve_sensitivities_adjoint");
}

}  // namespace phiq
