# engine/src/kinds/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/constraint_kinds_3d.cpp
  ${CMAKE_CURRENT_LIST_DIR}/curve.cpp
  ${CMAKE_CURRENT_LIST_DIR}/motion_law.cpp
  ${CMAKE_CURRENT_LIST_DIR}/typed_blocks.cpp
  ${CMAKE_CURRENT_LIST_DIR}/typed_blocks_0.cpp
  ${CMAKE_CURRENT_LIST_DIR}/typed_blocks_1.cpp
  ${CMAKE_CURRENT_LIST_DIR}/typed_blocks_2.cpp
)
# Every kind's block is compiled in these three files (typed_blocks.hpp): each its own translation unit, so that
# the two cores share them rather than one unity group holding all.
set_source_files_properties(
  ${CMAKE_CURRENT_LIST_DIR}/typed_blocks_0.cpp ${CMAKE_CURRENT_LIST_DIR}/typed_blocks_1.cpp
  ${CMAKE_CURRENT_LIST_DIR}/typed_blocks_2.cpp PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
