# FindcJSON: the cJSON parser (Debian: libcjson-dev), header included as <cJSON.h>.
# (cJSON's own package target `cjson` points at the include root above cjson/, so the
# header and library are searched by hand.)
# Defines the imported target cJSON::cJSON; hints: CJSON_INCLUDE_DIR, CJSON_LIBRARY.
include(${CMAKE_CURRENT_LIST_DIR}/fcm_find_helpers.cmake)
fcm_import_library(TARGET cJSON::cJSON VAR CJSON HEADER cJSON.h NAMES cjson PATH_SUFFIXES cjson)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(cJSON REQUIRED_VARS CJSON_FOUND)
