/* Exact integrals over the material of an affine background cell from the embedded body's
 * closed boundary surface, at a cost that follows the boundary triangles meeting the cell
 * (not the body's volume mesh).
 *
 * In reference coordinates the cell K is the cube [-1, 1]^3 or the unit tetrahedron; both
 * are bounded below by xi_k >= lo and have one exit facet in direction xi_1 (xi_1 = 1, or
 * xi_1 = 1 - xi_2 - xi_3). With F(xi) = int_lo^xi_1 f(t, xi_2, xi_3) dt, div(F e_1) = f and
 * the divergence theorem gives
 *   int_{V cap K} f = sum over boundary triangles T of int_{T cap K} F n_1 dA
 *                   + int over the exit facet's part inside V of F n_1 dA,
 * because F vanishes on xi_1 = lo and n_1 on the other facets. The exit facet term is the
 * same problem one dimension lower (projected on (xi_2, xi_3): the body's cross-section,
 * bounded by the segments where the triangles cross the facet's plane, with exit edge
 * xi_2 = 1 or 1 - xi_3), and that one's exit-edge term is one dimension lower again: the
 * intervals of the edge inside V, from the points where the segments cross it and the
 * inside status of the cell corner at its end. Every antiderivative is evaluated by Gauss
 * rules, so the result is a signed rule (points with weights of both signs, in reference
 * coordinates) exact for polynomials of degree <= m on V cap K, whose size follows the
 * triangles that meet the cell.
 *
 * Robustness: each plane classifies the triangle vertices once ("above" when the plane's
 * value is >= 0) and the point on a mesh edge is interpolated from its lower-numbered vertex,
 * so the two triangles sharing an edge produce the same point bit for bit and a line through
 * an edge or a vertex counts one crossing. Where two levels' rounding disagrees (a vertex
 * within rounding of a cell plane) the integrals differ by a region of rounding size: the
 * result is continuous in the vertex positions, so no decision can make it grossly wrong. The
 * surface must be closed and consistently oriented: a point's winding number is then the sum
 * of the signed crossings on either half of a line through it. On the geometry's own tree of a
 * geometry that is not a subset (closed where it was made) a line's shorter half is taken;
 * on another tree the whole line, and crossings that do not sum to zero say the surface is not
 * closed. */
#include "embed/moments_impl.h"

#include <math.h>
#include <string.h>

/* An empty rule on the reference cell of `cell`, its corner point moved to base (where given:
 * clamped to the cell's lower bounds); the cell's map must be affine. */
static fcm_status rule_start(fcm_ctx *ctx, const fcm__embed_cell *cell, const double *base,
                             ref_cell *r, fcm__srule *s)
{
  fcm_status st = FCM_OK;
  ref_cell_init(cell->info->shape == FCM_SHAPE_TET, r);
  if (base)
    for (int d = 0; d < 3; d++)
      r->c[d] = fmax(r->lo, base[d]);
  s->n = 0;
  FCM_CHECK(cell->affine, ctx, FCM_ERR_INTERNAL,
            "embed: background cell %lld is not affine (surface moments need an affine map)",
            (long long)cell->id);
cleanup:
  return st;
}

/* The exit facet's xi_1 at (xi_2, xi_3) and the exit edge's xi_2 at xi_3. */
static double exit1_at(const ref_cell *r, double x2, double x3)
{
  return r->tet ? 1.0 - x2 - x3 : 1.0;
}

static double exit2_at(const ref_cell *r, double x3)
{
  return r->tet ? 1.0 - x3 : 1.0;
}

/* ---------------------------------------------------------------- the quadratures */

/* W * F(y): F(y) = int_lo^y_1 f(t, y_2, y_3) dt (degree m in t). */
static fcm_status add_column(fcm_ctx *ctx, const fcm__moment_quad *q, double lo, const double y[3],
                             double W, fcm__srule *s)
{
  fcm_status st = FCM_OK;
  const int n = q->ng[0];
  const double len = y[0] - lo;
  if (len == 0.0 || W == 0.0) return FCM_OK;
  FCM_TRY(ctx, fcm__srule_room(ctx, s, (size_t)n));
  for (int g = 0; g < n; g++) {
    double *x = s->x + 3 * s->n;
    x[0] = lo + len * q->gt[0][g], x[1] = y[1], x[2] = y[2];
    s->w[s->n++] = W * len * q->ga[0][g];
  }
cleanup:
  return st;
}

