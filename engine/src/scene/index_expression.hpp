// The family index language: the small expression language of indexed families (`for i in A..B`,
// models/README.md). Numbers that use the indices ("0.1*i", "L{i}/2"), range bounds and names with {templates}
// ("x{i}", "node{i}_{j+1}") are compiled once per family body into stack programs over doubles and evaluated once
// per member, without the symbolic engine. It is a language of its own, apart from the equation expressions
// (engine/src/expression/), because it must cost nanoseconds per member and evaluate in the order written (a
// generator that writes `i + c` gets exactly the double it would have computed).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "phiq/types.hpp"

namespace phiq::detail::scene {

// The text cut to n characters, with "..." when cut: user text quoted in messages.
std::string clip(const std::string& text, std::size_t n = 60);
// Labels of family texts in messages, worded as the symbolic front end words its own ("expression "...": ...").
std::string expression_label(const std::string& text);
std::string template_label(const std::string& text);
// Error "label: what".
Error labelled(const std::string& label, const std::string& what);

// The names used in a text, as [begin, end) ranges (numbers skipped whole); `call` when followed by '('.
struct NameToken {
  std::size_t begin, end;
  bool call;
  bool templated;
};
std::vector<NameToken> name_tokens(const std::string& text, const std::string& label);

// What a name means in a family text.
struct Meaning {
  enum class Kind { kIndex, kConstant, kUnknown };
  Kind kind = Kind::kUnknown;
  int depth = 0;        // kIndex: the family level of the index (0 = outermost)
  double value = 0.0;   // kConstant: parameters and pi
  std::string message;  // kUnknown: what to say
};
using Meanings = std::function<Meaning(const std::string&)>;

// The values a family text is evaluated with: the current index of each family level, and the parameters
// (templated names such as L{i} are looked up among them per member).
struct Env {
  const double* index;
  const std::unordered_map<std::string, double>* parameters;
};

class NameTemplate;
class IndexParser;

// A number in a family: a small stack program over doubles, compiled once from the text and evaluated per member.
// The language is that of constant expressions (numbers, + - * / ^, parentheses, pi, parameters, the functions of
// equation expressions) plus the indices in scope and templated parameter names (L{i}).
class IndexExpr {
 public:
  IndexExpr(const std::string& text, const std::string& label, const Meanings& meaning, bool allow_templates);
  double eval(const Env& env) const {
    if (code_.size() == 1 && code_[0].op == Op::kIndex) return env.index[code_[0].a];  // the common "i"
    return run(env);
  }
  bool uses_index() const { return uses_index_; }

 private:
  friend class IndexParser;
  enum class Op : std::uint8_t { kConst, kIndex, kName, kAdd, kSub, kMul, kDiv, kPow, kNeg, kFn, kAtan2 };
  enum class Fn : std::uint8_t { kSin, kCos, kTan, kAsin, kAcos, kAtan, kExp, kLog, kSqrt, kSinh, kCosh, kTanh, kAbs };
  struct Instr {
    Op op;
    Fn fn = Fn::kSin;
    std::uint32_t a = 0;  // index level (kIndex), template (kName)
    double imm = 0.0;     // kConst
  };
  double run(const Env& env) const;

  std::string label_;
  std::vector<Instr> code_;
  std::vector<std::shared_ptr<const NameTemplate>> templates_;
  std::size_t max_stack_ = 0;
  bool uses_index_ = false;
};

// A name with {templates} ("x{i}", "P{i+1}", "node{i}_{j}"): literal text and integer expressions, rendered per
// member. A template must give a whole number.
class NameTemplate {
 public:
  NameTemplate(const std::string& text, const Meanings& meaning);
  const std::string& text() const { return text_; }
  // The name for the member of `env`, into `out` (reused: no allocation once it has grown). Throws Error.
  void render(const Env& env, std::string& out) const;

 private:
  struct Part {
    std::string literal;
    std::shared_ptr<const IndexExpr> expr;  // null for a literal
    std::string expr_text;                  // "{i+1}", for messages
  };
  std::string text_;
  std::vector<Part> parts_;
};

}  // namespace phiq::detail::scene
