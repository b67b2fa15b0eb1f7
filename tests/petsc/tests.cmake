# The PETSc backend's tests (label mpi; only in a build with FCM_HAVE_PETSC): each program runs
# under mpiexec on 1 and 2 processes (fcm_add_test(... NP n), the MPI environment of the root
# CMakeLists.txt). They are part of the default run (`ctest -LE 'bench|slow'`) of such a build;
# `ctest -L mpi` runs them alone.
set(FCM_MUMPS "-ksp_type preonly -pc_type cholesky -pc_factor_mat_solver_type mumps")
foreach(np 1 2)
  foreach(el hex8 tet4 hex20 tet10)
    foreach(kind static dynamic)
      # the default solver (CG + GAMG, rtol 1e-12) with PT-Scotch
      fcm_add_test(petsc_match_${el}_${kind}_np${np} tests/petsc/match.c NP ${np}
                   ARGS ${el} ${kind} ptscotch)
    endforeach()
  endforeach()
  # the Morton-ordered partition and MUMPS (the direct option)
  fcm_add_test(petsc_match_hex8_static_ordered_mumps_np${np} tests/petsc/match.c NP ${np}
               ARGS hex8 static ordered ${FCM_MUMPS})
  fcm_add_test(petsc_match_tet4_dynamic_ordered_mumps_np${np} tests/petsc/match.c NP ${np}
               ARGS tet4 dynamic ordered ${FCM_MUMPS})
endforeach()
# the distributed classification (each process intersects its share of the cells, the classes
# are gathered) equals the serial build bit for bit: classes, fractions, pieces, DOF numbering,
# own cells' volume and surface rules; phase 1 for each element and, on Hex8, phase 2 (a scene)
foreach(np 1 2)
  foreach(el hex8 tet4 hex20 tet10)
    set(scene_args)
    if(el STREQUAL "hex8")
      set(scene_args ${PROJECT_SOURCE_DIR}/tests/petsc/scenes static_snh.json)
    endif()
    fcm_add_test(petsc_classify_${el}_np${np} tests/petsc/classify.c NP ${np}
                 ARGS ${el} ordered ${scene_args})
  endforeach()
  fcm_add_test(petsc_classify_tet4_ptscotch_np${np} tests/petsc/classify.c NP ${np}
               ARGS tet4 ptscotch)
  # phase 2 with simplify = auto (the exchange, then the choice's reduce; Hex20) and with a cut
  fcm_add_test(petsc_classify_auto_np${np} tests/petsc/classify.c NP ${np}
               ARGS tet4 ordered ${PROJECT_SOURCE_DIR}/apps/scenes twisting_cylinder.json)
  fcm_add_test(petsc_classify_cut_np${np} tests/petsc/classify.c NP ${np}
               ARGS tet4 ordered ${PROJECT_SOURCE_DIR}/apps/scenes cut_slab.json)
endforeach()
# a process failing before its rules build (phase 2) or inside it before the per-cell loop
# (phase 1) ends every process at the classification exchange with the message, no hang
foreach(np 1 2)
  fcm_add_test(petsc_classify_failure_np${np} tests/petsc/classify_failure.c NP ${np}
               TIMEOUT 60)
endforeach()
# the local topology of phase 1 (own + ghost cells): the serial numbering bit for bit, every
# owned row's pattern the full one (and incomplete without the ghosts), exact preallocation,
# the whole-pattern functions refusing it, frames from the piece's values alone byte for byte
foreach(np 1 2 3)
  foreach(case "hex8;ball" "tet4;ball" "hex20;ball" "tet10;ball" "hex8;none")
    list(GET case 0 el)
    list(GET case 1 shape)
    fcm_add_test(petsc_ghost_${el}_${shape}_np${np} tests/petsc/ghost.c NP ${np}
                 ARGS ${el} ${shape} petsc_ghost_${el}_${shape}_np${np} TIMEOUT 120)
  endforeach()
endforeach()
# the local space of a cut body (several DOF copies per node, constrained copies), serial
foreach(el hex8 tet4 hex20 tet10)
  fcm_add_test(petsc_ghost_${el}_cut tests/petsc/ghost.c NP 1 ARGS ${el} cut unused)
