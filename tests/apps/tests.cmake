# Programs end to end (label app): each test gets the program's path and a scratch directory.
# Several tests share one program (fcm_add_test builds one executable per source).
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/app-tests)
set(work ${PROJECT_BINARY_DIR}/app-tests)
# The shared command-line helper apps/cli.c: numbers, lists, option tables, atomic output.
fcm_add_test(app_cli tests/apps/cli.c LABELS app ARGS ${work})
fcm_add_test(app_quadrature tests/apps/quadrature_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-quadrature> ${work})
# fcm-quadrature export: a cut box body's rules file (pieces on one side of the cut, volumes
# exact); bad arguments exit 2 with the reason and leave no file.
fcm_add_test(app_export tests/apps/export_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-quadrature> ${work})
# fcm-rulegen: tables written for the shapes and strengths asked for (positive weights adding
# up to the reference measure); --dry-run and bad options write nothing, bad options exit 2.
fcm_add_test(app_rulegen tests/apps/rulegen_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-rulegen> ${work})
# fcm-sim: a small scene run (frames, PVDs, CSV log, --steps, -o); checkpoints and --resume
# reproduce the uninterrupted run's frames byte for byte; invalid scenes exit non-zero with
# the parser's message and create no output directory.
fcm_add_test(app_sim_run tests/apps/sim_app.c LABELS app ARGS run $<TARGET_FILE:fcm-sim> ${work})
fcm_add_test(app_sim_errors tests/apps/sim_app.c LABELS app
             ARGS errors $<TARGET_FILE:fcm-sim> ${work})
fcm_add_test(app_sim_resume tests/apps/sim_app.c LABELS app
             ARGS resume $<TARGET_FILE:fcm-sim> ${work})
# fcm-sim --plot: the log drawn into <name>_log.png (a PNG of the stated size) through the
# script <name>_log.gp, whose data block has the log's rows; without gnuplot on the PATH the
# run still succeeds, writes the script and says that gnuplot was not found.
fcm_add_test(app_sim_plot tests/apps/sim_plot_app.c LABELS app
             ARGS plot $<TARGET_FILE:fcm-sim> ${work})
fcm_add_test(app_sim_plot_no_gnuplot tests/apps/sim_plot_app.c LABELS app
             ARGS no-gnuplot $<TARGET_FILE:fcm-sim> ${work})
# The README's picture (apps/docs/img/demo.png): its command on 6 steps of the demo's scene
# makes a PNG of the stated size (skipped without gnuplot, after checking the script says so).
add_test(NAME app_demo_picture COMMAND bash ${PROJECT_SOURCE_DIR}/tests/apps/demo_picture.sh
                                       $<TARGET_FILE:fcm-sim> ${PROJECT_SOURCE_DIR} ${work})
set_tests_properties(app_demo_picture PROPERTIES LABELS app TIMEOUT 300 SKIP_RETURN_CODE 77
                     ENVIRONMENT "${FCM_TEST_ENV}")
# The dice pictures (apps/docs/img/dice_landing.png): their command on 3 steps of
# apps/scenes/dice_on_floor.json makes a PNG of the stated size (skipped without gnuplot).
add_test(NAME app_dice_picture COMMAND bash ${PROJECT_SOURCE_DIR}/tests/apps/dice_picture.sh
                                       $<TARGET_FILE:fcm-sim> ${PROJECT_SOURCE_DIR} ${work})
set_tests_properties(app_dice_picture PROPERTIES LABELS app TIMEOUT 300 SKIP_RETURN_CODE 77
                     ENVIRONMENT "${FCM_TEST_ENV}")
# The README quick start, `fcm-sim` without arguments: the first 6 steps in the default run
# (frames, PVD indexes and log rows checked step by step); to the end (71 frames, 210 log
# rows; its run time: lib/docs/performance.md) labelled slow.
fcm_add_test(app_sim_default_quick tests/apps/sim_app.c LABELS app TIMEOUT 900
             ARGS default-quick $<TARGET_FILE:fcm-sim> ${work})
fcm_add_test(app_sim_default tests/apps/sim_app.c LABELS app slow TIMEOUT 1200
             ARGS default $<TARGET_FILE:fcm-sim> ${work})
