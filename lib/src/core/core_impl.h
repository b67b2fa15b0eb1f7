/* fcm core, internal part: the error idiom, allocation and logging helpers
 * every module uses. Not installed. */
#ifndef FCM_CORE_IMPL_H
#define FCM_CORE_IMPL_H

#include "fcm/core.h"

#include <limits.h>
#include <stdarg.h>

#if defined(__GNUC__)
#define FCM__PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define FCM__PRINTF(f, a)
#endif

/* An internal function that fcm's PETSc component (libfcm_petsc: lib/src/petsc and the scene
 * runner's distributed path, a library of its own on top of libfcm) calls: exported by the
 * shared libfcm, as the FCM_API functions are, but declared in no installed header, so it is no
 * part of the API (the fcm__ prefix). Only functions the component needs carry it; `bash
 * setup.sh install-check` checks that libfcm exports no other internal name. */
#if defined(FCM_BUILDING_LIBRARY) && defined(__GNUC__)
#define FCM_COMPONENT_API __attribute__((visibility("default")))
#else
#define FCM_COMPONENT_API
#endif

/* Record a new error in ctx (replacing any previous one, starting a fresh
 * traceback at file:line), log it at FCM_LOG_ERROR and return `code`.
 * Thread safe: concurrent errors keep one of them. ctx may be NULL. */
FCM_COMPONENT_API fcm_status fcm__error(fcm_ctx *ctx, fcm_status code, const char *file, int line,
                                        const char *func, const char *fmt, ...) FCM__PRINTF(6, 7);

/* Append a traceback frame to the recorded error. */
FCM_COMPONENT_API void fcm__trace(fcm_ctx *ctx, const char *file, int line, const char *func);

/* Prepend "prefix: " to the message of the error recorded in ctx (its traceback is kept);
 * nothing when no error is recorded. Not for use inside a parallel loop iteration. */
FCM_COMPONENT_API void fcm__error_prefix(fcm_ctx *ctx, const char *prefix);

/* Format a message and pass it to the log callback when level is enabled. */
void fcm__log(const fcm_ctx *ctx, fcm_log_level level, const char *fmt, ...) FCM__PRINTF(3, 4);

/* Notices given at most once per context (flags of fcm__ctx_once). */
enum { FCM__ONCE_BLAS_KERNELS = 1u << 0 };

/* 1 the first time it is called with `flag` on ctx, then 0 (thread safe); 0 for a NULL ctx. */
int fcm__ctx_once(fcm_ctx *ctx, unsigned flag);

/* Zero-filled array of n elements of `size` bytes through ctx's allocator.
 * Returns NULL on overflow or allocation failure (and records FCM_ERR_ALLOC).
 * n == 0 still returns a valid (1-byte) allocation. */
FCM_COMPONENT_API void *fcm__calloc(fcm_ctx *ctx, size_t n, size_t size);

/* As fcm__calloc, without the zero fill: for arrays written in full before they are read. */
FCM_COMPONENT_API void *fcm__malloc(fcm_ctx *ctx, size_t n, size_t size);

/* Release memory from fcm__calloc or fcm__malloc; accepts NULL. */
FCM_COMPONENT_API void fcm__free(fcm_ctx *ctx, void *ptr);

/* Arrays of at least this many bytes get huge-page alignment and a quarter more room from
 * fcm__calloc_large(); smaller ones neither. */
#define FCM__LARGE_MIN ((size_t)8 << 20)

/* As fcm__calloc for large arrays that are written all over (assembled matrix values): from
 * 8 MiB on, the array starts on a 2 MiB boundary and, on Linux, is advised to transparent huge
 * pages before its zero fill touches it; smaller ones are 64-byte aligned. Counted and failing
 * like fcm__calloc (one allocation through ctx's allocator, a little larger than asked; from
 * 8 MiB on, a quarter larger: room left untouched for fcm__calloc_large_from()).
 * Released with fcm__free_large only. */
void *fcm__calloc_large(fcm_ctx *ctx, size_t n, size_t size);

/* As fcm__calloc_large without the zero fill: for arrays whose entries are written before
 * they are read; pages never written are never touched (address space only). */
void *fcm__malloc_large(fcm_ctx *ctx, size_t n, size_t size);

/* Maps every page of the room of p (an array of fcm__calloc_large / fcm__malloc_large, or
 * NULL), its contents kept (each page read and written back once), so that the array's
 * successor (fcm__large_take()) grows into it without the first touch of fresh pages during a
 * cut (several milliseconds per 2 MiB huge page on some virtual machines). Costs the room as
 * resident memory (from FCM__LARGE_MIN on a quarter more than asked). Once per array: an
 * array mapped before (taken over since) returns at once. No other thread may use p
 * meanwhile. */
