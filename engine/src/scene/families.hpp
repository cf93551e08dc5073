// Indexed families (`for i in A..B`, models/README.md): the body of a family copied out of the YAML tree (TNode,
// Family), the state of the expansion (Families), and TCursor, the cursor over a body for the member being read.
// A family's body is copied once into compact nodes that know their field path; the texts in it — names with
// {templates}, numbers that use the indices, equations — are compiled on first use (ScalarPlan) and afterwards
// only evaluated, once per member: no YAML walk, no parsing and no symbolic work per member. TCursor has the
// interface of Cursor (yaml_cursor.hpp), so that the section readers read a member exactly as a plain entry.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "phiq/expression.hpp"
#include "scene/index_expression.hpp"
#include "scene/yaml_cursor.hpp"

namespace phiq::detail::scene {

// In a field path, this character stands for the member of the enclosing family: messages render it "[i=17]".
constexpr char kMemberMark = '\x01';

// A key that opens an indexed family: "for NAME in A..B".
bool is_family_key(const std::string& k);

struct Family;

// The compiled forms of one scalar of a family body, made on first use (a node is used in one role only).
struct ScalarPlan {
  std::shared_ptr<const NameTemplate> name;  // text(): the scalar as a name with templates
  bool number_ready = false;                 // number():
  bool number_constant = false;              //   the same for every member: number_value
  double number_value = 0.0;
  std::shared_ptr<const IndexExpr> number;  //   else evaluated per member
  static constexpr Index kNotLooked = -2;
  Index entity = kNotLooked;    // a coordinate, point or body named without template: its index
  Index last = -1, stride = 1;  // a templated reference: the last index found, the step before it
  struct Equation;
  std::shared_ptr<Equation> equation;  // equation and law expressions
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
    std::shared_ptr<Family> family;                    // a nested `for` entry (map sections)
    mutable std::shared_ptr<const NameTemplate> name;  // the key as a name, compiled on first use
  };
  Kind kind = Kind::kNull;
  bool templated = false;  // a scalar with braces
  YAML::Mark mark;         // where messages about it point
  std::string path;        // field path as written, with kMemberMark after each enclosing family's key
  std::string text;        // scalar
  std::vector<Entry> map;
  std::vector<TNode> seq;
  std::shared_ptr<Family> family;             // a list item that is a nested family {for ...: [...]}
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
  std::string key;   // as written
  std::string path;  // of the key, with the marks of the enclosing families
  YAML::Mark mark;   // of the key
  int depth = 0;     // 0 for a family in a section, 1 inside it, ...
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
  std::string render(const std::string& path) const;
};

// A Cursor over a family body, for the member being read: the same interface, so that the scene reader reads a
// member exactly as it reads a plain entry; text() renders templates; paths name the member.
class TCursor {
 public:
  TCursor(const TNode* node, Families* fx, const TNode* parent = nullptr, const char* key = nullptr)
      : node_(node), parent_(parent), key_(key), fx_(fx) {}

  const TNode* node() const { return node_; }
  // The field path of the member being read ("constraints[0][i=17]"), and where it is written.
  std::string path() const { return fx_->render(node_ ? node_->path : parent_->path + "." + key_); }
  YAML::Mark mark() const { return node_ ? node_->mark : parent_->mark; }
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
    check_fields(allowed, sig);
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
  Meanings meanings() const;

 private:
  // expect_map() the first time for this node and list of fields: the checks, then the mark that they passed.
  void check_fields(std::initializer_list<const char*> allowed, std::uintptr_t sig) const;

  const TNode* node_;
  const TNode* parent_;  // for a missing field: the map it is missing from
  const char* key_;
  Families* fx_;
};

// True for a reader instantiated on a family member (the readers are templates over Cursor and TCursor).
template <class C>
inline constexpr bool kInFamily = std::is_same_v<C, TCursor>;

}  // namespace phiq::detail::scene
