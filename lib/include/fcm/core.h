/* fcm — finite cell method library.
 * Core: status codes, the context object (allocation, logging, errors), timers. */
#ifndef FCM_CORE_H
#define FCM_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(FCM_BUILDING_LIBRARY) && defined(__GNUC__)
#define FCM_API __attribute__((visibility("default")))
#else
#define FCM_API
#endif

/** Global (64-bit) index type: nodes, DOFs, non-zeros, points of a mesh. */
typedef int64_t fcm_index;

/** One list generates the status enum and the messages of fcm_status_name(). */
#define FCM_STATUS_LIST(X)                                                                         \
  X(FCM_OK, "success")                                                                             \
  X(FCM_ERR_ARG, "invalid argument")                                                               \
  X(FCM_ERR_ALLOC, "out of memory")                                                                \
  X(FCM_ERR_IO, "input/output error")                                                              \
  X(FCM_ERR_FORMAT, "malformed input")                                                             \
  X(FCM_ERR_LAPACK, "dense linear algebra routine failed")                                         \
  X(FCM_ERR_SINGULAR, "matrix is singular or not positive definite")                               \
  X(FCM_ERR_NOT_CONVERGED, "iteration did not converge")                                           \
  X(FCM_ERR_NUMERIC, "NaN or infinity encountered")                                                \
  X(FCM_ERR_LP, "linear program failed")                                                           \
  X(FCM_ERR_GEOMETRY, "invalid or degenerate geometry")                                            \
  X(FCM_ERR_UNSUPPORTED, "operation not supported")                                                \
  X(FCM_ERR_INTERNAL, "internal error")

#define FCM_STATUS_ENUM_(name, msg) name,
/** Every fallible fcm function returns one of these; FCM_OK is zero. */
typedef enum fcm_status { FCM_STATUS_LIST(FCM_STATUS_ENUM_) FCM_STATUS_COUNT_ } fcm_status;
#undef FCM_STATUS_ENUM_

/** Static description of a status code ("invalid argument", ...); never NULL. */
FCM_API const char *fcm_status_name(fcm_status st);

/** The one "use the default" value of option members (and of the parameters documented so):
 * a member set to FCM_DEFAULT takes the default documented on it, which is computed where
 * it depends on the problem (element strengths, OpenMP threads, gravity, the scene).
 * fcm_x_options_default() stores FCM_DEFAULT in such members and the fixed number in the
 * others; 0 always keeps its literal meaning (a strength-0 rule, never, none). */
#define FCM_DEFAULT (-1)

/** Severity of a log message passed to the log callback: ERROR for every recorded error
 * (with its message), WARNING for counted fallbacks that change how a result is computed
 * (a simplification that keeps the input rule, CHOLMOD -> UMFPACK) and, once per context,
 * for BLAS kernels below the CPU's instruction set (fcm_blas_info_get()), INFO for housekeeping
 * the caller did not ask for (stale temporary files of dead processes removed). The library
 * emits nothing else, so there is no lower level. */
typedef enum fcm_log_level {
  FCM_LOG_ERROR = 0,
  FCM_LOG_WARNING = 1,
  FCM_LOG_INFO = 2
} fcm_log_level;

/** Log callback: `msg` is a complete line without the trailing newline. */
typedef void (*fcm_log_fn)(void *user, fcm_log_level level, const char *msg);

/** Allocator hook. `alloc` returns NULL on failure; `release` accepts NULL.
 * Both may be called from several threads at once. */
typedef struct fcm_allocator {
  void *(*alloc)(void *user, size_t size);
  void (*release)(void *user, void *ptr);
  void *user;
} fcm_allocator;

