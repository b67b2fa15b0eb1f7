/* Allocation-failure torture: with an allocator that fails the k-th allocation
 * (k = 0, 1, 2, ... until the call succeeds), every rule constructor returns
 * FCM_ERR_ALLOC, leaves *rule NULL and frees everything it allocated. */
#include "fcm/quad.h"
#include "fcm/rulegen.h"
#include "alloc_loop.h"

#include <stdio.h>

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

typedef struct rule_case {
  fcm_ctx *ctx;
  int kind, m;
  fcm_shape shape;
  fcm_rule *r; /* made by one round, or the rule of the moment residual */
  double res;  /* the moment residual */
} rule_case;

static fcm_status make_round(void *user)
{
  rule_case *c = user;
  c->r = (fcm_rule *)c; /* non-NULL: must be reset on failure */
  fcm_status st = make(c->ctx, c->kind, c->shape, c->m, &c->r);
  if (st == FCM_OK) TEST_TRUE(c->r != NULL && fcm_rule_num_points(c->r) > 0);
  return st != FCM_OK && c->r ? FCM_ERR_INTERNAL : st;
}

static void destroy_rule(void *user)
{
  fcm_rule_destroy(&((rule_case *)user)->r);
}

static fcm_status residual_round(void *user)
{
  rule_case *c = user;
  c->res = -1.0;
  fcm_status st = fcm_rule_moment_residual(c->ctx, c->r, 4, &c->res);
  if (st == FCM_OK) TEST_TRUE(c->res >= 0.0 && c->res < 1e-12);
  return st;
}

int main(void)
{
  failing f;
  rule_case c = {failing_ctx(&f), 0, 0, FCM_SHAPE_LINE, NULL, 0.0};
  TEST_TRUE(c.ctx != NULL);
  if (!c.ctx) return TEST_RESULT();

  /* rule struct, points, weights at least: 3 failing rounds */
  for (int kind = MAKE_COMPUTED; kind <= MAKE_USER; kind++)
    for (int s = 0; s < FCM_SHAPE_COUNT; s++) {
      if (kind >= MAKE_JACOBI && s > 0) break;
      char name[64];
      snprintf(name, sizeof name, "kind %d shape %d", kind, s);
      c.kind = kind, c.shape = (fcm_shape)s, c.m = kind == MAKE_JACOBI ? 7 : 5;
      alloc_loop(c.ctx, &f, name, make_round, destroy_rule, &c, 3, 100);
    }
  /* fcm_rule_moment_residual allocates its moment workspace */
  for (int s = 0; s < FCM_SHAPE_COUNT; s++) {
    TEST_OK(c.ctx, fcm_rule_create(c.ctx, (fcm_shape)s, 4, &c.r));
    char name[64];
    snprintf(name, sizeof name, "moment residual, shape %d", s);
    if (c.r) alloc_loop(c.ctx, &f, name, residual_round, NULL, &c, 1, 100);
    fcm_rule_destroy(&c.r);
  }
  fcm_ctx_destroy(&c.ctx);
  return TEST_RESULT();
}
