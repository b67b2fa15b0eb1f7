/* Cut surfaces inside one background cell: the cut triangles (their planes and edge planes,
 * the candidates of a cell, the inner edges of a cut surface) and the faces the pieces
 * (pieces.c) carry on the cell's faces and on the cuts: the polygons on the cell's faces that
 * the links between cells compare, and the cut faces. */
#include "embed/embed_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MATCH_RTOL FCM__EMBED_MATCH_RTOL

fcm_status fcm__embed_cut_candidates(fcm_ctx *ctx, const fcm_aabb_tree *cut_tree,
                                     const fcm__embed_cell *cell, fcm__idbuf *buf)
{
  double lo[3], hi[3];
  const double w = 2.0 * MATCH_RTOL * cell->size;
  for (int d = 0; d < 3; d++)
    lo[d] = cell->lo[d] - w, hi[d] = cell->hi[d] + w;
  return fcm__geom_tree_query(ctx, cut_tree, lo, hi, buf);
}

/* The longest edge of triangle (a, b, c), squared: a triangle whose |(b - a) x (c - a)| is
 * not above 1e-14 of it has no area for the cuts. */
static double longest_edge2(const double *a, const double *b, const double *c)
{
  const double *v[3] = {a, b, c};
  double l2 = 0.0;
  for (int k = 0; k < 3; k++) {
    const double *p = v[k], *q = v[(k + 1) % 3];
    double d2 = 0.0;
    for (int d = 0; d < 3; d++)
      d2 += (q[d] - p[d]) * (q[d] - p[d]);
    l2 = fmax(l2, d2);
  }
  return l2;
}

int fcm__embed_cut_tri_setup(const double a[3], const double b[3], const double c[3], int cut,
                             const unsigned char inner[3], const double *ref,
                             const fcm__cut_wall *walls, fcm__cut_tri *t)
{
  memcpy(t->inner, inner, sizeof t->inner);
  for (int k = 0; k < 3; k++)
    t->owns[k] = walls && walls[k].through ? walls[k].owns : 0;
  double e0[3], e1[3], n[3];
  const double l2 = longest_edge2(a, b, c);
  memcpy(t->x[0], a, sizeof t->x[0]);
  memcpy(t->x[1], b, sizeof t->x[1]);
  memcpy(t->x[2], c, sizeof t->x[2]);
  for (int d = 0; d < 3; d++) {
    e0[d] = b[d] - a[d];
    e1[d] = c[d] - a[d];
    t->lo[d] = fmin(a[d], fmin(b[d], c[d]));
    t->hi[d] = fmax(a[d], fmax(b[d], c[d]));
  }
  fcm__vec3_cross(e0, e1, n);
  const double ln = sqrt(fcm__vec3_dot(n, n));
  if (!(ln > 1e-14 * l2)) return 0;
  for (int d = 0; d < 3; d++)
    t->plane.n[d] = n[d] / ln;
  t->plane.d = fcm__vec3_dot(t->plane.n, a);
  if (ref) { /* the plane of the reference triangle of a coplanar patch, oriented as this one */
    double r0[3], r1[3], nr[3];
    for (int d = 0; d < 3; d++)
      r0[d] = ref[3 + d] - ref[d], r1[d] = ref[6 + d] - ref[d];
    fcm__vec3_cross(r0, r1, nr);
    const double lr = sqrt(fcm__vec3_dot(nr, nr)),
                 sg = fcm__vec3_dot(nr, t->plane.n) < 0.0 ? -1.0 : 1.0;
    if (lr > 0.0) {
      for (int d = 0; d < 3; d++)
        t->plane.n[d] = sg * nr[d] / lr;
      t->plane.d = fcm__vec3_dot(t->plane.n, ref);
    }
  }
  for (int k = 0; k < 3; k++) {
    const double *p = t->x[k], *q = t->x[(k + 1) % 3];
    double e[3], m[3];
    if (walls && walls[k].through) { /* the wall shared with the edge's other triangle */
      memcpy(t->edge[k].n, walls[k].n, sizeof t->edge[k].n);
      t->edge[k].d = fcm__vec3_dot(t->edge[k].n, walls[k].through == 1 ? p : q);
      continue;
    }
    for (int d = 0; d < 3; d++)
      e[d] = q[d] - p[d];
    fcm__vec3_cross(e, t->plane.n,
                    m); /* counter-clockwise around n: e x n points out of the triangle */
    const double lm = sqrt(fcm__vec3_dot(m, m));
    for (int d = 0; d < 3; d++)
      t->edge[k].n[d] = m[d] / lm;
    t->edge[k].d = fcm__vec3_dot(t->edge[k].n, p);
  }
  t->cut = cut;
  return 1;
}