/** Options of fcm_ctx_create(); initialize with fcm_ctx_options_default(). */
typedef struct fcm_ctx_options {
  fcm_allocator allocator; /**< all-NULL members: malloc/free */
  fcm_log_fn log;          /**< NULL: the library stays silent */
  void *log_user;          /**< passed to `log` */
  fcm_log_level log_level; /**< messages above this level are not formatted (default
                                WARNING: errors and warnings) */
  int num_threads;         /**< OpenMP threads of the library's parallel loops (cut-cell
                                rules, assembly, solvers, preconditioners, multigrid), >= 1;
                                FCM_DEFAULT (default): the OpenMP default at each call,
                                omp_get_max_threads(). Results do not depend on it.
                                fcm_ctx_set_num_threads() changes it */
} fcm_ctx_options;

/** The root object: allocator, log callback, last error. No global state exists
 * elsewhere; objects created from a context must be destroyed before it. */
typedef struct fcm_ctx fcm_ctx;

/** Default options: system allocator, no logging, level FCM_LOG_WARNING, FCM_DEFAULT threads. */
FCM_API fcm_ctx_options fcm_ctx_options_default(void);

/** Create a context.
 * @param[in]  opts options, copied; NULL means fcm_ctx_options_default()
 * @param[out] ctx  the new context, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (ctx NULL, allocator half set, num_threads neither >= 1 nor
 *         FCM_DEFAULT), FCM_ERR_ALLOC.
 * Allocates through the given allocator. Thread safe. */
FCM_API fcm_status fcm_ctx_create(const fcm_ctx_options *opts, fcm_ctx **ctx);

/** Destroy a context; accepts NULL and `*ctx == NULL`, sets `*ctx = NULL`. */
FCM_API void fcm_ctx_destroy(fcm_ctx **ctx);

/** Number of allocations made through `ctx` and not yet released (0 when every
 * object created from it has been destroyed). */
FCM_API long long fcm_ctx_live_allocations(const fcm_ctx *ctx);

/** The context's thread count (fcm_ctx_options.num_threads): the number set, or the OpenMP
 * default (omp_get_max_threads()) for FCM_DEFAULT or a NULL ctx; always >= 1. */
FCM_API int fcm_ctx_num_threads(const fcm_ctx *ctx);

/** Set the context's thread count: num_threads >= 1, or FCM_DEFAULT for the OpenMP default.
 * @return FCM_OK, FCM_ERR_ARG (ctx NULL, num_threads out of range: named). No allocation;
 * not while another thread calls the library with `ctx`. */
FCM_API fcm_status fcm_ctx_set_num_threads(fcm_ctx *ctx, int num_threads);

/** Status of the last error recorded in `ctx` (FCM_OK when none). */
FCM_API fcm_status fcm_ctx_error_status(const fcm_ctx *ctx);

/** Message of the last error ("" when none). The pointer stays valid until the
 * next failing call on `ctx` or fcm_ctx_error_clear(). */
FCM_API const char *fcm_ctx_error_message(const fcm_ctx *ctx);

/** Print the last error, its status and its traceback (innermost frame first)
 * to `stream`. Prints nothing when no error is recorded. */
FCM_API void fcm_ctx_error_view(const fcm_ctx *ctx, FILE *stream);

/** Forget the last error. */
FCM_API void fcm_ctx_error_clear(fcm_ctx *ctx);

/** Wall-clock seconds from a monotonic clock (arbitrary origin). */
FCM_API double fcm_wtime(void);

/** Accumulating stopwatch: start/stop pairs add to `total`. Plain value type. */
typedef struct fcm_timer {
  double total;    /**< accumulated seconds */
  double started;  /**< fcm_wtime() at the last start, negative when stopped */
  long long count; /**< completed start/stop intervals */
} fcm_timer;

/** A stopped timer with zero total. */
FCM_API fcm_timer fcm_timer_init(void);
/** Start (restart) the interval; no effect on a running timer. */
FCM_API void fcm_timer_start(fcm_timer *t);
/** Stop the interval and add it to the total; no effect on a stopped timer. */
FCM_API void fcm_timer_stop(fcm_timer *t);

#ifdef __cplusplus
}
#endif
#endif /* FCM_CORE_H */
