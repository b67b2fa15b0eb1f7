# Compiled into the PETSc component libfcm_petsc (CMakeLists.txt), not into libfcm.
list(APPEND FCM_PETSC_SOURCES lib/src/petsc/petsc_init.c lib/src/petsc/petsc_partition.c
     lib/src/petsc/petsc_numbering.c lib/src/petsc/petsc_linear.c lib/src/petsc/petsc_newton.c
     lib/src/petsc/petsc_output.c lib/src/petsc/pcmg.c)
