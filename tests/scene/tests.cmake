# Scene files: the example scenes and the built-in default parse and validate; a table of
# bad inputs (each error class, with status and JSON path); full-key parsing and the
# motion/velocity formulas; allocation-failure torture.
fcm_add_test(scene_parse tests/scene/parse.c)
fcm_add_test(scene_errors tests/scene/errors.c)
# The solver and quadrature sections start from the library's option defaults (no drift).
fcm_add_test(scene_defaults tests/scene/defaults.c)
fcm_add_test(scene_alloc tests/scene/alloc.c)
fcm_add_test(scene_default tests/scene/default.c
             ARGS ${PROJECT_SOURCE_DIR}/apps/scenes/twisting_cylinder.json)
# What the README says the built-in scene shows, on its whole run (about 20 s).
fcm_add_test(scene_default_claim tests/scene/default_claim.c TIMEOUT 1500)
fcm_add_test(scene_examples tests/scene/examples.c ARGS ${PROJECT_SOURCE_DIR}/apps/scenes)
# The scene runner: counters of what a scene computes and skips, frames, log, errors.
fcm_add_test(scene_run_counters tests/scene/run_counters.c)
# The time loop fcm_simulation_run(): the steps taken by hand, the monitor's events and its
# stop, a run continued and a finished one.
fcm_add_test(scene_run_loop tests/scene/run_loop.c)
# Checkpoints: a restored run continues bit for bit (static, dynamic, free body); errors.
fcm_add_test(scene_checkpoint tests/scene/checkpoint.c)
# Allocation failures in the runner: create, step, frames, log, checkpoints, centre of mass,
# summary, scene files and the built-in scene: FCM_ERR_ALLOC, no leak, no partial file.
# The quick set (a directly solved embedded body, a free body) by default; with MINRES and
# Schwarz and a static scene too under the label slow.
fcm_add_test(scene_alloc_simulation tests/scene/alloc_simulation.c TIMEOUT 900)
add_test(NAME scene_alloc_simulation_full COMMAND scene_alloc_simulation full)
set_tests_properties(scene_alloc_simulation_full PROPERTIES LABELS slow TIMEOUT 3600
                     ENVIRONMENT "OMP_NUM_THREADS=1;OMP_WAIT_POLICY=passive;OPENBLAS_NUM_THREADS=1")
# quadrature.simplify "auto": parsing, and the choice per rule kind in the run summary.
fcm_add_test(scene_simplify_auto tests/scene/simplify_auto.c)
# The geometry keys "voxels" and "level_set": parsed trees and options, errors with their
# JSON paths, scenes that build with the embedded volume of the geometry.
fcm_add_test(scene_geometry_keys tests/scene/geometry_keys.c)
# geometry.surface and background.fit_background: parse errors of the new keys; a binary STL
# cube and an open OBJ cube (refused, then closed with fill_holes) built on a fitted grid.
fcm_add_test(scene_surface tests/scene/surface_scene.c)
# fcm_simulation_write_preview() and the region check before the set-up: the coarse cell classes
# (exact on axis-aligned faces, conservative on a ball against the rules), a region on inactive
# nodes refused before the cell rules, the preview files counted by hand on a box grid.
fcm_add_test(scene_preview tests/scene/preview_scene.c)
# The cut effect: bodies and mass in the log across cuts, cuts at t = 0, no-op cuts, errors.
fcm_add_test(scene_cut tests/scene/cut_scene.c)
# fcm_simulation_cut(): the reference frame the same bits as the cut effect, the deformed
# frame carried back through an affine motion, misses, refusals, allocation failures.
fcm_add_test(scene_cut_api tests/scene/cut_api.c)
# Only the rule kinds a scene calls for: a static scene builds no mass rules (statistics,
# counter, summary line "rules built"), a dynamic one does; the log's mass agrees.
fcm_add_test(scene_rule_kinds tests/scene/rule_kinds.c)
# Output for the engineer: the log's reaction columns (minus the weight and its moment in
# equilibrium; change of momentum minus the weight in dynamics), stress arrays in the frames,
# the surface at reference positions, the summary's max |u| over the body.
fcm_add_test(scene_output tests/scene/output_scene.c)
# Fixed and motion on the embedded boundary (Nitsche) through the scene runner.
fcm_add_test(scene_boundary tests/scene/boundary_scene.c)
# The multigrid in scene runs (CG+MG, MINRES+MG, MG alone) agrees with the direct
# solver on static (clamped, Nitsche) and dynamic Hex8 embedded bodies and across an XFEM cut;
# CG+MG needs at most a fifth of CG+Jacobi's iterations; bad options are refused, named.
foreach(mode agree cut iterations errors)
  fcm_add_test(scene_multigrid_${mode} tests/scene/multigrid_scene.c ARGS ${mode} TIMEOUT 600)
endforeach()
# Inverted quadrature points through the runner: counters from the steps, each frame's NaN
# stresses equal to those its files hold, a checkpoint keeps them; "stop" refuses the first
# inverted step (FCM_ERR_GEOMETRY naming step, time, count and cell).
fcm_add_test(scene_inversion tests/scene/inversion_scene.c)
# The set-up's phases (fcm_simulation_options.setup_phase) for surface, Gmsh, level-set, cut,
# voxel and plain scenes: each once, in order, start before end, the times in the counters
# within their parts and the set-up; progress and warnings inside the phase that makes them.
fcm_add_test(scene_setup_phases tests/scene/setup_phases.c)
# Boundary in dropped cells: the counters, the rules' phase words and the summary line with a
# traction on a sliver face; none of it when nothing is dropped.
fcm_add_test(scene_dropped_boundary tests/scene/dropped_boundary.c)
# The background key "octree": parse, round trip, refusals, a step on the refined grid.
fcm_add_test(scene_octree tests/scene/octree_scene.c)
# The contact effect: apps/scenes/ball_on_floor.json round-trips through the normalized JSON,
# never gets below its floor and comes to rest on it with the reaction m g; bad keys and a
# scene without a geometry are refused, named.
fcm_add_test(scene_contact tests/scene/contact_scene.c ARGS ${PROJECT_SOURCE_DIR}/apps/scenes)
