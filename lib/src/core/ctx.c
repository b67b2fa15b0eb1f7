/* The fcm context: allocator hook with live-allocation count, log callback,
 * last error with traceback, status strings. */
#include "core_impl.h"

#include <omp.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define FCM__MAX_FRAMES 32
#define FCM__MSG_LEN    1024

typedef struct fcm_frame {
  const char *file;
  const char *func;
  int line;
} fcm_frame;

struct fcm_ctx {
  fcm_ctx_options opts;
  atomic_llong live;
  atomic_uint once; /* FCM__ONCE_* flags of the notices already given */
  fcm_status err_status;
  char err_msg[FCM__MSG_LEN];
  fcm_frame frames[FCM__MAX_FRAMES];
  int nframes;
  int frames_dropped;
};

#define FCM_STATUS_STR_(name, msg) msg,
static const char *const status_msgs[] = {FCM_STATUS_LIST(FCM_STATUS_STR_)};
#undef FCM_STATUS_STR_

const char *fcm_status_name(fcm_status st)
{
  if ((int)st < 0 || st >= FCM_STATUS_COUNT_) return "unknown status";
  return status_msgs[st];
}

static void *sys_alloc(void *user, size_t size)
{
  (void)user;
  return malloc(size);
}

static void sys_release(void *user, void *ptr)
{
  (void)user;
  free(ptr);
}

fcm_ctx_options fcm_ctx_options_default(void)
{
  fcm_ctx_options o;
  memset(&o, 0, sizeof o);
  o.log_level = FCM_LOG_WARNING;
  o.num_threads = FCM_DEFAULT;
  return o;
}

fcm_status fcm_ctx_create(const fcm_ctx_options *opts, fcm_ctx **out)
{
  fcm_ctx_options o = opts ? *opts : fcm_ctx_options_default();
  if (!out) return FCM_ERR_ARG;
  *out = NULL;
  if (!o.allocator.alloc != !o.allocator.release) return FCM_ERR_ARG;
  if (o.num_threads < 1 && o.num_threads != FCM_DEFAULT) return FCM_ERR_ARG;
  if (!o.allocator.alloc) {
    o.allocator.alloc = sys_alloc;
    o.allocator.release = sys_release;
    o.allocator.user = NULL;
  }
  fcm_ctx *ctx = o.allocator.alloc(o.allocator.user, sizeof *ctx);
  if (!ctx) return FCM_ERR_ALLOC;
  memset(ctx, 0, sizeof *ctx);
  ctx->opts = o;
  atomic_init(&ctx->live, 0);
  atomic_init(&ctx->once, 0u);
  ctx->err_status = FCM_OK;
  *out = ctx;
  return FCM_OK;
}

int fcm_ctx_num_threads(const fcm_ctx *ctx)
{
  if (ctx && ctx->opts.num_threads >= 1) return ctx->opts.num_threads;
  const int n = omp_get_max_threads();
  return n >= 1 ? n : 1;
}

fcm_status fcm_ctx_set_num_threads(fcm_ctx *ctx, int num_threads)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(ctx, ctx, FCM_ERR_ARG, "ctx: NULL context");
  FCM_CHECK(num_threads >= 1 || num_threads == FCM_DEFAULT, ctx, FCM_ERR_ARG,
            "ctx: num_threads = %d must be >= 1, or FCM_DEFAULT (-1)", num_threads);
  ctx->opts.num_threads = num_threads;
cleanup:
  return st;
}

void fcm_ctx_destroy(fcm_ctx **ctx)
{
  if (!ctx || !*ctx) return;
  fcm_allocator a = (*ctx)->opts.allocator;
  a.release(a.user, *ctx);
  *ctx = NULL;
}

long long fcm_ctx_live_allocations(const fcm_ctx *ctx)
{
  return ctx ? atomic_load(&((fcm_ctx *)ctx)->live) : 0;
}

fcm_status fcm_ctx_error_status(const fcm_ctx *ctx)
{
  return ctx ? ctx->err_status : FCM_OK;
}

const char *fcm_ctx_error_message(const fcm_ctx *ctx)
{
  return ctx ? ctx->err_msg : "";
}

void fcm_ctx_error_clear(fcm_ctx *ctx)
{
  if (!ctx) return;
#pragma omp critical(fcm_error)
  {
    ctx->err_status = FCM_OK;
    ctx->err_msg[0] = '\0';
    ctx->nframes = 0;
    ctx->frames_dropped = 0;
  }
}

