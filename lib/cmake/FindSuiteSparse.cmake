# FindSuiteSparse: the SuiteSparse libraries fcm uses (Debian 12: libsuitesparse-dev 5.12,
# which ships no CMake package). Components: CHOLMOD UMFPACK AMD COLAMD SuiteSparse_config
# (default: all). Defines the imported targets SuiteSparse::<component> (the names the
# SuiteSparse 7 packages use; existing targets are kept); hints: SUITESPARSE_<COMPONENT>_
# INCLUDE_DIR and SUITESPARSE_<COMPONENT>_LIBRARY.
include(${CMAKE_CURRENT_LIST_DIR}/fcm_find_helpers.cmake)
if(NOT SuiteSparse_FIND_COMPONENTS)
  set(SuiteSparse_FIND_COMPONENTS CHOLMOD UMFPACK AMD COLAMD SuiteSparse_config)
endif()
set(_fcm_ss_header_CHOLMOD cholmod.h)
set(_fcm_ss_lib_CHOLMOD cholmod)
set(_fcm_ss_header_UMFPACK umfpack.h)
set(_fcm_ss_lib_UMFPACK umfpack)
set(_fcm_ss_header_AMD amd.h)
set(_fcm_ss_lib_AMD amd)
set(_fcm_ss_header_COLAMD colamd.h)
set(_fcm_ss_lib_COLAMD colamd)
set(_fcm_ss_header_SuiteSparse_config SuiteSparse_config.h)
set(_fcm_ss_lib_SuiteSparse_config suitesparseconfig)
set(_fcm_ss_required "")
set(_fcm_ss_found "")
foreach(c IN LISTS SuiteSparse_FIND_COMPONENTS)
  if(NOT DEFINED _fcm_ss_lib_${c})
    message(FATAL_ERROR "FindSuiteSparse: unknown component '${c}' "
                        "(CHOLMOD, UMFPACK, AMD, COLAMD, SuiteSparse_config)")
  endif()
  string(TOUPPER "SUITESPARSE_${c}" var)
  fcm_import_library(TARGET SuiteSparse::${c} VAR ${var} HEADER ${_fcm_ss_header_${c}}
                     NAMES ${_fcm_ss_lib_${c}} PATH_SUFFIXES suitesparse)
  set(SuiteSparse_${c}_FOUND ${${var}_FOUND})
  list(APPEND _fcm_ss_found ${var}_FOUND)
  if(SuiteSparse_FIND_REQUIRED_${c})
    list(APPEND _fcm_ss_required ${var}_FOUND)
  endif()
endforeach()
if(NOT _fcm_ss_required)
  list(GET _fcm_ss_found 0 _fcm_ss_required) # none required: report the first one
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparse REQUIRED_VARS ${_fcm_ss_required} HANDLE_COMPONENTS)
