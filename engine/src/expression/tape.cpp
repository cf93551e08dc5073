// The register tape machine at run time: evaluation of a compiled Tape (the value, the gradient, ∂/∂t; on the
// Newton hot path for equation constraints, so its loop and the instruction semantics it inlines stay in this one
// file), second-order Taylor-mode evaluation for γ, and the listing. Compilation into tapes is tape_builder.cpp.
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "expression/tape_ops.hpp"
#include "phiq/expression.hpp"

namespace phiq {

using detail::apply;
using detail::int_power;
using detail::is_binary;

void Tape::evaluate(const double* q, const double* qd, double t, double* out) const {
  thread_local std::vector<double> r;
  if (r.size() < code_.size()) r.resize(code_.size());
  const std::size_t n = code_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = code_[i];
    switch (in.op) {
      case Op::kLoadQ:
        r[i] = q[in.a];
        break;
      case Op::kLoadQd:
        r[i] = qd[in.a];
        break;
      case Op::kLoadT:
        r[i] = t;
        break;
      default:
        r[i] = apply(in.op, r[in.a], r[in.b], in.imm);
        break;
    }
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) out[k] = r[outputs_[k]];
}

void Tape::taylor2(const double* q, const double* qd, double t, double out[3]) const {
  // Each register holds (w0, w1, w2): w(s) = w0 + w1 s + w2 s² + O(s³). Unary functions use
  // w1 = f'(a0) a1, w2 = f'(a0) a2 + ½ f''(a0) a1².
  struct J {
    double v, d, h;  // w0, w1, w2
  };
  thread_local std::vector<J> r;
  if (r.size() < code_.size()) r.resize(code_.size());
  auto unary = [](const J& a, double f, double f1, double f2) {
    return J{f, f1 * a.d, f1 * a.h + 0.5 * f2 * a.d * a.d};
  };
  const std::size_t n = code_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = code_[i];
    const J& a = r[in.a];
    const J& b = r[in.b];
    J w;
    switch (in.op) {
      case Op::kConst:
        w = {in.imm, 0.0, 0.0};
        break;
      case Op::kLoadQ:
        w = {q[in.a], qd[in.a], 0.0};
        break;
      case Op::kLoadQd:
        w = {qd[in.a], 0.0, 0.0};
        break;  // q̇ is held fixed along the direction (q̈ = 0)
      case Op::kLoadT:
        w = {t, 1.0, 0.0};
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
        const double w0 = a.v / b.v, w1 = (a.d - w0 * b.d) / b.v;
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
        const double s = std::sqrt(a.v), p = 0.5 * in.imm;
        w = unary(a, int_power(s, k), p * int_power(s, k - 2), p * (p - 1.0) * int_power(s, k - 4));
        break;
      }
      case Op::kPow: {
        if (b.d == 0.0 && b.h == 0.0) {  // a constant exponent (along the direction)
          const double p = b.v;
          w = unary(a, std::pow(a.v, p), p * std::pow(a.v, p - 1.0), p * (p - 1.0) * std::pow(a.v, p - 2.0));
          break;
        }
        // a^b = exp(b ln a)
        const J l = unary(a, std::log(a.v), 1.0 / a.v, -1.0 / (a.v * a.v));
        const J m{b.v * l.v, b.v * l.d + b.d * l.v, b.v * l.h + b.d * l.d + b.h * l.v};
        const double e = std::exp(m.v);
        w = unary(m, e, e, e);
        break;
      }
      case Op::kSqrt: {
        const double s0 = std::sqrt(a.v);
        w = unary(a, s0, 0.5 / s0, -0.25 / (s0 * a.v));
        break;
      }
      case Op::kSin:
        w = unary(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v));
        break;
      case Op::kCos:
        w = unary(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v));
        break;
      case Op::kTan: {
        const double tn = std::tan(a.v), sec2 = 1.0 + tn * tn;
        w = unary(a, tn, sec2, 2.0 * tn * sec2);
        break;
      }
      case Op::kAsin: {
        const double u = 1.0 - a.v * a.v, is = 1.0 / std::sqrt(u);
        w = unary(a, std::asin(a.v), is, a.v * is / u);
        break;
      }
      case Op::kAcos: {
        const double u = 1.0 - a.v * a.v, is = 1.0 / std::sqrt(u);
        w = unary(a, std::acos(a.v), -is, -a.v * is / u);
        break;
      }
      case Op::kAtan: {
        const double u = 1.0 / (1.0 + a.v * a.v);
        w = unary(a, std::atan(a.v), u, -2.0 * a.v * u * u);
        break;
      }
      case Op::kAtan2: {  // w' = (x y' − y x') / (x² + y²), y = a, x = b
        const double R = b.v * b.v + a.v * a.v, dR = 2.0 * (b.v * b.d + a.v * a.d);
        const double N = b.v * a.d - a.v * b.d, dN = 2.0 * (b.v * a.h - a.v * b.h);
        w = {std::atan2(a.v, b.v), N / R, (dN * R - N * dR) / (2.0 * R * R)};
        break;
      }
      case Op::kExp: {
        const double e = std::exp(a.v);
        w = unary(a, e, e, e);
        break;
      }
      case Op::kLog:
        w = unary(a, std::log(a.v), 1.0 / a.v, -1.0 / (a.v * a.v));
        break;
      case Op::kSinh:
        w = unary(a, std::sinh(a.v), std::cosh(a.v), std::sinh(a.v));
        break;
      case Op::kCosh:
        w = unary(a, std::cosh(a.v), std::sinh(a.v), std::cosh(a.v));
        break;
      case Op::kTanh: {
        const double th = std::tanh(a.v), s2 = 1.0 - th * th;
        w = unary(a, th, s2, -2.0 * th * s2);
        break;
      }
      case Op::kAbs:
        w = unary(a, std::fabs(a.v), (a.v > 0) - (a.v < 0), 0.0);
        break;
      case Op::kSign:
        w = {static_cast<double>((a.v > 0) - (a.v < 0)), 0.0, 0.0};
        break;
      default:
        w = {std::nan(""), std::nan(""), std::nan("")};
        break;
    }
    r[i] = w;
  }
  const J& o = r[outputs_.at(0)];
  out[0] = o.v, out[1] = o.d, out[2] = o.h;
}

std::string Tape::listing() const {
  static const char* const names[] = {"const",  "loadq",   "loadqd", "loadt", "add",  "sub",  "mul",  "div",  "neg",
                                      "powint", "powhalf", "pow",    "sqrt",  "sin",  "cos",  "tan",  "asin", "acos",
                                      "atan",   "atan2",   "exp",    "log",   "sinh", "cosh", "tanh", "abs",  "sign"};
  std::ostringstream s;
  char imm[64];
  for (std::size_t i = 0; i < code_.size(); ++i) {
    const Instr& in = code_[i];
    std::snprintf(imm, sizeof imm, "%a", in.imm);
    s << 'r' << i << " = " << names[static_cast<int>(in.op)];
    switch (in.op) {
      case Op::kConst:
        s << ' ' << imm;
        break;
      case Op::kLoadQ:
      case Op::kLoadQd:
        s << ' ' << in.a;
        break;
      case Op::kLoadT:
        break;
      default:
        s << " r" << in.a;
        if (is_binary(in.op)) s << " r" << in.b;
        if (in.op == Op::kPowInt || in.op == Op::kPowHalf) s << ' ' << imm;
    }
    s << '\n';
  }
  s << "out";
  for (std::uint32_t o : outputs_) s << " r" << o;
  s << '\n';
  return s.str();
}

}  // namespace phiq
