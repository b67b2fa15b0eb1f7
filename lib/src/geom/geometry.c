/* Embedded geometry object: creation from arrays (validated, oriented, copied or
 * taken over), boundary triangles, affine transformation, accessors, view. */
#include "geom/geom_impl.h"
#include "element/element_impl.h"
#include "la/vec3.h"
#include "mesh/mesh_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define HEX_CONVEX_RTOL 1e-10

static double tet_volume(const double *a, const double *b, const double *c, const double *d)
{
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return fcm__vec3_det(u, v, w) / 6.0;
}

static void gather(const fcm_geometry *g, fcm_index c, double *X)
{
  for (int a = 0; a < g->npc; a++)
    for (int d = 0; d < 3; d++)
      X[3 * a + d] = g->coords[3 * g->cells[(size_t)g->npc * (size_t)c + a] + d];
}

/* Largest distance of a corner outside a face plane, or of a face corner off its plane,
 * relative to nothing (absolute); *face and *corner say where. */
static double hex_convexity_defect(const double *X, int *face, int *corner)
{
  const fcm_element_info *info = fcm_element_get_info(FCM_ELEMENT_HEX8);
  fcm__plane pl[6];
  double worst = 0.0;
  fcm__geom_cell_planes(info, X, pl);
  *face = *corner = -1;
  for (int f = 0; f < 6; f++) {
    if (pl[f].n[0] == 0.0 && pl[f].n[1] == 0.0 && pl[f].n[2] == 0.0) {
      *face = f, *corner = -1;
      return HUGE_VAL;
    }
    for (int a = 0; a < 8; a++) {
      const double s =
          pl[f].n[0] * X[3 * a] + pl[f].n[1] * X[3 * a + 1] + pl[f].n[2] * X[3 * a + 2] - pl[f].d;
      int on_face = 0;
      for (int k = 0; k < 4; k++)
        on_face |= info->face_nodes[f][k] == a;
      const double defect = on_face ? fabs(s) : s;
      if (defect > worst) worst = defect, *face = f, *corner = a;
    }
  }
  return worst;
}

/* Faces met an odd number of times are boundary faces (the first of each such group,
 * in cell and face order, stands for it); emit their triangles. */
static fcm_status build_boundary(fcm_geometry *g)
{
  fcm_status st = FCM_OK;
  const fcm_element_info *info = fcm_element_get_info(g->type);
  const int nf = info->num_faces, tri_per_face = info->face_num_corners[0] - 2;
  const fcm_index total = g->num_cells * nf;
  fcm_index *first = NULL, *next = NULL, nb = 0;
  FCM_ALLOC(g->ctx, total, first);
  FCM_ALLOC(g->ctx, total, next);
  FCM_TRY(g->ctx, fcm__mesh_match_faces(g->ctx, info, g->cells, g->num_cells, first, next));
  for (fcm_index i = 0; i < total; i++) { /* keep the odd groups' first faces, in order */
    if (first[i] != i) continue;
    int count = 0;
    for (fcm_index j = i; j >= 0; j = next[j])
      count++;
    if (count % 2 == 1) first[nb++] = i;
  }
  g->num_tris = nb * tri_per_face;
  FCM_ALLOC(g->ctx, 3 * (size_t)g->num_tris, g->tris);
  FCM_ALLOC(g->ctx, (size_t)g->num_tris, g->tri_cell);
  for (fcm_index i = 0; i < nb; i++) {
    const fcm_index c = first[i] / nf;
    const fcm_index *cell = g->cells + (size_t)g->npc * (size_t)c;
    const int *fv = info->face_nodes[first[i] % nf];
    for (int t = 0; t < tri_per_face; t++) {
      const size_t k = (size_t)i * (size_t)tri_per_face + (size_t)t;
      g->tris[3 * k] = cell[fv[0]];
      g->tris[3 * k + 1] = cell[fv[t + 1]];
      g->tris[3 * k + 2] = cell[fv[t + 2]];
      g->tri_cell[k] = c;
    }
  }
cleanup:
  fcm__free(g->ctx, first);
  fcm__free(g->ctx, next);
  return st;
}

