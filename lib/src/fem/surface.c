/* The embedded surface for output: the boundary triangles of the geometry located in a space,
 * every point moving with the element (the material piece) that holds it, and both sides of
 * the cut faces. Where cuts split the body, a point goes to the piece whose material holds
 * it, and a boundary triangle that a cut crosses is replaced by its parts, split exactly as
 * the cut cells' pieces are (the same parts, made again: fcm__embed_finder), so no triangle
 * joins points of two pieces. Triangles no cut crosses keep their vertices and order.
 * This file makes the surface, locates its boundary vertices and lays out its points and triangles
 * after each cut; which triangles a cut splits, and into which parts, is surface_split.c's. */
#include "fem/surface_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Points and triangles a surface is made with room for, per boundary vertex and triangle
 * (surface_reserve()): Dick's Bunny 2 holds 2.8 points and 1.3 triangles per boundary vertex
 * and triangle after its four cuts. */
#define ROOM_POINTS    3
#define ROOM_TRIANGLES 2

fcm_status fcm__surface_cell_tree(fcm_embedded_surface *es)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_index nc = fcm_mesh_num_cells(es->mesh);
  const int npc = fcm_mesh_nodes_per_cell(es->mesh);
  double *boxes = NULL, X[3 * FCM_ELEMENT_MAX_NODES];
  if (es->cell_tree) return FCM_OK;
  FCM_ALLOC_RAW(ctx, 6 * (size_t)nc + 6, boxes);
  for (fcm_index c = 0; c < nc; c++) {
    double *b = boxes + 6 * c;
    fcm_mesh_cell_coords(es->mesh, c, X);
    for (int d = 0; d < 3; d++)
      b[d] = HUGE_VAL, b[3 + d] = -HUGE_VAL;
    for (int a = 0; a < npc; a++)
      for (int d = 0; d < 3; d++)
        b[d] = fmin(b[d], X[3 * a + d]), b[3 + d] = fmax(b[3 + d], X[3 * a + d]);
  }
  FCM_TRY(ctx, fcm_aabb_tree_create(ctx, nc, boxes, &es->cell_tree));
  double mlo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, mhi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  const fcm_index nn = fcm_mesh_num_nodes(es->mesh);
  const double *mx = fcm_mesh_coords(es->mesh);
  for (fcm_index i = 0; i < nn; i++)
    for (int d = 0; d < 3; d++)
      mlo[d] = fmin(mlo[d], mx[3 * i + d]), mhi[d] = fmax(mhi[d], mx[3 * i + d]);
  es->cell_pad = 1e-6 * fmax(mhi[0] - mlo[0], fmax(mhi[1] - mlo[1], mhi[2] - mlo[2]));
cleanup:
  fcm__free(ctx, boxes);
  return st;
}

/* *a (n_old x size, its first keep in use) as a new array of n: the rest not zeroed (written
 * before it is read), so that only the pages written are touched. */
