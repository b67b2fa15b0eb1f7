/* A geometry made of its boundary surface alone (fcm_surface_mesh_options.volume_mesh = 0):
 * the hollow ball's boundary triangles given as a surface. Asserts
 * - the geometry has no cells and the enclosed volume of the tets it came from (1e-12);
 * - its cut-cell rules, on Hex8, Tet4 and Hex20 grids: every moment of degree <= the kind's
 *   strength of the whole body equals the exact integral over the polyhedron (from the tets
 *   of the same polyhedron, 1e-12), every weight positive, at most M points a cut cell, and
 *   every cut cell fitted on surface moments;
 * - a body sticking out of the grid: the volume beyond each side computed from the surface
 *   equals the one computed from the tets (1e-12);
 * - a through-cut splits cells and keeps the volume; the volume path refuses the geometry
 *   (FCM_ERR_UNSUPPORTED);
 * - a single tet whose acute vertices end in small corner pieces of cells (2 % of a cell, a
 *   sharp tip in a corner of its box), on Hex8 and Tet4 grids: every cut cell fitted, exact;
 * - a tilted slab 1e-3 and 1e-4 of a cell thick, on Hex8, Tet4 and Hex20 grids: the fit fails
 *   in some cells (no positive rule on the candidates carries the moments of such a thin
 *   sheet), which take the volume path on the cell split by the boundary triangles; every
 *   moment exact as above;
 * - a through-cut, then a second plane through it turned by 1e-5 rad, with tets and pieces
 *   dropped below 1e-6 of their cell (so that a wedge thicker than the cuts' tolerance can
 *   hold more than a sliver while none of its tets does): both cuts go through, the thin
 *   wedges between them take the volume path, every piece's rule is positive with no more
 *   than its piece's volume, and the small pieces' rules carry their whole volume. */
#include "fcm/fcm.h"
#include "../geom/exact.h"
#include "test.h"

#include <math.h>
#include <stdio.h>

static fcm_ctx *ctx;

/* Every moment of degree <= the kind's strength of rules r summed over the cells equals the
 * exact integral over the polyhedron of tets; every weight positive, at most M points a cut
 * piece. cell_atol: each cut cell's share of the absolute tolerance (the fits accept a
 * residual of about 1e-14 of the material's box, which a thin sheet's error in a cell follows
 * rather than its volume). */
static void check_moments(const fcm_cell_rules *r, const fcm_mesh *mesh, const fcm_geometry *tets,
                          double cell_atol)
{
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  const double V = fcm_geometry_volume(tets);
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
      fcm_index first;
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
      if (fcm_cell_rules_class(r, c) == FCM_CELL_CUT)
        TEST_TRUE(authentic <= nm * fcm_cell_rules_cell_pieces(r, c, &first));
    }
    const int q = fcm_cell_rules_axis_degree(r, (fcm_rule_kind)kind);
    for (int k = 0; k < nm; k++)
      if (exact_in_axis(k, q))
        TEST_NEAR(got[k], exact[k], 0,
                  1e-12 * absum[k] + 1e-14 * V + cell_atol * (double)S->num_cut);
  }
}

/* A geometry of nc tets (nv corners x) and its boundary as a geometry without a volume mesh. */
static void tets_and_surface(fcm_index nv, const double *x, fcm_index nc, const fcm_index *tc,
                             const fcm_surface_mesh_options *mo, fcm_geometry **tets,
                             fcm_geometry **surf)
{
  fcm_surface *s = NULL;
  TEST_OK(ctx, fcm_geometry_create(ctx, FCM_ELEMENT_TET4, nv, x, nc, tc, tets));
  if (*tets)
    TEST_OK(ctx, fcm_surface_create(ctx, nv, x, fcm_geometry_num_boundary_triangles(*tets),
                                    fcm_geometry_boundary_triangles(*tets), &s));
  if (s) TEST_OK(ctx, fcm_geometry_create_from_surface(ctx, s, mo, surf));
  fcm_surface_destroy(&s);
}

/* The rules of a surface geometry against its tets (check_moments()), every cut cell fitted on
 * surface moments; fell_back: some of them are expected to take the volume path (else none). */