fcm_status fcm__geom_create_take(fcm_ctx *ctx, const char *who, fcm_element_type type,
                                 fcm_index num_nodes, double **coords, fcm_index num_cells,
                                 fcm_index **cells, int require_positive, fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  fcm_geometry *g = NULL;
  double X[24];
  FCM_CHECK(type == FCM_ELEMENT_TET4 || type == FCM_ELEMENT_HEX8, ctx, FCM_ERR_ARG,
            "%s: cell type %d is not tet4 (%d) or hex8 (%d)", who, (int)type, (int)FCM_ELEMENT_TET4,
            (int)FCM_ELEMENT_HEX8);
  FCM_CHECK(num_nodes >= 0 && num_cells >= 0, ctx, FCM_ERR_ARG,
            "%s: counts num_nodes = %lld, num_cells = %lld must be >= 0", who, (long long)num_nodes,
            (long long)num_cells);
  FCM_ALLOC(ctx, 1, g);
  g->ctx = ctx;
  g->type = type;
  g->npc = type == FCM_ELEMENT_TET4 ? 4 : 8;
  g->num_nodes = num_nodes;
  g->num_cells = num_cells;
  g->coords = *coords, *coords = NULL;
  g->cells = *cells, *cells = NULL;
  for (int d = 0; d < 3; d++)
    g->lo[d] = HUGE_VAL, g->hi[d] = -HUGE_VAL;
  for (fcm_index a = 0; a < num_nodes; a++)
    for (int d = 0; d < 3; d++) {
      const double v = g->coords[3 * a + d];
      FCM_CHECK(fabs(v) <= FCM__COORD_MAX, ctx, FCM_ERR_ARG,
                "%s: coordinate %d of node %lld (0-based) is %g, outside " FCM__COORD_RANGE, who, d,
                (long long)a, v);
      g->lo[d] = v < g->lo[d] ? v : g->lo[d];
      g->hi[d] = v > g->hi[d] ? v : g->hi[d];
    }
  for (fcm_index c = 0; c < num_cells; c++) {
    fcm_index *cell = g->cells + (size_t)g->npc * (size_t)c;
    for (int a = 0; a < g->npc; a++)
      FCM_CHECK(cell[a] >= 0 && cell[a] < num_nodes, ctx, FCM_ERR_ARG,
                "%s: node %d of cell %lld is %lld, outside [0,%lld)", who, a, (long long)c,
                (long long)cell[a], (long long)num_nodes);
    gather(g, c, X);
    double vol;
    if (type == FCM_ELEMENT_TET4) {
      vol = tet_volume(X, X + 3, X + 6, X + 9);
      if (vol < 0.0 && !require_positive) {
        const fcm_index t = cell[1];
        cell[1] = cell[2], cell[2] = t;
        vol = -vol;
      }
    } else {
      int f, corner;
      const double tol = HEX_CONVEX_RTOL * fcm__element_cell_size(8, X);
      const double defect = hex_convexity_defect(X, &f, &corner);
      FCM_CHECK(defect <= tol, ctx, FCM_ERR_GEOMETRY,
                "%s: hex cell %lld is not convex with planar faces (or is inverted): corner %d "
                "lies %g outside or off face %d (tolerance %g)",
                who, (long long)c, corner, defect, f, tol);
      fcm__poly p;
      fcm__geom_poly_from_cell(type, X, &p);
      vol = fcm__geom_poly_volume(&p);
    }
    FCM_CHECK(!require_positive || vol > 0.0, ctx, FCM_ERR_INTERNAL,
              "%s: generated cell %lld has volume %g (must be positive)", who, (long long)c, vol);
    g->volume += vol;
  }
  FCM_TRY(ctx, build_boundary(g));
  *geom = g;
  g = NULL;
cleanup:
  fcm__free(ctx, *coords);
  fcm__free(ctx, *cells);
  *coords = NULL, *cells = NULL;
  fcm_geometry_destroy(&g);
  return st;
}

