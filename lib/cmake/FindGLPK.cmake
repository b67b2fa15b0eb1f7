# FindGLPK: the GNU Linear Programming Kit (Debian: libglpk-dev).
# Defines the imported target GLPK::GLPK; hints: GLPK_INCLUDE_DIR, GLPK_LIBRARY.
include(${CMAKE_CURRENT_LIST_DIR}/fcm_find_helpers.cmake)
fcm_import_library(TARGET GLPK::GLPK VAR GLPK HEADER glpk.h NAMES glpk)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(GLPK REQUIRED_VARS GLPK_FOUND)
