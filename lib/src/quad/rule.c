/* The rule object: allocation, destruction, accessors, printing, rules from
 * caller arrays, and the catalogue (stored table, else the computed rule). */
#include "quad_impl.h"

#include <math.h>
#include <string.h>

static const char *origin_name(fcm_rule_origin o)
{
  switch (o) {
  case FCM_RULE_COMPUTED:
    return "computed";
  case FCM_RULE_TABLE:
    return "table";
  case FCM_RULE_USER:
    return "user";
  }
  return "unknown";
}

fcm_status fcm__quad_rule_alloc(fcm_ctx *ctx, fcm_shape shape, int strength, int n,
                                fcm_rule_origin origin, fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  fcm_rule *r = NULL;
  int dim = fcm_shape_dim(shape);
  *rule = NULL;
  FCM_CHECK(dim > 0, ctx, FCM_ERR_ARG, "rule: shape %d out of range [0, %d)", (int)shape,
            (int)FCM_SHAPE_COUNT);
  FCM_CHECK(n >= 0, ctx, FCM_ERR_ARG, "rule: number of points %d must be non-negative", n);
  FCM_ALLOC(ctx, 1, r);
  r->ctx = ctx;
  r->shape = shape;
  r->dim = dim;
  r->strength = strength;
  r->n = n;
  r->origin = origin;
  FCM_ALLOC(ctx, (size_t)n * (size_t)dim, r->points);
  FCM_ALLOC(ctx, (size_t)n, r->weights);
  *rule = r;
  r = NULL;
cleanup:
  fcm_rule_destroy(&r);
  return st;
}

void fcm_rule_destroy(fcm_rule **rule)
{
  if (!rule || !*rule) return;
  fcm_rule *r = *rule;
  fcm_ctx *ctx = r->ctx;
  fcm__free(ctx, r->points);
  fcm__free(ctx, r->weights);
  fcm__free(ctx, r);
  *rule = NULL;
}

fcm_shape fcm_rule_shape(const fcm_rule *rule)
{
  return rule ? rule->shape : FCM_SHAPE_COUNT;
}
int fcm_rule_strength(const fcm_rule *rule)
{
  return rule ? rule->strength : -1;
}
int fcm_rule_num_points(const fcm_rule *rule)
{
  return rule ? rule->n : 0;
}
const double *fcm_rule_points(const fcm_rule *rule)
{
  return rule ? rule->points : NULL;
}
const double *fcm_rule_weights(const fcm_rule *rule)
{
  return rule ? rule->weights : NULL;
}
fcm_rule_origin fcm_rule_get_origin(const fcm_rule *rule)
{
  return rule ? rule->origin : FCM_RULE_USER;
}
const char *fcm_rule_description(const fcm_rule *rule)
{
  return rule ? rule->description : "";
}

void fcm_rule_view(const fcm_rule *rule, int full, FILE *stream)
{
  if (!stream) return;
  if (!rule) {
    fprintf(stream, "rule: (null)\n");
    return;
  }
  double sum = 0.0;
  for (int i = 0; i < rule->n; i++)
    sum += rule->weights[i];
  fprintf(stream, "rule: %s, strength %d, %d points, origin %s, weight sum %.17g (%s)\n",
          fcm_shape_name(rule->shape), rule->strength, rule->n, origin_name(rule->origin), sum,
          rule->description);
  if (!full) return;
  for (int i = 0; i < rule->n; i++) {
    fprintf(stream, "  %4d ", i);
    for (int d = 0; d < rule->dim; d++)
      fprintf(stream, " % .17e", rule->points[i * rule->dim + d]);
    fprintf(stream, "   %.17e\n", rule->weights[i]);
  }
}

fcm_status fcm__quad_check_args(fcm_ctx *ctx, const char *who, fcm_shape shape, int strength,
                                fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(rule, ctx, FCM_ERR_ARG, "%s: output pointer is NULL", who);
  *rule = NULL;
  FCM_CHECK(ctx, ctx, FCM_ERR_ARG, "%s: context is NULL", who);
  FCM_CHECK((int)shape >= 0 && shape < FCM_SHAPE_COUNT, ctx, FCM_ERR_ARG,
            "%s: shape %d out of range [0, %d)", who, (int)shape, (int)FCM_SHAPE_COUNT);
  FCM_CHECK(strength >= 0 && strength <= FCM_RULE_MAX_STRENGTH, ctx, FCM_ERR_ARG,
            "%s: strength %d out of range [0, %d]", who, strength, FCM_RULE_MAX_STRENGTH);
cleanup:
  return st;
}

fcm_status fcm_rule_create_from_arrays(fcm_ctx *ctx, fcm_shape shape, int strength, int n,
                                       const double *points, const double *weights, fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  fcm_rule *r = NULL;
  int dim;
  FCM_TRY(ctx, fcm__quad_check_args(ctx, "user rule", shape, strength, rule));
  FCM_CHECK(n >= 0, ctx, FCM_ERR_ARG, "user rule: number of points %d must be non-negative", n);
  FCM_CHECK(n == 0 || (points && weights), ctx, FCM_ERR_ARG,
            "user rule: %s array is NULL with n = %d points", points ? "weights" : "points", n);
  dim = fcm_shape_dim(shape);
  for (int i = 0; i < n; i++) {
    for (int d = 0; d < dim; d++)
      FCM_CHECK(isfinite(points[i * dim + d]), ctx, FCM_ERR_ARG,
                "user rule: point %d coordinate %d = %g is not finite", i, d, points[i * dim + d]);
    FCM_CHECK(isfinite(weights[i]), ctx, FCM_ERR_ARG, "user rule: weight %d = %g is not finite", i,
              weights[i]);
  }
  FCM_TRY(ctx, fcm__quad_rule_alloc(ctx, shape, strength, n, FCM_RULE_USER, &r));
  if (n > 0) {
    memcpy(r->points, points, (size_t)n * (size_t)dim * sizeof *points);
    memcpy(r->weights, weights, (size_t)n * sizeof *weights);
  }
  snprintf(r->description, sizeof r->description, "user-supplied, %d points", n);
  *rule = r;
  r = NULL;
cleanup:
  fcm_rule_destroy(&r);
  return st;
}

fcm_status fcm_rule_create(fcm_ctx *ctx, fcm_shape shape, int strength, fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  fcm_rule *r = NULL;
  int n = 0;
  const double *points = NULL, *weights = NULL;
  const char *desc = NULL;
  FCM_TRY(ctx, fcm__quad_check_args(ctx, "rule", shape, strength, rule));
  if (!fcm__quad_table_lookup(shape, strength, &n, &points, &weights, &desc)) {
    FCM_TRY(ctx, fcm_rule_create_computed(ctx, shape, strength, rule));
    goto cleanup;
  }
  FCM_CHECK(n > 0 && points && weights, ctx, FCM_ERR_INTERNAL,
            "rule: stored %s table of strength %d is empty", fcm_shape_name(shape), strength);
  FCM_TRY(ctx, fcm__quad_rule_alloc(ctx, shape, strength, n, FCM_RULE_TABLE, &r));
  memcpy(r->points, points, (size_t)n * (size_t)r->dim * sizeof *points);
  memcpy(r->weights, weights, (size_t)n * sizeof *weights);
  snprintf(r->description, sizeof r->description, "%s", desc ? desc : "stored table");
  *rule = r;
  r = NULL;
cleanup:
  fcm_rule_destroy(&r);
  return st;
}
