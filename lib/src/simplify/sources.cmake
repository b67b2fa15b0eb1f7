list(APPEND FCM_SOURCES lib/src/simplify/basis.c lib/src/simplify/glpk_adapter.c
                        lib/src/simplify/lp.c lib/src/simplify/caratheodory.c
                        lib/src/simplify/recombine.c lib/src/simplify/fit.c
                        lib/src/simplify/fit_kernels.c
                        lib/src/simplify/simplify.c lib/src/simplify/stabilization.c)
# NNLS's own loops (back substitutions, Givens rotations, batch selection, its matrix-vector
# products): the per-CPU clones
# of FCM_MULTIVERSION (core/multiversion.h).
if(FCM_MULTIVERSION)
  set_property(SOURCE lib/src/simplify/fit.c lib/src/simplify/fit_kernels.c APPEND
               PROPERTY COMPILE_DEFINITIONS FCM_MULTIVERSION)
endif()