typedef struct edge_key {
  fcm_index a, b, slot; /* vertex ids (a < b); slot = 3 x triangle + edge */
} edge_key;

static int edge_cmp(const void *x, const void *y)
{
  const edge_key *p = x, *q = y;
  if (p->a != q->a) return p->a < q->a ? -1 : 1;
  if (p->b != q->b) return p->b < q->b ? -1 : 1;
  return (p->slot > q->slot) - (p->slot < q->slot);
}

/* Unit normal and offset of triangle t of s; 0 when it has no area. */
static int tri_plane(const double *x, const fcm_index *tv, fcm_index t, double n[3], double *d)
{
  const double *a = x + 3 * tv[3 * t], *b = x + 3 * tv[3 * t + 1], *c = x + 3 * tv[3 * t + 2];
  double u[3], v[3];
  for (int k = 0; k < 3; k++)
    u[k] = b[k] - a[k], v[k] = c[k] - a[k];
  fcm__vec3_cross(u, v, n);
  const double ln = sqrt(fcm__vec3_dot(n, n));
  if (!(ln > 0.0)) return 0;
  for (int k = 0; k < 3; k++)
    n[k] /= ln;
  *d = fcm__vec3_dot(n, a);
  return 1;
}

static fcm_index tri_find(fcm_index *uf, fcm_index a)
{
  while (uf[a] != a)
    a = uf[a] = uf[uf[a]];
  return a;
}

/* Twice the area of triangle t. */
static double tri_area2(const double *x, const fcm_index *tv, fcm_index t)
{
  const double *a = x + 3 * tv[3 * t], *b = x + 3 * tv[3 * t + 1], *c = x + 3 * tv[3 * t + 2];
  double u[3], v[3], n[3];
  for (int k = 0; k < 3; k++)
    u[k] = b[k] - a[k], v[k] = c[k] - a[k];
  fcm__vec3_cross(u, v, n);
  return sqrt(fcm__vec3_dot(n, n));
}

/* The wall of edge E[0] / E[1] (the same vertices a < b, slots of triangles s and r with unit
 * normals ns, nr) into walls, when the two are not a fold: their normals, s's and r's taken
 * with orientations that agree along the edge, within 60 degrees. */
static void shared_wall(const double *x, const fcm_index *tv, const edge_key *E, const double *ns,
                        const double *nr, fcm__cut_wall *walls)
{
  const fcm_index ss = E[0].slot, sr = E[1].slot;
  /* both kept by fcm__embed_cut_tri_setup() (a sliver's normal would tilt the wall) */
  for (int k = 0; k < 2; k++) {
    const fcm_index *v = tv + 3 * (E[k].slot / 3);
    const double l2 = longest_edge2(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2]);
    if (!(tri_area2(x, tv, E[k].slot / 3) > 1e-14 * l2)) return;
  }
  /* edge k of a triangle runs from its vertex k to k + 1: consistent orientations run the
   * shared edge in opposite directions */
  const int s_fwd = tv[ss] == E[0].a, r_fwd = tv[sr] == E[1].a;
  const double sg = s_fwd != r_fwd ? 1.0 : -1.0;
  double m[3], e[3], w[3];
  if (!(fcm__vec3_dot(ns, nr) * sg >= 0.5)) return;
  for (int d = 0; d < 3; d++)
    m[d] = ns[d] + sg * nr[d];
  for (int d = 0; d < 3; d++) /* along s's edge: e x n points out of s */
    e[d] = s_fwd ? x[3 * E[0].b + d] - x[3 * E[0].a + d] : x[3 * E[0].a + d] - x[3 * E[0].b + d];
  fcm__vec3_cross(e, m, w);
  const double lw = sqrt(fcm__vec3_dot(w, w));
  if (!(lw > 0.0)) return;
  for (int d = 0; d < 3; d++) {
    walls[ss].n[d] = w[d] / lw;
    walls[sr].n[d] = -walls[ss].n[d];
  }
  walls[ss].through = s_fwd ? 1 : 2; /* through vertex a, the edge's start or end */
  walls[sr].through = r_fwd ? 1 : 2;
  walls[ss].owns = 1, walls[sr].owns = 0;
}

