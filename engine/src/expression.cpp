// GiNaC front end (parse, differentiate) and the register tape back end of equation constraints.
#include "phiq/expression.hpp"

#include <ginac/ginac.h>

#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <tuple>

namespace phiq {

// ---------------------------------------------------------------------------------------------------------------
// Tape evaluation

void Tape::evaluate(const double* q, const double* qd, double t, double* out) const {
  thread_local std::vector<double> r;
  if (r.size() < code_.size()) r.resize(code_.size());
  const std::size_t n = code_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = code_[i];
    double v;
    switch (in.op) {
      case Op::kConst: v = in.imm; break;
      case Op::kLoadQ: v = q[in.a]; break;
      case Op::kLoadQd: v = qd[in.a]; break;
      case Op::kLoadT: v = t; break;
      case Op::kAdd: v = r[in.a] + r[in.b]; break;
      case Op::kSub: v = r[in.a] - r[in.b]; break;
      case Op::kMul: v = r[in.a] * r[in.b]; break;
      case Op::kDiv: v = r[in.a] / r[in.b]; break;
      case Op::kNeg: v = -r[in.a]; break;
      case Op::kPowInt: {
        // exact repeated squaring for integer exponents (keeps x^2 and x^-1 as accurate as a multiply)
        long e = static_cast<long>(in.imm);
        double base = r[in.a];
        if (e < 0) { base = 1.0 / base; e = -e; }
        double acc = 1.0;
        while (e) { if (e & 1) acc *= base; base *= base; e >>= 1; }
        v = acc;
        break;
      }
      case Op::kPow: v = std::pow(r[in.a], r[in.b]); break;
      case Op::kSqrt: v = std::sqrt(r[in.a]); break;
      case Op::kSin: v = std::sin(r[in.a]); break;
      case Op::kCos: v = std::cos(r[in.a]); break;
      case Op::kTan: v = std::tan(r[in.a]); break;
      case Op::kAsin: v = std::asin(r[in.a]); break;
      case Op::kAcos: v = std::acos(r[in.a]); break;
      case Op::kAtan: v = std::atan(r[in.a]); break;
      case Op::kAtan2: v = std::atan2(r[in.a], r[in.b]); break;
      case Op::kExp: v = std::exp(r[in.a]); break;
      case Op::kLog: v = std::log(r[in.a]); break;
      case Op::kSinh: v = std::sinh(r[in.a]); break;
      case Op::kCosh: v = std::cosh(r[in.a]); break;
      case Op::kTanh: v = std::tanh(r[in.a]); break;
      case Op::kAbs: v = std::fabs(r[in.a]); break;
      case Op::kSign: v = (r[in.a] > 0) - (r[in.a] < 0); break;
      default: v = std::nan(""); break;
    }
    r[i] = v;
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) out[k] = r[outputs_[k]];
}

// ---------------------------------------------------------------------------------------------------------------
// GiNaC expression -> tape, with common subexpressions shared by hashing each instruction.

class TapeBuilder {
 public:
  TapeBuilder(const std::map<std::string, Index>& coord_of_symbol, const std::string& text)
      : coord_of_symbol_(coord_of_symbol), text_(text) {}

  void add_output(const GiNaC::ex& e) { tape_.outputs_.push_back(emit(e)); }
  Tape take() { return std::move(tape_); }

 private:
  using Op = Tape::Op;

  std::uint32_t push(Op op, std::uint32_t a = 0, std::uint32_t b = 0, double imm = 0.0) {
    std::uint64_t bits;
    std::memcpy(&bits, &imm, sizeof bits);
    auto key = std::make_tuple(static_cast<int>(op), a, b, bits);
    auto it = cse_.find(key);
    if (it != cse_.end()) return it->second;
    tape_.code_.push_back(Tape::Instr{op, a, b, imm});
    auto reg = static_cast<std::uint32_t>(tape_.code_.size() - 1);
    cse_.emplace(key, reg);
    return reg;
  }
  std::uint32_t constant(double v) { return push(Op::kConst, 0, 0, v); }

  [[noreturn]] void fail(const std::string& what) const {
    throw Error("expression \"" + text_ + "\": " + what);
  }

