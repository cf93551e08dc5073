// Families as the scene reader meets them (scene_reader.hpp): the key "for NAME in A..B" read and its range
// evaluated, the body copied out of the YAML tree into TNodes (families.hpp), and the check, before any family is
// expanded, that all of them together stay within SceneLimits::max_family_instances. The walk over the members is
// in family_expansion.hpp.
#include <limits>
#include <set>
#include <sstream>

#include "phiq/text.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

// Reads the key "for NAME in A..B" of a family: its index and its range, compiled. `path` is the key's field
// path, `enclosing` the indices of the families around it (outermost first), which the bounds may use.
FamilyRange SceneReader::parse_range(const std::string& key, const YAML::Mark& key_mark, const std::string& path,
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
std::pair<std::int64_t, std::int64_t> SceneReader::range_bounds(const FamilyRange& r, const YAML::Mark& mark,
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
std::shared_ptr<Family> SceneReader::parse_family(const std::string& key, const YAML::Mark& key_mark,
                                                  const YAML::Node& body, const std::string& path,
                                                  const std::vector<std::string>& enclosing, bool list) {
  auto f = std::make_shared<Family>();
  static_cast<FamilyRange&>(*f) = parse_range(key, key_mark, path, enclosing);
  f->key = key, f->path = path, f->mark = key_mark, f->depth = static_cast<int>(enclosing.size());
  auto fail = [&](const std::string& what) { fail_at(file_, key_mark, families_.render(path), what); };
  const std::string& n = f->index;
  if (!valid_name(n)) fail("'" + n + "' is not a valid index name");
  if (n == "t" || n == "pi") fail("index '" + n + "' is reserved");
  if (names_.parameters.count(n)) fail("index '" + n + "' shadows the parameter '" + n + "'");
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
std::optional<std::string> SceneReader::family_item_key(const YAML::Node& item, const std::string& path) const {
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
TNode SceneReader::copy(const YAML::Node& n, const std::string& path, const YAML::Mark& parent_mark) const {
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
    for (std::size_t i = 0; i < n.size(); ++i)
      t.seq.push_back(copy(n[i], path + "[" + std::to_string(i) + "]", n.Mark()));
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

// Refuses at once a scene whose families would make more entries than SceneLimits::max_family_instances, before
// any is expanded (the budget of for_each_member is consumed section by section, so that a scene over the limit
// was refused only when a later section's family ran out of it: an nfourbar scene with N = 10^7 after its first
// 4·10^7 entries, 4.7 GB). Counts the families in the sections, M members x E entries of each body, a nested
// family counting as one entry per member as in for_each_member; the ranges of those nested in them may use the
// enclosing indices and stay checked as they are expanded. Reads only the keys and the sizes of the bodies: no
// body is copied or checked (parse_family does that as each is expanded).
void SceneReader::check_family_total(const Cursor& top) {
  constexpr std::uint64_t kAll = std::numeric_limits<std::uint64_t>::max();  // at least this many (saturated)
  auto add = [](std::uint64_t a, std::uint64_t b) { return b > kAll - a ? kAll : a + b; };
  std::uint64_t total = 0;
  bool nested = false;                                          // bodies hold families: they make more than counted
  std::vector<std::pair<std::string, std::uint64_t>> sections;  // entries by section, in order
  std::optional<std::pair<YAML::Mark, std::string>> over;       // the family that takes the total beyond
  auto count = [&](const std::string& section, const std::string& key, const YAML::Mark& mark, const std::string& path,
                   std::size_t entries, bool holds_families) {
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
  for (const char* section : {"coordinates", "points", "bodies", "vectors", "parts"}) {
    const Cursor c = top.field(section);
    if (!c.present() || !c.is_map() || (!spatial_ && std::string(section) == "vectors")) continue;
    for (auto it = c.node().begin(); it != c.node().end(); ++it) {
      if (!family_key(it->first)) continue;
      const YAML::Node body = it->second;  // a handle, by value: yaml-cpp's iterators give temporaries
      if (!body.IsMap()) continue;         // parse_family says what is wrong
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
      count(section, key, item.begin()->first.Mark(), c.path() + "[" + std::to_string(i) + "]." + key, body.size(),
            holds);
    }
  }
  if (!over) return;
  std::string by_section;
  for (const auto& [section, n] : sections)
    by_section += (by_section.empty() ? "" : ", ") + section + " " + std::to_string(n);
  fail_at(file_, over->first, over->second,
          "the families would make " + std::string(nested || total == kAll ? "at least " : "") + std::to_string(total) +
              " entries in all (" + by_section + "), more than the " + std::to_string(limits_.max_family_instances) +
              " they may make (SceneLimits::max_family_instances)");
}

}  // namespace phiq::detail::scene
