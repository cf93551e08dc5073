// The public CompiledExpression API: compile() (parse, keep the coordinates the text depends on, differentiate
// once with GiNaC, build the value, gradient and ∂/∂t tapes, enforce the size limits), the evaluations that run
// those tapes, rebind() (a compiled expression re-pointed at other coordinates by patching its tapes) and
// evaluate_constant_expression(). The pieces it assembles live in parser.cpp, tape_builder.cpp and tape.cpp.
#include <ginac/ginac.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include "expression/messages.hpp"
#include "expression/parser.hpp"
#include "expression/symbolic.hpp"
#include "expression/tape_builder.hpp"
#include "phiq/expression.hpp"

namespace phiq {

using detail::clean_ginac_message;
using detail::expression_error;

namespace {
// CompiledExpression::angle_difference(): every top-level term of g that holds an atan2 is ±atan2(…) itself, and
// there is at least one. (GiNaC keeps −atan2(…) as a product of the function and the number −1.)
bool is_angle_difference(const GiNaC::ex& g) {
  using namespace GiNaC;
  auto is_atan2 = [](const ex& e) { return is_the_function<atan2_SERIAL>(e); };
  auto signed_atan2 = [&](const ex& e) {
    if (is_atan2(e)) return true;
    if (!is_a<mul>(e) || e.nops() != 2) return false;
    for (std::size_t k = 0; k < 2; ++k)
      if (is_atan2(e.op(k)) && is_a<numeric>(e.op(1 - k)) && abs(ex_to<numeric>(e.op(1 - k))).is_equal(numeric(1)))
        return true;
    return false;
  };
  bool any = false;
  auto term = [&](const ex& e) {
    if (signed_atan2(e)) return any = true;
    return !e.has(atan2(wild(0), wild(1)));
  };
  if (is_a<add>(g)) {
    for (std::size_t k = 0; k < g.nops(); ++k)
      if (!term(g.op(k))) return false;
    return any;
  }
  return signed_atan2(g);
}
}  // namespace

// Where a compiled expression came from: its text (a family's with placeholders) and every name it read, with what
// the name was then, so that along_constants() can parse it again with the constants that move as symbols.
struct CompiledExpression::Source {
  std::string text;
  bool allow_time = true;
  bool allow_rates = false;
  std::vector<std::pair<std::string, NameBinding>> names;  // in the order the text first reads them; pi excluded
  std::size_t parameters = 0;                              // how many of them are constants (kConstant)
  // along_constants()' derivatives by their rates (of the parameters, then of the compiled indices): family
  // members whose constants move alike share one symbolic differentiation
  mutable std::mutex mutex;
  mutable std::map<std::vector<double>, std::shared_ptr<const CompiledExpression>> rates;
};

// GiNaC is not thread-safe: its expressions count references without atomics, and every expression shares the
// library's flyweights (the numbers 0, 1, −1, …), so two threads that merely build expressions race on them
// (ThreadSanitizer reports it at once for two threads compiling). Scenes are read on several threads (`phiq batch`,
// `phiq tolerance`, sensitivity_along()), so every use of GiNaC holds this lock, from the first symbol made to the
// last expression destroyed; the tapes it compiles to are plain data and run without it.
namespace {
std::mutex& ginac_mutex() {
  static std::mutex m;
  return m;
}
}  // namespace

// The symbols an expression is parsed into, and the values the tape builder folds in for the others.
struct Symbols {
  std::map<std::string, Index> coord_of_symbol;        // symbol name -> coordinate index
  std::map<std::string, double> value_of_constant;     // symbol name -> value folded in by the tape builder
  std::map<Index, GiNaC::realsymbol> symbol_of_coord;  // one symbol per coordinate, however many names it has
  std::map<Index, GiNaC::realsymbol> symbol_of_rate;   // q̇_i ("qd:<i>", which the tape builder loads as q̇)
  GiNaC::realsymbol t{"t"};
  GiNaC::ex coordinate(Index i) {
    auto [it, fresh] = symbol_of_coord.try_emplace(i, "q:" + std::to_string(i));
    if (fresh) coord_of_symbol[it->second.get_name()] = i;
    return it->second;
  }
  GiNaC::ex rate(Index i) { return symbol_of_rate.try_emplace(i, "qd:" + std::to_string(i)).first->second; }
  // der(u) = Σ ∂u/∂q_i q̇_i + ∂u/∂t, exactly; a u that reads q̇ already is refused (its rate would read q̈, which
  // no load is evaluated with)
  GiNaC::ex rate_of(const GiNaC::ex& u, const std::string& text) {
    for (const auto& [i, s] : symbol_of_rate)
      if (u.has(s)) throw detail::expression_error(text, "der() of a rate: an acceleration, which a load may not read");
    GiNaC::ex d = u.diff(t);
    const std::vector<std::pair<Index, GiNaC::realsymbol>> coords(symbol_of_coord.begin(), symbol_of_coord.end());
    for (const auto& [i, s] : coords)
      if (u.has(s)) d += u.diff(s) * rate(i);
    return d;
  }
};

// What compile() and along_constants() share: the symbolic work, g's tapes and what is read of it.
struct CompiledExpressionBuilder {
  // f(), GiNaC's own refusals (division by an exact zero, a derivative it cannot take) made one-line errors naming
  // `text`.
  template <class F>
  static auto symbolic(const std::string& text, F&& f) {
    try {
      return f();
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw expression_error(text, clean_ginac_message(e.what()));
    }
  }

