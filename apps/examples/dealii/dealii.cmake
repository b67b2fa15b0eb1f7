# The deal.II interop example (built when deal.II is found, FCM_WITH_DEALII): fcm_kinked (fcm's
# side: the kinked body's rules file and fcm's own solution) and dealii_kinked (a deal.II program
# on those rules), compared by the test interop_dealii (label interop) and run by convergence.sh
# for the rates of lib/docs/interop.md.
add_executable(fcm_example_kinked apps/examples/dealii/fcm_kinked.c)
target_link_libraries(fcm_example_kinked PRIVATE fcm::fcm)
if(FCM_MATH_LIBRARY)
  target_link_libraries(fcm_example_kinked PRIVATE m)
endif()
target_compile_options(fcm_example_kinked PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
set_target_properties(fcm_example_kinked PROPERTIES OUTPUT_NAME fcm_kinked)
# deal.II's compiler flags and libraries (its release variant) through its own CMake macro.
add_executable(dealii_kinked apps/examples/dealii/dealii_kinked.cc)
deal_ii_setup_target(dealii_kinked RELEASE)
if(FCM_WERROR)
  target_compile_options(dealii_kinked PRIVATE -Werror)
endif()
if(BUILD_TESTING)
  file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/interop-out)
  add_test(NAME interop_dealii
           COMMAND bash ${PROJECT_SOURCE_DIR}/apps/examples/dealii/convergence.sh --check
                   $<TARGET_FILE:fcm_example_kinked> $<TARGET_FILE:dealii_kinked>
                   ${PROJECT_BINARY_DIR}/interop-out)
  set_tests_properties(interop_dealii PROPERTIES LABELS interop TIMEOUT 300
                       ENVIRONMENT "OMP_NUM_THREADS=2;OMP_WAIT_POLICY=passive;OPENBLAS_NUM_THREADS=1")
endif()
