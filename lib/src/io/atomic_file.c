/* Atomic replacement of output files: write a uniquely named hidden temporary beside the
 * target, check every flush and close, rename over the target (durable files: fsync the
 * file before and the directory after), or remove it on error. Temporaries left by a
 * process that died (kill -9, power loss) are removed by the next process writing into
 * the same directory. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_impl.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define TMP_ATTEMPTS 100
#define TMP_TAG      ".tmp."
#define SWEPT_DIRS   256 /* directories remembered as swept, per process */

/* Thread-safe text of a system error (the XSI strerror_r). */
static void sys_error(int err, char *buf, size_t len)
{
  if (strerror_r(err, buf, len) != 0) snprintf(buf, len, "system error %d", err);
}

/* Whether `name` has the form of our temporaries, "." base ".tmp." pid "." n (base
 * non-empty, pid and n decimal); *pid receives the writer's process id. */
static int temporary_name(const char *name, long *pid)
{
  const char *tag = NULL;
  if (name[0] != '.') return 0;
  for (const char *p = strstr(name + 1, TMP_TAG); p; p = strstr(p + 1, TMP_TAG))
    tag = p;
  if (!tag || tag == name + 1) return 0;
  const char *s = tag + strlen(TMP_TAG);
  char *end = NULL;
  if (!isdigit((unsigned char)*s)) return 0;
  errno = 0;
  const long v = strtol(s, &end, 10);
  if (errno || *end != '.' || v <= 0 || !isdigit((unsigned char)end[1])) return 0;
  for (s = end + 1; *s; s++)
    if (!isdigit((unsigned char)*s)) return 0;
  *pid = v;
  return 1;
}

/* FNV-1a of a directory name, for the table of swept directories. */
static uint64_t dir_hash(const char *dir)
{
  uint64_t h = 14695981039346656037ull;
  for (const unsigned char *p = (const unsigned char *)dir; *p; p++)
    h = (h ^ *p) * 1099511628211ull;
  return h ? h : 1;
}

/* Whether this process has not swept `dir` yet (and now counts it as swept). */
static int first_visit(const char *dir)
{
  static uint64_t swept[SWEPT_DIRS];
  const uint64_t h = dir_hash(dir);
  int first = 0;
#pragma omp critical(fcm_atomic_swept)
  {
    size_t i = (size_t)(h % SWEPT_DIRS), k = 0;
    while (k < SWEPT_DIRS && swept[i] && swept[i] != h)
      i = (i + 1) % SWEPT_DIRS, k++;
    if (k == SWEPT_DIRS) {
      first = 1; /* table full: sweep again, harmless */
    } else if (!swept[i]) {
      swept[i] = h;
      first = 1;
    }
  }
  return first;
}

/* Remove the temporaries in `dir` whose writer process no longer exists (kill(pid, 0)
 * fails with ESRCH): regular files named as ours only; our own process's are left alone,
 * as are those of a live process or one we may not signal (EPERM: it exists). Best
 * effort, once per directory and process; returns the number removed. */
static int sweep_stale(const char *dir)
{
  int removed = 0;
  DIR *d = opendir(dir);
  if (!d) return 0;
  const long self = (long)getpid();
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    long pid = 0;
    struct stat sb;
    if (!temporary_name(e->d_name, &pid) || pid == self) continue;
    if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
    if (fstatat(dirfd(d), e->d_name, &sb, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(sb.st_mode))
      continue;
    if (unlinkat(dirfd(d), e->d_name, 0) == 0) removed++;
  }
  closedir(d);
  return removed;
}

/* The directory part of `path` ("." when none) into buf; 0 when it does not fit. */
static int dir_of(const char *path, char *buf, size_t len)
{
  const char *slash = strrchr(path, '/');
  if (!slash) return snprintf(buf, len, ".") < (int)len;
  if (slash == path) return snprintf(buf, len, "/") < (int)len;
  return snprintf(buf, len, "%.*s", (int)(slash - path), path) < (int)len;
}