/* W * G(y2, y3): G = int_c2^y2 F(e1(s, y3), s, y3) ds (degree m + 1 in s). */
static fcm_status add_face(fcm_ctx *ctx, const fcm__moment_quad *q, const ref_cell *r, double y2,
                           double y3, double W, fcm__srule *s)
{
  fcm_status st = FCM_OK;
  const double len = y2 - r->c[1];
  for (int j = 0; j < q->ng[1] && len != 0.0; j++) {
    const double z2 = r->c[1] + len * q->gt[1][j];
    const double y[3] = {exit1_at(r, z2, y3), z2, y3};
    FCM_TRY(ctx, add_column(ctx, q, r->c[0], y, W * len * q->ga[1][j], s));
  }
cleanup:
  return st;
}

/* W * H(z): H = int_c3^z G(e2(t), t) dt (degree m + 2 in t). */
static fcm_status add_edge(fcm_ctx *ctx, const fcm__moment_quad *q, const ref_cell *r, double z,
                           double W, fcm__srule *s)
{
  fcm_status st = FCM_OK;
  const double len = z - r->c[2];
  for (int k = 0; k < q->ng[2] && len != 0.0; k++) {
    const double t = r->c[2] + len * q->gt[2][k];
    FCM_TRY(ctx, add_face(ctx, q, r, exit2_at(r, t), t, W * len * q->ga[2][k], s));
  }
cleanup:
  return st;
}

/* ---------------------------------------------------------------- geometry of the levels */

/* Keep the part of the segment where every constraint is < 0; 0 when none is left. */
static int clip_segment(double P[3], double Q[3], const lin *c, int nc)
{
  for (int k = 0; k < nc; k++) {
    const double vp = lin_eval(c + k, P), vq = lin_eval(c + k, Q);
    const int op = vp >= 0.0, oq = vq >= 0.0;
    if (op && oq) return 0;
    if (op == oq) continue;
    const double t = vp / (vp - vq);
    double X[3];
    for (int d = 0; d < 3; d++)
      X[d] = P[d] + t * (Q[d] - P[d]);
    memcpy(op ? P : Q, X, sizeof X);
  }
  return 1;
}

/* Clip the polygon (n vertices) by {l < 0} into out; returns the new count. */
static int clip_polygon(const double *in, int n, const lin *l, double *out)
{
  int m = 0;
  for (int i = 0; i < n && m + 2 <= POLY_CAP; i++) {
    const double *p = in + 3 * i, *q = in + 3 * ((i + 1) % n);
    const double vp = lin_eval(l, p), vq = lin_eval(l, q);
    if (vp < 0.0) memcpy(out + 3 * m++, p, 3 * sizeof *p);
    if ((vp < 0.0) != (vq < 0.0)) {
      const double t = vp / (vp - vq);
      for (int d = 0; d < 3; d++)
        out[3 * m + d] = p[d] + t * (q[d] - p[d]);
      m++;
    }
  }
  return m;
}

int fcm__embed_clip_tri_to_cell(const ref_cell *r, const rtri *T, double *a)
{
  /* T wholly beyond one constraint by more than the rounding of the points that clipping by
   * the others makes (1e-12 of the coordinates, far above it): nothing left, as the clipping
   * below would find, without it */
  double big = 1.0;
  for (int i = 0; i < 9; i++)
    big = fmax(big, fabs(T->x[i]));
  const double margin = 1e-12 * big;
  unsigned inside = 0; /* bit k: every vertex strictly inside constraint k */
  for (int k = 0; k < r->ncell; k++) {
    const double v0 = lin_eval(r->cell + k, T->x), v1 = lin_eval(r->cell + k, T->x + 3),
                 v2 = lin_eval(r->cell + k, T->x + 6);
    if (v0 > margin && v1 > margin && v2 > margin) return 0;
    inside |= (unsigned)(v0 < -margin && v1 < -margin && v2 < -margin) << k;
  }
  /* clipping by a constraint every vertex of T lies inside by more than margin keeps the
   * polygon vertex for vertex: its vertices are T's and points on T's edges, whose values
   * (between two of T's, below -margin) the rounding of the points and of the constraint's
   * value (about 1e-16 of the coordinates) cannot bring to 0 */
  double b[3 * POLY_CAP];
  memcpy(a, T->x, sizeof T->x);
  int n = 3;
  for (int k = 0; k < r->ncell && n >= 3; k++) {
    if (inside >> k & 1u) continue;
    n = clip_polygon(a, n, r->cell + k, b);
    memcpy(a, b, 3 * (size_t)n * sizeof *a);
  }
  return n;
}

