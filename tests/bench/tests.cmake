fcm_add_test(bench_fem tests/bench/bench_fem.c LABELS bench TIMEOUT 1800)
fcm_add_test(bench_newton_step tests/bench/bench_newton_step.c LABELS bench TIMEOUT 3600)