# Every example scene with --check: at most 3 steps, finite state, the run summary. The
# twisting cylinder is the built-in scene (byte for byte, see scene_default) that
# app_sim_default_quick already runs, so its --check is labelled slow. surface_drop embeds an
# OBJ surface, tetrahedralized with Gmsh: only when fcm was built with it. The cutbench bunny
# scenes cut a surface body without a volume mesh.
set(fcm_check_scenes spinning_body slingshot hollow_ball static_beam cantilever twisting_cylinder
    voxel_block gyroid_lattice cut_slab dice cracked_beam clamped_surface hollow_ball_multigrid
    vibrating_beam octree_ball_hex8 octree_ball_hex20 octree_ball_multigrid ball_on_floor
    ball_off_wedge dice_on_floor cut_bar_resting folding_c)
list(APPEND fcm_check_scenes cutbench_tonthat_slab)
list(APPEND fcm_check_scenes octree_cut_ball_hex8 octree_cut_ball_hex20 cutbench_dick_bunny3
     cutbench_koschier_bunny octree_refine_cut_hex8)
if(FCM_HAVE_GMSH)
  list(APPEND fcm_check_scenes surface_drop)
endif()
foreach(scene IN LISTS fcm_check_scenes)
  set(labels app)
  if(scene STREQUAL "twisting_cylinder")
    set(labels app slow)
  endif()
  fcm_add_test(app_sim_check_${scene} tests/apps/sim_app.c LABELS ${labels} TIMEOUT 900
               ARGS check $<TARGET_FILE:fcm-sim> ${PROJECT_SOURCE_DIR}/apps/scenes/${scene}.json)
endforeach()
# apps/docs/tutorial.md as written: each of its sh blocks in order in a fresh directory with the
# programs on PATH (exit 0, the files it names, the output lines it shows), then the log's facts
# it states; its model is cut, which needs the body's volume mesh: only with Gmsh.
if(FCM_HAVE_GMSH)
  fcm_add_test(app_tutorial tests/apps/tutorial_app.c LABELS app TIMEOUT 300
               ARGS ${PROJECT_SOURCE_DIR}/apps/docs/tutorial.md $<TARGET_FILE_DIR:fcm-sim> ${work})
endif()
# fcm-sim and the embedding diagnostics: the outside-volume warning (half a box beyond +x),
# a body wholly outside and a bad voxel image exit 2 naming the scene section (traceback
# only with --debug), --progress off a terminal: the level-set and cell-rule progress, and the
# set-up's phases of an open surface with fill_holes (a line each with its time, in order, the
# times within the set-up's, the hole-filling warning inside its phase).
fcm_add_test(app_sim_geometry tests/apps/sim_geometry_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-sim> ${work})
# fcm-sim on bad contact input (negative friction, a box with max <= min, a body starting inside
# a sphere or a closed surface, an open obstacle surface): exit 2 naming the field.
fcm_add_test(app_sim_contact tests/apps/sim_contact_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-sim> ${work})
# fcm-condition: --quick CSV/PNG format and facts; the Fig. 5 claims (Longva et al. 2020)
fcm_add_test(app_condition tests/apps/condition_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-condition> ${work})
# Fig. 5 claims in parts that ctest runs side by side, each without and with the default
# simplification; claim 5 on every other decade without simplification, on the decades in
# between with it, and on every decade 1..1e-12 (13 fractions) with both under slow
fcm_add_test(app_condition_claims_1-4 tests/apps/condition_claims.c LABELS app TIMEOUT 1200
             ARGS $<TARGET_FILE:fcm-condition> ${work} 1-4)
fcm_add_test(app_condition_claims_5 tests/apps/condition_claims.c LABELS app TIMEOUT 1200
             ARGS $<TARGET_FILE:fcm-condition> ${work} 5)
fcm_add_test(app_condition_claims_5-simplify tests/apps/condition_claims.c LABELS app
             TIMEOUT 1200 ARGS $<TARGET_FILE:fcm-condition> ${work} 5-simplify)
fcm_add_test(app_condition_claims_6 tests/apps/condition_claims.c LABELS app TIMEOUT 1200
             ARGS $<TARGET_FILE:fcm-condition> ${work} 6)
fcm_add_test(app_condition_claims_long tests/apps/condition_claims.c LABELS slow TIMEOUT 3600
             ARGS $<TARGET_FILE:fcm-condition> ${work} 5-full)
