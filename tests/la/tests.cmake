fcm_add_test(la_blas tests/la/blas.c)
fcm_add_test(la_eigen tests/la/eigen.c)
fcm_add_test(la_svd tests/la/svd.c)
fcm_add_test(la_lu_chol tests/la/lu_chol.c)
fcm_add_test(la_lstsq tests/la/lstsq.c)
fcm_add_test(la_dense_alloc tests/la/dense_alloc.c)
fcm_add_test(la_mat3_eig tests/la/mat3_eig.c)
fcm_add_test(la_mat3_svd tests/la/mat3_svd.c)
# Random and adversarial F: orthogonality, reconstruction, signs and order to 1e-14.
fcm_add_test(la_mat3_svd_sweep tests/la/mat3_svd_sweep.c)
fcm_add_test(la_csr tests/la/csr.c)
fcm_add_test(la_direct tests/la/direct.c)
# Allocation failures: fcm_csr_create and fcm_csr_wrap.
fcm_add_test(la_alloc_failure tests/la/alloc_failure.c)
# The sparse triple product P^T A P against a dense product, 1 and 2 threads.
fcm_add_test(la_ptap tests/la/ptap.c)
# The grouped AMD ordering (a node's DOFs together) against CHOLMOD's own orderings.
fcm_add_test(la_ordering tests/la/ordering.c)
# The BLAS kernel query and its once-per-context warning: with the kernels OpenBLAS (or the
# test environment) chose, and with the SSE3 fallback forced, which every AVX CPU must flag.
fcm_add_test(la_blas_info tests/la/blas_info.c)
fcm_add_test(la_blas_info_prescott tests/la/blas_info.c ARGS prescott)
set_tests_properties(la_blas_info_prescott PROPERTIES ENVIRONMENT
                     "${FCM_TEST_ENV};OPENBLAS_CORETYPE=Prescott")
# Large matrix values on 2 MiB boundaries (huge pages), small ones 64-byte aligned; their
# allocation failures.
fcm_add_test(la_csr_large tests/la/csr_large.c)
# A matrix taking another's values storage where it fits (a cut's matrices on the old ones').
fcm_add_test(la_csr_take tests/la/csr_take.c)
