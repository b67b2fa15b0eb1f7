list(APPEND FCM_SOURCES lib/src/la/lapack.c)
