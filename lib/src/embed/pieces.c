/* Cutting (XFEM) inside one background cell: the convex parts of the embedded
 * geometry are split by the plane of every cut triangle that reaches them and by the
 * triangle's three edge planes, so that every new face lies wholly on or wholly off the
 * triangle; parts that share a face of positive area, wider than the tolerance's band, not
 * lying on a cut triangle are connected; the connected components are the cell's material
 * pieces. Each piece then goes through the same tetrahedralize -> map -> simplify -> stabilize
 * path as a cut cell.
 *
 * Robustness: each part vertex is classified once per plane with the cuts' tolerance
 * (fcm__geom_poly_clip), and both halves of a split are made from the same signed
 * distances, so the two sides of a new face have bitwise equal vertices; a cap through
 * vertices within the tolerance is stored as planar triangles, so later splits conserve the
 * volume exactly. Where two parts touch (in one cell, or across a cell face), what decides
 * whether they join is not where each placed the cut (the crossing of a plane nearly
 * parallel to a face is ill-conditioned: two cells can place it apart) but their sides:
 * parts whose touching face lies on a cut triangle join only when they lie on the same side
 * of it (fcm__embed_linked). A cut through a node, along an edge or in a face of the
 * background or the embedded mesh needs no special case: a face lying on a triangle
 * separates, wherever it came from. */
#include "embed/embed_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Relative tolerances of the connectivity tests: faces match when they face each other and
 * the vertices of each lie within MATCH_RTOL x the cell size of the other's plane, and they
 * overlap by more than AREA_RTOL x size^2 in a polygon wider than WIDE_FACTOR x MATCH_RTOL x
 * size (overlap_shared()). (Comparing the planes' normals and offsets
 * instead would let a face tilted 1e-6 off a cell face through the origin pass for one lying
 * on it, however far its vertices are.) */
#define MATCH_RTOL FCM__EMBED_MATCH_RTOL
#define AREA_RTOL  1e-12
/* The overlap of two faces is on a cut when its vertices lie within this many times the
 * matching tolerance of a cut triangle: clipping one face by the other's edges places new
 * vertices on segments between points within the tolerance, up to rounding. */
#define ON_CUT_FACTOR 2.0
/* A shared face is wider than this many times the matching tolerance (overlap_shared()). */
#define WIDE_FACTOR 4.0

void fcm__embed_parts_free(fcm_ctx *ctx, fcm__parts *P)
{
  fcm__free(ctx, P->poly);
  fcm__free(ctx, P->tol);
  fcm__free(ctx, P->vmin);
  fcm__free(ctx, P->piece);
  fcm__free(ctx, P->parent);
  fcm__free(ctx, P->fx);
  fcm__free(ctx, P->fmeta);
  fcm__free(ctx, P->uf);
  fcm__geom_idbuf_free(ctx, &P->tcand);
  fcm__material_destroy(ctx, &P->mat);
  fcm__free(ctx, P->mvol);
  P->mvol = NULL;
  P->poly = NULL;
  P->tol = P->vmin = P->fx = NULL;
  P->piece = P->parent = P->fmeta = P->uf = NULL;
  P->n = P->cap = P->nfx = P->capfx = P->nfp = P->capfp = P->ufcap = 0;
}

/* Room for `need` parts. The polyhedra are read only up to their counts (every slot is
 * written by fcm__geom_poly_copy() before it is read): the new array is neither zeroed nor filled
 * beyond the used part of the P->n there are, a fraction of the 26 kB each. */
static fcm_status parts_grow(fcm_ctx *ctx, fcm__parts *P, size_t need)
{
  fcm_status st = FCM_OK;
  if (need <= P->cap) return FCM_OK;
  size_t cap = P->cap ? 2 * P->cap : 16;
  while (cap < need)
    cap *= 2;
  void *t = P->tol, *v = P->vmin, *q = P->piece, *r = P->parent;
  fcm__poly *p = fcm__malloc(ctx, cap, sizeof *p);
  FCM_CHECK(p, ctx, FCM_ERR_ALLOC, "cell parts: out of memory for %zu polyhedra", cap);
  for (size_t i = 0; i < P->n; i++)
    fcm__geom_poly_copy(p + i, P->poly + i);
  fcm__free(ctx, P->poly);
  P->poly = p;
  FCM_TRY(ctx, fcm__resize(ctx, &t, P->n, cap, sizeof(double)));
  P->tol = t;
  FCM_TRY(ctx, fcm__resize(ctx, &v, P->n, cap, sizeof(double)));
  P->vmin = v;
  FCM_TRY(ctx, fcm__resize(ctx, &q, P->n, cap, sizeof(int)));
  P->piece = q;
  FCM_TRY(ctx, fcm__resize(ctx, &r, P->n, cap, sizeof(int)));
  P->parent = r;
  void *mv = P->mvol;
  FCM_TRY(ctx, fcm__resize(ctx, &mv, P->n, cap, sizeof(double)));
  P->mvol = mv;
  P->cap = cap;
cleanup:
  return st;
}

fcm_status fcm__embed_parts_put(fcm_ctx *ctx, fcm__parts *P, size_t slot, const fcm__poly *q,
                                double tol, double vmin, int parent)
{
  fcm_status st = FCM_OK;
  if (slot == P->n) {
    FCM_TRY(ctx, parts_grow(ctx, P, P->n + 1));
    P->n++;
  }
  fcm__geom_poly_copy(P->poly + slot, q);
  P->tol[slot] = tol;
  P->vmin[slot] = vmin;
  P->piece[slot] = 0;
  P->parent[slot] = parent;
  P->mvol[slot] = 0.0;
cleanup:
  return st;
}

