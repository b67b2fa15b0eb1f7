/* Exact integrals over the material of an affine background cell from the embedded body's
 * closed boundary surface, at a cost that follows the boundary triangles meeting the cell
 * (not the body's volume mesh), and the inside test of points that goes with them.
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
#include "embed/embed_impl.h"
#include "la/mat3.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* An affine function s(xi) = c0 + c . xi of reference coordinates; "above" when s >= 0. */
typedef struct lin {
  double c0, c[3];
} lin;

static double lin_eval(const lin *l, const double x[3])
{
  return l->c0 + l->c[0] * x[0] + l->c[1] * x[1] + l->c[2] * x[2];
}

/* The reference cell's planes: inside where every constraint is < 0. */
typedef struct ref_cell {
  int tet;
  double lo;   /* lower bound of every coordinate: -1 (cube) or 0 (tet) */
  double c[3]; /* where the antiderivatives start, per direction: lo, or above it when the
                  material lies above (shorter columns, no cancellation for small material) */
  lin exit1;   /* the exit facet's plane: xi_1 - 1 or xi_1 + xi_2 + xi_3 - 1 */
  lin exit2;   /* the exit edge on that facet (in xi_2, xi_3): xi_2 - 1 or xi_2 + xi_3 - 1 */
  lin cell[6]; /* the cell's constraints */
  int ncell;
  lin face[3]; /* the exit facet's other edges (in xi_2, xi_3) */
  int nface;
} ref_cell;

static lin mk(double c0, double a, double b, double c)
{
  lin l = {c0, {a, b, c}};
  return l;
}

/* The cell's constraints start with the exit facet: a triangle lying in its plane is then
 * kept or dropped on its own vertices' values, as the exit facet's segments see them. */
static void ref_cell_init(int tet, ref_cell *r)
{
  r->tet = tet;
  r->lo = tet ? 0.0 : -1.0;
  r->c[0] = r->c[1] = r->c[2] = r->lo;
  r->exit1 = tet ? mk(-1, 1, 1, 1) : mk(-1, 1, 0, 0);
  r->exit2 = tet ? mk(-1, 0, 1, 1) : mk(-1, 0, 1, 0);
  r->ncell = 0;
  r->cell[r->ncell++] = r->exit1;
  for (int k = 0; k < 3; k++)
    r->cell[r->ncell++] = mk(r->lo, -(k == 0), -(k == 1), -(k == 2)); /* lo - xi_k */
  r->nface = 0;
  r->face[r->nface++] = mk(r->lo, 0, -1, 0);
  r->face[r->nface++] = mk(r->lo, 0, 0, -1);
  if (!tet) {
    r->cell[r->ncell++] = mk(-1, 0, 1, 0);
    r->cell[r->ncell++] = mk(-1, 0, 0, 1);
    r->face[r->nface++] = mk(-1, 0, 0, 1);
  }
}

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

/* A boundary triangle in reference coordinates, with its vertex ids. */
typedef struct rtri {
  fcm_index id[3];
  double x[9];
} rtri;

static void to_ref(const fcm__embed_cell *cell, const double *p, double xi[3])
{
  const double d[3] = {p[0] - cell->X[0], p[1] - cell->X[1], p[2] - cell->X[2]};
  double s[3];
  fcm__mat3_mulv(cell->Ainv, d, s);
  for (int k = 0; k < 3; k++)
    xi[k] = cell->xi0[k] + s[k];
}

static void load_tri(const fcm_geometry *g, const fcm__embed_cell *cell, fcm_index t, rtri *T)
{
  for (int a = 0; a < 3; a++) {
    T->id[a] = g->tris[3 * t + a];
    to_ref(cell, g->coords + 3 * T->id[a], T->x + 3 * a);
  }
}

/* The point where mesh edge (i, j) meets the plane with values v, interpolated from the
 * lower-numbered vertex so both triangles of the edge get it bit for bit. */
static void edge_point(const rtri *T, const double v[3], int i, int j, double out[3])
{
  if (T->id[j] < T->id[i]) {
    const int k = i;
    i = j, j = k;
  }
  const double t = v[i] / (v[i] - v[j]);
  for (int d = 0; d < 3; d++)
    out[d] = T->x[3 * i + d] + t * (T->x[3 * j + d] - T->x[3 * i + d]);
}

