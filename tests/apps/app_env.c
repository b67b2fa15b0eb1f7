/* apps/app_env.c: the programs' OpenMP threads spin 10,000 times before sleeping unless the
 * user chose a policy, and select the CPU's OpenBLAS kernels when OpenBLAS runs older ones, unless
 * the user chose. The test runs itself as a child ("probe") under several environments; the probe
 * counts its executions in an environment variable, calls app_env_init() as the programs do, and
 * reports the policy and OPENBLAS_CORETYPE in its environment and, through
 * omp_display_env(), the policy the OpenMP runtime actually uses (libgomp: GOMP_SPINCOUNT 0
 * means passive). The BLAS cases preload a shim whose OpenBLAS names its kernels "Prescott"
 * (SSE3) unless OPENBLAS_CORETYPE is set. Asserts: with no policy set, the program runs twice
 * and the runtime spins 0 times; with OMP_WAIT_POLICY or GOMP_SPINCOUNT set by the user, it
 * runs once and the user's values are in effect; under the SSE3 kernels on a CPU with AVX or
 * more, it runs twice with OPENBLAS_CORETYPE = the CPU's kernel set and says so in one line
 * on stderr; OPENBLAS_CORETYPE set by the user or FCM_BLAS_CORETYPE=keep: one run, no note.
 * With GLIBC_TUNABLES unset it runs twice with the programs' malloc tunables in it (alone, or
 * with the other changes in one re-execution), and a 64 MiB block then comes from the heap
 * (mallinfo2()); set by the user, even empty, it is kept, and glibc maps such a block alone.
 * The other cases run with GLIBC_TUNABLES empty (glibc's defaults kept). */
#define _POSIX_C_SOURCE 200809L
#include "../../apps/app_env.h"
#include "test.h"

#include <fcm/la.h>
#include <malloc.h>
#include <omp.h>
#include <sys/wait.h>
#include <unistd.h>

#define RUNS_VAR "FCM_TEST_APP_ENV_RUNS"

/* The malloc tunables the programs set (apps/app_env.c) */
#define MALLOC                                                                                     \
  "glibc.malloc.hugetlb=1:glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=4294967296"

static int probe(int argc, char **argv)
{
  const char *r = getenv(RUNS_VAR);
  char buf[32];
  snprintf(buf, sizeof buf, "%d", (r ? atoi(r) : 0) + 1);
  setenv(RUNS_VAR, buf, 1);
  app_env_init(argc, argv);
  const char *p = getenv("OMP_WAIT_POLICY"), *c = getenv("OPENBLAS_CORETYPE"),
             *t = getenv("GLIBC_TUNABLES");
  /* a 64 MiB block: mapped alone under glibc's defaults (above its largest mmap threshold) */
  char *big = malloc((size_t)64 << 20);
  const struct mallinfo2 mi = mallinfo2();
  const int mapped = big && mi.hblks > 0;
  if (big) big[0] = 1;
  free(big);
  printf("runs=%s policy=%s coretype=%s tunables=%s mapped=%d\n", getenv(RUNS_VAR), p ? p : "-",
         c ? c : "-",
         !t     ? "-"
         : t[0] ? t
                : "(empty)",
         mapped);
  fflush(stdout);
  omp_display_env(1); /* to stderr */
  return 0;
}

/* The environment of one probe run; NULL members are unset. */
typedef struct probe_env {
  const char *policy, *spin; /* OMP_WAIT_POLICY, GOMP_SPINCOUNT */
  const char *coretype;      /* OPENBLAS_CORETYPE */
  const char *mode;          /* FCM_BLAS_CORETYPE */
  const char *preload;       /* LD_PRELOAD */
  const char *tunables;      /* GLIBC_TUNABLES: NULL empty (glibc's defaults kept) */
  int no_tunables;           /* GLIBC_TUNABLES unset */
} probe_env;

/* What a probe run reported. */
typedef struct probe_out {
  int runs;
  long long spincount; /* the runtime's GOMP_SPINCOUNT (-1 when not reported) */
  char policy[64];     /* OMP_WAIT_POLICY in its environment, "-" unset */
  char coretype[64];   /* OPENBLAS_CORETYPE in its environment, "-" unset */
  char tunables[256];  /* GLIBC_TUNABLES in its environment, "-" unset, "(empty)" */
  int mapped;          /* a 64 MiB block was mapped alone (glibc's default) */
  int blas_notes;      /* lines on stderr saying which kernels were selected */
  char blas_note[512]; /* the last one */
} probe_out;

static void set_or_unset(const char *name, const char *value)
{
  if (value)
    setenv(name, value, 1);
  else
    unsetenv(name);
}

