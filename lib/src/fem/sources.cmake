list(APPEND FCM_SOURCES lib/src/fem/space.c lib/src/fem/numbering.c lib/src/fem/topology.c
     lib/src/fem/visit.c
     lib/src/fem/assemble.c lib/src/fem/assemble_once.c lib/src/fem/corot_store.c lib/src/fem/locate.c lib/src/fem/surface.c
     lib/src/fem/surface_split.c)
list(APPEND FCM_SOURCES lib/src/fem/blocks.c lib/src/fem/fields.c lib/src/fem/eval.c
     lib/src/fem/motion.c lib/src/fem/cut_update.c lib/src/fem/hanging.c
     lib/src/fem/indicator.c lib/src/fem/refine_transfer.c)
list(APPEND FCM_SOURCES lib/src/fem/kernels.c lib/src/fem/corot.c)
# The element kernels: fused multiply-adds where the instruction set has them (ISO C mode
# turns GCC's contraction off), and the per-CPU clones of FCM_MULTIVERSION.
if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
  set_property(SOURCE lib/src/fem/kernels.c APPEND PROPERTY COMPILE_OPTIONS -ffp-contract=fast)
endif()
if(FCM_MULTIVERSION)
  set_property(SOURCE lib/src/fem/kernels.c APPEND PROPERTY COMPILE_DEFINITIONS FCM_MULTIVERSION)
endif()