void fcm_ctx_error_view(const fcm_ctx *ctx, FILE *stream)
{
  if (!ctx || !stream || ctx->err_status == FCM_OK) return;
  fprintf(stream, "fcm error: %s (%s)\n", ctx->err_msg, fcm_status_name(ctx->err_status));
  for (int i = 0; i < ctx->nframes; i++)
    fprintf(stream, "  [%d] %s() at %s:%d\n", i, ctx->frames[i].func, ctx->frames[i].file,
            ctx->frames[i].line);
  if (ctx->frames_dropped) fprintf(stream, "  ... %d more frames\n", ctx->frames_dropped);
}

/* Keep only the path below lib/ (or the base name) so tracebacks stay short; applied
 * once, when a frame is recorded. */
static const char *short_file(const char *file)
{
  const char *p = strstr(file, "lib/src/");
  if (p) return p + 8;
  const char *s = strrchr(file, '/');
  return s ? s + 1 : file;
}

static void push_frame(fcm_ctx *ctx, const char *file, int line, const char *func)
{
  if (ctx->nframes < FCM__MAX_FRAMES) {
    fcm_frame *f = &ctx->frames[ctx->nframes++];
    f->file = file;
    f->line = line;
    f->func = func;
  } else {
    ctx->frames_dropped++;
  }
}

static void log_message(const fcm_ctx *ctx, fcm_log_level level, const char *msg)
{
  if (ctx && ctx->opts.log && level <= ctx->opts.log_level)
    ctx->opts.log(ctx->opts.log_user, level, msg);
}

/* The loop iteration this thread is in (fcm__loop_enter), if any. */
static _Thread_local fcm__loop_iter *tl_iter = NULL;

/* The iteration collecting errors of ctx on this thread, or NULL. */
static fcm__loop_iter *active_iter(const fcm_ctx *ctx)
{
  return tl_iter && tl_iter->loop->ctx == ctx ? tl_iter : NULL;
}

static void record_frame(fcm__error_record *r, const char *file, int line, const char *func)
{
  if (r->nframes < FCM__LOOP_FRAMES) {
    r->frames[r->nframes].file = file;
    r->frames[r->nframes].func = func;
    r->frames[r->nframes].line = line;
    r->nframes++;
  } else {
    r->frames_dropped++;
  }
}

/* Record an error (message and frames) in ctx, or in the loop iteration this thread is in. */
static void store_error(fcm_ctx *ctx, const fcm__error_record *e)
{
  fcm__loop_iter *it = active_iter(ctx);
  if (it) { /* thread-private: no lock */
    it->rec = *e;
    return;
  }
#pragma omp critical(fcm_error)
  {
    ctx->err_status = e->code;
    snprintf(ctx->err_msg, sizeof ctx->err_msg, "%s", e->msg);
    ctx->nframes = 0;
    ctx->frames_dropped = e->frames_dropped;
    for (int k = 0; k < e->nframes; k++)
      push_frame(ctx, e->frames[k].file, e->frames[k].line, e->frames[k].func);
  }
  log_message(ctx, FCM_LOG_ERROR, e->msg);
}

fcm_status fcm__error(fcm_ctx *ctx, fcm_status code, const char *file, int line, const char *func,
                      const char *fmt, ...)
{
  if (!ctx) return code;
  fcm__error_record e;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(e.msg, sizeof e.msg, fmt, ap);
  va_end(ap);
  e.code = code;
  e.nframes = e.frames_dropped = 0;
  record_frame(&e, short_file(file), line, func);
  store_error(ctx, &e);
  return code;
}

/* "prefix: " then as much of msg (cap bytes) as fits. */
static void prefix_message(char *msg, size_t cap, const char *prefix)
{
  char old[FCM__MSG_LEN];
  snprintf(old, sizeof old, "%s", msg);
  const size_t np = strlen(prefix);
  if (np + 3 >= cap) return;
  const size_t room = cap - np - 3, no = strlen(old), k = no < room ? no : room;
  memcpy(msg, prefix, np);
  memcpy(msg + np, ": ", 2);
  memcpy(msg + np + 2, old, k);
  msg[np + 2 + k] = '\0';
}

void fcm__error_prefix(fcm_ctx *ctx, const char *prefix)
{
  if (!ctx || !prefix) return;
  fcm__loop_iter *it = active_iter(ctx);
  if (it) { /* the iteration's own error, thread-private: the loop reports it */
    if (it->rec.code != FCM_OK) prefix_message(it->rec.msg, sizeof it->rec.msg, prefix);
    return;
  }
#pragma omp critical(fcm_error)
  if (ctx->err_status != FCM_OK) prefix_message(ctx->err_msg, sizeof ctx->err_msg, prefix);
}

void fcm__trace(fcm_ctx *ctx, const char *file, int line, const char *func)
{
  if (!ctx) return;
  fcm__loop_iter *it = active_iter(ctx);
  if (it) {
    if (it->rec.code != FCM_OK) record_frame(&it->rec, short_file(file), line, func);
    return;
  }
#pragma omp critical(fcm_error)
  push_frame(ctx, short_file(file), line, func);
}

