/* A cheap classification of the background cells against the embedded geometry's boundary,
 * without clipping or rules: what a scene's preview and its region checks need before the set-up.
 *
 * A cell is cut when a boundary triangle meets its nodes' bounding box (separating-axis test of
 * Akenine-Möller, "Fast 3D triangle-box overlap testing", 2001) inside, so it errs towards
 * cut; when triangles only lie on its faces the body lies on one side of them. The other cells
 * fall into connected sets of face neighbours that no triangle reaches, each wholly
 * inside or outside the body; one point of each set decides it by the winding number of the
 * closed boundary (the sum of the triangles' solid angles, Van Oosterom and Strackee 1983),
 * which is well conditioned there: the point is at least half a cell from every triangle. */
#include "embed/embed_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

/* 1 when the projections of the triangle v[3] (not changed) and of the box of half sizes h (centred
 * at the origin) on `axis` overlap. */
static int overlap_on(double v[3][3], const double h[3], const double axis[3])
{
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int k = 0; k < 3; k++) {
    const double p = fcm__vec3_dot(axis, v[k]);
    lo = fmin(lo, p), hi = fmax(hi, p);
  }
  const double r = h[0] * fabs(axis[0]) + h[1] * fabs(axis[1]) + h[2] * fabs(axis[2]);
  return !(lo > r || hi < -r);
}

/* 1 when the triangle (a, b, c) meets the closed box [lo, hi]. */
static int tri_meets_box(const double *a, const double *b, const double *c, const double lo[3],
                         const double hi[3])
{
  double ctr[3], h[3], v[3][3], e[3][3], n[3];
  for (int d = 0; d < 3; d++)
    ctr[d] = 0.5 * (lo[d] + hi[d]), h[d] = 0.5 * (hi[d] - lo[d]);
  fcm__vec3_sub(a, ctr, v[0]);
  fcm__vec3_sub(b, ctr, v[1]);
  fcm__vec3_sub(c, ctr, v[2]);
  for (int d = 0; d < 3; d++) { /* the box's axes */
    const double mn = fmin(v[0][d], fmin(v[1][d], v[2][d]));
    const double mx = fmax(v[0][d], fmax(v[1][d], v[2][d]));
    if (mn > h[d] || mx < -h[d]) return 0;
  }
  for (int k = 0; k < 3; k++)
    fcm__vec3_sub(v[(k + 1) % 3], v[k], e[k]);
  for (int k = 0; k < 3; k++) /* the edges crossed with the box's axes */
    for (int d = 0; d < 3; d++) {
      double unit[3] = {0.0, 0.0, 0.0}, axis[3];
      unit[d] = 1.0;
      fcm__vec3_cross(unit, e[k], axis);
      if (!overlap_on(v, h, axis)) return 0;
    }
  fcm__vec3_cross(e[0], e[1], n); /* the triangle's plane */
  return overlap_on(v, h, n);
}

/* The winding number of g's boundary triangles around p. */
static double winding_number(const fcm_geometry *g, const double p[3])
{
  double sum = 0.0;
  for (fcm_index t = 0; t < g->num_tris; t++) {
    double a[3], b[3], c[3], bc[3];
    fcm__vec3_sub(g->coords + 3 * g->tris[3 * t], p, a);
    fcm__vec3_sub(g->coords + 3 * g->tris[3 * t + 1], p, b);
    fcm__vec3_sub(g->coords + 3 * g->tris[3 * t + 2], p, c);
    const double la = fcm__vec3_norm(a), lb = fcm__vec3_norm(b), lc = fcm__vec3_norm(c);
    fcm__vec3_cross(b, c, bc);
    const double num = fcm__vec3_dot(a, bc);
    const double den = la * lb * lc + fcm__vec3_dot(a, b) * lc + fcm__vec3_dot(a, c) * lb +
                       fcm__vec3_dot(b, c) * la;
    sum += 2.0 * atan2(num, den);
  }
  return sum / (4.0 * PI);
}

/* Where the triangle (a, b, c) lies against the box [lo, hi] (tol: how far a point may be off
 * a face and still be on it): 2 when it meets the inside of the box; +1 and -1 when it lies in
 * the plane of a face and meets the inside of that face, +1 when the body is on the box's side
 * (its outward normal points away from the box), -1 when not; 0 when it meets neither (it
 * touches the box along an edge or in a point, or misses it). */
static int tri_box_side(const double *a, const double *b, const double *c, const double lo[3],
                        const double hi[3], double tol)
{
  double ilo[3], ihi[3];
  for (int d = 0; d < 3; d++)
    ilo[d] = lo[d] + tol, ihi[d] = hi[d] - tol;
  if (tri_meets_box(a, b, c, ilo, ihi)) return 2;
  for (int d = 0; d < 3; d++)
    for (int up = 0; up < 2; up++) {
      const double f = up ? hi[d] : lo[d];
      if (fabs(a[d] - f) > tol || fabs(b[d] - f) > tol || fabs(c[d] - f) > tol) continue;
      double flo[3], fhi[3], e1[3], e2[3], n[3];
      memcpy(flo, ilo, sizeof flo);
      memcpy(fhi, ihi, sizeof fhi);
      flo[d] = f - tol, fhi[d] = f + tol;
      if (!tri_meets_box(a, b, c, flo, fhi)) return 0;
      fcm__vec3_sub(b, a, e1);
      fcm__vec3_sub(c, a, e2);
      fcm__vec3_cross(e1, e2, n);
      return (up ? n[d] : -n[d]) > 0.0 ? 1 : -1;
    }
  return 0;
}

