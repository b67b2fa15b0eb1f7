list(APPEND FCM_SOURCES lib/src/scene/json_adapter.c lib/src/scene/schema.c
                        lib/src/scene/effects.c lib/src/scene/effects_region.c
                        lib/src/scene/effects_contact.c lib/src/scene/scene.c
                        lib/src/scene/parse_model.c lib/src/scene/parse_solver.c
                        lib/src/scene/view.c
                        lib/src/scene/default_scene.c
                        lib/src/scene/run.c lib/src/scene/run_cut.c lib/src/scene/run_mesh.c lib/src/scene/run_effects.c
                        lib/src/scene/run_step.c lib/src/scene/run_output.c
                        lib/src/scene/run_summary.c lib/src/scene/checkpoint.c
                        lib/src/scene/preview.c)
if(FCM_HAVE_PETSC) # the runner on the PETSc backend (fcm/scene_petsc.h): in libfcm_petsc
  list(APPEND FCM_PETSC_SOURCES lib/src/scene/run_petsc.c)
endif()

# The built-in default scene is the example apps/scenes/twisting_cylinder.json, embedded
# byte for byte at configure time (a byte array: no limit on string literal length), so
# the two cannot drift apart. Editing the file re-runs the configuration.
set(FCM_DEFAULT_SCENE ${PROJECT_SOURCE_DIR}/apps/scenes/twisting_cylinder.json)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${FCM_DEFAULT_SCENE})
file(READ ${FCM_DEFAULT_SCENE} FCM_DEFAULT_SCENE_HEX HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," FCM_DEFAULT_SCENE_BYTES
       "${FCM_DEFAULT_SCENE_HEX}")
configure_file(lib/src/scene/default_scene_json.h.in
               ${PROJECT_BINARY_DIR}/generated/scene/default_scene_json.h @ONLY)
