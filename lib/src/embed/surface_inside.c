/* The inside test of points for the surface path: the winding number of the body's closed
 * boundary surface about a point of an affine cell, from the signed crossings of the boundary
 * triangles with a reference line of the cell through it (one line for a column of points; for
 * the columns of a hexahedral cell, the triangles that meet it kept once), the clear boxes that
 * answer points far from the boundary without a line, and the box that bounds the material in a
 * cell. The lines take the triangles as the surface moments' exit edge does (surface_moments.c
 * explains why a point on an edge or a vertex counts once), so the two decide alike. */
#include "embed/moments_impl.h"

#include <float.h>
#include <math.h>
#include <string.h>

void fcm__embed_line_segment(const fcm_geometry *g, const fcm__embed_cell *cell,
                             const double base[3], const double dir[3], double p0[3], double p1[3],
                             double *pad)
{
  double p[3], v[3], far = 0.0;
  const double x0[3] = {base[0] - cell->xi0[0], base[1] - cell->xi0[1], base[2] - cell->xi0[2]};
  fcm__mat3_mulv(cell->A, x0, p);
  fcm__mat3_mulv(cell->A, dir, v);
  for (int d = 0; d < 3; d++)
    p[d] += cell->X[d];
  const double speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int c = 0; c < 8; c++) { /* the farthest corner of the geometry's box */
    double r2 = 0.0;
    for (int d = 0; d < 3; d++) {
      const double e = ((c >> d) & 1 ? g->hi[d] : g->lo[d]) - p[d];
      r2 += e * e;
    }
    const double r = sqrt(r2);
    far = r > far ? r : far;
  }
  const double t = far / speed + 1.0;
  for (int d = 0; d < 3; d++)
    p0[d] = p[d] - t * v[d], p1[d] = p[d] + t * v[d];
  double na = 0.0, ni = 0.0; /* Frobenius norms: cond(A) <= na ni */
  for (int k = 0; k < 9; k++)
    na += cell->A[k] * cell->A[k], ni += cell->Ainv[k] * cell->Ainv[k];
  const double rel = 1e-9 + 64.0 * DBL_EPSILON * sqrt(na * ni);
  *pad = rel * (far + cell->size);
}

int fcm__embed_line_half(const fcm_geometry *g, const fcm__embed_cell *cell, const double base[3],
                         const double dir[3], double zlo, double zhi, double pad, double p0[3],
                         double p1[3])
{
  double p[3], v[3], up = HUGE_VAL, down = HUGE_VAL;
  const double x0[3] = {base[0] - cell->xi0[0], base[1] - cell->xi0[1], base[2] - cell->xi0[2]};
  fcm__mat3_mulv(cell->A, x0, p);
  fcm__mat3_mulv(cell->A, dir, v);
  for (int d = 0; d < 3; d++) {
    p[d] += cell->X[d];
    const double lo = g->lo[d] - pad, hi = g->hi[d] + pad;
    if (v[d] == 0.0) continue;
    const double u = ((v[d] > 0.0 ? hi : lo) - p[d]) / v[d],
                 w = (p[d] - (v[d] > 0.0 ? lo : hi)) / v[d];
    up = u < up ? u : up, down = w < down ? w : down;
  }
  /* t in the box: [-down, up] (empty when the line misses it) */
  const double top = fmax(up, zhi) + 1.0, bottom = fmin(-down, zlo) - 1.0;
  const int is_up = !(zhi + 1.0 - bottom < top - (zlo - 1.0));
  const double t0 = is_up ? zlo - 1.0 : bottom, t1 = is_up ? top : zhi + 1.0;
  for (int d = 0; d < 3; d++)
    p0[d] = p[d] + t0 * v[d], p1[d] = p[d] + t1 * v[d];
  return is_up;
}

fcm_status fcm__embed_line_crossings(fcm_ctx *ctx, const fcm_geometry *g,
                                     const fcm__embed_cell *cell, const fcm__idbuf *buf,
                                     const lin *l1, const lin *l2, fcm__crossings *out, int *sum)
{
  fcm_status st = FCM_OK;
  out->n = 0;
  *sum = 0;
  for (size_t k = 0; k < buf->n; k++) {
    rtri T;
    double P[3], Q[3], X[3];
    load_tri(g, cell, buf->ids[k], &T);
    if (!tri_segment(&T, l1, P, Q)) continue;
    const int sg = seg_cross(P, Q, l2, X);
    if (!sg) continue;
    if (out->n == out->cap) {
      const size_t cap = out->cap ? 2 * out->cap : 16;
      void *z = out->z, *s = out->sign;
      FCM_TRY(ctx, fcm__resize(ctx, &z, out->cap, cap, sizeof *out->z));
      out->z = z;
      FCM_TRY(ctx, fcm__resize(ctx, &s, out->cap, cap, sizeof *out->sign));
      out->sign = s;
      out->cap = cap;
    }
    out->z[out->n] = X[2];
    out->sign[out->n++] = sg;
    *sum += sg;
  }
cleanup:
  return st;
}

