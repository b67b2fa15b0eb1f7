/* Degenerate configurations give valid rules or a clean "dropped", never NaN: geometry
 * faces coplanar with cell faces (hex and tet grids), geometry vertices exactly on cell
 * planes (random tets snapped to grid planes: per-cell exactness against the independent
 * polytope integration), faces within the tolerance of a cell plane, a sliver tet of
 * relative volume 1e-12 and a cell cut to volume fraction 1e-10 (dropped by default;
 * with min_fraction 0 a positive rule of the right volume). */
#include "fcm/embed.h"
#include "../geom/exact.h"
#include "test.h"

static fcm_ctx *ctx;

/* Every stored number finite, weights positive, point counts consistent; returns the
 * sum over cells of the volume of the stiffness rule's authentic points. */
static double validate(const fcm_mesh *mesh, const fcm_cell_rules *r)
{
  const fcm_element_type type = fcm_mesh_element_type(mesh);
  double X[3 * FCM_ELEMENT_MAX_NODES], J[9], vol = 0.0;
  for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
    TEST_TRUE(isfinite(fcm_cell_rules_volume_fraction(r, c)));
    fcm_mesh_cell_coords(mesh, c, X);
    for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
      int n;
      const double *p, *w;
      const unsigned char *f;
      TEST_OK(ctx, fcm_cell_rules_get(r, c, (fcm_rule_kind)k, &n, &p, &w, &f));
      if (fcm_cell_rules_class(r, c) == FCM_CELL_DROPPED) TEST_TRUE(n == 0 && !p && !w && !f);
      for (int j = 0; j < n; j++) {
        TEST_TRUE(isfinite(p[3 * j]) && isfinite(p[3 * j + 1]) && isfinite(p[3 * j + 2]));
        TEST_TRUE(isfinite(w[j]) && w[j] > 0.0);
        if (k == 0 && !f[j]) vol += w[j] * fcm_element_jacobian(type, X, p + 3 * j, J);
      }
    }
  }
  return vol;
}

static fcm_cell_rules *build(const fcm_mesh *mesh, const fcm_geometry *g, double min_fraction)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = min_fraction;
  o.strength[FCM_RULE_STIFFNESS] = 3;
  o.strength[FCM_RULE_MASS] = 2;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, g, &o, &r));
  return r;
}

/* Geometry box [0,1]^3 in a 2x2x2 grid over [-1,1]^3: one cell full, the others empty. */
static void coplanar_faces(fcm_element_type type)
{
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, glo[3] = {0, 0, 0}, ghi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 2, 2}, gn[3] = {3, 2, 1};
  fcm_mesh *mesh = NULL;
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, type, lo, hi, n, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &g));
  fcm_cell_rules *r = mesh && g ? build(mesh, g, 1e-4) : NULL;
  if (r) {
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    const int per_cube = type == FCM_ELEMENT_HEX8 ? 1 : 6;
    TEST_TRUE(S->num_uncut == per_cube && S->num_cut == 0 && S->num_dropped == 7 * per_cube);
    TEST_NEAR(S->embedded_volume, 1.0, 1e-14, 0);
    TEST_NEAR(validate(mesh, r), 1.0, 1e-14, 0);
    for (fcm_index c = 0; c < fcm_mesh_num_cells(mesh); c++) {
      const double phi = fcm_cell_rules_volume_fraction(r, c);
      TEST_TRUE(fcm_cell_rules_class(r, c) == FCM_CELL_UNCUT ? fabs(phi - 1) < 1e-14 : phi == 0);
    }
  }
  fcm_cell_rules_destroy(&r);
  /* Within the clipping tolerance of the planes: the same classification. */
  fcm_geometry *t = NULL;
  const double A[9] = {1 + 2e-15, 0, 0, 0, 1, 0, 0, 0, 1}, b[3] = {-1e-15, 1e-15, 0};
  if (g) TEST_OK(ctx, fcm_geometry_create_transformed(ctx, g, A, b, &t));
  r = mesh && t ? build(mesh, t, 1e-4) : NULL;
  if (r) {
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    TEST_TRUE(S->num_cut == 0);
    TEST_NEAR(S->embedded_volume, fcm_geometry_volume(t), 1e-13, 0);
  }
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&t);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&mesh);
}

/* Random tets whose vertices lie exactly on grid planes (and grid nodes): per-cell
 * exactness for degree <= 3 against the independent polytope integration. */
