/* Triangle surface checks and repairs: edge topology (boundary, non-manifold, orientation),
 * enclosed volume, degenerate triangles, self-intersections, consistent orientation and
 * hole filling. */
#include "geom/surface_impl.h"
#include "la/vec3.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- edges */

/* One directed triangle edge a -> b of triangle t; sorted by the undirected key. */
typedef struct sedge {
  fcm_index lo, hi; /* min(a, b), max(a, b) */
  fcm_index a, b, t;
} sedge;

static int sedge_cmp(const void *x, const void *y)
{
  const sedge *e = x, *f = y;
  if (e->lo != f->lo) return e->lo < f->lo ? -1 : 1;
  if (e->hi != f->hi) return e->hi < f->hi ? -1 : 1;
  if (e->t != f->t) return e->t < f->t ? -1 : 1;
  return 0;
}

/* All 3 m directed edges sorted by undirected key (then triangle). */
static fcm_status edges_sorted(fcm_ctx *ctx, const fcm_surface *s, sedge **out)
{
  fcm_status st = FCM_OK;
  sedge *e = NULL;
  fcm_index m = s->num_triangles;
  FCM_ALLOC_RAW(ctx, 3 * (size_t)m, e);
  for (fcm_index t = 0; t < m; t++)
    for (int k = 0; k < 3; k++) {
      fcm_index a = s->tris[3 * t + k], b = s->tris[3 * t + (k + 1) % 3];
      sedge *x = &e[3 * t + k];
      x->a = a, x->b = b, x->t = t;
      x->lo = a < b ? a : b, x->hi = a < b ? b : a;
    }
  qsort(e, 3 * (size_t)m, sizeof *e, sedge_cmp);
  *out = e;
  e = NULL;
cleanup:
  fcm__free(ctx, e);
  return st;
}

/* ---------------------------------------------------------------- predicates */

/* 6 x the signed volume of (a, b, c, d). */
static double orient3(const double *a, const double *b, const double *c, const double *d)
{
  double u[3], v[3], w[3], n[3];
  fcm__vec3_sub(b, a, u), fcm__vec3_sub(c, a, v), fcm__vec3_sub(d, a, w);
  fcm__vec3_cross(u, v, n);
  return fcm__vec3_dot(n, w);
}

/* Sign with a tolerance: |x| <= eps counts as 0. */
static int sgn(double x, double eps)
{
  return x > eps ? 1 : x < -eps ? -1 : 0;
}

/* 2D orientation of (a, b, c) in the plane of the coordinates i, j. */
static double orient2(const double *a, const double *b, const double *c, int i, int j)
{
  return (b[i] - a[i]) * (c[j] - a[j]) - (b[j] - a[j]) * (c[i] - a[i]);
}

/* Do the closed segments pq and ab (coplanar, projected on i, j) meet? */
static int seg_seg2(const double *p, const double *q, const double *a, const double *b, int i,
                    int j, double eps)
{
  int d1 = sgn(orient2(a, b, p, i, j), eps), d2 = sgn(orient2(a, b, q, i, j), eps);
  int d3 = sgn(orient2(p, q, a, i, j), eps), d4 = sgn(orient2(p, q, b, i, j), eps);
  if (d1 * d2 > 0 || d3 * d4 > 0) return 0;
  if (d1 == 0 && d2 == 0) { /* collinear: overlap of the projections on the longer axis */
    int k = fabs(q[i] - p[i]) + fabs(b[i] - a[i]) >= fabs(q[j] - p[j]) + fabs(b[j] - a[j]) ? i : j;
    double s0 = fmin(p[k], q[k]), s1 = fmax(p[k], q[k]);
    double t0 = fmin(a[k], b[k]), t1 = fmax(a[k], b[k]);
    return s0 <= t1 && t0 <= s1;
  }
  return 1;
}

/* Is point p (coplanar) inside or on triangle abc, projected on i, j? */
static int point_in_tri2(const double *p, const double *a, const double *b, const double *c, int i,
                         int j, double eps)
{
  int s0 = sgn(orient2(a, b, p, i, j), eps), s1 = sgn(orient2(b, c, p, i, j), eps),
      s2 = sgn(orient2(c, a, p, i, j), eps);
  return !((s0 < 0 || s1 < 0 || s2 < 0) && (s0 > 0 || s1 > 0 || s2 > 0));
}

/* Does the closed segment pq meet the closed triangle abc? eps3 and eps2 are the
 * tolerances of the 3D and 2D orientation values. */
