list(APPEND FCM_SOURCES lib/src/fem/space.c lib/src/fem/numbering.c lib/src/fem/topology.c
     lib/src/fem/assemble.c lib/src/fem/locate.c lib/src/fem/surface.c)
list(APPEND FCM_SOURCES lib/src/fem/blocks.c lib/src/fem/fields.c lib/src/fem/eval.c
     lib/src/fem/motion.c)
