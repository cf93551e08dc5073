# engine/src/expression/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/compiled_expression.cpp
  ${CMAKE_CURRENT_LIST_DIR}/parser.cpp
  ${CMAKE_CURRENT_LIST_DIR}/symbolic.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tape.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tape_builder.cpp
)