  std::uint32_t emit(const GiNaC::ex& e) {
    using namespace GiNaC;
    if (is_a<numeric>(e)) {
      const numeric& n = ex_to<numeric>(e);
      if (!n.is_real()) fail("complex value " + to_text(e));
      return constant(n.to_double());
    }
    if (is_a<GiNaC::constant>(e)) return constant(ex_to<numeric>(evalf(e)).to_double());
    if (is_a<symbol>(e)) {
      const std::string name = ex_to<symbol>(e).get_name();
      if (name == "t") return push(Op::kLoadT);
      if (name.rfind("qd:", 0) == 0) return push(Op::kLoadQd, static_cast<std::uint32_t>(std::stoll(name.substr(3))));
      auto it = coord_of_symbol_.find(name);
      if (it == coord_of_symbol_.end()) fail("internal: unbound symbol " + name);
      return push(Op::kLoadQ, static_cast<std::uint32_t>(it->second));
    }
    if (is_a<add>(e)) {
      std::uint32_t acc = emit(e.op(0));
      for (std::size_t i = 1; i < e.nops(); ++i) {
        const ex& term = e.op(i);
        // a - b is stored as a + (-1)*b; emit a subtraction instead of a multiply by -1
        if (is_a<mul>(term) && term.nops() >= 2 && term.op(term.nops() - 1).is_equal(-1)) {
          acc = push(Op::kSub, acc, emit(-term));
        } else {
          acc = push(Op::kAdd, acc, emit(term));
        }
      }
      return acc;
    }
    if (is_a<mul>(e)) {
      const ex& last = e.op(e.nops() - 1);
      if (last.is_equal(-1)) return push(Op::kNeg, emit(-e));
      std::uint32_t acc = emit(e.op(0));
      for (std::size_t i = 1; i < e.nops(); ++i) {
        const ex& f = e.op(i);
        // x * y^-1 is emitted as a division
        if (is_a<power>(f) && f.op(1).is_equal(-1)) acc = push(Op::kDiv, acc, emit(f.op(0)));
        else acc = push(Op::kMul, acc, emit(f));
      }
      return acc;
    }
    if (is_a<power>(e)) {
      const ex& base = e.op(0);
      const ex& expo = e.op(1);
      if (is_a<numeric>(expo)) {
        const numeric& n = ex_to<numeric>(expo);
        if (n.is_integer()) {
          long k = n.to_long();
          if (k == 1) return emit(base);
          std::uint32_t b = emit(base);
          if (k == 2) return push(Op::kMul, b, b);
          if (k == -1) return push(Op::kDiv, constant(1.0), b);
          return push(Op::kPowInt, b, 0, static_cast<double>(k));
        }
        if (n.is_rational() && n.denom().is_equal(2)) {
          std::uint32_t s = push(Op::kSqrt, emit(base));
          long k = n.numer().to_long();
          if (k == 1) return s;
          if (k == -1) return push(Op::kDiv, constant(1.0), s);
          return push(Op::kPowInt, s, 0, static_cast<double>(k));
        }
      }
      return push(Op::kPow, emit(base), emit(expo));
    }
    if (is_a<function>(e)) {
      const std::string name = ex_to<function>(e).get_name();
      static const std::map<std::string, Op> unary = {
          {"sin", Op::kSin},   {"cos", Op::kCos},   {"tan", Op::kTan},   {"asin", Op::kAsin},
          {"acos", Op::kAcos}, {"atan", Op::kAtan}, {"exp", Op::kExp},   {"log", Op::kLog},
          {"sinh", Op::kSinh}, {"cosh", Op::kCosh}, {"tanh", Op::kTanh}, {"abs", Op::kAbs},
          {"csgn", Op::kSign}};
      if (name == "atan2" && e.nops() == 2) return push(Op::kAtan2, emit(e.op(0)), emit(e.op(1)));
      auto it = unary.find(name);
      if (it != unary.end() && e.nops() == 1) return push(it->second, emit(e.op(0)));
      fail("function '" + name + "' is not supported (supported: sin cos tan asin acos atan atan2 exp log sqrt "
           "sinh cosh tanh abs)");
    }
    fail("unsupported term " + to_text(e));
  }

  static std::string to_text(const GiNaC::ex& e) {
    std::ostringstream s;
    s << e;
    return s.str();
  }

  const std::map<std::string, Index>& coord_of_symbol_;
  const std::string& text_;
  Tape tape_;
  std::map<std::tuple<int, std::uint32_t, std::uint32_t, std::uint64_t>, std::uint32_t> cse_;
};

// ---------------------------------------------------------------------------------------------------------------
// Parsing

