# engine/src/scene/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/yaml_cursor.cpp
  ${CMAKE_CURRENT_LIST_DIR}/index_expression.cpp
  ${CMAKE_CURRENT_LIST_DIR}/families.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scene_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_values.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_equations.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_families.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_entities.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_constraints.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_drivers.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_settings.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_efforts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_parts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_limits.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_loads.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_shapes.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_clearance.cpp
  ${CMAKE_CURRENT_LIST_DIR}/read_scene_file.cpp
  ${CMAKE_CURRENT_LIST_DIR}/load_scene.cpp
)