/* Run `self probe` under `e`, stdout and stderr into files, and read what it reported. */
static void run(const char *self, const char *dir, probe_env e, probe_out *o)
{
  char out[4096], err[4096];
  snprintf(out, sizeof out, "%s/app_env.out", dir);
  snprintf(err, sizeof err, "%s/app_env.err", dir);
  pid_t pid = fork();
  if (pid == 0) {
    unsetenv(RUNS_VAR);
    unsetenv("KMP_BLOCKTIME");
    set_or_unset("OMP_WAIT_POLICY", e.policy);
    set_or_unset("GOMP_SPINCOUNT", e.spin);
    set_or_unset("OPENBLAS_CORETYPE", e.coretype);
    set_or_unset("FCM_BLAS_CORETYPE", e.mode);
    set_or_unset("LD_PRELOAD", e.preload);
    set_or_unset("GLIBC_TUNABLES", e.no_tunables ? NULL : e.tunables ? e.tunables : "");
    if (!freopen(out, "w", stdout) || !freopen(err, "w", stderr)) _exit(127);
    execl(self, self, "probe", (char *)NULL);
    _exit(127);
  }
  int status = -1;
  TEST_TRUE(pid > 0 && waitpid(pid, &status, 0) == pid);
  TEST_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  memset(o, 0, sizeof *o);
  o->runs = -1;
  o->spincount = -1;
  o->mapped = -1;
  FILE *f = fopen(out, "r");
  TEST_TRUE(f && fscanf(f, "runs=%d policy=%63s coretype=%63s tunables=%255s mapped=%d", &o->runs,
                        o->policy, o->coretype, o->tunables, &o->mapped) == 5);
  if (f) fclose(f);
  /* the last GOMP_SPINCOUNT line is the final process's */
  f = fopen(err, "r");
  char line[512];
  while (f && fgets(line, sizeof line, f)) {
    const char *s = strstr(line, "GOMP_SPINCOUNT = '");
    if (s) o->spincount = atoll(s + strlen("GOMP_SPINCOUNT = '"));
    if (strstr(line, "BLAS:")) {
      o->blas_notes++;
      snprintf(o->blas_note, sizeof o->blas_note, "%s", line);
    }
  }
  if (f) fclose(f);
}

int main(int argc, char **argv)
{
  if (argc >= 2 && !strcmp(argv[1], "probe")) return probe(argc, argv);
  if (argc < 3) {
    fprintf(stderr, "usage: app_env SCRATCH_DIR CORENAME_SHIM\n");
    return 2;
  }
  const char *self = argv[0], *dir = argv[1], *shim = argv[2];
  probe_out o;
  /* OpenMP, with the BLAS kernels as OpenBLAS chose them */
  /* nothing set: re-executed once with the short spin, and the runtime took it */
  run(self, dir, (probe_env){.mode = "keep"}, &o);
  TEST_TRUE(o.runs == 2 && !strcmp(o.policy, "-") && !strcmp(o.coretype, "-"));
  TEST_TRUE(o.spincount == 10000 || o.spincount == -1); /* -1: a runtime that does not report it */
  /* the user's policy wins: one run, the runtime spins */
  run(self, dir, (probe_env){.policy = "active", .mode = "keep"}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.policy, "active"));
  TEST_TRUE(o.spincount > 0 || o.spincount == -1);
  run(self, dir, (probe_env){.policy = "PASSIVE", .mode = "keep"}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.policy, "PASSIVE"));
  TEST_TRUE(o.spincount == 0 || o.spincount == -1);
  /* so does a spin count alone */
  run(self, dir, (probe_env){.spin = "777", .mode = "keep"}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.policy, "-"));
  TEST_TRUE(o.spincount == 777 || o.spincount == -1);

  /* BLAS kernels: OpenBLAS (the shim) names its SSE3 kernels */
  fcm_blas_info b;
  TEST_TRUE(fcm_blas_info_get(NULL, &b) == FCM_OK);
  const int avx = b.cpu_isa >= FCM_ISA_AVX && b.cpu_core[0];
  run(self, dir, (probe_env){.policy = "active", .preload = shim}, &o);
  if (avx) { /* re-executed once with the CPU's kernels, said in one line */
    TEST_TRUE(o.runs == 2 && !strcmp(o.coretype, b.cpu_core));
    TEST_TRUE(o.blas_notes == 1 && strstr(o.blas_note, b.cpu_core) &&
              strstr(o.blas_note, "in place of Prescott") &&
              strstr(o.blas_note, "FCM_BLAS_CORETYPE=keep"));
  } else { /* SSE3 is all the CPU has: nothing to select */
    TEST_TRUE(o.runs == 1 && !strcmp(o.coretype, "-") && o.blas_notes == 0);
  }
  TEST_TRUE(!strcmp(o.policy, "active"));
  /* one re-execution does both */
  run(self, dir, (probe_env){.preload = shim, .mode = "auto"}, &o);
  TEST_TRUE(o.runs == 2 && (o.spincount == 10000 || o.spincount == -1));
  TEST_TRUE(!strcmp(o.coretype, avx ? b.cpu_core : "-") && o.blas_notes == avx);
  /* the user's kernels win, and FCM_BLAS_CORETYPE=keep keeps OpenBLAS's */
  run(self, dir, (probe_env){.policy = "active", .coretype = "Haswell", .preload = shim}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.coretype, "Haswell") && o.blas_notes == 0);
  run(self, dir, (probe_env){.policy = "active", .mode = "keep", .preload = shim}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.coretype, "-") && o.blas_notes == 0);

  /* malloc: GLIBC_TUNABLES unset gets huge pages, alone or in the one re-execution */
  run(self, dir, (probe_env){.policy = "active", .mode = "keep", .no_tunables = 1}, &o);
  TEST_TRUE(o.runs == 2 && !strcmp(o.tunables, MALLOC) && !strcmp(o.policy, "active"));
  TEST_TRUE(o.mapped == 0);
  run(self, dir, (probe_env){.mode = "keep", .no_tunables = 1}, &o);
  TEST_TRUE(o.runs == 2 && !strcmp(o.tunables, MALLOC) &&
            (o.spincount == 10000 || o.spincount == -1));
  TEST_TRUE(o.mapped == 0);
  /* the user's tunables win, even empty */
  run(self, dir,
      (probe_env){.policy = "active", .mode = "keep", .tunables = "glibc.malloc.arena_max=2"}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.tunables, "glibc.malloc.arena_max=2") && o.mapped == 1);
  run(self, dir, (probe_env){.policy = "active", .mode = "keep"}, &o);
  TEST_TRUE(o.runs == 1 && !strcmp(o.tunables, "(empty)") && o.mapped == 1);
  return TEST_RESULT();
}