static fcm_status grow(fcm_ctx *ctx, void **a, size_t keep, size_t n, size_t size)
{
  fcm_status st = FCM_OK;
  void *fresh = fcm__malloc(ctx, n, size); /* reports the failure */
  if (!fresh) {
    st = FCM_ERR_ALLOC;
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  memcpy(fresh, *a, keep * size);
  fcm__free(ctx, *a);
  *a = fresh;
cleanup:
  return st;
}

/* Room for np points and nt triangles, the current ones kept: twice as much when it grows.
 * The surface is made with room for its first cuts (ROOM_POINTS, ROOM_TRIANGLES): a cut then
 * writes the parts and cut faces into pages already in memory, where a grown array's pages
 * would be faulted in again (a few ms at 100k points). */
static fcm_status surface_reserve(fcm_embedded_surface *es, fcm_index np, fcm_index nt)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  if (np > es->cap_p) {
    const size_t n = (size_t)FCM_MAX(np, 2 * es->cap_p), keep = (size_t)FCM_MAX(es->np, es->nb);
    FCM_TRY(ctx, grow(ctx, (void **)&es->X, 3 * keep, 3 * n, sizeof(double)));
    FCM_TRY(ctx, grow(ctx, (void **)&es->xi, 3 * keep, 3 * n, sizeof(double)));
    FCM_TRY(ctx, grow(ctx, (void **)&es->cell, keep, n, sizeof(fcm_index)));
    FCM_TRY(ctx, grow(ctx, (void **)&es->elem, keep, n, sizeof(fcm_index)));
    FCM_TRY(ctx, grow(ctx, (void **)&es->flag, keep, n, sizeof(int32_t)));
    es->cap_p = (fcm_index)n;
  }
  if (nt > es->cap_t) {
    const size_t n = (size_t)FCM_MAX(nt, 2 * es->cap_t);
    FCM_TRY(ctx, grow(ctx, (void **)&es->tri, 3 * (size_t)es->nt, 3 * n, sizeof(fcm_index)));
    es->cap_t = (fcm_index)n;
  }
cleanup:
  return st;
}

/* Keep the n cut-face points from v (cell order) for the next rebuild. */
static fcm_status cache_cut_faces(fcm_embedded_surface *es, fcm_index v, fcm_index n)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  es->cf_np = 0;
  if (n == 0) return FCM_OK;
  if (n > es->cf_cap) {
    const size_t cap = (size_t)FCM_MAX(n, 2 * es->cf_cap);
    fcm__free(ctx, es->cf_cell);
    fcm__free(ctx, es->cf_xi);
    fcm__free(ctx, es->cf_X);
    es->cf_cell = NULL, es->cf_xi = es->cf_X = NULL, es->cf_cap = 0;
    FCM_ALLOC_RAW(ctx, cap, es->cf_cell);
    FCM_ALLOC_RAW(ctx, 3 * cap, es->cf_xi);
    FCM_ALLOC_RAW(ctx, 3 * cap, es->cf_X);
    es->cf_cap = (fcm_index)cap;
  }
  memcpy(es->cf_cell, es->cell + v, (size_t)n * sizeof *es->cf_cell);
  memcpy(es->cf_xi, es->xi + 3 * v, 3 * (size_t)n * sizeof *es->cf_xi);
  memcpy(es->cf_X, es->X + 3 * v, 3 * (size_t)n * sizeof *es->cf_X);
  es->cf_np = n;
cleanup:
  return st;
}

/* fcm_space_locate() of the n points X in the current space, on the cells' tree. */
static fcm_status locate(fcm_embedded_surface *es, fcm_index n, const double *X, fcm_index *cell,
                         double *xi)
{
  const fcm_space *s = es->space;
  if (s->nn != fcm_mesh_nodes_per_cell(es->mesh)) /* other boxes than the tree's */
    return fcm_space_locate(s, n, X, cell, xi, NULL);
  fcm_status st = FCM_OK;
  FCM_TRY(es->ctx, fcm__surface_cell_tree(es));
  FCM_TRY(es->ctx, fcm__space_locate_in(s, es->cell_tree, n, X, cell, xi, NULL));
cleanup:
  return st;
}

/* Points [v, v + n) of the split triangles' parts: reference coordinates in their cells and
 * elements. A part no piece holds (in a dropped cell or piece) follows the element
 * fcm_space_point_element() picks, in the cell fcm_space_locate() finds when its own has no
 * element. Point i is vertex xat[i - v] of es->polys: its reference coordinates in its cell
 * are taken from es->pxi where mapped, else mapped and kept there. */
