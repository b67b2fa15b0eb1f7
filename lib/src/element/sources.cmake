list(APPEND FCM_SOURCES lib/src/element/element.c lib/src/element/tet.c lib/src/element/hex.c
     lib/src/element/inverse.c)
