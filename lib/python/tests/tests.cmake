# The Python package's tests (label python): one ctest per pytest file of lib/python/tests,
# run by the interpreter the package was built for, on the build tree's package. The C
# program python_reference computes the same problems through the C API for the bit-for-bit
# comparisons (its path in FCM_PY_REFERENCE).
execute_process(COMMAND ${Python3_EXECUTABLE} -c "import pytest" RESULT_VARIABLE _fcm_pytest_rc
                OUTPUT_QUIET ERROR_QUIET)
if(NOT _fcm_pytest_rc EQUAL 0)
  message(STATUS "fcm: the Python tests are not registered: ${Python3_EXECUTABLE} has no pytest "
                 "(Debian: apt-get install python3-pytest)")
  return()
endif()
add_executable(fcm_python_reference lib/python/tests/reference.c)
target_link_libraries(fcm_python_reference PRIVATE fcm::fcm)
target_compile_options(fcm_python_reference PRIVATE ${FCM_WARNINGS})
file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/python-tests)
# the rules-file reader's tests read files written by fcm-quadrature export (skipped without it)
set(_fcm_py_quadrature "")
if(TARGET fcm-quadrature)
  set(_fcm_py_quadrature ";FCM_QUADRATURE=$<TARGET_FILE:fcm-quadrature>")
endif()
file(GLOB _fcm_py_tests CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/lib/python/tests/test_*.py)
foreach(test IN LISTS _fcm_py_tests)
  get_filename_component(name ${test} NAME_WE)
  string(REGEX REPLACE "^test_" "" name ${name})
  add_test(NAME python_${name}
           COMMAND ${Python3_EXECUTABLE} -m pytest -q -p no:cacheprovider ${test}
           WORKING_DIRECTORY ${PROJECT_BINARY_DIR}/python-tests)
  set_tests_properties(python_${name} PROPERTIES LABELS python TIMEOUT 600 ENVIRONMENT
    "${FCM_TEST_ENV};PYTHONPATH=${FCM_PYTHON_DIR};PYTHONDONTWRITEBYTECODE=1;MPLBACKEND=Agg;FCM_PY_REFERENCE=$<TARGET_FILE:fcm_python_reference>;FCM_SOURCE_DIR=${PROJECT_SOURCE_DIR};FCM_PY_SCRATCH=${PROJECT_BINARY_DIR}/python-tests${_fcm_py_quadrature}")
endforeach()
