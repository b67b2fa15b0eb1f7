# FindOpenBLAS: OpenBLAS with its CBLAS header (Debian: libopenblas-dev).
# Defines the imported target OpenBLAS::OpenBLAS; hints: OPENBLAS_INCLUDE_DIR, OPENBLAS_LIBRARY.
include(${CMAKE_CURRENT_LIST_DIR}/fcm_find_helpers.cmake)
fcm_import_library(TARGET OpenBLAS::OpenBLAS VAR OPENBLAS HEADER cblas.h NAMES openblas
                   PATH_SUFFIXES openblas)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(OpenBLAS REQUIRED_VARS OPENBLAS_FOUND)
