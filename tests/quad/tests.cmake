# Standard quadrature: 1-D Gauss–Jacobi, tensor and collapsed rules, catalogue,
# user rules, error paths and allocation failure.
fcm_add_test(quad_gauss_jacobi tests/quad/gauss_jacobi.c)
fcm_add_test(quad_monomials tests/quad/monomials.c)
fcm_add_test(quad_high_strength tests/quad/high_strength.c)
fcm_add_test(quad_high_strength_full tests/quad/high_strength.c ARGS --full LABELS slow)
fcm_add_test(quad_user_rule tests/quad/user_rule.c)
fcm_add_test(quad_errors tests/quad/errors.c)
fcm_add_test(quad_alloc_failure tests/quad/alloc_failure.c)
# Node elimination (rule generation) and the stored tables of quadrature_tables/.
fcm_add_test(quad_node_elim tests/quad/node_elim.c)
fcm_add_test(quad_tables_verify tests/quad/tables_verify.c ARGS ${PROJECT_SOURCE_DIR}/quadrature_tables)
