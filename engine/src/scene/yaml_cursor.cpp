// The YAML cursor's out-of-line parts (yaml_cursor.hpp): messages located in the file, the checks of a mapping's
// fields, the reading of user-named entries and of plain YAML numbers.
#include "scene/yaml_cursor.hpp"

#include <limits>
#include <set>
#include <sstream>

#include "phiq/text.hpp"

namespace phiq::detail::scene {

[[noreturn]] void fail_at(const std::string& file, YAML::Mark m, const std::string& path, const std::string& what) {
  std::ostringstream s;
  s << file;
  if (m.line >= 0) s << ":" << m.line + 1 << ":" << m.column + 1;
  s << ": " << (path.empty() ? "(top level)" : path) << ": " << what;
  throw SceneError(single_line(s.str()));  // keys and values quoted in it may hold any bytes: one line of UTF-8
}

std::string allowed_list(std::initializer_list<const char*> allowed) {
  std::string list;
  for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
  return list;
}

void Cursor::expect_map(std::initializer_list<const char*> allowed) const {
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

std::vector<Cursor> Cursor::items() const {
  if (!node_.IsSequence()) fail("expected a list");
  std::vector<Cursor> v;
  for (std::size_t i = 0; i < node_.size(); ++i) v.push_back(at(i));
  return v;
}

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

}  // namespace phiq::detail::scene
