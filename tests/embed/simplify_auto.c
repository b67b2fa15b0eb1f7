/* Simplify only where it pays (FCM_CELL_SIMPLIFY_AUTO): the cost model fcm_simplify_pays()
 * on both sides of a given break-even and on invalid inputs; the simplification-time model
 * fcm_simplify_cost_estimate() (its formula, 0 where nothing is removed or the input is
 * invalid); AUTO with many expected assemblies gives exactly the rules of ON, with none or
 * with a negligible point cost exactly those of OFF; the reported decision follows from its
 * own reported inputs, and is the same with 1 and 2 threads (no timing enters it); bad AUTO
 * options are rejected naming the field. */
#include "fcm/embed.h"
#include "test.h"

#include <math.h>
#include <string.h>

static fcm_ctx *ctx;

static void cost_model(void)
{
  /* 1000 -> 100 points at 1e-6 s per point per assembly save 9e-4 s per assembly; a
   * simplification of 9e-3 s breaks even at 10 assemblies (strictly more pay). */
  TEST_TRUE(fcm_simplify_pays(10.5, 1e-6, 1000, 100, 9e-3) == 1);
  TEST_TRUE(fcm_simplify_pays(9.5, 1e-6, 1000, 100, 9e-3) == 0);
  TEST_TRUE(fcm_simplify_pays(1e6, 1e-6, 1000, 100, 9e-3) == 1);
  TEST_TRUE(fcm_simplify_pays(0.0, 1e-6, 1000, 100, 0.0) == 0); /* no assembly: nothing saved */
  TEST_TRUE(fcm_simplify_pays(100, 1e-6, 100, 100, 0.0) == 0);  /* no point saved */
  TEST_TRUE(fcm_simplify_pays(100, 1e-6, 1000, 100, 0.0) == 1); /* free simplification */
  TEST_TRUE(fcm_simplify_pays(NAN, 1e-6, 1000, 100, 9e-3) == 0);
  TEST_TRUE(fcm_simplify_pays(100, INFINITY, 1000, 100, 9e-3) == 0);
  TEST_TRUE(fcm_simplify_pays(-100, -1e-6, 1000, 100, 9e-3) == 0);
  TEST_TRUE(fcm_simplify_pays(100, 1e-6, 1000, 100, -1.0) == 0);
  TEST_TRUE(!strcmp(fcm_cell_simplify_name(FCM_CELL_SIMPLIFY_OFF), "off"));
  TEST_TRUE(!strcmp(fcm_cell_simplify_name(FCM_CELL_SIMPLIFY_ON), "on"));
  TEST_TRUE(!strcmp(fcm_cell_simplify_name(FCM_CELL_SIMPLIFY_AUTO), "auto"));
  TEST_TRUE(!strcmp(fcm_cell_simplify_name((fcm_cell_simplify)7), "invalid"));
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++)
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const double c = fcm_cell_rules_point_cost((fcm_element_type)t, (fcm_rule_kind)k);
      TEST_TRUE(isfinite(c) && c > 0.0 && c < 1e-3);
    }
  TEST_TRUE(fcm_cell_rules_point_cost(FCM_ELEMENT_COUNT, FCM_RULE_MASS) == 0.0);
  /* the time model: 2.5e-9 N M + 6.6e-10 M^3 for N > M */
  TEST_NEAR(fcm_simplify_cost_estimate(4, 2900), 2.5e-9 * 2900 * 35 + 6.6e-10 * 35 * 35 * 35, 1e-14,
            0.0);
  TEST_TRUE(fcm_simplify_cost_estimate(4, 35) == 0.0 && fcm_simplify_cost_estimate(4, 36) > 0.0);
  TEST_TRUE(fcm_simplify_cost_estimate(8, 64000) > fcm_simplify_cost_estimate(8, 32000));
  TEST_TRUE(fcm_simplify_cost_estimate(-1, 100) == 0.0 &&
            fcm_simplify_cost_estimate(21, 1e6) == 0.0);
  TEST_TRUE(fcm_simplify_cost_estimate(4, -5) == 0.0);
}

