// Equation constraints: phiq's parser, GiNaC for exact differentiation, and the register tape back end.
#include "phiq/expression.hpp"

#include <ginac/ginac.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>
#include <unordered_map>

namespace phiq {

// ---------------------------------------------------------------------------------------------------------------
// Tape evaluation

namespace {
// x^k by repeated squaring (as accurate as the multiplications x^2 or x^(-1) stand for). k = 0 gives 1, 0^k for
// k < 0 gives +inf.
double int_power(double x, long k) {
  if (k < 0) x = 1.0 / x, k = -k;
  double acc = 1.0;
  while (k) {
    if (k & 1) acc *= x;
    x *= x;
    k >>= 1;
  }
  return acc;
}

// One instruction on operand values a, b (loads excluded): shared by the evaluator and the builder's constant
// folding, so that a folded constant is exactly what the tape would have computed.
double apply(Tape::Op op, double a, double b, double imm) {
  using Op = Tape::Op;
  switch (op) {
    case Op::kConst: return imm;
    case Op::kAdd: return a + b;
    case Op::kSub: return a - b;
    case Op::kMul: return a * b;
    case Op::kDiv: return a / b;
    case Op::kNeg: return -a;
    case Op::kPowInt: return int_power(a, static_cast<long>(imm));
    case Op::kPowHalf: return int_power(std::sqrt(a), static_cast<long>(imm));
    case Op::kPow: return std::pow(a, b);
    case Op::kSqrt: return std::sqrt(a);
    case Op::kSin: return std::sin(a);
    case Op::kCos: return std::cos(a);
    case Op::kTan: return std::tan(a);
    case Op::kAsin: return std::asin(a);
    case Op::kAcos: return std::acos(a);
    case Op::kAtan: return std::atan(a);
    case Op::kAtan2: return std::atan2(a, b);
    case Op::kExp: return std::exp(a);
    case Op::kLog: return std::log(a);
    case Op::kSinh: return std::sinh(a);
    case Op::kCosh: return std::cosh(a);
    case Op::kTanh: return std::tanh(a);
    case Op::kAbs: return std::fabs(a);
    case Op::kSign: return (a > 0) - (a < 0);
    default: return std::nan("");
  }
}

bool is_binary(Tape::Op op) {
  using Op = Tape::Op;
  return op == Op::kAdd || op == Op::kSub || op == Op::kMul || op == Op::kDiv || op == Op::kPow ||
         op == Op::kAtan2;
}
}  // namespace

void Tape::evaluate(const double* q, const double* qd, double t, double* out) const {
  thread_local std::vector<double> r;
  if (r.size() < code_.size()) r.resize(code_.size());
  const std::size_t n = code_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = code_[i];
    switch (in.op) {
      case Op::kLoadQ: r[i] = q[in.a]; break;
      case Op::kLoadQd: r[i] = qd[in.a]; break;
      case Op::kLoadT: r[i] = t; break;
      default: r[i] = apply(in.op, r[in.a], r[in.b], in.imm); break;
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
  auto unary = [](const J& a, double f, double f1, double f2) { return J{f, f1 * a.d, f1 * a.h + 0.5 * f2 * a.d * a.d}; };
  const std::size_t n = code_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = code_[i];
    const J& a = r[in.a];
    const J& b = r[in.b];
    J w;
    switch (in.op) {
      case Op::kConst: w = {in.imm, 0.0, 0.0}; break;
      case Op::kLoadQ: w = {q[in.a], qd[in.a], 0.0}; break;
      case Op::kLoadQd: w = {qd[in.a], 0.0, 0.0}; break;  // q̇ is held fixed along the direction (q̈ = 0)
      case Op::kLoadT: w = {t, 1.0, 0.0}; break;
      case Op::kAdd: w = {a.v + b.v, a.d + b.d, a.h + b.h}; break;
      case Op::kSub: w = {a.v - b.v, a.d - b.d, a.h - b.h}; break;
      case Op::kNeg: w = {-a.v, -a.d, -a.h}; break;
      case Op::kMul: w = {a.v * b.v, a.v * b.d + a.d * b.v, a.v * b.h + a.d * b.d + a.h * b.v}; break;
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
      case Op::kSin: w = unary(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v)); break;
      case Op::kCos: w = unary(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v)); break;
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
      case Op::kLog: w = unary(a, std::log(a.v), 1.0 / a.v, -1.0 / (a.v * a.v)); break;
      case Op::kSinh: w = unary(a, std::sinh(a.v), std::cosh(a.v), std::sinh(a.v)); break;
      case Op::kCosh: w = unary(a, std::cosh(a.v), std::sinh(a.v), std::cosh(a.v)); break;
      case Op::kTanh: {
        const double th = std::tanh(a.v), s2 = 1.0 - th * th;
        w = unary(a, th, s2, -2.0 * th * s2);
        break;
      }
      case Op::kAbs: w = unary(a, std::fabs(a.v), (a.v > 0) - (a.v < 0), 0.0); break;
      case Op::kSign: w = {static_cast<double>((a.v > 0) - (a.v < 0)), 0.0, 0.0}; break;
      default: w = {std::nan(""), std::nan(""), std::nan("")}; break;
    }
    r[i] = w;
  }
  const J& o = r[outputs_.at(0)];
  out[0] = o.v, out[1] = o.d, out[2] = o.h;
}

