# engine/src/modes/: the sources of this stage (engine/CMakeLists.txt includes this file): every assembly mode of a
# model by polynomial homotopy continuation (phiq/modes.hpp).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/polynomial_system.cpp
  ${CMAKE_CURRENT_LIST_DIR}/path_tracking.cpp
  ${CMAKE_CURRENT_LIST_DIR}/start_systems.cpp
  ${CMAKE_CURRENT_LIST_DIR}/degree_lowering.cpp
  ${CMAKE_CURRENT_LIST_DIR}/homotopy_solve.cpp
  ${CMAKE_CURRENT_LIST_DIR}/model_rows.cpp
  ${CMAKE_CURRENT_LIST_DIR}/angle_relations.cpp
  ${CMAKE_CURRENT_LIST_DIR}/polynomial_fit.cpp
  ${CMAKE_CURRENT_LIST_DIR}/block_solve.cpp
  ${CMAKE_CURRENT_LIST_DIR}/assembly_modes.cpp
)
