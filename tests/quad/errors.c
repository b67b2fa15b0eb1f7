/* Error paths of the quad module: invalid shapes, strengths, point counts,
 * Jacobi exponents, non-finite user data and NULL arguments give FCM_ERR_ARG with
 * a message naming the value and the valid range, leave *rule NULL and leak nothing. */
#include "fcm/quad.h"
#include "test.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  fcm_rule *r = (fcm_rule *)&ctx; /* any non-NULL value: failures must reset it */
  const fcm_shape bad_shape = FCM_SHAPE_COUNT, neg_shape = (fcm_shape)-1;

  TEST_ERR(ctx, fcm_rule_create(ctx, bad_shape, 2, &r), FCM_ERR_ARG, "shape 5 out of range [0, 5)");
  TEST_TRUE(r == NULL);
  TEST_ERR(ctx, fcm_rule_create(ctx, neg_shape, 2, &r), FCM_ERR_ARG, "shape -1 out of range");
  TEST_ERR(ctx, fcm_rule_create_computed(ctx, bad_shape, 2, &r), FCM_ERR_ARG,
           "out of range [0, 5)");
  TEST_ERR(ctx, fcm_rule_create(ctx, FCM_SHAPE_TET, -1, &r), FCM_ERR_ARG,
           "strength -1 out of range [0, 40]");
  TEST_ERR(ctx, fcm_rule_create(ctx, FCM_SHAPE_HEX, 41, &r), FCM_ERR_ARG,
           "strength 41 out of range [0, 40]");
  TEST_ERR(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_TRI, 1000, &r), FCM_ERR_ARG,
           "strength 1000 out of range [0, 40]");
  TEST_ERR(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_TRI, 2, NULL), FCM_ERR_ARG, "NULL");
  TEST_TRUE(fcm_rule_create(NULL, FCM_SHAPE_TRI, 2, &r) == FCM_ERR_ARG && r == NULL);

  /* Gauss–Jacobi: n in [1, 200], alpha and beta finite and > -1 */
  r = (fcm_rule *)&ctx;
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 0, 0, 0, &r), FCM_ERR_ARG,
           "n = 0 points out of range [1, 200]");
  TEST_TRUE(r == NULL);
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 201, 0, 0, &r), FCM_ERR_ARG,
           "n = 201 points out of range [1, 200]");
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 4, -1, 0, &r), FCM_ERR_ARG,
           "alpha = -1 must be finite and > -1");
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 4, 0, -1.5, &r), FCM_ERR_ARG,
           "beta = -1.5 must be finite and > -1");
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 4, NAN, 0, &r), FCM_ERR_ARG, "alpha = nan");
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 4, 0, INFINITY, &r), FCM_ERR_ARG, "beta = inf");
  TEST_ERR(ctx, fcm_rule_create_gauss_jacobi(ctx, 4, 2000, 0, &r), FCM_ERR_ARG, "too large");
  TEST_TRUE(r == NULL);

  /* user arrays */
  double pts[6] = {0.1, 0.2, 0.3, 0.4, 0.2, 0.2}, wts[3] = {0.1, 0.2, 0.2};
  r = (fcm_rule *)&ctx;
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 2, -1, pts, wts, &r), FCM_ERR_ARG,
           "number of points -1 must be non-negative");
  TEST_TRUE(r == NULL);
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 2, 3, NULL, wts, &r), FCM_ERR_ARG,
           "points array is NULL with n = 3");
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 2, 3, pts, NULL, &r), FCM_ERR_ARG,
           "weights array is NULL with n = 3");
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, bad_shape, 2, 3, pts, wts, &r), FCM_ERR_ARG,
           "shape 5 out of range");
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 41, 3, pts, wts, &r), FCM_ERR_ARG,
           "strength 41 out of range [0, 40]");
  pts[3] = NAN;
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 2, 3, pts, wts, &r), FCM_ERR_ARG,
           "point 1 coordinate 1 = nan is not finite");
  pts[3] = 0.4;
  wts[2] = -INFINITY;
  TEST_ERR(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 2, 3, pts, wts, &r), FCM_ERR_ARG,
           "weight 2 = -inf is not finite");
  TEST_TRUE(r == NULL);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
