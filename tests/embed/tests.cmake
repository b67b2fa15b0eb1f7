# Embedded (cut-cell) quadrature: exactness per cell on random polyhedra (initial and
# simplified rules, Hex8 and Tet4 cells), global volume and moments of procedural shapes,
# degenerate configurations, surface rules, classification and stabilization, thread
# determinism, errors, allocation failures; the throughput benchmark (label bench).
fcm_add_test(embed_exact_hex_initial tests/embed/exactness.c ARGS hex initial)
fcm_add_test(embed_exact_tet_initial tests/embed/exactness.c ARGS tet initial)
fcm_add_test(embed_exact_hex_simplified tests/embed/exactness.c ARGS hex simplified)
fcm_add_test(embed_exact_tet_simplified tests/embed/exactness.c ARGS tet simplified)
fcm_add_test(embed_exact_hex_simplified_full tests/embed/exactness.c ARGS hex simplified-full
             LABELS slow TIMEOUT 3600)
fcm_add_test(embed_exact_tet_simplified_full tests/embed/exactness.c ARGS tet simplified-full
             LABELS slow TIMEOUT 3600)
fcm_add_test(embed_volume tests/embed/volume.c)
fcm_add_test(embed_degenerate tests/embed/degenerate.c)
fcm_add_test(embed_surface tests/embed/surface.c)
fcm_add_test(embed_rules tests/embed/rules.c)
fcm_add_test(embed_errors tests/embed/errors.c)
fcm_add_test(embed_bench tests/embed/bench.c LABELS bench TIMEOUT 3600)
fcm_add_test(embed_limits tests/embed/limits.c)