static int seg_tri(const double *p, const double *q, const double *a, const double *b,
                   const double *c, double eps3, double eps2)
{
  int dp = sgn(orient3(a, b, c, p), eps3), dq = sgn(orient3(a, b, c, q), eps3);
  if (dp * dq > 0) return 0;
  if (dp == 0 && dq == 0) { /* coplanar: 2D test in the plane's dominant projection */
    double u[3], v[3], n[3];
    fcm__vec3_sub(b, a, u), fcm__vec3_sub(c, a, v);
    fcm__vec3_cross(u, v, n);
    int k = fabs(n[0]) >= fabs(n[1]) ? (fabs(n[0]) >= fabs(n[2]) ? 0 : 2)
                                     : (fabs(n[1]) >= fabs(n[2]) ? 1 : 2);
    int i = (k + 1) % 3, j = (k + 2) % 3;
    return point_in_tri2(p, a, b, c, i, j, eps2) || point_in_tri2(q, a, b, c, i, j, eps2) ||
           seg_seg2(p, q, a, b, i, j, eps2) || seg_seg2(p, q, b, c, i, j, eps2) ||
           seg_seg2(p, q, c, a, i, j, eps2);
  }
  int s0 = sgn(orient3(p, q, a, b), eps3), s1 = sgn(orient3(p, q, b, c), eps3),
      s2 = sgn(orient3(p, q, c, a), eps3);
  return !((s0 < 0 || s1 < 0 || s2 < 0) && (s0 > 0 || s1 > 0 || s2 > 0));
}

/* Do triangles t and u meet other than along a shared edge or at a shared vertex? */
static int tri_tri(const fcm_surface *s, fcm_index t, fcm_index u)
{
  const fcm_index *A = s->tris + 3 * t, *B = s->tris + 3 * u;
  const double *x = s->coords;
  const double *a[3], *b[3];
  double L = 0.0;
  for (int k = 0; k < 3; k++) {
    a[k] = x + 3 * A[k], b[k] = x + 3 * B[k];
    for (int d = 0; d < 3; d++)
      L = fmax(L, fmax(fabs(a[k][d] - b[0][d]), fabs(b[k][d] - b[0][d])));
  }
  /* orientation values scale like L^3 (3D) and L^2 (2D) */
  double eps3 = 1e-12 * L * L * L, eps2 = 1e-12 * L * L;
  int sa = -1, sb = -1, shared = 0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      if (A[i] == B[j]) sa = i, sb = j, shared++;
  if (shared >= 2) {
    /* common edge: only a fold-over (the other vertices coplanar, on the same side) meets */
    int oa = 0, ob = 0;
    for (int i = 0; i < 3; i++)
      if (A[i] != B[0] && A[i] != B[1] && A[i] != B[2]) oa = i;
    for (int j = 0; j < 3; j++)
      if (B[j] != A[0] && B[j] != A[1] && B[j] != A[2]) ob = j;
    if (shared == 3) return 1; /* a duplicated triangle */
    if (sgn(orient3(a[0], a[1], a[2], b[ob]), eps3) != 0) return 0;
    /* the shared edge's vertices are the two of A other than oa */
    const double *e0 = a[(oa + 1) % 3], *e1 = a[(oa + 2) % 3];
    double g1[3], g2[3], n[3], w1[3], w2[3], c1[3], c2[3];
    fcm__vec3_sub(a[1], a[0], g1), fcm__vec3_sub(a[2], a[0], g2);
    fcm__vec3_cross(g1, g2, n);
    double d[3];
    fcm__vec3_sub(e1, e0, d);
    fcm__vec3_sub(a[oa], e0, w1), fcm__vec3_sub(b[ob], e0, w2);
    fcm__vec3_cross(d, w1, c1), fcm__vec3_cross(d, w2, c2);
    return fcm__vec3_dot(c1, n) * fcm__vec3_dot(c2, n) > 0;
  }
  if (shared == 1) {
    /* common vertex: the edge opposite it in one triangle against the other triangle */
    const double *p = a[(sa + 1) % 3], *q = a[(sa + 2) % 3];
    if (seg_tri(p, q, b[0], b[1], b[2], eps3, eps2)) return 1;
    p = b[(sb + 1) % 3], q = b[(sb + 2) % 3];
    return seg_tri(p, q, a[0], a[1], a[2], eps3, eps2);
  }
  for (int k = 0; k < 3; k++)
    if (seg_tri(a[k], a[(k + 1) % 3], b[0], b[1], b[2], eps3, eps2) ||
        seg_tri(b[k], b[(k + 1) % 3], a[0], a[1], a[2], eps3, eps2))
      return 1;
  return 0;
}

/* ---------------------------------------------------------------- the check */

fcm_surface_check_options fcm_surface_check_options_default(void)
{
  fcm_surface_check_options o = {1e-12, 1};
  return o;
}

