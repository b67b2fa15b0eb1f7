# sizes: large enough that the factor has stopped growing where the test compares them
fcm_add_test(mg_convergence_cube tests/mg/convergence.c ARGS cube 4 8 16)
fcm_add_test(mg_convergence_hemisphere tests/mg/convergence.c ARGS hemisphere 8 16 24)
fcm_add_test(mg_convergence_cut tests/mg/convergence.c ARGS cut 4 8 16)
fcm_add_test(mg_convergence_split tests/mg/convergence.c ARGS split 4 8 16)
fcm_add_test(mg_convergence_cube_hex20 tests/mg/convergence.c ARGS cube-hex20 4 8)
fcm_add_test(mg_convergence_hemisphere_hex20 tests/mg/convergence.c ARGS hemisphere-hex20 8 12)
fcm_add_test(mg_convergence_cut_hex20 tests/mg/convergence.c ARGS cut-hex20 8)
fcm_add_test(mg_convergence_hemisphere_hex20_long tests/mg/convergence.c
             ARGS hemisphere-hex20 8 16 24 LABELS slow TIMEOUT 1800)
fcm_add_test(mg_bodies tests/mg/bodies.c)
fcm_add_test(mg_threads tests/mg/threads.c)
fcm_add_test(mg_alloc_failure tests/mg/alloc_failure.c)
fcm_add_test(mg_bench tests/mg/bench.c ARGS cube 8 16 LABELS bench)
