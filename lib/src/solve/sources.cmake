list(APPEND FCM_SOURCES lib/src/solve/krylov.c lib/src/solve/jacobi.c lib/src/solve/schwarz.c)
