list(APPEND FCM_SOURCES lib/src/mg/mg.c)
