/* Rule storage and its options: uncut cells get the catalogue rule of the element's
 * strengths (lib/METHOD.md §3 defaults per kind), cut cells authentic points then stabilization
 * points (the full cell's rule times alpha, flag 1) per mode (mass + stiffness, mass only,
 * off), simplified counts <= M with the statistics adding up; the point dump lists every
 * point with X = map(xi) and w_phys = w_ref det J; the output is identical for 1, 2 and 3
 * threads; accessors reject out-of-range cells and kinds. */
#include "fcm/embed.h"
#include "test.h"

#include <stdlib.h>

static fcm_ctx *ctx;

static fcm_cell_rules *build(const fcm_mesh *m, const fcm_geometry *g, fcm_stabilization_mode mode,
                             int simplify, int threads)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.stabilization.mode = mode;
  o.stabilization.alpha = 1e-3;
  o.simplify = simplify;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, threads));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, FCM_DEFAULT));
  return r;
}

static void stabilization_and_classes(const fcm_mesh *m, const fcm_geometry *g)
{
  const fcm_element_type type = fcm_mesh_element_type(m);
  const fcm_element_info *info = fcm_element_get_info(type);
  for (int mode = 0; mode < FCM_STABILIZATION_MODE_COUNT; mode++) {
    /* Simplified in the default mode only (the LPs dominate the time). */
    const int simplified = mode == FCM_STABILIZATION_MASS_STIFFNESS;
    fcm_cell_rules *r = build(m, g, (fcm_stabilization_mode)mode, simplified, FCM_DEFAULT);
    if (!r) return;
    TEST_TRUE(fcm_cell_rules_strength(r, FCM_RULE_STIFFNESS) == info->stiffness_strength);
    TEST_TRUE(fcm_cell_rules_strength(r, FCM_RULE_MASS) == info->mass_strength);
    TEST_TRUE(fcm_cell_rules_element_type(r) == type);
    TEST_TRUE(fcm_cell_rules_num_cells(r) == fcm_mesh_num_cells(m));
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    TEST_TRUE(S->num_uncut > 0 && S->num_cut > 0 && S->num_dropped > 0);
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      const int mk = fcm_cell_rules_strength(r, (fcm_rule_kind)k);
      const int M = (mk + 1) * (mk + 2) * (mk + 3) / 6;
      const int stab = mode == FCM_STABILIZATION_MASS_STIFFNESS ||
                       (mode == FCM_STABILIZATION_MASS && k == FCM_RULE_MASS);
      fcm_rule *full = NULL;
      TEST_OK(ctx, fcm_rule_create(ctx, info->shape, mk, &full));
      if (!full) continue;
      const int nf = fcm_rule_num_points(full);
      const double *fp = fcm_rule_points(full), *fw = fcm_rule_weights(full);
      fcm_index sum_auth = 0, sum_stab = 0, sum_all = 0;
      for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
        int n;
        const double *p, *w;
        const unsigned char *f;
        TEST_OK(ctx, fcm_cell_rules_get(r, c, (fcm_rule_kind)k, &n, &p, &w, &f));
        sum_all += n;
        const fcm_cell_class cls = fcm_cell_rules_class(r, c);
        if (cls == FCM_CELL_UNCUT) { /* the catalogue rule itself */
          TEST_TRUE(n == nf);
          for (int j = 0; j < n; j++)
            TEST_TRUE(f[j] == 0 && w[j] == fw[j] && p[3 * j] == fp[3 * j] &&
                      p[3 * j + 1] == fp[3 * j + 1] && p[3 * j + 2] == fp[3 * j + 2]);
          continue;
        }
        if (cls == FCM_CELL_DROPPED) {
          TEST_TRUE(n == 0);
          continue;
        }
        int na = 0;
        while (na < n && f[na] == 0)
          na++;
        TEST_TRUE(na >= 1 && (!simplified || na <= M));
        TEST_TRUE(n - na == (stab ? nf : 0));
        sum_auth += na, sum_stab += n - na;
        for (int j = na; j < n; j++) { /* stabilization: the full rule times alpha */
          const int q = j - na;
          TEST_TRUE(f[j] == 1 && p[3 * j] == fp[3 * q] && p[3 * j + 1] == fp[3 * q + 1] &&
                    p[3 * j + 2] == fp[3 * q + 2]);
          TEST_NEAR(w[j], 1e-3 * fw[q], 1e-15, 0);
        }
      }
      TEST_TRUE(sum_auth == S->points_simplified[k] && sum_stab == S->points_stabilization[k]);
      TEST_TRUE(sum_all == S->points_total[k]);
      TEST_TRUE(simplified ? S->points_initial[k] >= S->points_simplified[k]
                           : S->points_initial[k] == S->points_simplified[k]);
      TEST_TRUE(S->max_residual[k] <= 1e-12 && S->simplify_fallbacks[k] == 0);
      fcm_rule_destroy(&full);
    }
    fcm_cell_rules_destroy(&r);
  }
}

