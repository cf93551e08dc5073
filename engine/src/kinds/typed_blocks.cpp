// detail::new_registered_block() (phiq/model.hpp): to the file that compiles the kind's block.
#include "kinds/typed_blocks.hpp"

#include <string>

#include "phiq/types.hpp"

namespace phiq {

std::shared_ptr<ConstraintBlock> detail::new_registered_block(std::size_t kind) {
  if (kind < kind_part_begin(1)) return new_block_part_0(kind);
  if (kind < kind_part_begin(2)) return new_block_part_1(kind);
  if (kind < ConstraintKinds::size) return new_block_part_2(kind);
  throw Error("new_registered_block: no registered kind " + std::to_string(kind) + " (phiq bug)");
}

}  // namespace phiq
