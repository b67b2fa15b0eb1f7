/* Error paths of fcm_simplify and fcm_stabilization_append: each bad argument gives
 * FCM_ERR_ARG with a message naming it, an empty result and no leak. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"

#define EXPECT_ARG(call, substr)                                                                   \
  do {                                                                                             \
    res.count = 99;                                                                                \
    TEST_ERR(ctx, call, FCM_ERR_ARG, substr);                                                      \
    TEST_TRUE(res.count == 0 && res.indices == NULL && res.weights == NULL);                       \
  } while (0)

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  enum { N = 40 };
  double pts[3 * N], w[N];
  const double lo[3] = {0, 0, 0};
  fcm_simplify_result res;
  fcm_simplify_options o = fcm_simplify_options_default();
  util_random_box(1, N, lo, 1.0, 1.0, pts, w);

  EXPECT_ARG(fcm_simplify(ctx, 21, N, pts, w, NULL, &res, NULL),
             "strength = 21 out of range [0, 20]");
  EXPECT_ARG(fcm_simplify(ctx, -1, N, pts, w, NULL, &res, NULL), "strength = -1");
  EXPECT_ARG(fcm_simplify(ctx, 2, 0, pts, w, NULL, &res, NULL), "n = 0 points");
  EXPECT_ARG(fcm_simplify(ctx, 2, N, NULL, w, NULL, &res, NULL), "must not be NULL");
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, NULL, NULL, &res, NULL), "must not be NULL");
  TEST_ERR(ctx, fcm_simplify(ctx, 2, N, pts, w, NULL, NULL, NULL), FCM_ERR_ARG,
           "out must not be NULL");
  TEST_TRUE(fcm_simplify(NULL, 2, N, pts, w, NULL, &res, NULL) == FCM_ERR_ARG);

  pts[3 * 5 + 1] = NAN;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, NULL, &res, NULL), "point 5 = ");
  pts[3 * 5 + 1] = 0.5;
  w[7] = -1e-3;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, NULL, &res, NULL), "weight 7 = -0.001");
  w[7] = INFINITY;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, NULL, &res, NULL), "weight 7 = inf");
  for (int j = 0; j < N; j++)
    w[j] = 0.0;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, NULL, &res, NULL), "total weight 0");
  for (int j = 0; j < N; j++)
    w[j] = 1e308; /* the sum overflows */
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, NULL, &res, NULL), "total weight inf");
  util_random_box(1, N, lo, 1.0, 1.0, pts, w);

  o.method = (fcm_simplify_method)7;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "method = 7");
  o = fcm_simplify_options_default();
  o.residual_tol = 0.0;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "residual_tol = 0");
  o = fcm_simplify_options_default();
  o.rank_tol = -1.0;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "rank_tol = -1");
  o = fcm_simplify_options_default();
  o.lp_iteration_limit = -5;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "lp_iteration_limit = -5");
  o = fcm_simplify_options_default();
  o.lp_time_limit = NAN;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "lp_time_limit = nan");
  o = fcm_simplify_options_default();
  o.elimination_block = 0;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "elimination_block = 0");
  o.elimination_block = FCM__ELIM_BLOCK_MAX + 1;
  EXPECT_ARG(fcm_simplify(ctx, 2, N, pts, w, &o, &res, NULL), "elimination_block = 257");
  o = fcm_simplify_options_default();
  EXPECT_ARG(fcm__simplify_hooked(ctx, 2, N, pts, w, &o, 3, &res, NULL), "force_lp_failure = 3");

  /* Stabilization. */
  fcm_rule *hex = NULL, *quad = NULL;
  TEST_OK(ctx, fcm_rule_create(ctx, FCM_SHAPE_HEX, 3, &hex));
  TEST_OK(ctx, fcm_rule_create(ctx, FCM_SHAPE_QUAD, 3, &quad));
  fcm_stabilization_options so = fcm_stabilization_options_default();
  fcm_index count = 2;
  double sp[3 * 64], sw[64];
  unsigned char flag[64];
  TEST_ERR(ctx, fcm_stabilization_append(ctx, &so, hex, 3, &count, sp, sw, flag), FCM_ERR_ARG,
           "exceed capacity 3");
  TEST_ERR(ctx, fcm_stabilization_append(ctx, &so, quad, 64, &count, sp, sw, flag), FCM_ERR_ARG,
           "shape quad");
  TEST_ERR(ctx, fcm_stabilization_append(ctx, &so, NULL, 64, &count, sp, sw, flag), FCM_ERR_ARG,
           "must not be NULL");
  so.alpha = 0.0;
  TEST_ERR(ctx, fcm_stabilization_append(ctx, &so, hex, 64, &count, sp, sw, flag), FCM_ERR_ARG,
           "alpha = 0");
  so = fcm_stabilization_options_default();
  so.mode = (fcm_stabilization_mode)9;
  TEST_ERR(ctx, fcm_stabilization_append(ctx, &so, hex, 64, &count, sp, sw, flag), FCM_ERR_ARG,
           "mode = 9");
  TEST_TRUE(count == 2);
  fcm_rule_destroy(&hex);
  fcm_rule_destroy(&quad);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
