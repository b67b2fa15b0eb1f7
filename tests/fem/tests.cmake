foreach(el tet4 tet10 hex8 hex20)
  fcm_add_test(fem_patch_${el} tests/fem/patch.c ARGS ${el} LABELS conformance)
  fcm_add_test(fem_assembly_${el} tests/fem/assembly.c ARGS ${el} LABELS conformance)
endforeach()