fcm_add_test(dense_spectrum tests/apps/dense_spectrum.c)
# fcm-converge: --quick CSV/PNG format, consistency and error exits, payoff --quick; the
# convergence rates of the manufactured problem (quick set in the default run, the full
# assertion set - every element, FCM and staircase FEM - labelled slow)
fcm_add_test(app_converge tests/apps/converge_app.c LABELS app TIMEOUT 900
             ARGS $<TARGET_FILE:fcm-converge> ${work})
fcm_add_test(app_converge_rates tests/apps/converge_rates.c LABELS app TIMEOUT 900
             ARGS quick $<TARGET_FILE:fcm-converge> ${work})
fcm_add_test(app_converge_rates_full tests/apps/converge_rates.c LABELS app slow TIMEOUT 7200
             ARGS full $<TARGET_FILE:fcm-converge> ${work})
# Faults around fcm-sim's output, through an LD_PRELOAD shim (tests/support/fault_shim.c):
# kill -9 inside file operations and at random moments, then resume (a handful of seeded
# kills by default, 60 under slow); the disk filling up (the shim's ENOSPC, and a real small
# tmpfs where an unprivileged mount namespace is allowed); power loss: a directory fsync
# after each durable write (checkpoints: temporary fsynced, then renamed).
add_library(fcm_fault_shim SHARED tests/support/fault_shim.c)
target_link_libraries(fcm_fault_shim PRIVATE ${CMAKE_DL_LIBS})
set_target_properties(fcm_fault_shim PROPERTIES C_VISIBILITY_PRESET default)
set(fault_args $<TARGET_FILE:fcm-sim> $<TARGET_FILE:fcm_fault_shim> ${work})
fcm_add_test(app_fault_kill tests/apps/fault_app.c LABELS app ARGS kill ${fault_args})
fcm_add_test(app_fault_kill_long tests/apps/fault_app.c LABELS app slow TIMEOUT 1800
             ARGS kill ${fault_args} 60 7)
fcm_add_test(app_fault_diskfull tests/apps/fault_app.c LABELS app ARGS diskfull ${fault_args})
fcm_add_test(app_fault_dirsync tests/apps/fault_app.c LABELS app ARGS dirsync ${fault_args})
add_dependencies(app_fault_kill fcm_fault_shim fcm-sim) # the program of the app_fault_* tests
# apps/app_env.c: a short OpenMP spin by default, the user's OMP_WAIT_POLICY / GOMP_SPINCOUNT
# kept; the CPU's OpenBLAS kernels selected when a shim makes OpenBLAS name its SSE3 ones, the
# user's OPENBLAS_CORETYPE and FCM_BLAS_CORETYPE=keep respected.
add_library(fcm_corename_shim SHARED tests/support/corename_shim.c)
set_target_properties(fcm_corename_shim PROPERTIES C_VISIBILITY_PRESET default)
fcm_add_test(app_env tests/apps/app_env.c LABELS app
             ARGS ${PROJECT_BINARY_DIR}/app-tests $<TARGET_FILE:fcm_corename_shim>)
target_sources(app_env PRIVATE ${PROJECT_SOURCE_DIR}/apps/app_env.c)
add_dependencies(app_env fcm_corename_shim)
# fcm-cut: the cutting experiments check their own claims (exit 1 when one fails): moments of
# every degree <= m over the pieces of a cut tet and hex within 1e-12 with <= M points, and
# the 36 sticks of the diced cube with the mass kept, the conditioning of a cut approaching a
# face (diagonally scaled kappa within 10x with the constraint, raw kappa above 1e8 without
# constraint and stabilization). The default run covers strengths 1-4
# and the Hex8 and Tet4 dice; the full study (strengths 1-8, all four elements) is slow.
add_test(NAME app_cut_accuracy COMMAND $<TARGET_FILE:fcm-cut> accuracy --max-strength 4
         --csv ${work}/cut_accuracy.csv --png ${work}/cut_accuracy.png)
add_test(NAME app_cut_dice_hex8 COMMAND $<TARGET_FILE:fcm-cut> dice --element hex8
         --csv ${work}/cut_dice.csv)
add_test(NAME app_cut_dice_tet4 COMMAND $<TARGET_FILE:fcm-cut> dice --element tet4)
add_test(NAME app_cut_condition COMMAND $<TARGET_FILE:fcm-cut> condition
         --csv ${work}/cut_condition.csv --png ${work}/cut_condition.png)