static void dump(const fcm_mesh *m, const fcm_geometry *g)
{
  fcm_cell_rules *r = build(m, g, FCM_STABILIZATION_MASS_STIFFNESS, 0, FCM_DEFAULT);
  if (!r) return;
  FILE *f = tmpfile();
  TEST_TRUE(f != NULL);
  if (!f) return;
  TEST_OK(ctx, fcm_cell_rules_view_points(r, m, FCM_RULE_MASS, f));
  rewind(f);
  char line[512];
  TEST_TRUE(fgets(line, sizeof line, f) && line[0] == '#');
  const fcm_element_type type = fcm_mesh_element_type(m);
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3];
  fcm_index count = 0;
  long long cell;
  double v[8];
  int flag;
  while (fscanf(f, "%lld %lf %lf %lf %lf %lf %lf %lf %lf %d", &cell, v, v + 1, v + 2, v + 3, v + 4,
                v + 5, v + 6, v + 7, &flag) == 10) {
    fcm_mesh_cell_coords(m, cell, X);
    fcm_element_map(type, X, v, x);
    const double det = fcm_element_jacobian(type, X, v, J);
    for (int d = 0; d < 3; d++)
      TEST_NEAR(v[3 + d], x[d], 1e-15, 1e-15);
    TEST_NEAR(v[7], v[6] * det, 1e-15, 0);
    TEST_TRUE(flag == 0 || flag == 1);
    count++;
  }
  TEST_TRUE(feof(f));
  TEST_TRUE(count == fcm_cell_rules_get_stats(r)->points_total[FCM_RULE_MASS]);
  fclose(f);
  f = tmpfile();
  if (f) {
    fcm_cell_rules_view(r, f);
    TEST_TRUE(ftell(f) > 100);
    fclose(f);
  }
  fcm_cell_rules_destroy(&r);
}

static void threads(const fcm_mesh *m, const fcm_geometry *g)
{
  fcm_cell_rules *r[3] = {NULL, NULL, NULL};
  for (int t = 0; t < 3; t++)
    r[t] = build(m, g, FCM_STABILIZATION_MASS_STIFFNESS, 1, t + 1);
  if (!r[0] || !r[1] || !r[2]) goto done;
  TEST_TRUE(fcm_cell_rules_get_stats(r[2])->num_threads == 3);
  for (int t = 1; t < 3; t++)
    for (fcm_index c = 0; c < fcm_mesh_num_cells(m); c++) {
      TEST_TRUE(fcm_cell_rules_class(r[0], c) == fcm_cell_rules_class(r[t], c));
      TEST_TRUE(fcm_cell_rules_volume_fraction(r[0], c) == fcm_cell_rules_volume_fraction(r[t], c));
      for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
        int n0, n1;
        const double *p0, *p1, *w0, *w1;
        const unsigned char *f0, *f1;
        TEST_OK(ctx, fcm_cell_rules_get(r[0], c, (fcm_rule_kind)k, &n0, &p0, &w0, &f0));
        TEST_OK(ctx, fcm_cell_rules_get(r[t], c, (fcm_rule_kind)k, &n1, &p1, &w1, &f1));
        TEST_TRUE(n0 == n1);
        if (n0 == n1 && n0 > 0)
          TEST_TRUE(!memcmp(p0, p1, 3 * (size_t)n0 * sizeof *p0) &&
                    !memcmp(w0, w1, (size_t)n0 * sizeof *w0) && !memcmp(f0, f1, (size_t)n0));
      }
    }
done:
  for (int t = 0; t < 3; t++)
    fcm_cell_rules_destroy(&r[t]);
}

static void accessors(const fcm_mesh *m, const fcm_geometry *g)
{
  fcm_cell_rules *r = build(m, g, FCM_STABILIZATION_OFF, 0, 1);
  if (!r) return;
  int n = 7;
  const double *p = (const double *)&n;
  const fcm_index nc = fcm_mesh_num_cells(m);
  TEST_ERR(ctx, fcm_cell_rules_get(r, nc, FCM_RULE_MASS, &n, &p, NULL, NULL), FCM_ERR_ARG,
           "out of range");
  TEST_TRUE(n == 0 && p == NULL);
  TEST_ERR(ctx, fcm_cell_rules_get(r, 0, (fcm_rule_kind)2, &n, NULL, NULL, NULL), FCM_ERR_ARG,
           "kind 2");
  TEST_ERR(ctx, fcm_cell_rules_get_surface(r, -1, &n, NULL, NULL, NULL, NULL), FCM_ERR_ARG,
           "cell -1 out of range");
  TEST_TRUE(fcm_cell_rules_class(r, nc) == FCM_CELL_DROPPED);
  TEST_TRUE(fcm_cell_rules_volume_fraction(r, -1) == 0.0);
  TEST_TRUE(fcm_cell_rules_surface_strength(r) == -1);
  TEST_OK(ctx, fcm_cell_rules_get_surface(r, 0, &n, NULL, NULL, NULL, NULL));
  TEST_TRUE(n == 0);
  TEST_ERR(ctx, fcm_cell_rules_view_points(r, m, (fcm_rule_kind)5, stdout), FCM_ERR_ARG, "kind 5");
  fcm_cell_rules_destroy(&r);
  fcm_cell_rules_destroy(&r);
  fcm_cell_rules_destroy(NULL);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double c0[3] = {0.1, 0.05, -0.02}, lo[3] = {-1.5, -1.5, -1.5}, hi[3] = {1.5, 1.5, 1.5};
  const fcm_index n[3] = {4, 4, 4};
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 1.3, 2, &g));
  for (int t = 0; t < FCM_ELEMENT_COUNT && g; t++) {
    fcm_mesh *m = NULL;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, (fcm_element_type)t, lo, hi, n, &m));
    if (!m) continue;
    if (t != FCM_ELEMENT_HEX20) stabilization_and_classes(m, g); /* mass 8: LPs too slow */
    if (t == FCM_ELEMENT_HEX8) {
      dump(m, g);
      accessors(m, g);
    }
    fcm_mesh_destroy(&m);
  }
  /* Last: a team of 3 threads followed by smaller teams would end the third thread, and
   * GLPK's per-thread environment (simplify module) is not released at thread exit. */
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET10, lo, hi, n, &m));
  if (m && g) threads(m, g);
  fcm_mesh_destroy(&m);
  fcm_geometry_destroy(&g);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
