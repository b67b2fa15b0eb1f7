/* Only the rule kinds asked for are built (fcm_cell_rules_options.kinds): stiffness alone
 * gives the same stiffness rules as both kinds, no mass points anywhere (statistics, dump,
 * accessors); asking for the kind that was not built is FCM_ERR_ARG naming it (rules
 * accessors, the mass matrix, the momentum), never an empty rule; the stiffness matrix still
 * assembles; a cut keeps the kinds; bad kind sets are rejected. */
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/la.h"
#include "fcm/material.h"
#include "test.h"

#include <stdlib.h>

static fcm_ctx *ctx;

static fcm_cell_rules *build(const fcm_mesh *m, const fcm_geometry *g, unsigned kinds)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.kinds = kinds;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 1));
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r));
  return r;
}

/* Stiffness rules identical to those of a build with both kinds; no mass anywhere. */
static void stiffness_only(const fcm_mesh *m, const fcm_geometry *g)
{
  fcm_cell_rules *all = build(m, g, FCM_RULES_ALL), *st = build(m, g, FCM_RULES_STIFFNESS);
  if (!all || !st) goto done;
  const fcm_cell_rules_stats *sa = fcm_cell_rules_get_stats(all);
  const fcm_cell_rules_stats *ss = fcm_cell_rules_get_stats(st);
  TEST_TRUE(sa->kinds == FCM_RULES_ALL && ss->kinds == FCM_RULES_STIFFNESS);
  TEST_TRUE(fcm_cell_rules_has_kind(all, FCM_RULE_MASS) &&
            !fcm_cell_rules_has_kind(st, FCM_RULE_MASS));
  TEST_TRUE(fcm_cell_rules_has_kind(st, FCM_RULE_STIFFNESS));
  TEST_TRUE(!fcm_cell_rules_has_kind(st, (fcm_rule_kind)7) && !fcm_cell_rules_has_kind(NULL, 0));
  TEST_TRUE(sa->num_cut > 0 && sa->num_uncut > 0); /* both classes are exercised */
  TEST_TRUE(sa->points_total[FCM_RULE_MASS] > 0);
  TEST_TRUE(ss->points_initial[FCM_RULE_MASS] == 0 && ss->points_simplified[FCM_RULE_MASS] == 0 &&
            ss->points_stabilization[FCM_RULE_MASS] == 0 && ss->points_total[FCM_RULE_MASS] == 0);
  TEST_TRUE(ss->points_total[FCM_RULE_STIFFNESS] == sa->points_total[FCM_RULE_STIFFNESS]);
  TEST_TRUE(ss->num_cut == sa->num_cut && ss->embedded_volume == sa->embedded_volume);
  TEST_TRUE(fcm_cell_rules_strength(st, FCM_RULE_MASS) == -1);
  TEST_TRUE(fcm_cell_rules_strength(st, FCM_RULE_STIFFNESS) ==
            fcm_cell_rules_strength(all, FCM_RULE_STIFFNESS));
  for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
    int na = -1, ns = -2;
    const double *pa, *ps, *wa, *ws;
    TEST_OK(ctx, fcm_cell_rules_get(all, c, FCM_RULE_STIFFNESS, &na, &pa, &wa, NULL));
    TEST_OK(ctx, fcm_cell_rules_get(st, c, FCM_RULE_STIFFNESS, &ns, &ps, &ws, NULL));
    TEST_TRUE(na == ns);
    if (na == ns && na > 0)
      TEST_TRUE(!memcmp(pa, ps, 3 * (size_t)na * sizeof *pa) &&
                !memcmp(wa, ws, (size_t)na * sizeof *wa));
  }
  /* the kind not built: an error naming it, outputs cleared, for uncut and cut cells */
  for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
    if (fcm_cell_rules_class(st, c) == FCM_CELL_DROPPED) continue;
    int n = 5;
    const double *p = (const double *)&n;
    TEST_ERR(ctx, fcm_cell_rules_get(st, c, FCM_RULE_MASS, &n, &p, NULL, NULL), FCM_ERR_ARG,
             "no mass rules were built");
    TEST_TRUE(n == 0 && p == NULL);
    fcm_index first = 0;
    fcm_cell_rules_cell_pieces(st, c, &first);
    TEST_ERR(ctx, fcm_cell_rules_get_piece(st, first, FCM_RULE_MASS, &n, NULL, NULL, NULL),
             FCM_ERR_ARG, "FCM_RULES_MASS");
  }
  FILE *devnull = fopen("/dev/null", "w");
  if (devnull) {
    TEST_ERR(ctx, fcm_cell_rules_view_points(st, m, FCM_RULE_MASS, devnull), FCM_ERR_ARG,
             "no mass rules");
    TEST_OK(ctx, fcm_cell_rules_view_points(st, m, FCM_RULE_STIFFNESS, devnull));
    fcm_cell_rules_view(st, devnull);
    fclose(devnull);
  }

  /* assembly: stiffness works, the mass matrix and the momentum are clear errors */
  fcm_space *sp = NULL;
  fcm_csr *A = NULL;
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  TEST_OK(ctx, fcm_space_create_embedded(ctx, m, st, &sp));
  if (sp) TEST_OK(ctx, fcm_space_matrix_create(sp, &A));
  if (sp && A) {
    TEST_OK(ctx, fcm_assemble_stiffness(sp, &mat, NULL, A));
    TEST_ERR(ctx, fcm_assemble_mass(sp, &mat, NULL, A), FCM_ERR_ARG,
             "mass matrix needs mass rules");
    double mass = -1.0;
    TEST_ERR(ctx, fcm_space_momentum(sp, mat.density, NULL, NULL, &mass, NULL, NULL), FCM_ERR_ARG,
             "without them");
  }
  fcm_csr_destroy(&A);
  fcm_space_destroy(&sp);

  /* mass only: the stiffness integrals are the error now, the mass matrix assembles */
  fcm_cell_rules *mo = build(m, g, FCM_RULES_MASS);
  if (mo) {
    TEST_TRUE(fcm_cell_rules_get_stats(mo)->points_total[FCM_RULE_STIFFNESS] == 0);
    TEST_TRUE(fcm_cell_rules_get_stats(mo)->points_total[FCM_RULE_MASS] ==
              sa->points_total[FCM_RULE_MASS]);
    TEST_OK(ctx, fcm_space_create_embedded(ctx, m, mo, &sp));
    if (sp) TEST_OK(ctx, fcm_space_matrix_create(sp, &A));
    if (sp && A) {
      TEST_OK(ctx, fcm_assemble_mass(sp, &mat, NULL, A));
      TEST_ERR(ctx, fcm_assemble_stiffness(sp, &mat, NULL, A), FCM_ERR_ARG,
               "needs stiffness rules");
    }
    fcm_csr_destroy(&A);
    fcm_space_destroy(&sp);
  }
  fcm_cell_rules_destroy(&mo);

  /* a cut keeps the kinds of the rules it extends */
  const double x[9] = {-2, -2, 0.1, 2, -2, 0.1, 0, 2, 0.1};
  const fcm_index tri[3] = {0, 1, 2};
  fcm_surface *cut = NULL;
  fcm_cell_rules *rc = NULL;
  TEST_OK(ctx, fcm_surface_create(ctx, 3, x, 1, tri, &cut));
  if (cut) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, m, g, st, cut, &rc));
  if (rc) {
    TEST_TRUE(fcm_cell_rules_get_stats(rc)->kinds == FCM_RULES_STIFFNESS);
    TEST_TRUE(fcm_cell_rules_get_stats(rc)->points_total[FCM_RULE_MASS] == 0);
    TEST_TRUE(fcm_cell_rules_get_stats(rc)->num_split > 0);
  }
  fcm_cell_rules_destroy(&rc);
  fcm_surface_destroy(&cut);
