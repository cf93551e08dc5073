// NameTable: the points, bodies and vectors of a scene by name, in order of definition. Apart from the readers
// because both the section that defines the names and the constraints that refer to them use it, and because its
// growth policy matters at 10^6-member families.
#pragma once

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

#include "phiq/types.hpp"

namespace phiq::detail::scene {

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

}  // namespace phiq::detail::scene