/* The segment P -> Q where T crosses plane l, oriented so that the cross-section of the body
 * lies on its left seen from the side the plane's normal points to (counter-clockwise around
 * the cross-section); 0 when T does not cross. */
static int tri_segment(const rtri *T, const lin *l, double P[3], double Q[3])
{
  double v[3];
  int up[3];
  for (int a = 0; a < 3; a++) {
    v[a] = lin_eval(l, T->x + 3 * a);
    up[a] = v[a] >= 0.0;
  }
  if (up[0] == up[1] && up[1] == up[2]) return 0;
  const int a = up[0] == up[1] ? 2 : up[0] == up[2] ? 1 : 0; /* the vertex alone on its side */
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  if (up[a]) {
    edge_point(T, v, a, b, P);
    edge_point(T, v, a, c, Q);
  } else {
    edge_point(T, v, a, c, P);
    edge_point(T, v, a, b, Q);
  }
  return 1;
}

/* Where the segment P -> Q crosses plane l: the point and +1 when it leaves the
 * non-negative side (P above), -1 when it enters; 0 when it does not cross. */
static int seg_cross(const double P[3], const double Q[3], const lin *l, double X[3])
{
  const double vp = lin_eval(l, P), vq = lin_eval(l, Q);
  if ((vp >= 0.0) == (vq >= 0.0)) return 0;
  const double t = vp / (vp - vq);
  for (int d = 0; d < 3; d++)
    X[d] = P[d] + t * (Q[d] - P[d]);
  return vp >= 0.0 ? 1 : -1;
}

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

#define POLY_CAP 16

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

static void grow_box(double box[6], const double x[3])
{
  for (int d = 0; d < 3; d++) {
    box[d] = fmin(box[d], x[d]);
    box[3 + d] = fmax(box[3 + d], x[d]);
  }
}

/* T clipped to K (the exit facet first: a triangle lying in its plane is kept or dropped on
 * its own vertices' values, as the exit facet's segments see them) into a; its count. */
static int clip_to_cell(const ref_cell *r, const rtri *T, double *a)
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
  const int n = clip_to_cell(r, T, a);
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

/* ---------------------------------------------------------------- lines through the body */

/* The physical segment that covers the reference line base + t dir (any t) over the
 * geometry's bounding box, and the distance the rounding of the map to reference coordinates
 * can move a triangle across the line: about eps cond(A) times the distance to the cell (a
 * sliver tet of a fan has cond(A) up to 1e12, and a triangle the reference line crosses can
 * then miss a tighter segment). */
static void line_segment(const fcm_geometry *g, const fcm__embed_cell *cell, const double base[3],
                         const double dir[3], double p0[3], double p1[3], double *pad)
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

/* The half of the reference line base + t dir beyond the values [zlo, zhi] of t that is the
 * shorter inside the geometry's bounding box (widened by pad), as a physical segment p0 -> p1
 * with a reference length of margin at each end: 1 when it runs up (t from zlo - 1 to the
 * box's far side), 0 when down (to zhi + 1). The crossings with the boundary on it are those
 * at t >= zlo (up) or t <= zhi (down) of the whole line, each from a triangle whose box meets
 * the segment: a closed surface's crossings at and beyond t sum to minus those before t, so
 * either half gives the winding numbers along [zlo, zhi], and a line near the body's top or
 * side visits a fraction of the tree's nodes the whole line would. */
/* Whether tree is g's own tree of its boundary triangles and g not a subset of another
 * geometry's: a closed surface (checked where the geometry was made; a subset's boundary is
 * part of one). Lines take their shorter half on it only; on other trees the whole line, whose
 * crossings must sum to zero. */
static int closed_tree(const fcm_geometry *g, const fcm_aabb_tree *tree)
{
  return tree == g->trees[1] && !g->tri_orig;
}

