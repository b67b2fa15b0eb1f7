list(APPEND FCM_SOURCES lib/src/core/alloc_large.c lib/src/core/ctx.c lib/src/core/file.c lib/src/core/timer.c lib/src/core/version.c)
