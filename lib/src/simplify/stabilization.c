/* Stabilization of cut cells (lib/METHOD.md §7, Longva et al. 2020 §5): the full cell's
 * standard rule with weights x alpha, appended after simplification and flagged. */
#include "simplify/simplify_impl.h"

#include <math.h>

fcm_stabilization_options fcm_stabilization_options_default(void)
{
  fcm_stabilization_options o;
  o.mode = FCM_STABILIZATION_MASS_STIFFNESS;
  o.alpha = 1e-6;
  return o;
}

fcm_status fcm_stabilization_append(fcm_ctx *ctx, const fcm_stabilization_options *opts,
                                    const fcm_rule *full_rule, fcm_index capacity, fcm_index *n,
                                    double *points, double *weights, unsigned char *fictitious)
{
  fcm_status st = FCM_OK;
  const fcm_stabilization_options o = opts ? *opts : fcm_stabilization_options_default();
  if (!ctx) return FCM_ERR_ARG;
  FCM_CHECK(full_rule && n && points && weights, ctx, FCM_ERR_ARG,
            "stabilization: full_rule, n, points and weights must not be NULL");
  FCM_CHECK(o.mode >= FCM_STABILIZATION_MASS_STIFFNESS && o.mode < FCM_STABILIZATION_MODE_COUNT,
            ctx, FCM_ERR_ARG, "stabilization: mode = %d out of range [0, %d)", (int)o.mode,
            (int)FCM_STABILIZATION_MODE_COUNT);
  const fcm_shape shape = fcm_rule_shape(full_rule);
  FCM_CHECK(fcm_shape_dim(shape) == 3, ctx, FCM_ERR_ARG,
            "stabilization: rule on shape %s, expected a 3-D shape (tet or hex)",
            fcm_shape_name(shape));
  if (o.mode == FCM_STABILIZATION_OFF) goto cleanup;
  FCM_CHECK(o.alpha > 0.0 && isfinite(o.alpha), ctx, FCM_ERR_ARG,
            "stabilization: alpha = %g must be finite and > 0", o.alpha);
  const fcm_index count = fcm_rule_num_points(full_rule);
  FCM_CHECK(*n >= 0 && *n + count <= capacity, ctx, FCM_ERR_ARG,
            "stabilization: %lld points + %lld stabilization points exceed capacity %lld",
            (long long)*n, (long long)count, (long long)capacity);
  const double *p = fcm_rule_points(full_rule), *w = fcm_rule_weights(full_rule);
  for (fcm_index j = 0; j < count; j++) {
    const fcm_index k = *n + j;
    for (int d = 0; d < 3; d++)
      points[3 * k + d] = p[3 * j + d];
    weights[k] = o.alpha * w[j];
    if (fictitious) fictitious[k] = 1;
  }
  *n += count;
cleanup:
  return st;
}
