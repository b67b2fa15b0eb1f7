fcm_add_test(bench_fem tests/bench/bench_fem.c LABELS bench TIMEOUT 1800)
