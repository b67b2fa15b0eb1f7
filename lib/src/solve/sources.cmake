list(APPEND FCM_SOURCES lib/src/solve/krylov.c lib/src/solve/jacobi.c lib/src/solve/schwarz.c
     lib/src/solve/schwarz_positions.c)
# the block smoothers' batched factors (build_batch()): per-CPU clones (core/multiversion.h)
if(FCM_MULTIVERSION)
  set_property(SOURCE lib/src/solve/schwarz.c APPEND PROPERTY COMPILE_DEFINITIONS FCM_MULTIVERSION)
endif()