void fcm__crossings_free(fcm_ctx *ctx, fcm__crossings *c)
{
  fcm__free(ctx, c->z);
  fcm__free(ctx, c->sign);
  fcm__free(ctx, c->col_x);
  fcm__free(ctx, c->col_v);
  c->col_x = NULL, c->col_v = NULL;
  c->col_n = c->col_cap = 0;
  c->col_tree = NULL;
  c->z = NULL, c->sign = NULL;
  c->n = c->cap = 0;
  c->tree = NULL;
  c->nclear = c->next = 0;
  c->tries = c->found = c->skipped = 0;
}

fcm_status fcm__embed_clear_box_add(fcm_ctx *ctx, const fcm_aabb_tree *tree, const double x[3],
                                    double r, double pad, int w, fcm__idbuf *buf,
                                    fcm__crossings *cr)
{
  fcm_status st = FCM_OK;
  double lo[3], hi[3], h = r;
  if (cr->tries >= 64 && 4 * cr->found < cr->tries && (++cr->skipped & 15) != 0) return FCM_OK;
  if (cr->tries >= 1024) cr->tries /= 2, cr->found /= 2;
  cr->tries++;
  for (int d = 0; d < 3; d++)
    lo[d] = x[d] - r - pad, hi[d] = x[d] + r + pad;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, lo, hi, buf));
  for (size_t k = 0; k < buf->n; k++) { /* the box's distance from x (max norm), less pad */
    const double *b = tree->boxes + 6 * buf->ids[k];
    double dist = 0.0;
    for (int d = 0; d < 3; d++)
      dist = fmax(dist, fmax(b[d] - x[d], x[d] - b[3 + d]));
    h = fmin(h, dist - pad);
  }
  if (!(h > 0.0)) goto cleanup;
  cr->found++;
  if (cr->tree != tree) cr->tree = tree, cr->nclear = cr->next = 0;
  fcm__clear_box *c = cr->clear + cr->next;
  cr->next = (cr->next + 1) % FCM__CLEAR_BOXES;
  cr->nclear = FCM_MIN(cr->nclear + 1, FCM__CLEAR_BOXES);
  for (int d = 0; d < 3; d++)
    c->lo[d] = x[d] - h, c->hi[d] = x[d] + h;
  c->pad = pad;
  c->winding = w;
cleanup:
  return st;
}

fcm_status fcm__embed_inside_line(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                  const fcm__embed_cell *cell, double a, double b, int n,
                                  const double *z, int *inside, fcm__idbuf *buf, fcm__crossings *cr)
{
  fcm_status st = FCM_OK;
  const double base[3] = {a, b, 0.0}, dir[3] = {0.0, 0.0, 1.0};
  const lin l1 = mk(-a, 1, 0, 0), l2 = mk(-b, 0, 1, 0);
  const int orient = cell->detA > 0.0 ? 1 : -1; /* the map turns the surface inside out */
  double x[3], p0[3], p1[3], pad;
  int sum;
  /* a point with no boundary triangle within the line's rounding distance has the winding
   * number of any point it sees without crossing the boundary: that of a clear box holding it */
  fcm__embed_line_segment(g, cell, base, dir, p0, p1, &pad);
  if (n == 1) {
    to_physical(cell, a, b, z[0], x);
    const fcm__clear_box *c = clear_box_find(cr, tree, x, pad);
    if (c) {
      inside[0] = orient * c->winding;
      return FCM_OK;
    }
  }
  double zlo = z[0], zhi = z[0];
  for (int i = 1; i < n; i++)
    zlo = z[i] < zlo ? z[i] : zlo, zhi = z[i] > zhi ? z[i] : zhi;
  const int half = closed_tree(g, tree);
  const int up = half ? fcm__embed_line_half(g, cell, base, dir, zlo, zhi, pad, p0, p1) : 1;
  FCM_TRY(ctx, fcm__geom_tree_segment(ctx, tree, p0, p1, pad, buf));
  FCM_TRY(ctx, fcm__embed_line_crossings(ctx, g, cell, buf, &l1, &l2, cr, &sum));
  FCM_CHECK(half || sum == 0, ctx, FCM_ERR_GEOMETRY,
            "embed: background cell %lld: a line through the body crosses its boundary %d more "
            "times outward than inward (the boundary surface is not closed)",
            (long long)cell->id, sum);
  for (int i = 0; i < n; i++) /* crossings at or beyond z[i], leaving counted +1 */
    inside[i] = line_winding(cr, up, z[i]);
  if (n == 1)
    FCM_TRY(ctx, fcm__embed_clear_box_add(ctx, tree, x, CLEAR_BOX_RSIZE * cell->size, 2.0 * pad,
                                          orient * inside[0], buf, cr));
cleanup:
  return st;
}

