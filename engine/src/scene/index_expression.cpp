// The family index language (index_expression.hpp): its lexer (names with {templates}, numbers), the recursive
// descent that compiles a text into IndexExpr's stack program, the stack machine, and the rendering of templated
// names.
#include "scene/index_expression.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>

#include "phiq/expression.hpp"
#include "phiq/text.hpp"
#include "base/names.hpp"

namespace phiq::detail::scene {

namespace {

bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)); }

// End of the name that starts at text[i]: letters, digits, '_' and {template} groups ("node{i}_{j+1}").
std::size_t name_end(const std::string& text, std::size_t i, const std::string& label) {
  std::size_t j = i;
  while (j < text.size()) {
    if (is_name_char(text[j])) {
      ++j;
    } else if (text[j] == '{') {
      const std::size_t close = text.find_first_of("{}", j + 1);
      if (close == std::string::npos || text[close] == '{') throw labelled(label, "unbalanced '{'");
      j = close + 1;
    } else {
      break;
    }
  }
  return j;
}

// End of the number that starts at text[i] (digits, '.', an exponent), as the expression parser reads numbers.
std::size_t number_end(const std::string& text, std::size_t i) {
  while (i < text.size() && (is_digit(text[i]) || text[i] == '.')) ++i;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    std::size_t j = i + 1;
    if (j < text.size() && (text[j] == '+' || text[j] == '-')) ++j;
    if (j < text.size() && is_digit(text[j])) {
      i = j;
      while (i < text.size() && is_digit(text[i])) ++i;
    }
  }
  return i;
}

}  // namespace

std::string clip(const std::string& text, std::size_t n) { return text.size() > n ? text.substr(0, n) + "..." : text; }
// Labels of family texts in messages, worded as the symbolic front end words its own ("expression "...": ...").
std::string expression_label(const std::string& text) {
  std::string s = "expression \"";
  s += clip(text);
  s += "\"";
  return s;
}
std::string template_label(const std::string& text) {
  std::string s = "template '";
  s += clip(text);
  s += "'";
  return s;
}
Error labelled(const std::string& label, const std::string& what) {
  std::string s = label;
  s += ": ";
  s += what;
  return Error(s);
}

std::vector<NameToken> name_tokens(const std::string& text, const std::string& label) {
  std::vector<NameToken> v;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (is_digit(c) || (c == '.' && i + 1 < text.size() && is_digit(text[i + 1]))) {
      i = number_end(text, i);
    } else if (is_name_start(c)) {
      const std::size_t j = name_end(text, i, label);
      std::size_t k = j;
      while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
      const bool templated = text.find('{', i) < j;
      v.push_back({i, j, k < text.size() && text[k] == '(', templated});
      i = j;
    } else {
      ++i;
    }
  }
  return v;
}

NameTemplate::NameTemplate(const std::string& text, const Meanings& meaning) : text_(text) {
  const std::string label = template_label(text);
  std::string literal;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '}') throw labelled(label, "unbalanced '}'");
    if (c != '{') {
      literal += c;
      ++i;
      continue;
    }
    const std::size_t close = text.find_first_of("{}", i + 1);
    if (close == std::string::npos || text[close] == '{') throw labelled(label, "unbalanced '{'");
    const std::string inner = text.substr(i + 1, close - i - 1);
    if (inner.find_first_not_of(" \t") == std::string::npos) throw labelled(label, "empty '{}'");
    if (!literal.empty()) parts_.push_back({std::move(literal), nullptr, {}}), literal.clear();
    parts_.push_back({{}, std::make_shared<IndexExpr>(inner, label, meaning, false), "{" + inner + "}"});
    i = close + 1;
  }
  if (!literal.empty()) parts_.push_back({std::move(literal), nullptr, {}});
}

void NameTemplate::render(const Env& env, std::string& out) const {
  out.clear();
  for (const Part& p : parts_) {
    if (!p.expr) {
      out += p.literal;
      continue;
    }
    const double v = p.expr->eval(env);
    if (!(std::floor(v) == v && std::fabs(v) <= 9007199254740992.0))
      throw labelled(template_label(text_), p.expr_text + " is " + shortest(v) + ", not a whole number");
    char buf[24];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, static_cast<std::int64_t>(v));
    out.append(buf, end);
  }
}