std::string Tape::listing() const {
  static const char* const names[] = {"const", "loadq", "loadqd", "loadt", "add",  "sub",  "mul",   "div",
                                      "neg",   "powint", "powhalf", "pow", "sqrt", "sin",  "cos",   "tan",
                                      "asin",  "acos",  "atan",   "atan2", "exp",  "log",  "sinh",  "cosh",
                                      "tanh",  "abs",   "sign"};
  std::ostringstream s;
  char imm[64];
  for (std::size_t i = 0; i < code_.size(); ++i) {
    const Instr& in = code_[i];
    std::snprintf(imm, sizeof imm, "%a", in.imm);
    s << 'r' << i << " = " << names[static_cast<int>(in.op)];
    switch (in.op) {
      case Op::kConst: s << ' ' << imm; break;
      case Op::kLoadQ: case Op::kLoadQd: s << ' ' << in.a; break;
      case Op::kLoadT: break;
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

// ---------------------------------------------------------------------------------------------------------------
// GiNaC expression -> tape

namespace {
Error expression_error(const std::string& text, const std::string& what);  // defined with the parsing helpers

// The functions an expression may call: the tape instruction, the number of arguments, and how GiNaC builds the
// call (one of make1, make2). One table for the parser (names, arity, what to build) and the tape builder (what a
// GiNaC function of that name computes).
struct FunctionSpec {
  Tape::Op op;
  int arity;
  GiNaC::ex (*make1)(const GiNaC::ex&) = nullptr;
  GiNaC::ex (*make2)(const GiNaC::ex&, const GiNaC::ex&) = nullptr;
};
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
      {"abs", {Op::kAbs, 1, [](const ex& a) -> ex { return GiNaC::abs(a); }}}};
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
GiNaC::ex constant_power_derivative(const GiNaC::ex& u, const GiNaC::ex& p, unsigned wrt);
unsigned constant_power_serial() {
  static const unsigned serial = GiNaC::function::register_new(
      GiNaC::function_options("phiq_pow", 2).derivative_func(constant_power_derivative));
  return serial;
}
GiNaC::ex constant_power(const GiNaC::ex& u, const GiNaC::ex& p) {
  return GiNaC::function(constant_power_serial(), u, p);
}
GiNaC::ex constant_power_derivative(const GiNaC::ex& u, const GiNaC::ex& p, unsigned wrt) {
  // ∂/∂p is never asked for (p is a constant), but is the exact one: u^p ln u
  return wrt == 0 ? p * constant_power(u, p - 1) : constant_power(u, p) * GiNaC::log(u);
}
bool is_constant_power(const GiNaC::ex& e) {
  return GiNaC::is_a<GiNaC::function>(e) && GiNaC::ex_to<GiNaC::function>(e).get_serial() == constant_power_serial();
}
// A power of either kind: GiNaC's own (numeric exponents from its derivatives, sqrt; exponents that are not
// constant) or phiq_pow; op(0) is the base and op(1) the exponent of both.
bool is_power(const GiNaC::ex& e) { return GiNaC::is_a<GiNaC::power>(e) || is_constant_power(e); }
}  // namespace

// GiNaC keeps the terms of a sum and the factors of a product in an order that follows hash values, seeded from
// the addresses of its classes' type names (which address-space randomisation moves from one process to the
// next) and from its symbols' serial numbers (which depend on what was compiled before). It also writes a sum
// that is a factor or an integer power's base with whichever sign makes its first term in that order positive:
// x − y in one process, −(y − x) in another. Emitted in GiNaC's order, the same text gave differently rounded
// tapes from run to run (the last bits of a scene's CSV). So the builder keeps an order of its own: each
// subexpression becomes a register and a sign (Signed: the value is −reg when neg), the terms and factors of
// sums and products are emitted in the order of their registers (constants first, then by a fingerprint of the
// register's computation, which knows nothing of GiNaC's hashes), a sum takes the sign that makes its first term
// in that order positive, and signs are carried out of products, integer powers, abs and csgn to where a value is
// needed. take() then numbers the registers in the order the outputs use them. The same text compiles to the same
// tape, hence the same bits, in every process. Common subexpressions are shared by hashing each instruction.
class TapeBuilder {
 public:
  TapeBuilder(const std::map<std::string, Index>& coord_of_symbol,
              const std::map<std::string, double>& value_of_constant, const std::string& text)
      : coord_of_symbol_(coord_of_symbol), value_of_constant_(value_of_constant), text_(text) {}

  void add_output(const GiNaC::ex& e) { outputs_.push_back(value(emit(e))); }

  // The program the outputs use, its registers numbered in the order they use them (operands first, a before b):
  // instructions no output uses (operands of folded constants, terms emitted before they were sorted) are left
  // out, and the numbering depends on the computation alone, not on the order GiNaC handed it over in.
  Tape take() {
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    const std::vector<Tape::Instr>& code = tape_.code_;
    Tape out;
    std::vector<std::uint32_t> index(code.size(), kNone);
    std::vector<std::pair<std::uint32_t, bool>> stack;  // register, operands already placed (no recursion: the
    for (const std::uint32_t r : outputs_) {            // tape may be a chain of 50 000 instructions)
      stack.emplace_back(r, false);
      while (!stack.empty()) {
        const auto [x, placed] = stack.back();
        const Tape::Instr& in = code[x];
        if (index[x] != kNone) {
          stack.pop_back();
        } else if (!placed && reads_registers(in.op)) {
          stack.back().second = true;
          if (is_binary(in.op)) stack.emplace_back(in.b, false);
          stack.emplace_back(in.a, false);
        } else {
          Tape::Instr c = in;
          if (reads_registers(in.op)) c.a = index[in.a], c.b = is_binary(in.op) ? index[in.b] : 0;
          index[x] = static_cast<std::uint32_t>(out.code_.size());
          out.code_.push_back(c);
          stack.pop_back();
        }
      }
      out.outputs_.push_back(index[r]);
    }
    return out;
  }

 private:
  using Op = Tape::Op;
  struct Signed {
    std::uint32_t reg;
    bool neg;  // the value is −reg
  };

  static bool reads_registers(Op op) {
    return !(op == Op::kConst || op == Op::kLoadQ || op == Op::kLoadQd || op == Op::kLoadT);
  }
  static std::uint64_t bits(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
  }
  static std::uint64_t mix(std::uint64_t h, std::uint64_t v) {  // splitmix64's finaliser of h combined with v
    std::uint64_t z = h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  std::uint32_t push(Op op, std::uint32_t a = 0, std::uint32_t b = 0, double imm = 0.0) {
    // Constant folding: numbers reach GiNaC as symbols (see ExpressionParser), so their arithmetic happens here,
    // in double precision, exactly as the tape would do it. A constant part that is not a finite real (sqrt(-1),
    // 1/0, exp(1000)) is refused at compile time rather than left as a NaN in the residual.
    if (reads_registers(op) && is_const(a) && (!is_binary(op) || is_const(b))) {
      const double v = apply(op, tape_.code_[a].imm, tape_.code_[b].imm, imm);
      if (!std::isfinite(v))
        fail(std::string("a constant part of it is not a finite real number (") +
             (std::isnan(v) ? "NaN" : v > 0 ? "+inf" : "-inf") + ")");
      op = Op::kConst, a = 0, b = 0, imm = v;
    }
    if (tape_.code_.size() >= CompiledExpression::kMaxTapeSize)
      fail("its derivatives compile to more than " + std::to_string(CompiledExpression::kMaxTapeSize) +
           " instructions; the limit is " + std::to_string(CompiledExpression::kMaxTapeSize));
    auto key = std::make_tuple(static_cast<int>(op), a, b, bits(imm));
    auto it = cse_.find(key);
    if (it != cse_.end()) return it->second;
    // the fingerprint: the operation, and the inputs' indices, the constants' bits or the operands' fingerprints
    std::uint64_t h = mix(0x7068697100000000ULL, static_cast<std::uint64_t>(op));
    if (op == Op::kConst) h = mix(h, bits(imm));
    else if (!reads_registers(op)) h = mix(h, a);
    else h = mix(mix(mix(h, fingerprint_[a]), is_binary(op) ? fingerprint_[b] : 0), bits(imm));
    tape_.code_.push_back(Tape::Instr{op, a, b, imm});
    fingerprint_.push_back(h);
    auto reg = static_cast<std::uint32_t>(tape_.code_.size() - 1);
    cse_.emplace(key, reg);
    return reg;
  }
  std::uint32_t constant(double v) { return push(Op::kConst, 0, 0, v); }
  bool is_const(std::uint32_t r) const { return r < tape_.code_.size() && tape_.code_[r].op == Op::kConst; }
  bool is_const(std::uint32_t r, double v) const { return is_const(r) && tape_.code_[r].imm == v; }
  Signed number(double v) { return {constant(std::fabs(v)), std::signbit(v)}; }
  std::uint32_t value(Signed s) { return s.neg ? push(Op::kNeg, s.reg) : s.reg; }

  // The order terms and factors are emitted in: constants first (so that they fold together), then by
  // fingerprint; two different registers with one fingerprint (a 64-bit collision) by their structure.
  bool before(std::uint32_t x, std::uint32_t y) const {
    if (x == y) return false;
    if (is_const(x) != is_const(y)) return is_const(x);
    if (fingerprint_[x] != fingerprint_[y]) return fingerprint_[x] < fingerprint_[y];
    const Tape::Instr& a = tape_.code_[x];
    const Tape::Instr& b = tape_.code_[y];
    if (a.op != b.op) return a.op < b.op;
    if (bits(a.imm) != bits(b.imm)) return bits(a.imm) < bits(b.imm);
    if (!reads_registers(a.op)) return a.a < b.a;
    return a.a != b.a ? before(a.a, b.a) : before(a.b, b.b);  // unequal somewhere: CSE merges equal ones
  }

  [[noreturn]] void fail(const std::string& what) const { throw expression_error(text_, what); }

  // GiNaC expressions are DAGs with shared subexpressions: memoise on the node so that each is emitted once
  // (a tree walk would revisit shared subtrees, exponentially in the worst case).
  Signed emit(const GiNaC::ex& e) {
    auto it = memo_.find(e);
    if (it != memo_.end()) return it->second;
    const Signed s = emit_node(e);
    memo_.emplace(e, s);
    return s;
  }

  // ±(t1 ± t2 ± …), terms in canonical order. Of the sum and its negation (the form GiNaC may hand over instead),
  // the one whose sorted terms come first is emitted: its first term is positive, and where a term appears with
  // both signs (two constants of one value: 0.5 - (0.5 - a)) the terms after it decide. A sum equal to its
  // negation (each term as often with either sign: 0.5*x - 0.5*x) is 0, as GiNaC would have made it had it known
  // the two constants were equal; its sign could not be chosen the same way in every process.
  Signed sum(std::vector<Signed> terms) {
    // terms that are 0 (a product with a factor 0, below) are left out: their sign is not canonical
    terms.erase(std::remove_if(terms.begin(), terms.end(), [&](const Signed& s) { return is_const(s.reg, 0.0); }),
                terms.end());
    if (terms.empty()) return {constant(0.0), false};
    auto less = [&](const Signed& x, const Signed& y) { return x.reg != y.reg ? before(x.reg, y.reg) : x.neg < y.neg; };
    std::vector<Signed> negated = terms;
    for (Signed& s : negated) s.neg = !s.neg;
    std::sort(terms.begin(), terms.end(), less);
    std::sort(negated.begin(), negated.end(), less);
    const bool neg = std::lexicographical_compare(negated.begin(), negated.end(), terms.begin(), terms.end(), less);
    if (!neg && !std::lexicographical_compare(terms.begin(), terms.end(), negated.begin(), negated.end(), less))
      return {constant(0.0), false};
    const std::vector<Signed>& emitted = neg ? negated : terms;
    std::uint32_t acc = emitted.front().reg;
    for (std::size_t i = 1; i < emitted.size(); ++i)
      acc = push(emitted[i].neg ? Op::kSub : Op::kAdd, acc, emitted[i].reg);
    return {acc, neg};
  }

  // ±Π base^exponent. Factors with one base are multiplied as one power, their exponents added (x^3/x is x^2,
  // with 3 − 1 folded: finite at x = 0, as the text means); factors with the exponent −1 are divided by last.
  Signed product(const std::vector<std::pair<GiNaC::ex, GiNaC::ex>>& factors) {
    struct Factor {
      Signed base;
      std::uint32_t exponent;
      bool integer, odd;  // the exponent is a constant integer, odd
    };
    std::vector<Factor> fs;
    for (const auto& [b, x] : factors) {
      const Signed base = emit(b);
      const std::uint32_t exponent = value(emit(x));
      const double p = is_const(exponent) ? tape_.code_[exponent].imm : 0.0;
      const bool integer = is_const(exponent) && p == std::round(p);
      fs.push_back({base, exponent, integer, integer && std::fmod(p, 2.0) != 0.0});
    }
    // A sign comes out of an integer power, (−u)^k = ±u^k; under any other exponent it stays in the base, −u. Where
    // one product has both u^k and (−u)^p (GiNaC merges √(−u)·(−u) into (−u)^(3/2) in some processes and leaves
    // it in others), u^k goes to the base −u as ±(−u)^k, so that the two are merged in every process.
    std::vector<std::uint32_t> negated;  // u where −u is a base with an exponent that is not an integer
    for (const Factor& f : fs)
      if (!f.integer && f.base.neg) negated.push_back(f.base.reg);
    bool neg = false;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> powers;  // base, exponent
    for (const Factor& f : fs) {
      std::uint32_t base = f.base.reg;
      if (!f.integer) {
        base = value(f.base);
      } else if (std::find(negated.begin(), negated.end(), base) != negated.end()) {
        base = push(Op::kNeg, base);
        neg ^= !f.base.neg && f.odd;
      } else {
        neg ^= f.base.neg && f.odd;
      }
      if (!is_const(base, 1.0)) powers.emplace_back(base, f.exponent);
    }
    // A factor 0 (a sum found to be 0 here, as GiNaC would have found it had it known that two constants were
    // equal) makes the product 0, of no sign; a division by it is refused, as GiNaC refuses one by its own zeros.
    bool zero = false;
    for (const auto& [base, x] : powers) {
      if (!is_const(base, 0.0) || !is_const(x)) continue;
      if (tape_.code_[x].imm < 0.0) fail("division by zero");
      zero = zero || tape_.code_[x].imm > 0.0;
    }
    if (zero) return {constant(0.0), false};
    std::sort(powers.begin(), powers.end(), [&](const auto& x, const auto& y) {
      return x.first != y.first ? before(x.first, y.first) : before(x.second, y.second);
    });
    std::optional<std::uint32_t> acc;
    std::vector<std::uint32_t> divisors;
    for (std::size_t i = 0; i < powers.size();) {
      const std::uint32_t base = powers[i].first;
      std::uint32_t x = powers[i].second;
      for (++i; i < powers.size() && powers[i].first == base; ++i) x = push(Op::kAdd, x, powers[i].second);
      if (is_const(x, 0.0)) continue;
      if (is_const(x, -1.0)) {  // a * b^(-1) is emitted as a division
        divisors.push_back(base);
        continue;
      }
      const std::uint32_t f = emit_power(base, x);
      acc = acc ? push(Op::kMul, *acc, f) : f;
    }
    for (const std::uint32_t d : divisors) acc = acc ? push(Op::kDiv, *acc, d) : push(Op::kDiv, constant(1.0), d);
    return {acc ? *acc : constant(1.0), neg};
  }

  // base^exponent. Constant integer and half-integer exponents by multiplication, sqrt and repeated squaring, as
  // accurate as the operations they stand for.
  std::uint32_t emit_power(std::uint32_t base, std::uint32_t exponent) {
    if (is_const(exponent)) {
      const double x = tape_.code_[exponent].imm;
      auto small_int = [](double v) { return v == std::round(v) && std::fabs(v) <= 1024; };
      if (small_int(x)) {
        const long k = std::lround(x);
        if (k == 0) return constant(1.0);
        if (k == 1) return base;
        if (k == 2) return push(Op::kMul, base, base);
        if (k == -1) return push(Op::kDiv, constant(1.0), base);
        return push(Op::kPowInt, base, 0, static_cast<double>(k));
      }
      if (small_int(2 * x)) {
        const long k = std::lround(2 * x);
        if (k == 1) return push(Op::kSqrt, base);
        if (k == -1) return push(Op::kDiv, constant(1.0), push(Op::kSqrt, base));
        return push(Op::kPowHalf, base, 0, static_cast<double>(k));  // one instruction: γ's closed forms
      }
    }
    return push(Op::kPow, base, exponent);
  }

  Signed emit_node(const GiNaC::ex& e) {
    using namespace GiNaC;
    if (is_a<numeric>(e)) {
      const numeric& n = ex_to<numeric>(e);
      if (!n.is_real()) fail("complex value " + to_text(e));
      return number(n.to_double());
    }
    if (is_a<GiNaC::constant>(e)) return number(ex_to<numeric>(evalf(e)).to_double());
    if (is_a<symbol>(e)) {
      const std::string name = ex_to<symbol>(e).get_name();
      if (name == "t") return {push(Op::kLoadT), false};
      if (auto c = value_of_constant_.find(name); c != value_of_constant_.end()) return number(c->second);
      if (name.rfind("qd:", 0) == 0)
        return {push(Op::kLoadQd, static_cast<std::uint32_t>(std::stoll(name.substr(3)))), false};
      auto it = coord_of_symbol_.find(name);
      if (it == coord_of_symbol_.end()) fail("internal: unbound symbol " + name);
      return {push(Op::kLoadQ, static_cast<std::uint32_t>(it->second)), false};
    }
    if (is_a<add>(e)) {
      std::vector<Signed> terms;
      for (std::size_t i = 0; i < e.nops(); ++i) terms.push_back(emit(e.op(i)));
      return sum(std::move(terms));
    }
    if (is_a<mul>(e)) {
      std::vector<std::pair<ex, ex>> factors;  // the numeric coefficient, if any, is a factor with exponent 1
      for (std::size_t i = 0; i < e.nops(); ++i) {
        const ex& f = e.op(i);
        factors.emplace_back(is_power(f) ? f.op(0) : f, is_power(f) ? f.op(1) : ex(1));
      }
      return product(factors);
    }
    if (is_power(e)) return product({{e.op(0), e.op(1)}});
    if (is_a<function>(e)) {
      const std::string name = ex_to<function>(e).get_name();
      if (name == "abs" && e.nops() == 1) return {push(Op::kAbs, emit(e.op(0)).reg), false};  // |−u| = |u|
      if (name == "csgn" && e.nops() == 1) {  // GiNaC's derivative of abs; csgn(−u) = −csgn(u)
        const Signed u = emit(e.op(0));
        return {push(Op::kSign, u.reg), u.neg};
      }
      auto it = supported_functions().find(name);
      if (it != supported_functions().end() && static_cast<int>(e.nops()) == it->second.arity) {
        const std::uint32_t a = value(emit(e.op(0)));
        return {it->second.arity == 1 ? push(it->second.op, a) : push(it->second.op, a, value(emit(e.op(1)))), false};
      }
      fail("function '" + name + "' is not supported (supported: " + supported_function_list() + ")");
    }
    fail("unsupported term " + to_text(e));
  }

  static std::string to_text(const GiNaC::ex& e) {
    std::ostringstream s;
    s << e;
    return s.str();
  }

  const std::map<std::string, Index>& coord_of_symbol_;
  const std::map<std::string, double>& value_of_constant_;
  const std::string& text_;
  Tape tape_;                               // every instruction pushed, in the order pushed
  std::vector<std::uint64_t> fingerprint_;  // per instruction of tape_
  std::vector<std::uint32_t> outputs_;
  std::map<std::tuple<int, std::uint32_t, std::uint32_t, std::uint64_t>, std::uint32_t> cse_;
  std::unordered_map<GiNaC::ex, Signed, std::hash<GiNaC::ex>, GiNaC::ex_is_equal> memo_;
};

// ---------------------------------------------------------------------------------------------------------------
// Parsing

namespace {

// "expression "<first 60 characters>...": <what>" — built with a stream: GCC 12 warns falsely (-Wrestrict,
// PR 105329) on "literal" + std::string temporaries.
Error expression_error(const std::string& text, const std::string& what) {
  std::ostringstream s;
  s << "expression \"" << single_line(text.substr(0, 60)) << (text.size() > 60 ? "..." : "") << "\": "
    << single_line(what);
  return Error(s.str());
}

std::string first_line(const std::string& s) {
  auto p = s.find('\n');
  return p == std::string::npos ? s : s.substr(0, p);
}

// GiNaC's messages carry its own source location; keep what a user can act on.
std::string clean_ginac_message(std::string m) {
  m = first_line(m);
  const std::string prefix = "GiNaC: ";
  if (m.rfind(prefix, 0) == 0) m = m.substr(prefix.size());
  return m;
}

bool is_ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }


// phiq's own recursive-descent parser, building the GiNaC expression operation by operation. GiNaC's text parser
// is not used: it crashes on input as small as "sin()" (found by fuzzing), knows dozens of functions phiq cannot
// evaluate, and reads x^-1 + y as x^(-1 + y). GiNaC is also kept away from numbers: it evaluates them exactly and
// eagerly, and on text a user (or a fuzzer) can write that recurses without bound (atan2 of complex constants
// such as (-1)^(1/2)) or never finishes (exact powers such as ((2*x)^1024)^1024 or 9^9^9). So every operation
// whose operands are all constant is folded here in double precision, with the very operation the tape evaluates
// (apply()), and its result reaches GiNaC as a fresh real symbol (its value kept for TapeBuilder); so do literals,
// parameters and pi. The one exact number GiNaC sees is 0 (so that 0*x makes no column), and an operation that
// cancels to a number (x - x, x/x) is folded at once. GiNaC is left with what it is for: exact differentiation.
//
// Grammar (usual precedence; ^ binds tighter than unary minus, -x^2 = -(x^2); a chained x^a^b is ambiguous and
// refused; a signed exponent x^-2 is x^(-2)):
//   sum      := product (('+' | '-') product)*
//   product  := unary (('*' | '/') unary)*
//   unary    := ('-' | '+') unary | power
//   power    := primary ('^' exponent)?
//   exponent := ('-' | '+') exponent | primary
//   primary  := number | name | function '(' sum (',' sum)* ')' | '(' sum ')'
class ExpressionParser {
 public:
  struct Node {
    GiNaC::ex e;            // the expression GiNaC sees: 0, a real symbol, or a term in coordinates and t
    bool constant = false;  // true when it depends on neither q nor t
    double value = 0.0;     // its value when constant
  };
  // What a name stands for: a constant value, or a GiNaC symbol (a coordinate or t).
  struct Name {
    std::optional<double> value;
    GiNaC::ex symbol;
  };
  using NameLookup = std::function<Name(const std::string&)>;

  ExpressionParser(const std::string& text, NameLookup name, std::map<std::string, double>& value_of_constant)
      : text_(text), name_(std::move(name)), value_of_constant_(value_of_constant) {}

  Node parse() {
    Node n = sum();
    skip_space();
    if (pos_ < text_.size()) {
      if (text_[pos_] == ')') fail_at("')' without a matching '('");
      fail_at("expected an operator before '" + token_text() + "'");
    }
    return n;
  }

  // A constant: 0 stays exact, anything else becomes a real symbol GiNaC cannot do arithmetic with.
  Node constant(double v) {
    if (!std::isfinite(v))
      fail(std::string("a constant part of it is not a finite real number (") +
           (std::isnan(v) ? "NaN" : v > 0 ? "+inf" : "-inf") + ")");
    if (v == 0.0) return Node{0, true, 0.0};
    const std::string symbol_name = "k:" + std::to_string(value_of_constant_.size());
    value_of_constant_[symbol_name] = v;
    return Node{GiNaC::realsymbol(symbol_name), true, v};
  }

 private:
  using Op = Tape::Op;

  [[noreturn]] void fail(const std::string& what) const { throw expression_error(text_, what); }
  [[noreturn]] void fail_at(const std::string& what) const {
    fail(what + " (column " + std::to_string(pos_ + 1) + ")");
  }

  // The parser recurses once per parenthesis level: bounded.
  void enter_parentheses() {
    if (++depth_ > CompiledExpression::kMaxNesting)
      fail("nested more than " + std::to_string(CompiledExpression::kMaxNesting) + " parentheses deep");
  }

  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  char peek() {
    skip_space();
    return pos_ < text_.size() ? text_[pos_] : '\0';
  }
  bool accept(char c) {
    if (peek() != c) return false;
    ++pos_;
    return true;
  }
  void expect(char c, const char* what) {
    if (accept(c)) return;
    if (pos_ >= text_.size()) fail(std::string("missing ") + what + " at the end");
    fail_at(std::string("expected ") + what + " before '" + token_text() + "'");
  }
  std::string token_text() const {  // the token at pos_, for messages
    std::size_t end = pos_ + 1;
    if (is_ident_char(text_[pos_]))
      while (end < text_.size() && is_ident_char(text_[end])) ++end;
    return text_.substr(pos_, std::min<std::size_t>(end - pos_, 40));
  }

  // The result of a GiNaC operation on operands not all constant: a number (by cancellation) is folded at once.
  Node settle(const GiNaC::ex& r) {
    if (GiNaC::is_a<GiNaC::numeric>(r)) {
      const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(r);
      if (!n.is_real()) fail("a constant part of it is not a finite real number (complex)");
      return constant(n.to_double());
    }
    return Node{r, false, 0.0};
  }

  Node negate(const Node& a) { return a.constant ? constant(-a.value) : settle(-a.e); }

  // A supported function of its arguments: folded when they are all constant, else built by GiNaC.
  Node call_function(const FunctionSpec& f, const std::vector<Node>& args) {
    const bool constant_args = std::all_of(args.begin(), args.end(), [](const Node& n) { return n.constant; });
    if (constant_args) return constant(apply(f.op, args[0].value, f.arity == 2 ? args[1].value : 0.0, 0.0));
    return settle(f.arity == 1 ? f.make1(args[0].e) : f.make2(args[0].e, args[1].e));
  }

  Node binary_op(Op op, const Node& a, const Node& b) {
    if (op == Op::kDiv && b.constant && b.value == 0.0) fail("division by zero");
    if (a.constant && b.constant) return constant(apply(op, a.value, b.value, 0.0));
    switch (op) {
      case Op::kAdd: return settle(a.e + b.e);
      case Op::kSub: return settle(a.e - b.e);
      case Op::kMul: return settle(a.e * b.e);
      case Op::kDiv: return settle(a.e / b.e);
      case Op::kPow:
        if (!b.constant) return settle(GiNaC::pow(a.e, b.e));
        if (b.value == 0.0) return constant(1.0);  // x^0 = 1, also at x = 0 (as the tape's power computes it)
        if (b.value == 1.0) return a;               // x^1 = x, for GiNaC too (x^1 - x cancels)
        return settle(constant_power(a.e, b.e));
      default: fail("internal: binary operation " + std::to_string(static_cast<int>(op)));
    }
  }

  Node sum() {
    Node n = product();
    for (;;) {
      if (accept('+')) n = binary_op(Op::kAdd, n, product());
      else if (accept('-')) n = binary_op(Op::kSub, n, product());
      else return n;
    }
  }

  Node product() {
    Node n = unary();
    for (;;) {
      if (accept('*')) n = binary_op(Op::kMul, n, unary());
      else if (accept('/')) n = binary_op(Op::kDiv, n, unary());
      else return n;
    }
  }

  Node unary() {
    if (accept('-')) return negate(unary());
    if (accept('+')) return unary();
    return power();
  }

  Node power() {
    Node base = primary();
    if (!accept('^')) return base;
    Node n = binary_op(Op::kPow, base, exponent());
    if (peek() == '^') fail_at("x^a^b is ambiguous: write (x^a)^b or x^(a^b)");
    return n;
  }

  Node exponent() {
    if (accept('-')) return negate(exponent());
    if (accept('+')) return exponent();
    return primary();
  }

  Node primary() {
    const char c = peek();
    if (c == '\0') fail("an operand is missing at the end");
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (is_ident_start(c)) {
      const std::size_t start = pos_;
      while (pos_ < text_.size() && is_ident_char(text_[pos_])) ++pos_;
      const std::string name = text_.substr(start, pos_ - start);
      if (peek() == '(') return call(name, start);
      const Name n = name_(name);
      return n.value ? constant(*n.value) : Node{n.symbol, false, 0.0};
    }
    if (accept('(')) {
      enter_parentheses();
      Node n = sum();
      expect(')', "')'");
      --depth_;
      return n;
    }
    fail_at("expected a number, a name or '(' before '" + token_text() + "'");
  }

  Node number() {
    const std::size_t start = pos_;
    const std::size_t n = text_.size();
    while (pos_ < n && (std::isdigit(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '.')) ++pos_;
    if (pos_ < n && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      std::size_t j = pos_ + 1;
      if (j < n && (text_[j] == '+' || text_[j] == '-')) ++j;
      if (j < n && std::isdigit(static_cast<unsigned char>(text_[j]))) {
        pos_ = j;
        while (pos_ < n && std::isdigit(static_cast<unsigned char>(text_[pos_]))) ++pos_;
      }
    }
    while (pos_ < n && is_ident_char(text_[pos_])) ++pos_;  // "2x" is one malformed number, not 2 times x
    const std::string literal = text_.substr(start, pos_ - start);
    char* end = nullptr;
    const double v = std::strtod(literal.c_str(), &end);
    if (end != literal.c_str() + literal.size())
      fail("'" + literal.substr(0, 40) + "' is not a number");
    if (!std::isfinite(v)) fail("number '" + literal.substr(0, 40) + "' is out of the range of a double");
    return constant(v);
  }

  Node call(const std::string& name, std::size_t start) {
    auto it = supported_functions().find(name);
    if (it == supported_functions().end())
      fail("unknown function '" + name.substr(0, 40) + "' (supported: " + supported_function_list() + ")");
    expect('(', "'('");
    enter_parentheses();
    std::vector<Node> args;
    if (peek() != ')') {
      args.push_back(sum());
      while (accept(',')) args.push_back(sum());
    }
    expect(')', "')'");
    --depth_;
    const FunctionSpec& f = it->second;
    if (static_cast<int>(args.size()) != f.arity) {
      pos_ = start;
      fail_at("'" + name + "' takes " + std::to_string(f.arity) + " argument" + (f.arity == 1 ? "" : "s") +
              ", not " + std::to_string(args.size()));
    }
    return call_function(f, args);
  }

  const std::string& text_;
  NameLookup name_;
  std::map<std::string, double>& value_of_constant_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

std::shared_ptr<const CompiledExpression> CompiledExpression::compile(const std::string& text,
                                                                      const NameResolver& resolve,
                                                                      bool allow_time) {
  using namespace GiNaC;
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error("expression is empty");
  if (text.size() > kMaxTextLength)
    throw Error("expression of " + std::to_string(text.size()) + " characters; the limit is " +
                std::to_string(kMaxTextLength));
  auto out = std::make_shared<CompiledExpression>();
  out->text_ = text;

  std::map<std::string, Index> coord_of_symbol;     // symbol name -> coordinate index
  std::map<std::string, double> value_of_constant;  // symbol name -> value folded in by the tape builder
  std::map<Index, realsymbol> symbol_of_coord;      // one symbol per coordinate, however many names it has
  realsymbol tsym("t");
  auto lookup = [&](const std::string& name) -> ExpressionParser::Name {
    if (name == "pi") return {M_PI, {}};
    const std::optional<NameBinding> b = resolve(name);
    if (!b) {
      if (name == "t" && !allow_time) throw expression_error(text, "time 't' is not allowed here");
      throw expression_error(text, "unknown name '" + name.substr(0, 40) + "'");
    }
    switch (b->kind) {
      case NameBinding::Kind::kTime:
        if (!allow_time) throw expression_error(text, "time 't' is not allowed here");
        return {std::nullopt, tsym};
      case NameBinding::Kind::kConstant:
        if (!std::isfinite(b->value)) throw expression_error(text, "'" + name + "' is not finite");
        return {b->value, {}};
      case NameBinding::Kind::kCoordinate:
        break;
    }
    auto [it, fresh] = symbol_of_coord.try_emplace(b->coordinate, "q:" + std::to_string(b->coordinate));
    if (fresh) coord_of_symbol[it->second.get_name()] = b->coordinate;
    return {std::nullopt, it->second};
  };

  ex g;
  try {
    ExpressionParser parser(text, lookup, value_of_constant);
    g = parser.parse().e;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // GiNaC's own refusals, e.g. division by an exact zero
    throw expression_error(text, clean_ginac_message(e.what()));
  }

  // Keep only the coordinates the expression really depends on, in ascending index order.
  std::vector<std::pair<realsymbol, Index>> used;
  for (auto& [i, s] : symbol_of_coord)
    if (g.has(s)) used.emplace_back(s, i);
  out->depends_on_time_ = g.has(tsym);

  try {
    std::vector<ex> grad;
    for (std::size_t k = 0; k < used.size(); ++k) grad.push_back(g.diff(used[k].first));
    auto build = [&](const std::vector<ex>& outs) {
      TapeBuilder b(coord_of_symbol, value_of_constant, out->text_);
      for (const ex& e : outs) b.add_output(e);
      return b.take();
    };
    out->value_ = build({g});
    out->gradient_ = build(grad);
    out->partial_t_ = build({g.diff(tsym)});
    const std::size_t size = out->value_.size() + out->gradient_.size() + out->partial_t_.size();
    if (size > kMaxTapeSize)
      throw expression_error(text, "its derivatives compile to " + std::to_string(size) +
                                       " instructions; the limit is " + std::to_string(kMaxTapeSize));
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw expression_error(text, clean_ginac_message(e.what()));
  }
  for (auto& [s, i] : used) out->coords_.push_back(i);
  return out;
}

std::string CompiledExpression::listing() const {
  return "value:\n" + value_.listing() + "gradient:\n" + gradient_.listing() + "partial_t:\n" + partial_t_.listing();
}

double CompiledExpression::value(const double* q, double t) const {
  double v;
  value_.evaluate(q, nullptr, t, &v);
  return v;
}

void CompiledExpression::gradient(const double* q, double t, double* dg_dq) const {
  gradient_.evaluate(q, nullptr, t, dg_dq);
}

double CompiledExpression::partial_t(const double* q, double t) const {
  double v;
  partial_t_.evaluate(q, nullptr, t, &v);
  return v;
}

double CompiledExpression::gamma(const double* q, const double* qd, double t) const {
  // γ = −d²/ds² g(q + s q̇, t + s) at s = 0 (with q̈ = 0) = −2 w2
  double w[3];
  value_.taylor2(q, qd, t, w);
  return -2.0 * w[2];
}

std::shared_ptr<const CompiledExpression> CompiledExpression::rebind(const std::vector<Index>& target,
                                                                     const std::vector<double>& value,
                                                                     std::string text) const {
  if (value.size() < target.size()) throw Error("rebind: fewer values than targets");
  auto out = std::make_shared<CompiledExpression>();
  out->text_ = std::move(text);
  out->depends_on_time_ = depends_on_time_;
  auto patch = [&](const Tape& in) {
    Tape tape = in;
    for (Tape::Instr& ins : tape.code_) {
      if (ins.op != Tape::Op::kLoadQ) continue;
      if (ins.a >= target.size()) throw Error("rebind: compiled coordinate index out of range");
      const Index j = target[ins.a];
      if (j >= 0) {
        ins.a = static_cast<std::uint32_t>(j);
      } else {
        ins.op = Tape::Op::kConst;
        ins.imm = value[ins.a];
        ins.a = 0;
      }
    }
    return tape;
  };
  out->value_ = patch(value_);
  out->partial_t_ = patch(partial_t_);
  Tape grad = patch(gradient_);
  // one gradient output per distinct target coordinate, ascending; constants drop out
  std::vector<std::pair<Index, std::uint32_t>> cols;
  for (std::size_t k = 0; k < coords_.size(); ++k) {
    const auto c = static_cast<std::size_t>(coords_[k]);
    if (c >= target.size()) throw Error("rebind: compiled coordinate index out of range");
    if (target[c] >= 0) cols.emplace_back(target[c], grad.outputs_[k]);
  }
  std::stable_sort(cols.begin(), cols.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  grad.outputs_.clear();
  for (std::size_t k = 0; k < cols.size(); ++k) {
    if (!out->coords_.empty() && out->coords_.back() == cols[k].first) {
      grad.code_.push_back(Tape::Instr{Tape::Op::kAdd, grad.outputs_.back(), cols[k].second, 0.0});
      grad.outputs_.back() = static_cast<std::uint32_t>(grad.code_.size() - 1);
    } else {
      out->coords_.push_back(cols[k].first);
      grad.outputs_.push_back(cols[k].second);
    }
  }
  out->gradient_ = std::move(grad);
  return out;
}

double evaluate_constant_expression(const std::string& text,
                                    const std::function<std::optional<double>(const std::string&)>& constant) {
  auto expr = CompiledExpression::compile(
      text,
      [&](const std::string& name) -> std::optional<NameBinding> {
        if (auto v = constant(name)) return NameBinding{NameBinding::Kind::kConstant, -1, *v};
        return std::nullopt;
      },
      /*allow_time=*/false);
  return expr->value(nullptr, 0.0);
}

}  // namespace phiq
