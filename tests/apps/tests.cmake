# Programs end to end (label app): each test gets the program's path and a scratch directory.
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/app-tests)
fcm_add_test(app_quadrature tests/apps/quadrature_app.c LABELS app
             ARGS $<TARGET_FILE:fcm-quadrature> ${PROJECT_BINARY_DIR}/app-tests)
