/* Embedding diagnostics: how much of the body lies outside the background mesh, beyond which
 * faces of its bounding box, and the error for a body that misses the mesh entirely; a cut
 * surface with no triangle of positive area. */
#include "embed/embed_impl.h"

#include <math.h>
#include <string.h>

fcm_status fcm__embed_outside(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                              fcm_cell_rules_stats *S)
{
  fcm_status st = FCM_OK;
  fcm_mesh_bounding_box(mesh, S->mesh_lo, S->mesh_hi);
  fcm_geometry_bounding_box(geom, S->geometry_lo, S->geometry_hi);
  const double gv = S->geometry_volume;
  S->volume_ratio = gv > 0.0 ? S->embedded_volume / gv : 0.0;
  const double out = gv - S->embedded_volume - S->sliver_volume;
  S->outside_volume = out > 1e-12 * gv ? out : 0.0;
  memset(S->outside_side_volume, 0, sizeof S->outside_side_volume);
  const double *glo = S->geometry_lo, *ghi = S->geometry_hi, *mlo = S->mesh_lo, *mhi = S->mesh_hi;
  FCM_CHECK(!(gv > 0.0) || S->embedded_volume > 1e-12 * gv, ctx, FCM_ERR_GEOMETRY,
            "embed: the geometry (volume %g) lies wholly outside the background mesh%s: geometry "
            "bounding box [%g, %g] x [%g, %g] x [%g, %g], background mesh bounding box [%g, %g] x "
            "[%g, %g] x [%g, %g]; move the body or enlarge the background",
            gv,
            glo[0] <= mhi[0] && ghi[0] >= mlo[0] && glo[1] <= mhi[1] && ghi[1] >= mlo[1] &&
                    glo[2] <= mhi[2] && ghi[2] >= mlo[2]
                ? " (the boxes overlap, but no geometry cell meets a background cell)"
                : "",
            glo[0], ghi[0], glo[1], ghi[1], glo[2], ghi[2], mlo[0], mhi[0], mlo[1], mhi[1], mlo[2],
            mhi[2]);
  if (geom->has_outside) { /* a crop: the whole geometry's, for this mesh box */
    FCM_CHECK(memcmp(geom->outside_mesh_lo, mlo, 3 * sizeof *mlo) == 0 &&
                  memcmp(geom->outside_mesh_hi, mhi, 3 * sizeof *mhi) == 0,
              ctx, FCM_ERR_INTERNAL,
              "embed: a cropped geometry used with another background mesh than its crop's");
    memcpy(S->outside_side_volume, geom->outside_side, sizeof S->outside_side_volume);
    return FCM_OK;
  }
  FCM_TRY(ctx, fcm__embed_outside_sides(ctx, mlo, mhi, geom, S->outside_side_volume));
cleanup:
  return st;
}

/* The body's volume beyond each flagged side of the box from its boundary alone: beyond the
 * plane x_d = a, F = (x_d - a) e_d has divergence 1 and vanishes on the plane, so the volume
 * is the sum over the triangles' parts beyond it of int (x_d - a) n_d dA (the centroid rule is
 * exact for the linear integrand). */
static fcm_status surface_sides(fcm_ctx *ctx, const double mlo[3], const double mhi[3],
                                const fcm_geometry *g, int beyond, double side_volume[6])
{
  double poly[3 * 16], work[3 * 16];
  (void)ctx;
  for (int side = 0; side < 6; side++) {
    if (!(beyond >> side & 1)) continue;
    const int d = side / 2, up = side % 2;
    const double a = up ? mhi[d] : mlo[d];
    fcm__plane pl = {{0, 0, 0}, up ? -a : a}; /* keep the part beyond: n.x <= dd */
    pl.n[d] = up ? -1.0 : 1.0;
    double v = 0.0;
    for (fcm_index t = 0; t < g->num_tris; t++) {
      for (int k = 0; k < 3; k++)
        memcpy(poly + 3 * k, g->coords + 3 * g->tris[3 * t + k], 3 * sizeof *poly);
      const int n = fcm__geom_polygon_clip(poly, 3, 16, &pl, 0.0, 1, work);
      for (int i = 1; i + 1 < n; i++) {
        const double *p0 = poly, *p1 = poly + 3 * i, *p2 = poly + 3 * (i + 1);
        const int e = (d + 1) % 3, f = (d + 2) % 3; /* n_d dA = the projected area / 2 */
        const double nd = (p1[e] - p0[e]) * (p2[f] - p0[f]) - (p1[f] - p0[f]) * (p2[e] - p0[e]);
        v += ((p0[d] + p1[d] + p2[d]) / 3.0 - a) * nd / 2.0;
      }
    }
    side_volume[side] = v;
  }
  return FCM_OK;
}

