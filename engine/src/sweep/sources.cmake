# engine/src/sweep/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/batch.cpp
  ${CMAKE_CURRENT_LIST_DIR}/chunk_schedule.cpp
  ${CMAKE_CURRENT_LIST_DIR}/euler_signs.cpp
  ${CMAKE_CURRENT_LIST_DIR}/limit_watch.cpp
  ${CMAKE_CURRENT_LIST_DIR}/parallel_sweep.cpp
  ${CMAKE_CURRENT_LIST_DIR}/predictors.cpp
  ${CMAKE_CURRENT_LIST_DIR}/resources.cpp
  ${CMAKE_CURRENT_LIST_DIR}/row_efforts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/run_sweep.cpp
  ${CMAKE_CURRENT_LIST_DIR}/singular_positions.cpp
  ${CMAKE_CURRENT_LIST_DIR}/step_failures.cpp
  ${CMAKE_CURRENT_LIST_DIR}/stepper.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sweep_summary.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sweeper.cpp
)
