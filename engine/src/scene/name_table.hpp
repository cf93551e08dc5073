// NameTable: the points, bodies and vectors of a scene by name, in order of definition. Apart from the readers
// because both the section that defines the names and the constraints that refer to them use it, and because its
// growth policy matters at 10^6-member families.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "phiq/model.hpp"
#include "phiq/types.hpp"

namespace phiq::detail::scene {

// Points and bodies by name, in order of definition (families look references up by guessing the next index).
// The names are indexed by open addressing (detail::NameIndex, as the model's coordinates and constraints): a
// node-based hash map allocated a node per name and took 13 % of loading 10⁶ four-bars (10⁶ points).
template <class T>
class NameTable {
 public:
  // Adds a name with a default value; returns its index, or -1 when the name exists.
  Index add(const std::string& name) {
    const Index k = size();
    if (!index_.insert(name, k, name_of())) return -1;
    values_.emplace_back();
    names_.push_back(name);
    return k;
  }
  bool contains(const std::string& name) const { return find(name) >= 0; }
  Index find(const std::string& name) const { return index_.find(name, name_of()); }
  Index size() const { return static_cast<Index>(values_.size()); }
  // Room for `more` entries (grow only).
  void reserve(std::size_t more) {
    const std::size_t n = values_.size() + more;
    index_.reserve(n);
    if (n > values_.capacity())
      values_.reserve(std::max(n, 2 * values_.capacity())), names_.reserve(values_.capacity());
  }
  const std::string& name(Index k) const { return names_[static_cast<std::size_t>(k)]; }
  T& operator[](Index k) { return values_[static_cast<std::size_t>(k)]; }
  const T& operator[](Index k) const { return values_[static_cast<std::size_t>(k)]; }

 private:
  auto name_of() const {
    return [this](Index k) -> const std::string& { return names_[static_cast<std::size_t>(k)]; };
  }
  detail::NameIndex index_;
  std::vector<T> values_;
  std::vector<std::string> names_;
};

}  // namespace phiq::detail::scene
