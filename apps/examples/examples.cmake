# The example host programs also built in fcm's own tree (FCM_BUILD_APPS) and run as tests
# (label app), so an API change that breaks them fails the default test run; CI additionally
# builds them against the installed package (setup.sh install-check). They use only the
# public headers and link the library as a host does (fcm::fcm), with fcm's warnings.
# Their sources and CMake project are installed with the documentation
# (<prefix>/share/doc/fcm/examples), where the install check builds them.
install(FILES apps/examples/host_static.c apps/examples/host_cut.c apps/examples/host_dynamic.cpp
              apps/examples/host_petsc.c apps/examples/CMakeLists.txt
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)
add_executable(fcm_example_host_static apps/examples/host_static.c)
target_link_libraries(fcm_example_host_static PRIVATE fcm::fcm)
target_compile_options(fcm_example_host_static PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
if(BUILD_TESTING)
  file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/examples-out)
  add_test(NAME app_example_host_static
           COMMAND fcm_example_host_static ${PROJECT_BINARY_DIR}/examples-out)
  set_tests_properties(app_example_host_static PROPERTIES LABELS app TIMEOUT 300
                       ENVIRONMENT "OMP_NUM_THREADS=2;OMP_WAIT_POLICY=passive;OPENBLAS_NUM_THREADS=1")
endif()
add_executable(fcm_example_host_cut apps/examples/host_cut.c)
target_link_libraries(fcm_example_host_cut PRIVATE fcm::fcm)
target_compile_options(fcm_example_host_cut PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
if(BUILD_TESTING)
  add_test(NAME app_example_host_cut COMMAND fcm_example_host_cut ${PROJECT_BINARY_DIR}/examples-out)
  set_tests_properties(app_example_host_cut PROPERTIES LABELS app TIMEOUT 300
                       ENVIRONMENT "OMP_NUM_THREADS=2;OMP_WAIT_POLICY=passive;OPENBLAS_NUM_THREADS=1")
endif()
# host_petsc: the PETSc component as a host links it (fcm::petsc); run on 2 processes by the
# test app_example_host_petsc (tests/petsc/tests.cmake).
if(FCM_HAVE_PETSC)
  add_executable(fcm_example_host_petsc apps/examples/host_petsc.c)
  target_link_libraries(fcm_example_host_petsc PRIVATE fcm::petsc)
  if(FCM_MATH_LIBRARY)
    target_link_libraries(fcm_example_host_petsc PRIVATE m)
  endif()
  target_compile_options(fcm_example_host_petsc PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
endif()
include(CheckLanguage)
check_language(CXX)
if(CMAKE_CXX_COMPILER)
  enable_language(CXX)
  add_executable(fcm_example_host_dynamic apps/examples/host_dynamic.cpp)
  target_link_libraries(fcm_example_host_dynamic PRIVATE fcm::fcm)
  set(cxx_warnings ${FCM_WARNINGS})
  list(REMOVE_ITEM cxx_warnings -Wstrict-prototypes -Wmissing-prototypes)
  target_compile_options(fcm_example_host_dynamic PRIVATE ${cxx_warnings} ${FCM_SAN_FLAGS})
  if(BUILD_TESTING)
    add_test(NAME app_example_host_dynamic
             COMMAND fcm_example_host_dynamic ${PROJECT_BINARY_DIR}/examples-out)
    set_tests_properties(app_example_host_dynamic PROPERTIES LABELS app TIMEOUT 300
                         ENVIRONMENT "OMP_NUM_THREADS=2;OMP_WAIT_POLICY=passive;OPENBLAS_NUM_THREADS=1")
  endif()
endif()
# The deal.II interop example (FCM_WITH_DEALII): apps/examples/dealii/dealii.cmake.
if(FCM_HAVE_DEALII)
  include(apps/examples/dealii/dealii.cmake)
endif()
