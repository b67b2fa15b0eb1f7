fcm_add_test(solve_cg_laplace tests/solve/cg_laplace.c)
fcm_add_test(solve_minres_indefinite tests/solve/minres_indefinite.c)
fcm_add_test(solve_krylov_errors tests/solve/krylov_errors.c)
fcm_add_test(solve_jacobi tests/solve/jacobi.c)
fcm_add_test(solve_schwarz tests/solve/schwarz.c)
fcm_add_test(solve_schwarz_space tests/solve/schwarz_space.c)
# a setup on a matrix of another pattern: bit for bit a fresh preconditioner
fcm_add_test(solve_schwarz_pattern tests/solve/schwarz_pattern.c)
# the block smoother's blocks factored four at a time: bit for bit one at a time
fcm_add_test(solve_schwarz_batch tests/solve/schwarz_batch.c)
fcm_add_test(solve_alloc_failure tests/solve/alloc_failure.c)
fcm_add_test(solve_threads tests/solve/threads.c)
# CG and MINRES stop as stagnated on a singular semi-definite system whose right-hand side
# leaves the range, and converge on a consistent one.
fcm_add_test(solve_stagnation tests/solve/stagnation.c)
