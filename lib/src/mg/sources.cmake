list(APPEND FCM_SOURCES lib/src/mg/mg.c lib/src/mg/hierarchy.c lib/src/mg/transfer.c lib/src/mg/octree.c
     lib/src/mg/smoothers.c lib/src/mg/sweeps.c lib/src/mg/cycle.c
     lib/src/mg/update.c lib/src/mg/carry.c)
# the sweeps and the cycle's residuals: per-CPU clones (core/multiversion.h)
if(FCM_MULTIVERSION)
  set_property(SOURCE lib/src/mg/sweeps.c lib/src/mg/cycle.c APPEND PROPERTY COMPILE_DEFINITIONS
                                                                     FCM_MULTIVERSION)
endif()
