/* Faults around fcm-sim's output, with the LD_PRELOAD shim of tests/support/fault_shim.c.
 * Modes (FCM_SIM: the program, SHIM: the shim library, WORK: a scratch directory):
 *   fault_app kill FCM_SIM SHIM WORK [TRIALS [SEED]]
 *       a small scene writing a frame, the log and a checkpoint every step runs uninterrupted
 *       (the reference); then each trial kills a run with SIGKILL inside a file operation
 *       chosen at random (seeded) among all of the reference run's fwrite/fflush/fsync/
 *       fclose/rename calls - an fwrite is cut in the middle - and a second trial in four
 *       at a random moment in time instead. After each kill every final file (VTU, PVD, CSV,
 *       checkpoint) is whole; the run resumes from its last checkpoint (the resumed run may
 *       be killed again, once) or starts over when there is none, and when it ends every
 *       frame is byte for byte the reference's, the log is the reference's but for the wall
 *       times, the PVD indexes list every frame and no temporary of a killed run is left.
 *   fault_app diskfull FCM_SIM SHIM WORK
 *       the disk fills up (the shim fails writes with ENOSPC after B bytes, B from nothing to
 *       inside the last checkpoint; and, when the machine lets an unprivileged user namespace
 *       mount one, a real 48 KiB tmpfs): fcm-sim exits non-zero with a message naming the
 *       file and "No space left on device", and leaves no temporary and no partial file.
 *   fault_app dirsync FCM_SIM SHIM WORK
 *       power loss: every durable write (the checkpoints: the temporary is fsynced, then
 *       renamed over the target) is followed by an fsync of the directory before the next
 *       rename or the exit, so that the new name survives too. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/simulation.h"
#include "output_check.h"
#include "app_run.h"
#include "test.h"
#include "test_alloc.h"

#include <dirent.h>
#include <fcntl.h>
#include <omp.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define STEPS 10

static const char scene_json[] =
    "{\"version\": 1, \"name\": \"fault\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
    "   \"max\": [1.5, 0.5, 0.5]}, \"cells\": [3, 1, 1]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.02, \"steps\": 10},"
    " \"output\": {\"frame_interval\": 1, \"checkpoint_interval\": 1},"
    " \"effects\": [{\"gravity\": {}}, {\"damping\": {\"stiffness\": 0.01}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0],"
    "   \"normal\": [-1, 0, 0]}}}}]}";

static const char *g_sim, *g_shim, *g_work;
static char g_scene[1024];

/* Environment of one run: the shim's variables (NULL: unset). */
typedef struct fault_env {
  long long kill_at, enospc_after; /* < 0: unset */
  const char *report;
  double kill_after_s; /* > 0: the parent kills the run after this many seconds */
} fault_env;

/* Run fcm-sim with `args` (NULL-terminated, after the program name) under the shim; stdout
 * and stderr go to `out` ("/dev/null" allowed). Returns the exit status, or 128 + signal. */
static int run_sim(const char *const *args, const fault_env *e, const char *out)
{
  const char *argv[32];
  int n = 0;
  argv[n++] = g_sim;
  for (int i = 0; args[i] && n < 31; i++)
    argv[n++] = args[i];
  argv[n] = NULL;
  fflush(NULL);
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    char buf[64];
    setenv("LD_PRELOAD", g_shim, 1);
    setenv("OMP_NUM_THREADS", "1", 1); /* small runs: no thread waits on a busy machine */
    unsetenv("FCM_FAULT_KILL_AT");
    unsetenv("FCM_FAULT_ENOSPC_AFTER");
    unsetenv("FCM_FAULT_REPORT");
    if (e && e->kill_at > 0)
      snprintf(buf, sizeof buf, "%lld", e->kill_at), setenv("FCM_FAULT_KILL_AT", buf, 1);
    if (e && e->enospc_after >= 0)
      snprintf(buf, sizeof buf, "%lld", e->enospc_after), setenv("FCM_FAULT_ENOSPC_AFTER", buf, 1);
    if (e && e->report) setenv("FCM_FAULT_REPORT", e->report, 1);
    int fd = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd >= 0) dup2(fd, 1), dup2(fd, 2), close(fd);
    execv(g_sim, (char *const *)argv);
    _exit(127);
  }
  int status = 0;
  if (e && e->kill_after_s > 0) {
    struct timespec ts = {(time_t)e->kill_after_s,
                          (long)((e->kill_after_s - (double)(time_t)e->kill_after_s) * 1e9)};
    nanosleep(&ts, NULL);
    kill(pid, SIGKILL);
  }
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static long long read_report(const char *path, const char *key)
{
  char buf[256] = "";
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = 0;
  const char *p = strstr(buf, key);
  return p ? atoll(p + strlen(key) + 1) : -1;
}