/* Intersecting pairs with at least one triangle >= first (each pair once). */
static fcm_status find_intersections_from(const fcm_surface *s, fcm_index first,
                                          fcm_surface_report *r)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_index m = s->num_triangles, cap = 64, count = 0;
  double *boxes = NULL;
  fcm_index *ids = NULL;
  fcm_aabb_tree *tree = NULL;
  FCM_ALLOC_RAW(ctx, 6 * (size_t)m, boxes);
  for (fcm_index t = 0; t < m; t++) {
    double *bx = boxes + 6 * t;
    for (int d = 0; d < 3; d++)
      bx[d] = INFINITY, bx[3 + d] = -INFINITY;
    for (int k = 0; k < 3; k++) {
      const double *p = s->coords + 3 * s->tris[3 * t + k];
      for (int d = 0; d < 3; d++)
        bx[d] = fmin(bx[d], p[d]), bx[3 + d] = fmax(bx[3 + d], p[d]);
    }
    double L = fmax(bx[3] - bx[0], fmax(bx[4] - bx[1], bx[5] - bx[2]));
    for (int d = 0; d < 3; d++) /* widen by the predicates' tolerance */
      bx[d] -= 1e-9 * L, bx[3 + d] += 1e-9 * L;
  }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, m, boxes, &tree));
  FCM_ALLOC_RAW(ctx, (size_t)cap, ids);
  r->num_intersections = 0;
  for (fcm_index t = first; t < m; t++) {
    FCM_TRY(ctx, fcm_aabb_tree_query(tree, boxes + 6 * t, boxes + 6 * t + 3, cap, ids, &count));
    if (count > cap) {
      FCM_FREE(ctx, ids);
      cap = 2 * count;
      FCM_ALLOC_RAW(ctx, (size_t)cap, ids);
      FCM_TRY(ctx, fcm_aabb_tree_query(tree, boxes + 6 * t, boxes + 6 * t + 3, cap, ids, &count));
    }
    for (fcm_index i = 0; i < count; i++) {
      fcm_index u = ids[i];
      if (u == t || (u >= first && u < t) || !tri_tri(s, t, u)) continue;
      if (r->num_intersections < FCM_SURFACE_REPORT_MAX)
        r->intersecting[r->num_intersections][0] = t, r->intersecting[r->num_intersections][1] = u;
      r->num_intersections++;
    }
  }
cleanup:
  fcm_aabb_tree_destroy(&tree);
  FCM_FREE(ctx, ids);
  FCM_FREE(ctx, boxes);
  return st;
}

static fcm_status find_intersections(const fcm_surface *s, fcm_surface_report *r)
{
  return find_intersections_from(s, 0, r);
}

/* Number of boundary loops: the boundary edges chained (each vertex's outgoing boundary
 * edges in a list); every chain of unused edges followed to its end is one loop. */
static fcm_status count_loops(fcm_ctx *ctx, const fcm_surface *s, const sedge *e, size_t ne,
                              fcm_index *loops);

fcm_status fcm_surface_check(const fcm_surface *s, const fcm_surface_check_options *opts,
                             fcm_surface_report *r)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  sedge *e = NULL;
  fcm_surface_check_options o = opts ? *opts : fcm_surface_check_options_default();
  if (!s || !r) return FCM_ERR_ARG; /* no context to report into when s is NULL */
  memset(r, 0, sizeof *r);
  FCM_CHECK(o.degenerate_tol >= 0.0 && isfinite(o.degenerate_tol), ctx, FCM_ERR_ARG,
            "surface check: degenerate_tol = %g must be finite and >= 0", o.degenerate_tol);
  const double *x = s->coords;
  fcm_index m = s->num_triangles;
  for (fcm_index t = 0; t < m; t++) {
    const fcm_index *T = s->tris + 3 * t;
    const double *a = x + 3 * T[0], *b = x + 3 * T[1], *c = x + 3 * T[2];
    double u[3], v[3], w[3], n[3];
    fcm__vec3_sub(b, a, u), fcm__vec3_sub(c, a, v), fcm__vec3_sub(c, b, w);
    fcm__vec3_cross(u, v, n);
    double twice = sqrt(fcm__vec3_dot(n, n));
    double L2 = fmax(fcm__vec3_dot(u, u), fmax(fcm__vec3_dot(v, v), fcm__vec3_dot(w, w)));
    r->area += 0.5 * twice;
    /* det(a, b, c) / 6, summed: the divergence theorem with the field x / 3 */
    r->signed_volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                         a[2] * (b[0] * c[1] - b[1] * c[0])) /
                        6.0;
    if (T[0] == T[1] || T[1] == T[2] || T[0] == T[2] || twice <= o.degenerate_tol * L2) {
      if (r->num_degenerate < FCM_SURFACE_REPORT_MAX) r->degenerate[r->num_degenerate] = t;
      r->num_degenerate++;
    }
  }
  FCM_TRY(ctx, edges_sorted(ctx, s, &e));
  size_t ne = 3 * (size_t)m;
  for (size_t i = 0; i < ne;) {
    size_t j = i + 1;
    while (j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi)
      j++;
    fcm_index pair[2] = {e[i].lo, e[i].hi};
    if (j - i == 1) {
      if (r->num_boundary_edges < FCM_SURFACE_REPORT_MAX)
        memcpy(r->boundary_edges[r->num_boundary_edges], pair, sizeof pair);
      r->num_boundary_edges++;
    } else if (j - i > 2) {
      if (r->num_nonmanifold_edges < FCM_SURFACE_REPORT_MAX)
        memcpy(r->nonmanifold_edges[r->num_nonmanifold_edges], pair, sizeof pair);
      r->num_nonmanifold_edges++;
    } else if (e[i].a == e[i + 1].a && e[i].lo != e[i].hi) {
      if (r->num_inconsistent_edges < FCM_SURFACE_REPORT_MAX)
        memcpy(r->inconsistent_edges[r->num_inconsistent_edges], pair, sizeof pair);
      r->num_inconsistent_edges++;
    }
    i = j;
  }
  if (r->num_boundary_edges > 0) FCM_TRY(ctx, count_loops(ctx, s, e, ne, &r->num_boundary_loops));
  r->num_intersections = -1;
  if (o.self_intersections) FCM_TRY(ctx, find_intersections(s, r));