static void grow_box(double box[6], const double x[3])
{
  for (int d = 0; d < 3; d++) {
    box[d] = fmin(box[d], x[d]);
    box[3 + d] = fmax(box[3 + d], x[d]);
  }
}

/* The physical bounding box of the reference face xi_3 = z of a hexahedral cell. */
static void face_box(const fcm__embed_cell *cell, double z, double lo[3], double hi[3])
{
  for (int d = 0; d < 3; d++)
    lo[d] = HUGE_VAL, hi[d] = -HUGE_VAL;
  for (int c = 0; c < 4; c++) {
    double x[3];
    to_physical(cell, c & 1 ? 1.0 : -1.0, c & 2 ? 1.0 : -1.0, z, x);
    for (int d = 0; d < 3; d++)
      lo[d] = fmin(lo[d], x[d]), hi[d] = fmax(hi[d], x[d]);
  }
}

/* Set cr's column cache up for cell (a hexahedron): which of its top and bottom faces no
 * boundary triangle's box comes within the lines' rounding distance of (a bound on every
 * column's, fcm__embed_inside_line()), the winding number there, and the triangles whose
 * boxes meet the cell widened by that distance (each crossing of a column inside the cell is
 * on one of them). */
static fcm_status column_cell(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                              const fcm__embed_cell *cell, fcm__idbuf *buf, fcm__crossings *cr)
{
  fcm_status st = FCM_OK;
  const double key[5] = {(double)cell->id, cell->X[0], cell->X[1], cell->X[2], cell->detA};
  if (cr->col_tree == tree && !memcmp(key, cr->col_key, sizeof key)) return FCM_OK;
  const double base[3] = {0.0, 0.0, 0.0}, dir[3] = {0.0, 0.0, 1.0};
  double p0[3], p1[3], pad, lo[3], hi[3];
  cr->col_tree = NULL;
  cr->col_face = 0;
  cr->col_n = 0;
  /* a column's base lies within the cell's size (its box's diagonal) of the centre's, so its
   * rounding distance (the distance to the geometry's far corner, plus the size) is at most
   * twice the centre's: four times, with room */
  fcm__embed_line_segment(g, cell, base, dir, p0, p1, &pad);
  pad *= 4.0;
  for (int side = 1; side >= -1 && !cr->col_face; side -= 2) {
    face_box(cell, side, lo, hi);
    for (int d = 0; d < 3; d++)
      lo[d] -= pad, hi[d] += pad;
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, lo, hi, buf));
    if (buf->n == 0) cr->col_face = side;
  }
  if (cr->col_face) {
    const double zf[2] = {cr->col_face, cr->col_face};
    int w[2];
    FCM_TRY(ctx, fcm__embed_inside_line(ctx, g, tree, cell, 0.0, 0.0, 2, zf, w, buf, cr));
    cr->col_winding = w[0];
    for (int d = 0; d < 3; d++)
      lo[d] = cell->lo[d] - pad, hi[d] = cell->hi[d] + pad;
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, lo, hi, buf));
    if (buf->n > cr->col_cap) {
      void *x = cr->col_x, *v = cr->col_v;
      FCM_TRY(ctx, fcm__resize(ctx, &x, 0, 9 * buf->n, sizeof(double)));
      cr->col_x = x;
      FCM_TRY(ctx, fcm__resize(ctx, &v, 0, 3 * buf->n, sizeof(fcm_index)));
      cr->col_v = v;
      cr->col_cap = buf->n;
    }
    for (size_t k = 0; k < buf->n; k++) {
      rtri T;
      load_tri(g, cell, buf->ids[k], &T);
      memcpy(cr->col_x + 9 * k, T.x, sizeof T.x);
      memcpy(cr->col_v + 3 * k, T.id, sizeof T.id);
    }
    cr->col_n = buf->n;
  }
  memcpy(cr->col_key, key, sizeof key);
  cr->col_tree = tree;