fcm_status fcm__embed_cell_parts(fcm_ctx *ctx, const fcm_geometry *geom, const fcm_aabb_tree *tree,
                                 const fcm__embed_cell *cell, double clip_rtol, double sliver_rtol,
                                 fcm__embed_ws *ws, fcm__parts *P, double *whole_mvol,
                                 fcm__embed_counts *counts)
{
  fcm_status st = FCM_OK;
  fcm_index nparts = 0;
  P->n = 0;
  P->num_pieces = 0;
  if (geom->num_cells == 0) { /* no volume mesh: the cell itself, if the body is in it */
    if (!P->mat) FCM_TRY(ctx, fcm__material_create(ctx, geom, &P->mat));
    fcm__geom_poly_from_cell(cell->info->num_corners == 4 ? FCM_ELEMENT_TET4 : FCM_ELEMENT_HEX8,
                             cell->X, &ws->poly);
    FCM_TRY(ctx,
            fcm__embed_parts_put(ctx, P, 0, &ws->poly, cell->tol, sliver_rtol * cell->volume, 0));
    P->whole = 1;
    FCM_TRY(ctx, fcm__embed_drop_dry(ctx, cell, P, whole_mvol));
    if (counts) counts->parts += (fcm_index)P->n;
    P->num_pieces = P->num_parents = P->n > 0;
    return FCM_OK;
  }
  FCM_TRY(ctx, fcm__geom_tree_query(ctx, tree, cell->lo, cell->hi, &ws->cand));
  for (size_t k = 0; k < ws->cand.n; k++) {
    double tol, vmin;
    FCM_TRY(ctx, fcm__embed_clip_cell(ctx, geom, cell, ws->cand.ids[k], clip_rtol, sliver_rtol, ws,
                                      &tol, &vmin));
    if (ws->poly.nf == 0) continue;
    nparts++;
    FCM_TRY(ctx, fcm__embed_parts_put(ctx, P, P->n, &ws->poly, tol, vmin, 0));
  }
  if (counts) {
    counts->candidates += (fcm_index)ws->cand.n;
    counts->parts += nparts;
  }
  P->num_pieces = P->num_parents = P->n > 0;
cleanup:
  return st;
}

/* Signed distance range of p's vertices to plane pl. */
static void plane_range(const fcm__poly *p, const fcm__plane *pl, double *lo, double *hi)
{
  *lo = HUGE_VAL, *hi = -HUGE_VAL;
  for (int i = 0; i < p->nv; i++) {
    const double s = fcm__vec3_dot(pl->n, p->x[i]) - pl->d;
    *lo = fmin(*lo, s), *hi = fmax(*hi, s);
  }
}

static fcm__plane flip(const fcm__plane *pl)
{
  fcm__plane q = {{-pl->n[0], -pl->n[1], -pl->n[2]}, -pl->d};
  return q;
}

/* Split part i by triangle t into up to 5 parts (outside each edge plane in turn, then the
 * rest, inside all three, on both sides of its plane); the first stays in slot i, the rest are
 * appended. A part strictly on one side of the plane, or outside an edge plane up to the
 * tolerance, is left. */
fcm_status fcm__embed_part_split(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *t,
                                 fcm__parts *P, size_t i)
{
  fcm_status st = FCM_OK;
  /* the cut planes classify with the connectivity tests' tolerance (a vertex within
   * MATCH_RTOL x the cell size is on the plane), so that a face the split treats as lying on
   * a cut is one the link test treats so too, and a cut passing that close to a vertex or a
   * face goes through it instead of cutting off a slice thinner than the tolerance */
  const double tol = fmax(P->tol[i], MATCH_RTOL * cell->size), vmin = P->vmin[i];
  const int parent = P->parent[i];
  double lo, hi;
  plane_range(P->poly + i, &t->plane, &lo, &hi);
  /* strictly on one side; or flat on the plane (within tol of it everywhere): split, it would
   * go to both sides; left whole, it is the flat part the links treat as such */
  if (lo > tol || hi < -tol || (lo >= -tol && hi <= tol)) return FCM_OK;
  for (int e = 0; e < 3; e++) {
    if (t->inner[e]) continue;
    plane_range(P->poly + i, &t->edge[e], &lo, &hi);
    if (lo >= -tol && !(t->owns[e] && hi <= tol)) return FCM_OK;
  }
  P->whole = 0;
  const double full = P->mat && fcm__embed_part_full(P, i) ? -1.0 : 0.0; /* the pieces' too */
  fcm__poly *W = P->w; /* W[0]: the part in the column; W[1]: one side; W[2]: outside an edge */
  fcm__geom_poly_copy(&W[0], P->poly + i);
  size_t slot = i;
  int overflow = 0;
  /* outside the triangle's column the plane is no cut: what lies there is left whole (split
   * by the plane's extension, it would make thin slabs between it and a neighbouring
   * triangle's plane, which the tolerance cannot resolve) */
  for (int e = 0; e < 3 && W[0].nf > 0; e++) {
    if (t->inner[e]) continue;
    /* a part flat on a plane is kept by both clips: it goes whole to one side, inside the
     * column on the wall this triangle owns, else outside */
    plane_range(&W[0], &t->edge[e], &lo, &hi);
    const int flat = lo >= -tol && hi <= tol;
    if (flat && t->owns[e]) continue;
    fcm__geom_poly_copy(&W[2], &W[0]);
    if (flat) {
      W[0].nv = W[0].nf = 0;
    } else {
      const fcm__plane out = flip(&t->edge[e]);
      overflow |= fcm__geom_poly_clip(&W[2], &out, tol, &P->scratch);
      overflow |= fcm__geom_poly_clip(&W[0], &t->edge[e], tol, &P->scratch);
    }
    if (W[2].nf > 0) {
      FCM_TRY(ctx, fcm__embed_parts_put(ctx, P, slot, &W[2], P->tol[i], vmin, parent));
      P->mvol[slot] = full;
      slot = P->n;
    }
  }
  plane_range(&W[0], &t->plane, &lo, &hi);
  const int flat = lo >= -tol && hi <= tol; /* one part, the flat one the links treat as such */
  for (int side = 0; side < 2 - flat && W[0].nf > 0; side++) {
    fcm__geom_poly_copy(&W[1], &W[0]);
    const fcm__plane h = side ? flip(&t->plane) : t->plane;
    if (!flat) overflow |= fcm__geom_poly_clip(&W[1], &h, tol, &P->scratch);
    if (W[1].nf > 0) {
      FCM_TRY(ctx, fcm__embed_parts_put(ctx, P, slot, &W[1], P->tol[i], vmin, parent));
      P->mvol[slot] = full;
      slot = P->n;
    }
  }
  FCM_CHECK(!overflow, ctx, FCM_ERR_INTERNAL,
            "embed: splitting a convex part of background cell %lld by a cut triangle exceeded "
            "the polyhedron capacity (%d vertices, %d faces)",
            (long long)cell->id, FCM__POLY_MAX_VERTS, FCM__POLY_MAX_FACES);
  if (slot == i) P->poly[i].nv = P->poly[i].nf = 0; /* nothing left: compacted later */
cleanup:
  return st;
}

