# Quadrature simplification (every path), its fallback, errors, allocation failures and
# threads; stabilization points; NNLS and the moment fit; the benchmark (label bench, not in
# the default run).
# The default path up to strength 10; the GLPK reference paths up to 7 (10 under slow).
fcm_add_test(simplify_rules_eliminate tests/simplify/rules.c ARGS eliminate)
# The elimination one direction at a time (rank-1 updates) and in blocks of 3 (a flush every
# few pivots, a partial block at the end).
fcm_add_test(simplify_rules_eliminate_rank1 tests/simplify/rules.c ARGS eliminate 8 1)
fcm_add_test(simplify_rules_eliminate_block3 tests/simplify/rules.c ARGS eliminate 8 3)
fcm_add_test(simplify_rules_lp tests/simplify/rules.c ARGS lp 7)
fcm_add_test(simplify_rules_recombine tests/simplify/rules.c ARGS recombine 7)
fcm_add_test(simplify_rules_lp_full tests/simplify/rules.c ARGS lp 10 LABELS slow TIMEOUT 1800)
fcm_add_test(simplify_rules_recombine_full tests/simplify/rules.c ARGS recombine 10 LABELS slow
             TIMEOUT 1800)
fcm_add_test(simplify_special tests/simplify/special.c)
fcm_add_test(simplify_fallback tests/simplify/fallback.c)
fcm_add_test(simplify_errors tests/simplify/errors.c)
fcm_add_test(simplify_alloc_failure tests/simplify/alloc_failure.c)
fcm_add_test(simplify_threads tests/simplify/threads.c)
fcm_add_test(simplify_stabilization tests/simplify/stabilization.c)
fcm_add_test(simplify_bench tests/simplify/bench_simplify.c LABELS bench TIMEOUT 1800)
fcm_add_test(simplify_names tests/simplify/names.c)
fcm_add_test(simplify_nnls tests/simplify/nnls.c)
# The moment space capped per variable (axis_degree; Q_2 = total degree 6, each variable 2):
# its size, basis values and rows, blocked moments, and simplification keeping Q_2's moments.
fcm_add_test(simplify_axis_degree tests/simplify/axis_degree.c)
