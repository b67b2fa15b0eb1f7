list(APPEND FCM_SOURCES lib/src/petsc/petsc.c lib/src/petsc/pcmg.c)