fcm_status fcm__io_atomic_open(fcm_ctx *ctx, const char *path, int durable,
                               const fcm__io_fault *fault, fcm__atomic_file *af)
{
  fcm_status st = FCM_OK;
  char msg[256];
  int fd = -1, err = 0;
  memset(af, 0, sizeof *af);
  af->fault.fail_after_bytes = -1;
  if (fault) af->fault = *fault;
  af->durable = durable;
  FCM_CHECK(path && *path, ctx, FCM_ERR_ARG, "io: output path is NULL or empty");
  FCM_TRY(ctx, fcm__io_strdup(ctx, path, &af->path));
  size_t cap = strlen(path) + 64;
  FCM_ALLOC(ctx, cap, af->tmp_path);
  FCM_ALLOC(ctx, cap, af->dir);
  if (!dir_of(path, af->dir, cap)) FCM_FREE(ctx, af->dir);
  if (af->dir && first_visit(af->dir)) {
    const int removed = sweep_stale(af->dir);
    if (removed)
      fcm__log(ctx, FCM_LOG_INFO,
               "io: removed %d temporary file(s) left in '%s' by processes that no longer run",
               removed, af->dir);
  }
  /* hidden beside the target: ".<name>.tmp.<pid>.<n>", so no glob for outputs
   * (name_*.vtu, *) ever lists it */
  const char *slash = strrchr(path, '/');
  const int dir_len = slash ? (int)(slash - path + 1) : 0;

  /* Unique without shared state: the process id and a per-call seed; O_EXCL makes
   * a collision (another thread or process) visible, and the next number is tried. */
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  uint64_t seed =
      ((uint64_t)(uintptr_t)af ^ (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 20)) % 1000000000u;
  for (int attempt = 0; attempt < TMP_ATTEMPTS; attempt++) {
    snprintf(af->tmp_path, cap, "%.*s.%s" TMP_TAG "%ld.%llu", dir_len, path, path + dir_len,
             (long)getpid(), (unsigned long long)(seed + (uint64_t)attempt));
    fd = open(af->tmp_path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) break;
  }
  if (fd < 0) {
    err = errno;
    sys_error(err, msg, sizeof msg);
    FCM_FREE(ctx, af->tmp_path); /* nothing was created */
    FCM_CHECK(0, ctx, FCM_ERR_IO, "io: cannot create a temporary file to write '%s': %s", path,
              msg);
  }
  af->fp = fdopen(fd, "wb");
  if (!af->fp) {
    err = errno;
    sys_error(err, msg, sizeof msg);
    close(fd);
    FCM_CHECK(0, ctx, FCM_ERR_IO, "io: cannot open a stream to write '%s': %s", path, msg);
  }
cleanup:
  if (st != FCM_OK) fcm__io_atomic_abort(ctx, af);
  return st;
}

fcm_status fcm__io_atomic_write(fcm_ctx *ctx, fcm__atomic_file *af, const void *data, size_t bytes)
{
  fcm_status st = FCM_OK;
  char msg[256];
  size_t todo = bytes;
  int err = 0;
  if (bytes == 0) return FCM_OK;
  FCM_ASSERT(af->fp != NULL, ctx);
  if (af->fault.fail_after_bytes >= 0 &&
      (unsigned long long)af->bytes + bytes > (unsigned long long)af->fault.fail_after_bytes) {
    todo = (size_t)(af->fault.fail_after_bytes - af->bytes); /* a partial write, then EIO */
    err = EIO;
  }
  errno = 0;
  size_t done = fwrite(data, 1, todo, af->fp);
  if (done != todo) err = errno ? errno : EIO;
  af->bytes += (long long)done;
  if (err) {
    sys_error(err, msg, sizeof msg);
    FCM_CHECK(0, ctx, FCM_ERR_IO, "io: writing '%s' failed after %lld bytes: %s", af->path,
              af->bytes, msg);
  }
cleanup:
  return st;
}

fcm_status fcm__io_atomic_printf(fcm_ctx *ctx, fcm__atomic_file *af, const char *fmt, ...)
{
  fcm_status st = FCM_OK;
  char small[512];
  char *big = NULL;
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(small, sizeof small, fmt, ap);
  va_end(ap);
  FCM_CHECK(n >= 0, ctx, FCM_ERR_INTERNAL, "io: formatting output for '%s' failed", af->path);
  if ((size_t)n < sizeof small) {
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, small, (size_t)n));
  } else {
    FCM_ALLOC(ctx, (size_t)n + 1, big);
    va_start(ap, fmt);
    vsnprintf(big, (size_t)n + 1, fmt, ap);
    va_end(ap);
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, big, (size_t)n));
  }
cleanup:
  FCM_FREE(ctx, big);
  return st;
}

fcm_status fcm__io_atomic_write_xml(fcm_ctx *ctx, fcm__atomic_file *af, const char *text)
{
  fcm_status st = FCM_OK;
  const char *run = text;
  for (const char *p = text;; p++) {
    const char *esc = NULL;
    switch (*p) {
    case '&':
      esc = "&amp;";
      break;
    case '<':
      esc = "&lt;";
      break;
    case '>':
      esc = "&gt;";
      break;
    case '"':
      esc = "&quot;";
      break;
    case '\'':
      esc = "&apos;";
      break;
    default:
      break;
    }
    if (!esc && *p) continue;
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, run, (size_t)(p - run)));
    if (!esc) break;
    FCM_TRY(ctx, fcm__io_atomic_write(ctx, af, esc, strlen(esc)));
    run = p + 1;
  }