cleanup:
  FCM_FREE(ctx, e);
  return st;
}

/* ---------------------------------------------------------------- boundary loops */

/* The boundary edges, each reversed (b -> a for the triangle's a -> b: the direction a
 * filling triangle runs it), with per-vertex adjacency in CSR form. */
typedef struct bloops {
  fcm_index n;      /* boundary edges */
  fcm_index *from;  /* n */
  fcm_index *to;    /* n */
  fcm_index *start; /* num_vertices + 1: edges leaving each vertex, in order */
  fcm_index *edge;  /* n: edge ids grouped by `from` */
  fcm_index *tri;   /* n: the triangle the edge borders */
  unsigned char *used;
} bloops;

static void bloops_free(fcm_ctx *ctx, bloops *L)
{
  FCM_FREE(ctx, L->from);
  FCM_FREE(ctx, L->to);
  FCM_FREE(ctx, L->start);
  FCM_FREE(ctx, L->edge);
  FCM_FREE(ctx, L->tri);
  FCM_FREE(ctx, L->used);
}

static fcm_status bloops_build(fcm_ctx *ctx, const fcm_surface *s, const sedge *e, size_t ne,
                               bloops *L)
{
  fcm_status st = FCM_OK;
  fcm_index n = 0, nv = s->num_vertices, *cur = NULL;
  memset(L, 0, sizeof *L);
  for (size_t i = 0; i < ne;) {
    size_t j = i + 1;
    while (j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi)
      j++;
    if (j - i == 1 && e[i].lo != e[i].hi) n++;
    i = j;
  }
  L->n = n;
  FCM_ALLOC_RAW(ctx, (size_t)n + 1, L->from);
  FCM_ALLOC_RAW(ctx, (size_t)n + 1, L->to);
  FCM_ALLOC_RAW(ctx, (size_t)n + 1, L->edge);
  FCM_ALLOC_RAW(ctx, (size_t)n + 1, L->tri);
  FCM_ALLOC(ctx, (size_t)n + 1, L->used);
  FCM_ALLOC(ctx, (size_t)nv + 1, L->start);
  n = 0;
  for (size_t i = 0; i < ne;) {
    size_t j = i + 1;
    while (j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi)
      j++;
    if (j - i == 1 && e[i].lo != e[i].hi) {
      L->from[n] = e[i].b, L->to[n] = e[i].a, L->tri[n] = e[i].t;
      L->start[e[i].b + 1]++;
      n++;
    }
    i = j;
  }
  for (fcm_index v = 0; v < nv; v++)
    L->start[v + 1] += L->start[v];
  FCM_ALLOC_RAW(ctx, (size_t)nv + 1, cur);
  memcpy(cur, L->start, (size_t)nv * sizeof *cur);
  for (fcm_index k = 0; k < n; k++)
    L->edge[cur[L->from[k]]++] = k;
cleanup:
  FCM_FREE(ctx, cur);
  return st;
}

/* Follow unused edges from edge k until back at its start; the loop's edge ids go to
 * out (capacity n), *len their count. Returns 0 when the chain ends without closing. */
static int trace_loop(bloops *L, fcm_index k, fcm_index *out, fcm_index *len)
{
  fcm_index first = L->from[k], cnt = 0, cur = k;
  for (;;) {
    L->used[cur] = 1;
    out[cnt++] = cur;
    fcm_index v = L->to[cur];
    if (v == first) break;
    fcm_index next = -1;
    for (fcm_index i = L->start[v]; i < L->start[v + 1]; i++)
      if (!L->used[L->edge[i]]) {
        next = L->edge[i];
        break;
      }
    if (next < 0) {
      *len = cnt;
      return 0;
    }
    cur = next;
  }
  *len = cnt;
  return 1;
}

static fcm_status count_loops(fcm_ctx *ctx, const fcm_surface *s, const sedge *e, size_t ne,
                              fcm_index *loops)
{
  fcm_status st = FCM_OK;
  bloops L;
  fcm_index *buf = NULL, len = 0;
  *loops = 0;
  FCM_TRY(ctx, bloops_build(ctx, s, e, ne, &L));
  FCM_ALLOC_RAW(ctx, (size_t)L.n + 1, buf);
  for (fcm_index k = 0; k < L.n; k++)
    if (!L.used[k]) {
      trace_loop(&L, k, buf, &len);
      (*loops)++;
    }
cleanup:
  FCM_FREE(ctx, buf);
  bloops_free(ctx, &L);
  return st;
}