void fcm__large_map(void *p);

/* As fcm__calloc_large, on the storage of *from (an array of fcm__calloc_large, or NULL) when
 * n elements fill at least half of its room (a large array's room is a quarter more than it
 * was asked for): *from is then set to NULL (its owner gives it up) and the array zero filled
 * again, on pages already mapped. Otherwise a new array, *from untouched. */
void *fcm__calloc_large_from(fcm_ctx *ctx, void **from, size_t n, size_t size);

/* *from (an array of fcm__calloc_large, or NULL) as an array of n elements, its contents as
 * they are, when they fill at least half of its room: *from is then set to NULL. Else NULL,
 * *from untouched. */
void *fcm__large_take(void **from, size_t n, size_t size);

/* Release memory from fcm__calloc_large; accepts NULL. */
void fcm__free_large(fcm_ctx *ctx, void *ptr);

/* Grow or shrink an fcm__calloc array, preserving min(old_n, new_n) elements and
 * zero-filling the rest. On failure *ptr is unchanged. */
FCM_COMPONENT_API fcm_status fcm__resize(fcm_ctx *ctx, void **ptr, size_t old_n, size_t new_n,
                                         size_t size);

/* Checked narrowing of a global index to int (LAPACK, GLPK, CHOLMOD sizes). */
fcm_status fcm__index_to_int(fcm_ctx *ctx, fcm_index v, const char *what, int *out);

/* Read the whole regular file `path` into a NUL-terminated buffer of *size + 1 bytes
 * (released with fcm__free). A directory, device, pipe or socket is refused with
 * FCM_ERR_IO naming it, before any read (a pipe is not waited on), as is a file larger
 * than max_bytes. Messages start with `what` (the reader's name). */
fcm_status fcm__file_read_all(fcm_ctx *ctx, const char *what, const char *path, size_t max_bytes,
                              char **data, size_t *size);

/* ---- errors of parallel loops: recorded once, the lowest failing iteration wins ----
 *
 * Inside an iteration bracketed by fcm__loop_enter()/fcm__loop_leave(), errors recorded on
 * the loop's ctx (FCM_CHECK, FCM_ALLOC, fcm__calloc, FCM_TRY frames) go to the iteration's
 * own record instead of the ctx, so threads never overwrite each other's message.
 * fcm__loop_end() then records the error of the lowest failing iteration in the ctx and
 * logs it once: the reported error does not depend on the thread count or scheduling.
 *
 *   fcm__loop L;
 *   fcm__loop_begin(ctx, &L);
 *   #pragma omp parallel for
 *   for (i = 0; i < n; i++) {
 *     if (fcm__loop_skip(&L, i)) continue;          // a lower iteration already failed
 *     fcm__loop_iter it;
 *     fcm__loop_enter(&L, &it, i);
 *     fcm__loop_leave(&L, &it, work(i));            // the iteration's status
 *   }
 *   FCM_TRY(ctx, fcm__loop_end(&L, &failed_index)); // FCM_OK or the lowest failure
 *
 * Loops nest (an iteration may run a loop of its own; its error becomes the iteration's).
 * An iteration that handles an error and returns FCM_OK leaves nothing behind. */
#define FCM__LOOP_MSG_LEN 1024
#define FCM__LOOP_FRAMES  32

/* An error message with its traceback (code FCM_OK: none). */
typedef struct fcm__error_record {
  fcm_status code;
  char msg[FCM__LOOP_MSG_LEN];
  struct {
    const char *file, *func;
    int line;
  } frames[FCM__LOOP_FRAMES];
  int nframes, frames_dropped;
} fcm__error_record;

typedef struct fcm__loop {
  fcm_ctx *ctx;
  fcm_index failed;      /* lowest iteration that returned an error; -1: none */
  fcm_status status;     /* its status */
  fcm__error_record rec; /* its message (code FCM_OK: it recorded none) */
} fcm__loop;

/* One iteration in progress (on the stack of the thread running it). */
typedef struct fcm__loop_iter {
  fcm__loop *loop;
  fcm_index index;
  struct fcm__loop_iter *prev; /* the iteration this thread was in before (nesting) */
  fcm__error_record rec;
} fcm__loop_iter;

/* Start a loop on ctx (no allocation). */
void fcm__loop_begin(fcm_ctx *ctx, fcm__loop *loop);

/* Whether iteration i can be skipped: an iteration below i has already failed. */
int fcm__loop_skip(fcm__loop *loop, fcm_index i);

/* Errors on loop->ctx from this thread now belong to iteration i (recorded in *it). */
void fcm__loop_enter(fcm__loop *loop, fcm__loop_iter *it, fcm_index i);

/* End iteration `it`, which returned `st`. */
void fcm__loop_leave(fcm__loop *loop, fcm__loop_iter *it, fcm_status st);