static void moments(const fcm_mesh *mesh, const fcm_geometry *surf, const fcm_geometry *tets,
                    int fell_back, double cell_atol)
{
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.min_fraction = 0.0;
  fcm_cell_rules *r = NULL;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &r));
  if (!r) return;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  TEST_NEAR(S->embedded_volume, fcm_geometry_volume(tets), 1e-12, 0);
  TEST_TRUE(S->num_cut > 0 && S->num_surface_cells == S->num_cut);
  printf("element type %d: %lld of %lld cut cells took the volume path\n",
         (int)fcm_mesh_element_type(mesh), (long long)S->num_surface_fallbacks,
         (long long)S->num_cut);
  TEST_TRUE(fell_back ? S->num_surface_fallbacks > 0 : S->num_surface_fallbacks == 0);
  check_moments(r, mesh, tets, cell_atol);
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
    if (mesh) moments(mesh, surf, tets, 0, 0.0);
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

  /* thin wedges between two cuts */
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &mesh));
  if (mesh) {
    const double p0[3] = {0.13, 0.05, -0.02}, n0[3] = {1, 0.3, 0.2};
    const double n1[3] = {1, 0.3 + 1e-5, 0.2 - 1e-5}, blo[3] = {-2, -2, -2}, bhi[3] = {2, 2, 2};
    fcm_surface *k0 = NULL, *k1 = NULL;
    fcm_cell_rules *r0 = NULL, *r1 = NULL, *r2 = NULL;
    o = fcm_cell_rules_options_default();
    o.min_fraction = 0.0;
    o.sliver_rtol = 1e-6;
    TEST_OK(ctx, fcm_surface_create_plane(ctx, p0, n0, blo, bhi, &k0));
    TEST_OK(ctx, fcm_surface_create_plane(ctx, p0, n1, blo, bhi, &k1));
    TEST_OK(ctx, fcm_cell_rules_create(ctx, mesh, surf, &o, &r0));
    if (r0 && k0) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, surf, r0, k0, &r1));
    if (r1 && k1) TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, mesh, surf, r1, k1, &r2));
    if (r2) {
      const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r2);
      printf("wedges: %lld -> %lld pieces, %lld of them on the volume path\n",
             (long long)fcm_cell_rules_num_pieces(r1), (long long)fcm_cell_rules_num_pieces(r2),
             (long long)S->num_surface_fallbacks);
      TEST_TRUE(fcm_cell_rules_num_pieces(r2) > fcm_cell_rules_num_pieces(r1));
      TEST_TRUE(S->num_surface_fallbacks > 0);
      const double K =
          (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) / (double)fcm_mesh_num_cells(mesh);
      int small = 0, whole = 0;
      for (fcm_index p = 0; p < fcm_cell_rules_num_pieces(r2); p++) {
        int np;
        const double *xi, *w;
        const unsigned char *f;
        double X[3 * FCM_ELEMENT_MAX_NODES], J[9], v = 0.0;
        const double pv = fcm_cell_rules_piece_volume(r2, p);
        TEST_OK(ctx, fcm_cell_rules_get_piece(r2, p, FCM_RULE_MASS, &np, &xi, &w, &f));
        fcm_mesh_cell_coords(mesh, fcm_cell_rules_piece_cell(r2, p), X);
        for (int j = 0; j < np; j++) {
          TEST_TRUE(w[j] > 0.0);
          if (!f[j]) v += w[j] * fcm_element_jacobian(FCM_ELEMENT_HEX8, X, xi + 3 * j, J);
        }
        if (!(v > 0.0 && v <= pv + 1e-12 * K))
          printf("piece %lld: rule volume %.17g, piece %.17g\n", (long long)p, v, pv);
        TEST_TRUE(v > 0.0 && v <= pv + 1e-12 * K);
        if (pv < 20.0 * o.sliver_rtol * K) small++, whole += fabs(v - pv) <= 1e-12 * K;
      }
      printf("wedges: %d pieces below 20 slivers, %d of them with their whole volume\n", small,
             whole);
      TEST_TRUE(small > 0 && whole == small);
    }
    fcm_cell_rules_destroy(&r2);
    fcm_cell_rules_destroy(&r1);
    fcm_cell_rules_destroy(&r0);
    fcm_surface_destroy(&k1);
    fcm_surface_destroy(&k0);
  }
  fcm_mesh_destroy(&mesh);

  /* the tips of a tet: the corner (2, 0, 0) in cell [1.75, 2.25] x [-0.25, 0.25]^2 */
  {
    const double tx[12] = {0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2};
    const fcm_index tc[4] = {0, 1, 2, 3};
    const double tlo[3] = {-0.25, -0.25, -0.25}, thi[3] = {2.25, 2.25, 2.25};
    const fcm_index tn[3] = {5, 5, 5};
    const fcm_element_type tt[2] = {FCM_ELEMENT_HEX8, FCM_ELEMENT_TET4};
    fcm_geometry *tet = NULL, *tsurf = NULL;
    tets_and_surface(4, tx, 1, tc, &mo, &tet, &tsurf);
    for (int t = 0; t < 2 && tsurf; t++) {
      TEST_OK(ctx, fcm_mesh_create_box(ctx, tt[t], tlo, thi, tn, &mesh));
      if (mesh) moments(mesh, tsurf, tet, 0, 0.0);
      fcm_mesh_destroy(&mesh);
    }
    fcm_geometry_destroy(&tsurf);
    fcm_geometry_destroy(&tet);
  }
  /* a thin tilted slab: 6 tets of a box 1.7 x thickness x 1.3, turned about z and x */
  for (int k = 0; k < 2; k++) {
    const double t = k ? 1e-4 : 1e-3, ra = 0.3, rb = 0.2;
    double x[24];
    for (int i = 0; i < 8; i++) {
      const double p0 = (i & 1 ? 0.85 : -0.85), p1 = (i & 2 ? 0.5 : -0.5) * t,
                   p2 = (i & 4 ? 0.65 : -0.65);
      const double q0 = cos(ra) * p0 - sin(ra) * p1, q1 = sin(ra) * p0 + cos(ra) * p1;
      x[3 * i] = q0 + 0.013;
      x[3 * i + 1] = cos(rb) * q1 - sin(rb) * p2 + 0.021;
      x[3 * i + 2] = sin(rb) * q1 + cos(rb) * p2 - 0.017;
    }
    const fcm_index tc[24] = {0, 1, 3, 7, 0, 3, 2, 7, 0, 2, 6, 7,
                              0, 6, 4, 7, 0, 4, 5, 7, 0, 5, 1, 7};
    fcm_geometry *slab = NULL, *ssurf = NULL;
    tets_and_surface(8, x, 6, tc, &mo, &slab, &ssurf);
    for (int t3 = 0; t3 < 3 && ssurf; t3++) {
      TEST_OK(ctx, fcm_mesh_create_box(ctx, types[t3], lo, hi, n, &mesh));
      const double box = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
      if (mesh) moments(mesh, ssurf, slab, 1, 1e-14 * box / (double)fcm_mesh_num_cells(mesh));
      fcm_mesh_destroy(&mesh);
    }
    fcm_geometry_destroy(&ssurf);
    fcm_geometry_destroy(&slab);
  }
  fcm_surface_destroy(&s);
  fcm_geometry_destroy(&surf);
  fcm_geometry_destroy(&tets);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
