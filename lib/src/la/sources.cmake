list(APPEND FCM_SOURCES lib/src/la/lapack.c lib/src/la/mat3.c lib/src/la/csr.c lib/src/la/direct.c
     lib/src/la/cholmod_adapter.c lib/src/la/umfpack_adapter.c)
list(APPEND FCM_SOURCES lib/src/la/dense_public.c lib/src/la/ptap.c lib/src/la/ptap_carry.c
     lib/src/la/blas_info.c)
# the Galerkin products' values: per-CPU clones (core/multiversion.h)
if(FCM_MULTIVERSION)
  set_property(SOURCE lib/src/la/ptap.c APPEND PROPERTY COMPILE_DEFINITIONS FCM_MULTIVERSION)
endif()
