// The TypedBlocks of part 0 of ConstraintKinds (kinds/typed_blocks.hpp).
#include "kinds/typed_blocks.hpp"

std::shared_ptr<phiq::ConstraintBlock> phiq::detail::new_block_part_0(std::size_t kind) {
  return new_block_in_part<0>(kind);
}
