/* LD_PRELOAD shim for the fault tests of the programs (tests/apps/fault_app.c). It watches
 * the file operations of the process on regular files other than the standard streams:
 * fwrite, fflush, fsync, fclose, rename and renameat ("operations", counted from 1 in the
 * order they are called), and directory fsyncs. Environment:
 *   FCM_FAULT_KILL_AT=N         operation N kills the process (SIGKILL); an fwrite first
 *                               writes half of its bytes and flushes them, so the file on
 *                               disk is cut in the middle of a write
 *   FCM_FAULT_ENOSPC_AFTER=B    the disk holds B bytes: an fwrite that would pass B bytes in
 *                               all writes what fits and fails with ENOSPC, as do later ones
 *   FCM_FAULT_REPORT=PATH       at exit, write "ops O renames R synced S durable U
 *                               dsynced V dirsyncs D" to PATH: S of the R renames were
 *                               followed by an fsync of a directory before the next rename
 *                               or the exit; U renames put a file in place that had been
 *                               fsynced since the previous rename (durable writes), V of
 *                               them were followed by a directory fsync
 * Not thread safe beyond what the programs need (they write files from one thread). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static long long ops, kill_at = -1, enospc_after = -1, written, renames, synced, dirsyncs;
static long long durable, dsynced;
static int pending_rename, pending_durable, file_synced, configured;

static void configure(void)
{
  if (configured) return;
  configured = 1;
  const char *s = getenv("FCM_FAULT_KILL_AT");
  if (s && *s) kill_at = atoll(s);
  s = getenv("FCM_FAULT_ENOSPC_AFTER");
  if (s && *s) enospc_after = atoll(s);
}

static void *next(const char *name)
{
  return dlsym(RTLD_NEXT, name);
}

/* Whether `fd` is a regular file other than stdin, stdout, stderr. */
static int watched_fd(int fd)
{
  struct stat sb;
  return fd > 2 && fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode);
}

static int watched(FILE *f)
{
  return f && watched_fd(fileno(f));
}

/* Count one operation; the chosen one kills. */
static void operation(void)
{
  configure();
  if (++ops == kill_at) raise(SIGKILL);
}

static void renamed(int rc)
{
  if (rc != 0) return;
  renames++;
  pending_rename = 1;
  pending_durable = file_synced;
  durable += file_synced;
  file_synced = 0;
}

size_t fwrite(const void *p, size_t size, size_t n, FILE *f)
{
  size_t (*real)(const void *, size_t, size_t, FILE *) = next("fwrite");
  int (*real_flush)(FILE *) = next("fflush");
  if (!watched(f) || size == 0) return real(p, size, n, f);
  configure();
  size_t bytes = size * n;
  if (ops + 1 == kill_at && bytes > 1) { /* cut in the middle of this write */
    real(p, 1, bytes / 2, f);
    real_flush(f);
  }
  operation();
  if (enospc_after >= 0 && written + (long long)bytes > enospc_after) {
    size_t fit = written < enospc_after ? (size_t)(enospc_after - written) : 0;
    fit -= fit % size;
    size_t done = fit ? real(p, size, fit / size, f) : 0;
    written += (long long)(done * size);
    errno = ENOSPC;
    return done;
  }
  size_t done = real(p, size, n, f);
  written += (long long)(done * size);
  return done;
}

int fflush(FILE *f)
{
  int (*real)(FILE *) = next("fflush");
  if (watched(f)) operation();
  return real(f);
}

int fclose(FILE *f)
{
  int (*real)(FILE *) = next("fclose");
  if (watched(f)) operation();
  return real(f);
}

int fsync(int fd)
{
  int (*real)(int) = next("fsync");
  struct stat sb;
  if (fstat(fd, &sb) == 0 && S_ISDIR(sb.st_mode)) {
    dirsyncs++;
    if (pending_rename) synced++, pending_rename = 0;
    if (pending_durable) dsynced++, pending_durable = 0;
  } else if (watched_fd(fd)) {
    operation();
    file_synced = 1;
  }
  return real(fd);
}

int rename(const char *from, const char *to)
{
  int (*real)(const char *, const char *) = next("rename");
  operation();
  int rc = real(from, to);
  renamed(rc);
  return rc;
}

int renameat(int dfrom, const char *from, int dto, const char *to)
{
  int (*real)(int, const char *, int, const char *) = next("renameat");
  operation();
  int rc = real(dfrom, from, dto, to);
  renamed(rc);
  return rc;
}

__attribute__((destructor)) static void report(void)
{
  const char *path = getenv("FCM_FAULT_REPORT");
  if (!path || !*path) return;
  char buf[256];
  int n = snprintf(buf, sizeof buf,
                   "ops %lld renames %lld synced %lld durable %lld dsynced %lld dirsyncs %lld\n",
                   ops, renames, synced, durable, dsynced, dirsyncs);
  int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0666);
  if (fd < 0) return;
  if (write(fd, buf, (size_t)n) != n) {
  }
  close(fd);
}
