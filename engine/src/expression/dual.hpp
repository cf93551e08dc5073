// Internal: dual numbers a + ε b (ε² = 0), b the derivative along a parameter of what a is the value of, with the
// functions a tape computes (expression/taylor.hpp runs a tape over them) and those the parts' frame jets use
// (parts/force_rate.cpp: the exact rate of the generalized forces along a design parameter).
#pragma once

#include <cmath>

#include "expression/tape_ops.hpp"

// In a namespace of their own, found by argument-dependent lookup: phiq::detail's code that calls sqrt(x) on a
// double does not meet them (a double converts to Dual implicitly).
namespace phiq::detail::dual {

struct Dual {
  double v = 0.0, e = 0.0;
  Dual() = default;
  Dual(double value, double rate = 0.0) : v(value), e(rate) {}  // NOLINT: a constant converts implicitly
};
inline Dual operator+(Dual a, Dual b) { return {a.v + b.v, a.e + b.e}; }
inline Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.e - b.e}; }
inline Dual operator-(Dual a) { return {-a.v, -a.e}; }
inline Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.e * b.v + a.v * b.e}; }
inline Dual operator*(double k, Dual a) { return {k * a.v, k * a.e}; }
inline Dual operator/(Dual a, Dual b) { return {a.v / b.v, (a.e * b.v - a.v * b.e) / (b.v * b.v)}; }
inline Dual operator/(double k, Dual b) { return {k / b.v, -k * b.e / (b.v * b.v)}; }
// Both parts equal: a value that does not move along p is not the same as one that does.
inline bool operator==(Dual a, Dual b) { return a.v == b.v && a.e == b.e; }
inline double value_of(Dual a) { return a.v; }

// f(a) from f(a.v) and f′(a.v).
inline Dual chain(Dual a, double f, double f1) { return {f, f1 * a.e}; }
inline Dual sqrt(Dual a) {
  const double r = std::sqrt(a.v);
  return {r, a.e / (2.0 * r)};
}
inline Dual sin(Dual a) { return {std::sin(a.v), std::cos(a.v) * a.e}; }
inline Dual cos(Dual a) { return {std::cos(a.v), -std::sin(a.v) * a.e}; }
inline Dual tan(Dual a) {
  const double t = std::tan(a.v);
  return chain(a, t, 1.0 + t * t);
}
inline Dual asin(Dual a) { return chain(a, std::asin(a.v), 1.0 / std::sqrt(1.0 - a.v * a.v)); }
inline Dual acos(Dual a) { return chain(a, std::acos(a.v), -1.0 / std::sqrt(1.0 - a.v * a.v)); }
inline Dual atan(Dual a) { return chain(a, std::atan(a.v), 1.0 / (1.0 + a.v * a.v)); }
inline Dual atan2(Dual y, Dual x) { return {std::atan2(y.v, x.v), (x.v * y.e - y.v * x.e) / (x.v * x.v + y.v * y.v)}; }
inline Dual exp(Dual a) {
  const double e = std::exp(a.v);
  return {e, e * a.e};
}
inline Dual log(Dual a) { return {std::log(a.v), a.e / a.v}; }
inline Dual sinh(Dual a) { return chain(a, std::sinh(a.v), std::cosh(a.v)); }
inline Dual cosh(Dual a) { return chain(a, std::cosh(a.v), std::sinh(a.v)); }
inline Dual tanh(Dual a) {
  const double t = std::tanh(a.v);
  return chain(a, t, 1.0 - t * t);
}
inline Dual fabs(Dual a) { return a.v < 0.0 ? -a : a; }
// a^b; the exponent's own rate through ln a only where it moves (a constant exponent of a negative base is fine).
inline Dual pow(Dual a, Dual b) {
  const double p = std::pow(a.v, b.v);
  return {p, b.v * std::pow(a.v, b.v - 1.0) * a.e + (b.e != 0.0 ? p * std::log(a.v) * b.e : 0.0)};
}
// a^k by repeated squaring for the value (as the tape computes it), k a^(k−1) for the rate (0 for k = 0).
inline Dual int_power(Dual a, long k) {
  if (k == 0) return {1.0, 0.0};
  return {detail::int_power(a.v, k), static_cast<double>(k) * detail::int_power(a.v, k - 1) * a.e};
}

}  // namespace phiq::detail::dual

namespace phiq::detail {
using dual::Dual;
}  // namespace phiq::detail