/* Level 3: int over T cap K of W F n_1 dA, by a fan of the clipped polygon. */
static fcm_status add_triangle(fcm_ctx *ctx, const fcm__moment_quad *q, const ref_cell *r,
                               const rtri *T, fcm__srule *s)
{
  fcm_status st = FCM_OK;
  double a[3 * POLY_CAP];
  const int n = fcm__embed_clip_tri_to_cell(r, T, a);
  for (int i = 1; i + 1 < n; i++) {
    const double *p0 = a, *p1 = a + 3 * i, *p2 = a + 3 * (i + 1);
    double e1[3], e2[3];
    for (int d = 0; d < 3; d++)
      e1[d] = p1[d] - p0[d], e2[d] = p2[d] - p0[d];
    const double n1 = e1[1] * e2[2] - e1[2] * e2[1]; /* 2 x projected area, signed */
    if (n1 == 0.0) continue;
    for (int j = 0; j < q->nt; j++) {
      const double u = q->tx[2 * j], v = q->tx[2 * j + 1];
      const double y[3] = {p0[0] + u * e1[0] + v * e2[0], p0[1] + u * e1[1] + v * e2[1],
                           p0[2] + u * e1[2] + v * e2[2]};
      FCM_TRY(ctx, add_column(ctx, q, r->c[0], y, q->tw[j] * n1, s));
    }
  }
cleanup:
  return st;
}

/* Level 2: the part of T's segment on the exit facet inside the facet: int G dxi_3 along it. */
static fcm_status add_segment(fcm_ctx *ctx, const fcm__moment_quad *q, const ref_cell *r,
                              const rtri *T, fcm__srule *s)
{
  fcm_status st = FCM_OK;
  double P[3], Q[3];
  if (!tri_segment(T, &r->exit1, P, Q)) return FCM_OK;
  /* the exit edge first, on the unclipped ends: the same decision and point as the exit
   * edge's crossings (level 1) */
  if (!clip_segment(P, Q, &r->exit2, 1) || !clip_segment(P, Q, r->face, r->nface)) return FCM_OK;
  const double d3 = Q[2] - P[2];
  if (d3 == 0.0) return FCM_OK;
  for (int k = 0; k < q->ng[2]; k++) {
    const double t = q->gt[2][k];
    FCM_TRY(ctx, add_face(ctx, q, r, P[1] + t * (Q[1] - P[1]), P[2] + t * (Q[2] - P[2]),
                          q->ga[2][k] * d3, s));
  }
cleanup:
  return st;
}

/* The cell's exit edge as a reference line: from the exit facet's corner (xi_3 = lo) to the
 * cell corner. */
static void exit_line(int tet, double base[3], double dir[3])
{
  base[0] = tet ? 0.0 : 1.0, base[1] = 1.0, base[2] = 0.0;
  dir[0] = 0.0, dir[1] = tet ? -1.0 : 0.0, dir[2] = 1.0;
}

/* fcm__embed_moment_rule(), with the sum of the signs of the exit edge line's crossings at
 * and beyond the cell corner (*corner) and the number of its crossings inside the edge
 * (*inner). boxes: buf holds on entry the triangles fcm__embed_cell_clear() found near the
 * cell (those that meet it are taken from them), and the corner's winding number comes from a
 * clear box kept in cr where one holds it (no boundary triangle within the line's rounding
 * distance of the corner: the crossings beyond it add up to that), else a box around it is
 * kept when it is clear. */
