// Scene loader: YAML (yaml-cpp) → ModelBuilder + SweepOptions, with every error located in the file.
#include "phiq/scene.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>
#include <type_traits>
#include <unordered_map>

#include "sweep/time_grid.hpp"

namespace phiq {

namespace {

const char* const kGround = "ground";

// In a field path, this character stands for the member of the enclosing family: messages render it "[i=17]".
constexpr char kMemberMark = '\x01';

[[noreturn]] void fail_at(const std::string& file, YAML::Mark m, const std::string& path, const std::string& what) {
  std::ostringstream s;
  s << file;
  if (m.line >= 0) s << ":" << m.line + 1 << ":" << m.column + 1;
  s << ": " << (path.empty() ? "(top level)" : path) << ": " << what;
  throw SceneError(s.str());
}

// Letters, digits and '_', not starting with a digit (ASCII: the "C" locale's isalpha/isalnum, without a call per
// character — families check millions of names).
bool valid_name(const std::string& s) {
  auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
  if (s.empty() || !letter(s[0])) return false;
  for (char c : s)
    if (!(letter(c) || (c >= '0' && c <= '9'))) return false;
  return true;
}

std::string allowed_list(std::initializer_list<const char*> allowed) {
  std::string list;
  for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
  return list;
}

// A key that opens an indexed family: "for NAME in A..B".
bool is_family_key(const std::string& k) {
  return k.size() > 3 && k.compare(0, 3, "for") == 0 && std::isspace(static_cast<unsigned char>(k[3]));
}

// A YAML node with the dotted path that led to it, for messages.
// Typed reads of a scalar, shared by the cursor over the YAML tree (Cursor) and over a family's copied body
// (TCursor): `c` supplies text() and fail().
template <class C>
std::string scalar_name(const C& c) {
  std::string s = c.text();
  if (!valid_name(s)) c.fail("'" + s + "' is not a valid name (letters, digits and '_', not starting with a digit)");
  return s;
}
template <class C>
bool scalar_boolean(const C& c) {
  std::string s = c.text();
  if (s == "true" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "no" || s == "off") return false;
  c.fail("expected true or false, got '" + s + "'");
}
template <class C>
std::int64_t scalar_integer(const C& c, std::int64_t lo, std::int64_t hi) {
  std::string s = c.text();
  std::int64_t v = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || p != s.data() + s.size()) c.fail("expected a whole number, got '" + s + "'");
  if (v < lo || v > hi) c.fail("must be between " + std::to_string(lo) + " and " + std::to_string(hi));
  return v;
}

class Cursor {
 public:
  Cursor(YAML::Node node, std::string path, const std::string* file, YAML::Mark parent_mark)
      : node_(std::move(node)), path_(std::move(path)), file_(file), parent_mark_(parent_mark) {}

  const YAML::Node& node() const { return node_; }
  const std::string& path() const { return path_; }
  bool present() const { return node_.IsDefined() && !node_.IsNull(); }
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }
  // Where a message about this node points: the node, else (missing or unmarked) the map or key above it.
  YAML::Mark mark() const {
    YAML::Mark m = node_.IsDefined() ? node_.Mark() : parent_mark_;
    if (m.line < 0) m = parent_mark_;
    return m;
  }

  [[noreturn]] void fail(const std::string& what) const { fail_at(*file_, mark(), path_, what); }

  // Map access: only the listed keys are allowed; duplicates are rejected.
  void expect_map(std::initializer_list<const char*> allowed) const {
    if (!node_.IsMap()) fail("expected a mapping (key: value)");
    std::set<std::string> seen;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      Cursor key(it->first, path_, file_, node_.Mark());
      if (!it->first.IsScalar()) key.fail("keys must be plain names");
      const std::string k = it->first.Scalar();
      if (!seen.insert(k).second) Cursor(it->first, join(k), file_, node_.Mark()).fail("duplicate field '" + k + "'");
      bool ok = false;
      for (const char* a : allowed) ok = ok || k == a;
      if (!ok)
        Cursor(it->first, join(k), file_, node_.Mark())
            .fail("unknown field '" + k + "' (allowed: " + allowed_list(allowed) + ")");
    }
  }
  Cursor field(const char* key) const {
    // yaml-cpp's operator[] on a const node does not insert
    const YAML::Node& n = node_;
    return Cursor(n[key], join(key), file_, node_.Mark());
  }
  Cursor require(const char* key) const {
    Cursor c = field(key);
    if (!c.node_.IsDefined()) fail(std::string("missing field '") + key + "'");
    if (c.node_.IsNull()) c.fail("has no value");
    return c;
  }
  std::size_t size() const { return node_.size(); }
  Cursor at(std::size_t i) const {
    return Cursor(node_[i], path_ + "[" + std::to_string(i) + "]", file_, node_.Mark());
  }
  std::vector<Cursor> items() const {
    if (!node_.IsSequence()) fail("expected a list");
    std::vector<Cursor> v;
    for (std::size_t i = 0; i < node_.size(); ++i) v.push_back(at(i));
    return v;
  }
  // One (key, value) pair of a map whose keys are user names.
  struct Entry;
  // Ordered (key, value) pairs of a map whose keys are user names.
  std::vector<Entry> entries() const;
  std::string text() const {
    if (!node_.IsScalar()) fail("expected a single value");
    return node_.Scalar();
  }
  std::string name() const { return scalar_name(*this); }
  bool boolean() const { return scalar_boolean(*this); }
  std::int64_t integer(std::int64_t lo, std::int64_t hi) const { return scalar_integer(*this, lo, hi); }

  static bool valid_name(const std::string& s) { return phiq::valid_name(s); }

  const std::string* file() const { return file_; }
  std::string join(const std::string& k) const { return path_.empty() ? k : path_ + "." + k; }

 private:
  YAML::Node node_;
  std::string path_;
  const std::string* file_;
  YAML::Mark parent_mark_;
};

struct Cursor::Entry {
  std::string name;
  YAML::Mark key_mark;
  Cursor value;
};

std::vector<Cursor::Entry> Cursor::entries() const {
  if (!node_.IsMap()) fail("expected a mapping (name: value)");
  std::vector<Entry> v;
  std::set<std::string> seen;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    if (!it->first.IsScalar()) Cursor(it->first, path_, file_, node_.Mark()).fail("names must be plain scalars");
    const std::string k = it->first.Scalar();
    Cursor value(it->second, join(k), file_, it->first.Mark());
    if (!seen.insert(k).second) Cursor(it->first, join(k), file_, node_.Mark()).fail("duplicate name '" + k + "'");
    v.push_back(Entry{k, it->first.Mark(), value});
  }
  return v;
}

// A YAML number as a double; nullopt when `s` is not a plain number (then it may be a constant expression).
// Throws SceneError-free Error for a number out of the range of a double: never hand those to the symbolic engine,
// which would try to represent 1e3082222222 exactly (found by the fuzzer: a hang in GMP).
std::optional<double> plain_number(const std::string& s) {
  if (s == ".nan" || s == ".NaN" || s == ".NAN") return std::numeric_limits<double>::quiet_NaN();
  if (s == ".inf" || s == ".Inf" || s == ".INF" || s == "+.inf") return std::numeric_limits<double>::infinity();
  if (s == "-.inf" || s == "-.Inf" || s == "-.INF") return -std::numeric_limits<double>::infinity();
  const char* b = s.data();
  const char* e = b + s.size();
  if (b != e && *b == '+') ++b;
  double v = 0.0;
  auto [p, ec] = std::from_chars(b, e, v);
  if (ec == std::errc() && p == e) return v;
  if (ec == std::errc::result_out_of_range && p == e) {
    // from_chars reports underflow and overflow alike: underflow is 0, overflow is not a finite number
    const auto epos = s.find_first_of("eE");
    const bool negative_exponent = epos != std::string::npos && epos + 1 < s.size() && s[epos + 1] == '-';
    if (negative_exponent) return 0.0;
    throw Error("'" + s.substr(0, 40) + (s.size() > 40 ? "..." : "") + "' is out of the range of a double");
  }
  return std::nullopt;
}

// ==============================================================================================================
// Indexed families (`for i in A..B`, models/README.md). A family's body is copied once out of the YAML tree into
// compact nodes (TNode) that know their field path; the texts in it — names with {templates}, numbers that use
// the indices, equations — are compiled on first use and afterwards only evaluated, once per member: no YAML walk,
// no parsing and no symbolic work per member. Numbers that use an index are evaluated in double precision in the
// order written (so that a generator that writes `i + c` gets exactly the double it would have computed).

bool is_ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)); }

std::string clip(const std::string& text, std::size_t n = 60) {
  return text.size() > n ? text.substr(0, n) + "..." : text;
}
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

// Shortest decimal that reads back as v.
std::string shortest(double v) {
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, p) : std::string("?");
}

