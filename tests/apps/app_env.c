/* apps/app_env.c: the programs wait passively in OpenMP unless the user chose a policy.
 * The test runs itself as a child ("probe") under several environments; the probe counts
 * its executions in an environment variable, calls app_env_init() as the programs do, and
 * reports the policy in its environment and, through omp_display_env(), the one the
 * OpenMP runtime actually uses (libgomp: GOMP_SPINCOUNT 0 means passive). Asserts: with no
 * policy set, the program runs twice and the runtime spins 0 times; with OMP_WAIT_POLICY
 * or GOMP_SPINCOUNT set by the user, it runs once and the user's values are in effect. */
#define _POSIX_C_SOURCE 200809L
#include "../../apps/app_env.h"
#include "test.h"

#include <omp.h>
#include <sys/wait.h>
#include <unistd.h>

#define RUNS_VAR "FCM_TEST_APP_ENV_RUNS"

static int probe(int argc, char **argv)
{
  const char *r = getenv(RUNS_VAR);
  char buf[32];
  snprintf(buf, sizeof buf, "%d", (r ? atoi(r) : 0) + 1);
  setenv(RUNS_VAR, buf, 1);
  app_env_init(argc, argv);
  const char *p = getenv("OMP_WAIT_POLICY");
  printf("runs=%s policy=%s\n", getenv(RUNS_VAR), p ? p : "-");
  fflush(stdout);
  omp_display_env(1); /* to stderr */
  return 0;
}

/* Run `self probe` with the variables set (NULL: unset), stdout and stderr into files;
 * return the runs count and the runtime's GOMP_SPINCOUNT (-1 when not reported). */
static void run(const char *self, const char *dir, const char *policy, const char *spin, int *runs,
                long long *spincount, char env_policy[64])
{
  char out[4096], err[4096];
  snprintf(out, sizeof out, "%s/app_env.out", dir);
  snprintf(err, sizeof err, "%s/app_env.err", dir);
  pid_t pid = fork();
  if (pid == 0) {
    unsetenv(RUNS_VAR);
    unsetenv("KMP_BLOCKTIME");
    unsetenv("LD_PRELOAD");
    if (policy)
      setenv("OMP_WAIT_POLICY", policy, 1);
    else
      unsetenv("OMP_WAIT_POLICY");
    if (spin)
      setenv("GOMP_SPINCOUNT", spin, 1);
    else
      unsetenv("GOMP_SPINCOUNT");
    if (!freopen(out, "w", stdout) || !freopen(err, "w", stderr)) _exit(127);
    execl(self, self, "probe", (char *)NULL);
    _exit(127);
  }
  int status = -1;
  TEST_TRUE(pid > 0 && waitpid(pid, &status, 0) == pid);
  TEST_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  *runs = -1;
  *spincount = -1;
  env_policy[0] = 0;
  FILE *f = fopen(out, "r");
  TEST_TRUE(f && fscanf(f, "runs=%d policy=%63s", runs, env_policy) == 2);
  if (f) fclose(f);
  /* the last GOMP_SPINCOUNT line is the final process's */
  f = fopen(err, "r");
  char line[512];
  while (f && fgets(line, sizeof line, f)) {
    const char *s = strstr(line, "GOMP_SPINCOUNT = '");
    if (s) *spincount = atoll(s + strlen("GOMP_SPINCOUNT = '"));
  }
  if (f) fclose(f);
}

int main(int argc, char **argv)
{
  if (argc >= 2 && !strcmp(argv[1], "probe")) return probe(argc, argv);
  if (argc < 2) {
    fprintf(stderr, "usage: app_env SCRATCH_DIR\n");
    return 2;
  }
  int runs;
  long long spin;
  char pol[64];
  /* nothing set: re-executed once with passive waiting, and the runtime took it */
  run(argv[0], argv[1], NULL, NULL, &runs, &spin, pol);
  TEST_TRUE(runs == 2 && !strcmp(pol, "passive"));
  TEST_TRUE(spin == 0 || spin == -1); /* -1: a runtime that does not report the spin count */
  /* the user's policy wins: one run, the runtime spins */
  run(argv[0], argv[1], "active", NULL, &runs, &spin, pol);
  TEST_TRUE(runs == 1 && !strcmp(pol, "active"));
  TEST_TRUE(spin > 0 || spin == -1);
  run(argv[0], argv[1], "PASSIVE", NULL, &runs, &spin, pol);
  TEST_TRUE(runs == 1 && !strcmp(pol, "PASSIVE") && (spin == 0 || spin == -1));
  /* so does a spin count alone */
  run(argv[0], argv[1], NULL, "777", &runs, &spin, pol);
  TEST_TRUE(runs == 1 && !strcmp(pol, "-"));
  TEST_TRUE(spin == 777 || spin == -1);
  return TEST_RESULT();
}
