/* A geometry made of its boundary surface alone (fcm_surface_mesh_options.volume_mesh = 0):
 * the hollow ball's boundary triangles given as a surface. Asserts
 * - the geometry has no cells and the enclosed volume of the tets it came from (1e-12);
 * - its cut-cell rules, on Hex8, Tet4 and Hex20 grids: every moment of degree <= the kind's
 *   strength of the whole body equals the exact integral over the polyhedron (from the tets
 *   of the same polyhedron, 1e-12), every weight positive, at most M points a cut cell, and
 *   every cut cell fitted on surface moments (no fallback is possible);
 * - a body sticking out of the grid: the volume beyond each side computed from the surface
 *   equals the one computed from the tets (1e-12);
 * - a through-cut splits cells and keeps the volume; the volume path refuses the geometry
 *   (FCM_ERR_UNSUPPORTED);
 * - a single tet whose acute vertices end in small corner pieces of cells (2 % of a cell, a
 *   sharp tip in a corner of its box), on Hex8 and Tet4 grids: every cut cell fitted, exact. */
#include "fcm/fcm.h"
#include "../geom/exact.h"
#include "test.h"

static fcm_ctx *ctx;

static void moments(const fcm_mesh *mesh, const fcm_geometry *surf, const fcm_geometry *tets)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &r));
  if (!r) return;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  const double V = fcm_geometry_volume(tets);
  TEST_NEAR(S->embedded_volume, V, 1e-12, 0);
  TEST_TRUE(S->num_cut > 0 && S->num_surface_cells == S->num_cut && S->num_surface_fallbacks == 0);
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], x[3], vals[EXACT_MAX_MONO];
  for (int kind = 0; kind < FCM_RULE_KIND_COUNT; kind++) {
    const int m = fcm_cell_rules_strength(r, (fcm_rule_kind)kind), nm = exact_num_mono(m);
    double exact[EXACT_MAX_MONO], got[EXACT_MAX_MONO] = {0}, absum[EXACT_MAX_MONO] = {0};
    exact_geometry_moments(tets, m, exact);
    for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
      int n;
      const double *p, *w;
      const unsigned char *f;
      TEST_OK(ctx, fcm_cell_rules_get(r, c, (fcm_rule_kind)kind, &n, &p, &w, &f));
      int authentic = 0;
      fcm_mesh_cell_coords(mesh, c, X);
      for (int j = 0; j < n; j++) {
        TEST_TRUE(isfinite(w[j]) && w[j] > 0.0);
        if (f[j]) continue;
        authentic++;
        fcm_element_map(type, X, p + 3 * j, x);
        const double det = fcm_element_jacobian(type, X, p + 3 * j, J);
        exact_eval(m, x, vals);
        for (int k = 0; k < nm; k++)
          got[k] += w[j] * det * vals[k], absum[k] += fabs(w[j] * det * vals[k]);
      }
      if (fcm_cell_rules_class(r, c) == FCM_CELL_CUT) TEST_TRUE(authentic <= nm);
    }
    const int q = fcm_cell_rules_axis_degree(r, (fcm_rule_kind)kind);
    for (int k = 0; k < nm; k++)
      if (exact_in_axis(k, q)) TEST_NEAR(got[k], exact[k], 0, 1e-12 * absum[k] + 1e-14 * V);
  }
  fcm_cell_rules_destroy(&r);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  const double c0[3] = {0.05, -0.03, 0.02};
  fcm_geometry *tets = NULL, *surf = NULL;
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_geometry_create_hollow_ball(ctx, c0, 0.5, 1.0, 0.3, 4, 2, &tets));
  TEST_OK(ctx, fcm_surface_create(ctx, fcm_geometry_num_nodes(tets), fcm_geometry_coords(tets),
                                  fcm_geometry_num_boundary_triangles(tets),
                                  fcm_geometry_boundary_triangles(tets), &s));
  fcm_surface_mesh_options mo = fcm_surface_mesh_options_default();
  mo.volume_mesh = 0;
  TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, &mo, &surf));
  if (!surf) return TEST_RESULT();
  TEST_TRUE(fcm_geometry_num_cells(surf) == 0);
  TEST_NEAR(fcm_geometry_volume(surf), fcm_geometry_volume(tets), 1e-12, 0);

  const double lo[3] = {-1.1, -1.1, -1.1}, hi[3] = {1.1, 1.2, 1.1};
  const fcm_index n[3] = {4, 5, 4};
  const fcm_element_type types[3] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_TET4, FCM_ELEMENT_HEX20};
  fcm_mesh *mesh = NULL;
  for (int t = 0; t < 3; t++) {
    TEST_OK(ctx, fcm_mesh_create_box(ctx, types[t], lo, hi, n, &mesh));
    if (mesh) moments(mesh, surf, tets);
    fcm_mesh_destroy(&mesh);
  }

  /* sticking out of the grid on four sides */
  const double plo[3] = {-0.7, -0.6, -1.1}, phi[3] = {0.75, 0.8, 1.1};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, plo, phi, n, &mesh));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  fcm_cell_rules *a = NULL, *b = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &a));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, tets, &o, &b));
  if (a && b) {
    const fcm_cell_rules_stats *sa = fcm_cell_rules_get_stats(a), *sb = fcm_cell_rules_get_stats(b);
    for (int side = 0; side < 6; side++)
      TEST_NEAR(sa->outside_side_volume[side], sb->outside_side_volume[side], 1e-12,
                1e-14 * fcm_geometry_volume(tets));
    TEST_TRUE(sa->outside_side_volume[0] > 0.0 && sa->outside_side_volume[3] > 0.0);
    TEST_NEAR(sa->outside_volume, sb->outside_volume, 1e-11, 0);

    /* a cut needs no cells: the pieces keep the body's volume (tests/embed/cut_surface.c
     * compares them with the volume mesh's); what needs the cells is the volume path */
    fcm_cell_rules *cut = NULL;
    fcm_surface *plane = NULL;
    const double px[12] = {-2, 0.1, -2, 2, 0.1, -2, 2, 0.1, 2, -2, 0.1, 2};
    const fcm_index pt[6] = {0, 1, 2, 0, 2, 3};
    TEST_OK(ctx, fcm_surface_create(ctx, 4, px, 2, pt, &plane));
    TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, surf, a, plane, &cut));
    if (cut) {
      double va = 0.0, vc = 0.0;
      for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(a); p++)
        va += fcm_cell_rules_piece_volume(a, p);
      for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(cut); p++)
        vc += fcm_cell_rules_piece_volume(cut, p);
      TEST_NEAR(vc, va, 1e-12, 0);
      TEST_TRUE(fcm_cell_rules_num_pieces(cut) > fcm_cell_rules_num_pieces(a));
    }
    fcm_cell_rules_destroy(&cut);
    fcm_surface_destroy(&plane);
    o.moments = FCM_CELL_MOMENTS_VOLUME;
    TEST_ERR(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &cut), FCM_ERR_UNSUPPORTED,
             "moments = volume");
  }
  fcm_cell_rules_destroy(&a);
  fcm_cell_rules_destroy(&b);
  fcm_mesh_destroy(&mesh);

  /* the tips of a tet: the corner (2, 0, 0) in cell [1.75, 2.25] x [-0.25, 0.25]^2 */
  {
    const double tx[12] = {0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2};
    const fcm_index tc[4] = {0, 1, 2, 3};
    const double tlo[3] = {-0.25, -0.25, -0.25}, thi[3] = {2.25, 2.25, 2.25};
    const fcm_index tn[3] = {5, 5, 5};
    const fcm_element_type tt[2] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_TET4};
    fcm_geometry *tet = NULL, *tsurf = NULL;
    fcm_surface *ts = NULL;
    TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, tx, 1, tc, &tet));
    if (tet) {
      TEST_OK(ctx, fcm_surface_create(ctx, 4, tx, fcm_geometry_num_boundary_triangles(tet),
                                      fcm_geometry_boundary_triangles(tet), &ts));
      TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, ts, &mo, &tsurf));
    }
    for (int t = 0; t < 2 && tsurf; t++) {
      TEST_OK(ctx, fcm_mesh_create_box(ctx, tt[t], tlo, thi, tn, &mesh));
      if (mesh) moments(mesh, tsurf, tet);
      fcm_mesh_destroy(&mesh);
    }
    fcm_surface_destroy(&ts);
    fcm_geometry_destroy(&tsurf);
    fcm_geometry_destroy(&tet);
  }
  fcm_surface_destroy(&s);
  fcm_geometry_destroy(&surf);
  fcm_geometry_destroy(&tets);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
