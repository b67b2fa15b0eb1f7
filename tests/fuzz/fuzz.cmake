# libFuzzer targets (FCM_FUZZ=ON, clang): one per parser, each a program fcm-fuzz-<name>
# taking libFuzzer's options and corpus directories; fcm-fuzz-seed-checkpoint writes the
# checkpoint seeds (tests/fuzz/make_corpus.sh makes all seed corpora). The library is
# compiled with coverage instrumentation (-fsanitize=fuzzer-no-link) and ASan + UBSan.
foreach(name gmsh tetgen scene checkpoint surface voxels)
  add_executable(fcm-fuzz-${name} tests/fuzz/fuzz_${name}.c)
  target_link_libraries(fcm-fuzz-${name} PRIVATE fcm_testlib)
  target_compile_options(fcm-fuzz-${name} PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS}
                                                  -fsanitize=fuzzer)
  target_link_options(fcm-fuzz-${name} PRIVATE -fsanitize=fuzzer)
endforeach()
add_executable(fcm-fuzz-seed-checkpoint tests/fuzz/seed_checkpoint.c)
target_link_libraries(fcm-fuzz-seed-checkpoint PRIVATE fcm_testlib)
target_compile_options(fcm-fuzz-seed-checkpoint PRIVATE ${FCM_WARNINGS} ${FCM_SAN_FLAGS})
