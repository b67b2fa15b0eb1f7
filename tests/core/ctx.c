/* Context: options, allocator hook and live-allocation count, log callback,
 * status strings, timers. */
#include "core/core_impl.h"
#include "test.h"

#include <omp.h>

typedef struct counting {
  int allocs, releases, fail_at; /* fail the fail_at-th allocation (0-based), -1: never */
} counting;

static void *count_alloc(void *user, size_t size)
{
  counting *c = user;
  if (c->fail_at >= 0 && c->allocs == c->fail_at) return NULL;
  c->allocs++;
  return malloc(size);
}

static void count_release(void *user, void *p)
{
  counting *c = user;
  if (p) c->releases++;
  free(p);
}

typedef struct logbook {
  int lines;
  fcm_log_level last;
  char text[256];
} logbook;

static void log_fn(void *user, fcm_log_level level, const char *msg)
{
  logbook *b = user;
  b->lines++;
  b->last = level;
  snprintf(b->text, sizeof b->text, "%s", msg);
}

int main(void)
{
  /* Status strings: one per code, the out-of-range value is handled. */
  TEST_TRUE(!strcmp(fcm_status_name(FCM_OK), "success"));
  TEST_TRUE(!strcmp(fcm_status_name(FCM_ERR_ALLOC), "out of memory"));
  TEST_TRUE(!strcmp(fcm_status_name((fcm_status)999), "unknown status"));
  for (int s = 0; s < FCM_STATUS_COUNT_; s++)
    TEST_TRUE(strlen(fcm_status_name((fcm_status)s)) > 0);

  /* Bad arguments to create. */
  TEST_TRUE(fcm_ctx_create(NULL, NULL) == FCM_ERR_ARG);
  fcm_ctx_options half = fcm_ctx_options_default();
  half.allocator.alloc = count_alloc;
  fcm_ctx *ctx = (fcm_ctx *)&half; /* must be reset to NULL on failure */
  TEST_TRUE(fcm_ctx_create(&half, &ctx) == FCM_ERR_ARG);
  TEST_TRUE(ctx == NULL);

  /* Custom allocator: every allocation goes through it, live count tracks it. */
  counting c = {0, 0, -1};
  logbook book = {0, FCM_LOG_WARNING, ""};
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = count_alloc;
  o.allocator.release = count_release;
  o.allocator.user = &c;
  o.log = log_fn;
  o.log_user = &book;
  o.log_level = FCM_LOG_INFO;
  TEST_OK(ctx, fcm_ctx_create(&o, &ctx));
  TEST_TRUE(c.allocs == 1);
  double *a = fcm__calloc(ctx, 10, sizeof *a);
  int *b = fcm__calloc(ctx, 0, sizeof *b);
  TEST_TRUE(a && b);
  for (int i = 0; i < 10; i++)
    TEST_TRUE(a[i] == 0.0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 2);
  a[9] = 7.0;
  TEST_OK(ctx, fcm__resize(ctx, (void **)&a, 10, 20, sizeof *a));
  TEST_TRUE(a[9] == 7.0 && a[19] == 0.0);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 2);
  fcm__free(ctx, a);
  fcm__free(ctx, b);
  fcm__free(ctx, NULL);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);

  /* Overflowing sizes fail cleanly with a message, not a wrapped allocation. */
  TEST_TRUE(fcm__calloc(ctx, SIZE_MAX / 2, 4) == NULL);
  TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ALLOC);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "overflows") != NULL);
  fcm_ctx_error_clear(ctx);

  /* A failing allocator gives FCM_ERR_ALLOC and nothing is counted as live. */
  c.fail_at = c.allocs;
  TEST_TRUE(fcm__calloc(ctx, 5, 8) == NULL);
  TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ALLOC);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  c.fail_at = -1;

  /* Logging: levels above the threshold are filtered; errors are logged. */
  int before = book.lines;
  fcm__log(ctx, FCM_LOG_INFO, "shown %d", 1);
  TEST_TRUE(book.lines == before + 1 && !strcmp(book.text, "shown 1"));
  TEST_TRUE(book.last == FCM_LOG_INFO);
  before = book.lines;
  fcm__log(ctx, FCM_LOG_WARNING, "shown %d", 2);
  TEST_TRUE(book.lines == before + 1 && !strcmp(book.text, "shown 2"));
  TEST_TRUE(book.last == FCM_LOG_WARNING);
  {
    fcm_ctx *quiet = NULL;
    fcm_ctx_options q = o;
    q.allocator = fcm_ctx_options_default().allocator;
    q.log_level = FCM_LOG_ERROR; /* warnings filtered, errors still logged */
    TEST_OK(quiet, fcm_ctx_create(&q, &quiet));
    before = book.lines;
    fcm__log(quiet, FCM_LOG_WARNING, "hidden %d", 1);
    fcm__log(quiet, FCM_LOG_INFO, "hidden %d", 2);
    TEST_TRUE(book.lines == before);
    fcm__log(quiet, FCM_LOG_ERROR, "shown %d", 3);
    TEST_TRUE(book.lines == before + 1 && !strcmp(book.text, "shown 3"));
    fcm_ctx_destroy(&quiet);
  }

  /* The one thread count: FCM_DEFAULT is OpenMP's, a set count is returned as set. */
  TEST_TRUE(fcm_ctx_options_default().num_threads == FCM_DEFAULT);
  TEST_TRUE(fcm_ctx_num_threads(ctx) == omp_get_max_threads());
  TEST_TRUE(fcm_ctx_num_threads(NULL) == omp_get_max_threads());
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 3));
  TEST_TRUE(fcm_ctx_num_threads(ctx) == 3);
  TEST_ERR(ctx, fcm_ctx_set_num_threads(ctx, 0), FCM_ERR_ARG, "num_threads = 0");
  TEST_TRUE(fcm_ctx_num_threads(ctx) == 3);
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, FCM_DEFAULT));
  TEST_TRUE(fcm_ctx_num_threads(ctx) == omp_get_max_threads());
  {
    fcm_ctx_options t = fcm_ctx_options_default();
    fcm_ctx *c2 = NULL;
    t.num_threads = 0;
    TEST_TRUE(fcm_ctx_create(&t, &c2) == FCM_ERR_ARG && c2 == NULL);
    t.num_threads = 2;
    TEST_OK(c2, fcm_ctx_create(&t, &c2));
    TEST_TRUE(fcm_ctx_num_threads(c2) == 2);
    fcm_ctx_destroy(&c2);
  }

  /* Index narrowing. */
  int n = -1;
  TEST_OK(ctx, fcm__index_to_int(ctx, 12345, "rows", &n));
  TEST_TRUE(n == 12345);
  TEST_ERR(ctx, fcm__index_to_int(ctx, (fcm_index)1 << 40, "rows", &n), FCM_ERR_UNSUPPORTED,
           "rows = 1099511627776");
  TEST_TRUE(book.last == FCM_LOG_ERROR);

  fcm_ctx_destroy(&ctx);
  TEST_TRUE(ctx == NULL);
  fcm_ctx_destroy(&ctx); /* NULL-safe */
  fcm_ctx_destroy(NULL);
  TEST_TRUE(c.allocs == c.releases);

  /* Allocation failure of the context itself. */
  c.fail_at = c.allocs;
  ctx = NULL;
  TEST_TRUE(fcm_ctx_create(&o, &ctx) == FCM_ERR_ALLOC && ctx == NULL);

  /* Timers accumulate intervals; wtime is monotonic. */
  fcm_timer t = fcm_timer_init();
  TEST_TRUE(t.total == 0.0 && t.count == 0);
  double w0 = fcm_wtime();
  fcm_timer_start(&t);
  volatile double s = 0;
  for (int i = 0; i < 100000; i++)
    s += i;
  fcm_timer_stop(&t);
  fcm_timer_stop(&t); /* no effect */
  TEST_TRUE(t.total >= 0.0 && t.count == 1);
  TEST_TRUE(fcm_wtime() >= w0);
  return TEST_RESULT();
}