// Recursive descent over one text, emitting IndexExpr's stack program.
class IndexParser {
 public:
  IndexParser(IndexExpr& out, const std::string& text, const Meanings& meaning, bool allow_templates)
      : out_(out), text_(text), meaning_(meaning), allow_templates_(allow_templates) {}

  void parse() {
    if (text_.find_first_not_of(" \t\r\n") == std::string::npos) fail("expression is empty");
    if (text_.size() > CompiledExpression::kMaxTextLength)
      fail("of " + std::to_string(text_.size()) + " characters; the limit is " +
           std::to_string(CompiledExpression::kMaxTextLength));
    sum();
    skip();
    if (pos_ < text_.size()) fail("unexpected '" + std::string(1, text_[pos_]) + "'");
  }

 private:
  using Op = IndexExpr::Op;
  using Fn = IndexExpr::Fn;

  [[noreturn]] void fail(const std::string& what) const { throw labelled(out_.label_, what); }
  void skip() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool take(char c) {
    skip();
    if (pos_ < text_.size() && text_[pos_] == c) return ++pos_, true;
    return false;
  }
  void emit(IndexExpr::Instr in, int stack_change) {
    out_.code_.push_back(in);
    depth_ += stack_change;
    out_.max_stack_ = std::max(out_.max_stack_, static_cast<std::size_t>(depth_));
  }

  void sum() {
    product();
    for (;;) {
      if (take('+'))
        product(), emit({Op::kAdd}, -1);
      else if (take('-'))
        product(), emit({Op::kSub}, -1);
      else
        return;
    }
  }
  void product() {
    unary();
    for (;;) {
      if (take('*'))
        unary(), emit({Op::kMul}, -1);
      else if (take('/'))
        unary(), emit({Op::kDiv}, -1);
      else
        return;
    }
  }
  // Signs, then a power: -x^2 is -(x^2), 2^-1 is 2^(-1), a^b^c is a^(b^c).
  void unary() {
    if (++nesting_ > kMaxNesting) fail("nested more than " + std::to_string(kMaxNesting) + " levels deep");
    bool negative = false;
    for (;;) {
      if (take('-'))
        negative = !negative;
      else if (!take('+'))
        break;
    }
    primary();
    if (take('^')) unary(), emit({Op::kPow}, -1);
    if (negative) emit({Op::kNeg}, 0);
    --nesting_;
  }
  void primary() {
    skip();
    if (pos_ >= text_.size()) fail("unexpected end");
    const char c = text_[pos_];
    if (c == '(') {
      ++pos_;
      sum();
      if (!take(')')) fail("missing ')'");
      return;
    }
    if (is_digit(c) || c == '.') {
      const std::size_t end = number_end(text_, pos_);
      const std::string s = text_.substr(pos_, end - pos_);
      pos_ = end;
      double v = 0.0;
      auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec == std::errc::result_out_of_range && p == s.data() + s.size()) {
        const auto e = s.find_first_of("eE");
        if (!(e != std::string::npos && e + 1 < s.size() && s[e + 1] == '-'))
          fail("number '" + clip(s, 40) + "' is out of the range of a double");
        v = 0.0;  // underflow, as a double would have it
      } else if (ec != std::errc() || p != s.data() + s.size()) {
        fail("malformed number '" + clip(s, 40) + "'");
      }
      emit({Op::kConst, Fn::kSin, 0, v}, 1);
      return;
    }
    if (!is_name_start(c)) fail("unexpected '" + std::string(1, c) + "'");
    const std::size_t end = name_end(text_, pos_, out_.label_);
    const std::string name = text_.substr(pos_, end - pos_);
    pos_ = end;
    if (take('(')) return call(name);
    if (name.find('{') != std::string::npos) {
      if (!allow_templates_) fail("a templated name is not allowed here ('" + name + "')");
      out_.templates_.push_back(std::make_shared<NameTemplate>(name, meaning_));
      emit({Op::kName, Fn::kSin, static_cast<std::uint32_t>(out_.templates_.size() - 1)}, 1);
      out_.uses_index_ = true;  // depends on the member
      return;
    }
    if (name == "pi") return emit({Op::kConst, Fn::kSin, 0, M_PI}, 1);
    const Meaning m = meaning_(name);
    if (m.kind == Meaning::Kind::kIndex) {
      out_.uses_index_ = true;
      return emit({Op::kIndex, Fn::kSin, static_cast<std::uint32_t>(m.depth)}, 1);
    }
    if (m.kind == Meaning::Kind::kConstant) return emit({Op::kConst, Fn::kSin, 0, m.value}, 1);
    fail(m.message);
  }
  void call(const std::string& name) {
    static const std::map<std::string, Fn> functions = {
        {"sin", Fn::kSin},   {"cos", Fn::kCos},   {"tan", Fn::kTan}, {"asin", Fn::kAsin}, {"acos", Fn::kAcos},
        {"atan", Fn::kAtan}, {"exp", Fn::kExp},   {"log", Fn::kLog}, {"sqrt", Fn::kSqrt}, {"sinh", Fn::kSinh},
        {"cosh", Fn::kCosh}, {"tanh", Fn::kTanh}, {"abs", Fn::kAbs}};
    if (name == "atan2") {
      sum();
      if (!take(',')) fail("atan2 takes two arguments");
      sum();
      if (!take(')')) fail("missing ')'");
      return emit({Op::kAtan2}, -1);
    }
    auto it = functions.find(name);
    if (it == functions.end())
      fail("function '" + name +
           "' is not supported (supported: sin cos tan asin acos atan atan2 exp log sqrt "
           "sinh cosh tanh abs)");
    sum();
    if (!take(')')) fail("missing ')' (" + name + " takes one argument)");
    emit({Op::kFn, it->second}, 0);
  }

  static constexpr int kMaxNesting = 3 * CompiledExpression::kMaxNesting;
  IndexExpr& out_;
  const std::string& text_;
  const Meanings& meaning_;
  bool allow_templates_;
  std::size_t pos_ = 0;
  int depth_ = 0, nesting_ = 0;
};

