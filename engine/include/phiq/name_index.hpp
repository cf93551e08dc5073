/// @file
/// detail::NameIndex: names to indices for tables of millions of names (a model's coordinates and constraints, a
/// scene's points and bodies). The names themselves are kept once, by the caller, and read through name_of(index).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "phiq/types.hpp"

namespace phiq::detail {

/// Names to indices. A name that ends in a decimal number ("x17", "crank3": a family's member) is kept in a
/// vector per stem indexed by that number, so that a family's members, added and looked up in order, touch
/// memory in order; any other name (and a numbered one far beyond its stem's count) by open addressing over
/// (hash, index) pairs, at most half full. At 10^6 members a hash slot per name cost a cache and TLB miss per
/// insertion and look-up: a third of loading a scene of 10^6 four-bars. A node-based
/// std::unordered_map<std::string, Index> costs, besides, an allocation and a copy of the name per entry.
class NameIndex {
 public:
  /// The index stored for `name`, or -1. name_of(k) returns the name stored with index k.
  template <class NameOf>
  Index find(std::string_view name, const NameOf& name_of) const {
    const Numbered n = numbered(name);
    if (n.number >= 0) {
      const Run* r = run(n.stem);
      if (!r) return -1;  // no name of this stem was ever stored
      if (static_cast<std::size_t>(n.number) < r->ids.size() && r->ids[static_cast<std::size_t>(n.number)] >= 0)
        return r->ids[static_cast<std::size_t>(n.number)];
      if (!r->spilled) return -1;
    }
    return hashed_find(name, name_of);
  }
  /// Stores `id` for `name`; false (and nothing stored) when the name is present. name_of is only called for the
  /// indices already stored.
  template <class NameOf>
  bool insert(std::string_view name, Index id, const NameOf& name_of) {
    const Numbered n = numbered(name);
    if (n.number < 0) {
      if (hashed_find(name, name_of) >= 0) return false;
      hashed_insert(name, id);
      return true;
    }
    Run& r = run_for(n.stem);
    const auto k = static_cast<std::size_t>(n.number);
    if (k < r.ids.size() && r.ids[k] >= 0) return false;
    if (r.spilled && hashed_find(name, name_of) >= 0) return false;
    if (k < 2 * r.count + 64) {  // dense enough: at least about half of the run's places are taken
      if (k >= r.ids.size()) r.ids.resize(std::max(k + 1, 2 * r.ids.size()), -1);
      r.ids[k] = id;
      ++r.count;
    } else {
      r.spilled = true;
      hashed_insert(name, id);
    }
    return true;
  }
  /// Kept for the callers that announce how many names follow: the runs grow geometrically, in order, and the
  /// hash table only holds the names that are not a family's.
  void reserve(std::size_t) {}
  /// Forgets every name and frees the memory.
  void clear();

 private:
  /// A name split into its stem and its trailing decimal number (-1: none, or one with a leading zero, or of
  /// more than nine digits: "x01" and "x1" are two names, and only the second is numbered).
  struct Numbered {
    std::string_view stem;
    std::int64_t number = -1;
  };
  /// The indices of the names stem + k by k (-1: no such name), how many are stored, and whether some name of
  /// the stem went to the hash table instead (its number far beyond the run's count).
  struct Run {
    std::vector<Index> ids;
    std::size_t count = 0;
    bool spilled = false;
  };
  struct Slot {
    std::uint64_t hash = 0;
    Index id = -1;
  };
  static Numbered numbered(std::string_view name);
  static std::uint64_t hash(std::string_view s);
  const Run* run(std::string_view stem) const;
  Run& run_for(std::string_view stem);
  template <class NameOf>
  Index hashed_find(std::string_view name, const NameOf& name_of) const {
    if (slots_.empty()) return -1;
    const std::uint64_t h = hash(name);
    for (std::size_t i = h & mask_;; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.id < 0) return -1;
      if (s.hash == h && name_of(s.id) == name) return s.id;
    }
  }
  void hashed_insert(std::string_view name, Index id);
  void grow(std::size_t cap);

  struct StemHash {
    using is_transparent = void;
    std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
  };
  std::unordered_map<std::string, Run, StemHash, std::equal_to<>> runs_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0, size_ = 0;
};

}  // namespace phiq::detail