namespace {

bool is_ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Names used as variables in `text` (identifiers not directly followed by '('); numbers are skipped whole so that
// the 'e' of 1e-3 is not taken for a name.
std::vector<std::string> variable_names(const std::string& text) {
  std::vector<std::string> names;
  std::size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c)) || (c == '.' && i + 1 < text.size() &&
                                                         std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
      while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
      if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        std::size_t j = i + 1;
        if (j < text.size() && (text[j] == '+' || text[j] == '-')) ++j;
        if (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) {
          i = j;
          while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
        }
      }
    } else if (is_ident_start(c)) {
      std::size_t j = i;
      while (j < text.size() && is_ident_char(text[j])) ++j;
      std::size_t k = j;
      while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
      if (k >= text.size() || text[k] != '(') names.push_back(text.substr(i, j - i));
      i = j;
    } else {
      ++i;
    }
  }
  return names;
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
  auto p = m.find("at line 0, column 0: ");
  if (p != std::string::npos) m.erase(p, std::strlen("at line 0, column 0: "));
  return m;
}

}  // namespace

std::shared_ptr<const CompiledExpression> CompiledExpression::compile(const std::string& text,
                                                                      const NameResolver& resolve,
                                                                      bool allow_time) {
  using namespace GiNaC;
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error("expression is empty");
  auto out = std::make_shared<CompiledExpression>();
  out->text_ = text;

  symtab table;
  std::map<std::string, Index> coord_of_symbol;  // symbol name -> coordinate index
  std::vector<std::pair<realsymbol, Index>> coord_symbols;
  realsymbol tsym("t");
  for (const std::string& name : variable_names(text)) {
    if (table.count(name)) continue;
    if (name == "pi") { table[name] = Pi; continue; }
    std::optional<NameBinding> b = resolve(name);
    if (!b) {
      if (name == "t" && !allow_time) throw Error("expression \"" + text + "\": time 't' is not allowed here");
      throw Error("expression \"" + text + "\": unknown name '" + name + "'");
    }
    switch (b->kind) {
      case NameBinding::Kind::kTime:
        if (!allow_time) throw Error("expression \"" + text + "\": time 't' is not allowed here");
        table[name] = tsym;
        break;
      case NameBinding::Kind::kConstant:
        if (!std::isfinite(b->value)) throw Error("expression \"" + text + "\": '" + name + "' is not finite");
        table[name] = numeric(b->value);
        break;
      case NameBinding::Kind::kCoordinate: {
        // symbol names are made unique per coordinate so that two names for one index could never alias wrongly
        realsymbol s("q:" + std::to_string(b->coordinate));
        table[name] = s;
        coord_of_symbol[s.get_name()] = b->coordinate;
        coord_symbols.emplace_back(s, b->coordinate);
        break;
      }
    }
  }

  ex g;
  try {
    parser reader(table);
    reader.strict = true;
    g = reader(text);
  } catch (const std::exception& e) {
    throw Error("expression \"" + text + "\": " + clean_ginac_message(e.what()));
  }

  // Keep only the coordinates the expression really depends on, in ascending index order.
  std::sort(coord_symbols.begin(), coord_symbols.end(), [](auto& a, auto& b) { return a.second < b.second; });
  std::vector<std::pair<realsymbol, Index>> used;
  for (auto& [s, i] : coord_symbols)
    if (g.has(s)) used.emplace_back(s, i);
  out->depends_on_time_ = g.has(tsym);

  // Velocity symbols for γ, bound by name in TapeBuilder ("qd:<index>").
  std::vector<realsymbol> qd;
  for (auto& [s, i] : used) qd.emplace_back("qd:" + std::to_string(i));

  try {
    // ψ = ġ with q̈ = 0 treated as a function of (q, q̇, t); then γ = −(Σ_k ψ_qk q̇k + ψ_t).
    std::vector<ex> grad;
    ex psi = g.diff(tsym);
    for (std::size_t k = 0; k < used.size(); ++k) {
      grad.push_back(g.diff(used[k].first));
      psi += grad.back() * qd[k];
    }
    ex gamma = psi.diff(tsym);
    for (std::size_t k = 0; k < used.size(); ++k) gamma += psi.diff(used[k].first) * qd[k];
    gamma = -gamma;

    auto build = [&](std::initializer_list<ex> outs) {
      TapeBuilder b(coord_of_symbol, out->text_);
      for (const ex& e : outs) b.add_output(e);
      return b.take();
    };
    out->value_ = build({g});
    {
      TapeBuilder b(coord_of_symbol, out->text_);
      for (const ex& d : grad) b.add_output(d);
      out->gradient_ = b.take();
    }
    out->partial_t_ = build({g.diff(tsym)});
    out->gamma_ = build({gamma});
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("expression \"" + text + "\": " + clean_ginac_message(e.what()));
  }
  for (auto& [s, i] : used) out->coords_.push_back(i);
  return out;
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
  double v;
  gamma_.evaluate(q, qd, t, &v);
  return v;
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