fcm_status fcm__embed_parts_split(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *t,
                                  fcm__parts *P)
{
  fcm_status st = FCM_OK;
  const size_t n0 = P->n;
  for (size_t i = 0; i < n0; i++)
    FCM_TRY(ctx, fcm__embed_part_split(ctx, cell, t, P, i));
  fcm__embed_parts_compact(P);
cleanup:
  return st;
}

fcm_status fcm__embed_parts_copy(fcm_ctx *ctx, const fcm__parts *P, int piece, fcm__parts *Q)
{
  fcm_status st = FCM_OK;
  Q->n = 0;
  for (size_t j = 0; j < P->n; j++)
    if (P->piece[j] == piece)
      FCM_TRY(ctx, fcm__embed_parts_put(ctx, Q, Q->n, P->poly + j, P->tol[j], P->vmin[j], 0));
cleanup:
  return st;
}

int fcm__embed_face_plane(const fcm__poly *p, int f, fcm__plane *pl)
{
  double n[3] = {0, 0, 0};
  const int m = p->fn[f];
  for (int k = 0; k < m; k++) {
    const double *a = p->x[p->fv[f][k]], *b = p->x[p->fv[f][(k + 1) % m]];
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  if (!(fcm__vec3_dot(n, n) > 0.0)) return 0;
  const fcm__plane *q = p->fp + f;
  if (q->n[0] == 0.0 && q->n[1] == 0.0 && q->n[2] == 0.0) return 0;
  *pl = *q;
  return 1;
}

/* Whether the m points x lie within tol of plane pl. */
static int points_on_plane(const double *x, int m, const fcm__plane *pl, double tol)
{
  for (int k = 0; k < m; k++)
    if (!(fabs(fcm__vec3_dot(pl->n, x + 3 * k) - pl->d) <= tol)) return 0;
  return 1;
}

int fcm__embed_face_coords(const fcm__poly *p, int f, double *x)
{
  for (int k = 0; k < p->fn[f]; k++)
    memcpy(x + 3 * k, p->x[p->fv[f][k]], 3 * sizeof *x);
  return p->fn[f];
}

/* The area of polygon x (m vertices). */
static double polygon_area(const double *x, int m)
{
  double n[3] = {0, 0, 0};
  for (int k = 0; k < m; k++) {
    const double *p = x + 3 * k, *q = x + 3 * ((k + 1) % m);
    n[0] += (p[1] - q[1]) * (p[2] + q[2]);
    n[1] += (p[2] - q[2]) * (p[0] + q[0]);
    n[2] += (p[0] - q[0]) * (p[1] + q[1]);
  }
  return 0.5 * sqrt(fcm__vec3_dot(n, n));
}

/* The plane of edge p, q of a face with normal nrm, outward (zero normal: a point edge). */
static fcm__plane edge_plane(const double p[3], const double q[3], const double nrm[3])
{
  fcm__plane pl = {{0, 0, 0}, 0};
  double e[3], mm[3];
  for (int d = 0; d < 3; d++)
    e[d] = q[d] - p[d];
  fcm__vec3_cross(e, nrm, mm);
  const double lm = sqrt(fcm__vec3_dot(mm, mm));
  if (!(lm > 0.0)) return pl;
  for (int d = 0; d < 3; d++)
    pl.n[d] = mm[d] / lm;
  pl.d = fcm__vec3_dot(pl.n, p);
  return pl;
}

static int zero_plane(const fcm__plane *pl)
{
  return pl->n[0] == 0.0 && pl->n[1] == 0.0 && pl->n[2] == 0.0;
}

double fcm__embed_overlap(const double *a, int na, const double *b, int nb,
                          const double nb_normal[3], double tol, double *overlap, int *num_overlap)
{
  double x[3 * FCM__POLY_MAX_VERTS], work[3 * FCM__POLY_MAX_VERTS];
  if (num_overlap) *num_overlap = 0;
  if (na < 3 || nb < 3 || na > FCM__POLY_MAX_VERTS) return 0.0;
  memcpy(x, a, 3 * (size_t)na * sizeof *x);
  int m = na;
  for (int k = 0; k < nb && m >= 3; k++) {
    const fcm__plane pl = edge_plane(b + 3 * k, b + 3 * ((k + 1) % nb), nb_normal);
    if (!zero_plane(&pl)) m = fcm__geom_polygon_clip(x, m, FCM__POLY_MAX_VERTS, &pl, tol, 1, work);
  }
  if (m < 3) return 0.0;
  if (overlap) memcpy(overlap, x, 3 * (size_t)m * sizeof *x);
  if (num_overlap) *num_overlap = m;
  return polygon_area(x, m);
}

/* Whether point x lies on one of the triangles within tol. */
static int point_on_cut(const fcm__cut_tri *tris, const fcm_index *ids, size_t n, const double x[3],
                        double tol)
{
  for (size_t k = 0; k < n; k++) {
    const fcm__cut_tri *t = tris + ids[k];
    if (fabs(fcm__vec3_dot(t->plane.n, x) - t->plane.d) > tol) continue;
    int in = 1;
    for (int e = 0; e < 3 && in; e++)
      in = fcm__vec3_dot(t->edge[e].n, x) - t->edge[e].d <= tol; /* inner edges too: a point beyond
                                                            an outer edge of the patch is off */
    if (in) return 1;
  }
  return 0;
}

/* Whether the overlap x (m vertices) of two faces is one they share: more than atol of area,
 * and wider than the band the tolerance alone makes. Faces within tol of each other's planes
 * overlap up to tol beyond the edges of each, so a sliver face of no width overlaps a face
 * across it in a band up to 2 tol wide; and a nearly zero edge of a sliver has an edge plane
 * that can point anywhere, so the band can run far past the sliver's end, across a cut surface
 * between parts on its two sides (with no vertex near the cut: the band's ends lie on either
 * side of it). The polygon's 2 area / perimeter (a strip's width) must exceed WIDE_FACTOR x
 * tol; a part that touches others only through such strips becomes a piece of its own. */
static int overlap_shared(const double *x, int m, double atol, double tol)
{
  const double area = polygon_area(x, m);
  if (!(area > atol)) return 0;
  double perimeter = 0.0;
  for (int k = 0; k < m; k++) {
    const double *p = x + 3 * k, *q = x + 3 * ((k + 1) % m);
    const double e[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    perimeter += sqrt(fcm__vec3_dot(e, e));
  }
  return 2.0 * area > WIDE_FACTOR * tol * perimeter;
}

int fcm__embed_on_cut(const fcm__cut_tri *tris, const fcm_index *ids, size_t n, const double *x,
                      int m, double tol)
{
  double c[3] = {0, 0, 0};
  for (int k = 0; k < m; k++) {
    if (!point_on_cut(tris, ids, n, x + 3 * k, tol)) return 0;
    for (int d = 0; d < 3; d++)
      c[d] += x[3 * k + d] / m;
  }
  return m > 0 && point_on_cut(tris, ids, n, c, tol);
}

/* The side of the convex part with vertices v (nv) of plane pl: +1 or -1 when all its
 * vertices lie on that side or within tol of the plane and one lies beyond tol, 0 when it is
 * flat on the plane or crosses it. */
static int part_side(const double *v, int nv, const fcm__plane *pl, double tol)
{
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (int k = 0; k < nv; k++) {
    const double sd = fcm__vec3_dot(pl->n, v + 3 * k) - pl->d;
    lo = fmin(lo, sd), hi = fmax(hi, sd);
  }
  if (lo >= -tol && hi > tol) return 1;
  if (hi <= tol && lo < -tol) return -1;
  return 0;
}

/* Whether the parts with vertices va (nva) and vb (nvb) whose faces overlap in the polygon x
 * (m vertices, of more than the area that counts) join: the overlap does not lie on a cut
 * triangle, or they lie on the same side of each it lies on. */
static int overlap_linked(const double *x, int m, const double *va, int nva, const double *vb,
                          int nvb, double tol, const fcm__cut_tri *tris, const fcm_index *ids,
                          size_t n)
{
  double c[3] = {0, 0, 0};
  const double ctol = ON_CUT_FACTOR * tol;
  if (!fcm__embed_on_cut(tris, ids, n, x, m, ctol)) return 1;
  for (int k = 0; k < m; k++)
    for (int d = 0; d < 3; d++)
      c[d] += x[3 * k + d] / m;
  /* joined only when on the same side of every cut triangle under the centroid (where cuts
   * cross, the overlap can lie on two: the parts may share the side of one and not the
   * other's) */
  for (size_t k = 0; k < n; k++) {
    const fcm_index t = ids[k];
    if (!point_on_cut(tris, &t, 1, c, ctol)) continue;
    const fcm__plane *pl = &tris[t].plane;
    const int sa = part_side(va, nva, pl, tol), sb = part_side(vb, nvb, pl, tol);
    if (!(sa * sb > 0 || (sa == 0 && sb == 0))) return 0;
  }
  return 1;
}

int fcm__embed_linked(const double *a, int na, const double *va, int nva, const double *b, int nb,
                      const double *vb, int nvb, const double nb_normal[3], double tol, double atol,
                      const fcm__cut_tri *tris, const fcm_index *ids, size_t n)
{
  double x[3 * FCM__POLY_MAX_VERTS];
  int m = 0;
  fcm__embed_overlap(a, na, b, nb, nb_normal, tol, x, &m);
  if (m < 3 || !overlap_shared(x, m, atol, tol)) return 0;
  return overlap_linked(x, m, va, nva, vb, nvb, tol, tris, ids, n);
}

static int uf_find(int *uf, int a)
{
  while (uf[a] != a) {
    uf[a] = uf[uf[a]];
    a = uf[a];
  }
  return a;
}

static void uf_union(int *uf, int a, int b)
{
  a = uf_find(uf, a), b = uf_find(uf, b);
  if (a < b)
    uf[b] = a;
  else if (b < a)
    uf[a] = b;
}

void fcm__embed_parts_compact(fcm__parts *P)
{
  size_t kept = 0;
  for (size_t i = 0; i < P->n; i++) {
    if (P->poly[i].nf == 0) continue;
    if (kept != i) {
      fcm__geom_poly_copy(P->poly + kept, P->poly + i);
      P->tol[kept] = P->tol[i];
      P->vmin[kept] = P->vmin[i];
      P->parent[kept] = P->parent[i];
      P->mvol[kept] = P->mvol[i];
    }
    kept++;
  }
  P->n = kept;
}

/* Split every part by the triangles tris[P->tcand.ids[k0 .. k1)], then drop the parts the
 * tolerance emptied; *change (unless NULL): how much that changed the parts' total volume.
 * Parts of a surface body without material are dropped too (after the volume is compared), and
 * parts holding separate lumps of it split into them. */
static fcm_status split_parts(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *tris,
                              size_t k0, size_t k1, fcm__parts *P, double *change)
{
  fcm_status st = FCM_OK;
  double before = 0.0, after = 0.0;
  for (size_t i = 0; change && i < P->n; i++)
    before += fcm__geom_poly_volume(P->poly + i);
  for (size_t k = k0; k < k1; k++) {
    const fcm__cut_tri *t = tris + P->tcand.ids[k];
    const size_t n0 = P->n;
    for (size_t i = 0; i < n0; i++)
      FCM_TRY(ctx, fcm__embed_part_split(ctx, cell, t, P, i));
  }
  fcm__embed_parts_compact(P);
  for (size_t i = 0; change && i < P->n; i++)
    after += fcm__geom_poly_volume(P->poly + i);
  if (change) *change = fabs(after - before);
  if (k1 > k0) {
    FCM_TRY(ctx, fcm__embed_drop_dry(ctx, cell, P, NULL));
    FCM_TRY(ctx, fcm__embed_split_lumps(ctx, cell, P));
  }
cleanup:
  return st;
}

/* The faces of positive area of a cell's parts, grouped by their planes: two faces can meet
 * only when the vertices of each lie within the tolerance of the other's plane, and those of a
 * face lie near few of the cell's planes (the cell's faces, the cut triangles' planes and edge
 * planes, the boundary triangles': every face lies on one), so each face is compared with the
 * faces of the planes it lies on, not with every face of every part near it. Faces whose
 * planes are equal up to orientation form a group; the distance of a point to a plane and its
 * negation are the same number, so the test against the group's plane is the test against
 * each of its faces' planes, bit for bit. */
typedef struct face_set {
  size_t n;        /* faces */
  int *part, *nx;  /* per face: its part, its vertex count */
  size_t *x0;      /* its first coordinate in x */
  fcm__plane *pl;  /* its plane as its part stores it */
  double *x;       /* the faces' vertices */
  fcm__plane *ep;  /* per vertex k of a face: the plane of its edge k, k + 1 through the face's
                      normal, outward, as fcm__embed_overlap() makes it (zero: none) */
  double *r;       /* per face: the largest magnitude of its vertices' coordinates */
  int *order;      /* the faces by group, then orientation, then part */
  size_t *goff;    /* group g: order[goff[g] .. goff[g + 1]) */
  size_t *gneg;    /* its first face facing opposite its plane gpl[g] */
  fcm__plane *gpl; /* the group's plane (the orientation of its first face) */
  size_t ng;       /* groups */
} face_set;

static void face_set_free(fcm_ctx *ctx, face_set *F)
{
  fcm__free(ctx, F->part);
  fcm__free(ctx, F->nx);
  fcm__free(ctx, F->x0);
  fcm__free(ctx, F->pl);
  fcm__free(ctx, F->x);
  fcm__free(ctx, F->ep);
  fcm__free(ctx, F->r);
  fcm__free(ctx, F->order);
  fcm__free(ctx, F->goff);
  fcm__free(ctx, F->gneg);
  fcm__free(ctx, F->gpl);
}

/* The sign that orients plane p canonically (its first nonzero normal component positive). */
static double plane_sign(const fcm__plane *p)
{
  for (int d = 0; d < 3; d++)
    if (p->n[d] != 0.0) return p->n[d] > 0.0 ? 1.0 : -1.0;
  return 1.0;
}

/* A face's sort key: its plane oriented canonically, its orientation against that, its part
 * and its index. */
typedef struct face_key {
  double k[4];
  double sign;
  int part, face;
} face_key;

/* Faces by their canonical plane, then by orientation (as the plane first), then by part. */
static int cmp_face(const void *pa, const void *pb)
{
  const face_key *p = pa, *q = pb;
  for (int d = 0; d < 4; d++)
    if (p->k[d] != q->k[d]) return p->k[d] < q->k[d] ? -1 : 1;
  if (p->sign != q->sign) return p->sign > q->sign ? -1 : 1;
  if (p->part != q->part) return p->part < q->part ? -1 : 1;
  return (p->face > q->face) - (p->face < q->face);
}

static int same_plane(const fcm__plane *p, const fcm__plane *q)
{
  const double sp = plane_sign(p), sq = plane_sign(q);
  return sp * p->n[0] == sq * q->n[0] && sp * p->n[1] == sq * q->n[1] &&
         sp * p->n[2] == sq * q->n[2] && sp * p->d == sq * q->d;
}

/* The edge planes of face f (F->ep) and the magnitude of its coordinates (F->r). */
static void edge_planes(face_set *F, size_t f)
{
  const int m = F->nx[f];
  const double *x = F->x + F->x0[f];
  double r = 0.0;
  for (int k = 0; k < m; k++) {
    for (int d = 0; d < 3; d++)
      r = fmax(r, fabs(x[3 * k + d]));
    F->ep[F->x0[f] / 3 + (size_t)k] = edge_plane(x + 3 * k, x + 3 * ((k + 1) % m), F->pl[f].n);
  }
  F->r[f] = r;
}

/* Whether the vertices of face a all lie beyond one edge plane of face b by more than twice
 * tol (plus the rounding of points of the size of theirs): then clipping a by b's edge planes
 * (fcm__embed_overlap()) leaves nothing, whatever the planes before that one clipped (their
 * points lie between a's, beyond it by more than tol), and the faces do not meet. */
static int faces_apart(const face_set *F, size_t a, size_t b, double tol)
{
  const int na = F->nx[a], nb = F->nx[b];
  const double *xa = F->x + F->x0[a];
  const fcm__plane *ep = F->ep + F->x0[b] / 3;
  const double lim = 2.0 * tol + 1e-12 * fmax(F->r[a], F->r[b]);
  if (na < 3 || nb < 3) return 0;
  for (int k = 0; k < nb; k++) {
    if (zero_plane(ep + k)) continue;
    int v = 0;
    while (v < na && fcm__vec3_dot(ep[k].n, xa + 3 * v) - ep[k].d > lim)
      v++;
    if (v == na) return 1;
  }
  return 0;
}

/* Gather the faces of P's parts with positive area and a finite plane (a face without either
 * matches no face: its distances are not within any tolerance) and group them. */
static fcm_status faces_build(fcm_ctx *ctx, const fcm__parts *P, face_set *F)
{
  fcm_status st = FCM_OK;
  face_key *keys = NULL;
  size_t nf = 0, nv = 0;
  for (size_t i = 0; i < P->n; i++) {
    nf += (size_t)P->poly[i].nf;
    for (int f = 0; f < P->poly[i].nf; f++)
      nv += (size_t)P->poly[i].fn[f];
  }
  FCM_ALLOC_RAW(ctx, nf + 1, F->part);
  FCM_ALLOC_RAW(ctx, nf + 1, F->nx);
  FCM_ALLOC_RAW(ctx, nf + 1, F->x0);
  FCM_ALLOC_RAW(ctx, nf + 1, F->pl);
  FCM_ALLOC_RAW(ctx, 3 * nv + 1, F->x);
  FCM_ALLOC_RAW(ctx, nv + 1, F->ep);
  FCM_ALLOC_RAW(ctx, nf + 1, F->r);
  FCM_ALLOC_RAW(ctx, nf + 1, F->order);
  size_t xn = 0;
  for (size_t i = 0; i < P->n; i++)
    for (int f = 0; f < P->poly[i].nf; f++) {
      fcm__plane pl;
      if (!fcm__embed_face_plane(P->poly + i, f, &pl)) continue;
      if (!(isfinite(pl.n[0]) && isfinite(pl.n[1]) && isfinite(pl.n[2]) && isfinite(pl.d)))
        continue;
      F->part[F->n] = (int)i, F->pl[F->n] = pl, F->x0[F->n] = xn;
      F->nx[F->n] = fcm__embed_face_coords(P->poly + i, f, F->x + xn);
      edge_planes(F, F->n);
      xn += 3 * (size_t)F->nx[F->n];
      F->n++;
    }
  FCM_ALLOC_RAW(ctx, F->n + 1, keys);
  for (size_t k = 0; k < F->n; k++) {
    const fcm__plane *p = F->pl + k;
    const double sg = plane_sign(p);
    face_key *fk = keys + k;
    for (int d = 0; d < 3; d++)
      fk->k[d] = sg * p->n[d];
    fk->k[3] = sg * p->d, fk->sign = sg, fk->part = F->part[k], fk->face = (int)k;
  }
  qsort(keys, F->n, sizeof *keys, cmp_face);
  for (size_t k = 0; k < F->n; k++)
    F->order[k] = keys[k].face;
  FCM_ALLOC_RAW(ctx, F->n + 1, F->goff);
  FCM_ALLOC_RAW(ctx, F->n + 1, F->gneg);
  FCM_ALLOC_RAW(ctx, F->n + 1, F->gpl);
  for (size_t k = 0; k < F->n; k++) {
    const fcm__plane *p = F->pl + F->order[k];
    if (k == 0 || !same_plane(p, F->pl + F->order[k - 1])) {
      F->goff[F->ng] = F->gneg[F->ng] = k;
      F->gpl[F->ng++] = *p;
    }
    const size_t g = F->ng - 1;
    if (plane_sign(p) == plane_sign(F->gpl + g)) F->gneg[g] = k + 1;
  }
  F->goff[F->ng] = F->n;
cleanup:
  fcm__free(ctx, keys);
  return st;
}

/* Whether face a (of part i) and face b (of part j > i) facing it share an area that does
 * not lie on a cut triangle and holds material (a body given by its surface); a's vertices
 * lie within mtol of b's plane. */
static int faces_linked(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *tris,
                        size_t ntri, const fcm__parts *P, const face_set *F, size_t a, size_t b)
{
  const double mtol = MATCH_RTOL * cell->size, atol = AREA_RTOL * cell->size * cell->size;
  const int i = F->part[a], j = F->part[b];
  const double *xa = F->x + F->x0[a], *xb = F->x + F->x0[b];
  const int na = F->nx[a], nb = F->nx[b];
  if (!points_on_plane(xb, nb, F->pl + a, mtol) || faces_apart(F, a, b, mtol)) return 0;
  /* fcm__embed_linked() on b's edge planes made once */
  double x[3 * FCM__POLY_MAX_VERTS], work[3 * FCM__POLY_MAX_VERTS];
  const fcm__plane *ep = F->ep + F->x0[b] / 3;
  int m = na;
  if (na < 3 || nb < 3 || na > FCM__POLY_MAX_VERTS) return 0;
  memcpy(x, xa, 3 * (size_t)na * sizeof *x);
  for (int k = 0; k < nb && m >= 3; k++)
    if (!zero_plane(ep + k))
      m = fcm__geom_polygon_clip(x, m, FCM__POLY_MAX_VERTS, ep + k, mtol, 1, work);
  if (m < 3 || !overlap_shared(x, m, atol, mtol)) return 0;
  const fcm__poly *pa = P->poly + i, *pb = P->poly + j;
  return overlap_linked(x, m, pa->x[0], pa->nv, pb->x[0], pb->nv, mtol, tris, P->tcand.ids, ntri) &&
         (!P->mat || fcm__embed_part_full(P, (size_t)i) || fcm__embed_part_full(P, (size_t)j) ||
          fcm__embed_overlap_material(ctx, P->mat, cell, xa, na, xb, nb, F->pl[b].n));
}

/* Join the parts whose boxes meet and that share a face of positive area not lying on a cut
 * triangle (with material, for a body given by its surface): face a of part i against the
 * faces b of parts j > i on the planes a lies on, facing it (their normals at more than 120
 * degrees). The components do not depend on the order the pairs are joined in. */
static void join_parts(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *tris,
                       size_t ntri, fcm__parts *P, const face_set *F, const double *box)
{
  const double mtol = MATCH_RTOL * cell->size;
  for (size_t a = 0; a < F->n; a++) {
    const int i = F->part[a];
    const fcm__plane *pa = F->pl + a;
    const double *bi = box + 6 * (size_t)i;
    for (size_t g = 0; g < F->ng; g++) {
      const double s = fcm__vec3_dot(pa->n, F->gpl[g].n);
      size_t k0, k1; /* the faces of the group facing a: normal -pa's side of the group's */
      if (s <= -0.5)
        k0 = F->goff[g], k1 = F->gneg[g];
      else if (-s <= -0.5)
        k0 = F->gneg[g], k1 = F->goff[g + 1];
      else
        continue;
      if (k0 == k1 || F->part[F->order[k1 - 1]] <= i) continue;
      if (!points_on_plane(F->x + F->x0[a], F->nx[a], F->gpl + g, mtol)) continue;
      for (size_t k = k0; k < k1; k++) {
        const size_t b = (size_t)F->order[k];
        const int j = F->part[b];
        if (j <= i) continue;
        const double *bj = box + 6 * (size_t)j;
        int apart = 0;
        for (int d = 0; d < 3; d++)
          apart |= bi[d] > bj[3 + d] || bj[d] > bi[3 + d];
        if (apart || uf_find(P->uf, i) == uf_find(P->uf, j)) continue;
        if (faces_linked(ctx, cell, tris, ntri, P, F, a, b)) uf_union(P->uf, i, j);
      }
    }
  }
}

fcm_status fcm__embed_parts_components(fcm_ctx *ctx, const fcm__embed_cell *cell,
                                       const fcm__cut_tri *tris, size_t ntri, fcm__parts *P,
                                       int *label, int *count)
{
  fcm_status st = FCM_OK;
  double *box = NULL;
  face_set F = {0};
  if (P->n > P->ufcap) {
    void *u = P->uf;
    FCM_TRY(ctx, fcm__resize(ctx, &u, 0, P->n, sizeof(int)));
    P->uf = u;
    P->ufcap = P->n;
  }
  FCM_ALLOC_RAW(ctx, 6 * P->n + 1, box);
  const double mtol = MATCH_RTOL * cell->size;
  for (size_t i = 0; i < P->n; i++) {
    P->uf[i] = (int)i;
    double *bi = box + 6 * i;
    for (int d = 0; d < 3; d++)
      bi[d] = HUGE_VAL, bi[3 + d] = -HUGE_VAL;
    for (int v = 0; v < P->poly[i].nv; v++)
      for (int d = 0; d < 3; d++) {
        bi[d] = fmin(bi[d], P->poly[i].x[v][d] - mtol);
        bi[3 + d] = fmax(bi[3 + d], P->poly[i].x[v][d] + mtol);
      }
  }
  FCM_TRY(ctx, faces_build(ctx, P, &F));
  join_parts(ctx, cell, tris, ntri, P, &F, box);
  if (P->mat) FCM_TRY(ctx, fcm__material_status(P->mat));
  int np = 0;
  for (size_t i = 0; i < P->n; i++) {
    const int r = uf_find(P->uf, (int)i);
    label[i] = r == (int)i ? np++ : label[r];
  }
  *count = np;
cleanup:
  fcm__free(ctx, box);
  face_set_free(ctx, &F);
  return st;
}

/* split_parts() by the triangles tris[P->tcand.ids[k0 .. k1)] one cut after the other: the
 * parts and their order then depend on the cuts alone, not on where first_new divides them (a
 * surface body's parts are dropped dry and split into lumps after each cut's triangles); *change
 * (unless NULL): the sum of the cuts' changes. */
static fcm_status split_cuts(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *tris,
                             size_t k0, size_t k1, fcm__parts *P, double *change)
{
  fcm_status st = FCM_OK;
  if (change) *change = 0.0;
  for (size_t k = k0; k < k1;) {
    const int cut = tris[P->tcand.ids[k]].cut;
    size_t e = k + 1;
    while (e < k1 && tris[P->tcand.ids[e]].cut == cut)
      e++;
    double d = 0.0;
    FCM_TRY(ctx, split_parts(ctx, cell, tris, k, e, P, change ? &d : NULL));
    if (change) *change += d;
    k = e;
  }
cleanup:
  return st;
}

fcm_status fcm__embed_cell_pieces(fcm_ctx *ctx, const fcm__embed_cell *cell,
                                  const fcm__cut_tri *tris, fcm_index first_new, fcm__parts *P)
{
  fcm_status st = FCM_OK;
  size_t nold = 0;
  double e1 = 0.0;
  while (nold < P->tcand.n && P->tcand.ids[nold] < first_new)
    nold++;
  FCM_TRY(ctx, split_cuts(ctx, cell, tris, 0, nold, P, NULL));
  if (nold > 0) {
    FCM_TRY(ctx, fcm__embed_parts_components(ctx, cell, tris, nold, P, P->parent, &P->num_parents));
  } else {
    for (size_t i = 0; i < P->n; i++)
      P->parent[i] = 0;
    P->num_parents = P->n > 0;
  }
  FCM_TRY(ctx, split_cuts(ctx, cell, tris, nold, P->tcand.n, P, &e1));
  P->split_error = e1;
  FCM_TRY(ctx,
          fcm__embed_parts_components(ctx, cell, tris, P->tcand.n, P, P->piece, &P->num_pieces));
cleanup:
  return st;
}

fcm_status fcm__embed_piece_tets(fcm_ctx *ctx, const fcm__parts *P, const int *label, int piece,
                                 fcm__embed_ws *ws, fcm__embed_counts *counts, double *volume)
{
  fcm_status st = FCM_OK;
  double vsum = 0.0, lost = 0.0, moved = 0.0;
  fcm_index nslivers = 0;
  ws->num_tets = 0;
  for (size_t i = 0; i < P->n; i++)
    if (label[i] == piece)
      FCM_TRY(ctx, fcm__embed_append_tets(ctx, ws, P->poly + i, P->vmin[i], &vsum, &lost, &moved,
                                          &nslivers));
  fcm__embed_counts_add_tets(counts, ws->num_tets, nslivers, lost, moved);
  *volume = vsum;
cleanup:
  return st;
}

int fcm__embed_clip_to_part(const fcm__parts *P, size_t i, double *x, int n, int cap,
                            const double nrm[3], double *work)
{
  return fcm__embed_clip_to_part_flat(P, i, x, n, cap, nrm, -1.0, work);
}

int fcm__embed_clip_to_part_flat(const fcm__parts *P, size_t i, double *x, int n, int cap,
                                 const double nrm[3], double flat_tol, double *work)
{
  const fcm__poly *p = P->poly + i;
  for (int f = 0; f < p->nf && n >= 3; f++) {
    fcm__plane pl;
    if (!fcm__embed_face_plane(p, f, &pl)) continue;
    const int keep = fcm__vec3_dot(nrm, pl.n) > 0.0;
    if (flat_tol >= 0.0 && points_on_plane(x, n, &pl, flat_tol)) {
      if (keep) continue;
      return 0;
    }
    n = fcm__geom_polygon_clip(x, n, cap, &pl, P->tol[i], keep, work);
  }
  return n;
}

int fcm__embed_part_planes(const fcm__parts *P, size_t i, fcm__plane *pl)
{
  int n = 0;
  for (int f = 0; f < P->poly[i].nf; f++)
    n += fcm__embed_face_plane(P->poly + i, f, pl + n);
  return n;
}

int fcm__embed_clip_to_planes(const fcm__plane *pl, int np, double tol, double *x, int n, int cap,
                              const double nrm[3], double *work)
{
  for (int f = 0; f < np && n >= 3; f++)
    n = fcm__geom_polygon_clip(x, n, cap, pl + f, tol, fcm__vec3_dot(nrm, pl[f].n) > 0.0, work);
  return n;
}

double fcm__embed_planes_excess(const fcm__plane *pl, int np, const double x[3])
{
  double e = -HUGE_VAL;
  for (int f = 0; f < np; f++)
    e = fmax(e, fcm__vec3_dot(pl[f].n, x) - pl[f].d);
  return e;
}

double fcm__embed_part_excess(const fcm__parts *P, size_t i, const double x[3])
{
  const fcm__poly *p = P->poly + i;
  double e = -HUGE_VAL;
  for (int f = 0; f < p->nf; f++) {
    fcm__plane pl;
    if (fcm__embed_face_plane(p, f, &pl)) e = fmax(e, fcm__vec3_dot(pl.n, x) - pl.d);
  }
  return e;
}
