// Internal: second-order Taylor-mode evaluation of a tape over any scalar T along a path whose loads say how each
// input moves: doubles for Tape::taylor2() (γ, on the Newton hot path: this loop inlines there as it was written
// there), dual numbers (expression/dual.hpp) for the exact rate of such a jet along a design parameter
// (parts/expression_rate.cpp).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "expression/dual.hpp"
#include "expression/tape_ops.hpp"
#include "phiq/expression.hpp"

namespace phiq {

// What the Taylor pass reads of a tape and of a compiled expression (friends of both).
struct TapeInternals {
  static const std::vector<Tape::Instr>& code(const Tape& t) { return t.code_; }
  static std::uint32_t output(const Tape& t) { return t.outputs_.at(0); }
  static const Tape& value(const CompiledExpression& e) { return e.value_; }
};

namespace detail {

// w(s) = v + d s + h s² + O(s³).
template <class T>
struct Taylor {
  T v, d, h;
};

inline double value_of(double x) { return x; }

// The Taylor coefficients of output 0 of `tape`, its inputs moving as `loads` says: loads.coordinate(j) the
// coefficients of q_j, loads.velocity(j) the (fixed) q̇_j, loads.time those of t. Exact (no truncation). Unary
// functions use w1 = f'(a0) a1, w2 = f'(a0) a2 + ½ f''(a0) a1². Thread-safe (scratch is thread-local).
template <class T, class Loads>
Taylor<T> taylor2(const Tape& tape, const Loads& loads) {
  using std::acos, std::asin, std::atan, std::atan2, std::cos, std::cosh, std::exp, std::fabs, std::log, std::pow,
      std::sin, std::sinh, std::sqrt, std::tan, std::tanh;
  using J = Taylor<T>;
  using Op = Tape::Op;
  const std::vector<Tape::Instr>& code = TapeInternals::code(tape);
  thread_local std::vector<J> r;
  if (r.size() < code.size()) r.resize(code.size());
  auto unary = [](const J& a, T f, T f1, T f2) { return J{f, f1 * a.d, f1 * a.h + 0.5 * f2 * a.d * a.d}; };
  const std::size_t n = code.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Tape::Instr& in = code[i];
    const J& a = r[in.a];
    const J& b = r[in.b];
    J w;
    switch (in.op) {
      case Op::kConst:
        w = {T(in.imm), T(0.0), T(0.0)};
        break;
      case Op::kLoadQ:
        w = loads.coordinate(in.a);
        break;
      case Op::kLoadQd:
        w = {loads.velocity(in.a), T(0.0), T(0.0)};
        break;  // q̇ is held fixed along the direction (q̈ = 0)
      case Op::kLoadT:
        w = loads.time;
        break;
      case Op::kAdd:
        w = {a.v + b.v, a.d + b.d, a.h + b.h};
        break;
      case Op::kSub:
        w = {a.v - b.v, a.d - b.d, a.h - b.h};
        break;
      case Op::kNeg:
        w = {-a.v, -a.d, -a.h};
        break;
      case Op::kMul:
        w = {a.v * b.v, a.v * b.d + a.d * b.v, a.v * b.h + a.d * b.d + a.h * b.v};
        break;
      case Op::kDiv: {
        const T w0 = a.v / b.v, w1 = (a.d - w0 * b.d) / b.v;
        w = {w0, w1, (a.h - w0 * b.h - w1 * b.d) / b.v};
        break;
      }
      // Powers with a constant exponent p by their closed forms p a^(p−1), p (p−1) a^(p−2), each power computed
      // as such: at a = 0 they are 0 where p is large enough, where a product with a^p/a would be 0·∞.
      case Op::kPowInt: {
        const long k = static_cast<long>(in.imm);
        w = unary(a, int_power(a.v, k), in.imm * int_power(a.v, k - 1),
                  in.imm * (in.imm - 1.0) * int_power(a.v, k - 2));
        break;
      }
      case Op::kPowHalf: {  // √a^k: p = k/2
        const long k = static_cast<long>(in.imm);
        const T s = sqrt(a.v);
        const double p = 0.5 * in.imm;
        w = unary(a, int_power(s, k), p * int_power(s, k - 2), p * (p - 1.0) * int_power(s, k - 4));
        break;
      }
      case Op::kPow: {
        if (b.d == T(0.0) && b.h == T(0.0)) {  // a constant exponent (along the direction)
          const T p = b.v;
          w = unary(a, pow(a.v, p), p * pow(a.v, p - 1.0), p * (p - 1.0) * pow(a.v, p - 2.0));
          break;
        }
        // a^b = exp(b ln a)
        const J l = unary(a, log(a.v), 1.0 / a.v, -1.0 / (a.v * a.v));
        const J m{b.v * l.v, b.v * l.d + b.d * l.v, b.v * l.h + b.d * l.d + b.h * l.v};
        const T e = exp(m.v);
        w = unary(m, e, e, e);
        break;
      }
      case Op::kSqrt: {
        const T s0 = sqrt(a.v);
        w = unary(a, s0, 0.5 / s0, -0.25 / (s0 * a.v));
        break;
      }
      case Op::kSin:
        w = unary(a, sin(a.v), cos(a.v), -sin(a.v));
        break;
      case Op::kCos:
        w = unary(a, cos(a.v), -sin(a.v), -cos(a.v));
        break;
      case Op::kTan: {
        const T tn = tan(a.v), sec2 = 1.0 + tn * tn;
        w = unary(a, tn, sec2, 2.0 * tn * sec2);
        break;
      }
      case Op::kAsin: {
        const T u = 1.0 - a.v * a.v, is = 1.0 / sqrt(u);
        w = unary(a, asin(a.v), is, a.v * is / u);
        break;
      }
      case Op::kAcos: {
        const T u = 1.0 - a.v * a.v, is = 1.0 / sqrt(u);
        w = unary(a, acos(a.v), -is, -a.v * is / u);
        break;
      }
      case Op::kAtan: {
        const T u = 1.0 / (1.0 + a.v * a.v);
        w = unary(a, atan(a.v), u, -2.0 * a.v * u * u);
        break;
      }
      case Op::kAtan2: {  // w' = (x y' − y x') / (x² + y²), y = a, x = b
        const T R = b.v * b.v + a.v * a.v, dR = 2.0 * (b.v * b.d + a.v * a.d);
        const T N = b.v * a.d - a.v * b.d, dN = 2.0 * (b.v * a.h - a.v * b.h);
        w = {atan2(a.v, b.v), N / R, (dN * R - N * dR) / (2.0 * R * R)};
        break;
      }
      case Op::kExp: {
        const T e = exp(a.v);
        w = unary(a, e, e, e);
        break;
      }
      case Op::kLog:
        w = unary(a, log(a.v), 1.0 / a.v, -1.0 / (a.v * a.v));
        break;
      case Op::kSinh:
        w = unary(a, sinh(a.v), cosh(a.v), sinh(a.v));
        break;
      case Op::kCosh:
        w = unary(a, cosh(a.v), sinh(a.v), cosh(a.v));
        break;
      case Op::kTanh: {
        const T th = tanh(a.v), s2 = 1.0 - th * th;
        w = unary(a, th, s2, -2.0 * th * s2);
        break;
      }
      case Op::kAbs:
        w = unary(a, fabs(a.v), T(static_cast<double>((value_of(a.v) > 0) - (value_of(a.v) < 0))), T(0.0));
        break;
      case Op::kSign:
        w = {T(static_cast<double>((value_of(a.v) > 0) - (value_of(a.v) < 0))), T(0.0), T(0.0)};
        break;
      default:
        w = {T(std::nan("")), T(std::nan("")), T(std::nan(""))};
        break;
    }
    r[i] = w;
  }
  return r[TapeInternals::output(tape)];
}

}  // namespace detail
}  // namespace phiq
