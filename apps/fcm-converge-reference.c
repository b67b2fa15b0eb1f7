/* fcm-converge: the reference solution of the reference problem, boundary-conforming
 * Tet10 on the geometry's own tets (optionally refined by edge midpoints), so that it lives
 * on exactly the polyhedron the FCM runs embed; and the point location in tets (an AABB
 * tree over tet boxes, barycentric test) that both the reference evaluation and the
 * staircase classification of fcm-converge-study.c and fcm-converge-run.c use. It is
 * built once per study and evaluated at every error quadrature point of every run. */
#include "fcm-converge-study-impl.h"

#include <fcm/quad.h>
#include <fcm/sim.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---------------------------------------------------------------- small helpers */

static double det3(const double J[9])
{
  return J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) +
         J[2] * (J[3] * J[7] - J[4] * J[6]);
}

/* Ji = J^{-1}; returns det J. */
double cv_inv3(const double J[9], double Ji[9])
{
  const double d = det3(J);
  Ji[0] = (J[4] * J[8] - J[5] * J[7]) / d;
  Ji[1] = (J[2] * J[7] - J[1] * J[8]) / d;
  Ji[2] = (J[1] * J[5] - J[2] * J[4]) / d;
  Ji[3] = (J[5] * J[6] - J[3] * J[8]) / d;
  Ji[4] = (J[0] * J[8] - J[2] * J[6]) / d;
  Ji[5] = (J[2] * J[3] - J[0] * J[5]) / d;
  Ji[6] = (J[3] * J[7] - J[4] * J[6]) / d;
  Ji[7] = (J[1] * J[6] - J[0] * J[7]) / d;
  Ji[8] = (J[0] * J[4] - J[1] * J[3]) / d;
  return d;
}

/* ---------------------------------------------------------------- point location in tets */

/* Barycentric coordinates of x in the tet (a, b, c, d); returns the smallest. */
static double tet_bary(const double *a, const double *b, const double *c, const double *d,
                       const double x[3], double l[4])
{
  double e1[3], e2[3], e3[3], r[3], J[9], Ji[9];
  for (int k = 0; k < 3; k++)
    e1[k] = b[k] - a[k], e2[k] = c[k] - a[k], e3[k] = d[k] - a[k];
  for (int k = 0; k < 3; k++)
    J[3 * k] = e1[k], J[3 * k + 1] = e2[k], J[3 * k + 2] = e3[k];
  if (!(fabs(cv_inv3(J, Ji)) > 0.0)) return -HUGE_VAL;
  for (int k = 0; k < 3; k++)
    r[k] = x[k] - a[k];
  for (int k = 0; k < 3; k++)
    l[k + 1] = Ji[3 * k] * r[0] + Ji[3 * k + 1] * r[1] + Ji[3 * k + 2] * r[2];
  l[0] = 1.0 - l[1] - l[2] - l[3];
  double m = l[0];
  for (int k = 1; k < 4; k++)
    m = fmin(m, l[k]);
  return m;
}

fcm_status cv_tet_index_create(fcm_ctx *ctx, const double *coords, const fcm_index *cells,
                               int stride, fcm_index n, tet_index *ti)
{
  fcm_status st = FCM_OK;
  double *boxes = malloc(sizeof *boxes * 6 * (size_t)(n > 0 ? n : 1));
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  ti->coords = coords, ti->cells = cells, ti->stride = stride, ti->n = n, ti->tree = NULL;
  if (!boxes) return FCM_ERR_ALLOC;
  for (fcm_index t = 0; t < n; t++) {
    double *bx = boxes + 6 * t;
    for (int d = 0; d < 3; d++)
      bx[d] = HUGE_VAL, bx[3 + d] = -HUGE_VAL;
    for (int a = 0; a < 4; a++)
      for (int d = 0; d < 3; d++) {
        const double v = coords[3 * cells[(size_t)stride * t + a] + d];
        bx[d] = fmin(bx[d], v), bx[3 + d] = fmax(bx[3 + d], v);
        lo[d] = fmin(lo[d], v), hi[d] = fmax(hi[d], v);
      }
  }
  ti->tol = 1e-12 * fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  st = fcm_aabb_tree_create(ctx, n, boxes, &ti->tree);
  free(boxes);
  return st;
}

