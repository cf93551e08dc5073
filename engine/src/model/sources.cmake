# engine/src/model/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/model.cpp
  ${CMAKE_CURRENT_LIST_DIR}/name_index.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sparse_pattern.cpp
)
