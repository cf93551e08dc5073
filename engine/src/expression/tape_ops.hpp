// What one tape instruction computes on its operand values: shared by the evaluator (tape.cpp, on the Newton hot
// path, where it must inline), the tape builder's constant folding and the parser's, so that a constant folded at
// compile time is exactly what the tape would have computed. Internal to engine/src/expression/.
#pragma once

#include <cmath>

#include "phiq/expression.hpp"

namespace phiq::detail {

// x^k by repeated squaring (as accurate as the multiplications x^2 or x^(-1) stand for). k = 0 gives 1, 0^k for
// k < 0 gives +inf.
inline double int_power(double x, long k) {
  if (k < 0) x = 1.0 / x, k = -k;
  double acc = 1.0;
  while (k) {
    if (k & 1) acc *= x;
    x *= x;
    k >>= 1;
  }
  return acc;
}

// One instruction on operand values a, b (loads excluded).
inline double apply(Tape::Op op, double a, double b, double imm) {
  using Op = Tape::Op;
  switch (op) {
    case Op::kConst:
      return imm;
    case Op::kAdd:
      return a + b;
    case Op::kSub:
      return a - b;
    case Op::kMul:
      return a * b;
    case Op::kDiv:
      return a / b;
    case Op::kNeg:
      return -a;
    case Op::kPowInt:
      return int_power(a, static_cast<long>(imm));
    case Op::kPowHalf:
      return int_power(std::sqrt(a), static_cast<long>(imm));
    case Op::kPow:
      return std::pow(a, b);
    case Op::kSqrt:
      return std::sqrt(a);
    case Op::kSin:
      return std::sin(a);
    case Op::kCos:
      return std::cos(a);
    case Op::kTan:
      return std::tan(a);
    case Op::kAsin:
      return std::asin(a);
    case Op::kAcos:
      return std::acos(a);
    case Op::kAtan:
      return std::atan(a);
    case Op::kAtan2:
      return std::atan2(a, b);
    case Op::kExp:
      return std::exp(a);
    case Op::kLog:
      return std::log(a);
    case Op::kSinh:
      return std::sinh(a);
    case Op::kCosh:
      return std::cosh(a);
    case Op::kTanh:
      return std::tanh(a);
    case Op::kAbs:
      return std::fabs(a);
    case Op::kSign:
      return (a > 0) - (a < 0);
    default:
      return std::nan("");
  }
}

// True for the instructions that read two registers (a and b).
inline bool is_binary(Tape::Op op) {
  using Op = Tape::Op;
  return op == Op::kAdd || op == Op::kSub || op == Op::kMul || op == Op::kDiv || op == Op::kPow || op == Op::kAtan2;
}

}  // namespace phiq::detail
