// detail::NameIndex's parts that are not templates (phiq/name_index.hpp).
#include "phiq/name_index.hpp"

#include <algorithm>

namespace phiq::detail {

NameIndex::Numbered NameIndex::numbered(std::string_view name) {
  std::size_t d = name.size();
  while (d > 0 && name[d - 1] >= '0' && name[d - 1] <= '9') --d;
  const std::size_t digits = name.size() - d;
  if (digits == 0 || digits > 9 || (digits > 1 && name[d] == '0')) return {};
  std::int64_t number = 0;
  for (std::size_t i = d; i < name.size(); ++i) number = 10 * number + (name[i] - '0');
  return {name.substr(0, d), number};
}

std::uint64_t NameIndex::hash(std::string_view s) { return std::hash<std::string_view>{}(s); }

const NameIndex::Run* NameIndex::run(std::string_view stem) const {
  const auto it = runs_.find(stem);
  return it == runs_.end() ? nullptr : &it->second;
}

NameIndex::Run& NameIndex::run_for(std::string_view stem) {
  const auto it = runs_.find(stem);
  if (it != runs_.end()) return it->second;
  return runs_.emplace(std::string(stem), Run{}).first->second;
}

void NameIndex::hashed_insert(std::string_view name, Index id) {
  if (2 * (size_ + 1) > slots_.size()) grow(std::max<std::size_t>(16, 2 * slots_.size()));
  const std::uint64_t h = hash(name);
  std::size_t i = h & mask_;
  while (slots_[i].id >= 0) i = (i + 1) & mask_;
  slots_[i] = Slot{h, id};
  ++size_;
}

void NameIndex::grow(std::size_t cap) {
  std::vector<Slot> old(cap);
  old.swap(slots_);
  mask_ = cap - 1;
  for (const Slot& s : old) {
    if (s.id < 0) continue;
    std::size_t i = s.hash & mask_;
    while (slots_[i].id >= 0) i = (i + 1) & mask_;
    slots_[i] = s;
  }
}

void NameIndex::clear() {
  std::unordered_map<std::string, Run, StemHash, std::equal_to<>>().swap(runs_);
  std::vector<Slot>().swap(slots_);
  mask_ = size_ = 0;
}

}  // namespace phiq::detail