add_test(NAME app_cut_accuracy_full COMMAND $<TARGET_FILE:fcm-cut> accuracy)
add_test(NAME app_cut_dice_full COMMAND $<TARGET_FILE:fcm-cut> dice)
set_tests_properties(app_cut_accuracy app_cut_dice_hex8 app_cut_dice_tet4 app_cut_condition
                     PROPERTIES LABELS app
                     ENVIRONMENT "OMP_NUM_THREADS=1")
set_tests_properties(app_cut_accuracy_full app_cut_dice_full PROPERTIES LABELS "app;slow"
                     TIMEOUT 900)
# fcm-scaling: small sizes end to end in the default run (CSV facts: every solver
# converges and agrees with CHOLMOD, cg-mg iterations flat, mg factor < 1, bad options exit 2);
# the --quick and full studies with --check (its claims) under bench / slow.
fcm_add_test(app_scaling tests/apps/scaling_app.c LABELS app TIMEOUT 120
             ARGS small $<TARGET_FILE:fcm-scaling> ${work})
fcm_add_test(app_scaling_quick tests/apps/scaling_app.c LABELS bench TIMEOUT 900
             ARGS quick $<TARGET_FILE:fcm-scaling> ${work})
fcm_add_test(app_scaling_full tests/apps/scaling_app.c LABELS slow TIMEOUT 36000
             ARGS full $<TARGET_FILE:fcm-scaling> ${work})
# fcm-scaling --backend petsc on 1 and 2 MPI processes: the PETSc rows agree with
# CHOLMOD's solution, report iterations and the process count; refused options exit non-zero
if(FCM_HAVE_PETSC)
  foreach(np 1 2)
    add_test(NAME app_scaling_petsc_np${np}
             COMMAND $<TARGET_FILE:app_scaling> petsc $<TARGET_FILE:fcm-scaling> ${work}
                     ${MPIEXEC_EXECUTABLE} ${np})
    set_tests_properties(app_scaling_petsc_np${np} PROPERTIES LABELS "app;mpi" TIMEOUT 300
                         PROCESSORS ${np} ENVIRONMENT "${FCM_MPI_TEST_ENV}")
  endforeach()
endif()
# fcm-sim and inverted elements: a soft block squashed through its held base warns (the log's
# inverted_points and nonfinite_stresses columns, the summary) and runs on, or with
# "on_inversion": "stop" exits 1 at the first inverted step leaving whole files; a gentle
# push reports zero.
fcm_add_test(app_sim_inversion tests/apps/inversion_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-sim> ${work})
# fcm-models: a small generated model (the bumpy sphere at 4,800 triangles, one cell size)
# on both paths (the volume path only with Gmsh): CSV columns consistent (rules time > 0, final
# points per cut cell <= M, equal cut cells, moments of the two paths within 1e-10), the PNG,
# bad options exit 2; the full ball study with its claim (exponent of
# rule time against cut cells <= 1.1) under bench.
fcm_add_test(app_models tests/apps/models_app.c LABELS app TIMEOUT 300
             ARGS small $<TARGET_FILE:fcm-models> ${work})
fcm_add_test(app_models_ball tests/apps/models_app.c LABELS bench TIMEOUT 3600
             ARGS ball $<TARGET_FILE:fcm-models> ${work})
# fcm-cutbench: --quick on small sizes (0.15 x the papers', a generated body of 2,000
# triangles) with a looser Newton tolerance as the interactive option set: the CSV's rows and
# columns (every figure finite, cut events, DOFs growing, phases within the cut, ratios and
# verdicts consistent, the two runs' displacements close), the PNG, the written scenes parse,
# bad options exit 2; every row at the papers' sizes under bench. The bunny rows cut the
# surface body without a volume mesh (no Gmsh). The rows left out of --quick: the accordion at
# 0.1 of its size (both runs ok, the cuts add DOFs, Newton steps taken; a few seconds) and
# the plate's, accordion's and octopus's written scenes parse.
fcm_add_test(app_cutbench_quick tests/apps/cutbench_app.c LABELS app TIMEOUT 300
             ARGS quick $<TARGET_FILE:fcm-cutbench> ${work})
fcm_add_test(app_cutbench_rows tests/apps/cutbench_app.c LABELS app TIMEOUT 120
             ARGS rows $<TARGET_FILE:fcm-cutbench> ${work})
fcm_add_test(app_cutbench_full tests/apps/cutbench_app.c LABELS bench TIMEOUT 36000
             ARGS full $<TARGET_FILE:fcm-cutbench> ${work})