/* The highest-numbered checkpoint in `dir` (path into `out`), or 0 when there is none. */
static int last_checkpoint(const char *dir, char *out, size_t cap)
{
  DIR *dp = opendir(dir);
  if (!dp) return 0;
  struct dirent *e;
  long best = -1;
  while ((e = readdir(dp))) {
    long k = -1;
    if (strstr(e->d_name, ".tmp") || !oc_ends_with(e->d_name, ".fcmck")) continue;
    if (sscanf(e->d_name, "fault_checkpoint_%ld.fcmck", &k) == 1 && k > best) best = k;
  }
  closedir(dp);
  if (best < 0) return 0;
  snprintf(out, cap, "%.900s/fault_checkpoint_%06ld.fcmck", dir, best);
  return 1;
}

/* Whole file into a malloc'ed buffer (NUL-terminated); NULL when missing. */
static char *slurp(const char *path, long *n)
{
  return (char *)vr_slurp(path, n);
}

/* `dir` holds the reference's frames byte for byte, its log and complete PVD indexes. */
static void compare_with_reference(const char *ref, const char *dir, const char *what)
{
  char a[1024], b[1024];
  const char *kinds[] = {"background", "surface"};
  for (int k = 0; k < 2; k++)
    for (int f = 0; f <= STEPS; f++) {
      long na = 0, nb = 0;
      snprintf(a, sizeof a, "%.900s/fault_%s_%04d.vtu", ref, kinds[k], f);
      snprintf(b, sizeof b, "%.900s/fault_%s_%04d.vtu", dir, kinds[k], f);
      char *x = slurp(a, &na), *y = slurp(b, &nb);
      if (!x || !y || na != nb || memcmp(x, y, (size_t)na))
        TEST_FAIL_("%s: %s differs from the uninterrupted run's", what, b);
      free(x), free(y);
    }
  for (int k = 0; k < 2; k++) {
    long n = 0;
    snprintf(b, sizeof b, "%.900s/fault_%s.pvd", dir, kinds[k]);
    char *x = slurp(b, &n);
    int sets = 0;
    for (char *p = x; p && (p = strstr(p, "<DataSet")); p++)
      sets++;
    if (sets != STEPS + 1) TEST_FAIL_("%s: %s lists %d frames, not %d", what, b, sets, STEPS + 1);
    free(x);
  }
  long na = 0, nb = 0;
  snprintf(a, sizeof a, "%.900s/fault_log.csv", ref);
  snprintf(b, sizeof b, "%.900s/fault_log.csv", dir);
  char *x = slurp(a, &na), *y = slurp(b, &nb);
  if (x && y) oc_strip_last_column(x), oc_strip_last_column(y);
  if (!x || !y || strcmp(x, y)) TEST_FAIL_("%s: %s differs from the uninterrupted run's", what, b);
  free(x), free(y);
}

static oc_seen g_seen; /* checkpoints restored once already */

static void check_files(fcm_ctx *ctx, const fcm_scene *scene, const char *dir, const char *what)
{
  oc_counts c = oc_check_dir_seen(dir, ctx, scene, &g_seen);
  if (c.bad) TEST_FAIL_("%s: %d incomplete final file(s): %s", what, c.bad, c.first_error);
}

