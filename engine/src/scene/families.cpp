// The out-of-line parts of families.hpp: family keys, member paths in messages, the field checks of a body
// (once per body, not per member) and the meanings of names in family texts.
#include "scene/families.hpp"

#include <cctype>
#include <set>

namespace phiq::detail::scene {

bool is_family_key(const std::string& k) {
  return k.size() > 3 && k.compare(0, 3, "for") == 0 && std::isspace(static_cast<unsigned char>(k[3]));
}

std::string Families::render(const std::string& path) const {
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

void TCursor::check_fields(std::initializer_list<const char*> allowed, std::uintptr_t sig) const {
  std::set<std::string> seen;
  for (const TNode::Entry& e : node_->map) {
    if (!e.key_scalar) fail_at(*fx_->file, e.key_mark, fx_->render(node_->path), "keys must be plain names");
    const std::string where = fx_->render(node_->path + "." + e.key);
    if (!seen.insert(e.key).second) fail_at(*fx_->file, e.key_mark, where, "duplicate field '" + e.key + "'");
    bool ok = false;
    for (const char* a : allowed) ok = ok || e.key == a;
    if (!ok)
      fail_at(*fx_->file, e.key_mark, where, "unknown field '" + e.key + "' (allowed: " + allowed_list(allowed) + ")");
  }
  node_->checked_fields = sig;
}

Meanings TCursor::meanings() const {
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

}  // namespace phiq::detail::scene