// End of the name that starts at text[i]: letters, digits, '_' and {template} groups ("node{i}_{j+1}").
std::size_t name_end(const std::string& text, std::size_t i, const std::string& label) {
  std::size_t j = i;
  while (j < text.size()) {
    if (is_ident_char(text[j])) {
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

// The names used in a text, as [begin, end) ranges (numbers skipped whole); `call` when followed by '('.
struct NameToken {
  std::size_t begin, end;
  bool call;
  bool templated;
};
std::vector<NameToken> name_tokens(const std::string& text, const std::string& label) {
  std::vector<NameToken> v;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (is_digit(c) || (c == '.' && i + 1 < text.size() && is_digit(text[i + 1]))) {
      i = number_end(text, i);
    } else if (is_ident_start(c)) {
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

// A number in a family: a small stack program over doubles, compiled once from the text and evaluated per member.
// The language is that of constant expressions (numbers, + - * / ^, parentheses, pi, parameters, the functions of
// equation expressions) plus the indices in scope and templated parameter names (L{i}).
class IndexExpr {
 public:
  IndexExpr(const std::string& text, const std::string& label, const Meanings& meaning, bool allow_templates);
  double eval(const Env& env) const;
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
  NameTemplate(const std::string& text, const Meanings& meaning) : text_(text) {
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
  const std::string& text() const { return text_; }
  void render(const Env& env, std::string& out) const {
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

 private:
  struct Part {
    std::string literal;
    std::shared_ptr<const IndexExpr> expr;  // null for a literal
    std::string expr_text;                  // "{i+1}", for messages
  };
  std::string text_;
  std::vector<Part> parts_;
};

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
      if (take('+')) product(), emit({Op::kAdd}, -1);
      else if (take('-')) product(), emit({Op::kSub}, -1);
      else return;
    }
  }
  void product() {
    unary();
    for (;;) {
      if (take('*')) unary(), emit({Op::kMul}, -1);
      else if (take('/')) unary(), emit({Op::kDiv}, -1);
      else return;
    }
  }
  // Signs, then a power: -x^2 is -(x^2), 2^-1 is 2^(-1), a^b^c is a^(b^c).
  void unary() {
    if (++nesting_ > kMaxNesting) fail("nested more than " + std::to_string(kMaxNesting) + " levels deep");
    bool negative = false;
    for (;;) {
      if (take('-')) negative = !negative;
      else if (!take('+')) break;
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
    if (!is_ident_start(c)) fail("unexpected '" + std::string(1, c) + "'");
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
        {"sin", Fn::kSin},   {"cos", Fn::kCos},   {"tan", Fn::kTan},   {"asin", Fn::kAsin}, {"acos", Fn::kAcos},
        {"atan", Fn::kAtan}, {"exp", Fn::kExp},   {"log", Fn::kLog},   {"sqrt", Fn::kSqrt}, {"sinh", Fn::kSinh},
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
      fail("function '" + name + "' is not supported (supported: sin cos tan asin acos atan atan2 exp log sqrt "
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

IndexExpr::IndexExpr(const std::string& text, const std::string& label, const Meanings& meaning,
                     bool allow_templates)
    : label_(label) {
  IndexParser(*this, text, meaning, allow_templates).parse();
}

double IndexExpr::eval(const Env& env) const {
  if (code_.size() == 1 && code_[0].op == Op::kIndex) return env.index[code_[0].a];  // the common "i"
  // Reentrant (a templated name evaluates its own templates): the stack is local.
  double small[32];
  std::vector<double> large;
  double* s = small;
  if (max_stack_ > 32) large.resize(max_stack_), s = large.data();
  std::size_t n = 0;
  std::string name;
  for (const Instr& in : code_) {
    switch (in.op) {
      case Op::kConst: s[n++] = in.imm; break;
      case Op::kIndex: s[n++] = env.index[in.a]; break;
      case Op::kName: {
        const NameTemplate& t = *templates_[in.a];
        t.render(env, name);
        auto it = env.parameters->find(name);
        if (it == env.parameters->end()) throw labelled(label_, "unknown name '" + name + "'");
        s[n++] = it->second;
        break;
      }
      case Op::kAdd: --n, s[n - 1] = s[n - 1] + s[n]; break;
      case Op::kSub: --n, s[n - 1] = s[n - 1] - s[n]; break;
      case Op::kMul: --n, s[n - 1] = s[n - 1] * s[n]; break;
      case Op::kDiv: --n, s[n - 1] = s[n - 1] / s[n]; break;
      case Op::kPow: --n, s[n - 1] = std::pow(s[n - 1], s[n]); break;
      case Op::kAtan2: --n, s[n - 1] = std::atan2(s[n - 1], s[n]); break;
      case Op::kNeg: s[n - 1] = -s[n - 1]; break;
      case Op::kFn: {
        double& x = s[n - 1];
        switch (in.fn) {
          case Fn::kSin: x = std::sin(x); break;
          case Fn::kCos: x = std::cos(x); break;
          case Fn::kTan: x = std::tan(x); break;
          case Fn::kAsin: x = std::asin(x); break;
          case Fn::kAcos: x = std::acos(x); break;
          case Fn::kAtan: x = std::atan(x); break;
          case Fn::kExp: x = std::exp(x); break;
          case Fn::kLog: x = std::log(x); break;
          case Fn::kSqrt: x = std::sqrt(x); break;
          case Fn::kSinh: x = std::sinh(x); break;
          case Fn::kCosh: x = std::cosh(x); break;
          case Fn::kTanh: x = std::tanh(x); break;
          case Fn::kAbs: x = std::fabs(x); break;
        }
        break;
      }
    }
  }
  return s[0];
}

struct Family;

// The compiled forms of one scalar of a family body, made on first use (a node is used in one role only).
struct ScalarPlan {
  std::shared_ptr<const NameTemplate> name;  // text(): the scalar as a name with templates
  bool number_ready = false;                 // number():
  bool number_constant = false;              //   the same for every member: number_value
  double number_value = 0.0;
  std::shared_ptr<const IndexExpr> number;   //   else evaluated per member
  static constexpr Index kNotLooked = -2;
  Index entity = kNotLooked;                 // a coordinate, point or body named without template: its index
  Index last = -1, stride = 1;               // a templated reference: the last index found, the step before it
  struct Equation;
  std::shared_ptr<Equation> equation;        // equation and law expressions
};

// An equation or law expression in a family. Either the same for every member (`shared`), or compiled once with
// placeholder coordinate indices — one per templated name, per coordinate and per index it uses — and rebound per
// member (CompiledExpression::rebind) to the member's coordinates and index values.
struct ScalarPlan::Equation {
  std::shared_ptr<const CompiledExpression> shared;
  std::shared_ptr<const CompiledExpression> compiled;
  struct Placeholder {
    enum class Kind { kCoordinate, kIndex, kTemplate } kind;
    Index coordinate = -1;  // kCoordinate
    int depth = 0;          // kIndex
    std::size_t name = 0;   // kTemplate: index into names
  };
  std::vector<Placeholder> placeholders;
  std::vector<std::shared_ptr<const NameTemplate>> names;
  bool allow_coordinates = true;
};

// A family body, copied out of the YAML tree.
struct TNode {
  enum class Kind : std::uint8_t { kNull, kScalar, kMap, kSeq };
  struct Entry {
    std::string key;
    YAML::Mark key_mark;
    bool key_scalar = true;
    std::shared_ptr<TNode> value;
    std::shared_ptr<Family> family;                        // a nested `for` entry (map sections)
    mutable std::shared_ptr<const NameTemplate> name;      // the key as a name, compiled on first use
  };
  Kind kind = Kind::kNull;
  bool templated = false;  // a scalar with braces
  YAML::Mark mark;         // where messages about it point
  std::string path;        // field path as written, with kMemberMark after each enclosing family's key
  std::string text;        // scalar
  std::vector<Entry> map;
  std::vector<TNode> seq;
  std::shared_ptr<Family> family;  // a list item that is a nested family {for ...: [...]}
  mutable std::uintptr_t checked_fields = 0;  // expect_map() passed for this list of fields
  mutable std::shared_ptr<ScalarPlan> plan;
};

// The key `for NAME in A..B` of a family: its index and its range, whose bounds are whole-number expressions of
// the parameters and the indices of the enclosing families.
struct FamilyRange {
  std::string index;  // NAME
  std::string lo_text, hi_text;
  std::shared_ptr<const IndexExpr> lo, hi;
};

// One `for NAME in A..B` with its body (a map in map sections, a list in list sections).
struct Family : FamilyRange {
  std::string key;    // as written
  std::string path;   // of the key, with the marks of the enclosing families
  YAML::Mark mark;    // of the key
  int depth = 0;      // 0 for a family in a section, 1 inside it, ...
  TNode body;
};

// The state of the expansion: the member of each family level being read, and what family texts see.
struct Families {
  const std::string* file = nullptr;
  const std::unordered_map<std::string, double>* parameters = nullptr;
  struct Frame {
    const Family* family;
    std::int64_t value;
  };
  std::vector<Frame> frames;  // outermost first; frames[k].family->depth == k
  std::vector<double> index;  // frames[k].value as a double, for evaluation
  std::size_t budget = 0;     // entries families may still make (SceneLimits::max_family_instances)

  Env env() const { return Env{index.data(), parameters}; }
  // The path with each member mark replaced by "[i=17]" for the member being read.
  std::string render(const std::string& path) const {
    std::string out;
    std::size_t level = 0;
    for (char c : path) {
      if (c != kMemberMark) {
        out += c;
        continue;
      }
      if (level < frames.size())
        out += "[" + frames[level].family->index + "=" + std::to_string(frames[level].value) + "]";
      ++level;
    }
    return out;
  }
};

// A Cursor over a family body, for the member being read: the same interface, so that the scene reader reads a
// member exactly as it reads a plain entry; text() renders templates; paths name the member.
class TCursor {
 public:
  TCursor(const TNode* node, Families* fx, const TNode* parent = nullptr, const char* key = nullptr)
      : node_(node), parent_(parent), key_(key), fx_(fx) {}

  const TNode* node() const { return node_; }
  Families& families() const { return *fx_; }
  bool present() const { return node_ && node_->kind != TNode::Kind::kNull; }
  bool is_map() const { return node_ && node_->kind == TNode::Kind::kMap; }
  bool is_sequence() const { return node_ && node_->kind == TNode::Kind::kSeq; }
  bool is_scalar() const { return node_ && node_->kind == TNode::Kind::kScalar; }

  [[noreturn]] void fail(const std::string& what) const {
    if (node_) fail_at(*fx_->file, node_->mark, fx_->render(node_->path), what);
    fail_at(*fx_->file, parent_->mark, fx_->render(parent_->path + "." + key_), what);
  }

  void expect_map(std::initializer_list<const char*> allowed) const {
    if (!is_map()) fail("expected a mapping (key: value)");
    // the fields of a body are the same for every member: checked once per list of allowed fields
    std::uintptr_t sig = allowed.size();
    for (const char* a : allowed) sig = sig * 1000003u + reinterpret_cast<std::uintptr_t>(a);
    if (node_->checked_fields == sig) return;
    std::set<std::string> seen;
    for (const TNode::Entry& e : node_->map) {
      if (!e.key_scalar) fail_at(*fx_->file, e.key_mark, fx_->render(node_->path), "keys must be plain names");
      const std::string where = fx_->render(node_->path + "." + e.key);
      if (!seen.insert(e.key).second) fail_at(*fx_->file, e.key_mark, where, "duplicate field '" + e.key + "'");
      bool ok = false;
      for (const char* a : allowed) ok = ok || e.key == a;
      if (!ok)
        fail_at(*fx_->file, e.key_mark, where,
                "unknown field '" + e.key + "' (allowed: " + allowed_list(allowed) + ")");
    }
    node_->checked_fields = sig;
  }
  TCursor field(const char* key) const {
    if (is_map())
      for (const TNode::Entry& e : node_->map)
        if (e.value && e.key == key) return TCursor(e.value.get(), fx_);
    return TCursor(nullptr, fx_, node_ ? node_ : parent_, key);
  }
  TCursor require(const char* key) const {
    TCursor c = field(key);
    if (!c.node_) fail(std::string("missing field '") + key + "'");
    if (c.node_->kind == TNode::Kind::kNull) c.fail("has no value");
    return c;
  }
  std::size_t size() const {
    if (!node_) return 0;
    return node_->kind == TNode::Kind::kSeq ? node_->seq.size() : node_->map.size();
  }
  TCursor at(std::size_t i) const {
    if (is_sequence() && i < node_->seq.size()) return TCursor(&node_->seq[i], fx_);
    return TCursor(nullptr, fx_, node_, "?");
  }
  std::vector<TCursor> items() const {
    if (!is_sequence()) fail("expected a list");
    std::vector<TCursor> v;
    v.reserve(node_->seq.size());
    for (const TNode& n : node_->seq) v.emplace_back(&n, fx_);
    return v;
  }
  // The scalar as written (templates unrendered).
  const std::string& raw() const {
    if (!is_scalar()) fail("expected a single value");
    return node_->text;
  }
  // The scalar with its templates rendered for the member.
  std::string text() const {
    const std::string& s = raw();
    if (!node_->templated) return s;
    ScalarPlan& p = plan();
    std::string out;
    try {
      if (!p.name) p.name = std::make_shared<NameTemplate>(s, meanings());
      p.name->render(fx_->env(), out);
    } catch (const Error& e) {
      fail(e.what());
    }
    return out;
  }
  std::string name() const { return scalar_name(*this); }
  bool boolean() const { return scalar_boolean(*this); }
  std::int64_t integer(std::int64_t lo, std::int64_t hi) const { return scalar_integer(*this, lo, hi); }

  ScalarPlan& plan() const {
    if (!node_->plan) node_->plan = std::make_shared<ScalarPlan>();
    return *node_->plan;
  }
  // Names in templates and numbers: the indices in scope (innermost first), parameters, else unknown.
  Meanings meanings() const {
    const Families* fx = fx_;
    return [fx](const std::string& n) {
      Meaning m;
      for (std::size_t k = fx->frames.size(); k-- > 0;)
        if (fx->frames[k].family->index == n) {
          m.kind = Meaning::Kind::kIndex;
          m.depth = static_cast<int>(k);
          return m;
        }
      if (auto it = fx->parameters->find(n); it != fx->parameters->end()) {
        m.kind = Meaning::Kind::kConstant;
        m.value = it->second;
        return m;
      }
      m.message = n == "t" ? "time 't' is not allowed here" : "unknown name '" + n + "'";
      return m;
    };
  }

 private:
  const TNode* node_;
  const TNode* parent_;  // for a missing field: the map it is missing from
  const char* key_;
  Families* fx_;
};

template <class C>
inline constexpr bool kInFamily = std::is_same_v<C, TCursor>;

// Points and bodies by name, in order of definition (families look references up by guessing the next index).
template <class T>
class NameTable {
 public:
  // Adds a name with a default value; returns its index, or -1 when the name exists.
  Index add(const std::string& name) {
    auto [it, fresh] = index_.try_emplace(name, static_cast<Index>(values_.size()));
    if (!fresh) return -1;
    values_.emplace_back();
    names_.push_back(&it->first);
    return it->second;
  }
  bool contains(const std::string& name) const { return index_.count(name) != 0; }
  Index find(const std::string& name) const {
    auto it = index_.find(name);
    return it == index_.end() ? -1 : it->second;
  }
  Index size() const { return static_cast<Index>(values_.size()); }
  // Room for `more` entries (grow only: a smaller reserve would shrink the hash table's buckets).
  void reserve(std::size_t more) {
    const std::size_t n = values_.size() + more;
    if (static_cast<double>(n) > static_cast<double>(index_.bucket_count()) * index_.max_load_factor())
      index_.reserve(n);
    if (n > values_.capacity()) values_.reserve(std::max(n, 2 * values_.capacity())), names_.reserve(values_.capacity());
  }
  const std::string& name(Index k) const { return *names_[static_cast<std::size_t>(k)]; }
  T& operator[](Index k) { return values_[static_cast<std::size_t>(k)]; }
  const T& operator[](Index k) const { return values_[static_cast<std::size_t>(k)]; }

 private:
  std::unordered_map<std::string, Index> index_;
  std::vector<T> values_;
  std::vector<const std::string*> names_;  // keys of index_ (node-based: stable)
};

class SceneReader {
 public:
  SceneReader(const std::string& file, const SceneLimits& limits) : file_(file), limits_(limits) {
    families_.file = &file_;
    families_.parameters = &parameters_;
    families_.budget = limits.max_family_instances;
  }

  Scene read(const YAML::Node& root) {
    Cursor top(root, "", &file_, YAML::Mark());
    if (!root.IsDefined() || root.IsNull()) top.fail("the scene is empty");
    top.expect_map({"phiq", "name", "description", "dimension", "parameters", "coordinates", "points", "bodies",
                    "vectors", "constraints", "drivers", "time", "output", "solver"});
    if (auto v = top.field("phiq"); v.present() && v.integer(1, 1) != 1) v.fail("unsupported format version");

    Scene scene;
    scene.path = file_;
    if (auto n = top.field("name"); n.present()) scene.name = n.text();
    if (auto d = top.field("description"); d.present()) (void)d.text();

    if (overrides_ && overrides_->share_analysis_with) builder_.share_analysis_with(*overrides_->share_analysis_with);
    if (auto d = top.field("dimension"); d.present()) spatial_ = d.integer(2, 3) == 3;
    read_parameters(top.field("parameters"));
    check_family_total(top);  // the parameters give the ranges of the families in the sections
    read_coordinates(top.require("coordinates"));
    if (auto p = top.field("points"); p.present()) read_points(p);
    if (auto b = top.field("bodies"); b.present()) read_bodies(b);
    if (auto v = top.field("vectors"); v.present()) {
      if (!spatial_) v.fail("natural unit vectors need 'dimension: 3'");
      read_vectors(v);
    }
    read_solver(top.field("solver"), scene.sweep);  // before constraints: length scale, linear solver

    reserve_ = [&](std::size_t more) { builder_.reserve(0, static_cast<Index>(more)); };
    if (auto c = top.field("constraints"); c.present())
      read_list(c, [&](const auto& item) { read_constraint(item); });
    if (auto d = top.field("drivers"); d.present()) read_list(d, [&](const auto& item) { read_driver(item); });

    read_time(top.require("time"), scene.sweep);
    read_output(top.field("output"), scene);
    points_ = {}, bodies_ = {};  // not needed any more: their memory is free for the model
    driver_laws_ = {};
    points3_ = {}, bodies3_ = {}, vectors_ = {}, joints3_.clear();

    try {
      scene.model = std::make_unique<Model>(std::move(builder_).build());
    } catch (const Error& e) {
      top.fail(e.what());
    }
    // Models that are not square (redundant constraints, missing drivers) load: the rank analysis and the
    // minimum-norm assembly (assembly.hpp) tell what they are, and `phiq run` solves the redundant ones.
    resolve_output_residuals(scene);
    return scene;
  }

 private:
  // ---- names and numbers --------------------------------------------------------------------------------------
  std::optional<double> parameter(const std::string& name) const {
    auto it = parameters_.find(name);
    if (it == parameters_.end()) return std::nullopt;
    return it->second;
  }

  // A constant expression of parameters and pi ("L2/2", "2*pi"), exactly (symbolic engine), with the hint that a
  // coordinate is not a constant.
  template <class C>
  double constant_expression(const C& c, const std::string& s) const {
    try {
      return evaluate_constant_expression(s, [&](const std::string& n) { return parameter(n); });
    } catch (const Error& e) {
      if (builder_.find_coordinate(s) >= 0) c.fail("'" + s + "' is a coordinate; a constant is expected here");
      c.fail(e.what());
    }
  }

  // A number: a YAML number, or a constant expression of parameters and pi ("L2/2", "2*pi"); in a family, also of
  // the indices ("i + 0.5", "0.1*i") and of templated parameter names ("L{i}").
  template <class C>
  double number(const C& c) const {
    if (!c.present()) c.fail("missing number");
    if constexpr (kInFamily<C>) {
      const std::string& s = c.raw();
      ScalarPlan& p = c.plan();
      if (!p.number_ready) {
        std::optional<double> v;
        try {
          v = plain_number(s);
        } catch (const Error& e) {
          c.fail(e.what());
        }
        if (v) {
          p.number_constant = true, p.number_value = *v;
        } else if (uses_member(c, s)) {
          try {
            p.number = std::make_shared<IndexExpr>(s, expression_label(s), member_meanings(c), true);
          } catch (const Error& e) {
            c.fail(e.what());
          }
        } else {
          p.number_constant = true, p.number_value = constant_expression(c, s);  // the same as outside a family
        }
        p.number_ready = true;
      }
      double v = p.number_value;
      if (!p.number_constant) {
        try {
          v = p.number->eval(c.families().env());
        } catch (const Error& e) {
          c.fail(e.what());
        }
      }
      if (!std::isfinite(v)) c.fail("'" + s + "' is not a finite number");
      return v;
    } else {
      const std::string s = c.text();
      double v;
      std::optional<double> p;
      try {
        p = plain_number(s);
      } catch (const Error& e) {
        c.fail(e.what());
      }
      v = p ? *p : constant_expression(c, s);
      if (!std::isfinite(v)) c.fail("'" + s + "' is not a finite number");
      return v;
    }
  }
  // True when a family text uses an index in scope or a template (then it is evaluated per member).
  bool uses_member(const TCursor& c, const std::string& s) const {
    std::vector<NameToken> tokens;
    try {
      tokens = name_tokens(s, expression_label(s));
    } catch (const Error& e) {
      c.fail(e.what());
    }
    for (const NameToken& t : tokens) {
      if (t.templated) return true;
      const std::string n = s.substr(t.begin, t.end - t.begin);
      for (const auto& f : families_.frames)
        if (f.family->index == n) return true;
    }
    return false;
  }
  Meanings member_meanings(const TCursor& c) const {
    Meanings base = c.meanings();
    const ModelBuilder* b = &builder_;
    return [base, b](const std::string& n) {
      Meaning m = base(n);
      if (m.kind == Meaning::Kind::kUnknown && b->find_coordinate(n) >= 0)
        m.message = "'" + n + "' is a coordinate; a constant is expected here";
      return m;
    };
  }

  template <class C>
  double positive(const C& c) const {
    double v = number(c);
    if (!(v > 0.0)) {
      if constexpr (kInFamily<C>)
        if (!plain_number(c.raw())) c.fail("must be positive, got " + c.raw() + " = " + shortest(v));
      c.fail("must be positive, got " + c.text());
    }
    return v;
  }
  template <class C>
  std::vector<double> numbers(const C& c, std::size_t n) const {
    auto items = c.items();
    if (n && items.size() != n) c.fail("expected a list of " + std::to_string(n) + " numbers");
    std::vector<double> v;
    for (const auto& i : items) v.push_back(number(i));
    return v;
  }
  template <class C>
  kin::V2 vec2(const C& c) const {
    if (!c.is_sequence()) c.fail("expected a list");
    if (c.size() != 2) c.fail("expected a list of 2 numbers");
    return {number(c.at(0)), number(c.at(1))};
  }

  template <class C>
  Index coordinate(const C& c) const {
    const std::string s = c.name();
    Index j = coordinate_at(c, s);
    if (j < 0) c.fail("unknown coordinate '" + s + "'");
    return j;
  }

  // The index of the entry `name` that the reference at c names, or -1. In a family, a reference written without
  // template is looked up once; a templated one first tries the entry one step (the step between the last two
  // found) after the last one found, verified by name: families mostly walk their tables in order, and a hash
  // lookup in a table of millions of names costs cache misses.
  template <class C, class Find, class NameAt>
  Index lookup(const C& c, const std::string& name, Index size, const Find& find, const NameAt& name_at) const {
    if constexpr (kInFamily<C>) {
      ScalarPlan& p = c.plan();
      if (!c.node()->templated) {
        if (p.entity == ScalarPlan::kNotLooked) p.entity = find(name);
        return p.entity;
      }
      if (p.last >= 0) {
        const Index k = p.last + p.stride;
        if (k >= 0 && k < size && name_at(k) == name) return p.last = k;
      }
      const Index j = find(name);
      if (j >= 0) {
        if (p.last >= 0) p.stride = j - p.last;
        p.last = j;
      }
      return j;
    } else {
      (void)c, (void)size, (void)name_at;
      return find(name);
    }
  }
  template <class C>
  Index coordinate_at(const C& c, const std::string& name) const {
    return lookup(
        c, name, builder_.num_coordinates(), [&](const std::string& n) { return builder_.find_coordinate(n); },
        [&](Index k) -> const std::string& { return builder_.coordinate_name(k); });
  }
  template <class C, class T>
  Index entry_at(const C& c, const std::string& name, const NameTable<T>& table) const {
    return lookup(
        c, name, table.size(), [&](const std::string& n) { return table.find(n); },
        [&](Index k) -> const std::string& { return table.name(k); });
  }
  // A slot: a coordinate name or a constant (number or constant expression).
  template <class C>
  Slot slot(const C& c) const {
    if (c.is_scalar()) {
      if constexpr (kInFamily<C>) {
        const Index j = c.node()->templated ? coordinate_at(c, c.text()) : coordinate_at(c, c.raw());
        if (j >= 0) return Slot::coordinate(j);
      } else {
        Index j = builder_.find_coordinate(c.text());
        if (j >= 0) return Slot::coordinate(j);
      }
    }
    return Slot::constant(number(c));
  }

  // ---- families -----------------------------------------------------------------------------------------------
  // Reads the key "for NAME in A..B" of a family: its index and its range, compiled. `path` is the key's field
  // path, `enclosing` the indices of the families around it (outermost first), which the bounds may use.
  FamilyRange parse_range(const std::string& key, const YAML::Mark& key_mark, const std::string& path,
                          const std::vector<std::string>& enclosing) const {
    auto fail = [&](const std::string& what) { fail_at(file_, key_mark, families_.render(path), what); };
    FamilyRange r;
    std::istringstream words(key);
    std::string w_for, w_in;
    words >> w_for >> r.index >> w_in;
    std::string range;
    std::getline(words, range);
    const std::size_t dots = range.find("..");
    if (w_for != "for" || w_in != "in" || dots == std::string::npos)
      fail("a family is 'for NAME in A..B' (A and B whole numbers, B included)");
    r.lo_text = range.substr(0, dots), r.hi_text = range.substr(dots + 2);
    auto trim = [](std::string& s) {
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t") + 1);
    };
    trim(r.lo_text), trim(r.hi_text);
    if (r.lo_text.empty() || r.hi_text.empty())
      fail("a family is 'for NAME in A..B' (A and B whole numbers, B included)");
    // the range: whole-number expressions of the parameters and the enclosing indices
    Meanings meaning = [&](const std::string& name) {
      Meaning m;
      for (std::size_t k = enclosing.size(); k-- > 0;)
        if (enclosing[k] == name) return m.kind = Meaning::Kind::kIndex, m.depth = static_cast<int>(k), m;
      if (auto p = parameter(name)) return m.kind = Meaning::Kind::kConstant, m.value = *p, m;
      m.message = "unknown name '" + name + "'";
      return m;
    };
    try {
      r.lo = std::make_shared<IndexExpr>(r.lo_text, "range bound '" + clip(r.lo_text) + "'", meaning, false);
      r.hi = std::make_shared<IndexExpr>(r.hi_text, "range bound '" + clip(r.hi_text) + "'", meaning, false);
    } catch (const Error& e) {
      fail(e.what());
    }
    return r;
  }

  // The first and last member of a range, for the members of the enclosing families being read (families_);
  // messages point at the family's key (`mark`, `path`). B < A: no member.
  std::pair<std::int64_t, std::int64_t> range_bounds(const FamilyRange& r, const YAML::Mark& mark,
                                                     const std::string& path) const {
    auto fail = [&](const std::string& what) { fail_at(file_, mark, families_.render(path), what); };
    auto bound = [&](const IndexExpr& e, const std::string& text) -> std::int64_t {
      double v = 0.0;
      try {
        v = e.eval(families_.env());
      } catch (const Error& x) {
        fail(x.what());
      }
      if (!(std::floor(v) == v && std::fabs(v) <= 4503599627370496.0))
        fail("range bound '" + clip(text) + "' is " + shortest(v) + ", not a whole number");
      return static_cast<std::int64_t>(v);
    };
    return {bound(*r.lo, r.lo_text), bound(*r.hi, r.hi_text)};
  }

  // Reads "for NAME in A..B" and copies the body out of the YAML tree. `path` is the key's field path, `enclosing`
  // the indices of the families around it (outermost first), `list` whether the body is a list of items.
  std::shared_ptr<Family> parse_family(const std::string& key, const YAML::Mark& key_mark, const YAML::Node& body,
                                       const std::string& path, const std::vector<std::string>& enclosing,
                                       bool list) {
    auto f = std::make_shared<Family>();
    static_cast<FamilyRange&>(*f) = parse_range(key, key_mark, path, enclosing);
    f->key = key, f->path = path, f->mark = key_mark, f->depth = static_cast<int>(enclosing.size());
    auto fail = [&](const std::string& what) { fail_at(file_, key_mark, families_.render(path), what); };
    const std::string& n = f->index;
    if (!valid_name(n)) fail("'" + n + "' is not a valid index name");
    if (n == "t" || n == "pi") fail("index '" + n + "' is reserved");
    if (parameters_.count(n)) fail("index '" + n + "' shadows the parameter '" + n + "'");
    for (const std::string& e : enclosing)
      if (e == n) fail("index '" + n + "' shadows the index of an enclosing family");
    if (builder_.find_coordinate(n) >= 0) fail("index '" + n + "' shadows the coordinate '" + n + "'");
    if (f->depth >= limits_.max_family_depth)
      fail("families nested more than " + std::to_string(limits_.max_family_depth) + " deep");
    // the body
    std::vector<std::string> inner = enclosing;
    inner.push_back(n);
    const std::string body_path = path + kMemberMark;
    if (list) {
      if (!body.IsSequence()) fail("the body of a family in a list is a list of items: {" + key + ": [...]}");
      f->body.kind = TNode::Kind::kSeq;
      f->body.mark = body.Mark();
      f->body.path = body_path;
      const bool several = body.size() > 1;
      for (std::size_t i = 0; i < body.size(); ++i) {
        const std::string item_path = several ? body_path + "[" + std::to_string(i) + "]" : body_path;
        const YAML::Node& item = body[i];
        if (auto fk = family_item_key(item, item_path)) {
          TNode t;
          t.kind = TNode::Kind::kMap, t.mark = item.Mark(), t.path = item_path;
          const auto it = item.begin();
          t.family = parse_family(*fk, it->first.Mark(), it->second, item_path + "." + *fk, inner, true);
          f->body.seq.push_back(std::move(t));
        } else {
          f->body.seq.push_back(copy(item, item_path, body.Mark()));
        }
      }
    } else {
      if (!body.IsMap()) fail("the body of a family in a map is a map of entries: {" + key + ": {NAME: VALUE, ...}}");
      f->body.kind = TNode::Kind::kMap;
      f->body.mark = body.Mark();
      f->body.path = body_path;
      std::set<std::string> seen;
      for (auto it = body.begin(); it != body.end(); ++it) {
        const std::string here = families_.render(body_path);
        if (!it->first.IsScalar()) fail_at(file_, it->first.Mark(), here, "names must be plain scalars");
        const std::string k = it->first.Scalar();
        if (!seen.insert(k).second)
          fail_at(file_, it->first.Mark(), families_.render(body_path + "." + k), "duplicate name '" + k + "'");
        TNode::Entry e;
        e.key = k, e.key_mark = it->first.Mark();
        if (is_family_key(k))
          e.family = parse_family(k, it->first.Mark(), it->second, body_path + "." + k, inner, false);
        else
          e.value = std::make_shared<TNode>(copy(it->second, body_path + "." + k, it->first.Mark()));
        f->body.map.push_back(std::move(e));
      }
    }
    return f;
  }

  // The key of a list item {for NAME in A..B: [...]}, or nullopt when the item is not a family.
  std::optional<std::string> family_item_key(const YAML::Node& item, const std::string& path) const {
    if (!item.IsMap()) return std::nullopt;
    std::optional<std::string> key;
    for (auto it = item.begin(); it != item.end(); ++it)
      if (it->first.IsScalar() && is_family_key(it->first.Scalar())) key = it->first.Scalar();
    if (key && item.size() != 1)
      fail_at(file_, item.Mark(), families_.render(path),
              "a family item is a map with the one key 'for NAME in A..B' and nothing beside it");
    return key;
  }

  // A plain YAML subtree as a TNode (no families inside: those are only items of lists and entries of maps).
  TNode copy(const YAML::Node& n, const std::string& path, const YAML::Mark& parent_mark) const {
    TNode t;
    t.path = path;
    t.mark = n.IsDefined() ? n.Mark() : parent_mark;
    if (t.mark.line < 0) t.mark = parent_mark;
    if (!n.IsDefined() || n.IsNull()) return t;
    if (n.IsScalar()) {
      t.kind = TNode::Kind::kScalar;
      t.text = n.Scalar();
      t.templated = t.text.find_first_of("{}") != std::string::npos;
    } else if (n.IsSequence()) {
      t.kind = TNode::Kind::kSeq;
      for (std::size_t i = 0; i < n.size(); ++i) t.seq.push_back(copy(n[i], path + "[" + std::to_string(i) + "]", n.Mark()));
    } else if (n.IsMap()) {
      t.kind = TNode::Kind::kMap;
      for (auto it = n.begin(); it != n.end(); ++it) {
        TNode::Entry e;
        e.key_scalar = it->first.IsScalar();
        e.key = e.key_scalar ? it->first.Scalar() : std::string();
        e.key_mark = it->first.Mark();
        e.value = std::make_shared<TNode>(copy(it->second, path + "." + e.key, n.Mark()));
        t.map.push_back(std::move(e));
      }
    }
    return t;
  }

  // Calls each() once per member of f, with the member's index in families_; checks the range and the budget.
  template <class Each>
  void for_each_member(const Family& f, Each&& each) {
    auto fail = [&](const std::string& what) { fail_at(file_, f.mark, families_.render(f.path), what); };
    const auto [lo, hi] = range_bounds(f, f.mark, f.path);
    const std::size_t entries = f.body.kind == TNode::Kind::kSeq ? f.body.seq.size() : f.body.map.size();
    if (hi < lo || entries == 0) return;
    const auto members = static_cast<std::uint64_t>(hi - lo) + 1;
    if (members > families_.budget / entries)
      fail("the family would make " + std::to_string(members) + " x " + std::to_string(entries) +
           " entries; families may make " + std::to_string(limits_.max_family_instances) + " entries in all and " +
           std::to_string(families_.budget) + " are left (SceneLimits::max_family_instances)");
    families_.budget -= members * entries;
    if (f.depth == 0 && reserve_) reserve_(members * entries);  // the tables grow once, not by doubling
    families_.frames.push_back({&f, lo});
    if (families_.index.size() < families_.frames.size()) families_.index.resize(families_.frames.size());
    const std::size_t level = families_.frames.size() - 1;
    for (std::int64_t v = lo;; ++v) {
      families_.frames[level].value = v;
      families_.index[level] = static_cast<double>(v);
      each();
      if (v == hi) break;
    }
    families_.frames.pop_back();
  }

  // The members' entries of a family in a map section: each(name, value cursor) in order.
  template <class Each>
  void expand_map(const Family& f, Each& each) {
    for_each_member(f, [&] {
      for (const TNode::Entry& e : f.body.map) {
        if (e.family) {
          expand_map(*e.family, each);
          continue;
        }
        TCursor value(e.value.get(), &families_);
        std::string name = e.key;
        if (e.key.find_first_of("{}") != std::string::npos) {
          try {
            if (!e.name) e.name = std::make_shared<NameTemplate>(e.key, value.meanings());
            e.name->render(families_.env(), name);
          } catch (const Error& x) {
            value.fail(x.what());
          }
        }
        each(name, value);
      }
    });
  }

  // The entries of a map section, plain ones and families' members, in order: each(name, cursor).
  template <class Each>
  void read_map(const std::vector<Cursor::Entry>& entries, Each each) {
    for (auto& [name, key_mark, value] : entries) {
      if (is_family_key(name)) {
        auto f = parse_family(name, key_mark, value.node(), value.path(), {}, false);
        expand_map(*f, each);
      } else {
        each(name, value);
      }
    }
  }

  // The items of a list section, plain ones and families' members, in order.
  template <class Each>
  void read_list(const Cursor& c, Each each) {
    const std::vector<Cursor> items = c.items();
    for (const Cursor& item : items) {
      if (auto key = family_item_key(item.node(), item.path())) {
        const auto it = item.node().begin();
        auto f = parse_family(*key, it->first.Mark(), it->second, item.path() + "." + *key, {}, true);
        expand_list(*f, each);
      } else {
        each(item);
      }
    }
  }
  template <class Each>
  void expand_list(const Family& f, Each& each) {
    for_each_member(f, [&] {
      for (const TNode& item : f.body.seq) {
        if (item.family) expand_list(*item.family, each);
        else each(TCursor(&item, &families_));
      }
    });
  }

  // Refuses at once a scene whose families would make more entries than SceneLimits::max_family_instances, before
  // any is expanded (the budget of for_each_member is consumed section by section, so that a scene over the limit
  // was refused only when a later section's family ran out of it: an nfourbar scene with N = 10^7 after its first
  // 4·10^7 entries, 4.7 GB). Counts the families in the sections, M members x E entries of each body, a nested
  // family counting as one entry per member as in for_each_member; the ranges of those nested in them may use the
  // enclosing indices and stay checked as they are expanded. Reads only the keys and the sizes of the bodies: no
  // body is copied or checked (parse_family does that as each is expanded).
  void check_family_total(const Cursor& top) {
    constexpr std::uint64_t kAll = std::numeric_limits<std::uint64_t>::max();  // at least this many (saturated)
    auto add = [](std::uint64_t a, std::uint64_t b) { return b > kAll - a ? kAll : a + b; };
    std::uint64_t total = 0;
    bool nested = false;  // bodies hold families: they make more than counted
    std::vector<std::pair<std::string, std::uint64_t>> sections;  // entries by section, in order
    std::optional<std::pair<YAML::Mark, std::string>> over;         // the family that takes the total beyond
    auto count = [&](const std::string& section, const std::string& key, const YAML::Mark& mark,
                     const std::string& path, std::size_t entries, bool holds_families) {
      const auto [lo, hi] = range_bounds(parse_range(key, mark, path, {}), mark, path);
      if (hi < lo || entries == 0) return;
      const auto members = static_cast<std::uint64_t>(hi - lo) + 1;
      const std::uint64_t made = members > kAll / entries ? kAll : members * entries;
      total = add(total, made);
      nested = nested || holds_families;
      if (sections.empty() || sections.back().first != section) sections.emplace_back(section, 0);
      sections.back().second = add(sections.back().second, made);
      if (!over && total > limits_.max_family_instances) over.emplace(mark, path);
    };
    auto family_key = [](const YAML::Node& key) { return key.IsScalar() && is_family_key(key.Scalar()); };
    for (const char* section : {"coordinates", "points", "bodies", "vectors"}) {
      const Cursor c = top.field(section);
      if (!c.present() || !c.is_map() || (!spatial_ && std::string(section) == "vectors")) continue;
      for (auto it = c.node().begin(); it != c.node().end(); ++it) {
        if (!family_key(it->first)) continue;
        const YAML::Node body = it->second;  // a handle, by value: yaml-cpp's iterators give temporaries
        if (!body.IsMap()) continue;  // parse_family says what is wrong
        bool holds = false;
        for (auto b = body.begin(); b != body.end() && !holds; ++b) holds = family_key(b->first);
        count(section, it->first.Scalar(), it->first.Mark(), c.join(it->first.Scalar()), body.size(), holds);
      }
    }
    for (const char* section : {"constraints", "drivers"}) {
      const Cursor c = top.field(section);
      if (!c.present() || !c.is_sequence()) continue;
      std::size_t i = 0;
      for (auto it = c.node().begin(); it != c.node().end(); ++it, ++i) {
        const YAML::Node item = *it;
        if (!item.IsMap() || item.size() != 1 || !family_key(item.begin()->first)) continue;
        const YAML::Node body = item.begin()->second;
        if (!body.IsSequence()) continue;  // parse_family says what is wrong
        bool holds = false;
        for (auto b = body.begin(); b != body.end() && !holds; ++b)
          if (b->IsMap())
            for (auto e = b->begin(); e != b->end() && !holds; ++e) holds = family_key(e->first);
        const std::string key = item.begin()->first.Scalar();
        count(section, key, item.begin()->first.Mark(), c.path() + "[" + std::to_string(i) + "]." + key,
              body.size(), holds);
      }
    }
    if (!over) return;
    std::string by_section;
    for (const auto& [section, n] : sections)
      by_section += (by_section.empty() ? "" : ", ") + section + " " + std::to_string(n);
    fail_at(file_, over->first, over->second,
            "the families would make " + std::string(nested || total == kAll ? "at least " : "") +
                std::to_string(total) + " entries in all (" + by_section + "), more than the " +
                std::to_string(limits_.max_family_instances) + " they may make (SceneLimits::max_family_instances)");
  }

  // ---- top-level sections -------------------------------------------------------------------------------------
  void read_parameters(const Cursor& c) {
    if (!c.present()) {
      if (overrides_ && !overrides_->parameters.empty())
        c.fail("'" + overrides_->parameters[0].first + "' (given for this run) is not a parameter of the scene");
      return;
    }
    for (auto& [name, key_mark, value] : c.entries()) {
      if (!Cursor::valid_name(name)) value.fail("'" + name + "' is not a valid parameter name");
      if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
      parameters_[name] = number(value);  // may use the parameters above it
      if (overrides_)
        for (const auto& [n, v] : overrides_->parameters)
          if (n == name) parameters_[name] = v;
    }
    if (overrides_)
      for (const auto& [n, v] : overrides_->parameters)
        if (!parameters_.count(n)) c.fail("'" + n + "' (given for this run) is not a parameter of the scene");
  }

  void read_coordinates(const Cursor& c) {
    const auto entries = c.entries();
    if (entries.empty()) c.fail("at least one coordinate is needed");
    reserve_ = [&](std::size_t more) { builder_.reserve(static_cast<Index>(more), 0); };
    read_map(entries, [&](const std::string& name, const auto& value) {
      if (!Cursor::valid_name(name)) value.fail("'" + name + "' is not a valid coordinate name");
      if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
      if (parameters_.count(name)) value.fail("'" + name + "' is already a parameter");
      const double v = number(value);
      try {
        builder_.add_coordinate(name, v);  // v is finite: a duplicate name is its only error
      } catch (const Error&) {
        value.fail("duplicate name '" + name + "'");
      }
    });
    if (builder_.num_coordinates() == 0) c.fail("at least one coordinate is needed");
  }

  // A new point or body: its index in `table`, after the checks (valid, not yet a point or a body).
  template <class C, class T, class U>
  Index new_entity(const C& where, const std::string& name, NameTable<T>& table, const NameTable<U>& other) {
    if (!Cursor::valid_name(name)) where.fail("'" + name + "' is not a valid name");
    const Index k = other.contains(name) ? -1 : table.add(name);
    if (k < 0) where.fail("duplicate point or body name '" + name + "'");
    return k;
  }

  // A new spatial point, body or vector: its index in `table`, after the checks (valid, not yet any of them).
  template <class C, class T>
  Index new_entity3(const C& where, const std::string& name, NameTable<T>& table) {
    if (!Cursor::valid_name(name)) where.fail("'" + name + "' is not a valid name");
    const bool taken = points3_.contains(name) || bodies3_.contains(name) || vectors_.contains(name);
    const Index k = taken ? -1 : table.add(name);
    if (k < 0) where.fail("duplicate point, body or vector name '" + name + "'");
    return k;
  }

  void read_points(const Cursor& c) {
    if (spatial_) {
      reserve_ = [&](std::size_t more) { points3_.reserve(more); };
      read_map(c.entries(), [&](const std::string& name, const auto& value) {
        const Index k = new_entity3(value, name, points3_);
        if (value.size() != 3 || !value.is_sequence()) value.fail("a point is [x, y, z] (dimension: 3)");
        points3_[k] = Point3{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
      });
      return;
    }
    reserve_ = [&](std::size_t more) { points_.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      const Index k = new_entity(value, name, points_, bodies_);
      if (value.size() != 2 || !value.is_sequence()) value.fail("a point is [x, y]");
      points_[k] = Point2{slot(value.at(0)), slot(value.at(1))};
    });
  }

  // Bodies that move are recorded for the Grübler–Kutzbach count (a body of constants is a fixed frame, as ground);
  // a spatial body's Euler normalisation `NAME.euler` is added with it.
  void read_bodies(const Cursor& c) {
    if (spatial_) {
      reserve_ = [&](std::size_t more) { bodies3_.reserve(more); };
      read_map(c.entries(), [&](const std::string& name, const auto& value) {
        if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
        const Index k = new_entity3(value, name, bodies3_);
        if (value.size() != 7 || !value.is_sequence()) value.fail("a body is [x, y, z, e0, e1, e2, e3] (dimension: 3)");
        Slot v[7];
        for (int i = 0; i < 7; ++i) v[i] = slot(value.at(static_cast<std::size_t>(i)));
        const Frame3 f{v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
        bodies3_[k] = f;
        if (!f.is_fixed()) {
          try {
            builder_.add_body(name, f);
          } catch (const Error& e) {
            value.fail(e.what());
          }
        }
      });
      return;
    }
    reserve_ = [&](std::size_t more) { bodies_.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
      const Index k = new_entity(value, name, bodies_, points_);
      if (value.size() != 3 || !value.is_sequence()) value.fail("a body is [x, y, psi]");
      const Frame2 f{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
      bodies_[k] = f;
      if (f.x.is_coordinate() || f.y.is_coordinate() || f.psi.is_coordinate()) builder_.add_body(name, f);
    });
  }

  // Natural unit vectors (dimension 3), each with its unit-norm constraint `NAME.unit`.
  void read_vectors(const Cursor& c) {
    reserve_ = [&](std::size_t more) { vectors_.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      const Index k = new_entity3(value, name, vectors_);
      if (value.size() != 3 || !value.is_sequence()) value.fail("a vector is [ux, uy, uz]");
      const Point3 u{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
      vectors_[k] = u;
      try {
        builder_.add_unit_vector(name, u);
      } catch (const Error& e) {
        value.fail(e.what());
      }
    });
  }

  // A point reference: a point name or an inline [x, y].
  template <class C>
  Point2 point(const C& c) const {
    if (c.is_sequence()) {
      if (c.size() != 2) c.fail("an inline point is [x, y]");
      return Point2{slot(c.at(0)), slot(c.at(1))};
    }
    const std::string s = c.name();
    const Index k = entry_at(c, s, points_);
    if (k < 0) c.fail("unknown point '" + s + "'");
    return points_[k];
  }
  template <class C>
  std::pair<Point2, Point2> segment(const C& c) const {
    if (!c.is_sequence() || c.size() != 2) c.fail("a segment is [from, to]");
    return {point(c.at(0)), point(c.at(1))};
  }
  template <class C>
  Frame2 body(const C& c) const {
    const std::string s = c.name();
    if (s == kGround) return Frame2{Slot::constant(0), Slot::constant(0), Slot::constant(0)};
    const Index k = entry_at(c, s, bodies_);
    if (k < 0) c.fail("unknown body '" + s + "'");
    return bodies_[k];
  }
  // An attachment of a revolute or prismatic pair: {body: B, at: [x, y]} (local point) or {point: P}.
  template <class C>
  std::pair<Frame2, kin::V2> attachment(const C& c) const {
    if (!c.is_map()) c.fail("expected {body: NAME, at: [x, y]} or {point: NAME}");
    if (c.field("point").present()) {
      c.expect_map({"point"});
      Point2 p = point(c.field("point"));
      return {Frame2{p.x, p.y, Slot::constant(0.0)}, kin::V2{0, 0}};
    }
    c.expect_map({"body", "at"});
    Frame2 f = body(c.require("body"));
    kin::V2 at{0, 0};
    if (auto a = c.field("at"); a.present()) at = vec2(a);
    return {f, at};
  }

  template <class C>
  void read_constraint(const C& c) {
    if (!c.is_map()) c.fail("a constraint is a mapping with a 'type'");
    const std::string type = c.require("type").text();
    std::string name;
    if (auto n = c.field("name"); n.present()) name = n.name();
    if (spatial_) return read_constraint_3d(c, type, name);
    static const std::set<std::string> spatial_only = {"spherical", "cylindrical", "universal", "planar",
                                                       "rigid",     "point_on_plane", "dot"};
    if (spatial_only.count(type))
      c.require("type").fail("'" + type + "' is a spatial constraint: it needs 'dimension: 3'");
    try {
      if (type == "distance") {
        c.expect_map({"type", "name", "points", "length"});
        auto [a, b] = segment(c.require("points"));
        add(c, name, DistanceSpec{a, b, positive(c.require("length"))});
      } else if (type == "fixed_point") {
        c.expect_map({"type", "name", "point", "at"});
        Point2 p = point(c.require("point"));
        kin::V2 at = vec2(c.require("at"));
        add(c, name, PinSpec{Frame2{p.x, p.y, Slot::constant(0)},
                             Frame2{Slot::constant(at.x), Slot::constant(at.y), Slot::constant(0)}, {0, 0}, {0, 0}});
      } else if (type == "point_on_line") {
        c.expect_map({"type", "name", "point", "line"});
        auto [a, b] = segment(c.require("line"));
        add(c, name, PointOnLineSpec{point(c.require("point")), a, b, 1.0});
      } else if (type == "constant_angle") {
        c.expect_map({"type", "name", "segments", "angle"});
        auto segs = c.require("segments");
        if (!segs.is_sequence() || segs.size() != 2) segs.fail("expected two segments [[A, B], [C, D]]");
        auto [a, b] = segment(segs.at(0));
        auto [cc, d] = segment(segs.at(1));
        add(c, name, ConstantAngleSpec{a, b, cc, d, number(c.require("angle")), 1.0});
      } else if (type == "segment_angle") {
        c.expect_map({"type", "name", "segment", "angle"});
        auto [a, b] = segment(c.require("segment"));
        add(c, name, SegmentAngleSpec{a, b, Slot::coordinate(coordinate(c.require("angle")))});
      } else if (type == "polar") {
        c.expect_map({"type", "name", "point", "origin", "length", "angle"});
        add(c, name, PolarSpec{point(c.require("point")), point(c.require("origin")), number(c.require("length")),
                               slot(c.require("angle"))});
      } else if (type == "revolute") {
        c.expect_map({"type", "name", "between"});
        auto between = c.require("between");
        if (!between.is_sequence() || between.size() != 2) between.fail("a revolute joins two attachments");
        auto [fa, sa] = attachment(between.at(0));
        auto [fb, sb] = attachment(between.at(1));
        add(c, name, PinSpec{fa, fb, sa, sb});
      } else if (type == "prismatic") {
        c.expect_map({"type", "name", "between", "axis", "angle"});
        auto between = c.require("between");
        if (!between.is_sequence() || between.size() != 2) between.fail("a prismatic pair joins two attachments");
        auto [fa, sa] = attachment(between.at(0));
        auto [fb, sb] = attachment(between.at(1));
        if (!fa.psi.is_coordinate() && !fb.psi.is_coordinate() && !between.at(0).field("body").present())
          between.fail("a prismatic pair needs bodies");
        PrismaticSpec spec{fa, fb, sa, sb, {1, 0}, 0.0};
        if (auto ax = c.field("axis"); ax.present()) spec.axis = vec2(ax);
        if (auto an = c.field("angle"); an.present()) spec.angle = number(an);
        if (spec.axis.x == 0.0 && spec.axis.y == 0.0) c.field("axis").fail("the axis must not be zero");
        add(c, name, spec);
      } else if (type == "loop") {
        c.expect_map({"type", "name", "links", "closure"});
        LoopSpec spec;
        for (const auto& l : c.require("links").items()) {
          l.expect_map({"length", "angles", "offset"});
          LoopSpec::Link link;
          link.length = slot(l.require("length"));
          if (auto o = l.field("offset"); o.present()) link.offset = number(o);
          if (auto as = l.field("angles"); as.present()) {
            for (const auto& a : as.items()) {
              std::string s = a.text();
              double sign = 1.0;
              if (!s.empty() && (s[0] == '-' || s[0] == '+')) sign = s[0] == '-' ? -1.0 : 1.0, s = s.substr(1);
              Index j = builder_.find_coordinate(s);
              if (j < 0) a.fail("unknown coordinate '" + s + "'");
              link.terms.push_back({Slot::coordinate(j), sign});
            }
          }
          spec.links.push_back(std::move(link));
        }
        if (spec.links.empty()) c.require("links").fail("a loop needs at least one link");
        if (auto cl = c.field("closure"); cl.present()) spec.closure = vec2(cl);
        add(c, name, std::move(spec));
      } else if (type == "equation") {
        c.expect_map({"type", "name", "expr", "unit"});
        EquationSpec spec{compile(c.require("expr"), true), std::nullopt, unit(c.field("unit"))};
        add(c, name, std::move(spec));
      } else {
        c.require("type").fail("unknown constraint type '" + type +
                               "' (distance, fixed_point, point_on_line, constant_angle, segment_angle, polar, "
                               "revolute, prismatic, loop, equation)");
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
  }

  // ---- dimension 3 ------------------------------------------------------------------------------------------------
  template <class C>
  kin3::V3 vec3(const C& c) const {
    if (!c.is_sequence() || c.size() != 3) c.fail("expected a list of 3 numbers");
    return {number(c.at(0)), number(c.at(1)), number(c.at(2))};
  }
  // A spatial point reference: a point name or an inline [x, y, z].
  template <class C>
  Point3 point3(const C& c) const {
    if (c.is_sequence()) {
      if (c.size() != 3) c.fail("an inline point is [x, y, z] (dimension: 3)");
      return Point3{slot(c.at(0)), slot(c.at(1)), slot(c.at(2))};
    }
    const std::string s = c.name();
    const Index k = entry_at(c, s, points3_);
    if (k < 0) c.fail("unknown point '" + s + "'");
    return points3_[k];
  }
  template <class C>
  Point3 vector3(const C& c) const {
    const std::string s = c.name();
    const Index k = entry_at(c, s, vectors_);
    if (k < 0) c.fail("unknown vector '" + s + "'");
    return vectors_[k];
  }
  template <class C>
  Frame3 body3(const C& c) const {
    const std::string s = c.name();
    if (s == kGround) return Frame3::ground();
    const Index k = entry_at(c, s, bodies3_);
    if (k < 0) c.fail("unknown body '" + s + "'");
    return bodies3_[k];
  }
  // A non-zero finite direction.
  template <class C>
  kin3::V3 direction3(const C& c) const {
    const kin3::V3 v = vec3(c);
    if (kin3::is_zero(v)) c.fail("must not be the zero vector");
    return v;
  }
  // A side of a spatial joint: {body: B, at: [x, y, z], axis: [..], ref: [..]} or {point: P, vector: u}.
  template <class C>
  JointSide3 side3(const C& c) const {
    if (!c.is_map()) c.fail("expected {body: NAME, at: [x, y, z], axis: [x, y, z], ref: [x, y, z]} or {point: NAME, vector: NAME}");
    if (c.field("point").present()) {
      c.expect_map({"point", "vector"});
      std::optional<Point3> v;
      if (auto u = c.field("vector"); u.present()) v = vector3(u);
      return JointSide3::natural_point(point3(c.field("point")), v);
    }
    c.expect_map({"body", "at", "axis", "ref"});
    JointSide3 s = JointSide3::body(body3(c.require("body")), kin3::V3{});
    if (auto a = c.field("at"); a.present()) s.at = vec3(a);
    if (auto a = c.field("axis"); a.present()) s.axis = direction3(a);
    if (auto r = c.field("ref"); r.present()) s.ref = direction3(r);
    return s;
  }
  template <class C>
  std::pair<JointSide3, JointSide3> sides3(const C& c, const std::string& type) const {
    auto between = c.require("between");
    if (!between.is_sequence() || between.size() != 2) between.fail("a " + type + " joint joins two attachments");
    return {side3(between.at(0)), side3(between.at(1))};
  }
  // A direction of a dot product: a vector name, or a segment [A, B] of points (B − A).
  template <class C>
  std::pair<Attachment3, Attachment3> dot_direction(const C& c, Unit& unit) const {
    if (c.is_sequence()) {
      if (c.size() != 2) c.fail("a direction is a vector name or a segment [A, B]");
      unit = Unit::kLength;
      return {Attachment3::natural(point3(c.at(1))), Attachment3::natural(point3(c.at(0)))};
    }
    unit = Unit::kNone;
    return {Attachment3::natural(vector3(c)), Attachment3::zero()};
  }

  template <class Spec, class C>
  void add_joint3(const C& c, const std::string& name, const std::string& type) {
    c.expect_map({"type", "name", "between"});
    Spec spec;
    std::tie(spec.a, spec.b) = sides3(c, type);
    if (!name.empty()) joints3_[name] = Joint3{type, spec.a, spec.b};
    add(c, name, std::move(spec));
  }

  template <class C>
  void read_constraint_3d(const C& c, const std::string& type, const std::string& name) {
    try {
      if (type == "distance") {
        c.expect_map({"type", "name", "points", "between", "length"});
        SpatialDistanceSpec spec;
        if (c.field("points").present() == c.field("between").present())
          c.fail("a distance has either 'points' (natural points) or 'between' (attachments)");
        if (auto pts = c.field("points"); pts.present()) {
          if (!pts.is_sequence() || pts.size() != 2) pts.fail("a distance joins two points [A, B]");
          spec.ends[0] = Attachment3::natural(point3(pts.at(0)));
          spec.ends[1] = Attachment3::natural(point3(pts.at(1)));
        } else {
          auto [a, b] = sides3(c, "distance");
          spec.ends[0] = Attachment3::body_point(a.frame, a.at);
          spec.ends[1] = Attachment3::body_point(b.frame, b.at);
        }
        spec.length = positive(c.require("length"));
        add(c, name, spec);
      } else if (type == "fixed_point") {
        c.expect_map({"type", "name", "point", "at"});
        SphericalSpec spec;
        spec.a = JointSide3::natural_point(point3(c.require("point")));
        spec.b = JointSide3::body(Frame3::ground(), vec3(c.require("at")));
        add(c, name, std::move(spec));
      } else if (type == "dot") {
        c.expect_map({"type", "name", "directions", "value"});
        auto dirs = c.require("directions");
        if (!dirs.is_sequence() || dirs.size() != 2) dirs.fail("a dot product has two directions [D1, D2]");
        DotSpec spec;
        std::tie(spec.ends[0], spec.ends[1]) = dot_direction(dirs.at(0), spec.end_units[0]);
        std::tie(spec.ends[2], spec.ends[3]) = dot_direction(dirs.at(1), spec.end_units[1]);
        spec.value = number(c.require("value"));
        add(c, name, spec);
      } else if (type == "spherical") {
        add_joint3<SphericalSpec>(c, name, type);
      } else if (type == "revolute") {
        add_joint3<SpatialRevoluteSpec>(c, name, type);
      } else if (type == "prismatic") {
        add_joint3<SpatialPrismaticSpec>(c, name, type);
      } else if (type == "cylindrical") {
        add_joint3<CylindricalSpec>(c, name, type);
      } else if (type == "universal") {
        add_joint3<UniversalSpec>(c, name, type);
      } else if (type == "planar") {
        add_joint3<PlanarSpec>(c, name, type);
      } else if (type == "rigid") {
        add_joint3<RigidSpec>(c, name, type);
      } else if (type == "point_on_line") {
        add_joint3<SpatialPointOnLineSpec>(c, name, type);
      } else if (type == "point_on_plane") {
        add_joint3<PointOnPlaneSpec>(c, name, type);
      } else if (type == "equation") {
        c.expect_map({"type", "name", "expr", "unit"});
        add(c, name, EquationSpec{compile(c.require("expr"), true), std::nullopt, unit(c.field("unit"))});
      } else if (type == "polar" || type == "segment_angle" || type == "constant_angle" || type == "loop") {
        c.require("type").fail("'" + type + "' is a planar constraint; this scene has 'dimension: 3'");
      } else {
        c.require("type").fail("unknown constraint type '" + type +
                               "' (dimension 3: distance, fixed_point, dot, spherical, revolute, prismatic, "
                               "cylindrical, universal, planar, rigid, point_on_line, point_on_plane, equation)");
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
  }

  // {joint: NAME, measure: angle | distance, law}: the rotation of a revolute or cylindrical joint, the
  // translation of a prismatic or cylindrical one.
  template <class C>
  void read_joint_driver(const C& c, const std::string& name, MotionLaw law) {
    auto j = c.field("joint");
    if (!spatial_) j.fail("joint drivers need 'dimension: 3' (in the plane, drive a coordinate)");
    const std::string joint = j.name();
    auto it = joints3_.find(joint);
    if (it == joints3_.end()) j.fail("unknown joint '" + joint + "' (a named spatial joint of 'constraints')");
    const Joint3& J = it->second;
    std::string measure;
    if (auto m = c.field("measure"); m.present()) {
      measure = m.text();
      if (measure != "angle" && measure != "distance") m.fail("measure is angle or distance");
    } else if (J.type == "revolute") {
      measure = "angle";
    } else if (J.type == "prismatic") {
      measure = "distance";
    } else if (J.type == "cylindrical") {
      c.fail("a cylindrical joint's driver needs 'measure: angle' or 'measure: distance'");
    }
    const bool angle_ok = J.type == "revolute" || J.type == "cylindrical";
    const bool distance_ok = J.type == "prismatic" || J.type == "cylindrical";
    if ((measure == "angle" && !angle_ok) || (measure == "distance" && !distance_ok) || measure.empty())
      j.fail("joint '" + joint + "' is a " + J.type + " joint: drivers measure the angle of a revolute or " +
             "cylindrical joint, or the distance of a prismatic or cylindrical one");
    if (measure == "angle") {
      JointAngleDriverSpec d;
      d.a = J.a, d.b = J.b, d.law = std::move(law);
      add(c, name, std::move(d));
    } else {
      JointDistanceDriverSpec d;
      d.a = J.a, d.b = J.b, d.law = std::move(law);
      add(c, name, std::move(d));
    }
  }

  template <class C>
  void read_driver(const C& c) {
    if (!c.is_map()) c.fail("a driver is a mapping with 'coordinate', 'expr' or 'joint', and a 'law'");
    c.expect_map({"name", "coordinate", "expr", "unit", "joint", "measure", "law"});
    std::string name;
    if (auto n = c.field("name"); n.present()) name = n.name();
    MotionLaw law = motion_law(c.require("law"));
    if (!name.empty()) driver_laws_.emplace(name, law);  // for `output: drivers` (shared data: a cheap copy)
    const bool by_coordinate = c.field("coordinate").present(), by_expr = c.field("expr").present(),
               by_joint = c.field("joint").present();
    if (int(by_coordinate) + int(by_expr) + int(by_joint) != 1)
      c.fail("a driver has one of 'coordinate', 'expr' or 'joint'");
    if (c.field("measure").present() && !by_joint) c.field("measure").fail("'measure' goes with 'joint'");
    try {
      if (by_joint) {
        if (c.field("unit").present()) c.field("unit").fail("'unit' goes with 'expr' (a joint driver has its own)");
        read_joint_driver(c, name, std::move(law));
      } else if (by_coordinate) {
        if (c.field("unit").present()) c.field("unit").fail("'unit' goes with 'expr' (a coordinate has its own)");
        add(c, name, CoordinateDriverSpec{Slot::coordinate(coordinate(c.field("coordinate"))), std::move(law)});
      } else {
        add(c, name, EquationSpec{compile(c.field("expr"), false), std::move(law), unit(c.field("unit"))});
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
  }

  template <class C>
  MotionLaw motion_law(const C& c) const {
    if (!c.is_map()) c.fail("a law is a mapping with a 'type'");
    const std::string type = c.require("type").text();
    try {
      if (type == "linear") {
        c.expect_map({"type", "initial", "rate"});
        return MotionLaw::linear(number(c.require("initial")), number(c.require("rate")));
      }
      if (type == "polynomial") {
        c.expect_map({"type", "coefficients"});
        auto v = numbers(c.require("coefficients"), 0);
        if (v.empty()) c.require("coefficients").fail("needs at least one coefficient");
        return MotionLaw::polynomial(v);
      }
      if (type == "harmonic") {
        c.expect_map({"type", "offset", "amplitude", "frequency", "phase"});
        double off = c.field("offset").present() ? number(c.field("offset")) : 0.0;
        double ph = c.field("phase").present() ? number(c.field("phase")) : 0.0;
        return MotionLaw::harmonic(off, number(c.require("amplitude")), number(c.require("frequency")), ph);
      }
      if (type == "table") {
        c.expect_map({"type", "t", "values"});
        auto t = numbers(c.require("t"), 0), v = numbers(c.require("values"), 0);
        if (t.size() != v.size()) c.require("values").fail("needs as many values as times");
        if (t.size() < 2) c.require("t").fail("a table needs at least 2 points");
        for (std::size_t k = 1; k < t.size(); ++k)
          if (!(t[k] > t[k - 1])) c.require("t").at(k).fail("times must increase strictly");
        return MotionLaw::table(t, v);
      }
      if (type == "expression") {
        c.expect_map({"type", "f"});
        auto f = c.require("f");
        std::shared_ptr<const CompiledExpression> expr;
        if constexpr (kInFamily<C>) {
          expr = family_expression(f, true, false);
        } else {
          expr = CompiledExpression::compile(f.text(), [&](const std::string& n) -> std::optional<NameBinding> {
            if (n == "t") return NameBinding{NameBinding::Kind::kTime};
            if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
            return std::nullopt;
          });
        }
        return MotionLaw::expression(expr);
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
    c.require("type").fail("unknown law type '" + type + "' (linear, polynomial, harmonic, table, expression)");
  }

  template <class C>
  std::shared_ptr<const CompiledExpression> compile(const C& c, bool allow_time) const {
    try {
      if constexpr (kInFamily<C>) {
        return family_expression(c, allow_time, true);
      } else {
        return CompiledExpression::compile(c.text(), resolver(true), allow_time);
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
  }
  // Names of equation expressions: t, coordinates (when allowed), parameters.
  NameResolver resolver(bool coordinates) const {
    return [this, coordinates](const std::string& n) -> std::optional<NameBinding> {
      if (n == "t") return NameBinding{NameBinding::Kind::kTime};
      if (coordinates)
        if (Index j = builder_.find_coordinate(n); j >= 0) return NameBinding{NameBinding::Kind::kCoordinate, j};
      if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
      return std::nullopt;
    };
  }

  // An equation (or law) expression of a family member: compiled once per body, rebound per member. Throws Error.
  std::shared_ptr<const CompiledExpression> family_expression(const TCursor& c, bool allow_time,
                                                              bool allow_coordinates) const {
    const std::string& text = c.raw();
    ScalarPlan& plan = c.plan();
    if (!plan.equation) {
      auto eq = std::make_shared<ScalarPlan::Equation>();
      eq->allow_coordinates = allow_coordinates;
      if (!uses_member(c, text)) {
        eq->shared = CompiledExpression::compile(text, resolver(allow_coordinates), allow_time);
      } else {
        // each templated name becomes a placeholder identifier that the text cannot already contain
        const std::vector<NameToken> tokens = name_tokens(text, expression_label(text));
        std::string prefix = "phiq_template_";
        while (text.find(prefix) != std::string::npos) prefix += "_";
        std::string rewritten;
        std::map<std::string, std::string> placeholder_of;  // token -> placeholder identifier
        std::vector<std::pair<std::string, std::string>> back;  // placeholder identifier -> token
        std::size_t last = 0;
        for (const NameToken& t : tokens) {
          if (!t.templated) continue;
          const std::string token = text.substr(t.begin, t.end - t.begin);
          if (t.call) throw labelled(expression_label(text), "'" + token + "' is not a function");
          auto [it, fresh] = placeholder_of.emplace(token, prefix + std::to_string(placeholder_of.size()) + "_");
          if (fresh) {
            eq->names.push_back(std::make_shared<NameTemplate>(token, c.meanings()));
            back.emplace_back(it->second, token);
          }
          rewritten += text.substr(last, t.begin - last) + it->second;
          last = t.end;
        }
        rewritten += text.substr(last);
        // compiled indices: one per placeholder, index and coordinate the text names
        std::map<std::string, Index> compiled_index;
        const Families& fx = c.families();
        auto add = [&](const std::string& n, ScalarPlan::Equation::Placeholder p) {
          auto [it, fresh] = compiled_index.emplace(n, static_cast<Index>(eq->placeholders.size()));
          if (fresh) eq->placeholders.push_back(p);
          return it->second;
        };
        NameResolver resolve = [&](const std::string& n) -> std::optional<NameBinding> {
          using P = ScalarPlan::Equation::Placeholder;
          for (std::size_t k = 0; k < back.size(); ++k)
            if (back[k].first == n)
              return NameBinding{NameBinding::Kind::kCoordinate, add(n, P{P::Kind::kTemplate, -1, 0, k})};
          for (std::size_t k = fx.frames.size(); k-- > 0;)
            if (fx.frames[k].family->index == n)
              return NameBinding{NameBinding::Kind::kCoordinate,
                                 add(n, P{P::Kind::kIndex, -1, static_cast<int>(k), 0})};
          if (n == "t") return NameBinding{NameBinding::Kind::kTime};
          if (allow_coordinates)
            if (Index j = builder_.find_coordinate(n); j >= 0)
              return NameBinding{NameBinding::Kind::kCoordinate, add(n, P{P::Kind::kCoordinate, j, 0, 0})};
          if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
          return std::nullopt;
        };
        try {
          eq->compiled = CompiledExpression::compile(rewritten, resolve, allow_time);
        } catch (const Error& e) {
          // say it with the text as written
          std::string m = e.what();
          for (const auto& [placeholder, token] : back)
            for (std::size_t p = m.find(placeholder); p != std::string::npos; p = m.find(placeholder, p + token.size()))
              m.replace(p, placeholder.size(), token);
          throw Error(m);
        }
      }
      plan.equation = eq;
    }
    const ScalarPlan::Equation& eq = *plan.equation;
    if (eq.shared) return eq.shared;
    const Families& fx = c.families();
    std::vector<Index> target(eq.placeholders.size(), -1);
    std::vector<double> value(eq.placeholders.size(), 0.0);
    std::string name;
    for (std::size_t k = 0; k < eq.placeholders.size(); ++k) {
      const auto& p = eq.placeholders[k];
      using K = ScalarPlan::Equation::Placeholder::Kind;
      if (p.kind == K::kCoordinate) {
        target[k] = p.coordinate;
      } else if (p.kind == K::kIndex) {
        value[k] = fx.index[static_cast<std::size_t>(p.depth)];
      } else {
        eq.names[p.name]->render(fx.env(), name);
        if (Index j = eq.allow_coordinates ? builder_.find_coordinate(name) : -1; j >= 0) target[k] = j;
        else if (auto v = parameter(name)) value[k] = *v;
        else throw labelled(expression_label(text), "unknown name '" + name + "'");
      }
    }
    return eq.compiled->rebind(target, value, text);
  }

  template <class C>
  Unit unit(const C& c) const {
    if (!c.present()) return Unit::kNone;
    const std::string s = c.text();
    if (s == "length") return Unit::kLength;
    if (s == "angle") return Unit::kAngle;
    if (s == "none") return Unit::kNone;
    c.fail("unit is length, angle or none, got '" + s + "'");
  }

  template <class C, class Spec>
  void add(const C& c, const std::string& name, Spec spec) {
    const std::string label = name.empty() ? std::string(Spec::kKind) + "#" + std::to_string(++unnamed_) : name;
    try {
      builder_.add(label, std::move(spec));
    } catch (const Error&) {
      // the builder registers the name only when it adds the constraint: a name it has is a duplicate (reported
      // before anything else wrong with the constraint, as a check before adding would)
      if (builder_.has_constraint(label))
        c.field("name").fail("duplicate constraint or driver name '" + label + "'");
      throw;
    }
  }

  void read_time(const Cursor& c, SweepOptions& o) const {
    c.expect_map({"start", "end", "steps"});
    o.t_begin = number(c.require("start"));
    o.t_end = number(c.require("end"));
    o.steps = c.require("steps").integer(0, 1000000000);
    if (o.steps > 0 && o.t_end == o.t_begin) c.require("end").fail("end equals start but steps > 0");
    if (const std::string why = detail::time_grid_problem(o.t_begin, o.t_end, o.steps); !why.empty())
      c.require("end").fail(why);  // steps that would not move time: run_sweep refuses them
  }

  // The output list, and from it the sweep's plan: derivatives, points, residuals and the condition estimate are
  // computed only when listed here (models/README.md, `output`).
  void read_output(const Cursor& c, Scene& scene) {
    scene.sweep.velocities = scene.sweep.accelerations = false;
    bool coordinates_listed = false;
    if (c.present()) {
      c.expect_map({"velocities", "accelerations", "coordinates", "points", "drivers", "residuals", "max_residual",
                    "rcond"});
      if (auto v = c.field("velocities"); v.present()) scene.sweep.velocities = v.boolean();
      if (auto a = c.field("accelerations"); a.present()) scene.sweep.accelerations = a.boolean();
      if (auto cs = c.field("coordinates"); cs.present()) {
        coordinates_listed = true;
        std::set<Index> seen;
        for (const Cursor& i : cs.items()) {
          Index j = coordinate(i);
          if (!seen.insert(j).second) i.fail("coordinate listed twice");
          scene.output_coordinates.push_back(j);
        }
      }
      if (auto ps = c.field("points"); ps.present()) {
        std::set<std::string> seen;
        for (const Cursor& i : ps.items()) {
          OutputPoint p = output_point(i);
          if (!seen.insert(p.name).second) i.fail("output point '" + p.name + "' listed twice");
          scene.sweep.points.push_back(std::move(p));
        }
      }
      if (auto ds = c.field("drivers"); ds.present()) {
        std::set<std::string> seen;
        for (const Cursor& i : ds.items()) {
          const std::string n = i.name();
          auto it = driver_laws_.find(n);
          if (it == driver_laws_.end()) i.fail("unknown driver '" + n + "' (a named entry of `drivers`)");
          if (!seen.insert(n).second) i.fail("driver listed twice");
          scene.output_drivers.push_back({n, it->second});
        }
      }
      if (auto rs = c.field("residuals"); rs.present()) {
        std::set<std::string> seen;
        for (const Cursor& i : rs.items()) {
          const std::string n = i.name();
          if (!builder_.has_constraint(n)) i.fail("unknown constraint or driver '" + n + "'");
          if (!seen.insert(n).second) i.fail("constraint listed twice");
          residual_names_.push_back(n);
        }
      }
      if (auto v = c.field("max_residual"); v.present()) scene.output_max_residual = v.boolean();
      if (auto v = c.field("rcond"); v.present()) scene.sweep.condition = v.boolean();
      scene.sweep.residuals = scene.output_max_residual || !residual_names_.empty();
    }
    if (!coordinates_listed)
      for (Index j = 0; j < builder_.num_coordinates(); ++j) scene.output_coordinates.push_back(j);
    // the columns `residual` and `rcond` must not collide with a coordinate's
    for (Index j : scene.output_coordinates) {
      const std::string& n = builder_.coordinate_name(j);
      if ((n == "residual" && scene.output_max_residual) || (n == "rcond" && scene.sweep.condition))
        c.fail("coordinate '" + n + "' and the column '" + n + "' would share a name: leave it out of coordinates");
    }
  }
  // An output point: a point name, or {name: P, body: B, at: [x, y]} (a point fixed on body B, in B's frame;
  // [x, y, z] in dimension 3).
  OutputPoint output_point(const Cursor& c) const {
    if (spatial_) {
      if (!c.is_map()) {
        const std::string n = c.name();
        const Index k = entry_at(c, n, points3_);
        if (k < 0) c.fail("unknown point '" + n + "' (or write {name: P, body: B, at: [x, y, z]})");
        return spatial_point(n, points3_[k]);
      }
      c.expect_map({"name", "body", "at"});
      const std::string n = c.require("name").name();
      if (!Cursor::valid_name(n)) c.require("name").fail("'" + n + "' is not a valid name");
      const Frame3 f = body3(c.require("body"));
      kin3::V3 at;
      if (auto a = c.field("at"); a.present()) at = vec3(a);
      return spatial_body_point(n, f, at);
    }
    if (!c.is_map()) {
      const std::string n = c.name();
      const Index k = entry_at(c, n, points_);
      if (k < 0) c.fail("unknown point '" + n + "' (or write {name: P, body: B, at: [x, y]})");
      return planar_point(n, points_[k]);
    }
    c.expect_map({"name", "body", "at"});
    const std::string n = c.require("name").name();
    if (!Cursor::valid_name(n)) c.require("name").fail("'" + n + "' is not a valid name");
    const Frame2 f = body(c.require("body"));
    kin::V2 at{0, 0};
    if (auto a = c.field("at"); a.present()) at = vec2(a);
    return planar_body_point(n, f, at.x, at.y);
  }
  // Constraint names of `output: residuals` to indices, once the model is built (one pass over the constraints).
  void resolve_output_residuals(Scene& scene) const {
    if (residual_names_.empty()) return;
    std::unordered_map<std::string, Index> wanted;
    for (const std::string& n : residual_names_) wanted.emplace(n, -1);
    const auto& cs = scene.model->constraints();
    for (std::size_t k = 0; k < cs.size(); ++k)
      if (auto it = wanted.find(cs[k].name); it != wanted.end()) it->second = static_cast<Index>(k);
    for (const std::string& n : residual_names_) scene.output_residuals.push_back(wanted.at(n));
  }

  void read_solver(const Cursor& c, SweepOptions& o) {
    if (!c.present()) return;
    c.expect_map({"tolerance", "max_iterations", "assembly_max_iterations", "line_search", "predictor",
                  "max_subdivisions", "length_scale", "linear_solver", "newton"});
    if (auto v = c.field("tolerance"); v.present()) {
      double tol = positive(v);
      if (tol >= 1.0) v.fail("tolerance must be below 1");
      o.newton.tolerance = o.assembly.tolerance = tol;
    }
    if (auto v = c.field("max_iterations"); v.present()) o.newton.max_iterations = static_cast<int>(v.integer(1, 1000));
    if (auto v = c.field("assembly_max_iterations"); v.present())
      o.assembly.max_iterations = static_cast<int>(v.integer(1, 10000));
    if (auto v = c.field("line_search"); v.present()) o.newton.line_search = v.boolean();
    if (auto v = c.field("max_subdivisions"); v.present()) o.max_subdivisions = static_cast<int>(v.integer(0, 30));
    if (auto v = c.field("newton"); v.present()) {
      const std::string s = v.text();
      if (s == "modified") o.newton.jacobian_update = JacobianUpdate::kWhenSlow;
      else if (s == "full") o.newton.jacobian_update = JacobianUpdate::kEveryIteration;
      else v.fail("newton is modified or full");
    }
    if (auto v = c.field("predictor"); v.present()) {
      if (!predictor_from_string(v.text(), &o.predictor)) v.fail(std::string("predictor is ") + predictor_names());
    }
    if (auto v = c.field("length_scale"); v.present()) builder_.set_length_scale(positive(v));
    if (auto v = c.field("linear_solver"); v.present()) {
      const std::string s = v.text();
      if (s == "umfpack") builder_.set_linear_solver(LinearSolverKind::kUmfpack);
      else if (s == "klu") builder_.set_linear_solver(LinearSolverKind::kKlu);
      else if (s == "dense") builder_.set_linear_solver(LinearSolverKind::kDense);
      else v.fail("linear_solver is umfpack, klu or dense");
    }
    predictor_field_ = c.field("predictor").present();
  }

  const std::string& file_;
  const SceneLimits& limits_;
  ModelBuilder builder_;

 public:
  const SceneOverrides* overrides_ = nullptr;  ///< the caller's changes, if any

 private:
  std::unordered_map<std::string, double> parameters_;
  NameTable<Point2> points_;
  NameTable<Frame2> bodies_;
  bool spatial_ = false;  // dimension: 3
  NameTable<Point3> points3_;
  NameTable<Frame3> bodies3_;
  NameTable<Point3> vectors_;
  // Named spatial joints, for the drivers that measure them.
  struct Joint3 {
    std::string type;
    JointSide3 a, b;
  };
  std::unordered_map<std::string, Joint3> joints3_;
  Families families_;
  std::function<void(std::size_t)> reserve_;  // room for that many more entries of the section being read
  int unnamed_ = 0;
  bool predictor_field_ = false;
  std::unordered_map<std::string, MotionLaw> driver_laws_;  // named drivers, for `output: drivers`
  std::vector<std::string> residual_names_;                 // `output: residuals`, resolved after the build

 public:
  bool predictor_given() const { return predictor_field_; }
};

// First pass over the YAML events, before any node tree is built: refuses what a scene never needs and what
// could exhaust memory or stack (deep nesting, aliases, several documents, too many nodes, huge values).
class ShapeGuard final : public YAML::EventHandler {
 public:
  ShapeGuard(const std::string& path, const SceneLimits& limits) : path_(path), limits_(limits) {}
  void OnDocumentStart(const YAML::Mark& m) override {
    if (++documents_ > 1) fail(m, "a scene is one YAML document (found a second '---')");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { count(m); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override {
    fail(m, "YAML aliases (*name) are not supported in scenes");
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string& value) override {
    count(m);
    if (value.size() > limits_.max_scalar_bytes)
      fail(m, "a value of " + std::to_string(value.size()) + " bytes; the limit is " +
                  std::to_string(limits_.max_scalar_bytes));
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    enter(m);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    enter(m);
  }
  void OnMapEnd() override { --depth_; }

 private:
  void count(const YAML::Mark& m) {
    if (++nodes_ > limits_.max_nodes)
      fail(m, "more than " + std::to_string(limits_.max_nodes) + " values; the scene is too large");
  }
  void enter(const YAML::Mark& m) {
    count(m);
    if (++depth_ > limits_.max_depth)
      fail(m, "nested more than " + std::to_string(limits_.max_depth) + " levels deep");
  }
  [[noreturn]] void fail(const YAML::Mark& m, const std::string& what) const {
    throw SceneError(path_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ": " + what);
  }
  const std::string& path_;
  const SceneLimits& limits_;
  int documents_ = 0, depth_ = 0;
  std::size_t nodes_ = 0;
};

std::string yaml_error(const std::string& path, const YAML::Exception& e) {
  std::ostringstream s;
  s << path;
  if (e.mark.line >= 0) s << ":" << e.mark.line + 1 << ":" << e.mark.column + 1;
  s << ": YAML syntax error: " << e.msg;
  return s.str();
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits) {
  return parse_scene(text, path, limits, SceneOverrides{});
}

Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits,
                  const SceneOverrides& overrides) {
  if (text.size() > limits.max_file_bytes)
    throw SceneError(path + ": the scene is " + std::to_string(text.size() >> 20) + " MiB; the limit is " +
                     std::to_string(limits.max_file_bytes >> 20) + " MiB");
  if (text.find('\0') != std::string::npos) throw SceneError(path + ": the scene is not text (contains a NUL byte)");
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    ShapeGuard guard(path, limits);
    while (parser.HandleNextDocument(guard)) {
    }
  } catch (const YAML::Exception& e) {
    throw SceneError(yaml_error(path, e));
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw SceneError(yaml_error(path, e));
  }
  SceneReader reader(path, limits);
  reader.overrides_ = &overrides;
  Scene scene = reader.read(root);
  // A predictor that needs derivatives the scene does not output would compute extra work silently: refuse.
  if (reader.predictor_given()) {
    const Predictor p = scene.sweep.predictor;
    if ((predictor_needs_accelerations(p) && !scene.sweep.accelerations) ||
        (predictor_needs_velocities(p) && !(scene.sweep.velocities || scene.sweep.accelerations)))
      throw SceneError(path + ": solver.predictor: '" + to_string(p) +
                       "' needs the derivatives it extrapolates with in the output (velocities / accelerations)");
  }
  return scene;
}

Scene load_scene(const std::string& path, const SceneLimits& limits) {
  return load_scene(path, limits, SceneOverrides{});
}

Scene load_scene(const std::string& path, const SceneLimits& limits, const SceneOverrides& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open the scene file");
  // size first: a huge file is refused before it is read into memory
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw SceneError(path + ": cannot read the scene file (not a regular file?)");
  if (static_cast<std::uint64_t>(size) > limits.max_file_bytes)
    throw SceneError(path + ": the scene is " + std::to_string(size >> 20) + " MiB; the limit is " +
                     std::to_string(limits.max_file_bytes >> 20) + " MiB");
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), size);
  if (in.gcount() != size) throw SceneError(path + ": cannot read the scene file");
  return parse_scene(text, path, limits, overrides);
}

}  // namespace phiq
