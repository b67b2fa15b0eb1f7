/* Global checks of the per-cell rules of procedural shapes in background meshes of every
 * element type, including non-affine (trapezoidal) Hex8 cells: the per-cell embedded
 * volumes sum to the geometry volume (1e-12), and the authentic points of all cells
 * reproduce every moment of degree <= the kind's strength of the geometry, computed here
 * from its tets by the exact barycentric formula (initial and simplified rules; for the
 * non-affine cells the initial rules of cut cells, which are exact in physical
 * coordinates). Classes agree with the volume fractions. */
#include "fcm/embed.h"
#include "../geom/exact.h"
#include "test.h"

static fcm_ctx *ctx;

/* Exact moments of degree <= m over a Hex8 cell with planar faces (6 Kuhn tets). */
static void hex_moments(const double *X, int m, double *mom)
{
  static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                 {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
  for (int t = 0; t < 6; t++) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        v[a][d] = X[3 * kuhn[t][a] + d];
    exact_tet_add(v, m, mom);
  }
}

/* Uncut cells use the catalogue rule, exact in reference coordinates; with non-affine
 * cells (`affine` 0) the uncut cells' exact physical moments are subtracted instead of
 * integrating them with the rule. */
static void check(const fcm_mesh *mesh, const fcm_geometry *g, int simplify, const char *what,
                  int affine)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0; /* keep every non-empty cell: moments must add up exactly */
  o.simplify = simplify;
  o.strength[FCM_RULE_MASS] = 4;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  if (!r) return;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  const double V = fcm_geometry_volume(g);
  TEST_NEAR(S->embedded_volume, V, 1e-12, 0);
  TEST_NEAR(S->geometry_volume, V, 0, 0);
  TEST_TRUE(S->num_uncut + S->num_cut + S->num_dropped == S->num_cells);
  TEST_TRUE(S->num_cut > 0 && S->num_slivers >= 0 && S->points_initial[0] > 0);
  if (!simplify) TEST_TRUE(S->points_simplified[0] == S->points_initial[0]);
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3], vals[EXACT_MAX_MONO];
  for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
    const int m = fcm_cell_rules_strength(r, (fcm_rule_kind)kind);
    const int nm = exact_num_mono(m);
    double exact[EXACT_MAX_MONO], got[EXACT_MAX_MONO] = {0}, absum[EXACT_MAX_MONO] = {0};
    exact_geometry_moments(g, m, exact);
    fcm_index total = 0;
    for (fcm_index c = 0; c < nc; c++) {
      const fcm_cell_class cls = fcm_cell_rules_class(r, c);
      const double phi = fcm_cell_rules_volume_fraction(r, c);
      TEST_TRUE(phi >= 0.0 && phi <= 1.0 + 1e-12);
      TEST_TRUE(cls == FCM_CELL_UNCUT ? phi >= 1.0 - 1e-12
                                      : (cls == FCM_CELL_CUT ? phi > 0.0 : phi == 0.0));
      int n;
      const double *p, *w;
      const unsigned char *f;
      TEST_OK(ctx, fcm_cell_rules_get(r, c, (fcm_rule_kind)kind, &n, &p, &w, &f));
      total += n;
      fcm_mesh_cell_coords(mesh, c, X);
      if (!affine && cls == FCM_CELL_UNCUT) {
        double km[EXACT_MAX_MONO] = {0};
        hex_moments(X, m, km);
        for (int k = 0; k < nm; k++)
          exact[k] -= km[k], absum[k] += fabs(km[k]);
        continue;
      }
      for (int j = 0; j < n; j++) {
        TEST_TRUE(isfinite(w[j]) && w[j] > 0.0);
        if (f[j]) continue; /* stabilization points are not part of the geometry */
        fcm_element_map(type, X, p + 3 * j, x);
        const double det = fcm_element_jacobian(type, X, p + 3 * j, J);
        exact_eval(m, x, vals);
        for (int k = 0; k < nm; k++)
          got[k] += w[j] * det * vals[k], absum[k] += fabs(w[j] * det * vals[k]);
      }
    }
    TEST_TRUE(total == S->points_total[kind]);
    for (int k = 0; k < nm; k++)
      if (!(fabs(got[k] - exact[k]) <= 1e-12 * absum[k] + 1e-14 * V)) {
        int e[3];
        exact_exponents(m, k, e);
        TEST_FAIL_("%s simplify %d kind %d x^%d y^%d z^%d: %.17g vs exact %.17g", what, simplify,
                   kind, e[0], e[1], e[2], got[k], exact[k]);
      }
  }
  fcm_cell_rules_destroy(&r);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  /* Hemisphere of radius 1 on y = 0 in [-1,1] x [0,1] x [-1,1] (the convergence setup). */
  {
    const double c0[3] = {0, 0, 0}, lo[3] = {-1, 0, -1}, hi[3] = {1, 1, 1};
    const fcm_index n[3] = {4, 2, 4};
    TEST_OK(ctx, fcm_geometry_create_hemisphere(ctx, c0, 1.0, 3, &g));
    for (int t = 0; t < FCM_ELEMENT_COUNT && g; t++) {
      TEST_OK(ctx, fcm_mesh_create_box(ctx, (fcm_element_type)t, lo, hi, n, &mesh));
      if (mesh) check(mesh, g, t % 2, fcm_element_get_info((fcm_element_type)t)->name, 1);
      fcm_mesh_destroy(&mesh);
    }
    fcm_geometry_destroy(&g);
  }
  /* Tube and hollow ball with holes in a Tet4 and a Hex20 grid. */
  {
    const double c0[3] = {0.05, -0.03, 0.02}, lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.2, 1.1};
    const fcm_index n[3] = {3, 3, 3};
    fcm_geometry *tube = NULL;
    TEST_OK(ctx, fcm_geometry_create_tube(ctx, c0, 1, 0.5, 0.9, 2.0, 2, 12, 3, &tube));
    TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.5, 1.0, 0.3, 4, 2, &g));
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET4, lo, hi, n, &mesh));
    if (mesh && tube && g) {
      check(mesh, tube, 1, "tube in tet4", 1);
      check(mesh, g, 0, "hollow ball in tet4", 1);
    }
    fcm_mesh_destroy(&mesh);
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX20, lo, hi, n, &mesh));
    if (mesh && g) check(mesh, g, 0, "hollow ball in hex20", 1);
    fcm_mesh_destroy(&mesh);
    fcm_geometry_destroy(&tube);
    fcm_geometry_destroy(&g);
  }
  /* Ball in trapezoidal Hex8 cells (z scaled by 1 + 0.2 x: planar faces, not affine). */
  {
    const double c0[3] = {0.1, 0.0, -0.05}, lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    const fcm_index n[3] = {3, 3, 3};
    fcm_mesh *box = NULL;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &box));
    if (box) {
      const fcm_index nn = fcm_mesh_num_nodes(box), ncell = fcm_mesh_num_cells(box);
      double *x = malloc(3 * (size_t)nn * sizeof *x);
      memcpy(x, fcm_mesh_coords(box), 3 * (size_t)nn * sizeof *x);
      for (fcm_index a = 0; a < nn; a++)
        x[3 * a + 2] *= 1.2 + 0.2 * x[3 * a];
      TEST_OK(ctx,
              fcm_mesh_create(ctx, FCM_ELEMENT_HEX8, nn, x, ncell, fcm_mesh_cells(box), &mesh));
      free(x);
    }
    TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.85, 3, &g));
    if (mesh && g) {
      double X[24];
      fcm_mesh_cell_coords(mesh, 0, X);
      TEST_TRUE(!fcm_element_is_affine(FCM_ELEMENT_HEX8, X, 1e-6));
      /* Cut cells: the mapped tet rules are exact in physical coordinates whatever the
       * map (simplified rules keep reference moments only, so they are not checked here). */
      check(mesh, g, 0, "ball in trapezoids", 0);
    }
    fcm_mesh_destroy(&box);
    fcm_mesh_destroy(&mesh);
    fcm_geometry_destroy(&g);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