/* ---------------------------------------------------------------- the error */

fcm_status fcm_surface_report_check(const fcm_surface *s, const char *what,
                                    const fcm_surface_report *r)
{
  if (!s || !r) return FCM_ERR_ARG;
  fcm_ctx *ctx = s->ctx;
  const double *x = s->coords;
  const char *w = what ? what : "surface";
  char loc[512];
  size_t n = 0;
  loc[0] = '\0';
#define LOC_EDGES(list, count)                                                                     \
  for (fcm_index i_ = 0; i_ < (count) && i_ < FCM_SURFACE_REPORT_MAX && n < sizeof loc - 1;        \
       i_++) {                                                                                     \
    fcm_index a_ = (list)[i_][0], b_ = (list)[i_][1];                                              \
    int k_ = snprintf(loc + n, sizeof loc - n, "%s(%lld, %lld) at (%g, %g, %g)-(%g, %g, %g)",      \
                      i_ ? ", " : "", (long long)a_, (long long)b_, x[3 * a_], x[3 * a_ + 1],      \
                      x[3 * a_ + 2], x[3 * b_], x[3 * b_ + 1], x[3 * b_ + 2]);                     \
    if (k_ > 0) n += (size_t)k_;                                                                   \
    if (n >= sizeof loc) n = sizeof loc - 1;                                                       \
  }
  if (r->num_boundary_edges > 0) {
    LOC_EDGES(r->boundary_edges, r->num_boundary_edges);
    return fcm__error(ctx, FCM_ERR_GEOMETRY, __FILE__, __LINE__, __func__,
                      "%s: the surface is not closed: %lld boundary edges in %lld loop(s) "
                      "(first: vertex ids %s; ids count from 0 in the file's order); close small "
                      "holes with fill_holes",
                      w, (long long)r->num_boundary_edges, (long long)r->num_boundary_loops, loc);
  }
  if (r->num_nonmanifold_edges > 0) {
    LOC_EDGES(r->nonmanifold_edges, r->num_nonmanifold_edges);
    return fcm__error(ctx, FCM_ERR_GEOMETRY, __FILE__, __LINE__, __func__,
                      "%s: the surface is not manifold: %lld edges shared by 3 or more triangles "
                      "(first: vertex ids %s; ids count from 0 in the file's order)",
                      w, (long long)r->num_nonmanifold_edges, loc);
  }
  if (r->num_degenerate > 0) {
    fcm_index t = r->degenerate[0];
    const fcm_index *T = s->tris + 3 * t;
    return fcm__error(ctx, FCM_ERR_GEOMETRY, __FILE__, __LINE__, __func__,
                      "%s: %lld degenerate (zero-area) triangle(s); the first is triangle %lld "
                      "(ids count from 0 in the file's order) with vertices %lld (%g, %g, %g), "
                      "%lld (%g, %g, %g), %lld (%g, %g, %g)",
                      w, (long long)r->num_degenerate, (long long)t, (long long)T[0], x[3 * T[0]],
                      x[3 * T[0] + 1], x[3 * T[0] + 2], (long long)T[1], x[3 * T[1]],
                      x[3 * T[1] + 1], x[3 * T[1] + 2], (long long)T[2], x[3 * T[2]],
                      x[3 * T[2] + 1], x[3 * T[2] + 2]);
  }
  if (r->num_inconsistent_edges > 0) {
    LOC_EDGES(r->inconsistent_edges, r->num_inconsistent_edges);
    return fcm__error(ctx, FCM_ERR_GEOMETRY, __FILE__, __LINE__, __func__,
                      "%s: inconsistent orientation: %lld edges are run the same way by both "
                      "their triangles (first: vertex ids %s; ids count from 0 in the file's "
                      "order); reorient with "
                      "fcm_surface_create_oriented()",
                      w, (long long)r->num_inconsistent_edges, loc);
  }
  if (r->num_intersections > 0) {
    fcm_index t = r->intersecting[0][0], u = r->intersecting[0][1];
    const double *p = x + 3 * s->tris[3 * t], *q = x + 3 * s->tris[3 * u];
    return fcm__error(
        ctx, FCM_ERR_GEOMETRY, __FILE__, __LINE__, __func__,
        "%s: the surface intersects itself: %lld triangle pair(s), the first "
        "triangles %lld (vertex (%g, %g, %g)) and %lld (vertex (%g, %g, %g)); ids count "
        "from 0 in the file's order",
        w, (long long)r->num_intersections, (long long)t, p[0], p[1], p[2], (long long)u, q[0],
        q[1], q[2]);
  }
  if (!(r->signed_volume > 0.0))
    return fcm__error(ctx, FCM_ERR_GEOMETRY, __FILE__, __LINE__, __func__,
                      "%s: the enclosed (signed) volume is %g, not positive: the normals point "
                      "inward; reorient with fcm_surface_create_oriented()",
                      w, r->signed_volume);
#undef LOC_EDGES
  return FCM_OK;
}