static fcm_status part_points(fcm_embedded_surface *es, fcm_index v, fcm_index n,
                              const fcm_index *piece, const size_t *xat)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_space *s = es->space;
  double X[3 * FCM_ELEMENT_MAX_NODES];
  fcm_index last = -1, *lost = NULL, nlost = 0;
  double *lx = NULL, *lxi = NULL;
  fcm_index *lc = NULL;
  for (fcm_index i = v; i < v + n; i++) {
    const fcm_index c = es->cell[i];
    double *kept = es->pxi ? es->pxi + 3 * xat[i - v] : NULL;
    if (kept && !isnan(kept[0])) {
      memcpy(es->xi + 3 * i, kept, 3 * sizeof *kept);
    } else {
      if (c != last) fcm_mesh_cell_coords(es->mesh, c, X);
      last = c;
      FCM_TRY(ctx, fcm_element_inverse_map(ctx, s->type, X, es->X + 3 * i, es->xi + 3 * i));
      if (kept) memcpy(kept, es->xi + 3 * i, 3 * sizeof *kept);
    }
    es->elem[i] = fcm__surface_piece_element(s, c, piece[i - v]);
    if (es->elem[i] < 0) es->elem[i] = fcm_space_point_element(s, c, es->xi + 3 * i);
    if (es->elem[i] < 0) {
      if (!lost) FCM_ALLOC_RAW(ctx, (size_t)n, lost);
      lost[nlost++] = i;
    }
  }
  if (nlost) {
    FCM_ALLOC_RAW(ctx, 3 * (size_t)nlost, lx);
    FCM_ALLOC_RAW(ctx, 3 * (size_t)nlost, lxi);
    FCM_ALLOC_RAW(ctx, (size_t)nlost, lc);
    for (fcm_index k = 0; k < nlost; k++)
      memcpy(lx + 3 * k, es->X + 3 * lost[k], 3 * sizeof *lx);
    FCM_TRY(ctx, locate(es, nlost, lx, lc, lxi));
    for (fcm_index k = 0; k < nlost; k++) {
      const fcm_index i = lost[k];
      es->cell[i] = lc[k];
      memcpy(es->xi + 3 * i, lxi + 3 * k, 3 * sizeof *lxi);
      es->elem[i] = fcm_space_point_element(s, lc[k], lxi + 3 * k);
    }
  }
cleanup:
  fcm__free(ctx, lost);
  fcm__free(ctx, lx);
  fcm__free(ctx, lxi);
  fcm__free(ctx, lc);
  return st;
}

/* Element of every boundary vertex, the parts of the boundary triangles the cuts split, and
 * the cut faces of the current space. */
