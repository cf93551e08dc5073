// Motion laws f(t) of rheonomic driving constraints, with exact first and second derivatives.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "phiq/expression.hpp"

namespace phiq {

struct LawValue {
  double f = 0.0, df = 0.0, ddf = 0.0;  // f(t), f'(t), f''(t)
};

class MotionLaw {
 public:
  // f = initial + rate * t
  static MotionLaw linear(double initial, double rate);
  // f = Σ_k c_k t^k
  static MotionLaw polynomial(std::vector<double> coefficients);
  // f = offset + amplitude * sin(frequency * t + phase)   (frequency in rad/s)
  static MotionLaw harmonic(double offset, double amplitude, double frequency, double phase);
  // C² cubic spline through (t_k, value_k) (Eigen's interpolating B-spline; exact for cubics); t strictly
  // increasing, at least 2 points (fewer than 4 lower the degree). Defined on [t_0, t_last] only.
  static MotionLaw table(std::vector<double> t, std::vector<double> values);
  // Any function of t written as text, e.g. "0.1*t^2 + sin(t)"; derivatives are exact (see expression.hpp).
  static MotionLaw expression(std::shared_ptr<const CompiledExpression> f_of_t);

  LawValue evaluate(double t) const;
  // Interval on which the law is defined: infinite for analytic laws, the table's range for tables.
  double domain_begin() const;
  double domain_end() const;
  const std::string& description() const { return description_; }

  struct Impl;

 private:
  std::shared_ptr<const Impl> impl_;
  std::string description_;
};

}  // namespace phiq
