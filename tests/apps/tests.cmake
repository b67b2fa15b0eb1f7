# Programs end to end (label app): each test gets the program's path and a scratch directory.
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/app-tests)
fcm_add_test(app_quadrature tests/apps/quadrature_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-quadrature> ${PROJECT_BINARY_DIR}/app-tests)
# fcm-sim: a small scene run (frames, PVDs, CSV log, --steps, -o) and the cantilever demo;
# checkpoints and --resume reproduce the uninterrupted run's frames byte for byte;
# invalid scenes exit non-zero with the parser's message and create no output directory;
# every example scene and the built-in scene run `--check` (the heavy ones labelled slow).
fcm_add_test(app_sim_run tests/apps/sim_app.c LABELS app
             ARGS run $<TARGET_FILE:fcm-sim> ${PROJECT_BINARY_DIR}/app-tests)
add_test(NAME app_sim_errors COMMAND app_sim_run errors $<TARGET_FILE:fcm-sim>
         ${PROJECT_BINARY_DIR}/app-tests)
set_tests_properties(app_sim_errors PROPERTIES LABELS app TIMEOUT 300)
add_test(NAME app_sim_resume COMMAND app_sim_run resume $<TARGET_FILE:fcm-sim>
         ${PROJECT_BINARY_DIR}/app-tests)
set_tests_properties(app_sim_resume PROPERTIES LABELS app TIMEOUT 300)
# The README quick start: `fcm-sim` without arguments, to the end (about 40 s).
add_test(NAME app_sim_default COMMAND app_sim_run default $<TARGET_FILE:fcm-sim>
         ${PROJECT_BINARY_DIR}/app-tests)
set_tests_properties(app_sim_default PROPERTIES LABELS app TIMEOUT 1200)
# Every example scene and the built-in one ("-", no file) with --check (about 25 s in all
# on 2 idle cores; the twisting cylinder's cut-cell rules take most of it).
foreach(scene spinning_body slingshot hollow_ball static_beam twisting_cylinder -)
  if(scene STREQUAL "-")
    set(name builtin)
    set(arg -)
  else()
    set(name ${scene})
    set(arg ${PROJECT_SOURCE_DIR}/apps/scenes/${scene}.json)
  endif()
  add_test(NAME app_sim_check_${name} COMMAND app_sim_run check $<TARGET_FILE:fcm-sim> ${arg})
  set_tests_properties(app_sim_check_${name} PROPERTIES LABELS app TIMEOUT 900)
endforeach()
# fcm-condition: --quick CSV/PNG format and facts; the Fig. 5 claims (Longva et al. 2020)
fcm_add_test(app_condition tests/apps/condition_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-condition> ${PROJECT_BINARY_DIR}/app-tests)
fcm_add_test(app_condition_claims tests/apps/condition_claims.c LABELS app TIMEOUT 1200
             ARGS $<TARGET_FILE:fcm-condition> ${PROJECT_BINARY_DIR}/app-tests)
fcm_add_test(dense_spectrum tests/apps/dense_spectrum.c)
# fcm-converge: --quick CSV/PNG format, consistency and error exits, payoff --quick; the
# convergence rates of the manufactured problem (quick set in the default run, the full
# assertion set - every element, FCM and staircase FEM - labelled slow)
fcm_add_test(app_converge tests/apps/converge_app.c LABELS app TIMEOUT 900
             ARGS $<TARGET_FILE:fcm-converge> ${PROJECT_BINARY_DIR}/app-tests)
fcm_add_test(app_converge_rates tests/apps/converge_rates.c LABELS app TIMEOUT 900
             ARGS quick $<TARGET_FILE:fcm-converge> ${PROJECT_BINARY_DIR}/app-tests)
add_test(NAME app_converge_rates_full COMMAND app_converge_rates full $<TARGET_FILE:fcm-converge>
         ${PROJECT_BINARY_DIR}/app-tests)
set_tests_properties(app_converge_rates_full PROPERTIES LABELS "app;slow" TIMEOUT 7200
                     ENVIRONMENT "OMP_NUM_THREADS=2")
# Faults around fcm-sim's output, through an LD_PRELOAD shim (tests/support/fault_shim.c):
# kill -9 inside file operations and at random moments, then resume (a handful of seeded
# kills by default, 60 under slow); the disk filling up (the shim's ENOSPC, and a real small
# tmpfs where an unprivileged mount namespace is allowed); a directory fsync after each
# rename that puts an output file in place.
add_library(fcm_fault_shim SHARED tests/support/fault_shim.c)
target_link_libraries(fcm_fault_shim PRIVATE ${CMAKE_DL_LIBS})
set_target_properties(fcm_fault_shim PROPERTIES C_VISIBILITY_PRESET default)
fcm_add_test(app_fault_kill tests/apps/fault_app.c LABELS app
             ARGS kill $<TARGET_FILE:fcm-sim> $<TARGET_FILE:fcm_fault_shim>
                  ${PROJECT_BINARY_DIR}/app-tests)
add_dependencies(app_fault_kill fcm_fault_shim fcm-sim)
add_test(NAME app_fault_kill_long COMMAND app_fault_kill kill $<TARGET_FILE:fcm-sim>
         $<TARGET_FILE:fcm_fault_shim> ${PROJECT_BINARY_DIR}/app-tests 60 7)
set_tests_properties(app_fault_kill_long PROPERTIES LABELS "app;slow" TIMEOUT 1800)
add_test(NAME app_fault_diskfull COMMAND app_fault_kill diskfull $<TARGET_FILE:fcm-sim>
         $<TARGET_FILE:fcm_fault_shim> ${PROJECT_BINARY_DIR}/app-tests)
set_tests_properties(app_fault_diskfull PROPERTIES LABELS app TIMEOUT 300)
add_test(NAME app_fault_dirsync COMMAND app_fault_kill dirsync $<TARGET_FILE:fcm-sim>
         $<TARGET_FILE:fcm_fault_shim> ${PROJECT_BINARY_DIR}/app-tests)
set_tests_properties(app_fault_dirsync PROPERTIES LABELS app TIMEOUT 300)
