/* Prints the OpenBLAS kernel set to select for this CPU (OPENBLAS_CORETYPE) and the one
 * OpenBLAS chose, "SkylakeX Prescott", when fcm_blas_info_get() reports a fallback; nothing
 * otherwise. ctest runs it before the tests (tests/support/blas_kernels.cmake). */
#include <fcm/la.h>

#include <stdio.h>

int main(void)
{
  fcm_blas_info b;
  if (fcm_blas_info_get(NULL, &b) == FCM_OK && b.fallback) printf("%s %s\n", b.cpu_core, b.core);
  return 0;
}