static fcm_cell_rules *build(const fcm_mesh *m, const fcm_geometry *g, fcm_cell_simplify mode,
                             double assemblies, double point_cost, int threads)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.strength[FCM_RULE_STIFFNESS] = 2;
  o.strength[FCM_RULE_MASS] = 3;
  o.simplify = mode;
  o.moments = FCM_CELL_MOMENTS_VOLUME; /* the policy weighs the tet rules' initial points (the
                                          surface path fits at most M points directly) */
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    o.expected_assemblies[k] = assemblies;
    o.point_cost[k] = point_cost;
  }
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, threads));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, FCM_DEFAULT));
  return r;
}

/* Bitwise identical rules of one kind. */
static int same_rules(const fcm_cell_rules *a, const fcm_cell_rules *b, fcm_rule_kind k)
{
  for (fcm_index c = 0; c < fcm_cell_rules_num_cells(a); c++) {
    int na, nb;
    const double *pa, *pb, *wa, *wb;
    const unsigned char *fa, *fb;
    if (fcm_cell_rules_get(a, c, k, &na, &pa, &wa, &fa) != FCM_OK ||
        fcm_cell_rules_get(b, c, k, &nb, &pb, &wb, &fb) != FCM_OK || na != nb)
      return 0;
    if (na && (memcmp(pa, pb, 3 * (size_t)na * sizeof *pa) || memcmp(wa, wb, na * sizeof *wa) ||
               memcmp(fa, fb, (size_t)na)))
      return 0;
  }
  return 1;
}

/* The decision is fcm_simplify_pays() of its own reported estimates. */
static void check_decision(const fcm_cell_rules *r, int expect_simplified)
{
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const fcm_simplify_decision *d = &S->decision[k];
    const int m = fcm_cell_rules_strength(r, (fcm_rule_kind)k);
    const double M = (m + 1) * (m + 2) * (m + 3) / 6.0;
    TEST_TRUE(d->simplified == expect_simplified);
    const double n = (double)S->points_initial[k], A = d->expected_assemblies;
    TEST_NEAR(d->cost_plain, n * d->point_cost * A, 1e-14, 0.0);
    /* every cut cell keeps min(N, M) points; the model's time is positive when some cell
     * has more than M points and at most that of all points in one cell */
    TEST_TRUE(d->estimated_kept > 0.0 && d->estimated_kept <= (double)S->num_cut * M &&
              d->estimated_kept < n);
    TEST_TRUE(d->estimated_time > 0.0 &&
              d->estimated_time <=
                  (double)S->num_cut * fcm_simplify_cost_estimate(m, S->points_initial[k]));
    TEST_NEAR(d->cost_simplified, d->estimated_time + d->estimated_kept * d->point_cost * A, 1e-14,
              0.0);
    TEST_TRUE(d->simplified ==
              fcm_simplify_pays(A, d->point_cost, n, d->estimated_kept, d->estimated_time));
    /* simplified: the stored counts are those of ON; else those of OFF */
    if (d->simplified)
      TEST_TRUE(S->points_simplified[k] < S->points_initial[k]);
    else
      TEST_TRUE(S->points_simplified[k] == S->points_initial[k] && S->max_residual[k] == 0.0 &&
                d->time_simplify == 0.0);
  }
}

/* Same decision inputs and results (the model has no timing in it). */
static void same_decision(const fcm_cell_rules *a, const fcm_cell_rules *b)
{
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    const fcm_simplify_decision *x = &fcm_cell_rules_get_stats(a)->decision[k],
                                *y = &fcm_cell_rules_get_stats(b)->decision[k];
    TEST_TRUE(x->simplified == y->simplified && x->estimated_time == y->estimated_time &&
              x->estimated_kept == y->estimated_kept && x->cost_plain == y->cost_plain &&
              x->cost_simplified == y->cost_simplified);
    TEST_TRUE(same_rules(a, b, (fcm_rule_kind)k));
  }
}