static fcm_status moment_rule(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                              const fcm__embed_cell *cell, const fcm__moment_quad *q,
                              const double base[3], int boxes, fcm__idbuf *buf, fcm__crossings *cr,
                              fcm__srule *s, int *corner, int *inner)
{
  fcm_status st = FCM_OK;
  ref_cell r;
  const int tet = cell->info->shape == FCM_SHAPE_TET;
  const int orient = cell->detA > 0.0 ? 1 : -1; /* the map turns the surface inside out */
  *corner = *inner = 0;
  FCM_TRY(ctx, rule_start(ctx, cell, base, &r, s));
  /* levels 3 and 2: the triangles that meet the cell (as the tree's box query finds them) */
  if (boxes) {
    size_t n = 0;
    for (size_t k = 0; k < buf->n; k++) {
      const double *b = tree->boxes + 6 * buf->ids[k];
      if (b[0] <= cell->hi[0] && cell->lo[0] <= b[3] && b[1] <= cell->hi[1] &&
          cell->lo[1] <= b[4] && b[2] <= cell->hi[2] && cell->lo[2] <= b[5])
        buf->ids[n++] = buf->ids[k];
    }
    buf->n = n;
  } else {
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, cell->lo, cell->hi, buf));
  }
  for (size_t k = 0; k < buf->n; k++) {
    rtri T;
    load_tri(g, cell, buf->ids[k], &T);
    FCM_TRY(ctx, add_triangle(ctx, q, &r, &T, s));
    FCM_TRY(ctx, add_segment(ctx, q, &r, &T, s));
  }
  /* level 1: the exit edge, from the exit facet's corner (xi_3 = lo) to the cell corner */
  double lbase[3], dir[3], p0[3], p1[3], pad, P[3];
  const fcm__clear_box *cb = NULL;
  int sum;
  exit_line(tet, lbase, dir);
  fcm__embed_line_segment(g, cell, lbase, dir, p0, p1, &pad);
  if (boxes) {
    to_physical(cell, lbase[0] + dir[0], lbase[1] + dir[1], lbase[2] + dir[2], P);
    cb = clear_box_find(cr, tree, P, pad);
  }
  int up = 1;
  const int half = closed_tree(g, tree);
  if (cb) /* the crossings inside the edge only */
    to_physical(cell, lbase[0] + r.lo * dir[0], lbase[1] + r.lo * dir[1], lbase[2] + r.lo * dir[2],
                p0);
  else if (half) /* the edge and the shorter half of the line beyond it */
    up = fcm__embed_line_half(g, cell, lbase, dir, r.lo, 1.0, pad, p0, p1);
  FCM_TRY(ctx, fcm__geom_tree_segment(ctx, tree, p0, cb ? P : p1, pad, buf));
  FCM_TRY(ctx, fcm__embed_line_crossings(ctx, g, cell, buf, &r.exit1, &r.exit2, cr, &sum));
  FCM_CHECK(cb || half || sum == 0, ctx, FCM_ERR_GEOMETRY,
            "embed: background cell %lld: its edge line crosses the body's boundary %d more "
            "times outward than inward (the boundary surface is not closed)",
            (long long)cell->id, sum);
  for (size_t k = 0; k < cr->n; k++) {
    const double z = cr->z[k];
    if (z > r.lo && z < 1.0) {
      FCM_TRY(ctx, add_edge(ctx, q, &r, z, cr->sign[k], s));
      ++*inner;
    }
  }
  *corner = cb ? orient * cb->winding : line_winding(cr, up, 1.0);
  if (*corner) FCM_TRY(ctx, add_edge(ctx, q, &r, 1.0, *corner, s));
  if (boxes && !cb)
    FCM_TRY(ctx, fcm__embed_clear_box_add(ctx, tree, P, CLEAR_BOX_RSIZE * cell->size, 2.0 * pad,
                                          orient * *corner, buf, cr));
cleanup:
  return st;
}

fcm_status fcm__embed_moment_rule(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                  const fcm__embed_cell *cell, const fcm__moment_quad *q,
                                  const double base[3], fcm__idbuf *buf, fcm__crossings *cr,
                                  fcm__srule *s)
{
  int corner, inner;
  return moment_rule(ctx, g, tree, cell, q, base, 0, buf, cr, s, &corner, &inner);
}

fcm_status fcm__embed_moment_rule_kept(fcm_ctx *ctx, const fcm_geometry *g,
                                       const fcm_aabb_tree *tree, const fcm__embed_cell *cell,
                                       const fcm__moment_quad *q, const double base[3],
                                       fcm__idbuf *buf, fcm__crossings *cr, fcm__srule *s)
{
  int corner, inner;
  return moment_rule(ctx, g, tree, cell, q, base, 1, buf, cr, s, &corner, &inner);
}

fcm_status fcm__embed_cell_clear(fcm_ctx *ctx, const fcm_geometry *g, const fcm_aabb_tree *tree,
                                 const fcm__embed_cell *cell, fcm__idbuf *buf, int *clear)
{
  fcm_status st = FCM_OK;
  double lbase[3], dir[3], p0[3], p1[3], pad, lo[3], hi[3];
  exit_line(cell->info->shape == FCM_SHAPE_TET, lbase, dir);
  fcm__embed_line_segment(g, cell, lbase, dir, p0, p1, &pad);
  for (int d = 0; d < 3; d++)
    lo[d] = cell->lo[d] - pad, hi[d] = cell->hi[d] + pad;
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, lo, hi, buf));
  *clear = buf->n == 0;
cleanup:
  return st;
}

fcm_status fcm__embed_moment_rule_clear(fcm_ctx *ctx, const fcm_geometry *g,
                                        const fcm_aabb_tree *tree, const fcm__embed_cell *cell,
                                        const fcm__moment_quad *q, const double base[3],
                                        fcm__idbuf *buf, fcm__crossings *cr, int *winding,
                                        fcm__srule *s)
{
  fcm_status st = FCM_OK;
  const int orient = cell->detA > 0.0 ? 1 : -1; /* the map turns the surface inside out */
  if (*winding == FCM__WINDING_UNKNOWN) {
    int corner, inner;
    FCM_TRY(ctx, moment_rule(ctx, g, tree, cell, q, base, 0, buf, cr, s, &corner, &inner));
    if (inner == 0) *winding = orient * corner; /* else not clear after all: as it is */
    goto cleanup;
  }
  ref_cell r;
  FCM_TRY(ctx, rule_start(ctx, cell, base, &r, s));
  if (*winding) FCM_TRY(ctx, add_edge(ctx, q, &r, 1.0, orient * *winding, s));
cleanup:
  return st;
}
