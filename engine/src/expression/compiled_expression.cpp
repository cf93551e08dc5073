// The public CompiledExpression API: compile() (parse, keep the coordinates the text depends on, differentiate
// once with GiNaC, build the value, gradient and ∂/∂t tapes, enforce the size limits), the evaluations that run
// those tapes, rebind() (a compiled expression re-pointed at other coordinates by patching its tapes) and
// evaluate_constant_expression(). The pieces it assembles live in parser.cpp, tape_builder.cpp and tape.cpp.
#include <ginac/ginac.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "expression/messages.hpp"
#include "expression/parser.hpp"
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
    g = detail::parse_expression(text, lookup, value_of_constant);
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
  out->angle_difference_ = is_angle_difference(g);

  try {
    std::vector<ex> grad;
    for (std::size_t k = 0; k < used.size(); ++k) grad.push_back(g.diff(used[k].first));
    auto build = [&](const std::vector<ex>& outs) {
      return detail::compile_tape(outs, coord_of_symbol, value_of_constant, out->text_);
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
  out->angle_difference_ = angle_difference_;
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
