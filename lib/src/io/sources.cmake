list(APPEND FCM_SOURCES lib/src/io/atomic_file.c lib/src/io/checkpoint_file.c lib/src/io/io_util.c lib/src/io/pvd.c lib/src/io/vtu.c)
