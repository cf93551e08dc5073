# engine/src/output/: the sources of this stage (engine/CMakeLists.txt includes this file).
target_sources(phiq_engine PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/csv_compare.cpp
  ${CMAKE_CURRENT_LIST_DIR}/csv_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/hdf5_handle.cpp
  ${CMAKE_CURRENT_LIST_DIR}/hdf5_reader.cpp
  ${CMAKE_CURRENT_LIST_DIR}/hdf5_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mechanism_sketch.cpp
  ${CMAKE_CURRENT_LIST_DIR}/derived_geometry.cpp
  ${CMAKE_CURRENT_LIST_DIR}/drawn_parts.cpp
  ${CMAKE_CURRENT_LIST_DIR}/output_joints.cpp
  ${CMAKE_CURRENT_LIST_DIR}/output_plan.cpp
  ${CMAKE_CURRENT_LIST_DIR}/output_points.cpp
)