fcm_status fcm__geom_create_boundary(fcm_ctx *ctx, const char *who, fcm_index nv,
                                     const double *coords, fcm_index nt, const fcm_index *tris,
                                     fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  fcm_geometry *g = NULL;
  *geom = NULL;
  FCM_ALLOC(ctx, 1, g);
  g->ctx = ctx;
  g->type = FCM_ELEMENT_TET4;
  g->npc = 4;
  g->num_nodes = nv;
  g->num_tris = nt;
  g->custom_boundary = 1;
  FCM_ALLOC(ctx, 3 * (size_t)nv + 1, g->coords);
  FCM_ALLOC(ctx, 1, g->cells);
  FCM_ALLOC(ctx, 3 * (size_t)nt + 1, g->tris);
  FCM_ALLOC(ctx, (size_t)nt + 1, g->tri_cell);
  memcpy(g->coords, coords, 3 * (size_t)nv * sizeof *coords);
  memcpy(g->tris, tris, 3 * (size_t)nt * sizeof *tris);
  for (int d = 0; d < 3; d++)
    g->lo[d] = HUGE_VAL, g->hi[d] = -HUGE_VAL;
  for (fcm_index a = 0; a < nv; a++)
    for (int d = 0; d < 3; d++) {
      g->lo[d] = fmin(g->lo[d], coords[3 * a + d]);
      g->hi[d] = fmax(g->hi[d], coords[3 * a + d]);
    }
  for (fcm_index t = 0; t < nt; t++) { /* sum of the tets (origin, triangle) */
    const double *a = coords + 3 * tris[3 * t], *b = coords + 3 * tris[3 * t + 1],
                 *c = coords + 3 * tris[3 * t + 2];
    g->tri_cell[t] = -1;
    g->volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                  a[2] * (b[0] * c[1] - b[1] * c[0])) /
                 6.0;
  }
  FCM_CHECK(g->volume > 0.0 && isfinite(g->volume), ctx, FCM_ERR_GEOMETRY,
            "%s: the surface encloses volume %g (must be positive: a closed surface oriented "
            "outward)",
            who, g->volume);
  *geom = g;
  g = NULL;
cleanup:
  fcm_geometry_destroy(&g);
  return st;
}

fcm_status fcm_geometry_create(fcm_ctx *ctx, fcm_element_type type, fcm_index num_nodes,
                               const double *coords, fcm_index num_cells, const fcm_index *cells,
                               fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  double *x = NULL;
  fcm_index *c = NULL;
  int npc = type == FCM_ELEMENT_HEX8 ? 8 : 4;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "geometry: output pointer is NULL");
  *geom = NULL;
  FCM_CHECK(ctx, ctx, FCM_ERR_ARG, "geometry: ctx is NULL");
  FCM_CHECK(num_nodes >= 0 && num_cells >= 0, ctx, FCM_ERR_ARG,
            "geometry: counts num_nodes = %lld, num_cells = %lld must be >= 0",
            (long long)num_nodes, (long long)num_cells);
  FCM_CHECK((coords || num_nodes == 0) && (cells || num_cells == 0), ctx, FCM_ERR_ARG,
            "geometry: NULL coordinate or cell array");
  FCM_ALLOC(ctx, 3 * (size_t)num_nodes, x);
  FCM_ALLOC(ctx, (size_t)npc * (size_t)num_cells, c);
  if (num_nodes) memcpy(x, coords, 3 * (size_t)num_nodes * sizeof *x);
  if (num_cells) memcpy(c, cells, (size_t)npc * (size_t)num_cells * sizeof *c);
  FCM_TRY(ctx, fcm__geom_create_take(ctx, "geometry", type, num_nodes, &x, num_cells, &c, 0, geom));
cleanup:
  fcm__free(ctx, x);
  fcm__free(ctx, c);
  return st;
}

fcm_status fcm_geometry_create_from_gmsh(fcm_ctx *ctx, const char *path, fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  fcm_mesh *m = NULL;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "geometry: output pointer is NULL");
  *geom = NULL;
  FCM_TRY(ctx, fcm_mesh_create_from_gmsh(ctx, path, &m));
  const fcm_element_type t = fcm_mesh_element_type(m);
  FCM_CHECK(t == FCM_ELEMENT_TET4 || t == FCM_ELEMENT_HEX8, ctx, FCM_ERR_UNSUPPORTED,
            "geometry: %s holds %s cells; embedded geometry needs straight tet4 or hex8 cells",
            path, fcm_element_get_info(t)->name);
  FCM_TRY(ctx, fcm_geometry_create(ctx, t, fcm_mesh_num_nodes(m), fcm_mesh_coords(m),
                                   fcm_mesh_num_cells(m), fcm_mesh_cells(m), geom));
cleanup:
  fcm_mesh_destroy(&m);
  return st;
}