endforeach()
# errors on one or all processes end every process with the message, no hang
foreach(np 1 2)
  fcm_add_test(petsc_failure_np${np} tests/petsc/failure.c NP ${np} TIMEOUT 60)
endforeach()
# example scenes: the PETSc backend against the serial fcm_simulation
foreach(np 1 2)
  fcm_add_test(petsc_scene_cantilever_np${np} tests/petsc/scene.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/apps/scenes cantilever.json 1)
  fcm_add_test(petsc_scene_vibrating_beam_np${np} tests/petsc/scene.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes vibrating_beam_euler.json 10)
endforeach()
if(FCM_BUILD_APPS)
  # every example scene on 2 processes against the serial fcm-sim: petsc_app_scene_* below
  # a scene that fails while the simulation is built (its cut's surface file holds no surface):
  # every process exits non-zero, with the message
  add_test(NAME petsc_app_sim_bad_cut
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${MPIEXEC_PREFLAGS}
                   $<TARGET_FILE:fcm-sim> ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/bad_cut.json
                   --backend petsc --check)
  set_tests_properties(petsc_app_sim_bad_cut PROPERTIES LABELS mpi TIMEOUT 120 PROCESSORS 2
                       WILL_FAIL TRUE ENVIRONMENT "${FCM_MPI_TEST_ENV}")
  add_test(NAME petsc_app_sim_bad_cut_message
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${MPIEXEC_PREFLAGS}
                   $<TARGET_FILE:fcm-sim> ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/bad_cut.json
                   --backend petsc --check)
  set_tests_properties(petsc_app_sim_bad_cut_message PROPERTIES LABELS mpi TIMEOUT 120
                       PROCESSORS 2 ENVIRONMENT "${FCM_MPI_TEST_ENV}"
                       PASS_REGULAR_EXPRESSION "effects\\[2\\]\\.cut\\.surface\\.mesh: surface: .*empty mesh")
endif()
# memory and time per DOF on 1 and 2 processes (labels bench, mpi: not in the default run)
foreach(np 1 2)
  fcm_add_test(petsc_bench_np${np} tests/petsc/bench.c NP ${np} LABELS bench ARGS hex8 24
               TIMEOUT 1800)
endforeach()
# a linear scene on the linear driver against the integrator on PETSc (fcm-sim's path): set-up
# and time per step (labels bench, mpi: not in the default run; lib/docs/petsc_backend.md)
foreach(np 1 2)
  fcm_add_test(petsc_driver_paths_np${np} tests/petsc/driver_paths.c NP ${np} LABELS bench
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/vibrating_beam_fine.json 10 3
               TIMEOUT 600)
endforeach()
# checkpoints: resume bit for bit on the same processes, to 1e-10 on another count
foreach(np 1 2)
  fcm_add_test(petsc_checkpoint_np${np} tests/petsc/checkpoint.c NP ${np})
endforeach()
# the linear driver's checkpoints (the serial container, and the older .fcmpk the test writes)
# load into the integrator on PETSc, the serial simulation (fcm_simulation_read_checkpoint()) and
# the driver: its state bit for bit, the next step equal to the driver's to 1e-8; files of
# another problem, truncated and corrupted ones refused
foreach(np 1 2)
  fcm_add_test(petsc_legacy_checkpoint_np${np} tests/petsc/legacy_checkpoint.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes vibrating_beam_euler.json 5
                    ${CMAKE_CURRENT_BINARY_DIR}/petsc_legacy_checkpoint)
endforeach()
if(FCM_BUILD_APPS)
  # fcm-sim --backend petsc --checkpoint-every / --resume on a linear scene: byte for byte on 2
  # processes; the linear driver's checkpoints (the container and the older .fcmpk) resume to 1e-8
  add_test(NAME petsc_app_sim_resume
           COMMAND bash ${PROJECT_SOURCE_DIR}/tests/petsc/resume.sh ${MPIEXEC_EXECUTABLE}
                   $<TARGET_FILE:fcm-sim> $<TARGET_FILE:petsc_state_diff>
                   $<TARGET_FILE:petsc_legacy_checkpoint>
                   ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/vibrating_beam_euler.json
                   ${CMAKE_CURRENT_BINARY_DIR}/petsc_app_sim_resume)
  set_tests_properties(petsc_app_sim_resume PROPERTIES LABELS mpi TIMEOUT 300 PROCESSORS 2
                       ENVIRONMENT "${FCM_MPI_TEST_ENV}")
