/* Whole-file input for the readers (meshes, geometries, scenes, checkpoints): regular
 * files only, read through the ctx allocator with an upper bound on the size. */
#define _POSIX_C_SOURCE 200809L
#include "core_impl.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Thread-safe text of a system error (the XSI strerror_r). */
static void sys_error(int err, char *buf, size_t len)
{
  if (strerror_r(err, buf, len) != 0) snprintf(buf, len, "system error %d", err);
}

fcm_status fcm__file_read_all(fcm_ctx *ctx, const char *what, const char *path, size_t max_bytes,
                              char **data, size_t *size)
{
  fcm_status st = FCM_OK;
  char msg[128];
  char *buf = NULL;
  struct stat sb;
  int fd = -1;
  FCM_CHECK(data && size, ctx, FCM_ERR_ARG, "%s: NULL output arguments", what);
  *data = NULL, *size = 0;
  FCM_CHECK(path, ctx, FCM_ERR_ARG, "%s: file name is NULL", what);
  /* O_NONBLOCK: opening a FIFO must not wait for a writer before we can refuse it */
  fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    sys_error(errno, msg, sizeof msg);
    FCM_CHECK(0, ctx, FCM_ERR_IO, "%s: cannot open '%s': %s", what, path, msg);
  }
  if (fstat(fd, &sb) != 0) {
    sys_error(errno, msg, sizeof msg);
    FCM_CHECK(0, ctx, FCM_ERR_IO, "%s: cannot stat '%s': %s", what, path, msg);
  }
  FCM_CHECK(S_ISREG(sb.st_mode), ctx, FCM_ERR_IO,
            "%s: '%s' is not a regular file (%s); give the path of a file", what, path,
            S_ISDIR(sb.st_mode)    ? "a directory"
            : S_ISFIFO(sb.st_mode) ? "a pipe"
            : S_ISCHR(sb.st_mode)  ? "a character device"
            : S_ISBLK(sb.st_mode)  ? "a block device"
                                   : "a socket or other special file");
  FCM_CHECK(sb.st_size >= 0 && (unsigned long long)sb.st_size <= max_bytes, ctx, FCM_ERR_IO,
            "%s: '%s' has %lld bytes, more than the %zu bytes this reader accepts", what, path,
            (long long)sb.st_size, max_bytes);
  /* Read until the end of the file, never beyond the size found above (+1 to see
   * growth): a file that grows while being read is refused rather than followed. */
  size_t len = (size_t)sb.st_size, got = 0;
  FCM_ALLOC(ctx, len + 2, buf);
  while (got < len + 1) {
    ssize_t n = read(fd, buf + got, len + 1 - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      sys_error(errno, msg, sizeof msg);
      FCM_CHECK(0, ctx, FCM_ERR_IO, "%s: cannot read '%s': %s", what, path, msg);
    }
    if (n == 0) break;
    got += (size_t)n;
  }
  FCM_CHECK(got == len, ctx, FCM_ERR_IO,
            "%s: '%s' changed size while being read (%zu bytes expected, %s%zu read)", what, path,
            len, got > len ? "more than " : "", got > len ? len : got);
  buf[len] = '\0';
  *data = buf, *size = len;
  buf = NULL;
cleanup:
  if (fd >= 0) close(fd);
  fcm__free(ctx, buf);
  return st;
}