/* The cells a boundary triangle reaches: FCM_CELL_CUT in cls when one meets the inside of the
 * cell's box; FCM_CELL_UNCUT or FCM_CELL_DROPPED when the triangles that reach it all lie on its
 * faces with the body on one side (a body whose faces are grid planes: no material on the
 * other side), CUT when they disagree; `open` for the others, which no triangle reaches or
 * only along an edge or in a point. */
static fcm_status mark_touched(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *g,
                               unsigned char *cls, unsigned char open)
{
  fcm_status st = FCM_OK;
  const fcm_aabb_tree *tree = NULL;
  fcm__idbuf buf = {NULL, 0, 0};
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh);
  const fcm_index *cells = fcm_mesh_cells(mesh);
  const double *X = fcm_mesh_coords(mesh);
  if (g->num_tris > 0) FCM_TRY(ctx, fcm__geom_tree(ctx, g, 1, &tree));
  for (fcm_index c = 0; c < nc; c++) {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++) {
        const double x = X[3 * cells[(size_t)npc * c + a] + d];
        lo[d] = fmin(lo[d], x), hi[d] = fmax(hi[d], x);
      }
    /* the candidates: a little beyond the box, so a triangle on a face is one */
    const double tol =
        1e-9 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                    (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double wlo[3], whi[3];
    for (int d = 0; d < 3; d++)
      wlo[d] = lo[d] - tol, whi[d] = hi[d] + tol;
    cls[c] = open;
    if (!tree) continue;
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, wlo, whi, &buf));
    int in = 0, out = 0, cut = 0;
    for (size_t k = 0; k < buf.n && !cut; k++) {
      const fcm_index *t = g->tris + 3 * buf.ids[k];
      const int side = tri_box_side(g->coords + 3 * t[0], g->coords + 3 * t[1],
                                    g->coords + 3 * t[2], lo, hi, tol);
      in += side == 1, out += side == -1, cut = side == 2;
    }
    if (cut || (in && out))
      cls[c] = FCM_CELL_CUT;
    else if (in || out)
      cls[c] = in ? FCM_CELL_UNCUT : FCM_CELL_DROPPED;
  }
cleanup:
  fcm__geom_idbuf_free(ctx, &buf);
  return st;
}

fcm_status fcm__embed_classify_coarse(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom,
                                      unsigned char *cls, fcm_index counts[3])
{
  fcm_status st = FCM_OK;
  fcm_index *stack = NULL;
  const unsigned char open = 255, queued = 254;
  const fcm_index nc = fcm_mesh_num_cells(mesh);
  const int npc = fcm_mesh_nodes_per_cell(mesh);
  const int nf = fcm_mesh_get_element_info(mesh)->num_faces;
  const fcm_index *cells = fcm_mesh_cells(mesh), *nbr = fcm_mesh_neighbors(mesh);
  const double *X = fcm_mesh_coords(mesh);
  FCM_CHECK(ctx && mesh && geom && cls, ctx, FCM_ERR_ARG, "embed: classify_coarse: NULL argument");
  FCM_TRY(ctx, mark_touched(ctx, mesh, geom, cls, open));
  FCM_ALLOC_RAW(ctx, (size_t)nc + 1, stack);
  for (fcm_index c0 = 0; c0 < nc; c0++) {
    if (cls[c0] != open) continue;
    /* one point of the set decides it: the first cell's node centroid */
    double p[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++)
        p[d] += X[3 * cells[(size_t)npc * c0 + a] + d] / npc;
    int in_box = 1;
    for (int d = 0; d < 3; d++)
      in_box &= p[d] >= geom->lo[d] && p[d] <= geom->hi[d];
    const unsigned char side =
        in_box && fabs(winding_number(geom, p)) > 0.5 ? FCM_CELL_UNCUT : FCM_CELL_DROPPED;
    fcm_index n = 0;
    stack[n++] = c0;
    cls[c0] = queued;
    while (n > 0) {
      const fcm_index c = stack[--n];
      cls[c] = side;
      for (int f = 0; f < nf; f++) {
        const fcm_index o = nbr[(size_t)nf * c + f];
        if (o >= 0 && cls[o] == open) cls[o] = queued, stack[n++] = o;
      }
    }
  }
  if (counts) {
    counts[0] = counts[1] = counts[2] = 0;
    for (fcm_index c = 0; c < nc; c++)
      counts[cls[c]]++;
  }
cleanup:
  fcm__free(ctx, stack);
  return st;
}