/* After the parallel region: FCM_OK, or the status of the lowest failing iteration with
 * its message and traceback recorded in the ctx (or in the enclosing loop's iteration).
 * `failed` (may be NULL) receives that iteration, -1 if none. */
fcm_status fcm__loop_end(fcm__loop *loop, fcm_index *failed);

/* ---- the one error idiom: every function has `fcm_status st` and `cleanup:` ---- */

/* Fail with `code` and a formatted message unless `cond` holds. */
#define FCM_CHECK(cond, ctx, code, ...)                                                            \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      st = fcm__error((ctx), (code), __FILE__, __LINE__, __func__, __VA_ARGS__);                   \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)

/* Propagate a failing status from `call`, adding a traceback frame. */
#define FCM_TRY(ctx, call)                                                                         \
  do {                                                                                             \
    st = (call);                                                                                   \
    if (st != FCM_OK) {                                                                            \
      fcm__trace((ctx), __FILE__, __LINE__, __func__);                                             \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)

/* Allocate `n` elements of *p's type into p through `fn` (fcm__calloc or fcm__malloc), or
 * fail with FCM_ERR_ALLOC. */
#define FCM__ALLOC_WITH(fn, ctx, n, p)                                                             \
  do {                                                                                             \
    (p) = fn((ctx), (size_t)(n), sizeof *(p));                                                     \
    if (!(p)) {                                                                                    \
      st = FCM_ERR_ALLOC;                                                                          \
      fcm__trace((ctx), __FILE__, __LINE__, __func__);                                             \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)

/* Allocate `n` zeroed elements of *p's type into p, or fail with FCM_ERR_ALLOC. */
#define FCM_ALLOC(ctx, n, p) FCM__ALLOC_WITH(fcm__calloc, ctx, n, p)

/* As FCM_ALLOC without the zero fill (fcm__malloc): every element is written before use. */
#define FCM_ALLOC_RAW(ctx, n, p) FCM__ALLOC_WITH(fcm__malloc, ctx, n, p)

/* Free and reset to NULL. */
#define FCM_FREE(ctx, p)                                                                           \
  do {                                                                                             \
    fcm__free((ctx), (p));                                                                         \
    (p) = NULL;                                                                                    \
  } while (0)

/* Internal invariant; compiled out of release (NDEBUG) builds. */
#ifdef NDEBUG
#define FCM_ASSERT(cond, ctx) ((void)0)
#else
#define FCM_ASSERT(cond, ctx)                                                                      \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      st = fcm__error((ctx), FCM_ERR_INTERNAL, __FILE__, __LINE__, __func__,                       \
                      "assertion failed: %s", #cond);                                              \
      goto cleanup;                                                                                \
    }                                                                                              \
  } while (0)
#endif

/* Largest coordinate magnitude the mesh, geometry and surface readers and constructors
 * accept. The geometry computations form products of up to about six coordinates (or of
 * their differences): a volume is a cube, the squared norm of a normal a fourth power, a
 * tolerance times such a norm more; at 1e50 a sixth power of a difference still stays below
 * 1e303, while squares overflow from about 1.3e154 on and fourth powers from 1.3e77. A
 * coordinate beyond the limit is refused as out of range instead of surfacing later as a
 * degenerate triangle or a non-finite volume. */
#define FCM__COORD_MAX 1e50
/* The range as messages state it. */
#define FCM__COORD_RANGE                                                                           \
  "the supported range [-1e50, 1e50] (larger magnitudes overflow the products of coordinates "     \
  "in volumes and normals)"

#define FCM_MIN(a, b) ((a) < (b) ? (a) : (b))
#define FCM_MAX(a, b) ((a) > (b) ? (a) : (b))

/* The first i in [lo, hi) with a[stride * i] >= key, hi when none: a lower-bound bisection
 * over a[stride * lo], ..., a[stride * (hi - 1)] ascending (stride 1: a sorted list; 2: pairs
 * sorted by their first entries). */
static inline fcm_index fcm__lower_bound(const fcm_index *a, fcm_index stride, fcm_index lo,
                                         fcm_index hi, fcm_index key)
{
  while (lo < hi) {
    const fcm_index mid = lo + (hi - lo) / 2;
    if (a[stride * mid] < key)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/* a[0..n) ascending by insertion (a few entries). */
static inline void fcm__insertion_sort(fcm_index *a, fcm_index n)
{
  for (fcm_index i = 1; i < n; i++) {
    const fcm_index v = a[i];
    fcm_index j = i;
    for (; j > 0 && a[j - 1] > v; j--)
      a[j] = a[j - 1];
    a[j] = v;
  }
}

#endif /* FCM_CORE_IMPL_H */