fcm_status fcm__embed_cut_inner_edges(fcm_ctx *ctx, const fcm_surface *cut, unsigned char *inner,
                                      fcm_index *ref, fcm__cut_wall *walls)
{
  fcm_status st = FCM_OK;
  const fcm_index nt = fcm_surface_num_triangles(cut);
  const double *x = fcm_surface_coords(cut);
  const fcm_index *tv = fcm_surface_triangles(cut);
  edge_key *E = NULL;
  memset(inner, 0, 3 * (size_t)nt);
  memset(walls, 0, 3 * (size_t)nt * sizeof *walls);
  for (fcm_index t = 0; t < nt; t++)
    ref[t] = t;
  if (nt < 2) return FCM_OK;
  FCM_ALLOC(ctx, 3 * (size_t)nt, E);
  for (fcm_index t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) {
      const fcm_index p = tv[3 * t + k], q = tv[3 * t + (k + 1) % 3];
      E[3 * t + k] = (edge_key){FCM_MIN(p, q), FCM_MAX(p, q), 3 * t + k};
    }
  qsort(E, 3 * (size_t)nt, sizeof *E, edge_cmp);
  for (size_t i = 0; i + 1 < 3 * (size_t)nt; i++) {
    if (E[i].a != E[i + 1].a || E[i].b != E[i + 1].b) continue;
    if (i + 2 < 3 * (size_t)nt && E[i + 2].a == E[i].a && E[i + 2].b == E[i].b) continue;
    if (i > 0 && E[i - 1].a == E[i].a && E[i - 1].b == E[i].b) continue;
    const fcm_index s = E[i].slot / 3, r = E[i + 1].slot / 3;
    /* coplanar: the other triangle's far vertex on the plane of the larger triangle (whose
     * normal rounding disturbs least; a sliver's normal may be off by far more than 1e-12),
     * within 1e-12 of the longest edge; and the two far vertices on opposite sides of the
     * shared edge (not a fold) */
    const fcm_index fs = tv[3 * s + (E[i].slot % 3 + 2) % 3],
                    fr = tv[3 * r + (E[i + 1].slot % 3 + 2) % 3];
    double ns[3], nr[3], ds, dr, e[3], ps[3], pr[3], cs[3], cr[3], lmax = 0.0;
    if (!tri_plane(x, tv, s, ns, &ds) || !tri_plane(x, tv, r, nr, &dr)) continue;
    for (int k = 0; k < 3; k++) {
      e[k] = x[3 * E[i].b + k] - x[3 * E[i].a + k];
      ps[k] = x[3 * fs + k] - x[3 * E[i].a + k], pr[k] = x[3 * fr + k] - x[3 * E[i].a + k];
    }
    fcm__vec3_cross(e, ps, cs);
    fcm__vec3_cross(e, pr, cr);
    lmax = fmax(sqrt(fcm__vec3_dot(e, e)),
                fmax(sqrt(fcm__vec3_dot(ps, ps)), sqrt(fcm__vec3_dot(pr, pr))));
    const int s_ref = fcm__vec3_dot(cs, cs) >= fcm__vec3_dot(cr, cr);
    const double *nref = s_ref ? ns : nr, dref = s_ref ? ds : dr;
    const double *far = x + 3 * (s_ref ? fr : fs);
    if (fabs(fcm__vec3_dot(nref, far) - dref) > 1e-12 * lmax ||
        !(fcm__vec3_dot(cs, nref) * fcm__vec3_dot(cr, nref) < 0.0)) {
      shared_wall(x, tv, E + i, ns, nr, walls);
      continue;
    }
    inner[E[i].slot] = inner[E[i + 1].slot] = 1;
    const fcm_index ra = tri_find(ref, s), rb = tri_find(ref, r);
    if (ra != rb) ref[FCM_MAX(ra, rb)] = FCM_MIN(ra, rb);
  }
  /* ref: union-find roots of the coplanar patches -> each patch's largest triangle */
  for (fcm_index t = 0; t < nt; t++)
    ref[t] = tri_find(ref, t);
  {
    fcm_index *best = (fcm_index *)E; /* 3 nt >= nt entries, no longer needed as keys */
    for (fcm_index t = 0; t < nt; t++)
      best[t] = -1;
    for (fcm_index t = 0; t < nt; t++) {
      const fcm_index r = ref[t];
      if (best[r] < 0 || tri_area2(x, tv, t) > tri_area2(x, tv, best[r])) best[r] = t;
    }
    for (fcm_index t = 0; t < nt; t++)
      ref[t] = best[ref[t]];
  }
cleanup:
  fcm__free(ctx, E);
  return st;
}

