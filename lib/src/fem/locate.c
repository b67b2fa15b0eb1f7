/* Locating physical points in the active cells of a space and evaluating the
 * discrete field there; points outside every active cell (an embedded surface in
 * a dropped cell) are extrapolated from the nearest active cell. */
#include "fem/fem_impl.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Whether xi lies in the reference element, with tolerance tol. */
static int inside_reference(fcm_shape shape, const double xi[3], double tol)
{
  if (shape == FCM_SHAPE_TET)
    return xi[0] >= -tol && xi[1] >= -tol && xi[2] >= -tol && xi[0] + xi[1] + xi[2] <= 1 + tol;
  return fabs(xi[0]) <= 1 + tol && fabs(xi[1]) <= 1 + tol && fabs(xi[2]) <= 1 + tol;
}

enum { MAX_CANDIDATES = 256 };

/* The cells a locate searches: the items of a tree over their boxes (the bounds of their
 * nodes), item k cell tree_cell[k] (tree_cell NULL: cell k), kept when active is NULL or
 * active[k]; reach: the largest extent of a kept cell's box. */
typedef struct locator {
  const fcm_aabb_tree *tree;
  const fcm_index *tree_cell;
  const unsigned char *active;
  double reach;
} locator;

/* The kept items whose boxes overlap [lo, hi], ascending: into `ids` (MAX_CANDIDATES entries)
 * when the tree's answer fits, else into *many (allocated here, released by the caller) by a
 * second query sized to the count; *cand points at whichever holds them. */
static fcm_status query_all(const fcm_space *s, const locator *L, const double lo[3],
                            const double hi[3], fcm_index *ids, fcm_index **many,
                            const fcm_index **cand, fcm_index *count)
{
  fcm_status st = FCM_OK;
  fcm_index *got = ids;
  FCM_TRY(s->ctx, fcm_aabb_tree_query(L->tree, lo, hi, MAX_CANDIDATES, ids, count));
  if (*count > MAX_CANDIDATES) { /* a crowded box: ids was not written; fetch them all */
    fcm_index want = *count;
    fcm__free(s->ctx, *many);
    *many = NULL;
    FCM_ALLOC(s->ctx, want, *many);
    FCM_TRY(s->ctx, fcm_aabb_tree_query(L->tree, lo, hi, want, *many, count));
    FCM_CHECK(*count == want, s->ctx, FCM_ERR_INTERNAL,
              "locate: the box query returned %lld boxes, then %lld", (long long)want,
              (long long)*count);
    got = *many;
  }
  if (L->active) { /* the kept ones, in order */
    fcm_index m = 0;
    for (fcm_index k = 0; k < *count; k++)
      if (L->active[got[k]]) got[m++] = got[k];
    *count = m;
  }
  *cand = got;
cleanup:
  return st;
}

/* Locate one point: an active cell containing it (the first in the tree's order, the same
 * on every run), else the active cell with the nearest centroid among those near it
 * (extrapolated = 1). */
