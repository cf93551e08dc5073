// phiq's recursive-descent parser for equation text (the grammar is below): builds the GiNaC expression operation
// by operation, folding constant parts in double precision with the tape's own arithmetic, and writes the error
// messages for malformed text. Separate from the tape builder: parsing decides what GiNaC sees, the builder what
// the tape computes from GiNaC's derivatives.
#include "expression/parser.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "base/names.hpp"  // identifiers follow the scene's rule for names
#include "expression/messages.hpp"
#include "expression/symbolic.hpp"
#include "expression/tape_ops.hpp"

namespace phiq::detail {

namespace {

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
// `der` is the one function that is no tape instruction: der(u) is u's rate along the motion, Σ ∂u/∂q_j q̇_j + ∂u/∂t,
// built symbolically by the caller (RateOf), where velocities may be read.
class ExpressionParser {
 public:
  struct Node {
    GiNaC::ex e;            // the expression GiNaC sees: 0, a real symbol, or a term in coordinates and t
    bool constant = false;  // true when it depends on neither q nor t
    double value = 0.0;     // its value when constant
  };
  using Name = ParsedName;

  ExpressionParser(const std::string& text, NameLookup name, std::map<std::string, double>& value_of_constant,
                   RateOf rate_of)
      : text_(text), name_(std::move(name)), value_of_constant_(value_of_constant), rate_of_(std::move(rate_of)) {}

  Node parse() {
    Node n = sum();
    skip_space();
    if (pos_ < text_.size()) {
      if (text_[pos_] == ')') fail_at("')' without a matching '('");
      fail_before("expected an operator");
    }
    return n;
  }

  // A constant: 0 stays exact, anything else becomes a real symbol GiNaC cannot do arithmetic with.
  Node constant(double v) {
    if (!std::isfinite(v))
      fail(std::string("a constant part of it is not a finite real number (") +
           (std::isnan(v) ? "NaN"
            : v > 0       ? "+inf"
                          : "-inf") +
           ")");
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
    fail_before(std::string("expected ") + what);
  }
  std::string token_text() const {  // the token at pos_, for messages: a name, or one whole code point
    std::size_t end = pos_ + std::max<std::size_t>(1, utf8_sequence_length(text_, pos_));
    if (is_name_char(text_[pos_]))
      while (end < text_.size() && is_name_char(text_[end])) ++end;
    return single_line(text_.substr(pos_, std::min<std::size_t>(end - pos_, 40)));
  }
  // "expected ... before 'X' (column N)", and for a character that only looks like an operator, what to write.
  [[noreturn]] void fail_before(const std::string& expected) const {
    const std::string token = token_text();
    fail(expected + " before '" + token + "' (column " + std::to_string(pos_ + 1) + ")" + lookalike_hint(token));
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
      case Op::kAdd:
        return settle(a.e + b.e);
      case Op::kSub:
        return settle(a.e - b.e);
      case Op::kMul:
        return settle(a.e * b.e);
      case Op::kDiv:
        return settle(a.e / b.e);
      case Op::kPow:
        if (!b.constant) return settle(GiNaC::pow(a.e, b.e));
        if (b.value == 0.0) return constant(1.0);  // x^0 = 1, also at x = 0 (as the tape's power computes it)
        if (b.value == 1.0) return a;              // x^1 = x, for GiNaC too (x^1 - x cancels)
        return settle(constant_power(a.e, b.e));
      default:
        fail("internal: binary operation " + std::to_string(static_cast<int>(op)));
    }
  }

  Node sum() {
    Node n = product();
    for (;;) {
      if (accept('+'))
        n = binary_op(Op::kAdd, n, product());
      else if (accept('-'))
        n = binary_op(Op::kSub, n, product());
      else
        return n;
    }
  }

  Node product() {
    Node n = unary();
    for (;;) {
      if (accept('*'))
        n = binary_op(Op::kMul, n, unary());
      else if (accept('/'))
        n = binary_op(Op::kDiv, n, unary());
      else
        return n;
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
    if (is_name_start(c)) {
      const std::size_t start = pos_;
      while (pos_ < text_.size() && is_name_char(text_[pos_])) ++pos_;
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
    fail_before("expected a number, a name or '('");
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
    while (pos_ < n && is_name_char(text_[pos_])) ++pos_;  // "2x" is one malformed number, not 2 times x
    const std::string literal = text_.substr(start, pos_ - start);
    char* end = nullptr;
    const double v = std::strtod(literal.c_str(), &end);
    if (end != literal.c_str() + literal.size()) fail("'" + literal.substr(0, 40) + "' is not a number");
    if (!std::isfinite(v)) fail("number '" + literal.substr(0, 40) + "' is out of the range of a double");
    return constant(v);
  }

  Node call(const std::string& name, std::size_t start) {
    if (name == "der") return rate(start);
    auto it = supported_functions().find(name);
    if (it == supported_functions().end())
      fail("unknown function '" + name.substr(0, 40) + "' (supported: " + supported_function_list() +
           (rate_of_ ? " der" : "") + ")");
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
      fail_at("'" + name + "' takes " + std::to_string(f.arity) + " argument" + (f.arity == 1 ? "" : "s") + ", not " +
              std::to_string(args.size()));
    }
    return call_function(f, args);
  }

  // der(u): the rate of u along the motion (0 for a constant u)
  Node rate(std::size_t start) {
    if (!rate_of_)
      fail(
          "der() reads velocities: only the forces and torques of `loads` may (a constraint, driver or law is of q "
          "and t)");
    expect('(', "'('");
    enter_parentheses();
    if (peek() == ')') pos_ = start, fail_at("'der' takes 1 argument, not 0");
    Node u = sum();
    if (peek() == ',') pos_ = start, fail_at("'der' takes 1 argument, not 2 or more");
    expect(')', "')'");
    --depth_;
    return u.constant ? constant(0.0) : settle(rate_of_(u.e));
  }

  const std::string& text_;
  NameLookup name_;
  std::map<std::string, double>& value_of_constant_;
  RateOf rate_of_;
  std::size_t pos_ = 0;
  int depth_ = 0;
};

}  // namespace

GiNaC::ex parse_expression(const std::string& text, NameLookup name, std::map<std::string, double>& value_of_constant,
                           RateOf rate_of) {
  ExpressionParser parser(text, std::move(name), value_of_constant, std::move(rate_of));
  return parser.parse().e;
}

}  // namespace phiq::detail
