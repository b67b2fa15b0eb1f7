# sizes: large enough that the factor has stopped growing where the test compares them
fcm_add_test(mg_convergence_cube tests/mg/convergence.c ARGS cube 4 8 16)
fcm_add_test(mg_convergence_cube_jacobi tests/mg/convergence.c ARGS cube-jacobi 4 8 16)
fcm_add_test(mg_convergence_hemisphere tests/mg/convergence.c ARGS hemisphere 8 16 24)
fcm_add_test(mg_convergence_cut tests/mg/convergence.c ARGS cut 8 16)
fcm_add_test(mg_convergence_split tests/mg/convergence.c ARGS split 8 16)
fcm_add_test(mg_convergence_hollow tests/mg/convergence.c ARGS hollow 8 16 32)
fcm_add_test(mg_convergence_cube_hex20 tests/mg/convergence.c ARGS cube-hex20 4 8)
fcm_add_test(mg_convergence_hemisphere_hex20 tests/mg/convergence.c ARGS hemisphere-hex20 8 12)
fcm_add_test(mg_convergence_cut_hex20 tests/mg/convergence.c ARGS cut-hex20 8)
fcm_add_test(mg_convergence_hemisphere_hex20_long tests/mg/convergence.c
             ARGS hemisphere-hex20 8 16 24 LABELS slow TIMEOUT 1800)
fcm_add_test(mg_bodies tests/mg/bodies.c)
fcm_add_test(mg_threads tests/mg/threads.c)
fcm_add_test(mg_setup_values tests/mg/setup_values.c)
fcm_add_test(mg_update_cut tests/mg/update_cut.c)
# a hierarchy created on the pattern (a cut's) and set up with the values equals fcm_mg_create()
fcm_add_test(mg_prepare tests/mg/prepare.c)
fcm_add_test(mg_prepare_cut tests/mg/prepare_cut.c)
# carried over a cut: the Galerkin plans' rows the cut left taken from the hierarchy before it
fcm_add_test(mg_carry_cut tests/mg/carry_cut.c)
fcm_add_test(mg_carry_bench tests/mg/carry_bench.c ARGS 32 5 LABELS bench)
fcm_add_test(mg_update_bench tests/mg/update_bench.c ARGS 32 5 LABELS bench)
fcm_add_test(mg_slabs tests/mg/slabs.c)
fcm_add_test(mg_alloc_failure tests/mg/alloc_failure.c)
fcm_add_test(mg_bench tests/mg/bench.c ARGS cube 8 16 LABELS bench)
fcm_add_test(mg_octree_hex8 tests/mg/octree.c ARGS hex8 1 2 3)
fcm_add_test(mg_octree_hex20 tests/mg/octree.c ARGS hex20 1 2)
fcm_add_test(mg_octree_balls tests/mg/octree.c ARGS balls 2 3)
fcm_add_test(mg_octree_cut_hex8 tests/mg/octree.c ARGS cut_hex8 1 2)
fcm_add_test(mg_octree_cut_hex20 tests/mg/octree.c ARGS cut_hex20 1 2)
# depth 3 (178,572 DOFs, 3.7 GB, 80-130 s CPU) with the W-cycle, whose count stays within 1.5x
# of depth 1 there (the V-cycle's is 1.57x: lib/docs/octree.md)
fcm_add_test(mg_octree_cut_hex20_deep tests/mg/octree.c ARGS cut_hex20 1 3 LABELS slow
             TIMEOUT 1800)
set_tests_properties(mg_octree_cut_hex20_deep PROPERTIES ENVIRONMENT FCM_TEST_MG_CYCLE=2)
# the one-way block sweeps, and with the vertex blocks alone (the cheapest block set)
fcm_add_test(mg_convergence_cut_oneway tests/mg/convergence.c ARGS cut 8 16)
set_tests_properties(mg_convergence_cut_oneway PROPERTIES ENVIRONMENT FCM_TEST_MG_BLOCK_SWEEP=1)
# the one-way block and pointwise sweeps (Dick's interactive set)
fcm_add_test(mg_convergence_cut_pointway tests/mg/convergence.c ARGS cut 8 16)
set_tests_properties(mg_convergence_cut_pointway PROPERTIES
                     ENVIRONMENT "FCM_TEST_MG_BLOCK_SWEEP=1;FCM_TEST_MG_POINT_SWEEP=1")
fcm_add_test(mg_convergence_cut_vertex_oneway tests/mg/convergence.c ARGS cut 8 16)
set_tests_properties(mg_convergence_cut_vertex_oneway PROPERTIES
                     ENVIRONMENT "FCM_TEST_MG_BLOCKS=1;FCM_TEST_MG_BLOCK_SWEEP=1")
# the finest level's blocks only at cells with a small piece (Dick's interactive set's 0.5)
fcm_add_test(mg_convergence_cut_fraction tests/mg/convergence.c ARGS cut 8 16)
set_tests_properties(mg_convergence_cut_fraction PROPERTIES
                     ENVIRONMENT
                     "FCM_TEST_MG_BLOCKS=2;FCM_TEST_MG_BLOCK_SWEEP=1;FCM_TEST_MG_POINT_SWEEP=1;FCM_TEST_MG_BLOCK_FRACTION=0.5")
fcm_add_test(mg_block_fraction tests/mg/block_fraction.c)
fcm_add_test(mg_smooth_paths tests/mg/smooth_paths.c)
fcm_add_test(mg_block_apply tests/mg/block_apply.c)
# the coarser levels' values every coarse_interval-th set-up, then those of a fresh hierarchy
fcm_add_test(mg_coarse_interval tests/mg/coarse_interval.c)
# level 0's residual three rows at a time against fcm_csr_apply(), bit for bit
fcm_add_test(mg_residual_paths tests/mg/residual_paths.c)
# two threads' pointwise sweeps with slab 0's lead beside the thin slab, against one thread
fcm_add_test(mg_row_split tests/mg/row_split.c)
