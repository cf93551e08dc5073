// The TypedBlocks of part 2 of ConstraintKinds (kinds/typed_blocks.hpp).
#include "kinds/typed_blocks.hpp"

std::shared_ptr<phiq::ConstraintBlock> phiq::detail::new_block_part_2(std::size_t kind) {
  return new_block_in_part<2>(kind);
}
