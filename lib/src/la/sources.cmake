list(APPEND FCM_SOURCES lib/src/la/lapack.c lib/src/la/mat3.c lib/src/la/csr.c lib/src/la/direct.c
     lib/src/la/cholmod_adapter.c lib/src/la/umfpack_adapter.c)
list(APPEND FCM_SOURCES lib/src/la/dense_public.c lib/src/la/ptap.c lib/src/la/ptap_carry.c
     lib/src/la/blas_info.c lib/src/la/ordering.c)