static int line_half(const fcm_geometry *g, const fcm__embed_cell *cell, const double base[3],
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

/* The winding number at t = z of the line whose crossings (at cr->z, signs cr->sign) were
 * found on its half up (all at t >= z counted) or down (all at t < z counted, negated). */
static int line_winding(const fcm__crossings *cr, int up, double z)
{
  int w = 0;
  for (size_t k = 0; k < cr->n; k++)
    if ((cr->z[k] >= z) == up) w += cr->sign[k];
  return up ? w : -w;
}

/* The crossings of the body's boundary with the line {l1 = 0, l2 = 0} (base + t dir), as
 * values of xi_3 with +1 (leaving the body going up in xi_3) or -1; the candidates are the
 * triangles in buf. *sum: the sum of the signs (0 for a closed surface). */
static fcm_status line_crossings(fcm_ctx *ctx, const fcm_geometry *g, const fcm__embed_cell *cell,
                                 const fcm__idbuf *buf, const lin *l1, const lin *l2,
                                 fcm__crossings *out, int *sum)
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

/* A clear box of half-width this x the cell's size is looked for around a point whose inside
 * test finds none: the later points in it (a part's quadrature points, a fit's candidates) take
 * its winding number. */
#define CLEAR_BOX_RSIZE 0.25

/* The point (a, b, z) of the cell in physical coordinates. */
static void to_physical(const fcm__embed_cell *cell, double a, double b, double z, double x[3])
{
  const double d[3] = {a - cell->xi0[0], b - cell->xi0[1], z - cell->xi0[2]};
  fcm__mat3_mulv(cell->A, d, x);
  for (int k = 0; k < 3; k++)
    x[k] += cell->X[k];
}

/* A clear box of cr's that holds x for queries of rounding distance pad; NULL: none. */
static const fcm__clear_box *clear_box_find(const fcm__crossings *cr, const fcm_aabb_tree *tree,
                                            const double x[3], double pad)
{
  if (cr->tree != tree) return NULL;
  for (int i = 0; i < cr->nclear; i++) {
    const fcm__clear_box *c = cr->clear + i;
    if (pad <= c->pad && c->lo[0] <= x[0] && x[0] <= c->hi[0] && c->lo[1] <= x[1] &&
        x[1] <= c->hi[1] && c->lo[2] <= x[2] && x[2] <= c->hi[2])
      return c;
  }
  return NULL;
}

/* Keep a box around x with winding number w, of half-width up to r, that no boundary
 * triangle's box (the tree's) comes within pad of: the triangles' boxes near x bound it.
 * While fewer than a quarter of the recent looks found one (points inside the triangles'
 * boxes: the query costs more than it saves), one call in 16 looks. */
static fcm_status clear_box_add(fcm_ctx *ctx, const fcm_aabb_tree *tree, const double x[3],
                                double r, double pad, int w, fcm__idbuf *buf, fcm__crossings *cr)
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
  line_segment(g, cell, base, dir, p0, p1, &pad);
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
  const int up = half ? line_half(g, cell, base, dir, zlo, zhi, pad, p0, p1) : 1;
  FCM_TRY(ctx, fcm__geom_tree_segment(ctx, tree, p0, p1, pad, buf));
  FCM_TRY(ctx, line_crossings(ctx, g, cell, buf, &l1, &l2, cr, &sum));
  FCM_CHECK(half || sum == 0, ctx, FCM_ERR_GEOMETRY,
            "embed: background cell %lld: a line through the body crosses its boundary %d more "
            "times outward than inward (the boundary surface is not closed)",
            (long long)cell->id, sum);
  for (int i = 0; i < n; i++) /* crossings at or beyond z[i], leaving counted +1 */
    inside[i] = line_winding(cr, up, z[i]);
  if (n == 1)
    FCM_TRY(ctx, clear_box_add(ctx, tree, x, CLEAR_BOX_RSIZE * cell->size, 2.0 * pad,
                               orient * inside[0], buf, cr));
cleanup:
  return st;
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
  line_segment(g, cell, base, dir, p0, p1, &pad);
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
    const int n = clip_to_cell(&r, &T, a);
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
  line_segment(g, cell, lbase, dir, p0, p1, &pad);
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
    up = line_half(g, cell, lbase, dir, r.lo, 1.0, pad, p0, p1);
  FCM_TRY(ctx, fcm__geom_tree_segment(ctx, tree, p0, cb ? P : p1, pad, buf));
  FCM_TRY(ctx, line_crossings(ctx, g, cell, buf, &r.exit1, &r.exit2, cr, &sum));
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
    FCM_TRY(ctx, clear_box_add(ctx, tree, P, CLEAR_BOX_RSIZE * cell->size, 2.0 * pad,
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
  line_segment(g, cell, lbase, dir, p0, p1, &pad);
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
