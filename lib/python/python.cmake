# The Python package fcm (lib/python): the extension module fcm._fcm, written in C against the
# public headers and NumPy's C API and linked to libfcm, plus the pure-Python classes of
# lib/python/fcm. FCM_WITH_PYTHON = AUTO (default: built when a Python 3 interpreter with
# NumPy and its development headers is found), ON (required) or OFF. Not with the sanitizers
# or the fuzzing build: an instrumented module cannot be loaded into an uninstrumented
# interpreter (ASan's runtime must come first in the process).
set(FCM_WITH_PYTHON AUTO CACHE STRING "Build the Python package fcm: AUTO, ON or OFF")
set_property(CACHE FCM_WITH_PYTHON PROPERTY STRINGS AUTO ON OFF)
set(FCM_HAVE_PYTHON OFF)
set(_fcm_py_why "")
if(FCM_WITH_PYTHON STREQUAL "OFF")
  set(_fcm_py_why "FCM_WITH_PYTHON=OFF")
elseif(FCM_SANITIZE OR FCM_FUZZ)
  set(_fcm_py_why "not with FCM_SANITIZE or FCM_FUZZ: the sanitizer runtime and a Python "
                  "interpreter do not mix")
else()
  # The interpreter: Python3_EXECUTABLE when given, else the first python3 on the PATH that
  # imports NumPy, else the system's /usr/bin/python3 (a python3 of pyenv or a virtual
  # environment on the PATH often lacks NumPy while Debian's python3-numpy serves the other).
  if(NOT Python3_EXECUTABLE)
    find_program(_fcm_py_path python3 NO_CACHE)
    foreach(candidate IN ITEMS ${_fcm_py_path} /usr/bin/python3)
      if(EXISTS ${candidate})
        execute_process(COMMAND ${candidate} -c "import numpy" RESULT_VARIABLE _fcm_py_rc
                        OUTPUT_QUIET ERROR_QUIET)
        if(_fcm_py_rc EQUAL 0)
          set(Python3_EXECUTABLE ${candidate} CACHE FILEPATH "Python interpreter of fcm's package")
          break()
        endif()
      endif()
    endforeach()
  endif()
  if(Python3_EXECUTABLE)
    find_package(Python3 COMPONENTS Interpreter Development.Module NumPy)
  endif()
  if(Python3_FOUND AND Python3_NumPy_FOUND AND Python3_Development.Module_FOUND)
    set(FCM_HAVE_PYTHON ON)
  elseif(NOT Python3_EXECUTABLE)
    set(_fcm_py_why "no python3 that imports NumPy (Debian: apt-get install python3-numpy)")
  else()
    set(_fcm_py_why "${Python3_EXECUTABLE}: the development headers or NumPy's C headers were "
                    "not found (Debian: apt-get install python3-dev python3-numpy)")
  endif()
endif()
if(FCM_HAVE_PYTHON)
  message(STATUS "fcm: Python package: ON (${Python3_EXECUTABLE}, Python ${Python3_VERSION}, "
                 "NumPy ${Python3_NumPy_VERSION})")
elseif(FCM_WITH_PYTHON STREQUAL "ON")
  message(FATAL_ERROR "fcm: FCM_WITH_PYTHON=ON but the package cannot be built: ${_fcm_py_why}")
else()
  string(REPLACE ";" "" _fcm_py_why "${_fcm_py_why}")
  message(STATUS "fcm: Python package: OFF (${_fcm_py_why})")
endif()

if(FCM_HAVE_PYTHON)
  # Where the package goes under the install prefix: the interpreter's own site directory
  # relative to its prefix (Debian: lib/python3.11/dist-packages, on the system python3's path
  # for the default prefix /usr/local); FCM_PYTHON_INSTALL_DIR overrides it.
  execute_process(
    COMMAND ${Python3_EXECUTABLE} -c
            "import os, sys, sysconfig\np = sysconfig.get_path('platlib')\nfor b in ('/usr/local', sys.prefix, sys.base_prefix):\n    if p.startswith(b + os.sep):\n        print(os.path.relpath(p, b)); break\nelse:\n    print('lib/python%d.%d/site-packages' % sys.version_info[:2])"
    OUTPUT_VARIABLE _fcm_py_site OUTPUT_STRIP_TRAILING_WHITESPACE)
  set(FCM_PYTHON_INSTALL_DIR ${_fcm_py_site} CACHE STRING
      "Directory of the Python package fcm, relative to the install prefix")
  set(FCM_PYTHON_DIR ${PROJECT_BINARY_DIR}/python) # the build tree's package (PYTHONPATH)
  Python3_add_library(fcm_python MODULE WITH_SOABI lib/python/src/module.c
                      lib/python/src/arrays.c lib/python/src/geometry.c lib/python/src/rules.c
                      lib/python/src/simulation.c lib/python/src/scene.c)
  target_link_libraries(fcm_python PRIVATE fcm::fcm Python3::NumPy)
  target_include_directories(fcm_python PRIVATE ${PROJECT_SOURCE_DIR}/lib/python/src)
  target_compile_definitions(fcm_python PRIVATE NPY_NO_DEPRECATED_API=NPY_1_7_API_VERSION)
  target_compile_options(fcm_python PRIVATE ${FCM_WARNINGS})
  file(RELATIVE_PATH _fcm_py_rpath ${CMAKE_INSTALL_PREFIX}/${FCM_PYTHON_INSTALL_DIR}/fcm
       ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR})
  set_target_properties(fcm_python PROPERTIES OUTPUT_NAME _fcm
                        LIBRARY_OUTPUT_DIRECTORY ${FCM_PYTHON_DIR}/fcm
                        INSTALL_RPATH "$ORIGIN/${_fcm_py_rpath}")
  # The pure-Python modules are copied next to the extension (one rule per file, so an edited
  # module is copied again). A glob: every module of the package folder belongs to it.
  file(GLOB FCM_PYTHON_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/lib/python/fcm/*.py)
  set(_fcm_py_copies "")
  foreach(src IN LISTS FCM_PYTHON_SOURCES)
    get_filename_component(name ${src} NAME)
    add_custom_command(OUTPUT ${FCM_PYTHON_DIR}/fcm/${name}
                       COMMAND ${CMAKE_COMMAND} -E copy ${src} ${FCM_PYTHON_DIR}/fcm/${name}
                       DEPENDS ${src})
    list(APPEND _fcm_py_copies ${FCM_PYTHON_DIR}/fcm/${name})
  endforeach()
  add_custom_target(fcm_python_files ALL DEPENDS ${_fcm_py_copies})
  add_dependencies(fcm_python fcm_python_files)
  install(TARGETS fcm_python LIBRARY DESTINATION ${FCM_PYTHON_INSTALL_DIR}/fcm)
  install(FILES ${FCM_PYTHON_SOURCES} DESTINATION ${FCM_PYTHON_INSTALL_DIR}/fcm)
  if(BUILD_TESTING)
    include(lib/python/tests/tests.cmake)
  endif()
endif()
