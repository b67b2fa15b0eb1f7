/* Stabilization points: appending the catalogue rule of a tet and a hex cell after a
 * simplified rule adds exactly its points, flagged fictitious, with weights alpha w (so
 * they sum to alpha |K|), leaves the simplified part untouched; mode OFF adds nothing. */
#include "simplify_util.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  fcm_stabilization_options so = fcm_stabilization_options_default();
  TEST_TRUE(so.mode == FCM_STABILIZATION_MASS_STIFFNESS && so.alpha == 1e-6);

  const fcm_shape shapes[2] = {FCM_SHAPE_TET, FCM_SHAPE_HEX};
  for (int s = 0; s < 2; s++)
    for (int m = 1; m <= 6; m += 5) {
      fcm_rule *rule = NULL;
      TEST_OK(ctx, fcm_rule_create(ctx, shapes[s], m, &rule));
      if (!rule) continue;
      const int q = fcm_rule_num_points(rule), base = 5, cap = base + q;
      double *p = calloc(3 * (size_t)cap, sizeof *p), *w = calloc((size_t)cap, sizeof *w);
      unsigned char *flag = calloc((size_t)cap, 1);
      for (int j = 0; j < base; j++)
        w[j] = 0.25, p[3 * j] = 0.125;
      fcm_index n = base;
      so.alpha = 1e-8;
      TEST_OK(ctx, fcm_stabilization_append(ctx, &so, rule, cap, &n, p, w, flag));
      TEST_TRUE(n == base + q);
      double sum = 0.0;
      for (int j = 0; j < base; j++)
        TEST_TRUE(w[j] == 0.25 && p[3 * j] == 0.125 && flag[j] == 0);
      for (int j = 0; j < q; j++) {
        TEST_TRUE(flag[base + j] == 1);
        TEST_NEAR(w[base + j], 1e-8 * fcm_rule_weights(rule)[j], 1e-15, 0.0);
        for (int d = 0; d < 3; d++)
          TEST_TRUE(p[3 * (base + j) + d] == fcm_rule_points(rule)[3 * j + d]);
        sum += w[base + j];
      }
      TEST_NEAR(sum, 1e-8 * fcm_shape_measure(shapes[s]), 1e-13, 0.0);

      so.mode = FCM_STABILIZATION_OFF;
      TEST_OK(ctx, fcm_stabilization_append(ctx, &so, rule, cap, &n, p, w, NULL));
      TEST_TRUE(n == base + q);
      so.mode = FCM_STABILIZATION_MASS;
      n = base;
      TEST_OK(ctx, fcm_stabilization_append(ctx, &so, rule, cap, &n, p, w, NULL)); /* no flags */
      TEST_TRUE(n == base + q);
      so = fcm_stabilization_options_default();
      free(p);
      free(w);
      free(flag);
      fcm_rule_destroy(&rule);
    }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