fcm_status fcm_geometry_create_transformed(fcm_ctx *ctx, const fcm_geometry *src, const double A[9],
                                           const double b[3], fcm_geometry **geom)
{
  fcm_status st = FCM_OK;
  double *x = NULL;
  fcm_index *c = NULL;
  FCM_CHECK(geom, ctx, FCM_ERR_ARG, "geometry transform: output pointer is NULL");
  *geom = NULL;
  FCM_CHECK(ctx && src && A && b, ctx, FCM_ERR_ARG,
            "geometry transform: NULL argument (ctx, src, A and b are required)");
  for (int i = 0; i < 9; i++)
    FCM_CHECK(isfinite(A[i]) && (i >= 3 || isfinite(b[i])), ctx, FCM_ERR_ARG,
              "geometry transform: A or b has a non-finite entry");
  const double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                     A[2] * (A[3] * A[7] - A[4] * A[6]);
  FCM_CHECK(fabs(det) > 0.0, ctx, FCM_ERR_ARG, "geometry transform: det A = %g is not invertible",
            det);
  const size_t nn = (size_t)src->num_nodes, ncell = (size_t)src->num_cells;
  FCM_ALLOC(ctx, 3 * nn, x);
  FCM_ALLOC(ctx, (size_t)src->npc * ncell, c);
  for (size_t a = 0; a < nn; a++) {
    const double *p = src->coords + 3 * a;
    for (int i = 0; i < 3; i++)
      x[3 * a + i] = A[3 * i] * p[0] + A[3 * i + 1] * p[1] + A[3 * i + 2] * p[2] + b[i];
  }
  memcpy(c, src->cells, (size_t)src->npc * ncell * sizeof *c);
  if (det < 0.0 && src->type == FCM_ELEMENT_HEX8) {
    for (size_t k = 0; k < ncell; k++) /* mirror: swap the bottom and top quads */
      for (int a = 0; a < 4; a++) {
        const fcm_index t = c[8 * k + a];
        c[8 * k + a] = c[8 * k + 4 + a], c[8 * k + 4 + a] = t;
      }
  }
  /* Tets are reoriented by fcm__geom_create_take. */
  FCM_TRY(ctx, fcm__geom_create_take(ctx, "geometry transform", src->type, src->num_nodes, &x,
                                     src->num_cells, &c, 0, geom));
  if (src->custom_boundary) { /* keep the source's triangles, mirrored when det A < 0 */
    fcm_geometry *g = *geom;
    fcm_index *t = NULL, *tc = NULL;
    t = fcm__malloc(ctx, 3 * (size_t)src->num_tris + 1, sizeof *t);
    tc = fcm__malloc(ctx, (size_t)src->num_tris + 1, sizeof *tc);
    if (!t || !tc) {
      fcm__free(ctx, t);
      fcm__free(ctx, tc);
      fcm_geometry_destroy(geom);
      FCM_CHECK(0, ctx, FCM_ERR_ALLOC, "geometry transform: out of memory");
    }
    memcpy(t, src->tris, 3 * (size_t)src->num_tris * sizeof *t);
    memcpy(tc, src->tri_cell, (size_t)src->num_tris * sizeof *tc);
    if (det < 0.0)
      for (fcm_index k = 0; k < src->num_tris; k++) {
        const fcm_index s1 = t[3 * k + 1];
        t[3 * k + 1] = t[3 * k + 2], t[3 * k + 2] = s1;
      }
    fcm__free(ctx, g->tris);
    fcm__free(ctx, g->tri_cell);
    g->tris = t, g->tri_cell = tc, g->num_tris = src->num_tris, g->custom_boundary = 1;
    if (src->num_cells == 0) g->volume = src->volume * fabs(det); /* a surface alone */
  }
cleanup:
  fcm__free(ctx, x);
  fcm__free(ctx, c);
  return st;
}

fcm_status fcm__geom_boxes(fcm_ctx *ctx, const fcm_geometry *g, int tris, double **out,
                           fcm_index *n)
{
  fcm_status st = FCM_OK;
  const int npv = tris ? 3 : g->npc;
  const fcm_index *conn = tris ? g->tris : g->cells;
  const fcm_index m = tris ? g->num_tris : g->num_cells;
  double *b = NULL;
  FCM_ALLOC(ctx, 6 * (size_t)m, b);
  for (fcm_index i = 0; i < m; i++) {
    double *bi = b + 6 * i;
    for (int d = 0; d < 3; d++)
      bi[d] = HUGE_VAL, bi[3 + d] = -HUGE_VAL;
    for (int a = 0; a < npv; a++)
      for (int d = 0; d < 3; d++) {
        const double v = g->coords[3 * conn[(size_t)npv * (size_t)i + a] + d];
        bi[d] = fmin(bi[d], v);
        bi[3 + d] = fmax(bi[3 + d], v);
      }
  }
  *out = b;
  *n = m;
cleanup:
  return st;
}

