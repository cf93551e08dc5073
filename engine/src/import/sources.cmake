# engine/src/import/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/asmt_compare.cpp
  ${CMAKE_CURRENT_LIST_DIR}/asmt_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/asmt_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/import_asmt.cpp
  ${CMAKE_CURRENT_LIST_DIR}/import_model.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mechanism.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mechanism_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mjcf_documents.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mjcf_option.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mjcf_equality.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mjcf_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sdf_module.cpp
  ${CMAKE_CURRENT_LIST_DIR}/urdf_reader.cpp
)

# SDF: libsdformat 12 in a module of its own, loaded on the first SDF file (sdf_module.hpp says why). It shares the
# few helpers of mechanism.cpp and text.cpp by compiling them, not by linking the engine.
add_library(phiq_sdf MODULE
  ${CMAKE_CURRENT_LIST_DIR}/sdf_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mechanism.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../base/text.cpp)
target_include_directories(phiq_sdf PRIVATE ${CMAKE_CURRENT_LIST_DIR}/.. ${CMAKE_CURRENT_LIST_DIR}/../../include
  ${CMAKE_CURRENT_BINARY_DIR}/include)
target_compile_features(phiq_sdf PRIVATE cxx_std_20)
target_compile_options(phiq_sdf PRIVATE -Wall -Wextra)
target_link_libraries(phiq_sdf PRIVATE Eigen3::Eigen sdformat12::sdformat12
  PkgConfig::URDFDOM PkgConfig::TINYXML2)  # console_bridge (urdfdom's), tinyxml2 (the XML checked first)
set_target_properties(phiq_sdf PROPERTIES CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
  UNITY_BUILD OFF)
add_dependencies(phiq_engine phiq_sdf)  # whatever links the engine can read SDF files from the build tree
if(PHIQ_SANITIZE)
  # a reader the tests pass through briefly, unoptimised as the engine's other readers are there (engine/CMakeLists.txt)
  target_compile_options(phiq_sdf PRIVATE -O0)
endif()