static int mode_kill(int trials, unsigned long long seed)
{
  char ref[512], dir[512], report[512], out[512], what[256], ck[1024];
  snprintf(ref, sizeof ref, "%s/fault-ref", g_work);
  snprintf(report, sizeof report, "%s/fault-report.txt", g_work);
  snprintf(out, sizeof out, "%s/fault-out.txt", g_work);
  snprintf(dir, sizeof dir, "%s/fault-kill", g_work);
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s'", ref, dir);
  app_run(cmd);
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_json, "fault.json", &scene));
  if (!scene) return TEST_RESULT();

  /* the reference, counting the file operations */
  fault_env e = {-1, -1, report, 0};
  double t0 = fcm_wtime();
  const char *ref_args[] = {g_scene, "-o", ref, "-q", NULL};
  TEST_TRUE(run_sim(ref_args, &e, out) == 0);
  double wall = fcm_wtime() - t0;
  long long total = read_report(report, "ops");
  TEST_TRUE(total > 4 * STEPS); /* frames, PVDs, log and checkpoint every step */
  check_files(ctx, scene, ref, "reference");
  if (total <= 0) return TEST_RESULT();

  rng r = {seed ? seed : 1};
  int killed = 0, resumed = 0, restarted = 0;
  for (int t = 0; t < trials; t++) {
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    app_run(cmd);
    g_seen.n = 0;
    fault_env k = {-1, -1, NULL, 0};
    if (t % 4 == 1)
      k.kill_after_s = (0.5 + 0.5 * rng_uniform(&r)) * wall; /* a moment in [0, wall) */
    else
      k.kill_at = 1 + (long long)((0.5 + 0.5 * rng_uniform(&r)) * (double)total);
    const char *args[] = {g_scene, "-o", dir, "-q", NULL};
    int rc = run_sim(args, &k, out);
    snprintf(what, sizeof what, "trial %d (kill at %s %.6g)", t,
             k.kill_at > 0 ? "operation" : "second",
             k.kill_at > 0 ? (double)k.kill_at : k.kill_after_s);
    if (rc == 128 + SIGKILL)
      killed++;
    else if (rc != 0)
      TEST_FAIL_("%s: exit %d", what, rc);
    check_files(ctx, scene, dir, what);
    /* resume (or start over) until the run ends; the first resumed run may be killed too */
    for (int round = 0; rc != 0 && round < 4; round++) {
      fault_env k2 = {-1, -1, NULL, 0};
      if (round == 0) k2.kill_at = 1 + (long long)((0.5 + 0.5 * rng_uniform(&r)) * (double)total);
      if (last_checkpoint(dir, ck, sizeof ck)) {
        const char *rargs[] = {g_scene, "-o", dir, "-q", "--resume", ck, NULL};
        rc = run_sim(rargs, &k2, out);
        resumed++;
      } else {
        rc = run_sim(args, &k2, out);
        restarted++;
      }
      if (rc != 0 && rc != 128 + SIGKILL) {
        TEST_FAIL_("%s: the resumed run exits %d", what, rc);
        break;
      }
      check_files(ctx, scene, dir, what);
    }
    TEST_TRUE(rc == 0);
    /* the temporaries of the killed runs were swept by the runs after them */
    oc_counts c = oc_check_dir(dir, ctx, NULL);
    if (c.tmp) TEST_FAIL_("%s: %d temporaries of killed runs are left", what, c.tmp);
    compare_with_reference(ref, dir, what);
  }
  if (getenv("FCM_FAULT_VERBOSE"))
    printf("fault_app: %d trials, %lld operations per run, %d killed, %d resumed, %d restarted\n",
           trials, total, killed, resumed, restarted);
  TEST_TRUE(killed >= trials / 2);
  TEST_TRUE(resumed > 0);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s' '%s' '%s'", ref, dir, report, out);
  app_run(cmd);
  return TEST_RESULT();
}

/* After a failed run in `dir`: no temporary, nothing partial. */
static void check_no_partial(fcm_ctx *ctx, const fcm_scene *scene, const char *dir,
                             const char *what)
{
  oc_counts c = oc_check_dir(dir, ctx, scene);
  if (c.tmp) TEST_FAIL_("%s: %d temporaries left", what, c.tmp);
  if (c.bad) TEST_FAIL_("%s: %d partial file(s): %s", what, c.bad, c.first_error);
}

static int file_has(const char *path, const char *needle)
{
  long n = 0;
  char *s = slurp(path, &n);
  int has = s && strstr(s, needle);
  free(s);
  return has;
}