static fcm_status surface_rebuild(fcm_embedded_surface *es)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_space *s = es->space;
  const fcm_cell_rules *rules = s->rules;
  const fcm_index npieces = rules ? fcm_cell_rules_num_pieces(rules) : 0;
  unsigned char *split = NULL;
  fcm__embed_polys polys = {NULL, NULL, NULL, 0, 0, 0, 0};
  fcm_index *src = NULL, *pcell = NULL, *order = NULL, *ppiece = NULL, *by_tri = NULL;
  size_t *first_x = NULL, *xat = NULL;
  fcm_index ncf = 0;
  for (fcm_index p = 0; p < npieces; p++)
    ncf += fcm_cell_rules_get_piece_cut_faces(rules, p, NULL);
  const int cuts = rules && fcm_cell_rules_num_cuts(rules) > 0;
  for (fcm_index i = 0; i < es->nb; i++) {
    const fcm_index c = es->cell[i];
    es->flag[i] = 0;
    /* with cuts, fcm__surface_split() gives the vertices in cells of several elements theirs */
    if (cuts && c >= 0 && c < s->num_cells && s->cell_elem[c + 1] - s->cell_elem[c] > 1) continue;
    es->elem[i] = fcm_space_point_element(s, c, es->xi + 3 * i);
    FCM_CHECK(es->elem[i] >= 0, ctx, FCM_ERR_ARG,
              "embedded surface: vertex %lld lies in cell %lld, which has no element in this "
              "space (another mesh or active set?)",
              (long long)i, (long long)es->cell[i]);
  }
  FCM_ALLOC(ctx, (size_t)es->nbt + 1, split);
  if (cuts)
    FCM_TRY(ctx, fcm__surface_split(es, split, &polys, &src, &pcell));
  else
    fcm__surface_cache_clear(es);
  /* the kept parts in triangle order (each triangle's in cell order) */
  fcm_index nkeep = 0, nsv = 0, nst = 0, nsplit = 0;
  for (fcm_index t = 0; t < es->nbt; t++)
    nsplit += split[t];
  FCM_ALLOC(ctx, polys.n + 1, order);
  FCM_ALLOC(ctx, polys.n + 1, first_x);
  for (size_t j = 0, off = 0; j < polys.n; off += (size_t)polys.nv[j], j++) {
    first_x[j] = off;
    if (!split[src[j]]) continue;
    order[nkeep++] = (fcm_index)j;
    nsv += polys.nv[j];
    nst += polys.nv[j] - 2;
  }
  /* by triangle, stably: the parts come in cell order, far from the triangles' */
  FCM_ALLOC_RAW(ctx, 2 * (size_t)nkeep + 2, by_tri);
  for (fcm_index k = 0; k < nkeep; k++)
    by_tri[2 * k] = src[order[k]], by_tri[2 * k + 1] = order[k];
  if (nkeep > 1) qsort(by_tri, (size_t)nkeep, 2 * sizeof *by_tri, fcm__surface_cmp_pair);
  for (fcm_index k = 0; k < nkeep; k++)
    order[k] = by_tri[2 * k + 1];
  const fcm_index np = es->nb + nsv + 3 * ncf, nt = es->nbt - nsplit + nst + ncf;
  FCM_TRY(ctx, surface_reserve(es, np, nt));
  fcm_index v = es->nb, t = 0;
  for (fcm_index k = 0; k < es->nbt; k++)
    if (!split[k]) memcpy(es->tri + 3 * t++, es->tri0 + 3 * k, 3 * sizeof *es->tri);
  FCM_ALLOC(ctx, (size_t)nsv + 1, ppiece);
  FCM_ALLOC_RAW(ctx, (size_t)nsv + 1, xat);
  for (fcm_index k = 0; k < nkeep; k++) {
    const fcm_index j = order[k];
    const int m = polys.nv[j];
    for (int a = 0; a < m; a++) {
      memcpy(es->X + 3 * (v + a), polys.x + 3 * (first_x[j] + (size_t)a), 3 * sizeof(double));
      es->cell[v + a] = pcell[j];
      es->flag[v + a] = 0;
      ppiece[v + a - es->nb] = polys.piece[j];
      xat[v + a - es->nb] = first_x[j] + (size_t)a;
    }
    for (int a = 1; a + 1 < m; a++, t++) { /* fan: the polygon keeps the triangle's orientation */
      es->tri[3 * t] = v;
      es->tri[3 * t + 1] = v + a;
      es->tri[3 * t + 2] = v + a + 1;
    }
    v += m;
  }
  FCM_TRY(ctx, part_points(es, es->nb, nsv, ppiece, xat));
  /* the cut faces, piece by piece (so cell by cell): a point with the cell and the reference
   * coordinates of the last rebuild's point in its place among its cell's takes its position */
  double Xc[3 * FCM_ELEMENT_MAX_NODES];
  const fcm_index v0 = v, ncached = es->cf_np;
  fcm_index j = 0, last = -1, r = 0;
  for (fcm_index p = 0; p < npieces; p++) {
    const double *xi;
    const fcm_index n = fcm_cell_rules_get_piece_cut_faces(rules, p, &xi);
    if (!n) continue;
    const fcm_index c = fcm_cell_rules_piece_cell(rules, p),
                    e = fcm__surface_piece_element(s, c, p);
    if (c != last) {
      while (j < ncached && es->cf_cell[j] < c)
        j++;
      last = c, r = 0;
    }
    int have_xc = 0;
    for (fcm_index k = 0; k < 3 * n; k++, v++, r++) {
      const fcm_index q = j + r;
      if (q < ncached && es->cf_cell[q] == c &&
          !memcmp(es->cf_xi + 3 * q, xi + 3 * k, 3 * sizeof(double))) {
        memcpy(es->X + 3 * v, es->cf_X + 3 * q, 3 * sizeof(double));
      } else {
        if (!have_xc) fcm_mesh_cell_coords(s->mesh, c, Xc);
        have_xc = 1;
        fcm_element_map(s->type, Xc, xi + 3 * k, es->X + 3 * v);
      }
      memcpy(es->xi + 3 * v, xi + 3 * k, 3 * sizeof(double));
      es->cell[v] = c;
      es->elem[v] = e;
      es->flag[v] = 1;
    }
    for (fcm_index k = 0; k < n; k++, t++)
      for (int a = 0; a < 3; a++)
        es->tri[3 * t + a] = v - 3 * n + 3 * k + a;
  }
  FCM_TRY(ctx, cache_cut_faces(es, v0, v - v0));
  es->np = np;
  es->nt = nt;
  es->num_split = nsplit;
