/* apps: process environment of the fcm programs — a short OpenMP spin before sleeping, the
 * CPU's OpenBLAS kernels and malloc's memory on huge pages by default, by re-executing the
 * program once (see app_env.h). */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L /* setenv */
#endif

#include "app_env.h"

#include <fcm/la.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Set in the re-executed program: the kernels OpenBLAS had chosen before the selection. */
#define NOTE_VAR "FCM_BLAS_CORETYPE_REPLACED"

/* glibc's malloc (hugetlb: 2.35 and later; others ignore what they do not know): its heap
 * advised for transparent huge pages, every block from the heap (none mapped alone) and freed
 * memory kept up to 4 GiB at the heap's top (app_env.h) */
#define MALLOC_TUNABLES                                                                            \
  "glibc.malloc.hugetlb=1:glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=4294967296"

/* libgomp's polls of a waiting OpenMP thread before it sleeps (app_env.h) */
#define SPINCOUNT "10000"

static const char *base_name(const char *path)
{
  const char *s = strrchr(path, '/');
  return s ? s + 1 : path;
}

/* The OpenBLAS kernel set to select, or NULL: the user chose (OPENBLAS_CORETYPE set, or
 * FCM_BLAS_CORETYPE=keep) or OpenBLAS's own choice fits the CPU. */
static const char *blas_core_to_select(const char *prog, fcm_blas_info *b)
{
  if (getenv("OPENBLAS_CORETYPE")) return NULL;
  const char *mode = getenv("FCM_BLAS_CORETYPE");
  if (mode && strcmp(mode, "keep") == 0) return NULL;
  if (mode && mode[0] && strcmp(mode, "auto") != 0)
    fprintf(stderr, "%s: FCM_BLAS_CORETYPE=%s: expected keep or auto; using auto\n", prog, mode);
  if (fcm_blas_info_get(NULL, b) != FCM_OK || !b->fallback) return NULL;
  return b->cpu_core;
}

/* In the re-executed program: say which kernels were selected, once. */
static void note_selection(const char *prog)
{
  const char *replaced = getenv(NOTE_VAR);
  fcm_blas_info b;
  if (!replaced || fcm_blas_info_get(NULL, &b) != FCM_OK) return;
  if (strcmp(b.core, replaced) == 0) /* an OpenBLAS built for one CPU only */
    fprintf(stderr, "%s: BLAS: OPENBLAS_CORETYPE=%s had no effect; %s runs its %s kernels\n", prog,
            b.cpu_core, b.name, b.core);
  else
    fprintf(stderr,
            "%s: BLAS: %s kernels %s (%s) selected for this CPU in place of %s "
            "(FCM_BLAS_CORETYPE=keep keeps OpenBLAS's choice)\n",
            prog, b.name, b.core, fcm_isa_name(b.core_isa), replaced);
  unsetenv(NOTE_VAR); /* not again in the programs this one starts */
}

static void init(int argc, char **argv, int omp)
{
  if (argc < 1 || !argv || !argv[0]) return;
  const char *prog = base_name(argv[0]);
  note_selection(prog);
  /* under valgrind the re-executed program would run outside the tool */
  const char *preload = getenv("LD_PRELOAD");
  if (preload && strstr(preload, "vgpreload")) return;
  /* the user's choice wins */
  const int set_omp =
      omp && !getenv("OMP_WAIT_POLICY") && !getenv("GOMP_SPINCOUNT") && !getenv("KMP_BLOCKTIME");
  const int set_malloc = omp && !getenv("GLIBC_TUNABLES");
  fcm_blas_info b;
  const char *core = blas_core_to_select(prog, &b);
  if (!set_omp && !set_malloc && !core) return;
#ifdef __linux__
  if (set_omp && setenv("GOMP_SPINCOUNT", SPINCOUNT, 1) != 0) return;
  if (set_malloc && setenv("GLIBC_TUNABLES", MALLOC_TUNABLES, 1) != 0) return;
  if (core && (setenv("OPENBLAS_CORETYPE", core, 1) != 0 || setenv(NOTE_VAR, b.core, 1) != 0))
    return;
  execv("/proc/self/exe", argv);
  /* exec failed (no /proc?): go on as started; the variables stay set, so a child process of
   * ours would spin briefly, use the selected kernels and huge pages */
  unsetenv(NOTE_VAR);
#endif
}

void app_env_init(int argc, char **argv)
{
  init(argc, argv, 1);
}

void app_env_init_blas(int argc, char **argv)
{
  init(argc, argv, 0);
}
