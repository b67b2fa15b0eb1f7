/* LD_PRELOAD shim for the app_env test: an OpenBLAS that names its kernels "Prescott" (SSE3),
 * as Debian 12's does on CPUs newer than it, unless OPENBLAS_CORETYPE names others. The
 * library looks the query up at run time, so the shim's comes first; the kernels stay real. */
#include <stdlib.h>

char *openblas_get_corename(void);

char *openblas_get_corename(void)
{
  static char prescott[] = "Prescott";
  char *c = getenv("OPENBLAS_CORETYPE");
  return c && c[0] ? c : prescott;
}
