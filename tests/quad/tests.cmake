# Standard quadrature: 1-D Gauss–Jacobi, tensor and collapsed rules, catalogue,
# user rules, error paths and allocation failure.
fcm_add_test(quad_gauss_jacobi tests/quad/gauss_jacobi.c)
fcm_add_test(quad_monomials tests/quad/monomials.c)
fcm_add_test(quad_high_strength tests/quad/high_strength.c)
fcm_add_test(quad_user_rule tests/quad/user_rule.c)
fcm_add_test(quad_errors tests/quad/errors.c)
fcm_add_test(quad_alloc_failure tests/quad/alloc_failure.c)
