fcm_add_test(core_ctx tests/core/ctx.c)
fcm_add_test(core_errors tests/core/errors.c)
fcm_add_test(core_version tests/core/version.c ARGS ${PROJECT_VERSION})
