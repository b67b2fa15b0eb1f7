/* Computed and catalogue rules of every shape and strength 0..20 integrate every
 * monomial of total degree <= m to 1e-13 (closed-form integrals), with positive
 * weights, interior points and ceil((m+1)/2)^dim points; and they are not exact
 * one degree beyond what k <= 8 Gauss points can do (the check can fail).
 * `--report` prints the worst errors per shape. */
#include "moments.h"

#define RTOL 1e-13
#define ZTOL 1e-14

/* sum_i w_i x_i0^deg (first coordinate only). */
static double first_coord_moment(const fcm_rule *r, int deg)
{
  int dim = mom_dim(fcm_rule_shape(r));
  double s = 0.0;
  for (int i = 0; i < fcm_rule_num_points(r); i++)
    s += fcm_rule_weights(r)[i] * pow(fcm_rule_points(r)[i * dim], deg);
  return s;
}

int main(int argc, char **argv)
{
  int report = argc > 1 && !strcmp(argv[1], "--report");
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  for (int s = 0; s < FCM_SHAPE_COUNT; s++) {
    fcm_shape shape = (fcm_shape)s;
    int dim = mom_dim(shape);
    int simplex = shape == FCM_SHAPE_TRI || shape == FCM_SHAPE_TET;
    mom_stats comp = {0, 0}, cat = {0, 0};
    for (int m = 0; m <= 20; m++) {
      fcm_rule *r = NULL, *c = NULL;
      TEST_OK(ctx, fcm_rule_create_computed(ctx, shape, m, &r));
      TEST_OK(ctx, fcm_rule_create(ctx, shape, m, &c));
      if (!r || !c) break;
      int k = (m + 2) / 2, expect = dim == 1 ? k : dim == 2 ? k * k : k * k * k;
      TEST_TRUE(fcm_rule_shape(r) == shape && fcm_rule_strength(r) == m);
      TEST_TRUE(fcm_rule_get_origin(r) == FCM_RULE_COMPUTED);
      if (fcm_rule_num_points(r) != expect)
        TEST_FAIL_("%s m=%d: %d points, expected %d", fcm_shape_name(shape), m,
                   fcm_rule_num_points(r), expect);
      char desc[64];
      if (simplex)
        snprintf(desc, sizeof desc, "collapsed Gauss-Jacobi %d^%d", k, dim);
      else if (dim == 1)
        snprintf(desc, sizeof desc, "Gauss-Legendre %d", k);
      else
        snprintf(desc, sizeof desc, "Gauss-Legendre %d^%d", k, dim);
      if (strcmp(fcm_rule_description(r), desc))
        TEST_FAIL_("description \"%s\", expected \"%s\"", fcm_rule_description(r), desc);
      mom_check_exact(r, m, RTOL, ZTOL, &comp);
      mom_check_inside_positive(r);

      /* k Gauss points in the first direction cannot integrate x^(2k) exactly; the
       * error is far above the tolerance for k <= 8 (and below 1e-9 from k ~ 10) */
      int e[3] = {2 * k, 0, 0};
      double ex = mom_exact(shape, e), q = first_coord_moment(r, 2 * k);
      if (k <= 8 && !(fabs(q - ex) > 1e-9 * ex))
        TEST_FAIL_("%s m=%d: x^%d integrated to %.17g vs exact %.17g: unexpectedly exact",
                   fcm_shape_name(shape), m, 2 * k, q, ex);

      /* the catalogue rule: same shape and strength, same guarantees */
      TEST_TRUE(fcm_rule_shape(c) == shape && fcm_rule_strength(c) == m);
      TEST_TRUE(fcm_rule_description(c)[0] != '\0');
      mom_check_exact(c, m, RTOL, ZTOL, &cat);
      mom_check_inside_positive(c);
      fcm_rule_destroy(&r);
      fcm_rule_destroy(&c);
      TEST_TRUE(r == NULL && c == NULL);
    }
    if (report)
      printf("%-4s m=0..20: computed max rel %.2e, max |Q|/measure (zero moments) %.2e; "
             "catalogue %.2e, %.2e\n",
             fcm_shape_name(shape), comp.max_rel, comp.max_zero, cat.max_rel, cat.max_zero);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