/* The tet containing x (closed, tolerance 1e-10 in barycentric coordinates), else the
 * candidate with the largest smallest coordinate, else -1. */
fcm_index cv_tet_locate(const tet_index *ti, const double x[3], double l[4])
{
  fcm_index buf[64], *ids = buf, cnt = 0, best = -1;
  double lo[3], hi[3], bl = -HUGE_VAL, lt[4];
  for (int d = 0; d < 3; d++)
    lo[d] = x[d] - ti->tol, hi[d] = x[d] + ti->tol;
  if (fcm_aabb_tree_query(ti->tree, lo, hi, 64, ids, &cnt) != FCM_OK) return -1;
  if (cnt > 64) { /* the buffer's content is unspecified: query again with room for all */
    ids = malloc(sizeof *ids * (size_t)cnt);
    if (!ids || fcm_aabb_tree_query(ti->tree, lo, hi, cnt, ids, &cnt) != FCM_OK) {
      free(ids);
      return -1;
    }
  }
  for (fcm_index k = 0; k < cnt; k++) {
    const fcm_index *c = ti->cells + (size_t)ti->stride * ids[k];
    const double m = tet_bary(ti->coords + 3 * c[0], ti->coords + 3 * c[1], ti->coords + 3 * c[2],
                              ti->coords + 3 * c[3], x, lt);
    if (m > bl) {
      bl = m, best = ids[k];
      memcpy(l, lt, sizeof lt);
      if (m >= -1e-10) break;
    }
  }
  if (ids != buf) free(ids);
  return best;
}

/* ---- reference solution (boundary-conforming Tet10 on the geometry's tets) */

typedef struct edge_key {
  fcm_index a, b;
} edge_key;

static int edge_cmp(const void *p, const void *q)
{
  const edge_key *x = p, *y = q;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  return x->b < y->b ? -1 : x->b > y->b;
}

