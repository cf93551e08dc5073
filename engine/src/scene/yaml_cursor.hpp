// The cursor over the YAML tree of a scene: a node with the dotted field path that led to it, typed reads of its
// scalars, and messages that name the file, line, column and field ("scene.yaml:12:5: constraints[3].length: ...").
// Every section reader reads through it (or through TCursor, its twin over family bodies, families.hpp), which is
// why it is apart from the readers.
#pragma once

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "phiq/scene.hpp"
#include "base/names.hpp"

namespace phiq::detail::scene {

// Throws SceneError "file:line:column: path: what" (without line and column when the mark has none).
[[noreturn]] void fail_at(const std::string& file, YAML::Mark m, const std::string& path, const std::string& what);

// "a, b, c": the allowed fields of a mapping, for messages.
std::string allowed_list(std::initializer_list<const char*> allowed);

// A YAML number as a double; nullopt when `s` is not a plain number (then it may be a constant expression).
// Throws SceneError-free Error for a number out of the range of a double: never hand those to the symbolic engine,
// which would try to represent 1e3082222222 exactly (found by the fuzzer: a hang in GMP).
std::optional<double> plain_number(const std::string& s);

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

// A YAML node with the dotted path that led to it, for messages.
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
  void expect_map(std::initializer_list<const char*> allowed) const;
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
  std::vector<Cursor> items() const;
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

}  // namespace phiq::detail::scene
