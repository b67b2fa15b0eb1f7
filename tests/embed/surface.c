/* Surface rules on the embedded boundary: the weights of all cells sum to the boundary
 * area; for every monomial f of degree <= s and every axis d, sum w f n_d equals the
 * volume integral of df/dx_d (divergence theorem, exact moments of the geometry's tets);
 * points lie in their triangle's plane and in their cell; normals are unit. A boundary
 * lying exactly on cell faces is counted once, in the cell holding the material. */
#include "fcm/embed.h"
#include "../geom/exact.h"
#include "test.h"

static fcm_ctx *ctx;

static void check(const fcm_mesh *mesh, const fcm_geometry *g, int s, const char *what)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.surface_strength = s;
  o.min_fraction = 0.0;
  o.simplify = 0;
  o.strength[FCM_RULE_STIFFNESS] = 1;
  o.strength[FCM_RULE_MASS] = 1;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  if (!r) return;
  TEST_TRUE(fcm_cell_rules_surface_strength(r) == s);
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  const int tet = type == FCM_ELEMENT_TET4 || type == FCM_ELEMENT_TET10;
  const double *gx = fcm_geometry_coords(g);
  const fcm_index *gt = fcm_geometry_boundary_triangles(g);
  const int nm = exact_num_mono(s);
  double X[3 * FCM_ELEMENT_MAX_NODES], x[3], vals[EXACT_MAX_MONO];
  double flux[3][EXACT_MAX_MONO] = {{0}}, area = 0.0;
  fcm_index npts = 0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    int n;
    const double *p, *w, *nrm;
    const fcm_index *tri;
    TEST_OK(ctx, fcm_cell_rules_get_surface(r, c, &n, &p, &w, &nrm, &tri));
    npts += n;
    if (fcm_cell_rules_class(r, c) == FCM_CELL_DROPPED) TEST_TRUE(n == 0);
    fcm_mesh_cell_coords(mesh, c, X);
    for (int j = 0; j < n; j++) {
      const double *xi = p + 3 * j, *nj = nrm + 3 * j;
      TEST_TRUE(w[j] > 0.0 && isfinite(w[j]));
      TEST_NEAR(nj[0] * nj[0] + nj[1] * nj[1] + nj[2] * nj[2], 1.0, 1e-14, 0);
      if (tet)
        TEST_TRUE(xi[0] >= -1e-12 && xi[1] >= -1e-12 && xi[2] >= -1e-12 &&
                  xi[0] + xi[1] + xi[2] <= 1 + 1e-12);
      else
        TEST_TRUE(fabs(xi[0]) <= 1 + 1e-12 && fabs(xi[1]) <= 1 + 1e-12 && fabs(xi[2]) <= 1 + 1e-12);
      fcm_element_map(type, X, xi, x);
      TEST_TRUE(tri[j] >= 0 && tri[j] < fcm_geometry_num_boundary_triangles(g));
      const double *a = gx + 3 * gt[3 * tri[j]];
      TEST_NEAR(nj[0] * (x[0] - a[0]) + nj[1] * (x[1] - a[1]) + nj[2] * (x[2] - a[2]), 0, 0, 1e-13);
      area += w[j];
      exact_eval(s, x, vals);
      for (int d = 0; d < 3; d++)
        for (int k = 0; k < nm; k++)
          flux[d][k] += w[j] * vals[k] * nj[d];
    }
  }
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  TEST_TRUE(S->surface_points == npts);
  TEST_NEAR(S->embedded_area, area, 1e-14, 0);
  TEST_NEAR(area, exact_boundary_area(g), 1e-12, 0);
  /* Divergence theorem against exact volume moments of degree s - 1. */
  double vol[EXACT_MAX_MONO] = {0};
  const double *x0 = fcm_geometry_coords(g);
  const fcm_index *cells = fcm_geometry_cells(g);
  for (fcm_index k = 0; k < fcm_geometry_num_cells(g); k++) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++)
        v[a][d] = x0[3 * cells[4 * k + a] + d];
    exact_tet_add(v, s > 0 ? s - 1 : 0, vol);
  }
  for (int k = 0; k < nm; k++) {
    int e[3];
    exact_exponents(s, k, e);
    for (int d = 0; d < 3; d++) {
      double expect = 0.0;
      if (e[d] > 0) {
        int de[3] = {e[0], e[1], e[2]};
        de[d]--;
        expect = e[d] * vol[exact_index(de)];
      }
      if (!(fabs(flux[d][k] - expect) <= 1e-12 * fmax(1.0, fabs(expect))))
        TEST_FAIL_("%s: flux of x^%d y^%d z^%d along %d: %.17g, expected %.17g", what, e[0], e[1],
                   e[2], d, flux[d][k], expect);
    }
  }
  fcm_cell_rules_destroy(&r);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index n3[3] = {3, 3, 3}, n2[3] = {2, 2, 2};
  /* Ball in Hex8 and Hex20 grids; hemisphere in a Tet4 grid. */
  const double c0[3] = {0.05, -0.1, 0.02};
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c0, 0.8, 2, &g));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n3, &mesh));
  if (g && mesh) check(mesh, g, 3, "ball in hex8");
  fcm_mesh_destroy(&mesh);
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX20, lo, hi, n2, &mesh));
  if (g && mesh) check(mesh, g, 4, "ball in hex20");
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&g);
  const double hlo[3] = {-1, 0, -1};
  const fcm_index nh[3] = {2, 1, 2};
  TEST_OK(ctx, fcm_geometry_create_hemisphere(ctx, (double[3]){0, 0, 0}, 1.0, 2, &g));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_TET4, hlo, hi, nh, &mesh));
  if (g && mesh) check(mesh, g, 2, "hemisphere in tet4");
  fcm_mesh_destroy(&mesh);
  fcm_geometry_destroy(&g);
  /* The box [0,1]^3 fills one cell exactly: its 6 faces lie on cell faces. */
  const double blo[3] = {0, 0, 0};
  const fcm_index nb[3] = {2, 1, 1};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, hi, nb, &g));
  for (int t = 0; t < 2 && g; t++) {
    const fcm_element_type type = t ? FCM_ELEMENT_TET4 : FCM_ELEMENT_HEX8;
    TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n2, &mesh));
    if (!mesh) continue;
    check(mesh, g, 1, t ? "box in tet4" : "box in hex8");
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.surface_strength = 0;
    fcm_cell_rules *r = NULL;
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
    if (r) {
      TEST_NEAR(fcm_cell_rules_get_stats(r)->embedded_area, 6.0, 1e-15, 0);
      for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
        int n;
        TEST_OK(ctx, fcm_cell_rules_get_surface(r, c, &n, NULL, NULL, NULL, NULL));
        /* Only the cells inside [0,1]^3 carry the faces. */
        if (fcm_cell_rules_class(r, c) != FCM_CELL_UNCUT) TEST_TRUE(n == 0);
      }
    }
    fcm_cell_rules_destroy(&r);
    fcm_mesh_destroy(&mesh);
  }
  fcm_geometry_destroy(&g);
  /* Two unit boxes touching at x = 0 without shared nodes: both x = 0 faces are boundary,
   * opposite normals, on a face between two kept cells; each cell keeps its own box's. */
  {
    fcm_geometry *a = NULL, *b = NULL;
    const double alo[3] = {-1, 0, 0}, ahi[3] = {0, 1, 1};
    const fcm_index one[3] = {1, 1, 1};
    TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, hi, one, &a));
    TEST_OK(ctx, fcm_geometry_create_box(ctx, alo, ahi, one, &b));
    if (a && b) {
      double x[2 * 3 * 8];
      fcm_index c[2 * 24];
      memcpy(x, fcm_geometry_coords(a), 24 * sizeof *x);
      memcpy(x + 24, fcm_geometry_coords(b), 24 * sizeof *x);
      for (int k = 0; k < 24; k++)
        c[k] = fcm_geometry_cells(a)[k], c[24 + k] = fcm_geometry_cells(b)[k] + 8;
      TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 16, x, 12, c, &g));
    }
    TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n2, &mesh));
    if (g && mesh) {
      TEST_NEAR(exact_boundary_area(g), 12.0, 1e-15, 0);
      check(mesh, g, 2, "touching boxes");
      fcm_cell_rules_options o = fcm_cell_rules_options_default();
      o.surface_strength = 0;
      fcm_cell_rules *r = NULL;
      TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
      for (fcm_index cell = 0; r && cell < fcm_mesh_num_cells(mesh); cell++) {
        int n;
        const double *w;
        TEST_OK(ctx, fcm_cell_rules_get_surface(r, cell, &n, NULL, &w, NULL, NULL));
        double area = 0.0;
        for (int j = 0; j < n; j++)
          area += w[j];
        TEST_NEAR(area, fcm_cell_rules_class(r, cell) == FCM_CELL_UNCUT ? 6.0 : 0.0, 1e-15, 0);
      }
      fcm_cell_rules_destroy(&r);
    }
    fcm_mesh_destroy(&mesh);
    fcm_geometry_destroy(&g);
    fcm_geometry_destroy(&a);
    fcm_geometry_destroy(&b);
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
