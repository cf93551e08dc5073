# engine/src/linear/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/klu_lu.cpp
  ${CMAKE_CURRENT_LIST_DIR}/linear_solver.cpp
  ${CMAKE_CURRENT_LIST_DIR}/min_norm_solver.cpp
)
