// The walk over the members of families, for the readers of map sections (coordinates, points, bodies, vectors)
// and list sections (constraints, drivers). Templates over the caller's lambda, defined in a header so that the
// per-member call is inlined: a 10^6-member family costs no indirect call per member.
#pragma once

#include <string>

#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

// Calls each() once per member of f, with the member's index in families_; checks the range and the budget.
template <class Each>
void SceneReader::for_each_member(const Family& f, Each&& each) {
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
void SceneReader::expand_map(const Family& f, Each& each) {
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
void SceneReader::read_map(const std::vector<Cursor::Entry>& entries, Each each) {
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
void SceneReader::read_list(const Cursor& c, Each each) {
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
void SceneReader::expand_list(const Family& f, Each& each) {
  for_each_member(f, [&] {
    for (const TNode& item : f.body.seq) {
      if (item.family)
        expand_list(*item.family, each);
      else
        each(TCursor(&item, &families_));
    }
  });
}

}  // namespace phiq::detail::scene
