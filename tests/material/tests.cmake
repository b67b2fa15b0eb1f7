# One conformance and one projection program run for every material model, plus the
# error paths and the benchmark.
foreach(model IN ITEMS linear stvk corotated snh corotated_linear)
  fcm_add_test(material_conformance_${model} tests/material/conformance.c ARGS ${model}
               LABELS conformance)
  fcm_add_test(material_projection_${model} tests/material/projection.c ARGS ${model}
               LABELS conformance)
endforeach()
fcm_add_test(material_errors tests/material/errors.c)
fcm_add_test(material_bench tests/material/bench.c LABELS bench)