/* ---------------------------------------------------------------- orientation */

fcm_status fcm_surface_create_oriented(fcm_ctx *ctx, const fcm_surface *src, fcm_surface **surf,
                                       fcm_index *flipped)
{
  fcm_status st = FCM_OK;
  sedge *e = NULL;
  fcm_index *tris = NULL, *nbr = NULL, *queue = NULL;
  unsigned char *flip = NULL, *seen = NULL;
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "surface orient: output pointer is NULL");
  *surf = NULL;
  if (flipped) *flipped = 0;
  FCM_CHECK(ctx && src, ctx, FCM_ERR_ARG, "surface orient: NULL argument (ctx and src)");
  fcm_index m = src->num_triangles;
  size_t ne = 3 * (size_t)m;
  FCM_TRY(ctx, edges_sorted(ctx, src, &e));
  /* nbr[3 t + k]: the triangle across edge k of t when that edge is manifold, else -1 */
  FCM_ALLOC_RAW(ctx, ne, nbr);
  for (size_t i = 0; i < ne; i++)
    nbr[i] = -1;
  for (size_t i = 0; i < ne;) {
    size_t j = i + 1;
    while (j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi)
      j++;
    if (j - i == 2 && e[i].t != e[i + 1].t) {
      for (int h = 0; h < 2; h++) {
        const sedge *me = &e[i + (size_t)h], *other = &e[i + 1 - (size_t)h];
        const fcm_index *T = src->tris + 3 * me->t;
        int k = T[0] == me->a ? 0 : T[1] == me->a ? 1 : 2;
        nbr[3 * me->t + k] = other->t;
      }
    }
    i = j;
  }
  FCM_ALLOC(ctx, (size_t)m, flip);
  FCM_ALLOC(ctx, (size_t)m, seen);
  FCM_ALLOC_RAW(ctx, (size_t)m, queue);
  for (fcm_index t0 = 0; t0 < m; t0++) {
    if (seen[t0]) continue;
    fcm_index head = 0, tail = 0;
    queue[tail++] = t0;
    seen[t0] = 1;
    while (head < tail) {
      fcm_index t = queue[head++];
      const fcm_index *T = src->tris + 3 * t;
      for (int k = 0; k < 3; k++) {
        fcm_index u = nbr[3 * t + k];
        if (u < 0 || seen[u]) continue;
        /* t (as oriented: flip[t]) runs a -> b; u must run b -> a */
        fcm_index a = T[k], b = T[(k + 1) % 3];
        const fcm_index *U = src->tris + 3 * u;
        int ka = U[0] == a ? 0 : U[1] == a ? 1 : 2;
        int same = U[(ka + 1) % 3] == b; /* u runs a -> b too */
        flip[u] = (unsigned char)(flip[t] ^ same);
        seen[u] = 1;
        queue[tail++] = u;
      }
    }
  }
  FCM_ALLOC_RAW(ctx, ne, tris);
  double vol = 0.0;
  for (fcm_index t = 0; t < m; t++) {
    fcm_index *T = tris + 3 * t;
    memcpy(T, src->tris + 3 * t, 3 * sizeof *T);
    if (flip[t]) {
      fcm_index tmp = T[1];
      T[1] = T[2], T[2] = tmp;
    }
    const double *a = src->coords + 3 * T[0], *b = src->coords + 3 * T[1],
                 *c = src->coords + 3 * T[2];
    double n[3];
    fcm__vec3_cross(b, c, n);
    vol += fcm__vec3_dot(a, n);
  }
  fcm_index nflip = 0;
  for (fcm_index t = 0; t < m; t++) {
    if (vol < 0.0) {
      fcm_index tmp = tris[3 * t + 1];
      tris[3 * t + 1] = tris[3 * t + 2], tris[3 * t + 2] = tmp;
    }
    nflip += (flip[t] != 0) != (vol < 0.0);
  }
  FCM_TRY(ctx, fcm_surface_create(ctx, src->num_vertices, src->coords, m, tris, surf));
  if (flipped) *flipped = nflip;
cleanup:
  FCM_FREE(ctx, e);
  FCM_FREE(ctx, tris);
  FCM_FREE(ctx, nbr);
  FCM_FREE(ctx, queue);
  FCM_FREE(ctx, flip);
  FCM_FREE(ctx, seen);
  return st;
}

/* ---------------------------------------------------------------- hole filling */

fcm_surface_fill_options fcm_surface_fill_options_default(void)
{
  fcm_surface_fill_options o = {0, 0.0};
  return o;
}

static double tri_area(const double *a, const double *b, const double *c)
{
  double u[3], v[3], n[3];
  fcm__vec3_sub(b, a, u), fcm__vec3_sub(c, a, v);
  fcm__vec3_cross(u, v, n);
  return 0.5 * sqrt(fcm__vec3_dot(n, n));
}