static int mode_diskfull(void)
{
  char dir[512], out[512], report[512], cmd[8192], what[1024];
  snprintf(dir, sizeof dir, "%s/fault-full", g_work);
  snprintf(out, sizeof out, "%s/fault-full-out.txt", g_work);
  snprintf(report, sizeof report, "%s/fault-full-report.txt", g_work);
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_json, "fault.json", &scene));
  if (!scene) return TEST_RESULT();
  const char *args[] = {g_scene, "-o", dir, "-q", NULL};

  /* the bytes a whole run writes */
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  app_run(cmd);
  fault_env e = {-1, 1LL << 60, report, 0};
  TEST_TRUE(run_sim(args, &e, out) == 0);
  long long total = 0;
  {
    DIR *dp = opendir(dir);
    struct dirent *de;
    while (dp && (de = readdir(dp))) {
      struct stat sb;
      char p[2048];
      snprintf(p, sizeof p, "%s/%s", dir, de->d_name);
      if (stat(p, &sb) == 0 && S_ISREG(sb.st_mode)) total += (long long)sb.st_size;
    }
    if (dp) closedir(dp);
  }
  TEST_TRUE(total > 10000);
  /* the disk fills up at B bytes: nothing, a few, a fifth, half, most of the run */
  const double at[] = {0.0, 1e-4, 0.2, 0.5, 0.9, 0.99};
  for (int i = 0; i < 6; i++) {
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    app_run(cmd);
    /* the files are rewritten (PVD, log) along the way: more than `total` is written */
    fault_env f = {-1, (long long)(at[i] * (double)total), NULL, 0};
    int rc = run_sim(args, &f, out);
    snprintf(what, sizeof what, "disk full after %lld bytes", f.enospc_after);
    if (rc == 0 || rc >= 128) TEST_FAIL_("%s: exit %d", what, rc);
    if (!file_has(out, "No space left on device") || !file_has(out, dir))
      TEST_FAIL_("%s: no message naming the file and the cause", what);
    check_no_partial(ctx, scene, dir, what);
  }

  /* a real small file system, when an unprivileged mount namespace is allowed */
  char mnt[512], copy[512], rcfile[512];
  snprintf(mnt, sizeof mnt, "%s/fault-tmpfs", g_work);
  snprintf(copy, sizeof copy, "%s/fault-tmpfs-copy", g_work);
  snprintf(rcfile, sizeof rcfile, "%s/fault-tmpfs-rc.txt", g_work);
  snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s' '%s' && mkdir -p '%s' '%s'", mnt, copy, rcfile, mnt,
           copy);
  app_run(cmd);
  snprintf(cmd, sizeof cmd,
           "unshare -rm sh -c \"mount -t tmpfs -o size=48k fcm-fault '%s'\" > /dev/null 2>&1", mnt);
  if (app_run(cmd) != 0) {
    printf("fault_app: no unprivileged tmpfs here; the disk-full case ran with the shim only\n");
  } else {
    snprintf(cmd, sizeof cmd,
             "unshare -rm sh -c \"mount -t tmpfs -o size=48k fcm-fault '%s' &&"
             " { '%s' '%s' -o '%s/out' -q > '%s' 2>&1; echo \\$? > '%s';"
             " cp -a '%s/out/.' '%s/'; }\"",
             mnt, g_sim, g_scene, mnt, out, rcfile, mnt, copy);
    TEST_TRUE(app_run(cmd) == 0);
    long n = 0;
    char *rc = slurp(rcfile, &n);
    int code = rc ? atoi(rc) : -1;
    free(rc);
    if (code == 0 || code >= 128 || code < 0) TEST_FAIL_("tmpfs: fcm-sim exits %d", code);
    TEST_TRUE(file_has(out, "No space left on device"));
    check_no_partial(ctx, scene, copy, "tmpfs");
  }
  snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s' '%s' '%s' '%s' '%s'", dir, out, report, mnt, copy,
           rcfile);
  app_run(cmd);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}

static int mode_dirsync(void)
{
  char dir[512], out[512], report[512], cmd[4096];
  snprintf(dir, sizeof dir, "%s/fault-sync", g_work);
  snprintf(out, sizeof out, "%s/fault-sync-out.txt", g_work);
  snprintf(report, sizeof report, "%s/fault-sync-report.txt", g_work);
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  app_run(cmd);
  const char *args[] = {g_scene, "-o", dir, "-q", "--steps", "3", NULL};
  fault_env e = {-1, -1, report, 0};
  TEST_TRUE(run_sim(args, &e, out) == 0);
  long long renames = read_report(report, "renames"), durable = read_report(report, "durable");
  long long dsynced = read_report(report, "dsynced");
  /* 4 frames x (2 VTU + 2 PVD), the log after each, 3 checkpoints (synced: durable) */
  TEST_TRUE(renames >= 4 * 5 + 3);
  TEST_TRUE(durable >= 3);
  if (dsynced != durable)
    TEST_FAIL_("%lld of %lld durable writes (fsync, rename) were not followed by an fsync of "
               "the directory",
               durable - dsynced, durable);
  snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s' '%s'", dir, out, report);
  app_run(cmd);
  return TEST_RESULT();
}

int main(int argc, char **argv)
{
  if (argc < 5) return 2;
  omp_set_num_threads(1);
  g_sim = argv[2];
  g_shim = argv[3];
  g_work = argv[4];
  /* one scene file per mode: the modes run in parallel under ctest -j */
  snprintf(g_scene, sizeof g_scene, "%.900s/fault-%.16s.json", g_work, argv[1]);
  FILE *f = fopen(g_scene, "w");
  if (!f) return 2;
  fputs(scene_json, f);
  fclose(f);
  int rc = 2;
  if (!strcmp(argv[1], "kill"))
    rc = mode_kill(argc > 5 ? atoi(argv[5]) : 6, argc > 6 ? strtoull(argv[6], NULL, 10) : 19);
  else if (!strcmp(argv[1], "diskfull"))
    rc = mode_diskfull();
  else if (!strcmp(argv[1], "dirsync"))
    rc = mode_dirsync();
  remove(g_scene);
  return rc;
}
