# engine/src/solve/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/assembly.cpp
  ${CMAKE_CURRENT_LIST_DIR}/friction_losses.cpp
  ${CMAKE_CURRENT_LIST_DIR}/friction_losses_along.cpp
  ${CMAKE_CURRENT_LIST_DIR}/block_triangular.cpp
  ${CMAKE_CURRENT_LIST_DIR}/derivatives.cpp
  ${CMAKE_CURRENT_LIST_DIR}/effort_sensitivity.cpp
  ${CMAKE_CURRENT_LIST_DIR}/inverse_dynamics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/joint_reactions.cpp
  ${CMAKE_CURRENT_LIST_DIR}/natural_joints.cpp
  ${CMAKE_CURRENT_LIST_DIR}/natural_reactions.cpp
  ${CMAKE_CURRENT_LIST_DIR}/natural_flat_sites.cpp
  ${CMAKE_CURRENT_LIST_DIR}/evaluation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/force_diagnosis.cpp
  ${CMAKE_CURRENT_LIST_DIR}/factorisation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/kinematics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/parameter_reach.cpp
  ${CMAKE_CURRENT_LIST_DIR}/position_report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/rank_analysis.cpp
  ${CMAKE_CURRENT_LIST_DIR}/rounding_rows.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sensitivity.cpp
)