IndexExpr::IndexExpr(const std::string& text, const std::string& label, const Meanings& meaning, bool allow_templates)
    : label_(label) {
  IndexParser(*this, text, meaning, allow_templates).parse();
}

// Reentrant (a templated name evaluates its own templates): the stack is local.
double IndexExpr::run(const Env& env) const {
  double small[32];
  std::vector<double> large;
  double* s = small;
  if (max_stack_ > 32) large.resize(max_stack_), s = large.data();
  std::size_t n = 0;
  std::string name;
  for (const Instr& in : code_) {
    switch (in.op) {
      case Op::kConst:
        s[n++] = in.imm;
        break;
      case Op::kIndex:
        s[n++] = env.index[in.a];
        break;
      case Op::kName: {
        const NameTemplate& t = *templates_[in.a];
        t.render(env, name);
        auto it = env.parameters->find(name);
        if (it == env.parameters->end()) throw labelled(label_, "unknown name '" + name + "'");
        s[n++] = it->second;
        break;
      }
      case Op::kAdd:
        --n, s[n - 1] = s[n - 1] + s[n];
        break;
      case Op::kSub:
        --n, s[n - 1] = s[n - 1] - s[n];
        break;
      case Op::kMul:
        --n, s[n - 1] = s[n - 1] * s[n];
        break;
      case Op::kDiv:
        --n, s[n - 1] = s[n - 1] / s[n];
        break;
      case Op::kPow:
        --n, s[n - 1] = std::pow(s[n - 1], s[n]);
        break;
      case Op::kAtan2:
        --n, s[n - 1] = std::atan2(s[n - 1], s[n]);
        break;
      case Op::kNeg:
        s[n - 1] = -s[n - 1];
        break;
      case Op::kFn: {
        double& x = s[n - 1];
        switch (in.fn) {
          case Fn::kSin:
            x = std::sin(x);
            break;
          case Fn::kCos:
            x = std::cos(x);
            break;
          case Fn::kTan:
            x = std::tan(x);
            break;
          case Fn::kAsin:
            x = std::asin(x);
            break;
          case Fn::kAcos:
            x = std::acos(x);
            break;
          case Fn::kAtan:
            x = std::atan(x);
            break;
          case Fn::kExp:
            x = std::exp(x);
            break;
          case Fn::kLog:
            x = std::log(x);
            break;
          case Fn::kSqrt:
            x = std::sqrt(x);
            break;
          case Fn::kSinh:
            x = std::sinh(x);
            break;
          case Fn::kCosh:
            x = std::cosh(x);
            break;
          case Fn::kTanh:
            x = std::tanh(x);
            break;
          case Fn::kAbs:
            x = std::fabs(x);
            break;
        }
        break;
      }
    }
  }
  return s[0];
}

}  // namespace phiq::detail::scene
