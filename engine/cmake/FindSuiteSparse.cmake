# FindSuiteSparse: SuiteSparse 5.x as Debian 12 ships it (libsuitesparse-dev), which has no CMake config.
#
#   find_package(SuiteSparse REQUIRED COMPONENTS UMFPACK CHOLMOD KLU SPQR)
#
# Defines an imported target SuiteSparse::<COMP> per component (with its dependencies: AMD, COLAMD, BTF,
# SuiteSparse_config) and SuiteSparse_VERSION from SuiteSparse_config.h. A missing header or library fails
# with a message naming it and the Debian package that provides it.

find_path(SuiteSparse_INCLUDE_DIR SuiteSparse_config.h PATH_SUFFIXES suitesparse)

if(SuiteSparse_INCLUDE_DIR AND EXISTS "${SuiteSparse_INCLUDE_DIR}/SuiteSparse_config.h")
  file(STRINGS "${SuiteSparse_INCLUDE_DIR}/SuiteSparse_config.h" _ss_ver REGEX "#define SUITESPARSE_(MAIN|SUB|SUBSUB)_VERSION")
  string(REGEX REPLACE ".*MAIN_VERSION ([0-9]+).*" "\\1" _ss_major "${_ss_ver}")
  string(REGEX REPLACE ".*SUB_VERSION ([0-9]+).*SUBSUB.*" "\\1" _ss_minor "${_ss_ver}")
  string(REGEX REPLACE ".*SUBSUB_VERSION ([0-9]+).*" "\\1" _ss_patch "${_ss_ver}")
  set(SuiteSparse_VERSION "${_ss_major}.${_ss_minor}.${_ss_patch}")
endif()

# name -> header and library
set(_ss_config_header SuiteSparse_config.h)
set(_ss_config_lib suitesparseconfig)
set(_ss_AMD_header amd.h)
set(_ss_AMD_lib amd)
set(_ss_COLAMD_header colamd.h)
set(_ss_COLAMD_lib colamd)
set(_ss_CAMD_header camd.h)
set(_ss_CAMD_lib camd)
set(_ss_CCOLAMD_header ccolamd.h)
set(_ss_CCOLAMD_lib ccolamd)
set(_ss_BTF_header btf.h)
set(_ss_BTF_lib btf)
set(_ss_CHOLMOD_header cholmod.h)
set(_ss_CHOLMOD_lib cholmod)
set(_ss_UMFPACK_header umfpack.h)
set(_ss_UMFPACK_lib umfpack)
set(_ss_KLU_header klu.h)
set(_ss_KLU_lib klu)
set(_ss_SPQR_header SuiteSparseQR.hpp)
set(_ss_SPQR_lib spqr)
# component -> components it links against
set(_ss_AMD_deps config)
set(_ss_COLAMD_deps config)
set(_ss_CAMD_deps config)
set(_ss_CCOLAMD_deps config)
set(_ss_BTF_deps config)
set(_ss_CHOLMOD_deps AMD COLAMD CAMD CCOLAMD config)
set(_ss_UMFPACK_deps CHOLMOD AMD config)
set(_ss_KLU_deps AMD COLAMD BTF config)
set(_ss_SPQR_deps CHOLMOD config)

set(_ss_missing "")
function(_ss_add comp)
  if(TARGET SuiteSparse::${comp})
    return()
  endif()
  find_library(SuiteSparse_${comp}_LIBRARY NAMES ${_ss_${comp}_lib})
  if(NOT SuiteSparse_${comp}_LIBRARY OR NOT EXISTS "${SuiteSparse_INCLUDE_DIR}/${_ss_${comp}_header}")
    set(_ss_missing "${_ss_missing} ${comp}(${_ss_${comp}_header}, lib${_ss_${comp}_lib})" PARENT_SCOPE)
    return()
  endif()
  add_library(SuiteSparse::${comp} UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::${comp} PROPERTIES
    IMPORTED_LOCATION "${SuiteSparse_${comp}_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${SuiteSparse_INCLUDE_DIR}")
  foreach(dep IN LISTS _ss_${comp}_deps)
    _ss_add(${dep})
    set(_ss_missing "${_ss_missing}" PARENT_SCOPE)
    if(TARGET SuiteSparse::${dep})
      set_property(TARGET SuiteSparse::${comp} APPEND PROPERTY INTERFACE_LINK_LIBRARIES SuiteSparse::${dep})
    endif()
  endforeach()
endfunction()

if(SuiteSparse_INCLUDE_DIR)
  foreach(comp IN LISTS SuiteSparse_FIND_COMPONENTS)
    _ss_add(${comp})
  endforeach()
  foreach(comp IN LISTS SuiteSparse_FIND_COMPONENTS)
    if(TARGET SuiteSparse::${comp})
      set(SuiteSparse_${comp}_FOUND TRUE)
    endif()
  endforeach()
endif()

include(FindPackageHandleStandardArgs)
if(_ss_missing)
  set(_ss_reason "missing:${_ss_missing}. Install Debian's libsuitesparse-dev (tools/install_deps.sh does).")
elseif(NOT SuiteSparse_INCLUDE_DIR)
  set(_ss_reason "SuiteSparse_config.h not found. Install Debian's libsuitesparse-dev (tools/install_deps.sh does).")
endif()
find_package_handle_standard_args(SuiteSparse
  REQUIRED_VARS SuiteSparse_INCLUDE_DIR
  VERSION_VAR SuiteSparse_VERSION
  HANDLE_COMPONENTS
  REASON_FAILURE_MESSAGE "${_ss_reason}")
mark_as_advanced(SuiteSparse_INCLUDE_DIR)