static fcm_status locate_one(const fcm_space *s, const locator *L, fcm_index i, const double p[3],
                             fcm_index *ids, fcm_index *cell, double xi[3], int *extrapolated)
{
  fcm_status st = FCM_OK;
  double X[3 * FCM_ELEMENT_MAX_NODES];
  fcm_index *many = NULL;
  const fcm_index *cand = NULL;
  const fcm_element_info *info = fcm_element_get_info(s->type);
  fcm_index count = 0;
  FCM_TRY(s->ctx, query_all(s, L, p, p, ids, &many, &cand, &count));
  for (fcm_index k = 0; k < count; k++) { /* the first containing cell in the tree's order */
    fcm_index c = L->tree_cell ? L->tree_cell[cand[k]] : cand[k];
    fcm_mesh_cell_coords(s->mesh, c, X);
    if (fcm_element_inverse_map(NULL, s->type, X, p, xi) == FCM_OK &&
        inside_reference(info->shape, xi, 1e-10)) {
      *cell = c;
      *extrapolated = 0;
      goto cleanup;
    }
  }
  /* not inside any active cell: the nearest centroid within a growing box */
  for (double r = L->reach;; r *= 2.0) {
    double lo[3] = {p[0] - r, p[1] - r, p[2] - r}, hi[3] = {p[0] + r, p[1] + r, p[2] + r};
    FCM_TRY(s->ctx, query_all(s, L, lo, hi, ids, &many, &cand, &count));
    if (count == 0 && r < 1e6 * L->reach) continue;
    FCM_CHECK(count > 0, s->ctx, FCM_ERR_GEOMETRY,
              "locate: point %lld (%g, %g, %g) has no active cell within %g of it", (long long)i,
              p[0], p[1], p[2], r);
    double best = HUGE_VAL;
    *cell = -1;
    for (fcm_index k = 0; k < count; k++) {
      const double *b = L->tree->boxes + 6 * cand[k];
      double cc[3];
      for (int d = 0; d < 3; d++)
        cc[d] = 0.5 * (b[d] + b[3 + d]);
      double d = (cc[0] - p[0]) * (cc[0] - p[0]) + (cc[1] - p[1]) * (cc[1] - p[1]) +
                 (cc[2] - p[2]) * (cc[2] - p[2]);
      if (d < best) best = d, *cell = L->tree_cell ? L->tree_cell[cand[k]] : cand[k];
    }
    break;
  }
  fcm_mesh_cell_coords(s->mesh, *cell, X);
  /* Newton outside a curved cell may not converge; then extrapolate with the map
   * linearized at the reference centre: xi = xi_c + J(xi_c)^{-1} (p - x(xi_c)). */
  if (fcm_element_inverse_map(NULL, s->type, X, p, xi) != FCM_OK) {
    double xc[3], J[9], d[3];
    double c0 = info->shape == FCM_SHAPE_TET ? 0.25 : 0.0, ref[3] = {c0, c0, c0};
    fcm_element_map(s->type, X, ref, xc);
    double det = fcm_element_jacobian(s->type, X, ref, J);
    FCM_CHECK(det != 0.0, s->ctx, FCM_ERR_GEOMETRY,
              "locate: point %lld: the nearest active cell %lld is degenerate", (long long)i,
              (long long)*cell);
    for (int k = 0; k < 3; k++)
      d[k] = p[k] - xc[k];
    /* Cramer's rule on J dxi = d */
    for (int k = 0; k < 3; k++) {
      double Jk[9];
      memcpy(Jk, J, sizeof Jk);
      for (int r = 0; r < 3; r++)
        Jk[3 * r + k] = d[r];
      double dk = Jk[0] * (Jk[4] * Jk[8] - Jk[5] * Jk[7]) -
                  Jk[1] * (Jk[3] * Jk[8] - Jk[5] * Jk[6]) + Jk[2] * (Jk[3] * Jk[7] - Jk[4] * Jk[6]);
      xi[k] = ref[k] + dk / det;
    }
  }
  *extrapolated = 1;
cleanup:
  fcm__free(s->ctx, many);
  return st;
}

/* Locate the n points X with L (fcm_space_locate()). */
static fcm_status locate_points(const fcm_space *s, const locator *L, fcm_index n, const double *X,
                                fcm_index *cell, double *xi, int *extrapolated)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_index *ids = NULL;
  const int nthreads = fcm_ctx_num_threads(ctx);
  FCM_ALLOC(ctx, (size_t)MAX_CANDIDATES * nthreads, ids);
  fcm__loop loop; /* an error is recorded once: the lowest failing point's */
  fcm__loop_begin(ctx, &loop);
#pragma omp parallel num_threads(nthreads)
  {
    fcm_index *my_ids = ids + (size_t)MAX_CANDIDATES * omp_get_thread_num();
#pragma omp for schedule(dynamic, 64)
    for (fcm_index i = 0; i < n; i++) {
      int ex = 0;
      if (fcm__loop_skip(&loop, i)) continue;
      fcm__loop_iter it;
      fcm__loop_enter(&loop, &it, i);
      fcm_status si = locate_one(s, L, i, X + 3 * i, my_ids, cell + i, xi + 3 * i, &ex);
      fcm__loop_leave(&loop, &it, si);
      if (si == FCM_OK && extrapolated) extrapolated[i] = ex;
    }
  }
  FCM_TRY(ctx, fcm__loop_end(&loop, NULL));
cleanup:
  fcm__free(ctx, ids);
  return st;
}

