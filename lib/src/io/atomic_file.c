/* Atomic replacement of output files: write a uniquely named temporary beside the
 * target, check every flush and close, rename over the target, or remove it on error. */
#define _POSIX_C_SOURCE 200809L
#include "io/io_impl.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define TMP_ATTEMPTS 100

/* Thread-safe text of a system error (the XSI strerror_r). */
static void sys_error(int err, char *buf, size_t len)
{
  if (strerror_r(err, buf, len) != 0) snprintf(buf, len, "system error %d", err);
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

  /* Unique without shared state: the process id and a per-call seed; O_EXCL makes
   * a collision (another thread or process) visible, and the next number is tried. */
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  uint64_t seed =
      ((uint64_t)(uintptr_t)af ^ (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 20)) % 1000000000u;
  for (int attempt = 0; attempt < TMP_ATTEMPTS; attempt++) {
    snprintf(af->tmp_path, cap, "%s.tmp.%ld.%llu", path, (long)getpid(),
             (unsigned long long)(seed + (uint64_t)attempt));
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
  FCM_FREE(ctx, af->tmp_path); /* renamed: nothing to remove */
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

FILE *fcm_atomic_file_stream(fcm_atomic_file *file) { return file ? file->af.fp : NULL; }

fcm_status fcm_atomic_file_commit(fcm_atomic_file **file)
{
  if (!file || !*file) return FCM_ERR_ARG;
  fcm_atomic_file *f = *file;
  fcm_ctx *ctx = f->ctx;
  fcm_status st = FCM_OK;
  *file = NULL;
  FCM_CHECK(f->af.fp && !ferror(f->af.fp), ctx, FCM_ERR_IO, "io: writing '%s' failed",
            f->af.path);
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
