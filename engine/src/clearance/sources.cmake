# engine/src/clearance/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/clearance_geometry.cpp
  ${CMAKE_CURRENT_LIST_DIR}/clearance_pairs.cpp
  ${CMAKE_CURRENT_LIST_DIR}/clearance_broad_phase.cpp
  ${CMAKE_CURRENT_LIST_DIR}/clearance_along.cpp
  ${CMAKE_CURRENT_LIST_DIR}/clearance_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/clearance_files.cpp
)