fcm_status fcm_space_locate(const fcm_space *s, fcm_index n, const double *X, fcm_index *cell,
                            double *xi, int *extrapolated)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_aabb_tree *tree = NULL;
  double *boxes = NULL;
  fcm_index *tree_cell = NULL, nact = 0;
  locator L = {NULL, NULL, NULL, 0.0};
  FCM_CHECK(n >= 0 && (n == 0 || (X && cell && xi)), ctx, FCM_ERR_ARG,
            "locate: n = %lld with NULL arrays", (long long)n);
  for (fcm_index c = 0; c < s->num_cells; c++)
    nact += s->active[c];
  FCM_ALLOC(ctx, 6 * nact, boxes);
  FCM_ALLOC(ctx, nact, tree_cell);
  {
    double Xc[3 * FCM_ELEMENT_MAX_NODES];
    fcm_index k = 0;
    for (fcm_index c = 0; c < s->num_cells; c++) {
      if (!s->active[c]) continue;
      double *b = boxes + 6 * k;
      fcm_mesh_cell_coords(s->mesh, c, Xc);
      for (int d = 0; d < 3; d++)
        b[d] = HUGE_VAL, b[3 + d] = -HUGE_VAL;
      for (int a = 0; a < s->nn; a++)
        for (int d = 0; d < 3; d++) {
          b[d] = fmin(b[d], Xc[3 * a + d]);
          b[3 + d] = fmax(b[3 + d], Xc[3 * a + d]);
        }
      for (int d = 0; d < 3; d++)
        L.reach = fmax(L.reach, b[3 + d] - b[d]);
      tree_cell[k++] = c;
    }
  }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nact, boxes, &tree));
  L.tree = tree, L.tree_cell = tree_cell;
  FCM_TRY(ctx, locate_points(s, &L, n, X, cell, xi, extrapolated));
cleanup:
  fcm_aabb_tree_destroy(&tree);
  fcm__free(ctx, boxes);
  fcm__free(ctx, tree_cell);
  return st;
}

fcm_status fcm__space_locate_in(const fcm_space *s, const fcm_aabb_tree *cells, fcm_index n,
                                const double *X, fcm_index *cell, double *xi, int *extrapolated)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  locator L = {cells, NULL, s->active, 0.0};
  FCM_CHECK(n >= 0 && (n == 0 || (X && cell && xi)), ctx, FCM_ERR_ARG,
            "locate: n = %lld with NULL arrays", (long long)n);
  FCM_CHECK(cells && cells->num_items == s->num_cells && s->nn == fcm_mesh_nodes_per_cell(s->mesh),
            ctx, FCM_ERR_ARG, "locate: the cells' tree is not one of the space's mesh cells");
  for (fcm_index c = 0; c < s->num_cells; c++) {
    if (!s->active[c]) continue;
    const double *b = cells->boxes + 6 * c;
    for (int d = 0; d < 3; d++)
      L.reach = fmax(L.reach, b[3 + d] - b[d]);
  }
  FCM_TRY(ctx, locate_points(s, &L, n, X, cell, xi, extrapolated));
cleanup:
  return st;
}

fcm_status fcm_space_interpolate(const fcm_space *s, fcm_index n, const fcm_index *cell,
                                 const double *xi, const double *u, double *values)
{
  fcm_status st = FCM_OK;
  fcm_index bad = -1;
  FCM_CHECK(n >= 0 && (n == 0 || (cell && xi && u && values)), s->ctx, FCM_ERR_ARG,
            "interpolate: n = %lld with NULL arrays", (long long)n);
#pragma omp parallel for num_threads(fcm_ctx_num_threads(s->ctx)) schedule(static)
  for (fcm_index i = 0; i < n; i++) {
    fcm_index c = cell[i];
    if (c < 0 || c >= s->num_cells || !s->active[c] || s->cell_elem[c + 1] - s->cell_elem[c] != 1) {
#pragma omp critical(fcm_interpolate)
      if (bad < 0 || i < bad) bad = i;
      continue;
    }
    double N[FCM_ELEMENT_MAX_NODES], v[3] = {0, 0, 0};
    fcm_element_eval_shape(s->type, xi + 3 * i, N);
    const fcm_index *ed = s->elem_dof + s->cell_elem[c] * s->nn;
    for (int a = 0; a < s->nn; a++) {
      const double *ua = u + ed[a];
      for (int d = 0; d < 3; d++)
        v[d] += N[a] * ua[d];
    }
    memcpy(values + 3 * i, v, sizeof v);
  }
  FCM_CHECK(bad < 0, s->ctx, FCM_ERR_ARG,
            "interpolate: point %lld names cell %lld, which is "
            "out of range, inactive or split into pieces by cuts",
            (long long)bad, (long long)cell[bad]);
cleanup:
  return st;
}