endif()
# phase 2: scenes through the integrator (Newton) on PETSc (fcm_petsc_simulation_create())
# against the serial fcm_simulation: state, energies and the log (mass, momentum, reactions)
# to 1e-8 relative, the state bit for bit the same on every process (tests/petsc/newton.c)
set(FCM_SCENES ${PROJECT_SOURCE_DIR}/apps/scenes)
foreach(np 1 2)
  # static Stable Neo-Hookean, penalty boundary constraint, traction, 3 load steps (MUMPS)
  fcm_add_test(petsc_newton_static_snh_np${np} tests/petsc/newton.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes static_snh.json 1)
  # the same with CG + GAMG on the Newton systems
  fcm_add_test(petsc_newton_static_snh_gamg_np${np} tests/petsc/newton.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes static_snh.json 1 1e-8
                    -ksp_type cg -pc_type gamg)
  # the same with CG + fcm's multigrid as PCMG (pcmg.c) on the Newton systems
  fcm_add_test(petsc_newton_static_snh_mg_np${np} tests/petsc/newton.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes static_snh.json 1 1e-8
                    -ksp_type cg -pc_type mg)
  # dynamic SNH, Nitsche on the embedded boundary (fixed and rotating caps), gravity, damping
  fcm_add_test(petsc_newton_clamped_surface_np${np} tests/petsc/newton.c NP ${np}
               ARGS ${FCM_SCENES} clamped_surface.json 3)
  # linear material through Newton: traction and pressure, load steps, CG + GAMG
  fcm_add_test(petsc_newton_static_beam_np${np} tests/petsc/newton.c NP ${np}
               ARGS ${FCM_SCENES} static_beam.json 1)
  # plain FEM without an embedded geometry (each process integrates its own cells; no cell
  # rules): gravity, a clamp and a moving end, backward Euler (MUMPS)
  fcm_add_test(petsc_newton_plain_beam_np${np} tests/petsc/newton.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes plain_beam.json 5)
endforeach()
# initial velocity (Hex20, free body: momentum), and a MINRES scene with release and damping
# (the serial run solves with MINRES to rtol 1e-5 there: compared to 1e-6; MINRES + GAMG to the
# test's rtol 1e-12 needs up to ~500 iterations, the scene's limit, so the limit is raised: a
# KSP that stops there makes the integrator halve the step, another path)
fcm_add_test(petsc_newton_spinning_body_np2 tests/petsc/newton.c NP 2
             ARGS ${FCM_SCENES} spinning_body.json 3)
fcm_add_test(petsc_newton_slingshot_np2 tests/petsc/newton.c NP 2
             ARGS ${FCM_SCENES} slingshot.json 2 1e-6 -ksp_max_it 5000)
# the integrator on PETSc: a failure on one process, in the setup's sums, in the KSP (after the
# step's halvings) and in a cut between steps on one process end every process with the
# message, no hang
# (3 processes too: checkpoints with 0, 1 and 2 cuts, whose mean equals one process's count)
foreach(np 1 2 3)
  fcm_add_test(petsc_newton_failure_np${np} tests/petsc/newton_failure.c NP ${np} TIMEOUT 180)
endforeach()
# 3 processes: a DOF's partial Newton rows reach its owner from more than one other process
# through PETSc's stash (on 2 there is one sender), as do the cut's rebuilt backends
fcm_add_test(petsc_newton_clamped_surface_np3 tests/petsc/newton.c NP 3
             ARGS ${FCM_SCENES} clamped_surface.json 3)
fcm_add_test(petsc_newton_cut_late_np3 tests/petsc/newton_cut.c NP 3
             ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes cut_late.json 6)