/* Loops up to this size are triangulated by the minimum-area dynamic programme (O(n^3)
 * time, O(n^2) memory); larger ones by a fan around their centroid. */
#define FILL_DP_MAX 400

/* Minimum-area triangulation of the polygon v[0..n) (Liepa 2003, "Filling holes in
 * meshes", with the area weight only): W[i][j] = min_k W[i][k] + W[k][j] + area(i, k, j);
 * the triangles (v_i, v_k, v_j), i < k < j, run the loop's direction. */
static void unit_normal(const double *a, const double *b, const double *c, double *n)
{
  double u[3], v[3];
  fcm__vec3_sub(b, a, u), fcm__vec3_sub(c, a, v);
  fcm__vec3_cross(u, v, n);
  double l = sqrt(fcm__vec3_dot(n, n));
  if (l > 0.0) n[0] /= l, n[1] /= l, n[2] /= l;
}

/* Weight of the new triangle (v_i, v_k, v_j): its area, times 1 + 10 (1 - cos) for each
 * side on the loop, cos the cosine of the angle between its normal and that of the surface
 * triangle across the side (a fold back into the surface costs up to 21 times its area). */
static double fill_weight(const double *x, const fcm_index *T, const fcm_index *v,
                          const fcm_index *nb, fcm_index n, fcm_index i, fcm_index k, fcm_index j,
                          double fold)
{
  const double *a = x + 3 * v[i], *b = x + 3 * v[k], *c = x + 3 * v[j];
  double w = tri_area(a, b, c), nn[3], no[3], f = 1.0;
  unit_normal(a, b, c, nn);
  fcm_index sides[3] = {k == i + 1 ? i : -1, j == k + 1 ? k : -1, (i == 0 && j == n - 1) ? j : -1};
  for (int q = 0; q < 3; q++) {
    if (sides[q] < 0) continue;
    const fcm_index *t = T + 3 * nb[sides[q]];
    unit_normal(x + 3 * t[0], x + 3 * t[1], x + 3 * t[2], no);
    f += fold * (1.0 - fcm__vec3_dot(nn, no));
  }
  return w * f;
}

static fcm_status fill_min_area(fcm__sbuild *B, const double *x, const fcm_index *T,
                                const fcm_index *v, const fcm_index *nb, fcm_index n, double fold,
                                double *area)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = B->ctx;
  double *W = NULL;
  fcm_index *K = NULL, *stack = NULL;
  size_t nn = (size_t)n * (size_t)n;
  FCM_ALLOC(ctx, nn, W);
  FCM_ALLOC(ctx, nn, K);
  FCM_ALLOC_RAW(ctx, 2 * (size_t)n, stack);
  for (fcm_index len = 2; len < n; len++)
    for (fcm_index i = 0; i + len < n; i++) {
      fcm_index j = i + len, best = -1;
      double wbest = INFINITY;
      for (fcm_index k = i + 1; k < j; k++) {
        double w = W[(size_t)i * (size_t)n + (size_t)k] + W[(size_t)k * (size_t)n + (size_t)j] +
                   fill_weight(x, T, v, nb, n, i, k, j, fold);
        if (w < wbest) wbest = w, best = k;
      }
      W[(size_t)i * (size_t)n + (size_t)j] = wbest;
      K[(size_t)i * (size_t)n + (size_t)j] = best;
    }
  *area = 0.0;
  fcm_index top = 0;
  stack[top++] = 0, stack[top++] = n - 1;
  while (top > 0) {
    fcm_index j = stack[--top], i = stack[--top];
    if (j - i < 2) continue;
    fcm_index k = K[(size_t)i * (size_t)n + (size_t)j];
    FCM_TRY(ctx, fcm__sbuild_triangle(B, v[i], v[k], v[j]));
    *area += tri_area(x + 3 * v[i], x + 3 * v[k], x + 3 * v[j]);
    stack[top++] = i, stack[top++] = k;
    stack[top++] = k, stack[top++] = j;
  }
cleanup:
  FCM_FREE(ctx, W);
  FCM_FREE(ctx, K);
  FCM_FREE(ctx, stack);
  return st;
}

