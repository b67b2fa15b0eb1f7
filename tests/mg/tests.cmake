foreach(kind cube hemisphere cut)
  fcm_add_test(mg_convergence_${kind} tests/mg/convergence.c ARGS ${kind})
endforeach()
