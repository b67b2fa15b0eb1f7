fcm_add_test(bench_fem tests/bench/bench_fem.c LABELS bench TIMEOUT 1800)
fcm_add_test(bench_newton_step tests/bench/bench_newton_step.c LABELS bench TIMEOUT 3600)
# Shared cores: MINRES + Schwarz alone and beside 3 busy loops per core; the
# slowdown with the programs' passive waiting and with libgomp's default spinning.
add_test(NAME bench_shared_cores COMMAND bench_newton_step shared)
add_test(NAME bench_shared_cores_spin COMMAND bench_newton_step shared)
set_tests_properties(bench_shared_cores bench_shared_cores_spin PROPERTIES LABELS bench
                     TIMEOUT 3600 RUN_SERIAL TRUE)
set_tests_properties(bench_shared_cores PROPERTIES ENVIRONMENT "OMP_WAIT_POLICY=passive")
set_tests_properties(bench_shared_cores_spin PROPERTIES ENVIRONMENT "GOMP_SPINCOUNT=300000")
# Peak bytes of the level-set build per triangulated sub-cell (FCM_LEVEL_SET_SUBCELL_BYTES,
# the default max_subcells): spheres and gyroids at refinements 1-32.
fcm_add_test(bench_level_set_memory tests/bench/bench_level_set_memory.c LABELS bench TIMEOUT 600)
# Shared cores, multigrid: CG + multigrid and MINRES + Schwarz steps on the hollow ball alone
# and beside 8 busy processes; the slowdown of each (figures in lib/docs/multigrid_threads.md).
fcm_add_test(bench_mg_shared tests/bench/bench_mg_shared.c LABELS bench TIMEOUT 3600)
set_tests_properties(bench_mg_shared PROPERTIES RUN_SERIAL TRUE)
# The solver benchmarks select the CPU's OpenBLAS kernels as the programs do (apps/app_env.h).
foreach(b bench_newton_step bench_mg_shared)
  target_sources(${b} PRIVATE ${PROJECT_SOURCE_DIR}/apps/app_env.c)
endforeach()
# The core's peaks (one-thread DGEMM, STREAM triad) and a CHOLMOD factorization of 3D elasticity,
# each with OpenBLAS's fallback kernels (Prescott) and the ones selected for the CPU: time, rate,
# fraction of the peak, a CSV (figures in lib/docs/performance.md).
fcm_add_test(bench_roofline tests/bench/bench_roofline.c LABELS bench TIMEOUT 1800
             ARGS ${PROJECT_BINARY_DIR}/bench_roofline.csv)
set_tests_properties(bench_roofline PROPERTIES RUN_SERIAL TRUE)
target_sources(bench_roofline PRIVATE ${PROJECT_SOURCE_DIR}/tests/bench/roofline_peaks.c
                                      ${PROJECT_SOURCE_DIR}/tests/bench/roofline_kernels.c
                                      ${PROJECT_SOURCE_DIR}/tests/bench/roofline_simplify.c)
# The space and integrator part of a cut, with and without what the cut keeps (cut_reuse), on a
# Hex8 grid around a ball of about 5k and 20k active cells (figures in lib/docs/cutting.md).
fcm_add_test(bench_cut_update tests/bench/bench_cut_update.c LABELS bench TIMEOUT 1800)
set_tests_properties(bench_cut_update PROPERTIES RUN_SERIAL TRUE)
# What a cut in the deformed frame adds (fcm_simulation_rest_positions(), the cut in either
# frame) on Dick's Bunny 3 row (figures in lib/docs/cutting.md).
fcm_add_test(bench_cut_frame tests/bench/bench_cut_frame.c LABELS bench TIMEOUT 1800
             ARGS ${PROJECT_SOURCE_DIR}/apps/scenes/models/cutbench_body.obj)
set_tests_properties(bench_cut_frame PROPERTIES RUN_SERIAL TRUE)
# Octree backgrounds refined along a sphere and the cutbench body against uniform grids of the
# same finest cell size: cells, crossed and active cells (figures in lib/docs/octree.md).
fcm_add_test(bench_octree_cells tests/bench/bench_octree_cells.c LABELS bench TIMEOUT 1800
             ARGS ${PROJECT_SOURCE_DIR}/apps/scenes/models/cutbench_body.obj)
# Convergence toward a corner singularity: octrees grown by the stress-jump indicator against
# uniform grids, the DOFs at equal error (figures in lib/docs/octree.md).
fcm_add_test(bench_octree_converge tests/bench/bench_octree_converge.c LABELS bench TIMEOUT 1800)
# The 3x3 SVD of the corotated model: ns per call against the reference Jacobi with three dot
# products a pair, paired in the same run (figures in lib/docs/cutting.md).
fcm_add_test(bench_mat3_svd tests/bench/bench_mat3_svd.c LABELS bench TIMEOUT 600)
# Convergence toward a crack front (a cut ending inside the body, the exact Williams field):
# uniform grids against octrees refined by the stress jumps and toward the front, Hex8 and Hex20
# (tables in lib/docs/octree.md).
fcm_add_test(bench_octree_cuttip tests/bench/bench_octree_cuttip.c ARGS hex8 LABELS bench TIMEOUT 3600)
fcm_add_test(bench_octree_cuttip_hex20 tests/bench/bench_octree_cuttip.c ARGS hex20 LABELS bench TIMEOUT 3600)