/* Unique edges of Tet4 cells (sorted); `edges` has capacity 6 n. */
static fcm_index unique_edges(fcm_index n, const fcm_index *tets, edge_key *edges)
{
  static const int E[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  fcm_index m = 0;
  for (fcm_index t = 0; t < n; t++)
    for (int e = 0; e < 6; e++) {
      fcm_index a = tets[4 * t + E[e][0]], b = tets[4 * t + E[e][1]];
      edges[m].a = a < b ? a : b, edges[m].b = a < b ? b : a, m++;
    }
  qsort(edges, (size_t)m, sizeof *edges, edge_cmp);
  fcm_index u = 0;
  for (fcm_index k = 0; k < m; k++)
    if (u == 0 || edge_cmp(edges + k, edges + u - 1)) edges[u++] = edges[k];
  return u;
}

static fcm_index edge_id(const edge_key *edges, fcm_index ne, fcm_index a, fcm_index b)
{
  edge_key k = {a < b ? a : b, a < b ? b : a};
  const edge_key *p = bsearch(&k, edges, (size_t)ne, sizeof *edges, edge_cmp);
  return p ? (fcm_index)(p - edges) : -1;
}

static double tet_volume6(const double *X, const fcm_index *t)
{
  double J[9];
  for (int k = 0; k < 3; k++)
    for (int d = 0; d < 3; d++)
      J[3 * d + k] = X[3 * t[k + 1] + d] - X[3 * t[0] + d];
  return det3(J);
}

/* Edge midpoints appended to the nodes: coordinates grow from nv to nv + ne. */
static fcm_status add_midpoints(fcm_index nt, const fcm_index *tets, fcm_index *nv, double **X,
                                edge_key **edges, fcm_index *ne)
{
  *edges = malloc(sizeof **edges * 6 * (size_t)(nt > 0 ? nt : 1));
  if (!*edges) return FCM_ERR_ALLOC;
  *ne = unique_edges(nt, tets, *edges);
  double *Y = realloc(*X, sizeof *Y * 3 * (size_t)(*nv + *ne));
  if (!Y) return FCM_ERR_ALLOC;
  *X = Y;
  for (fcm_index e = 0; e < *ne; e++)
    for (int d = 0; d < 3; d++)
      Y[3 * (*nv + e) + d] = 0.5 * (Y[3 * (*edges)[e].a + d] + Y[3 * (*edges)[e].b + d]);
  return FCM_OK;
}

/* One uniform (red) refinement: every tet into 8, positively oriented. */
static fcm_status refine_tets(fcm_index *nv, double **X, fcm_index *nt, fcm_index **tets)
{
  edge_key *edges = NULL;
  fcm_index ne = 0, n = *nt, v0 = *nv;
  fcm_status st = add_midpoints(n, *tets, nv, X, &edges, &ne);
  fcm_index *T = st == FCM_OK ? malloc(sizeof *T * 32 * (size_t)(n > 0 ? n : 1)) : NULL;
  if (st == FCM_OK && !T) st = FCM_ERR_ALLOC;
  for (fcm_index t = 0; t < n && st == FCM_OK; t++) {
    const fcm_index *c = *tets + 4 * t;
    fcm_index m[4][4];
    for (int i = 0; i < 4; i++)
      for (int j = i + 1; j < 4; j++)
        m[i][j] = m[j][i] = v0 + edge_id(edges, ne, c[i], c[j]);
    const fcm_index sub[8][4] = {
        {c[0], m[0][1], m[0][2], m[0][3]},    {m[0][1], c[1], m[1][2], m[1][3]},
        {m[0][2], m[1][2], c[2], m[2][3]},    {m[0][3], m[1][3], m[2][3], c[3]},
        {m[0][1], m[0][2], m[0][3], m[1][3]}, {m[0][1], m[0][2], m[1][2], m[1][3]},
        {m[0][2], m[0][3], m[1][3], m[2][3]}, {m[0][2], m[1][2], m[1][3], m[2][3]}};
    for (int k = 0; k < 8; k++) {
      fcm_index *o = T + 4 * (8 * t + k);
      memcpy(o, sub[k], sizeof sub[k]);
      if (tet_volume6(*X, o) < 0.0) {
        const fcm_index tmp = o[1];
        o[1] = o[2], o[2] = tmp;
      }
    }
  }
  free(edges);
  if (st == FCM_OK) {
    free(*tets);
    *tets = T;
    *nv += ne;
    *nt = 8 * n;
  } else {
    free(T);
  }
  return st;
}

/* Tet10 mesh on the Tet4 cells (VTK edge order from the element info). */
static fcm_status make_tet10(fcm_ctx *ctx, fcm_index nv, double *X, fcm_index nt,
                             const fcm_index *tets, fcm_mesh **mesh)
{
  const fcm_element_info *info = fcm_element_get_info(FCM_ELEMENT_TET10);
  edge_key *edges = NULL;
  fcm_index ne = 0, v = nv;
  double *Y = malloc(sizeof *Y * 3 * (size_t)(nv > 0 ? nv : 1));
  if (!Y) return FCM_ERR_ALLOC;
  memcpy(Y, X, sizeof *Y * 3 * (size_t)nv);
  fcm_status st = add_midpoints(nt, tets, &v, &Y, &edges, &ne);
  fcm_index *C = st == FCM_OK ? malloc(sizeof *C * 10 * (size_t)(nt > 0 ? nt : 1)) : NULL;
  if (st == FCM_OK && !C) st = FCM_ERR_ALLOC;
  for (fcm_index t = 0; t < nt && st == FCM_OK; t++) {
    const fcm_index *c = tets + 4 * t;
    fcm_index *o = C + 10 * t;
    for (int a = 0; a < 4; a++)
      o[a] = c[a];
    for (int e = 0; e < info->num_edges; e++)
      o[info->edge_nodes[e][2]] =
          nv + edge_id(edges, ne, c[info->edge_nodes[e][0]], c[info->edge_nodes[e][1]]);
  }
  if (st == FCM_OK) st = fcm_mesh_create(ctx, FCM_ELEMENT_TET10, nv + ne, Y, nt, C, mesh);
  free(edges);
  free(Y);
  free(C);
  return st;
}
fcm_status cv_reference_create(cv_study *S)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  fcm_index nv = fcm_geometry_num_nodes(S->geom), nt = fcm_geometry_num_cells(S->geom);
  double *X = malloc(sizeof *X * 3 * (size_t)nv), *f = NULL;
  fcm_index *T = malloc(sizeof *T * 4 * (size_t)nt);
  fcm_csr *K = NULL;
  const double t0 = fcm_wtime();
  if (!X || !T) {
    free(X), free(T);
    return FCM_ERR_ALLOC;
  }
  memcpy(X, fcm_geometry_coords(S->geom), sizeof *X * 3 * (size_t)nv);
  memcpy(T, fcm_geometry_cells(S->geom), sizeof *T * 4 * (size_t)nt);
  for (int r = 0; r < S->s.ref_refine && st == FCM_OK; r++)
    st = refine_tets(&nv, &X, &nt, &T);
  if (st == FCM_OK) st = make_tet10(ctx, nv, X, nt, T, &S->ref_mesh);
  free(X), free(T);
  if (st == FCM_OK) st = fcm_space_create(ctx, S->ref_mesh, NULL, &S->ref_space);
  if (st != FCM_OK) return st;
  const fcm_index n = fcm_space_num_dofs(S->ref_space);
  fprintf(stderr, CV_PROG ": reference: Tet10 on %lld tets (%d refinement(s)), %lld DOFs ...\n",
          (long long)nt, S->s.ref_refine, (long long)n);
  S->ref_u = calloc((size_t)n, sizeof *S->ref_u);
  if (!S->ref_u) return FCM_ERR_ALLOC;
  st = cv_assemble_system(S, S->ref_space, 0, NULL, &K, &f);
  if (st == FCM_OK) st = cv_direct_solve(ctx, K, f, S->ref_u);
  fcm_csr_destroy(&K);
  free(f);
  if (st == FCM_OK)
    st = cv_tet_index_create(ctx, fcm_mesh_coords(S->ref_mesh), fcm_mesh_cells(S->ref_mesh), 10,
                             fcm_mesh_num_cells(S->ref_mesh), &S->ref_tets);
  S->ref_time = fcm_wtime() - t0;
  if (st == FCM_OK) fprintf(stderr, CV_PROG ": reference solved in %.1f s\n", S->ref_time);
  return st;
}