cleanup:
  if (st != FCM_OK) fcm__surface_cache_clear(es);
  /* the finder's parts and cut triangles' tree are the rules': freed per call (per cut); what
   * it holds for the mesh and geometry stays, as does the cells' tree (the mesh's, which a new
   * space keeps: fcm_embedded_surface_set_space()) */
  fcm__embed_finder_release(es->finder);
  fcm__free(ctx, split);
  fcm__free(ctx, src);
  fcm__free(ctx, pcell);
  fcm__free(ctx, order);
  fcm__free(ctx, by_tri);
  fcm__free(ctx, first_x);
  fcm__free(ctx, ppiece);
  fcm__free(ctx, xat);
  fcm__embed_polys_free(ctx, &polys);
  return st;
}

fcm_status fcm_embedded_surface_create(const fcm_space *s, const fcm_geometry *geom,
                                       fcm_embedded_surface **out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s ? s->ctx : NULL;
  fcm_embedded_surface *es = NULL;
  fcm_index *map = NULL;
  FCM_CHECK(s && geom && out, ctx, FCM_ERR_ARG, "embedded surface: NULL space, geometry or output");
  *out = NULL;
  const fcm_index nv = fcm_geometry_num_nodes(geom), nt = fcm_geometry_num_boundary_triangles(geom);
  const fcm_index *tri = fcm_geometry_boundary_triangles(geom);
  const double *GX = fcm_geometry_coords(geom);
  FCM_CHECK(nt > 0, ctx, FCM_ERR_ARG, "embedded surface: the geometry has no boundary triangles");
  FCM_ALLOC(ctx, 1, es);
  es->ctx = ctx;
  es->space = s;
  es->mesh = s->mesh;
  es->geom = geom;
  FCM_ALLOC(ctx, nv, map);
  for (fcm_index i = 0; i < nv; i++)
    map[i] = -1;
  fcm_index nb = 0;
  for (fcm_index k = 0; k < 3 * nt; k++)
    if (map[tri[k]] < 0) map[tri[k]] = nb++;
  es->cap_p = ROOM_POINTS * nb;
  es->cap_t = ROOM_TRIANGLES * nt;
  /* the room beyond the boundary's points is written before it is read (raw: a surface that
   * is never cut does not touch its pages) */
  FCM_ALLOC_RAW(ctx, 3 * (size_t)es->cap_p, es->X);
  FCM_ALLOC_RAW(ctx, 3 * (size_t)es->cap_p, es->xi);
  FCM_ALLOC_RAW(ctx, es->cap_p, es->cell);
  FCM_ALLOC_RAW(ctx, es->cap_p, es->elem);
  FCM_ALLOC_RAW(ctx, es->cap_p, es->flag);
  FCM_ALLOC_RAW(ctx, 3 * (size_t)es->cap_t, es->tri);
  memset(es->X, 0, 3 * (size_t)nb * sizeof *es->X);
  memset(es->xi, 0, 3 * (size_t)nb * sizeof *es->xi);
  memset(es->cell, 0, (size_t)nb * sizeof *es->cell);
  memset(es->elem, 0, (size_t)nb * sizeof *es->elem);
  memset(es->flag, 0, (size_t)nb * sizeof *es->flag);
  FCM_ALLOC(ctx, 3 * nt, es->tri0);
  for (fcm_index k = 0; k < 3 * nt; k++)
    es->tri[k] = es->tri0[k] = map[tri[k]];
  for (fcm_index i = 0; i < nv; i++)
    if (map[i] >= 0) memcpy(es->X + 3 * map[i], GX + 3 * i, 3 * sizeof(double));
  es->nb = nb;
  es->nbt = nt;
  FCM_TRY(ctx, locate(es, nb, es->X, es->cell, es->xi));
  FCM_TRY(ctx, surface_rebuild(es));
  *out = es;
  es = NULL;
cleanup:
  fcm__free(ctx, map);
  fcm_embedded_surface_destroy(&es);
  return st;
}

