/* Errors of parallel loops (fcm__loop): whatever the thread count and scheduling, the
 * error reported is the one of the lowest failing iteration, with its own message,
 * status and traceback, recorded once; an iteration that handles an error of its own and
 * returns FCM_OK leaves nothing; a loop nested in an iteration reports into it; an
 * iteration failing without a message gets a generic one naming it; a prefix added inside a
 * failing iteration (fcm__error_prefix()) stays on the message the loop reports. */
#include "core/core_impl.h"
#include "test.h"

#include <omp.h>

static int logged;

static void count_log(void *user, fcm_log_level level, const char *msg)
{
  (void)user, (void)msg;
  if (level == FCM_LOG_ERROR) {
#pragma omp atomic
    logged++;
  }
}

/* Iteration i of the outer loop: fails at the listed iterations with its own code. */
static fcm_status work(fcm_ctx *ctx, fcm_index i, const fcm_index *fail, int nfail, int silent)
{
  fcm_status st = FCM_OK;
  if (i == 100) { /* an error handled inside the iteration */
    fcm__error(ctx, FCM_ERR_NUMERIC, __FILE__, __LINE__, __func__, "handled at %lld", (long long)i);
    return FCM_OK;
  }
  for (int k = 0; k < nfail; k++)
    if (i == fail[k]) {
      if (silent) return FCM_ERR_INTERNAL;
      FCM_CHECK(0, ctx, i % 2 ? FCM_ERR_GEOMETRY : FCM_ERR_ARG, "iteration %lld failed",
                (long long)i);
    }
cleanup:
  return st;
}

static fcm_status outer(fcm_ctx *ctx, fcm_index n, const fcm_index *fail, int nfail, int silent,
                        fcm_index *failed)
{
  fcm_status st = FCM_OK;
  fcm__loop L;
  fcm__loop_begin(ctx, &L);
#pragma omp parallel for schedule(dynamic, 3)
  for (fcm_index i = 0; i < n; i++) {
    if (fcm__loop_skip(&L, i)) continue;
    fcm__loop_iter it;
    fcm__loop_enter(&L, &it, i);
    fcm__loop_leave(&L, &it, work(ctx, i, fail, nfail, silent));
  }
  FCM_TRY(ctx, fcm__loop_end(&L, failed));
cleanup:
  return st;
}

/* The loop of outer() whose iterations prefix their own errors. */
static fcm_status prefixed(fcm_ctx *ctx, const fcm_index *fail, int nfail)
{
  fcm_status st = FCM_OK;
  fcm__loop L;
  fcm__loop_begin(ctx, &L);
#pragma omp parallel for schedule(dynamic, 3)
  for (fcm_index i = 0; i < 1000; i++) {
    if (fcm__loop_skip(&L, i)) continue;
    fcm__loop_iter it;
    fcm__loop_enter(&L, &it, i);
    const fcm_status s = work(ctx, i, fail, nfail, 0);
    if (s != FCM_OK) fcm__error_prefix(ctx, "part");
    fcm__loop_leave(&L, &it, s);
  }
  FCM_TRY(ctx, fcm__loop_end(&L, NULL));
cleanup:
  return st;
}

/* A loop whose iteration 5 runs an inner loop failing at its iterations 9 and 4. */
static fcm_status nested(fcm_ctx *ctx)
{
  fcm_status st = FCM_OK;
  fcm__loop L;
  fcm__loop_begin(ctx, &L);
#pragma omp parallel for schedule(dynamic, 1)
  for (fcm_index i = 0; i < 8; i++) {
    fcm__loop_iter it;
    fcm__loop_enter(&L, &it, i);
    fcm_status s = FCM_OK;
    if (i == 5) {
      const fcm_index inner_fail[2] = {9, 4};
      s = outer(ctx, 12, inner_fail, 2, 0, NULL);
    }
    fcm__loop_leave(&L, &it, s);
  }
  FCM_TRY(ctx, fcm__loop_end(&L, NULL));
cleanup:
  return st;
}

int main(void)
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.log = count_log;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&o, &ctx));
  const fcm_index fail[4] = {701, 300, 999, 302};
  const int threads[4] = {1, 2, 3, 4};
  for (int run = 0; run < 40; run++) {
    omp_set_num_threads(threads[run % 4]);
    fcm_index failed = -2;
    logged = 0;
    TEST_ERR(ctx, outer(ctx, 1000, fail, 4, 0, &failed), FCM_ERR_ARG, "iteration 300 failed");
    TEST_TRUE(failed == 300 && logged == 1);
    /* a clean loop: no error even though iteration 100 recorded and handled one */
    TEST_OK(ctx, outer(ctx, 1000, fail, 0, 0, &failed));
    TEST_TRUE(failed == -1 && fcm_ctx_error_status(ctx) == FCM_OK);
    /* no message of its own: a generic one naming the iteration */
    TEST_ERR(ctx, outer(ctx, 1000, fail, 4, 1, NULL), FCM_ERR_INTERNAL,
             "iteration 300 of a parallel loop failed");
    /* nested: the inner loop's lowest failure, reported through the outer iteration */
    TEST_ERR(ctx, nested(ctx), FCM_ERR_ARG, "iteration 4 failed");
    TEST_ERR(ctx, prefixed(ctx, fail, 4), FCM_ERR_ARG, "part: iteration 300 failed");
  }
  /* outside a loop the context's message takes the prefix */
  TEST_TRUE(outer(ctx, 1000, fail, 4, 0, NULL) == FCM_ERR_ARG);
  fcm__error_prefix(ctx, "run");
  TEST_TRUE(strncmp(fcm_ctx_error_message(ctx), "run: iteration 300 failed", 25) == 0);
  /* the traceback: the FCM_CHECK frame first, then the frames of the callers */
  TEST_TRUE(outer(ctx, 1000, fail, 4, 0, NULL) == FCM_ERR_ARG);
  char buf[4096] = {0};
  FILE *f = tmpfile();
  if (f) {
    fcm_ctx_error_view(ctx, f);
    rewind(f);
    size_t got = fread(buf, 1, sizeof buf - 1, f);
    buf[got] = '\0';
    fclose(f);
  }
  const char *w = strstr(buf, "[0] work()"), *o1 = strstr(buf, "[1] outer()");
  TEST_TRUE(w && o1 && w < o1 && !strstr(buf, "[2]"));
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