fcm_status fcm__embed_face_polygons(fcm_ctx *ctx, const fcm__embed_cell *cell, fcm__parts *P)
{
  fcm_status st = FCM_OK;
  const double mtol = MATCH_RTOL * cell->size;
  P->nfx = P->nfp = 0;
  for (size_t i = 0; i < P->n; i++) {
    const fcm__poly *p = P->poly + i;
    int full = -1; /* fcm__embed_part_full(), asked at the part's first face polygon */
    for (int f = 0; f < p->nf; f++) {
      fcm__plane pl;
      if (!fcm__embed_face_plane(p, f, &pl)) continue;
      for (int g = 0; g < cell->num_planes; g++) {
        const fcm__plane *cp = cell->planes + g;
        if (fcm__vec3_dot(pl.n, cp->n) < 0.5) continue;
        const size_t m = (size_t)p->fn[f], mv = m + (size_t)p->nv;
        int on = 1;
        for (size_t k = 0; k < m && on; k++)
          on = fabs(fcm__vec3_dot(cp->n, p->x[p->fv[f][k]]) - cp->d) <= mtol;
        if (!on) continue;
        if (P->nfp + 1 > P->capfp) {
          const size_t cap = P->capfp ? 2 * P->capfp : 64;
          void *q = P->fmeta;
          FCM_TRY(ctx, fcm__resize(ctx, &q, FCM__EMBED_FMETA * P->nfp, FCM__EMBED_FMETA * cap,
                                   sizeof(int)));
          P->fmeta = q;
          P->capfp = cap;
        }
        if (P->nfx + mv > P->capfx) {
          size_t cap = P->capfx ? 2 * P->capfx : 256;
          while (cap < P->nfx + mv)
            cap *= 2;
          void *q = P->fx;
          FCM_TRY(ctx, fcm__resize(ctx, &q, 3 * P->nfx, 3 * cap, sizeof(double)));
          P->fx = q;
          P->capfx = cap;
        }
        fcm__embed_face_coords(p, f, P->fx + 3 * P->nfx);
        memcpy(P->fx + 3 * (P->nfx + m), p->x[0], 3 * (size_t)p->nv * sizeof(double));
        int *meta = P->fmeta + FCM__EMBED_FMETA * P->nfp;
        meta[0] = g;
        meta[1] = P->piece[i];
        meta[2] = (int)m;
        meta[3] = p->nv;
        if (P->mat && P->piece[i] >= 0 && full < 0) full = fcm__embed_part_full(P, i);
        meta[4] =
            P->mat && P->piece[i] >= 0 && fcm__embed_part_face_deep(P, i, full, cp->n, cell->size);
        P->nfp++;
        P->nfx += mv;
        break;
      }
    }
  }
cleanup:
  return st;
}

fcm_status fcm__embed_tris_fan(fcm_ctx *ctx, fcm__tribuf *b, const double *x, int m)
{
  fcm_status st = FCM_OK;
  if (m < 3) return FCM_OK;
  if (b->n + m - 2 > b->cap) {
    const int cap = FCM_MAX(2 * b->cap, b->n + m - 2 + 16);
    void *v = b->t;
    FCM_TRY(ctx, fcm__resize(ctx, &v, 9 * (size_t)b->n, 9 * (size_t)cap, sizeof(double)));
    b->t = v;
    b->cap = cap;
  }
  for (int k = 1; k + 1 < m; k++, b->n++) {
    double *t = b->t + 9 * (size_t)b->n;
    memcpy(t, x, 3 * sizeof *t);
    memcpy(t + 3, x + 3 * k, 3 * sizeof *t);
    memcpy(t + 6, x + 3 * (k + 1), 3 * sizeof *t);
  }
cleanup:
  return st;
}

fcm_status fcm__embed_cut_faces(fcm_ctx *ctx, const fcm__embed_cell *cell, const fcm__cut_tri *tris,
                                const fcm__parts *P, int piece, double **tri, int *ntri)
{
  fcm_status st = FCM_OK;
  const double mtol = MATCH_RTOL * cell->size;
  double x[3 * FCM__POLY_MAX_FV];
  fcm__tribuf b = {NULL, 0, 0};
  for (size_t i = 0; i < P->n; i++) {
    if (P->piece[i] != piece) continue;
    const fcm__poly *q = P->poly + i;
    /* a part the body does not fill may reach beyond it: its faces' part inside the body */
    const int clip = P->mat && !fcm__embed_part_full(P, i);
    for (int f = 0; f < q->nf; f++) {
      const int m = fcm__embed_face_coords(q, f, x);
      if (!fcm__embed_on_cut(tris, P->tcand.ids, P->tcand.n, x, m, mtol)) continue;
      if (clip)
        FCM_TRY(ctx, fcm__material_face_inside(ctx, P->mat, cell, x, m, &b));
      else
        FCM_TRY(ctx, fcm__embed_tris_fan(ctx, &b, x, m)); /* the face's orientation (outward) */
    }
  }
  *tri = b.t, *ntri = b.n;
  b.t = NULL;
cleanup:
  fcm__free(ctx, b.t);
  return st;
}
