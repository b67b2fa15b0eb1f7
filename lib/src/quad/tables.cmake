# The stored rule tables are compiled into the library (it never reads files at run
# time): quadrature_tables/<shape>/<shape>_<mm>.txt -> one generated C source.
file(GLOB FCM_QUAD_TABLE_FILES CONFIGURE_DEPENDS
     ${PROJECT_SOURCE_DIR}/quadrature_tables/*/*.txt)
set(FCM_QUAD_TABLE_SOURCE ${PROJECT_BINARY_DIR}/generated/quad_tables_data.c)
add_custom_command(
  OUTPUT ${FCM_QUAD_TABLE_SOURCE}
  COMMAND ${CMAKE_COMMAND} -DTABLE_DIR=${PROJECT_SOURCE_DIR}/quadrature_tables
          -DOUTPUT=${FCM_QUAD_TABLE_SOURCE} -P ${PROJECT_SOURCE_DIR}/lib/cmake/embed_tables.cmake
  DEPENDS ${FCM_QUAD_TABLE_FILES} ${PROJECT_SOURCE_DIR}/lib/cmake/embed_tables.cmake
  COMMENT "Embedding quadrature tables"
  VERBATIM)
list(APPEND FCM_SOURCES ${FCM_QUAD_TABLE_SOURCE})
