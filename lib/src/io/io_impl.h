/* fcm io, internal part: atomic replacement of output files, shared by every writer
 * (VTU, PVD, CSV logs, checkpoints, rule tables), and the fault hook their tests use. */
#ifndef FCM_IO_IMPL_H
#define FCM_IO_IMPL_H

#include "core/core_impl.h"
#include "fcm/io.h"

#include <stdint.h>
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

/* A PVD collection of one data set in parts (at time 0): part i is the file files[i] (relative
 * to the index's directory) named names[i]; n in [0, FCM__PVD_MAX_PARTS]. Written atomically to
 * `path`.
 * FCM_ERR_ARG (a name or file empty or unprintable), FCM_ERR_IO, FCM_ERR_ALLOC. */
#define FCM__PVD_MAX_PARTS 16
fcm_status fcm__pvd_write_parts(fcm_ctx *ctx, const char *path, int n, const char *const *names,
                                const char *const *files);

/* fcm_pvd_add() with a fault plan (tests only). */
fcm_status fcm__pvd_add_fault(fcm_pvd *pvd, double time, const char *file,
                              const fcm__io_fault *fault);

/* ---- checkpoint container (checkpoint_file.c) ----
 *
 * 8 bytes magic, u64 version, u64 byte-order mark, the writer's payload of typed values, u64
 * FNV-1a 64 checksum of every byte before it (host byte order). The writer goes through a
 * durable atomic file: a failed or aborted write leaves the target untouched. */

#define FCM__FNV_OFFSET 0xcbf29ce484222325ull

/* The magic of fcm's checkpoints (8 bytes with the NUL). */
#define FCM__CKPT_MAGIC "FCMCKPT"

/* FNV-1a 64 of n bytes, continuing h (start with FCM__FNV_OFFSET). */
uint64_t fcm__io_fnv(uint64_t h, const void *data, size_t n);

typedef struct fcm__ckpt_writer {
  fcm_ctx *ctx;
  fcm__atomic_file af;
  uint64_t hash; /* of every byte written so far */
} fcm__ckpt_writer;

/* Open the temporary beside `path` and write the header. On failure nothing is left behind. */
FCM_COMPONENT_API fcm_status fcm__ckpt_open(fcm_ctx *ctx, const char *path, const char magic[8],
                                            uint64_t version, fcm__ckpt_writer *w);

/* Payload values: raw bytes, integers as int64/uint64, doubles as binary64. */
fcm_status fcm__ckpt_put(fcm__ckpt_writer *w, const void *data, size_t n);
fcm_status fcm__ckpt_put_u64(fcm__ckpt_writer *w, uint64_t x);
fcm_status fcm__ckpt_put_i64(fcm__ckpt_writer *w, long long x);
fcm_status fcm__ckpt_put_f64(fcm__ckpt_writer *w, double x);
fcm_status fcm__ckpt_put_f64s(fcm__ckpt_writer *w, const double *x, size_t n);

/* Append the checksum and replace the target; on failure the temporary is removed. */
FCM_COMPONENT_API fcm_status fcm__ckpt_commit(fcm__ckpt_writer *w);

/* Drop an unfinished file (after a failed put); harmless after commit or a failed open. */
FCM_COMPONENT_API void fcm__ckpt_abort(fcm__ckpt_writer *w);

typedef struct fcm__ckpt_reader {
  fcm_ctx *ctx;
  const char *path;
  unsigned char *data;
  size_t size;       /* the payload's end (the checksum excluded) */
  size_t pos;        /* the next value */
  uint64_t version;  /* the file's (0 for the legacy linear-driver file) */
  int legacy_linear; /* the linear driver's older ".fcmpk" (no header, no checksum) */
} fcm__ckpt_reader;

/* Read the whole file and check it: the magic, the byte-order mark, the version in
 * [1, max_version] and the checksum; the reader then stands at the payload. A file of the
 * linear driver's older format ("fcm-petsc-ck-1") is accepted with legacy_linear set and the
 * reader after its magic line (read it with fcm__ckpt_get_linear()). Errors name the file and
 * what is wrong: FCM_ERR_IO (cannot read), FCM_ERR_FORMAT (not a checkpoint, other byte order,
 * unknown version, truncated or corrupted), FCM_ERR_ALLOC. Release with
 * fcm__ckpt_read_close() (also after a failure). */
FCM_COMPONENT_API fcm_status fcm__ckpt_read_open(fcm_ctx *ctx, const char *path,
                                                 const char magic[8], uint64_t max_version,
                                                 fcm__ckpt_reader *r);
FCM_COMPONENT_API void fcm__ckpt_read_close(fcm__ckpt_reader *r);

/* The next n bytes (FCM_ERR_FORMAT naming `what` when the file ends first). */
FCM_COMPONENT_API fcm_status fcm__ckpt_get(fcm__ckpt_reader *r, void *out, size_t n,
                                           const char *what);
FCM_COMPONENT_API fcm_status fcm__ckpt_get_u64(fcm__ckpt_reader *r, uint64_t *x, const char *what);
/* An integer in [lo, hi] (FCM_ERR_FORMAT naming `what`, the value and the range). */
fcm_status fcm__ckpt_get_i64(fcm__ckpt_reader *r, long long *x, long long lo, long long hi,
                             const char *what);
fcm_status fcm__ckpt_get_f64(fcm__ckpt_reader *r, double *x, const char *what);

/* `count` records of `each` bytes fit in what is left (checked before allocating for them). */
fcm_status fcm__ckpt_need(fcm__ckpt_reader *r, long long count, size_t each, const char *what);

/* Nothing is left after the payload (FCM_ERR_FORMAT: trailing bytes). */
FCM_COMPONENT_API fcm_status fcm__ckpt_read_end(fcm__ckpt_reader *r);

/* The payload of a checkpoint without a scene (the PETSc linear driver): the source word
 * FCM__CKPT_SOURCE_LINEAR where a scene run writes its scene's fingerprint (never 0), then
 * i64 num_dofs, elements, steps, integrator kind; f64 time, dt; num_dofs x f64 displacement,
 * num_dofs x f64 velocity (the space's DOF numbering). The older ".fcmpk" holds the same
 * values after its magic line. */
#define FCM__CKPT_SOURCE_LINEAR 0ull

/* The container's version, the same for every writer so that each reader recognizes the other's
 * files: 4 introduced the linear driver's payload (the scene reader reads it from version 4 on),
 * 5 the Newton tolerance in a scene run's log rows, 6 the time scheme, its parameters, the
 * acceleration and the load work of a scene run (and the energies in its log rows), 7 the
 * contact columns of its log rows. */
#define FCM__CKPT_VERSION 7u

typedef struct fcm__ckpt_linear {
  long long num_dofs, elements, steps, kind;
  double time, dt;
} fcm__ckpt_linear;

/* The source word, the counts and the state. */
FCM_COMPONENT_API fcm_status fcm__ckpt_put_linear(fcm__ckpt_writer *w, const fcm__ckpt_linear *h,
                                                  const double *u, const double *v);

/* The counts after the source word (or the legacy magic line), checked in range, and that the
 * state's 2 num_dofs doubles follow (read them with fcm__ckpt_get(), then
 * fcm__ckpt_read_end()). */
FCM_COMPONENT_API fcm_status fcm__ckpt_get_linear(fcm__ckpt_reader *r, fcm__ckpt_linear *h);

#endif /* FCM_IO_IMPL_H */