cleanup:
  return st;
}

fcm_status fcm__io_atomic_commit(fcm_ctx *ctx, fcm__atomic_file *af)
{
  fcm_status st = FCM_OK;
  char msg[256];
  const char *stage = NULL;
  int err = 0;
  FCM_ASSERT(af->fp != NULL && af->tmp_path != NULL, ctx);
  if (af->fault.fail_commit) {
    err = EIO;
    stage = "flushing";
  } else if (fflush(af->fp) != 0) {
    err = errno;
    stage = "flushing";
  } else if (af->durable && fsync(fileno(af->fp)) != 0) {
    err = errno;
    stage = "syncing";
  }
  int rc = fclose(af->fp);
  af->fp = NULL;
  if (!err && rc != 0) {
    err = errno;
    stage = "closing";
  }
  if (!err && rename(af->tmp_path, af->path) != 0) {
    err = errno;
    stage = "renaming the temporary over";
  }
  if (err) {
    sys_error(err, msg, sizeof msg);
    FCM_CHECK(0, ctx, FCM_ERR_IO, "io: %s '%s' failed: %s", stage, af->path, msg);
  }
  FCM_FREE(ctx, af->tmp_path);  /* renamed: nothing to remove */
  if (af->dir && af->durable) { /* the rename itself must survive a power loss */
    int fd = open(af->dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    err = fd < 0 ? errno : fsync(fd) != 0 ? errno : 0;
    if (fd >= 0) close(fd);
    if (err == EINVAL || err == EROFS) err = 0; /* directories that cannot be synced */
    if (err) {
      sys_error(err, msg, sizeof msg);
      FCM_CHECK(0, ctx, FCM_ERR_IO,
                "io: '%s' was written, but syncing its directory '%s' failed: %s (the new "
                "file may not survive a power loss)",
                af->path, af->dir, msg);
    }
  }
cleanup:
  fcm__io_atomic_abort(ctx, af);
  return st;
}

void fcm__io_atomic_abort(fcm_ctx *ctx, fcm__atomic_file *af)
{
  if (!af) return;
  if (af->fp) fclose(af->fp);
  af->fp = NULL;
  if (af->tmp_path) remove(af->tmp_path);
  FCM_FREE(ctx, af->tmp_path);
  FCM_FREE(ctx, af->path);
  FCM_FREE(ctx, af->dir);
}

/* ---------------------------------------------------------------- public wrapper */

struct fcm_atomic_file {
  fcm_ctx *ctx;
  fcm__atomic_file af;
};

fcm_status fcm_atomic_file_open(fcm_ctx *ctx, const char *path, fcm_atomic_file **file)
{
  fcm_status st = FCM_OK;
  fcm_atomic_file *f = NULL;
  FCM_CHECK(file != NULL, ctx, FCM_ERR_ARG, "io: fcm_atomic_file_open: file is NULL");
  *file = NULL;
  FCM_ALLOC(ctx, 1, f);
  f->ctx = ctx;
  FCM_TRY(ctx, fcm__io_atomic_open(ctx, path, 0, NULL, &f->af));
  *file = f;
  f = NULL;
cleanup:
  if (f) fcm__io_atomic_abort(ctx, &f->af);
  FCM_FREE(ctx, f);
  return st;
}

FILE *fcm_atomic_file_stream(fcm_atomic_file *file)
{
  return file ? file->af.fp : NULL;
}

fcm_status fcm_atomic_file_commit(fcm_atomic_file **file)
{
  if (!file || !*file) return FCM_ERR_ARG;
  fcm_atomic_file *f = *file;
  fcm_ctx *ctx = f->ctx;
  fcm_status st = FCM_OK;
  *file = NULL;
  FCM_CHECK(f->af.fp && !ferror(f->af.fp), ctx, FCM_ERR_IO, "io: writing '%s' failed", f->af.path);
  FCM_TRY(ctx, fcm__io_atomic_commit(ctx, &f->af));
cleanup:
  fcm__io_atomic_abort(ctx, &f->af);
  FCM_FREE(ctx, f);
  return st;
}

void fcm_atomic_file_abort(fcm_atomic_file **file)
{
  if (!file || !*file) return;
  fcm_atomic_file *f = *file;
  fcm_ctx *ctx = f->ctx;
  *file = NULL;
  fcm__io_atomic_abort(ctx, &f->af);
  FCM_FREE(ctx, f);
}