if(FCM_BUILD_APPS)
  # the state of two checkpoints (fcm-sim's .fcmck or the linear driver's .fcmpk) to a relative
  # tolerance: a tool of the shell tests below (no MPI)
  add_executable(petsc_state_diff tests/petsc/state_diff.c)
  target_link_libraries(petsc_state_diff PRIVATE m)
  target_compile_options(petsc_state_diff PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
  target_link_options(petsc_state_diff PRIVATE ${FCM_SAN_FLAGS})
endif()
if(FCM_BUILD_APPS)
  # EVERY example scene of apps/scenes on 2 processes through fcm-sim --backend petsc
  # (tests/petsc/scene_app.sh): the state after the first steps equals the serial fcm-sim's to
  # the tolerance, or the scene is refused with the message. One table; a scene of apps/scenes
  # in neither list fails petsc_app_scene_listed.
  # name        steps  relative tolerance of the state (1e-8; slingshot: the serial run
  #                    solves with MINRES to the scene's rtol 1e-5)
  set(FCM_PETSC_SCENES_RUN
      cantilever            2 1e-8
      clamped_surface       2 1e-8
      gyroid_lattice        2 1e-8
      hollow_ball           2 1e-8
      hollow_ball_multigrid 1 1e-8
      slingshot             1 1e-6
      spinning_body         2 1e-8
      static_beam           2 1e-8
      surface_drop          2 1e-8
      vibrating_beam        2 1e-8
      voxel_block           2 1e-8
      cracked_beam          1 1e-8
      cut_slab              2 1e-8
      dice                  2 1e-8
      twisting_cylinder     1 1e-8
      cutbench_dick_bunny3    1 1e-8
      cutbench_koschier_bunny 1 1e-8
      cutbench_tonthat_slab   1 1e-8)
  # name               the message (grep -E) of the refusal
  set(FCM_PETSC_SCENES_REFUSED
      octree_ball_hex8  "octree with [0-9]+ hanging .*applied by the serial solvers only"
      octree_ball_hex20 "octree with [0-9]+ hanging .*applied by the serial solvers only"
      octree_ball_multigrid "octree with [0-9]+ hanging .*applied by the serial solvers only"
      octree_cut_ball_hex8 "octree with [0-9]+ hanging .*applied by the serial solvers only"
      octree_cut_ball_hex20 "octree with [0-9]+ hanging .*applied by the serial solvers only"
      octree_refine_cut_hex8 "octree with [0-9]+ hanging .*applied by the serial solvers only"
      ball_on_floor     "contact is not supported with a distributed backend"
      ball_off_wedge    "contact is not supported with a distributed backend"
      dice_on_floor     "contact is not supported with a distributed backend"
      cut_bar_resting   "contact is not supported with a distributed backend"
      folding_c         "contact is not supported with a distributed backend")
  set(listed "")
  set(run ${FCM_PETSC_SCENES_RUN})
  while(run)
    list(POP_FRONT run name steps rtol)
    list(APPEND listed ${name})
    add_test(NAME petsc_app_scene_${name}
             COMMAND bash ${PROJECT_SOURCE_DIR}/tests/petsc/scene_app.sh run ${MPIEXEC_EXECUTABLE}
                     $<TARGET_FILE:fcm-sim> $<TARGET_FILE:petsc_state_diff>
                     ${FCM_SCENES}/${name}.json ${steps} ${rtol}
                     ${CMAKE_CURRENT_BINARY_DIR}/petsc_app_scene_${name})
    set_tests_properties(petsc_app_scene_${name} PROPERTIES LABELS mpi TIMEOUT 300 PROCESSORS 2
                         ENVIRONMENT "${FCM_MPI_TEST_ENV}")
  endwhile()
  set(refused ${FCM_PETSC_SCENES_REFUSED})
  while(refused)
    list(POP_FRONT refused name regex)
    list(APPEND listed ${name})
    add_test(NAME petsc_app_scene_${name}
             COMMAND bash ${PROJECT_SOURCE_DIR}/tests/petsc/scene_app.sh refused
                     ${MPIEXEC_EXECUTABLE} $<TARGET_FILE:fcm-sim> - ${FCM_SCENES}/${name}.json -
                     "${regex}" ${CMAKE_CURRENT_BINARY_DIR}/petsc_app_scene_${name})
    set_tests_properties(petsc_app_scene_${name} PROPERTIES LABELS mpi TIMEOUT 120 PROCESSORS 2
                         ENVIRONMENT "${FCM_MPI_TEST_ENV}")
  endwhile()
  file(GLOB scene_files RELATIVE ${FCM_SCENES} CONFIGURE_DEPENDS ${FCM_SCENES}/*.json)
  set(unlisted "")
  foreach(f ${scene_files})
    string(REGEX REPLACE "\\.json$" "" name ${f})
    if(NOT name IN_LIST listed)
      list(APPEND unlisted ${name})
    endif()
  endforeach()
  # the run summary on 2 processes counts every process's cells (points, boundary points,
  # max |u|): the same lines as the serial fcm-sim's
  foreach(name clamped_surface spinning_body)
    add_test(NAME petsc_app_summary_${name}
             COMMAND bash ${PROJECT_SOURCE_DIR}/tests/petsc/scene_app.sh summary
                     ${MPIEXEC_EXECUTABLE} $<TARGET_FILE:fcm-sim> - ${FCM_SCENES}/${name}.json - -
                     ${CMAKE_CURRENT_BINARY_DIR}/petsc_app_summary_${name})
    set_tests_properties(petsc_app_summary_${name} PROPERTIES LABELS mpi TIMEOUT 120
                         PROCESSORS 2 ENVIRONMENT "${FCM_MPI_TEST_ENV}")
  endforeach()
  # every example scene is in one of the two lists (a new scene is added to one of them)
  add_test(NAME petsc_app_scene_listed
           COMMAND ${CMAKE_COMMAND} -E echo "example scenes in neither list: ${unlisted}")
  set_tests_properties(petsc_app_scene_listed PROPERTIES LABELS mpi
                       FAIL_REGULAR_EXPRESSION "neither list: [a-z]")
endif()
if(FCM_BUILD_APPS)
  # fcm-sim --backend petsc on the integrator path: checkpoints (the scene's interval,
  # --checkpoint-every), --resume byte for byte on 2 processes, to 1e-10 on 1 and serially
  add_test(NAME petsc_app_newton_resume
           COMMAND bash ${PROJECT_SOURCE_DIR}/tests/petsc/newton_resume.sh ${MPIEXEC_EXECUTABLE}
                   $<TARGET_FILE:fcm-sim> $<TARGET_FILE:petsc_state_diff>
                   ${FCM_SCENES}/clamped_surface.json
                   ${CMAKE_CURRENT_BINARY_DIR}/petsc_app_newton_resume)
  set_tests_properties(petsc_app_newton_resume PROPERTIES LABELS mpi TIMEOUT 300 PROCESSORS 2
                       ENVIRONMENT "${FCM_MPI_TEST_ENV}")
endif()
# phase 2 with cuts and quadrature.simplify = "auto" (tests/petsc/newton_cut.c): the example
# scenes' cuts at t = 0 (dice: 10 planes into 36 sticks; cut_slab: 2 planes; cracked_beam: a
# partial crack, static), a test scene cut between steps (after solves) plus a cut that misses,
# and twisting_cylinder's "auto" (Hex20): against the serial run step by step, with the cut
# bookkeeping and the simplification choice equal to the serial ones
foreach(np 1 2)
  fcm_add_test(petsc_newton_cut_dice_np${np} tests/petsc/newton_cut.c NP ${np}
               ARGS ${FCM_SCENES} dice.json 3)
  fcm_add_test(petsc_newton_cut_slab_np${np} tests/petsc/newton_cut.c NP ${np}
               ARGS ${FCM_SCENES} cut_slab.json 3)
  fcm_add_test(petsc_newton_cut_cracked_beam_np${np} tests/petsc/newton_cut.c NP ${np}
               ARGS ${FCM_SCENES} cracked_beam.json 1)
  fcm_add_test(petsc_newton_cut_late_np${np} tests/petsc/newton_cut.c NP ${np}
               ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes cut_late.json 6)
endforeach()
# (2 processes: the choice's inputs are summed; on 1 the serial rules build decides)
fcm_add_test(petsc_newton_auto_twisting_cylinder_np2 tests/petsc/newton_cut.c NP 2
             ARGS ${FCM_SCENES} twisting_cylinder.json 1 TIMEOUT 300)
# the late cut with CG + GAMG on the rebuilt KSP
fcm_add_test(petsc_newton_cut_late_gamg_np2 tests/petsc/newton_cut.c NP 2
             ARGS ${PROJECT_SOURCE_DIR}/tests/petsc/scenes cut_late.json 6 1e-8
                  -ksp_type cg -pc_type gamg)
# each problem reads its PETSc options under its own prefix (tests/petsc/options.c): strings
# of earlier problems do not leak into later ones; the command line wins (unprefixed: every
# problem; -fcm2_...: the second problem alone)
foreach(np 1 2)
  fcm_add_test(petsc_options_np${np} tests/petsc/options.c NP ${np}
               ARGS minres cg gmres jacobi gamg gamg)
  fcm_add_test(petsc_options_cmdline_np${np} tests/petsc/options.c NP ${np}
               ARGS bcgs bcgs bcgs jacobi gamg gamg -ksp_type bcgs)
  fcm_add_test(petsc_options_prefixed_np${np} tests/petsc/options.c NP ${np}
               ARGS minres cg gmres jacobi jacobi gamg -fcm2_pc_type jacobi)
endforeach()
# fcm's geometric multigrid as PCMG (-pc_type mg): the CHOLMOD solution to 1e-8, CG iterations
# at rtol 1e-10 bounded, fewer than GAMG's by a factor; a clear error on non-box meshes
foreach(np 1 2)
  fcm_add_test(petsc_pcmg_hex8_np${np} tests/petsc/pcmg.c NP ${np} ARGS hex8 12 32 0)
  fcm_add_test(petsc_pcmg_hex20_np${np} tests/petsc/pcmg.c NP ${np} ARGS hex20 6 40 5)
endforeach()
# a local failure on ONE process in PCMG's setup (tests/petsc/pcmg_failure.c): every allocation
# of the setup and first step failed in turn on process 1; every process fails with the
# message, none hangs (the timeout is the guard)
# every allocation on 2 processes, every third on 3 (oversubscribed: slower); Hex20 (its
# first level is the Hex8 space of the same elements) every fifth on 2
fcm_add_test(petsc_pcmg_failure_hex8_np2 tests/petsc/pcmg_failure.c NP 2 TIMEOUT 90
             ARGS hex8 4 1)
fcm_add_test(petsc_pcmg_failure_hex8_np3 tests/petsc/pcmg_failure.c NP 3 TIMEOUT 90
             ARGS hex8 4 3)
fcm_add_test(petsc_pcmg_failure_hex20_np2 tests/petsc/pcmg_failure.c NP 2 TIMEOUT 90
             ARGS hex20 3 5)
# the integrator on PETSc's creation (rules, local space, numbering, matrix preallocation,
# options): every allocation on 2 processes, every third on 3
fcm_add_test(petsc_newton_create_failure_np2 tests/petsc/pcmg_failure.c NP 2 TIMEOUT 120
             ARGS create ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/static_snh.json 1)
fcm_add_test(petsc_newton_create_failure_np3 tests/petsc/pcmg_failure.c NP 3 TIMEOUT 120
             ARGS create ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/static_snh.json 3)
# phase 2 (the integrator, -pc_type mg): every 37th allocation of the first step
fcm_add_test(petsc_pcmg_failure_newton_np2 tests/petsc/pcmg_failure.c NP 2 TIMEOUT 120
             ARGS scene ${PROJECT_SOURCE_DIR}/tests/petsc/scenes/static_snh.json 37)
# The example host of the PETSc component (apps/examples/host_petsc.c, linked as a host links
# it: fcm::petsc) on 2 processes: at the static equilibrium the elastic energy is half the
# work of the load.
if(TARGET fcm_example_host_petsc)
  add_test(NAME app_example_host_petsc
           COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 ${MPIEXEC_PREFLAGS}
                   $<TARGET_FILE:fcm_example_host_petsc>)
  set_tests_properties(app_example_host_petsc PROPERTIES LABELS "app;mpi" TIMEOUT 120
                       PROCESSORS 2 ENVIRONMENT "${FCM_MPI_TEST_ENV}")
endif()
