# engine/src/import/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/asmt_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/asmt_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/import_asmt.cpp
  ${CMAKE_CURRENT_LIST_DIR}/import_model.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mechanism_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mjcf_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sdf_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/urdf_reader.cpp
)
