# engine/src/import/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/asmt_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/asmt_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/import_asmt.cpp
)
