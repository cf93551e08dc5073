// The GiNaC side of expressions: the table of supported functions, phiq_pow, a power with a constant exponent
// whose derivative is its closed form, and phiq_abs, |u| with the derivative sign(u) (symbolic.hpp says who uses
// them).
#include "expression/symbolic.hpp"

namespace phiq::detail {

const std::map<std::string, FunctionSpec>& supported_functions() {
  using Op = Tape::Op;
  using GiNaC::ex;
  static const std::map<std::string, FunctionSpec> table = {
      {"sin", {Op::kSin, 1, [](const ex& a) -> ex { return GiNaC::sin(a); }}},
      {"cos", {Op::kCos, 1, [](const ex& a) -> ex { return GiNaC::cos(a); }}},
      {"tan", {Op::kTan, 1, [](const ex& a) -> ex { return GiNaC::tan(a); }}},
      {"asin", {Op::kAsin, 1, [](const ex& a) -> ex { return GiNaC::asin(a); }}},
      {"acos", {Op::kAcos, 1, [](const ex& a) -> ex { return GiNaC::acos(a); }}},
      {"atan", {Op::kAtan, 1, [](const ex& a) -> ex { return GiNaC::atan(a); }}},
      {"atan2", {Op::kAtan2, 2, nullptr, [](const ex& y, const ex& x) -> ex { return GiNaC::atan2(y, x); }}},
      {"exp", {Op::kExp, 1, [](const ex& a) -> ex { return GiNaC::exp(a); }}},
      {"log", {Op::kLog, 1, [](const ex& a) -> ex { return GiNaC::log(a); }}},
      {"sqrt", {Op::kSqrt, 1, [](const ex& a) -> ex { return GiNaC::sqrt(a); }}},  // a power to GiNaC
      {"sinh", {Op::kSinh, 1, [](const ex& a) -> ex { return GiNaC::sinh(a); }}},
      {"cosh", {Op::kCosh, 1, [](const ex& a) -> ex { return GiNaC::cosh(a); }}},
      {"tanh", {Op::kTanh, 1, [](const ex& a) -> ex { return GiNaC::tanh(a); }}},
      {"abs", {Op::kAbs, 1, [](const ex& a) -> ex { return absolute_value(a); }}},
      {"sign", {Op::kSign, 1, [](const ex& a) -> ex { return sign_of(a); }}}};
  return table;
}

std::string supported_function_list() {
  std::string s;
  for (const auto& [name, spec] : supported_functions()) s += (s.empty() ? "" : " ") + name;
  return s;
}

// u^p for an exponent p that is a constant of the text, as a GiNaC function of its own, phiq_pow(u, p), whose
// derivative is the closed form p·phiq_pow(u, p − 1)·u'. Such a p reaches GiNaC as a symbol (see ExpressionParser),
// and GiNaC's power differentiates a symbolic exponent by D(u^p) = u^p·(p'·ln u + p·u'/u): 0·∞ wherever u = 0,
// even for u² (a parallelogram's coupler (xA − xB)² + (yA − yB)² − b², yA = yB, failed as "singular"). Merging
// u^p·u^(−1) back into u^(p−1) on the tape worked only while GiNaC left u^(−1) alone, which it does not: (2x)^(−1)
// becomes ½·x^(−1), and (x − y)^(−1) becomes −(y − x)^(−1) in about half of all processes (its term order follows
// hash values). Here p − 1 is folded in double precision like any constant part, and the tape computes
// u^(p−1) as a power (exact: 0 for u = 0 and p > 1).
namespace {
GiNaC::ex constant_power_derivative(const GiNaC::ex& u, const GiNaC::ex& p, unsigned wrt);
unsigned constant_power_serial() {
  static const unsigned serial =
      GiNaC::function::register_new(GiNaC::function_options("phiq_pow", 2).derivative_func(constant_power_derivative));
  return serial;
}
}  // namespace

GiNaC::ex constant_power(const GiNaC::ex& u, const GiNaC::ex& p) {
  return GiNaC::function(constant_power_serial(), u, p);
}

namespace {
GiNaC::ex constant_power_derivative(const GiNaC::ex& u, const GiNaC::ex& p, unsigned wrt) {
  // ∂/∂p is never asked for (p is a constant), but is the exact one: u^p ln u
  return wrt == 0 ? p * constant_power(u, p - 1) : constant_power(u, p) * GiNaC::log(u);
}
bool is_constant_power(const GiNaC::ex& e) {
  return GiNaC::is_a<GiNaC::function>(e) && GiNaC::ex_to<GiNaC::function>(e).get_serial() == constant_power_serial();
}
}  // namespace

bool is_power(const GiNaC::ex& e) { return GiNaC::is_a<GiNaC::power>(e) || is_constant_power(e); }

// |u| as phiq_abs(u), whose derivative is phiq_sign(u) u' (0 at u = 0), and phiq_sign's 0. GiNaC's own abs
// differentiates to u u'/|u|, which is 0/0 where u = 0: a drag −c ẋ|ẋ| at rest, a force of |x − x0| where x = x0
// had a NaN gradient (and so NaN sensitivities) exactly there.
namespace {
GiNaC::ex sign_derivative(const GiNaC::ex&, unsigned) { return 0; }
unsigned sign_serial() {
  static const unsigned serial =
      GiNaC::function::register_new(GiNaC::function_options("phiq_sign", 1).derivative_func(sign_derivative));
  return serial;
}
GiNaC::ex abs_derivative(const GiNaC::ex& u, unsigned) { return GiNaC::function(sign_serial(), u); }
unsigned abs_serial() {
  static const unsigned serial =
      GiNaC::function::register_new(GiNaC::function_options("phiq_abs", 1).derivative_func(abs_derivative));
  return serial;
}
}  // namespace

GiNaC::ex absolute_value(const GiNaC::ex& u) { return GiNaC::function(abs_serial(), u); }

GiNaC::ex sign_of(const GiNaC::ex& u) { return GiNaC::function(sign_serial(), u); }

}  // namespace phiq::detail