/* Build g's tree `tris` on g's context (under the caller's lock). */
static fcm_status build_tree(fcm_geometry *g, int tris)
{
  fcm_status st = FCM_OK;
  double *boxes = NULL;
  fcm_index n = 0;
  FCM_TRY(g->ctx, fcm__geom_boxes(g->ctx, g, tris, &boxes, &n));
  FCM_TRY(g->ctx, fcm_aabb_tree_create(g->ctx, n, boxes, &g->trees[tris]));
cleanup:
  fcm__free(g->ctx, boxes);
  return st;
}

fcm_status fcm__geom_tree(fcm_ctx *ctx, const fcm_geometry *g, int tris, const fcm_aabb_tree **tree)
{
  fcm_status st = FCM_OK;
  fcm_geometry *cache = (fcm_geometry *)g; /* the trees are a cache: built once, then read */
  fcm_status built = FCM_OK;
#pragma omp critical(fcm_geometry_tree)
  {
    if (!cache->trees[tris]) built = build_tree(cache, tris);
  }
  FCM_CHECK(built == FCM_OK, ctx, built, "geometry: building the search tree of its %s failed (%s)",
            tris ? "boundary triangles" : "cells", fcm_status_name(built));
  *tree = g->trees[tris];
cleanup:
  return st;
}

void fcm_geometry_destroy(fcm_geometry **geom)
{
  if (!geom || !*geom) return;
  fcm_geometry *g = *geom;
  fcm_aabb_tree_destroy(&g->trees[0]);
  fcm_aabb_tree_destroy(&g->trees[1]);
  fcm__free(g->ctx, g->coords);
  fcm__free(g->ctx, g->cells);
  fcm__free(g->ctx, g->tris);
  fcm__free(g->ctx, g->tri_cell);
  fcm__free(g->ctx, g->cell_orig);
  fcm__free(g->ctx, g->tri_orig);
  fcm__free(g->ctx, g);
  *geom = NULL;
}

fcm_status fcm__geom_create_subset(fcm_ctx *ctx, const fcm_geometry *g,
                                   const unsigned char *keep_cell, const unsigned char *keep_tri,
                                   fcm_geometry **out)
{
  fcm_status st = FCM_OK;
  fcm_geometry *s = NULL;
  fcm_index *node_new = NULL, *cell_new = NULL;
  FCM_CHECK(g && keep_cell && keep_tri && out, ctx, FCM_ERR_ARG,
            "geometry subset: NULL argument (geometry, keep_cell, keep_tri, out)");
  *out = NULL;
  const int npc = g->npc;
  FCM_ALLOC(ctx, (size_t)g->num_nodes + 1, node_new);
  FCM_ALLOC(ctx, (size_t)g->num_cells + 1, cell_new);
  FCM_ALLOC(ctx, 1, s);
  s->ctx = ctx;
  s->type = g->type;
  s->npc = npc;
  s->volume = g->volume;
  s->custom_boundary = 1;
  memcpy(s->lo, g->lo, sizeof s->lo);
  memcpy(s->hi, g->hi, sizeof s->hi);
  s->orig_cells = g->cell_orig ? g->orig_cells : g->num_cells;
  s->orig_tris = g->tri_orig ? g->orig_tris : g->num_tris;
  /* mark the nodes used, then number them in their original order */
  for (fcm_index c = 0; c < g->num_cells; c++) {
    cell_new[c] = -1;
    if (!keep_cell[c]) continue;
    cell_new[c] = s->num_cells++;
    for (int a = 0; a < npc; a++)
      node_new[g->cells[(size_t)npc * (size_t)c + (size_t)a]] = 1;
  }
  for (fcm_index t = 0; t < g->num_tris; t++) {
    if (!keep_tri[t]) continue;
    s->num_tris++;
    for (int a = 0; a < 3; a++)
      node_new[g->tris[3 * (size_t)t + (size_t)a]] = 1;
  }
  for (fcm_index k = 0; k < g->num_nodes; k++)
    node_new[k] = node_new[k] ? s->num_nodes++ : -1;
  FCM_ALLOC(ctx, 3 * (size_t)s->num_nodes + 1, s->coords);
  FCM_ALLOC(ctx, (size_t)npc * (size_t)s->num_cells + 1, s->cells);
  FCM_ALLOC(ctx, (size_t)s->num_cells + 1, s->cell_orig);
  FCM_ALLOC(ctx, 3 * (size_t)s->num_tris + 1, s->tris);
  FCM_ALLOC(ctx, (size_t)s->num_tris + 1, s->tri_cell);
  FCM_ALLOC(ctx, (size_t)s->num_tris + 1, s->tri_orig);
  for (fcm_index k = 0; k < g->num_nodes; k++)
    if (node_new[k] >= 0)
      memcpy(s->coords + 3 * node_new[k], g->coords + 3 * k, 3 * sizeof(double));
  for (fcm_index c = 0; c < g->num_cells; c++) {
    if (cell_new[c] < 0) continue;
    const size_t i = (size_t)cell_new[c];
    for (int a = 0; a < npc; a++)
      s->cells[(size_t)npc * i + (size_t)a] =
          node_new[g->cells[(size_t)npc * (size_t)c + (size_t)a]];
    s->cell_orig[i] = g->cell_orig ? g->cell_orig[c] : c;
  }
  fcm_index i = 0;
  for (fcm_index t = 0; t < g->num_tris; t++) {
    if (!keep_tri[t]) continue;
    for (int a = 0; a < 3; a++)
      s->tris[3 * i + a] = node_new[g->tris[3 * (size_t)t + (size_t)a]];
    const fcm_index tc = g->tri_cell ? g->tri_cell[t] : -1;
    s->tri_cell[i] = tc >= 0 ? cell_new[tc] : -1;
    s->tri_orig[i] = g->tri_orig ? g->tri_orig[t] : t;
    i++;
  }
  *out = s;
  s = NULL;
cleanup:
  fcm__free(ctx, node_new);
  fcm__free(ctx, cell_new);
  fcm_geometry_destroy(&s);
  return st;
}