/* Reference displacement and gradient at x; returns 0 when x lies in no reference tet. */
int cv_reference_eval(const cv_study *S, const double x[3], double u[3], double G[9])
{
  double l[4], N[10], dN[30], J[9], Ji[9], X[30];
  const fcm_index t = cv_tet_locate(&S->ref_tets, x, l);
  if (t < 0 || l[0] < -1e-6 || l[1] < -1e-6 || l[2] < -1e-6 || l[3] < -1e-6) return 0;
  const double xi[3] = {l[1], l[2], l[3]};
  fcm_mesh_cell_coords(S->ref_mesh, t, X);
  fcm_element_eval_shape(FCM_ELEMENT_TET10, xi, N);
  fcm_element_eval_grad(FCM_ELEMENT_TET10, xi, dN);
  fcm_element_jacobian(FCM_ELEMENT_TET10, X, xi, J);
  cv_inv3(J, Ji);
  const fcm_index *cn = fcm_mesh_cells(S->ref_mesh) + 10 * t;
  memset(u, 0, 3 * sizeof *u);
  memset(G, 0, 9 * sizeof *G);
  for (int a = 0; a < 10; a++) {
    const double *ua = S->ref_u + fcm_space_node_dof(S->ref_space, cn[a]);
    double g[3];
    for (int j = 0; j < 3; j++)
      g[j] = dN[3 * a] * Ji[j] + dN[3 * a + 1] * Ji[3 + j] + dN[3 * a + 2] * Ji[6 + j];
    for (int i = 0; i < 3; i++) {
      u[i] += N[a] * ua[i];
      for (int j = 0; j < 3; j++)
        G[3 * i + j] += ua[i] * g[j];
    }
  }
  return 1;
}
