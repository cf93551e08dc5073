// Internal: detail::new_registered_block() (phiq/model.hpp). Each registered kind's TypedBlock is compiled here and
// nowhere else, in three files built side by side (typed_blocks_0.cpp …), each holding a third of ConstraintKinds.
#pragma once

#include <memory>
#include <utility>

#include "phiq/model.hpp"

namespace phiq::detail {

// Part p holds the kinds [kind_part_begin(p), kind_part_begin(p + 1)) of ConstraintKinds.
constexpr std::size_t kind_part_begin(std::size_t p) { return ConstraintKinds::size * p / 3; }

std::shared_ptr<ConstraintBlock> new_block_part_0(std::size_t kind);  // typed_blocks_0.cpp
std::shared_ptr<ConstraintBlock> new_block_part_1(std::size_t kind);  // typed_blocks_1.cpp
std::shared_ptr<ConstraintBlock> new_block_part_2(std::size_t kind);  // typed_blocks_2.cpp

// The block of `kind` among the kinds Begin + I (null for another kind).
template <std::size_t Begin, std::size_t... I>
std::shared_ptr<ConstraintBlock> new_block_among(std::size_t kind, std::index_sequence<I...>) {
  std::shared_ptr<ConstraintBlock> out;
  ((kind == Begin + I ? void(out = std::make_shared<TypedBlock<ConstraintKinds::at<Begin + I>>>()) : void()), ...);
  return out;
}

// The block of `kind` among the kinds of part `Part`.
template <std::size_t Part>
std::shared_ptr<ConstraintBlock> new_block_in_part(std::size_t kind) {
  constexpr std::size_t begin = kind_part_begin(Part), end = kind_part_begin(Part + 1);
  return new_block_among<begin>(kind, std::make_index_sequence<end - begin>{});
}

}  // namespace phiq::detail
