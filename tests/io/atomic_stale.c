/* Temporaries of killed writers: a process killed (SIGKILL) between
 * creating its temporary and committing leaves it behind; the temporary is hidden (no
 * glob for outputs -- "frame_*.vtu", "frame_*", "*" -- lists it) and the next process
 * writing into the same directory removes it. Temporaries of live processes, our own,
 * and files merely resembling ours (no leading dot, non-numeric pid, a directory) stay. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_impl.h"
#include "test.h"
#include "vtk_reader.h"

#include <glob.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#define DIR "io_atomic_stale.d"

static size_t glob_count(const char *pattern)
{
  glob_t g;
  size_t n = 0;
  if (glob(pattern, 0, NULL, &g) == 0) n = g.gl_pathc;
  globfree(&g);
  return n;
}

static void touch(const char *path)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (f) fclose(f);
}

/* A child that opens a temporary for DIR/name, writes a little and is killed. */
static long killed_writer(const char *name)
{
  pid_t pid = fork();
  if (pid == 0) {
    fcm_ctx *ctx = NULL;
    fcm__atomic_file af;
    char path[256];
    snprintf(path, sizeof path, DIR "/%s", name);
    if (fcm_ctx_create(NULL, &ctx) != FCM_OK) _exit(2);
    if (fcm__io_atomic_open(ctx, path, 0, NULL, &af) != FCM_OK) _exit(3);
    if (fcm__io_atomic_printf(ctx, &af, "partial frame\n") != FCM_OK) _exit(4);
    fflush(af.fp);
    raise(SIGKILL);
    _exit(5);
  }
  int status = 0;
  TEST_TRUE(pid > 0 && waitpid(pid, &status, 0) == pid);
  TEST_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  return (long)pid;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(vr_mkdir(DIR));
  char name[256];

  /* a frame written by a killed process: its temporary stays, hidden; the next killed
   * writer's first open removes it, and leaves its own */
  const long dead = killed_writer("frame_0001.vtu");
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 1);
  snprintf(name, sizeof name, ".frame_0001.vtu.tmp.%ld.", dead);
  TEST_TRUE(vr_count_entries(DIR, name) == 1);
  killed_writer("frame_0002.vtu");
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 1 && vr_count_entries(DIR, name) == 0);
  TEST_TRUE(glob_count(DIR "/frame_*.vtu") == 0);
  TEST_TRUE(glob_count(DIR "/frame_*") == 0);
  TEST_TRUE(glob_count(DIR "/*") == 0);

  /* look-alikes that must survive the sweep */
  snprintf(name, sizeof name, DIR "/.keep.tmp.%ld.7", (long)getppid()); /* a live process */
  touch(name);
  snprintf(name, sizeof name, DIR "/.mine.tmp.%ld.7", (long)getpid()); /* our own */
  touch(name);
  snprintf(name, sizeof name, DIR "/frame_0003.vtu.tmp.%ld.7", dead); /* not hidden */
  touch(name);
  touch(DIR "/.frame.vtu.tmp.abc.7"); /* pid not a number */
  touch(DIR "/.frame.vtu.tmp.12x.7");
  snprintf(name, sizeof name, DIR "/.adir.tmp.%ld.7", dead); /* a directory */
  TEST_TRUE(mkdir(name, 0700) == 0);
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 7);

  /* the next run writes a frame: the stale temporary goes, everything else stays */
  fcm__atomic_file af;
  TEST_OK(ctx, fcm__io_atomic_open(ctx, DIR "/frame_0001.vtu", 1, NULL, &af));
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 6 + 1); /* + its own, open */
  TEST_OK(ctx, fcm__io_atomic_printf(ctx, &af, "complete frame\n"));
  TEST_OK(ctx, fcm__io_atomic_commit(ctx, &af)); /* durable: file and directory synced */
  TEST_TRUE(vr_count_entries(DIR, ".tmp.") == 6);
  TEST_TRUE(glob_count(DIR "/frame_*.vtu") == 1);
  long size = 0;
  unsigned char *data = vr_slurp(DIR "/frame_0001.vtu", &size);
  TEST_TRUE(data && size == 15 && !memcmp(data, "complete frame\n", 15));
  free(data);

  /* clean up */
  snprintf(name, sizeof name, DIR "/.adir.tmp.%ld.7", dead);
  TEST_TRUE(rmdir(name) == 0);
  vr_rmdir(DIR);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
