# One conformance program run for every element type, plus the error paths.
foreach(el IN ITEMS tet4 tet10 hex8 hex20)
  fcm_add_test(element_conformance_${el} tests/element/conformance.c ARGS ${el} LABELS conformance)
endforeach()
fcm_add_test(element_errors tests/element/errors.c)
fcm_add_test(element_bench tests/element/bench.c LABELS bench)
