# FindGmsh: Gmsh's C API (Debian: libgmsh-dev, GPL-2.0-or-later), header <gmshc.h>, library
# libgmsh. Used by fcm only in lib/src/geom/gmsh_adapter.c (surface tetrahedralization),
# which compiles against the header and loads the library at run time (dlopen).
# Defines the imported target Gmsh::Gmsh; hints: GMSH_INCLUDE_DIR, GMSH_LIBRARY.
include(${CMAKE_CURRENT_LIST_DIR}/fcm_find_helpers.cmake)
fcm_import_library(TARGET Gmsh::Gmsh VAR GMSH HEADER gmshc.h NAMES gmsh)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Gmsh REQUIRED_VARS GMSH_FOUND)
