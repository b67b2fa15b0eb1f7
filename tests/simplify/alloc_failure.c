/* Allocation-failure torture: with an allocator that fails the k-th allocation
 * (k = 0, 1, 2, ... until the call succeeds), fcm_simplify on both paths and on the
 * fallback path returns FCM_ERR_ALLOC (never a fallback rule), leaves the result empty
 * and frees everything it allocated. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"
#include "test_alloc.h"

int main(void)
{
  failing f = {0, -1};
  fcm_ctx_options opts = fcm_ctx_options_default();
  opts.allocator.alloc = failing_alloc;
  opts.allocator.release = failing_release;
  opts.allocator.user = &f;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&opts, &ctx));
  if (!ctx) return TEST_RESULT();

  const int m = 2, M = util_num_basis(m), n = 9 * M; /* two recombination rounds */
  const double lo[3] = {-1, -1, -1};
  double *pts = malloc(3 * (size_t)n * sizeof *pts), *w = malloc((size_t)n * sizeof *w);
  util_random_box(5, n, lo, 2.0, 1.0, pts, w);

  for (int variant = 0; variant < 3; variant++) {
    fcm_simplify_options o = fcm_simplify_options_default();
    o.method = variant == 1 ? FCM_SIMPLIFY_RECOMBINE : FCM_SIMPLIFY_LP;
    int succeeded = 0, failures = 0;
    for (long k = 0; k < 2000 && !succeeded; k++) {
      fcm_simplify_result res;
      fcm_simplify_info info;
      f.count = 0;
      f.fail_at = k;
      fcm_status st = fcm__simplify_hooked(ctx, m, n, pts, w, &o, variant == 2, &res, &info);
      f.fail_at = -1;
      if (st == FCM_OK) {
        succeeded = 1;
        TEST_TRUE(info.fallback == (variant == 2));
        if (variant < 2) util_check("after failures", m, n, pts, w, &res, M, 1e-12);
        fcm_simplify_result_destroy(&res);
      } else {
        failures++;
        if (st != FCM_ERR_ALLOC)
          TEST_FAIL_("variant %d: failing allocation %ld gave %s", variant, k, fcm_status_name(st));
        TEST_TRUE(res.count == 0 && res.indices == NULL && res.weights == NULL);
        TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ALLOC);
        fcm_ctx_error_clear(ctx);
      }
      if (fcm_ctx_live_allocations(ctx) != 0)
        TEST_FAIL_("variant %d: %lld allocations leaked after failing allocation %ld", variant,
                   fcm_ctx_live_allocations(ctx), k);
    }
    TEST_TRUE(succeeded);
    TEST_TRUE(failures >= 8);
    if (getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "variant %d: %d failing allocations\n", variant, failures);
  }
  free(pts);
  free(w);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
