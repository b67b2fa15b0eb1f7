/* embed module, private to the surface moments (surface_moments.c) and the inside tests of
 * points that go with them (surface_inside.c): the reference cell's planes, the boundary
 * triangles in reference coordinates, and the lines through the body, which both take from the
 * same triangles the same way so that they decide alike. The small helpers are static inline:
 * they run in the inner loops of a cut's rules. */
#ifndef FCM_EMBED_MOMENTS_IMPL_H
#define FCM_EMBED_MOMENTS_IMPL_H

#include "embed/embed_impl.h"
#include "la/mat3.h"

/* An affine function s(xi) = c0 + c . xi of reference coordinates; "above" when s >= 0. */
typedef struct lin {
  double c0, c[3];
} lin;

static inline double lin_eval(const lin *l, const double x[3])
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

static inline lin mk(double c0, double a, double b, double c)
{
  lin l = {c0, {a, b, c}};
  return l;
}

/* The cell's constraints start with the exit facet: a triangle lying in its plane is then
 * kept or dropped on its own vertices' values, as the exit facet's segments see them. */
static inline void ref_cell_init(int tet, ref_cell *r)
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

/* A boundary triangle in reference coordinates, with its vertex ids. */
typedef struct rtri {
  fcm_index id[3];
  double x[9];
} rtri;

static inline void to_ref(const fcm__embed_cell *cell, const double *p, double xi[3])
{
  const double d[3] = {p[0] - cell->X[0], p[1] - cell->X[1], p[2] - cell->X[2]};
  double s[3];
  fcm__mat3_mulv(cell->Ainv, d, s);
  for (int k = 0; k < 3; k++)
    xi[k] = cell->xi0[k] + s[k];
}

static inline void load_tri(const fcm_geometry *g, const fcm__embed_cell *cell, fcm_index t,
                            rtri *T)
{
  for (int a = 0; a < 3; a++) {
    T->id[a] = g->tris[3 * t + a];
    to_ref(cell, g->coords + 3 * T->id[a], T->x + 3 * a);
  }
}

/* The point where mesh edge (i, j) meets the plane with values v, interpolated from the
 * lower-numbered vertex so both triangles of the edge get it bit for bit. */
static inline void edge_point(const rtri *T, const double v[3], int i, int j, double out[3])
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
static inline int tri_segment(const rtri *T, const lin *l, double P[3], double Q[3])
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
static inline int seg_cross(const double P[3], const double Q[3], const lin *l, double X[3])
{
  const double vp = lin_eval(l, P), vq = lin_eval(l, Q);
  if ((vp >= 0.0) == (vq >= 0.0)) return 0;
  const double t = vp / (vp - vq);
  for (int d = 0; d < 3; d++)
    X[d] = P[d] + t * (Q[d] - P[d]);
  return vp >= 0.0 ? 1 : -1;
}

/* Room for the vertices of a triangle clipped to the cell (fcm__embed_clip_tri_to_cell()). */
#define POLY_CAP 16

/* T clipped to K (the exit facet first: a triangle lying in its plane is kept or dropped on
 * its own vertices' values, as the exit facet's segments see them) into a; its count. */
int fcm__embed_clip_tri_to_cell(const ref_cell *r, const rtri *T, double *a);

/* ---------------------------------------------------------------- lines through the body */

/* The physical segment that covers the reference line base + t dir (any t) over the
 * geometry's bounding box, and the distance the rounding of the map to reference coordinates
 * can move a triangle across the line: about eps cond(A) times the distance to the cell (a
 * sliver tet of a fan has cond(A) up to 1e12, and a triangle the reference line crosses can
 * then miss a tighter segment). */
void fcm__embed_line_segment(const fcm_geometry *g, const fcm__embed_cell *cell,
                             const double base[3], const double dir[3], double p0[3], double p1[3],
                             double *pad);

/* Whether tree is g's own tree of its boundary triangles and g not a subset of another
 * geometry's: a closed surface (checked where the geometry was made; a subset's boundary is
 * part of one). Lines take their shorter half on it only; on other trees the whole line, whose
 * crossings must sum to zero. */
static inline int closed_tree(const fcm_geometry *g, const fcm_aabb_tree *tree)
{
  return tree == g->trees[1] && !g->tri_orig;
}

/* The half of the reference line base + t dir beyond the values [zlo, zhi] of t that is the
 * shorter inside the geometry's bounding box (widened by pad), as a physical segment p0 -> p1
 * with a reference length of margin at each end: 1 when it runs up (t from zlo - 1 to the
 * box's far side), 0 when down (to zhi + 1). The crossings with the boundary on it are those
 * at t >= zlo (up) or t <= zhi (down) of the whole line, each from a triangle whose box meets
 * the segment: a closed surface's crossings at and beyond t sum to minus those before t, so
 * either half gives the winding numbers along [zlo, zhi], and a line near the body's top or
 * side visits a fraction of the tree's nodes the whole line would. */
int fcm__embed_line_half(const fcm_geometry *g, const fcm__embed_cell *cell, const double base[3],
                         const double dir[3], double zlo, double zhi, double pad, double p0[3],
                         double p1[3]);

/* The winding number at t = z of the line whose crossings (at cr->z, signs cr->sign) were
 * found on its half up (all at t >= z counted) or down (all at t < z counted, negated). */
static inline int line_winding(const fcm__crossings *cr, int up, double z)
{
  int w = 0;
  for (size_t k = 0; k < cr->n; k++)
    if ((cr->z[k] >= z) == up) w += cr->sign[k];
  return up ? w : -w;
}

/* The crossings of the body's boundary with the line {l1 = 0, l2 = 0} (base + t dir), as
 * values of xi_3 with +1 (leaving the body going up in xi_3) or -1; the candidates are the
 * triangles in buf. *sum: the sum of the signs (0 for a closed surface). */
fcm_status fcm__embed_line_crossings(fcm_ctx *ctx, const fcm_geometry *g,
                                     const fcm__embed_cell *cell, const fcm__idbuf *buf,
                                     const lin *l1, const lin *l2, fcm__crossings *out, int *sum);

/* A clear box of half-width this x the cell's size is looked for around a point whose inside
 * test finds none: the later points in it (a part's quadrature points, a fit's candidates) take
 * its winding number. */
#define CLEAR_BOX_RSIZE 0.25

/* The point (a, b, z) of the cell in physical coordinates. */
static inline void to_physical(const fcm__embed_cell *cell, double a, double b, double z,
                               double x[3])
{
  const double d[3] = {a - cell->xi0[0], b - cell->xi0[1], z - cell->xi0[2]};
  fcm__mat3_mulv(cell->A, d, x);
  for (int k = 0; k < 3; k++)
    x[k] += cell->X[k];
}

/* A clear box of cr's that holds x for queries of rounding distance pad; NULL: none. */
static inline const fcm__clear_box *
clear_box_find(const fcm__crossings *cr, const fcm_aabb_tree *tree, const double x[3], double pad)
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
fcm_status fcm__embed_clear_box_add(fcm_ctx *ctx, const fcm_aabb_tree *tree, const double x[3],
                                    double r, double pad, int w, fcm__idbuf *buf,
                                    fcm__crossings *cr);

#endif
