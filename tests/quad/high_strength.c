/* Computed rules of every shape at strengths 21..40 (up to 21^3 points)
 * integrate every monomial of total degree <= m to 1e-12 relative (closed-form
 * integrals), with positive weights and interior points. The default run checks the odd
 * and even ends and every third strength between (21, 22, 25, 28, ..., 40); `--full`
 * (label slow) every strength; `--report` prints the worst errors per shape. */
#include "moments.h"

#define RTOL 1e-12
#define ZTOL 1e-13

int main(int argc, char **argv)
{
  int report = 0, full = 0;
  for (int i = 1; i < argc; i++) {
    report |= !strcmp(argv[i], "--report");
    full |= !strcmp(argv[i], "--full");
  }
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  for (int s = 0; s < FCM_SHAPE_COUNT; s++) {
    fcm_shape shape = (fcm_shape)s;
    mom_stats st = {0, 0};
    for (int m = 21; m <= FCM_RULE_MAX_STRENGTH; m++) {
      if (!full && m > 22 && m < FCM_RULE_MAX_STRENGTH && (m - 22) % 3 != 0) continue;
      fcm_rule *r = NULL;
      TEST_OK(ctx, fcm_rule_create_computed(ctx, shape, m, &r));
      if (!r) break;
      int k = (m + 2) / 2, dim = mom_dim(shape);
      TEST_TRUE(fcm_rule_num_points(r) == (dim == 1 ? k : dim == 2 ? k * k : k * k * k));
      mom_check_exact(r, m, RTOL, ZTOL, &st);
      mom_check_inside_positive(r);
      fcm_rule_destroy(&r);
    }
    if (report)
      printf("%-4s m=21..40 (%s): max rel %.2e, max |Q|/measure (zero moments) %.2e\n",
             fcm_shape_name(shape), full ? "all" : "sampled", st.max_rel, st.max_zero);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
