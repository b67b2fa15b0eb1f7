list(APPEND FCM_SOURCES lib/src/quad/gauss.c lib/src/quad/product.c lib/src/quad/rule.c lib/src/quad/tables.c)
list(APPEND FCM_SOURCES lib/src/quad/orthobasis.c lib/src/quad/node_elim.c)
include(lib/src/quad/tables.cmake)
