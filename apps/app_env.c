/* apps: process environment of the fcm programs — passive OpenMP waiting by default,
 * by re-executing the program once with OMP_WAIT_POLICY=passive (see app_env.h). */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* setenv */
#endif

#include "app_env.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void app_env_init(int argc, char **argv)
{
  if (argc < 1 || !argv || !argv[0]) return;
  /* the user's choice wins */
  if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT") || getenv("KMP_BLOCKTIME")) return;
  /* under valgrind the re-executed program would run outside the tool */
  const char *preload = getenv("LD_PRELOAD");
  if (preload && strstr(preload, "vgpreload")) return;
#ifdef __linux__
  if (setenv("OMP_WAIT_POLICY", "passive", 1) != 0) return;
  execv("/proc/self/exe", argv);
  /* exec failed (no /proc?): go on with the policy the runtime started with; the variable
   * stays set, so a child process of ours would wait passively */
#endif
}
