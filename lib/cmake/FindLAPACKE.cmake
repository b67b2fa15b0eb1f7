# FindLAPACKE: the C interface to LAPACK (Debian: liblapacke-dev).
# Defines the imported target LAPACKE::LAPACKE; hints: LAPACKE_INCLUDE_DIR, LAPACKE_LIBRARY.
include(${CMAKE_CURRENT_LIST_DIR}/fcm_find_helpers.cmake)
fcm_import_library(TARGET LAPACKE::LAPACKE VAR LAPACKE HEADER lapacke.h NAMES lapacke
                   PATH_SUFFIXES openblas)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LAPACKE REQUIRED_VARS LAPACKE_FOUND)
