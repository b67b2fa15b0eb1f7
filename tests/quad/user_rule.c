/* Rules from caller arrays are copies (origin user) that keep the given shape,
 * strength, points and weights; empty rules are allowed; destroy accepts NULL;
 * fcm_rule_view prints the header and, with `full`, one line per point. */
#include "fcm/quad.h"
#include "test.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  /* 3-point strength-2 rule on the unit triangle: edge midpoints, weights 1/6 */
  double pts[6] = {0.5, 0.0, 0.5, 0.5, 0.0, 0.5}, wts[3] = {1.0 / 6, 1.0 / 6, 1.0 / 6};
  fcm_rule *r = NULL;
  TEST_OK(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_TRI, 2, 3, pts, wts, &r));
  if (r) {
    pts[0] = 9.0; /* the rule holds a copy */
    wts[0] = 9.0;
    TEST_TRUE(fcm_rule_shape(r) == FCM_SHAPE_TRI && fcm_rule_strength(r) == 2);
    TEST_TRUE(fcm_rule_num_points(r) == 3 && fcm_rule_get_origin(r) == FCM_RULE_USER);
    TEST_TRUE(fcm_rule_points(r)[0] == 0.5 && fcm_rule_points(r)[5] == 0.5);
    TEST_TRUE(fcm_rule_weights(r)[0] == 1.0 / 6);
    TEST_TRUE(strstr(fcm_rule_description(r), "user") != NULL);

    FILE *f = tmpfile();
    TEST_TRUE(f != NULL);
    if (f) {
      char buf[4096];
      fcm_rule_view(r, 1, f);
      rewind(f);
      size_t len = fread(buf, 1, sizeof buf - 1, f);
      buf[len] = '\0';
      fclose(f);
      TEST_TRUE(strstr(buf, "tri") && strstr(buf, "strength 2") && strstr(buf, "3 points"));
      TEST_TRUE(strstr(buf, "user"));
      int lines = 0;
      for (size_t i = 0; i < len; i++)
        lines += buf[i] == '\n';
      TEST_TRUE(lines == 4); /* header + 3 points */
    }
  }
  fcm_rule_destroy(&r);
  TEST_TRUE(r == NULL);
  fcm_rule_destroy(&r); /* NULL object and NULL handle are fine */
  fcm_rule_destroy(NULL);

  /* an empty rule (a cell with nothing inside) */
  TEST_OK(ctx, fcm_rule_create_from_arrays(ctx, FCM_SHAPE_HEX, 0, 0, NULL, NULL, &r));
  TEST_TRUE(r && fcm_rule_num_points(r) == 0);
  fcm_rule_destroy(&r);

  /* view of a computed rule without points: one line */
  TEST_OK(ctx, fcm_rule_create_computed(ctx, FCM_SHAPE_HEX, 5, &r));
  if (r) {
    FILE *f = tmpfile();
    if (f) {
      char buf[1024];
      fcm_rule_view(r, 0, f);
      rewind(f);
      size_t len = fread(buf, 1, sizeof buf - 1, f);
      buf[len] = '\0';
      fclose(f);
      TEST_TRUE(strstr(buf, "hex") && strstr(buf, "27 points") && strstr(buf, "computed"));
      TEST_TRUE(strstr(buf, "Gauss-Legendre 3^3") && strchr(buf, '\n') == buf + len - 1);
    }
  }
  fcm_rule_destroy(&r);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
