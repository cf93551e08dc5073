/// @file
/// Motion laws f(t) of rheonomic driving constraints, with exact first and second derivatives.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/expression.hpp"

namespace phiq {

/// A motion law and its derivatives at one time.
struct LawValue {
  double f = 0.0;    ///< f(t)
  double df = 0.0;   ///< f'(t)
  double ddf = 0.0;  ///< f''(t)
};

/// A driver's motion law f(t). A value type (cheap to copy: the data is shared, immutable); thread-safe.
/// The factory functions throw phiq::Error for non-finite or inconsistent data.
class MotionLaw {
 public:
  /// f = initial + rate * t
  static MotionLaw linear(double initial, double rate);
  /// f = Σ_k c_k t^k
  static MotionLaw polynomial(std::vector<double> coefficients);
  /// f = offset + amplitude * sin(frequency * t + phase)   (frequency in rad/s)
  static MotionLaw harmonic(double offset, double amplitude, double frequency, double phase);
  /// C² cubic spline through (t_k, value_k) (Eigen's interpolating B-spline; exact for cubics); t strictly
  /// increasing, at least 2 points (fewer than 4 lower the degree). Defined on [t_0, t_last] only. `periodic`:
  /// the cyclic C² cubic spline, repeating with period t_last − t_0 and defined at every t; at least 3 points, the
  /// last value equal to the first (a cam's lift over a turn, a gas force over an engine's cycle).
  static MotionLaw table(std::vector<double> t, std::vector<double> values, bool periodic = false);
  /// Any function of t written as text, e.g. "0.1*t^2 + sin(t)"; derivatives are exact (see expression.hpp).
  static MotionLaw expression(std::shared_ptr<const CompiledExpression> f_of_t);
  /// f = Σ_k w_k f_k(t), terms (w_k, f_k): a superposition of laws, defined where every term is. Throws
  /// phiq::Error for no terms, a non-finite weight or a default-constructed law.
  static MotionLaw sum(const std::vector<std::pair<double, MotionLaw>>& terms);
  /// The law's rate along a design parameter p: the law ∂f/∂p (its f′ and f″ are ∂f′/∂p and ∂f″/∂p), from the law
  /// `at` p and its copies `along` at p − 2h, p − h, p + h, p + 2h (the scene read there). The data's rates are the
  /// fourth-order central difference of the copies' data (exact for data of degree ≤ 4 in p), and f is
  /// differentiated along them exactly: a polynomial's coefficients and a table's values enter f linearly, a
  /// harmonic's frequency and phase through the chain rule, an expression along the parameters its text reads
  /// (CompiledExpression::along_constants()). Laws whose data cannot be matched (a table whose times move, an
  /// expression whose exponent moves, laws of other kinds) get the fourth-order difference of the four laws
  /// themselves, a sum(). Pre-condition: the five laws have values, h > 0.
  static MotionLaw rate_along(const MotionLaw& at, const std::array<const MotionLaw*, 4>& along, double h);

  /// f, f', f'' at t; NaN outside [domain_begin(), domain_end()]. Throws phiq::Error on a default-constructed law.
  LawValue evaluate(double t) const;
  /// False for a default-constructed law (no function: evaluate() throws), true for every law the factory
  /// functions make. ModelBuilder refuses a driver whose law has none.
  bool has_value() const { return impl_ != nullptr; }
  /// Interval on which the law is defined: infinite for analytic laws, the table's range for tables.
  double domain_begin() const;
  double domain_end() const;  ///< see domain_begin()
  /// The same law: the same kind with the same data (coefficients, table, program), or both default-constructed.
  /// Laws read from one scene at two values of a parameter they use differ (DistanceSpec::operator==).
  bool operator==(const MotionLaw& other) const;
  /// Short human-readable form, e.g. "linear 0 + 2*t".
  const std::string& description() const { return description_; }

  /// @cond internal
  struct Impl;
  /// @endcond

 private:
  static MotionLaw periodic_table(const std::vector<double>& t, const std::vector<double>& values);
  std::shared_ptr<const Impl> impl_;
  std::string description_;
};

}  // namespace phiq