  // parse_expression()'s der(), where rates may be read
  static detail::RateOf rate_hook(bool allow_rates, Symbols& sym, const std::string& text) {
    if (!allow_rates) return nullptr;
    return [&sym, &text](const GiNaC::ex& u) { return sym.rate_of(u, text); };
  }

  // The coordinates g depends on (and whose rates it reads), its flags, and its value, gradient, ∂/∂t and ∂/∂q̇
  // tapes into `out`.
  static void finish(CompiledExpression& out, const GiNaC::ex& g, const Symbols& sym) {
    using namespace GiNaC;
    // Keep only the coordinates the expression really depends on, in ascending index order.
    std::vector<std::pair<realsymbol, Index>> used, used_rates;
    for (auto& [i, s] : sym.symbol_of_coord)
      if (g.has(s)) used.emplace_back(s, i);
    for (auto& [i, s] : sym.symbol_of_rate)
      if (g.has(s)) used_rates.emplace_back(s, i);
    out.depends_on_time_ = g.has(sym.t);
    out.angle_difference_ = is_angle_difference(g);
    const std::string& text = out.text_;
    symbolic(text, [&] {
      std::vector<ex> grad, rate_grad;
      for (std::size_t k = 0; k < used.size(); ++k) grad.push_back(g.diff(used[k].first));
      for (std::size_t k = 0; k < used_rates.size(); ++k) rate_grad.push_back(g.diff(used_rates[k].first));
      auto build = [&](const std::vector<ex>& outs) {
        return detail::compile_tape(outs, sym.coord_of_symbol, sym.value_of_constant, text);
      };
      out.value_ = build({g});
      out.gradient_ = build(grad);
      out.partial_t_ = build({g.diff(sym.t)});
      out.rate_gradient_ = build(rate_grad);
      const std::size_t size =
          out.value_.size() + out.gradient_.size() + out.partial_t_.size() + out.rate_gradient_.size();
      if (size > CompiledExpression::kMaxTapeSize)
        throw expression_error(text, "its derivatives compile to " + std::to_string(size) +
                                         " instructions; the limit is " +
                                         std::to_string(CompiledExpression::kMaxTapeSize));
    });
    for (auto& [s, i] : used) out.coords_.push_back(i);
    for (auto& [s, i] : used_rates) out.rate_coords_.push_back(i);
  }