done:
  fcm_cell_rules_destroy(&all);
  fcm_cell_rules_destroy(&st);
}

static void bad_options(const fcm_mesh *m, const fcm_geometry *g)
{
  static const unsigned bad[] = {0u, 4u, FCM_RULES_ALL | 8u};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.kinds = bad[i];
    fcm_cell_rules *r = (fcm_cell_rules *)&o;
    TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), FCM_ERR_ARG, "kinds = 0x");
    TEST_TRUE(r == NULL);
  }
  TEST_TRUE(fcm_cell_rules_options_default().kinds == FCM_RULES_ALL);
  TEST_TRUE(!strcmp(fcm_rule_kind_name(FCM_RULE_MASS), "mass") &&
            !strcmp(fcm_rule_kind_name(FCM_RULE_STIFFNESS), "stiffness") &&
            !strcmp(fcm_rule_kind_name((fcm_rule_kind)2), "invalid"));
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double c0[3] = {0.1, 0.05, -0.02}, lo[3] = {-1.5, -1.5, -1.5}, hi[3] = {1.5, 1.5, 1.5};
  const fcm_index n[3] = {3, 3, 3};
  fcm_geometry *g = NULL;
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.3, 2, &g));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  if (m && g) {
    stiffness_only(m, g);
    bad_options(m, g);
  }
  fcm_mesh_destroy(&m);
  fcm_geometry_destroy(&g);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