void fcm__loop_begin(fcm_ctx *ctx, fcm__loop *loop)
{
  loop->ctx = ctx;
  loop->failed = -1;
  loop->status = FCM_OK;
  loop->rec.code = FCM_OK;
  loop->rec.msg[0] = '\0';
  loop->rec.nframes = loop->rec.frames_dropped = 0;
}

int fcm__loop_skip(fcm__loop *loop, fcm_index i)
{
  fcm_index f;
#pragma omp atomic read
  f = loop->failed;
  return f >= 0 && f < i;
}

void fcm__loop_enter(fcm__loop *loop, fcm__loop_iter *it, fcm_index i)
{
  it->loop = loop;
  it->index = i;
  it->prev = tl_iter;
  it->rec.code = FCM_OK;
  it->rec.nframes = it->rec.frames_dropped = 0;
  tl_iter = it;
}

void fcm__loop_leave(fcm__loop *loop, fcm__loop_iter *it, fcm_status st)
{
  tl_iter = it->prev;
  if (st == FCM_OK) return;
#pragma omp critical(fcm_error)
  if (loop->failed < 0 || it->index < loop->failed) {
    loop->status = st;
    loop->rec = it->rec;
#pragma omp atomic write
    loop->failed = it->index;
  }
}

fcm_status fcm__loop_end(fcm__loop *loop, fcm_index *failed)
{
  if (failed) *failed = loop->failed;
  if (loop->failed < 0) return FCM_OK;
  if (loop->rec.code == FCM_OK) { /* the iteration failed without a message of its own */
    loop->rec.code = loop->status;
    snprintf(loop->rec.msg, sizeof loop->rec.msg, "iteration %lld of a parallel loop failed: %s",
             (long long)loop->failed, fcm_status_name(loop->status));
    loop->rec.nframes = loop->rec.frames_dropped = 0;
  }
  loop->rec.code = loop->status;
  store_error(loop->ctx, &loop->rec);
  return loop->status;
}

void fcm__log(const fcm_ctx *ctx, fcm_log_level level, const char *fmt, ...)
{
  if (!ctx || !ctx->opts.log || level > ctx->opts.log_level) return;
  char msg[FCM__MSG_LEN];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  ctx->opts.log(ctx->opts.log_user, level, msg);
}

int fcm__ctx_once(fcm_ctx *ctx, unsigned flag)
{
  if (!ctx) return 0;
  return !(atomic_fetch_or(&ctx->once, flag) & flag);
}

void *fcm__calloc(fcm_ctx *ctx, size_t n, size_t size)
{
  void *p = fcm__malloc(ctx, n, size);
  if (p) memset(p, 0, n * size);
  return p;
}

void *fcm__malloc(fcm_ctx *ctx, size_t n, size_t size)
{
  if (size && n > SIZE_MAX / size) {
    fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "allocation of %zu elements of %zu bytes overflows size_t", n, size);
    return NULL;
  }
  size_t bytes = n * size;
  if (bytes == 0) bytes = 1;
  void *p = ctx->opts.allocator.alloc(ctx->opts.allocator.user, bytes);
  if (!p) {
    fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
               "out of memory allocating %zu bytes", bytes);
    return NULL;
  }
  atomic_fetch_add(&ctx->live, 1);
  return p;
}

void fcm__free(fcm_ctx *ctx, void *ptr)
{
  if (!ptr) return;
  ctx->opts.allocator.release(ctx->opts.allocator.user, ptr);
  atomic_fetch_sub(&ctx->live, 1);
}

fcm_status fcm__resize(fcm_ctx *ctx, void **ptr, size_t old_n, size_t new_n, size_t size)
{
  fcm_status st = FCM_OK;
  unsigned char *fresh = fcm__malloc(ctx, new_n, size);
  FCM_CHECK(fresh, ctx, FCM_ERR_ALLOC, "out of memory resizing an array to %zu elements", new_n);
  const size_t kept = *ptr ? FCM_MIN(old_n, new_n) : 0; /* copied, the rest zeroed */
  if (kept) memcpy(fresh, *ptr, kept * size);
  memset(fresh + kept * size, 0, (new_n - kept) * size);
  fcm__free(ctx, *ptr);
  *ptr = fresh;
cleanup:
  return st;
}

fcm_status fcm__index_to_int(fcm_ctx *ctx, fcm_index v, const char *what, int *out)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(v >= 0 && v <= INT_MAX, ctx, FCM_ERR_UNSUPPORTED,
            "%s = %lld does not fit the 32-bit integer range [0, %d] of the solver interface", what,
            (long long)v, INT_MAX);
  *out = (int)v;
cleanup:
  return st;
}