fcm_status fcm__embed_outside_sides(fcm_ctx *ctx, const double mlo[3], const double mhi[3],
                                    const fcm_geometry *geom, double side_volume[6])
{
  fcm_status st = FCM_OK;
  fcm__poly *p = NULL, *scratch = NULL;
  const double *glo = geom->lo, *ghi = geom->hi;
  memset(side_volume, 0, 6 * sizeof *side_volume);
  int beyond = 0;
  for (int d = 0; d < 3; d++)
    beyond |= (glo[d] < mlo[d]) << (2 * d) | (ghi[d] > mhi[d]) << (2 * d + 1);
  if (!beyond) return FCM_OK;
  if (geom->num_cells == 0) return surface_sides(ctx, mlo, mhi, geom, beyond, side_volume);
  const int npc = fcm_geometry_nodes_per_cell(geom);
  const fcm_element_type type = fcm_geometry_cell_type(geom);
  const double *GX = fcm_geometry_coords(geom);
  const fcm_index *cells = fcm_geometry_cells(geom);
  FCM_ALLOC(ctx, 2, p);
  scratch = p + 1;
  for (fcm_index c = 0; c < fcm_geometry_num_cells(geom); c++) {
    double X[24], lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++) {
        X[3 * a + d] = GX[3 * cells[(size_t)npc * (size_t)c + (size_t)a] + d];
        lo[d] = fmin(lo[d], X[3 * a + d]), hi[d] = fmax(hi[d], X[3 * a + d]);
      }
    for (int side = 0; side < 6; side++) {
      const int d = side / 2, up = side % 2;
      if (!(beyond >> side & 1)) continue;
      const double bound = up ? mhi[d] : mlo[d];
      if (up ? hi[d] <= bound : lo[d] >= bound) continue; /* nothing beyond this side */
      fcm__geom_poly_from_cell(type, X, p);
      if (up ? lo[d] < bound : hi[d] > bound) { /* straddles: keep the part beyond */
        fcm__plane pl = {{0, 0, 0}, up ? -bound : bound};
        pl.n[d] = up ? -1.0 : 1.0;
        if (fcm__geom_poly_clip(p, &pl, 0.0, scratch) != 0) continue;
      }
      side_volume[side] += fcm__geom_poly_volume(p);
    }
  }
cleanup:
  fcm__free(ctx, p);
  return st;
}

fcm_status fcm__embed_cut_check(fcm_ctx *ctx, const fcm_surface *cut, const char *what)
{
  fcm_status st = FCM_OK;
  static const unsigned char none[3] = {0, 0, 0};
  const fcm_index nt = fcm_surface_num_triangles(cut);
  const double *x = fcm_surface_coords(cut);
  const fcm_index *tv = fcm_surface_triangles(cut);
  for (fcm_index t = 0; t < nt; t++) {
    fcm__cut_tri probe;
    if (fcm__embed_cut_tri_setup(x + 3 * tv[3 * t], x + 3 * tv[3 * t + 1], x + 3 * tv[3 * t + 2], 0,
                                 none, NULL, NULL, &probe))
      return FCM_OK;
  }
  const double *a = x + 3 * tv[0], *b = x + 3 * tv[1], *c = x + 3 * tv[2];
  FCM_CHECK(0, ctx, FCM_ERR_GEOMETRY,
            "%s: all %lld triangle(s) of the cut surface have zero area (the first: (%g, %g, %g), "
            "(%g, %g, %g), (%g, %g, %g)), so the cut would separate nothing; give a surface with "
            "triangles of positive area",
            what, (long long)nt, a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]);
cleanup:
  return st;
}