  // Σ_j key[j] ∂g/∂c_j of `source`'s text, key holding the rates of its parameters (source.parameters of them),
  // then of its compiled indices (a family's placeholders that a member binds to constants): the constants that
  // move become symbols, the others are folded as compile() folds them.
  static std::shared_ptr<const CompiledExpression> differentiate(const CompiledExpression::Source& source,
                                                                 const std::vector<double>& key) {
    using namespace GiNaC;
    const std::lock_guard<std::mutex> ginac(ginac_mutex());
    Symbols sym;
    std::vector<std::pair<realsymbol, double>> moving;  // the symbols that move, with their rates
    std::map<std::string, std::size_t> parameter_of;    // parameter name -> its place in key
    for (const auto& [name, b] : source.names)
      if (b.kind == NameBinding::Kind::kConstant) parameter_of.emplace(name, parameter_of.size());
    std::map<std::string, realsymbol> moving_of;
    auto lookup = [&](const std::string& name) -> detail::ParsedName {
      if (name == "pi") return {M_PI, {}};
      auto it = std::find_if(source.names.begin(), source.names.end(), [&](const auto& n) { return n.first == name; });
      if (it == source.names.end()) throw expression_error(source.text, "unknown name '" + name.substr(0, 40) + "'");
      const NameBinding& b = it->second;
      switch (b.kind) {
        case NameBinding::Kind::kTime:
          return {std::nullopt, sym.t};
        case NameBinding::Kind::kConstant: {
          const double rate = key[parameter_of.at(name)];
          if (rate == 0.0) return {b.value, {}};
          auto [m, fresh] = moving_of.try_emplace(name, "c:" + name);
          if (fresh) {
            sym.value_of_constant[m->second.get_name()] = b.value;
            moving.emplace_back(m->second, rate);
          }
          return {std::nullopt, m->second};
        }
        case NameBinding::Kind::kCoordinate:
          break;
      }
      return {std::nullopt, sym.coordinate(b.coordinate)};
    };
    const ex d = symbolic(source.text, [&] {
      const ex g = detail::parse_expression(source.text, lookup, sym.value_of_constant,
                                            rate_hook(source.allow_rates, sym, source.text));
      for (std::size_t k = source.parameters; k < key.size(); ++k) {
        if (key[k] == 0.0) continue;
        auto it = sym.symbol_of_coord.find(static_cast<Index>(k - source.parameters));
        if (it != sym.symbol_of_coord.end()) moving.emplace_back(it->second, key[k]);
      }
      // a moving exponent: g's power of a constant exponent (phiq_pow) is not the general power its rate needs
      for (auto e = g.preorder_begin(); e != g.preorder_end(); ++e)
        if (detail::is_power(*e))
          for (const auto& [s, rate] : moving)
            if (e->op(1).has(s)) throw expression_error(source.text, "a constant that moves is an exponent");
      // the rates reach GiNaC as symbols too (folded by the tape builder), as every number does (parser.cpp says
      // why)
      ex sum = 0;
      for (const auto& [s, rate] : moving) {
        const realsymbol r("r:" + s.get_name());
        sym.value_of_constant[r.get_name()] = rate;
        sum += r * g.diff(s);
      }
      return sum;
    });
    auto out = std::make_shared<CompiledExpression>();
    out->text_ = "rate of " + source.text;
    finish(*out, d, sym);
    return out;
  }
};

std::shared_ptr<const CompiledExpression> CompiledExpression::compile(const std::string& text,
                                                                      const NameResolver& resolve, bool allow_time,
                                                                      bool allow_rates) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw Error("expression is empty");
  if (text.size() > kMaxTextLength)
    throw Error("expression of " + std::to_string(text.size()) + " characters; the limit is " +
                std::to_string(kMaxTextLength));
  auto out = std::make_shared<CompiledExpression>();
  out->text_ = text;
  auto source = std::make_shared<Source>();
  source->text = text;
  source->allow_time = allow_time;
  source->allow_rates = allow_rates;

  const std::lock_guard<std::mutex> ginac(ginac_mutex());
  Symbols sym;
  auto note = [&](const std::string& name, const NameBinding& b) {
    for (const auto& n : source->names)
      if (n.first == name) return;
    source->names.emplace_back(name, b);
    if (b.kind == NameBinding::Kind::kConstant) out->constants_.push_back(b.value), ++source->parameters;
  };
  auto lookup = [&](const std::string& name) -> detail::ParsedName {
    if (name == "pi") return {M_PI, {}};
    const std::optional<NameBinding> b = resolve(name);
    if (!b) {
      if (name == "t" && !allow_time) throw expression_error(text, "time 't' is not allowed here");
      throw expression_error(text, "unknown name '" + name.substr(0, 40) + "'");
    }
    switch (b->kind) {
      case NameBinding::Kind::kTime:
        if (!allow_time) throw expression_error(text, "time 't' is not allowed here");
        note(name, *b);
        return {std::nullopt, sym.t};
      case NameBinding::Kind::kConstant:
        if (!std::isfinite(b->value)) throw expression_error(text, "'" + name + "' is not finite");
        note(name, *b);
        return {b->value, {}};
      case NameBinding::Kind::kCoordinate:
        break;
    }
    note(name, *b);
    return {std::nullopt, sym.coordinate(b->coordinate)};
  };

  const GiNaC::ex g = CompiledExpressionBuilder::symbolic(text, [&] {
    return detail::parse_expression(text, lookup, sym.value_of_constant,
                                    CompiledExpressionBuilder::rate_hook(allow_rates, sym, text));
  });
  CompiledExpressionBuilder::finish(*out, g, sym);
  out->source_ = std::move(source);
  return out;
}

bool CompiledExpression::same_source(const CompiledExpression& o) const {
  if (!source_ || !o.source_ || target_ != o.target_ || constants_.size() != o.constants_.size()) return false;
  if (source_ == o.source_) return true;
  const Source& a = *source_;
  const Source& b = *o.source_;
  if (a.text != b.text || a.allow_time != b.allow_time || a.allow_rates != b.allow_rates ||
      a.names.size() != b.names.size())
    return false;
  for (std::size_t k = 0; k < a.names.size(); ++k) {
    const auto& [na, ba] = a.names[k];
    const auto& [nb, bb] = b.names[k];
    if (na != nb || ba.kind != bb.kind || ba.coordinate != bb.coordinate) return false;
  }
  return true;
}

