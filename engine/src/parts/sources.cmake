# engine/src/parts/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/applied_loads.cpp
  ${CMAKE_CURRENT_LIST_DIR}/curve_tube.cpp
  ${CMAKE_CURRENT_LIST_DIR}/expression_rate.cpp
  ${CMAKE_CURRENT_LIST_DIR}/force_rate.cpp
  ${CMAKE_CURRENT_LIST_DIR}/frame_rates.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mass_properties.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_file.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mesh_is_closed.cpp
  ${CMAKE_CURRENT_LIST_DIR}/part_motion.cpp
  ${CMAKE_CURRENT_LIST_DIR}/part_pose.cpp
  ${CMAKE_CURRENT_LIST_DIR}/polygon.cpp
  ${CMAKE_CURRENT_LIST_DIR}/same_forces.cpp
  ${CMAKE_CURRENT_LIST_DIR}/shape_checks.cpp
  ${CMAKE_CURRENT_LIST_DIR}/shape_triangles.cpp
)