double fcm__geom_bytes(const fcm_geometry *g)
{
  if (!g) return 0.0;
  const double idx = (double)sizeof(fcm_index);
  return (double)sizeof *g + 3.0 * sizeof(double) * (double)g->num_nodes +
         idx * (double)g->npc * (double)g->num_cells + idx * 4.0 * (double)g->num_tris +
         (g->cell_orig ? idx * (double)g->num_cells : 0.0) +
         (g->tri_orig ? idx * (double)g->num_tris : 0.0);
}

fcm_element_type fcm_geometry_cell_type(const fcm_geometry *geom)
{
  return geom->type;
}
int fcm_geometry_nodes_per_cell(const fcm_geometry *geom)
{
  return geom->npc;
}
fcm_index fcm_geometry_num_nodes(const fcm_geometry *geom)
{
  return geom->num_nodes;
}
fcm_index fcm_geometry_num_cells(const fcm_geometry *geom)
{
  return geom->num_cells;
}
const double *fcm_geometry_coords(const fcm_geometry *geom)
{
  return geom->coords;
}
const fcm_index *fcm_geometry_cells(const fcm_geometry *geom)
{
  return geom->cells;
}
double fcm_geometry_volume(const fcm_geometry *geom)
{
  return geom->volume;
}
fcm_index fcm_geometry_num_boundary_triangles(const fcm_geometry *geom)
{
  return geom->num_tris;
}
const fcm_index *fcm_geometry_boundary_triangles(const fcm_geometry *geom)
{
  return geom->tris;
}
const fcm_index *fcm_geometry_boundary_cells(const fcm_geometry *geom)
{
  return geom->tri_cell;
}

void fcm_geometry_bounding_box(const fcm_geometry *geom, double lo[3], double hi[3])
{
  for (int d = 0; d < 3; d++)
    lo[d] = geom->lo[d], hi[d] = geom->hi[d];
}

void fcm_geometry_view(const fcm_geometry *geom, FILE *stream)
{
  if (!geom || !stream) return;
  fprintf(stream,
          "geometry: %s cells %lld, nodes %lld, volume %.17g, boundary triangles %lld\n"
          "  bounding box [%g, %g] x [%g, %g] x [%g, %g]\n",
          fcm_element_get_info(geom->type)->name, (long long)geom->num_cells,
          (long long)geom->num_nodes, geom->volume, (long long)geom->num_tris, geom->lo[0],
          geom->hi[0], geom->lo[1], geom->hi[1], geom->lo[2], geom->hi[2]);
}
