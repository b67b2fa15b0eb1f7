/* The error idiom: FCM_CHECK records a message and a first frame, FCM_TRY adds
 * traceback frames, cleanup runs on every path, views print innermost first. */
#include "core/core_impl.h"
#include "test.h"

static fcm_status inner(fcm_ctx *ctx, int n, int *cleaned)
{
  fcm_status st = FCM_OK;
  double *w = NULL;
  FCM_ALLOC(ctx, 4, w);
  FCM_CHECK(n > 0, ctx, FCM_ERR_ARG, "inner: n = %d must be positive", n);
cleanup:
  if (w) (*cleaned)++;
  FCM_FREE(ctx, w);
  return st;
}

static fcm_status outer(fcm_ctx *ctx, int n, int *cleaned)
{
  fcm_status st = FCM_OK;
  int *buf = NULL;
  FCM_ALLOC(ctx, 8, buf);
  FCM_TRY(ctx, inner(ctx, n, cleaned));
cleanup:
  if (buf) (*cleaned)++;
  FCM_FREE(ctx, buf);
  return st;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_OK);
  TEST_TRUE(!strcmp(fcm_ctx_error_message(ctx), ""));

  int cleaned = 0;
  TEST_OK(ctx, outer(ctx, 3, &cleaned));
  TEST_TRUE(cleaned == 2);

  cleaned = 0;
  TEST_TRUE(outer(ctx, -2, &cleaned) == FCM_ERR_ARG);
  TEST_TRUE(cleaned == 2);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ARG);
  TEST_TRUE(!strcmp(fcm_ctx_error_message(ctx), "inner: n = -2 must be positive"));

  /* The view lists the message and both frames, innermost first. */
  FILE *f = tmpfile();
  TEST_TRUE(f != NULL);
  if (f) {
    fcm_ctx_error_view(ctx, f);
    rewind(f);
    char text[2048] = {0};
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    TEST_TRUE(len > 0);
    char *pi = strstr(text, "inner()"), *po = strstr(text, "outer()");
    TEST_TRUE(strstr(text, "invalid argument") != NULL);
    TEST_TRUE(pi && po && pi < po);
  }

  /* A new error replaces the old one and restarts the traceback. */
  cleaned = 0;
  TEST_TRUE(inner(ctx, 0, &cleaned) == FCM_ERR_ARG);
  TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "n = 0") != NULL);
  fcm_ctx_error_clear(ctx);
  TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_OK);

  /* Deep recursion beyond the frame limit does not overflow the record. */
  for (int i = 0; i < 100; i++)
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
