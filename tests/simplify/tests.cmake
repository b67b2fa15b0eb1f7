# Quadrature simplification (every path), its fallback, errors, allocation failures and
# threads; stabilization points; the benchmark (label bench, not in the default run).
fcm_add_test(simplify_rules_lp tests/simplify/rules.c ARGS lp)
fcm_add_test(simplify_rules_recombine tests/simplify/rules.c ARGS recombine)
fcm_add_test(simplify_rules_eliminate tests/simplify/rules.c ARGS eliminate)
fcm_add_test(simplify_special tests/simplify/special.c)
fcm_add_test(simplify_fallback tests/simplify/fallback.c)
fcm_add_test(simplify_errors tests/simplify/errors.c)
fcm_add_test(simplify_alloc_failure tests/simplify/alloc_failure.c)
fcm_add_test(simplify_threads tests/simplify/threads.c)
fcm_add_test(simplify_stabilization tests/simplify/stabilization.c)
fcm_add_test(simplify_bench tests/simplify/bench_simplify.c LABELS bench TIMEOUT 1800)
fcm_add_test(simplify_names tests/simplify/names.c)
