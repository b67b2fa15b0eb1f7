# fcm_import_library(TARGET <ns::name> HEADER <h> NAMES <lib...> [PATH_SUFFIXES ...] [LINK <targets>])
# Find one header and one library by hand (for dependencies that ship no CMake package on
# Debian 12) and wrap them in an UNKNOWN IMPORTED target; a no-op when TARGET exists.
# The cache variables <VAR>_INCLUDE_DIR / <VAR>_LIBRARY (VAR = the target name with "::"
# replaced by "_", upper case) can point at another installation.
include_guard(GLOBAL)

function(fcm_import_library)
  cmake_parse_arguments(A "" "TARGET;HEADER;VAR" "NAMES;PATH_SUFFIXES;LINK" ${ARGN})
  if(TARGET ${A_TARGET})
    set(${A_VAR}_FOUND TRUE PARENT_SCOPE)
    return()
  endif()
  find_path(${A_VAR}_INCLUDE_DIR NAMES ${A_HEADER} PATH_SUFFIXES ${A_PATH_SUFFIXES})
  find_library(${A_VAR}_LIBRARY NAMES ${A_NAMES})
  mark_as_advanced(${A_VAR}_INCLUDE_DIR ${A_VAR}_LIBRARY)
  if(${A_VAR}_INCLUDE_DIR AND ${A_VAR}_LIBRARY)
    add_library(${A_TARGET} UNKNOWN IMPORTED)
    set_target_properties(${A_TARGET} PROPERTIES
      IMPORTED_LOCATION "${${A_VAR}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${${A_VAR}_INCLUDE_DIR}")
    if(A_LINK)
      set_property(TARGET ${A_TARGET} PROPERTY INTERFACE_LINK_LIBRARIES ${A_LINK})
    endif()
    set(${A_VAR}_FOUND TRUE PARENT_SCOPE)
  else()
    set(${A_VAR}_FOUND FALSE PARENT_SCOPE)
  endif()
endfunction()