static void auto_mode(const fcm_mesh *m, const fcm_geometry *g)
{
  fcm_cell_rules *off = build(m, g, FCM_CELL_SIMPLIFY_OFF, 1, FCM_DEFAULT, 2);
  fcm_cell_rules *on = build(m, g, FCM_CELL_SIMPLIFY_ON, 1, FCM_DEFAULT, 2);
  fcm_cell_rules *many = build(m, g, FCM_CELL_SIMPLIFY_AUTO, 1e12, FCM_DEFAULT, 2);
  fcm_cell_rules *none = build(m, g, FCM_CELL_SIMPLIFY_AUTO, 0, FCM_DEFAULT, 2);
  fcm_cell_rules *cheap = build(m, g, FCM_CELL_SIMPLIFY_AUTO, 1, 1e-30, 2);
  /* near the break-even of this grid (mass, strength 3): the same decision on one thread */
  fcm_cell_rules *mid2 = build(m, g, FCM_CELL_SIMPLIFY_AUTO, 3, FCM_DEFAULT, 2);
  fcm_cell_rules *mid1 = build(m, g, FCM_CELL_SIMPLIFY_AUTO, 3, FCM_DEFAULT, 1);
  if (!off || !on || !many || !none || !cheap || !mid1 || !mid2) goto done;
  same_decision(mid1, mid2);
  TEST_TRUE(fcm_cell_rules_get_stats(off)->num_cut > 3);
  TEST_TRUE(fcm_cell_rules_get_stats(on)->decision[0].simplified == 1 &&
            fcm_cell_rules_get_stats(off)->decision[0].simplified == 0);
  check_decision(many, 1);
  check_decision(none, 0);
  check_decision(cheap, 0);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    TEST_TRUE(same_rules(many, on, (fcm_rule_kind)k));
    TEST_TRUE(same_rules(none, off, (fcm_rule_kind)k));
    TEST_TRUE(same_rules(cheap, off, (fcm_rule_kind)k));
    TEST_TRUE(fcm_cell_rules_get_stats(none)->decision[k].point_cost ==
              fcm_cell_rules_point_cost(FCM_ELEMENT_HEX8, (fcm_rule_kind)k));
  }
done:
  fcm_cell_rules_destroy(&off);
  fcm_cell_rules_destroy(&on);
  fcm_cell_rules_destroy(&many);
  fcm_cell_rules_destroy(&none);
  fcm_cell_rules_destroy(&cheap);
  fcm_cell_rules_destroy(&mid1);
  fcm_cell_rules_destroy(&mid2);
}

static void errors(const fcm_mesh *m, const fcm_geometry *g)
{
  fcm_cell_rules *r = NULL;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.simplify = (fcm_cell_simplify)3;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), FCM_ERR_ARG,
           "simplify = 3 is not a mode");
  o = fcm_cell_rules_options_default();
  o.moments = (fcm_cell_moments)3;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), FCM_ERR_ARG, "moments = 3 is not a path");
  o = fcm_cell_rules_options_default();
  o.simplify = FCM_CELL_SIMPLIFY_AUTO;
  o.expected_assemblies[FCM_RULE_MASS] = -1.0;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), FCM_ERR_ARG,
           "expected_assemblies[mass] = -1 must be finite and >= 0");
  o = fcm_cell_rules_options_default();
  o.simplify = FCM_CELL_SIMPLIFY_AUTO;
  o.point_cost[FCM_RULE_STIFFNESS] = 0.0;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), FCM_ERR_ARG,
           "point_cost[stiffness] = 0 must be > 0");
  TEST_TRUE(r == NULL);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  cost_model();
  const double c0[3] = {0.1, 0.05, -0.02}, lo[3] = {-1.5, -1.5, -1.5}, hi[3] = {1.5, 1.5, 1.5};
  const fcm_index n[3] = {3, 3, 3};
  fcm_geometry *g = NULL;
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.3, 2, &g));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  if (g && m) {
    auto_mode(m, g);
    errors(m, g);
  }
  fcm_mesh_destroy(&m);
  fcm_geometry_destroy(&g);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
