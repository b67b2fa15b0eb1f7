/* Allocation-failure torture: with an allocator that fails the k-th allocation
 * (k = 0, 1, 2, ... until the call succeeds), every rule constructor returns
 * FCM_ERR_ALLOC, leaves *rule NULL and frees everything it allocated. */
#include "fcm/quad.h"
#include "fcm/rulegen.h"
#include "test.h"
#include "test_alloc.h"

enum { MAKE_COMPUTED, MAKE_CATALOGUE, MAKE_JACOBI, MAKE_USER };

static fcm_status make(fcm_ctx *ctx, int kind, fcm_shape shape, int m, fcm_rule **r)
{
  static const double pts[3] = {-0.5, 0.0, 0.5}, wts[3] = {0.5, 1.0, 0.5};
  switch (kind) {
  case MAKE_COMPUTED:
    return fcm_rule_create_computed(ctx, shape, m, r);
  case MAKE_CATALOGUE:
    return fcm_rule_create(ctx, shape, m, r);
  case MAKE_JACOBI:
    return fcm_rule_create_gauss_jacobi(ctx, m, 1.0, 0.5, r);
  default:
    return fcm_rule_create_from_arrays(ctx, FCM_SHAPE_LINE, 1, 3, pts, wts, r);
  }
}

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

  for (int kind = MAKE_COMPUTED; kind <= MAKE_USER; kind++)
    for (int s = 0; s < FCM_SHAPE_COUNT; s++) {
      if (kind >= MAKE_JACOBI && s > 0) break;
      int m = kind == MAKE_JACOBI ? 7 : 5, succeeded = 0, failures = 0;
      for (long k = 0; k < 100 && !succeeded; k++) {
        fcm_rule *r = (fcm_rule *)&f; /* non-NULL: must be reset on failure */
        f.count = 0;
        f.fail_at = k;
        fcm_status st = make(ctx, kind, (fcm_shape)s, m, &r);
        f.fail_at = -1;
        if (st == FCM_OK) {
          succeeded = 1;
          TEST_TRUE(r != NULL && fcm_rule_num_points(r) > 0);
          fcm_rule_destroy(&r);
        } else {
          failures++;
          if (st != FCM_ERR_ALLOC)
            TEST_FAIL_("kind %d shape %d: failing allocation %ld gave %s", kind, s, k,
                       fcm_status_name(st));
          TEST_TRUE(r == NULL);
          TEST_TRUE(fcm_ctx_error_status(ctx) == FCM_ERR_ALLOC);
          fcm_ctx_error_clear(ctx);
        }
        if (fcm_ctx_live_allocations(ctx) != 0)
          TEST_FAIL_("kind %d shape %d: %lld allocations leaked after failing allocation %ld", kind,
                     s, fcm_ctx_live_allocations(ctx), k);
      }
      TEST_TRUE(succeeded);
      TEST_TRUE(failures >= 3); /* rule struct, points, weights at least */
    }
  /* fcm_rule_moment_residual allocates its moment workspace */
  for (int s = 0; s < FCM_SHAPE_COUNT; s++) {
    fcm_rule *r = NULL;
    TEST_OK(ctx, fcm_rule_create(ctx, (fcm_shape)s, 4, &r));
    int succeeded = 0, failures = 0;
    const long long live = fcm_ctx_live_allocations(ctx); /* the rule's */
    for (long k = 0; k < 100 && r && !succeeded; k++) {
      double res = -1.0;
      f.count = 0;
      f.fail_at = k;
      fcm_status st = fcm_rule_moment_residual(ctx, r, 4, &res);
      f.fail_at = -1;
      if (st == FCM_OK) {
        succeeded = 1;
        TEST_TRUE(res >= 0.0 && res < 1e-12);
      } else {
        failures++;
        if (st != FCM_ERR_ALLOC || fcm_ctx_error_status(ctx) != FCM_ERR_ALLOC)
          TEST_FAIL_("moment residual, shape %d: failing allocation %ld gave %s", s, k,
                     fcm_status_name(st));
        fcm_ctx_error_clear(ctx);
      }
      if (fcm_ctx_live_allocations(ctx) != live)
        TEST_FAIL_("moment residual, shape %d: leak after failing allocation %ld", s, k);
    }
    TEST_TRUE(succeeded && failures >= 1);
    fcm_rule_destroy(&r);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
