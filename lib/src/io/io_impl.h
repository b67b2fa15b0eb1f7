/* fcm io, internal part: atomic replacement of output files, shared by every writer
 * (VTU, PVD, CSV logs, checkpoints, rule tables), and the fault hook their tests use. */
#ifndef FCM_IO_IMPL_H
#define FCM_IO_IMPL_H

#include "core/core_impl.h"
#include "fcm/io.h"

#include <stdio.h>

/* Simulated failures for tests of the error paths; library callers pass NULL. */
typedef struct fcm__io_fault {
  long long
      fail_after_bytes; /* the write that would pass this many bytes fails (EIO); < 0: never */
  int fail_commit;      /* the commit fails (EIO, as fflush/fsync/fclose could) */
} fcm__io_fault;

/* An output file being written: the data goes to the hidden "<dir>/.<name>.tmp.<pid>.<n>"
 * (created exclusively, mode 0666 minus umask; no glob for outputs such as name_*.vtu or *
 * matches it) and replaces `path` only at commit. */
typedef struct fcm__atomic_file {
  FILE *fp;
  char *path;      /* the target (copy) */
  char *tmp_path;  /* the temporary (NULL once renamed or removed) */
  char *dir;       /* the target's directory */
  long long bytes; /* written so far */
  int durable;     /* fsync the file before the rename and its directory after it; other files
                      (frames, logs) are only renamed: whole or absent, not forced to disk */
  fcm__io_fault fault;
} fcm__atomic_file;

/* Create the temporary beside `path`. The first open into a directory in a process also
 * removes the temporaries there whose writer process no longer exists (left by kill -9 or
 * a crash; only files named as ours, never a live process's). On failure (FCM_ERR_IO naming `path`
 * and the system error, FCM_ERR_ALLOC) nothing is left behind and `af` needs no abort, though
 * fcm__io_atomic_abort() is harmless. `fault` may be NULL. */
fcm_status fcm__io_atomic_open(fcm_ctx *ctx, const char *path, int durable,
                               const fcm__io_fault *fault, fcm__atomic_file *af);

/* Write `bytes` bytes; FCM_ERR_IO (naming the path and the system error) on a short write. */
fcm_status fcm__io_atomic_write(fcm_ctx *ctx, fcm__atomic_file *af, const void *data, size_t bytes);

/* Formatted text; may allocate a buffer for long output. */
fcm_status fcm__io_atomic_printf(fcm_ctx *ctx, fcm__atomic_file *af, const char *fmt, ...)
    FCM__PRINTF(3, 4);

/* Text with the XML attribute escapes &amp; &lt; &gt; &quot; &apos;. */
fcm_status fcm__io_atomic_write_xml(fcm_ctx *ctx, fcm__atomic_file *af, const char *text);

/* fflush, fsync when durable, fclose (each checked), then rename over the target and,
 * when durable, fsync the directory. On any failure before the rename the temporary is removed,
 * the target is untouched and FCM_ERR_IO names the path and the system error (a failing
 * directory sync is FCM_ERR_IO too, with the new file in place). `af` is released either
 * way. */
fcm_status fcm__io_atomic_commit(fcm_ctx *ctx, fcm__atomic_file *af);

/* Close and remove the temporary and release `af`; accepts an unopened or released
 * `af` (zero-initialize it before open). Never fails. */
void fcm__io_atomic_abort(fcm_ctx *ctx, fcm__atomic_file *af);

/* Whether `s` is non-empty and has no control characters (valid in an XML attribute). */
int fcm__io_printable(const char *s);

/* Copy a string through the ctx allocator. */
fcm_status fcm__io_strdup(fcm_ctx *ctx, const char *s, char **out);

/* "LittleEndian" or "BigEndian": the host's byte order, found at run time. */
const char *fcm__io_byte_order(void);

/* x with 17 significant digits (round trip exact) and '.' as decimal point whatever
 * the C locale. */
void fcm__io_format_double(double x, char buf[32]);

/* fcm_vtu_write() with a fault plan (tests only). */
fcm_status fcm__vtu_write_fault(fcm_vtu *vtu, const char *path, fcm_vtu_info *info,
                                const fcm__io_fault *fault);

/* fcm_pvd_add() with a fault plan (tests only). */
fcm_status fcm__pvd_add_fault(fcm_pvd *pvd, double time, const char *file,
                              const fcm__io_fault *fault);

#endif /* FCM_IO_IMPL_H */
