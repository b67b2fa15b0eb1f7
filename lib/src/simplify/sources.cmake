list(APPEND FCM_SOURCES lib/src/simplify/basis.c lib/src/simplify/glpk_adapter.c
                        lib/src/simplify/lp.c lib/src/simplify/caratheodory.c
                        lib/src/simplify/recombine.c lib/src/simplify/fit.c
                        lib/src/simplify/simplify.c lib/src/simplify/stabilization.c)