fcm_index fcm_space_point_element(const fcm_space *s, fcm_index cell, const double xi[3])
{
  if (!s || cell < 0 || cell >= s->num_cells) return -1;
  const fcm_index e0 = s->cell_elem[cell], ne = s->cell_elem[cell + 1] - e0;
  if (ne <= 1) return ne == 1 ? e0 : -1;
  /* the piece with the nearest authentic quadrature point (reference coordinates) */
  fcm_index best = e0;
  double dmin = HUGE_VAL;
  for (fcm_index e = e0; e < e0 + ne; e++) {
    int nq = 0;
    const double *pts = NULL;
    const unsigned char *fl = NULL;
    if (fcm_cell_rules_get_piece(s->rules, s->elem_piece[e], FCM_RULE_STIFFNESS, &nq, &pts, NULL,
                                 &fl) != FCM_OK)
      continue;
    for (int q = 0; q < nq; q++) {
      if (fl[q]) continue;
      const double dx = pts[3 * q] - xi[0], dy = pts[3 * q + 1] - xi[1],
                   dz = pts[3 * q + 2] - xi[2];
      const double d = dx * dx + dy * dy + dz * dz;
      if (d < dmin) dmin = d, best = e;
    }
  }
  return best;
}

/* Union-find of the elements through shared DOF copies: on return uf[e] is the smallest
 * element of e's body (uf: num_elems entries, first: num_dofs / 3 scratch). */
static void label_bodies(const fcm_space *s, fcm_index *uf, fcm_index *first)
{
  const fcm_index ncopy = s->num_dofs / 3;
  for (fcm_index e = 0; e < s->num_elems; e++)
    uf[e] = e;
  for (fcm_index k = 0; k < ncopy; k++)
    first[k] = -1;
  for (fcm_index e = 0; e < s->num_elems; e++)
    for (int a = 0; a < s->nn; a++) {
      const fcm_index k = s->elem_dof[e * s->nn + a] / 3;
      if (first[k] < 0) {
        first[k] = e;
        continue;
      }
      fcm_index x = e, y = first[k];
      while (uf[x] != x)
        x = uf[x] = uf[uf[x]];
      while (uf[y] != y)
        y = uf[y] = uf[uf[y]];
      if (x != y) uf[x > y ? x : y] = x < y ? x : y;
    }
  /* every root is the smallest element of its set: resolve in ascending order */
  for (fcm_index e = 0; e < s->num_elems; e++)
    uf[e] = uf[uf[e]];
}

fcm_index fcm_space_num_bodies(const fcm_space *s)
{
  if (!s || s->num_elems == 0) return 0;
  const fcm_index ncopy = s->num_dofs / 3;
  fcm_index *uf = malloc(sizeof *uf * (size_t)s->num_elems),
            *first = malloc(sizeof *first * (size_t)(ncopy > 0 ? ncopy : 1));
  if (!uf || !first) {
    free(uf);
    free(first);
    return -1;
  }
  label_bodies(s, uf, first);
  fcm_index count = 0;
  for (fcm_index e = 0; e < s->num_elems; e++)
    count += uf[e] == e;
  free(uf);
  free(first);
  return count;
}

fcm_status fcm__space_body_labels(const fcm_space *s, fcm_index *elem_body, fcm_index *num_bodies)
{
  fcm_status st = FCM_OK;
  fcm_index *first = NULL;
  FCM_ALLOC(s->ctx, s->num_dofs / 3 + 1, first);
  label_bodies(s, elem_body, first);
  fcm_index nb = 0;
  for (fcm_index e = 0; e < s->num_elems; e++) /* roots come first in ascending order */
    elem_body[e] = elem_body[e] == e ? nb++ : elem_body[elem_body[e]];
  *num_bodies = nb;
cleanup:
  fcm__free(s->ctx, first);
  return st;
}