static void vertices_on_planes(void)
{
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 2, 2};
  fcm_mesh *mesh = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  if (!mesh) return;
  unsigned long long rng = 5;
  for (int trial = 0; trial < 20; trial++) {
    double v[4][3];
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++) {
        const double u = exact_rand(&rng);
        /* Snap most coordinates to -1, 0 or 1. */
        v[a][d] = u < 0.6 ? (double)((int)(3 * exact_rand(&rng)) - 1) : 2 * u - 1;
      }
    const fcm_index cells[4] = {0, 1, 2, 3};
    fcm_geometry *g = NULL;
    if (fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, &v[0][0], 1, cells, &g) != FCM_OK) {
      TEST_TRUE(0);
      continue;
    }
    if (fcm_geometry_volume(g) < 1e-3) { /* flat draws are covered below */
      fcm_geometry_destroy(&g);
      continue;
    }
    fcm_cell_rules *r = build(mesh, g, 0.0);
    if (r) {
      validate(mesh, r);
      exact_plane pl[10];
      exact_tet_planes(v, pl);
      double X[24], J[9], x[3], vals[EXACT_MAX_MONO];
      for (fcm_index c = 0; c < 8; c++) {
        fcm_mesh_cell_coords(mesh, c, X);
        for (int d = 0; d < 3; d++) {
          for (int i = 0; i < 3; i++)
            pl[4 + 2 * d].n[i] = i == d, pl[5 + 2 * d].n[i] = -(i == d);
          pl[4 + 2 * d].d = X[18 + d], pl[5 + 2 * d].d = -X[d];
        }
        double exact[EXACT_MAX_MONO] = {0}, got[EXACT_MAX_MONO] = {0};
        exact_polytope_add(pl, 10, 3, 1e-13, exact);
        int np;
        const double *p, *w;
        const unsigned char *f;
        TEST_OK(ctx, fcm_cell_rules_get(r, c, FCM_RULE_STIFFNESS, &np, &p, &w, &f));
        for (int j = 0; j < np; j++) {
          if (f[j]) continue; /* stabilization */
          fcm_element_map(FCM_ELEMENT_HEX8, X, p + 3 * j, x);
          const double det = fcm_element_jacobian(FCM_ELEMENT_HEX8, X, p + 3 * j, J);
          exact_eval(3, x, vals);
          for (int k = 0; k < exact_num_mono(3); k++)
            got[k] += w[j] * det * vals[k];
        }
        for (int k = 0; k < exact_num_mono(3); k++)
          TEST_NEAR(got[k], exact[k], 0, 1e-13);
      }
    }
    fcm_cell_rules_destroy(&r);
    fcm_geometry_destroy(&g);
  }
  fcm_mesh_destroy(&mesh);
}

static void slivers(void)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {1, 1, 1};
  fcm_mesh *mesh = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  if (!mesh) return;
  /* A flat tet of volume 1e-12 inside the cell. */
  const double h = 3e-12 / 0.125; /* base area 1/8: volume h / 24 = 1e-12 */
  const double X[12] = {0.2, 0.2, 0.5, 0.7, 0.2, 0.5, 0.2, 0.7, 0.5, 0.3, 0.3, 0.5 + h};
  const fcm_index cells[4] = {0, 1, 2, 3};
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, 4, X, 1, cells, &g));
  TEST_NEAR(fcm_geometry_volume(g), 1e-12, 1e-3, 0);
  fcm_cell_rules *r = g ? build(mesh, g, 1e-4) : NULL;
  if (r) {
    TEST_TRUE(fcm_cell_rules_class(r, 0) == FCM_CELL_DROPPED);
    TEST_NEAR(fcm_cell_rules_volume_fraction(r, 0), 1e-12, 1e-3, 0);
    validate(mesh, r);
  }
  fcm_cell_rules_destroy(&r);
  r = g ? build(mesh, g, 0.0) : NULL;
  if (r) {
    TEST_TRUE(fcm_cell_rules_class(r, 0) == FCM_CELL_CUT);
    TEST_NEAR(validate(mesh, r), fcm_geometry_volume(g), 1e-10, 0);
  }
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&g);
  /* A box overlapping the cell by a layer of 1e-10: volume fraction 1e-10. */
  const double blo[3] = {-1, 0.1, 0.1}, bhi[3] = {1e-10, 0.9, 0.9}, bhi2[3] = {1, 2, 2};
  const fcm_index bn[3] = {1, 1, 1};
  fcm_geometry *b = NULL;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, bhi, bn, &b));
  r = b ? build(mesh, b, 1e-4) : NULL;
  if (r) {
    TEST_TRUE(fcm_cell_rules_class(r, 0) == FCM_CELL_DROPPED);
    TEST_NEAR(fcm_cell_rules_volume_fraction(r, 0), 0.64e-10, 1e-5, 0);
    validate(mesh, r);
  }
  fcm_cell_rules_destroy(&r);
  r = b ? build(mesh, b, 0.0) : NULL;
  if (r) {
    TEST_TRUE(fcm_cell_rules_class(r, 0) == FCM_CELL_CUT);
    TEST_NEAR(validate(mesh, r), 0.64e-10, 1e-5, 0);
  }
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&b);
  /* A box covering the cell except a layer of 1e-13: counted uncut (phi >= 1 - 1e-12). */
  const double clo[3] = {1e-13, -1, -1};
  TEST_OK(ctx, fcm_geometry_create_box(ctx, clo, bhi2, bn, &b));
  r = b ? build(mesh, b, 1e-4) : NULL;
  if (r) {
    TEST_TRUE(fcm_cell_rules_class(r, 0) == FCM_CELL_UNCUT);
    TEST_NEAR(validate(mesh, r), 1.0, 1e-15, 0);
  }
  fcm_cell_rules_destroy(&r);
  fcm_geometry_destroy(&b);
  fcm_mesh_destroy(&mesh);
}

int main(void)
{
  TEST_OK(NULL, fcm_ctx_create(NULL, &ctx));
  coplanar_faces(FCM_ELEMENT_HEX8);
  coplanar_faces(FCM_ELEMENT_TET4);
  vertices_on_planes();
  slivers();
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