cleanup:
  return st;
}

fcm_status fcm__embed_inside_column(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                    const fcm__embed_cell *cell, double a, double b, int n,
                                    const double *z, int *inside, fcm__idbuf *buf,
                                    fcm__crossings *cr)
{
  fcm_status st = FCM_OK;
  if (cell->info->shape != FCM_SHAPE_HEX || !cell->affine || !closed_tree(g, tree))
    return fcm__embed_inside_line(ctx, g, tree, cell, a, b, n, z, inside, buf, cr);
  FCM_TRY(ctx, column_cell(ctx, g, tree, cell, buf, cr));
  if (!cr->col_face) return fcm__embed_inside_line(ctx, g, tree, cell, a, b, n, z, inside, buf, cr);
  const lin l1 = mk(-a, 1, 0, 0), l2 = mk(-b, 0, 1, 0);
  const int top = cr->col_face > 0;
  for (int i = 0; i < n; i++)
    inside[i] = cr->col_winding;
  /* the winding number at z: the face's, plus the crossings at or above z below the top
   * face, or less those at or above the bottom face below z */
  for (size_t k = 0; k < cr->col_n; k++) {
    rtri T;
    double P[3], Q[3], X[3];
    memcpy(T.x, cr->col_x + 9 * k, sizeof T.x);
    memcpy(T.id, cr->col_v + 3 * k, sizeof T.id);
    if (!tri_segment(&T, &l1, P, Q)) continue;
    const int sg = seg_cross(P, Q, &l2, X);
    if (!sg) continue;
    for (int i = 0; i < n; i++)
      if (top && X[2] >= z[i] && X[2] < 1.0)
        inside[i] += sg;
      else if (!top && X[2] >= -1.0 && X[2] < z[i])
        inside[i] -= sg;
  }
cleanup:
  return st;
}

fcm_status fcm__embed_material_box(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                   const fcm__embed_cell *cell, fcm__idbuf *buf, fcm__crossings *cr,
                                   fcm__srule *bnd, double box[6], int *touched)
{
  fcm_status st = FCM_OK;
  ref_cell r;
  ref_cell_init(cell->info->shape == FCM_SHAPE_TET, &r);
  *touched = 0;
  if (bnd) bnd->n = 0;
  for (int d = 0; d < 3; d++)
    box[d] = HUGE_VAL, box[3 + d] = -HUGE_VAL;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, cell->lo, cell->hi, buf));
  for (size_t k = 0; k < buf->n; k++) {
    rtri T;
    double a[3 * POLY_CAP];
    load_tri(g, cell, buf->ids[k], &T);
    const int n = fcm__embed_clip_tri_to_cell(&r, &T, a);
    if (n < 3) continue;
    *touched = 1;
    double c[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < n; i++) {
      grow_box(box, a + 3 * i);
      for (int d = 0; d < 3; d++)
        c[d] += a[3 * i + d] / n;
    }
    if (!bnd) continue;
    FCM_TRY(ctx, fcm__srule_room(ctx, bnd, (size_t)n + 1));
    memcpy(bnd->x + 3 * bnd->n, a, 3 * (size_t)n * sizeof *a);
    memcpy(bnd->x + 3 * (bnd->n + (size_t)n), c, sizeof c);
    for (int i = 0; i <= n; i++)
      bnd->w[bnd->n + (size_t)i] = 0.0;
    bnd->n += (size_t)n + 1;
  }
  if (!*touched) goto cleanup;
  /* the corners inside the body: the material's other vertices are on the triangles' parts */
  const int tet = cell->info->shape == FCM_SHAPE_TET;
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++) {
      if (tet && i + j > 1) continue;
      const double a = i ? 1.0 : r.lo, b = j ? 1.0 : r.lo, z[2] = {r.lo, 1.0};
      const int nz = tet && i + j == 1 ? 1 : 2;
      int in[2];
      FCM_TRY(ctx, fcm__embed_inside_column(ctx, g, tree, cell, a, b, nz, z, in, buf, cr));
      for (int k = 0; k < nz; k++) {
        const double x[3] = {a, b, z[k]};
        if (in[k] == 1) grow_box(box, x);
      }
    }
cleanup:
  return st;
}
