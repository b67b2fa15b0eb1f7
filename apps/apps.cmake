# The programs' shared command-line helper (apps/cli.h) and the sphere triangulation their
# generated surfaces start from (apps/app_sphere.h), linked into each program.
add_library(fcm_apps_cli STATIC apps/cli.c apps/app_sphere.c)
target_link_libraries(fcm_apps_cli PUBLIC fcm::fcm)
target_compile_options(fcm_apps_cli PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
fcm_add_app(fcm-sim apps/fcm-sim.c apps/fcm-sim-plot.c)
if(FCM_HAVE_PETSC) # --backend petsc: the PETSc component
  target_sources(fcm-sim PRIVATE apps/fcm-sim-petsc.c)
  target_link_libraries(fcm-sim PRIVATE fcm::petsc)
endif()
fcm_add_app(fcm-rulegen apps/fcm-rulegen.c)
fcm_add_app(fcm-quadrature apps/fcm-quadrature.c apps/fcm-quadrature-embed.c
            apps/fcm-quadrature-export.c apps/fcm-quadrature-grid.c)
fcm_add_app(fcm-condition apps/fcm-condition.c apps/fcm-condition-study.c apps/fcm-condition-output.c)
fcm_add_app(fcm-converge apps/fcm-converge.c apps/fcm-converge-study.c
            apps/fcm-converge-reference.c apps/fcm-converge-run.c apps/fcm-converge-output.c)
fcm_add_app(fcm-cut apps/fcm-cut.c apps/fcm-cut-accuracy.c)
fcm_add_app(fcm-scaling apps/fcm-scaling.c apps/fcm-scaling-study.c apps/fcm-scaling-output.c)
if(FCM_HAVE_PETSC) # --backend petsc: the PETSc component
  target_link_libraries(fcm-scaling PRIVATE fcm::petsc)
endif()
fcm_add_app(fcm-models apps/fcm-models.c apps/fcm-models-run.c apps/fcm-models-output.c)
fcm_add_app(fcm-cutbench apps/fcm-cutbench.c apps/fcm-cutbench-scenes.c apps/fcm-cutbench-bodies.c
            apps/fcm-cutbench-output.c)
# fcm-models finds its built-in pebble (apps/scenes/models/pebble.obj) in the source tree.
target_compile_definitions(fcm-models PRIVATE FCM_MODELS_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# Every program spins briefly in OpenMP, selects the CPU's OpenBLAS kernels and puts malloc's
# memory on huge pages unless the user says otherwise (apps/app_env.h).
foreach(app fcm-sim fcm-rulegen fcm-quadrature fcm-condition fcm-converge fcm-cut fcm-scaling
            fcm-models fcm-cutbench)
  target_sources(${app} PRIVATE apps/app_env.c)
endforeach()