void fcm_embedded_surface_destroy(fcm_embedded_surface **surface)
{
  if (!surface || !*surface) return;
  fcm_embedded_surface *es = *surface;
  fcm__embed_finder_destroy(&es->finder);
  fcm_aabb_tree_destroy(&es->cell_tree);
  fcm__surface_cache_clear(es);
  void *arrays[] = {es->X,       es->xi,    es->cell,     es->elem,   es->tri,
                    es->tri0,    es->flag,  es->tc_first, es->tc_ids, es->tc_n,
                    es->cf_cell, es->cf_xi, es->cf_X,     es->tarea};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(es->ctx, arrays[k]);
  fcm__free(es->ctx, es);
  *surface = NULL;
}

fcm_status fcm_embedded_surface_set_space(fcm_embedded_surface *es, const fcm_space *s)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(es && s, es ? es->ctx : NULL, FCM_ERR_ARG, "embedded surface: NULL surface or space");
  FCM_CHECK(s->mesh == es->mesh, es->ctx, FCM_ERR_ARG,
            "embedded surface: the new space is on another mesh");
  es->space = s;
  FCM_TRY(es->ctx, surface_rebuild(es));
cleanup:
  return st;
}

fcm_index fcm_embedded_surface_num_points(const fcm_embedded_surface *es)
{
  return es ? es->np : 0;
}
fcm_index fcm_embedded_surface_num_triangles(const fcm_embedded_surface *es)
{
  return es ? es->nt : 0;
}
const double *fcm_embedded_surface_points(const fcm_embedded_surface *es)
{
  return es ? es->X : NULL;
}
const fcm_index *fcm_embedded_surface_triangles(const fcm_embedded_surface *es)
{
  return es ? es->tri : NULL;
}
const int32_t *fcm_embedded_surface_cut_flags(const fcm_embedded_surface *es)
{
  return es ? es->flag : NULL;
}

fcm_index fcm_embedded_surface_num_split_triangles(const fcm_embedded_surface *es)
{
  return es ? es->num_split : 0;
}

fcm_status fcm_embedded_surface_eval(const fcm_embedded_surface *es, const double *u,
                                     double *displacement, double *deformed)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(es && u, es ? es->ctx : NULL, FCM_ERR_ARG, "embedded surface: NULL surface or field");
  for (fcm_index i = 0; i < es->np; i++) {
    double d[3];
    FCM_TRY(es->ctx, fcm_space_element_eval(es->space, es->elem[i], es->xi + 3 * i, u, d));
    if (displacement) memcpy(displacement + 3 * i, d, sizeof d);
    if (deformed)
      for (int k = 0; k < 3; k++)
        deformed[3 * i + k] = es->X[3 * i + k] + d[k];
  }
cleanup:
  return st;
}
