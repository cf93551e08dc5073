// GiNaC expression → register tape (TapeBuilder): phiq's own order of terms and factors, signs carried to where a
// value is needed, constants folded in double precision, common subexpressions shared, powers with constant
// exponents as repeated squaring. Separate from the tape's evaluation (tape.cpp), which runs in the Newton loop,
// and from the parser, which builds the GiNaC expressions this compiles.
#include "expression/tape_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "expression/messages.hpp"
#include "expression/symbolic.hpp"
#include "expression/tape_ops.hpp"

namespace phiq {

using detail::apply;
using detail::expression_error;
using detail::is_binary;
using detail::is_power;
using detail::supported_function_list;
using detail::supported_functions;

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
             (std::isnan(v) ? "NaN"
              : v > 0       ? "+inf"
                            : "-inf") +
             ")");
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
    if (op == Op::kConst)
      h = mix(h, bits(imm));
    else if (!reads_registers(op))
      h = mix(h, a);
    else
      h = mix(mix(mix(h, fingerprint_[a]), is_binary(op) ? fingerprint_[b] : 0), bits(imm));
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
      if ((name == "phiq_abs" || name == "abs") && e.nops() == 1)
        return {push(Op::kAbs, emit(e.op(0)).reg), false};             // |−u| = |u|
      if ((name == "phiq_sign" || name == "csgn") && e.nops() == 1) {  // |u|'s derivative; sign(−u) = −sign(u)
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

Tape detail::compile_tape(const std::vector<GiNaC::ex>& outputs, const std::map<std::string, Index>& coord_of_symbol,
                          const std::map<std::string, double>& value_of_constant, const std::string& text) {
  TapeBuilder b(coord_of_symbol, value_of_constant, text);
  for (const GiNaC::ex& e : outputs) b.add_output(e);
  return b.take();
}

}  // namespace phiq