std::shared_ptr<const CompiledExpression> CompiledExpression::along_constants(const std::vector<double>& rate) const {
  if (rate.size() != constants_.size())
    throw Error("expression \"" + text_ + "\": " + std::to_string(rate.size()) + " rates for " +
                std::to_string(constants_.size()) + " constants");
  if (std::all_of(rate.begin(), rate.end(), [](double r) { return r == 0.0; })) return nullptr;
  if (!source_) throw Error("expression \"" + text_ + "\": not compiled from a text");
  // the rates of the parameters, then of the compiled indices (0 where a member binds a coordinate)
  const std::size_t parameters = source_->parameters;
  std::vector<double> key(rate.begin(), rate.begin() + static_cast<std::ptrdiff_t>(parameters));
  std::vector<double> value(target_.size(), 0.0);
  key.resize(parameters + target_.size(), 0.0);
  for (std::size_t k = 0, j = parameters; k < target_.size(); ++k)
    if (target_[k] < 0) key[parameters + k] = rate[j], value[k] = constants_[j], ++j;
  std::shared_ptr<const CompiledExpression> d;
  {
    std::lock_guard<std::mutex> lock(source_->mutex);
    if (auto it = source_->rates.find(key); it != source_->rates.end()) d = it->second;
  }
  if (!d) {
    d = CompiledExpressionBuilder::differentiate(*source_, key);
    std::lock_guard<std::mutex> lock(source_->mutex);
    source_->rates.emplace(key, d);
  }
  return target_.empty() ? d : d->rebind(target_, value, "rate of " + text_);
}

std::string CompiledExpression::listing() const {
  return "value:\n" + value_.listing() + "gradient:\n" + gradient_.listing() + "partial_t:\n" + partial_t_.listing() +
         (rate_coords_.empty() ? "" : "rate_gradient:\n" + rate_gradient_.listing());
}

double CompiledExpression::value(const double* q, const double* qd, double t) const {
  double v;
  value_.evaluate(q, qd, t, &v);
  return v;
}

void CompiledExpression::gradient(const double* q, const double* qd, double t, double* dg_dq) const {
  gradient_.evaluate(q, qd, t, dg_dq);
}

void CompiledExpression::rate_gradient(const double* q, const double* qd, double t, double* dg_dqd) const {
  rate_gradient_.evaluate(q, qd, t, dg_dqd);
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
  out->angle_difference_ = angle_difference_;
  if (source_ && target_.empty()) {  // its constants: the parameters', then those the rebinding gives
    out->source_ = source_;
    out->target_ = target;
    out->constants_ = constants_;
    for (std::size_t k = 0; k < target.size(); ++k)
      if (target[k] < 0) out->constants_.push_back(value[k]);
  }
  // a compiled index bound to a constant: its value, and its rate 0
  auto patch = [&](const Tape& in) {
    Tape tape = in;
    for (Tape::Instr& ins : tape.code_) {
      if (ins.op != Tape::Op::kLoadQ && ins.op != Tape::Op::kLoadQd) continue;
      if (ins.a >= target.size()) throw Error("rebind: compiled coordinate index out of range");
      const Index j = target[ins.a];
      if (j >= 0) {
        ins.a = static_cast<std::uint32_t>(j);
      } else {
        ins.imm = ins.op == Tape::Op::kLoadQ ? value[ins.a] : 0.0;
        ins.op = Tape::Op::kConst;
        ins.a = 0;
      }
    }
    return tape;
  };
  out->value_ = patch(value_);
  out->partial_t_ = patch(partial_t_);
  // one gradient output per distinct target coordinate, ascending; constants drop out
  auto columns = [&](const Tape& in, const std::vector<Index>& coords, std::vector<Index>& out_coords) {
    Tape grad = patch(in);
    std::vector<std::pair<Index, std::uint32_t>> cols;
    for (std::size_t k = 0; k < coords.size(); ++k) {
      const auto c = static_cast<std::size_t>(coords[k]);
      if (c >= target.size()) throw Error("rebind: compiled coordinate index out of range");
      if (target[c] >= 0) cols.emplace_back(target[c], grad.outputs_[k]);
    }
    std::stable_sort(cols.begin(), cols.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    grad.outputs_.clear();
    for (std::size_t k = 0; k < cols.size(); ++k) {
      if (!out_coords.empty() && out_coords.back() == cols[k].first) {
        grad.code_.push_back(Tape::Instr{Tape::Op::kAdd, grad.outputs_.back(), cols[k].second, 0.0});
        grad.outputs_.back() = static_cast<std::uint32_t>(grad.code_.size() - 1);
      } else {
        out_coords.push_back(cols[k].first);
        grad.outputs_.push_back(cols[k].second);
      }
    }
    return grad;
  };
  out->gradient_ = columns(gradient_, coords_, out->coords_);
  out->rate_gradient_ = columns(rate_gradient_, rate_coords_, out->rate_coords_);
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