fcm_status fcm_surface_create_filled(fcm_ctx *ctx, const fcm_surface *src,
                                     const fcm_surface_fill_options *opts, fcm_surface **surf,
                                     fcm_surface_fill_info *info)
{
  fcm_status st = FCM_OK;
  sedge *e = NULL;
  bloops L = {0};
  fcm_index *loop = NULL, *verts = NULL, *nbtri = NULL;
  fcm__sbuild B = {0};
  fcm_surface_fill_info I;
  memset(&I, 0, sizeof I);
  FCM_CHECK(surf, ctx, FCM_ERR_ARG, "surface fill_holes: output pointer is NULL");
  *surf = NULL;
  if (info) memset(info, 0, sizeof *info);
  FCM_CHECK(ctx && src, ctx, FCM_ERR_ARG, "surface fill_holes: NULL argument (ctx and src)");
  fcm_surface_fill_options o = opts ? *opts : fcm_surface_fill_options_default();
  FCM_CHECK(o.max_edges >= 0 && o.max_perimeter >= 0.0 && isfinite(o.max_perimeter), ctx,
            FCM_ERR_ARG,
            "surface fill_holes: max_edges = %lld and max_perimeter = %g must be >= 0 (0: any)",
            (long long)o.max_edges, o.max_perimeter);
  B.ctx = ctx;
  for (fcm_index v = 0; v < src->num_vertices; v++)
    FCM_TRY(ctx, fcm__sbuild_vertex(&B, src->coords + 3 * v));
  for (fcm_index t = 0; t < src->num_triangles; t++)
    FCM_TRY(ctx,
            fcm__sbuild_triangle(&B, src->tris[3 * t], src->tris[3 * t + 1], src->tris[3 * t + 2]));
  FCM_TRY(ctx, edges_sorted(ctx, src, &e));
  FCM_TRY(ctx, bloops_build(ctx, src, e, 3 * (size_t)src->num_triangles, &L));
  FCM_ALLOC_RAW(ctx, (size_t)L.n + 1, loop);
  FCM_ALLOC_RAW(ctx, (size_t)L.n + 1, verts);
  FCM_ALLOC_RAW(ctx, (size_t)L.n + 1, nbtri);
  for (fcm_index k = 0; k < L.n; k++) {
    if (L.used[k]) continue;
    fcm_index len = 0;
    int closed = trace_loop(&L, k, loop, &len);
    I.num_loops++;
    double perim = 0.0, c[3] = {0, 0, 0};
    for (fcm_index i = 0; i < len; i++) {
      const double *p = src->coords + 3 * L.from[loop[i]], *q = src->coords + 3 * L.to[loop[i]];
      double d[3];
      fcm__vec3_sub(q, p, d);
      perim += sqrt(fcm__vec3_dot(d, d));
      for (int j = 0; j < 3; j++)
        c[j] += p[j] / (double)len;
    }
    int fill = closed && len >= 3 && (o.max_edges == 0 || len <= o.max_edges) &&
               (o.max_perimeter == 0.0 || perim <= o.max_perimeter);
    if (!fill) {
      if (len > I.largest_left) I.largest_left = len;
      continue;
    }
    /* candidates: minimum area, area with a fold penalty, fan; the first whose triangles
     * meet no other triangle is kept, else the one with the fewest intersections */
    double area = 0.0;
    size_t nv0 = B.nv, nt0 = B.nt;
    fcm_index best = -1, best_count = -1;
    for (int pass = 0; pass < 2 && best_count != 0; pass++)
      for (int method = 0; method < 3; method++) {
        if (pass == 1 && method != best) continue;
        if (method < 2 && len > FILL_DP_MAX) continue;
        B.nv = nv0, B.nt = nt0, area = 0.0;
        if (method < 2) {
          for (fcm_index i = 0; i < len; i++)
            verts[i] = L.from[loop[i]], nbtri[i] = L.tri[loop[i]];
          FCM_TRY(ctx, fill_min_area(&B, src->coords, src->tris, verts, nbtri, len,
                                     method == 0 ? 0.0 : 3.0, &area));
        } else {
          fcm_index cv = (fcm_index)B.nv;
          FCM_TRY(ctx, fcm__sbuild_vertex(&B, c));
          for (fcm_index i = 0; i < len; i++) {
            fcm_index a = L.from[loop[i]], b = L.to[loop[i]];
            FCM_TRY(ctx, fcm__sbuild_triangle(&B, a, b, cv));
            area += tri_area(src->coords + 3 * a, src->coords + 3 * b, c);
          }
        }
        if (pass == 1) break;
        struct fcm_surface view = {ctx, (fcm_index)B.nv, (fcm_index)B.nt, B.x, B.t, {0}, {0}};
        fcm_surface_report rep;
        FCM_TRY(ctx, find_intersections_from(&view, (fcm_index)nt0, &rep));
        if (best < 0 || rep.num_intersections < best_count)
          best = method, best_count = rep.num_intersections;
        if (best_count == 0) break;
      }
    I.triangles_added += (fcm_index)(B.nt - nt0);
    I.vertices_added += (fcm_index)(B.nv - nv0);
    if (I.num_filled < FCM_SURFACE_FILL_MAX_LOOPS)
      I.loop_edges[I.num_filled] = len, I.loop_area[I.num_filled] = area;
    I.num_filled++;
    I.area_added += area;
  }
  FCM_TRY(ctx, fcm_surface_create(ctx, (fcm_index)B.nv, B.x, (fcm_index)B.nt, B.t, surf));
  if (info) *info = I;
cleanup:
  FCM_FREE(ctx, e);
  FCM_FREE(ctx, loop);
  FCM_FREE(ctx, verts);
  FCM_FREE(ctx, nbtri);
  bloops_free(ctx, &L);
  fcm__sbuild_free(&B);
  return st;
}
