/* The embedded surface's split (surface.c builds the rest of the surface): which boundary
 * triangles the cuts cross or touch, the piece of each boundary vertex in a cell of several
 * pieces, and the parts of the split triangles, clipped by the cut cells' pieces
 * (fcm__embed_finder). Each cut's rules extend the last ones, so a rebuild keeps what it found
 * (the rules' cut triangles and pieces, the vertices' pieces, the crossings, the clipped
 * parts; the cells each boundary triangle meets for the surface's life) and the next one
 * takes over the answers in the cells no new cut triangle reaches instead of finding them
 * again. */
#include "fem/surface_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A split triangle's parts must add up to its area to this relative tolerance; otherwise (a
 * triangle partly outside the mesh) it is kept whole. */
#define SPLIT_AREA_RTOL 1e-9

/* Area of triangle (a, b, c). */
static double tri_area(const double *a, const double *b, const double *c)
{
  double u[3], v[3];
  for (int d = 0; d < 3; d++)
    u[d] = b[d] - a[d], v[d] = c[d] - a[d];
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
  return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* The boundary triangle t's three vertices (9 doubles). */
static void tri_coords(const fcm_embedded_surface *es, fcm_index t, double x[9])
{
  for (int a = 0; a < 3; a++)
    memcpy(x + 3 * a, es->X + 3 * es->tri0[3 * t + a], 3 * sizeof *x);
}

/* A piece of the last rebuild's rules in cell c in the current rules' numbering (-1: none,
 * -2: on a cut, as they are). */
static fcm_index map_piece(const fcm_embedded_surface *es, fcm_index c, fcm_index p)
{
  return p < 0 ? p : p - es->prev_piece_off[c] + es->space->rules->piece_off[c];
}

/* changed[c] (num cells): 0 where the last rebuild's answers still hold, as the finder would
 * give them again: the current rules extend that rebuild's (its cut triangles first, the
 * same cells), cell c has as many pieces, each the child of the one in its place, and no
 * new cut triangle's box comes within a millionth of the mesh's size of the cell's box (the
 * finder takes the cut triangles within 2e-9 of a cell's size), with the same tolerances of
 * the parts. All 1 otherwise; *extends_out: whether the rules extend that rebuild's. */
static fcm_status changed_cells(fcm_embedded_surface *es, unsigned char *changed, int *extends_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_cell_rules *R = es->space->rules;
  const fcm_index nc = R->num_cells;
  fcm__idbuf ids = {NULL, 0, 0};
  const int extends =
      es->prev_tris && R->piece_parent && nc == es->prev_ncells &&
      R->opts.clip_rtol == es->prev_rtol[0] && R->opts.sliver_rtol == es->prev_rtol[1] &&
      R->num_cut_tris >= es->prev_ntris &&
      !memcmp(R->cut_tris, es->prev_tris, (size_t)es->prev_ntris * sizeof *R->cut_tris);
  *extends_out = extends;
  for (fcm_index c = 0; c < nc; c++) {
    const fcm_index p0 = R->piece_off[c], n = R->piece_off[c + 1] - p0;
    changed[c] = !extends || n != es->prev_piece_off[c + 1] - es->prev_piece_off[c];
    for (fcm_index i = 0; i < n && !changed[c]; i++)
      changed[c] = R->piece_parent[p0 + i] != es->prev_piece_off[c] + i;
  }
  if (!extends) return FCM_OK;
  FCM_TRY(ctx, fcm__surface_cell_tree(es));
  const double w = es->cell_pad;
  for (fcm_index t = es->prev_ntris; t < R->num_cut_tris; t++) {
    double lo[3], hi[3];
    for (int d = 0; d < 3; d++)
      lo[d] = R->cut_tris[t].lo[d] - w, hi[d] = R->cut_tris[t].hi[d] + w;
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, es->cell_tree, lo, hi, &ids));
    for (size_t k = 0; k < ids.n; k++)
      changed[ids.ids[k]] = 1;
  }
cleanup:
  fcm__geom_idbuf_free(ctx, &ids);
  return st;
}

/* Forget what the last rebuild with cuts found. */
void fcm__surface_cache_clear(fcm_embedded_surface *es)
{
  void *arrays[] = {es->prev_tris, es->prev_piece_off, es->vpiece, es->pairs,
                    es->poff,      es->xoff,           es->cross,  es->pxi};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
    fcm__free(es->ctx, arrays[k]);
  fcm__embed_polys_free(es->ctx, &es->polys);
  es->prev_tris = NULL, es->prev_piece_off = es->vpiece = es->pairs = NULL;
  es->poff = es->xoff = NULL;
  es->cross = NULL, es->pxi = NULL;
  es->prev_ntris = es->prev_ncells = 0;
  es->npairs = 0;
}

/* Keep the rules' cut triangles and pieces per cell for the next rebuild. */
static fcm_status cache_rules(fcm_embedded_surface *es)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_cell_rules *R = es->space->rules;
  fcm__free(ctx, es->prev_tris);
  fcm__free(ctx, es->prev_piece_off);
  es->prev_tris = NULL, es->prev_piece_off = NULL;
  FCM_ALLOC_RAW(ctx, (size_t)R->num_cut_tris + 1, es->prev_tris);
  memcpy(es->prev_tris, R->cut_tris, (size_t)R->num_cut_tris * sizeof *R->cut_tris);
  FCM_ALLOC_RAW(ctx, (size_t)R->num_cells + 1, es->prev_piece_off);
  memcpy(es->prev_piece_off, R->piece_off, ((size_t)R->num_cells + 1) * sizeof *R->piece_off);
  es->prev_ntris = R->num_cut_tris;
  es->prev_ncells = R->num_cells;
  es->prev_rtol[0] = R->opts.clip_rtol, es->prev_rtol[1] = R->opts.sliver_rtol;
cleanup:
  if (st != FCM_OK) fcm__surface_cache_clear(es);
  return st;
}

/* Keep the clipped parts of the (cell, triangle) pairs (*pairs, n, sorted) for the next
 * rebuild, with their vertices' reference coordinates (*pxi, 3 per vertex of polys; NaN: not
 * mapped yet): the arrays are taken, the polygons copied. */
static fcm_status cache_parts(fcm_embedded_surface *es, const fcm__embed_polys *polys,
                              fcm_index **pairs, size_t n, size_t **poff, size_t **xoff,
                              double **pxi)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  fcm__embed_polys copy = {NULL, NULL, NULL, 0, 0, 0, 0};
  FCM_ALLOC_RAW(ctx, 3 * polys->nx + 3, copy.x);
  FCM_ALLOC_RAW(ctx, polys->n + 1, copy.nv);
  FCM_ALLOC_RAW(ctx, polys->n + 1, copy.piece);
  if (polys->nx > 0) memcpy(copy.x, polys->x, 3 * polys->nx * sizeof *copy.x);
  if (polys->n > 0) { /* none: a cut that split no boundary triangle */
    memcpy(copy.nv, polys->nv, polys->n * sizeof *copy.nv);
    memcpy(copy.piece, polys->piece, polys->n * sizeof *copy.piece);
  }
  copy.n = copy.cap = polys->n;
  copy.nx = copy.capx = polys->nx;
  fcm__embed_polys_free(ctx, &es->polys);
  es->polys = copy;
  copy.x = NULL, copy.nv = NULL, copy.piece = NULL;
  fcm__free(ctx, es->pairs);
  fcm__free(ctx, es->poff);
  fcm__free(ctx, es->xoff);
  fcm__free(ctx, es->pxi);
  es->pairs = *pairs, es->poff = *poff, es->xoff = *xoff, es->npairs = n;
  es->pxi = *pxi;
  *pairs = NULL, *poff = NULL, *xoff = NULL, *pxi = NULL;
cleanup:
  fcm__embed_polys_free(ctx, &copy);
  return st;
}

/* Polygons clipped ahead: those of the (cell, triangle) pairs pairs[0 .. n) (sorted), pair k's
 * polys.x from xoff[k], polygons off[k] .. off[k + 1] of polys; clipped[k]: whether pair k was
 * clipped (a pair left out has no polygons here). */
typedef struct preclip {
  fcm_index *pairs;
  size_t *off, *xoff, n;
  unsigned char *clipped;
  fcm__embed_polys polys;
} preclip;

static void preclip_free(fcm_ctx *ctx, preclip *pc)
{
  fcm__free(ctx, pc->pairs);
  fcm__free(ctx, pc->off);
  fcm__free(ctx, pc->xoff);
  fcm__free(ctx, pc->clipped);
  fcm__embed_polys_free(ctx, &pc->polys);
  memset(pc, 0, sizeof *pc);
}

/* The cells boundary triangle t touches within rounding: *n of them from *ids (valid until the
 * next call), found once a surface (es->tc_*: they depend on the geometry and mesh alone). */
static fcm_status tri_cells(fcm_embedded_surface *es, fcm_index t, const fcm_index **ids, size_t *n)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  fcm__idbuf q = {NULL, 0, 0};
  if (!es->tc_first) {
    fcm_index *first = NULL;
    if (!es->tc_n) FCM_ALLOC_RAW(ctx, (size_t)es->nbt + 1, es->tc_n);
    FCM_ALLOC_RAW(ctx, (size_t)es->nbt + 1, first);
    for (fcm_index k = 0; k < es->nbt; k++)
      first[k] = -1;
    es->tc_first = first;
  }
  if (es->tc_first[t] < 0) {
    double x[9], lo[3], hi[3], w = 0.0;
    tri_coords(es, t, x);
    for (int d = 0; d < 3; d++) {
      lo[d] = fmin(x[d], fmin(x[3 + d], x[6 + d]));
      hi[d] = fmax(x[d], fmax(x[3 + d], x[6 + d]));
      w = fmax(w, hi[d] - lo[d]);
    }
    for (int d = 0; d < 3; d++)
      lo[d] -= 1e-9 * w, hi[d] += 1e-9 * w;
    FCM_TRY(ctx, fcm__geom_tree_query(ctx, es->cell_tree, lo, hi, &q));
    if (!es->tc_ids || es->tc_len + q.n > es->tc_cap) {
      size_t cap = es->tc_cap ? 2 * es->tc_cap : 4096;
      while (cap < es->tc_len + q.n)
        cap *= 2;
      void *a = es->tc_ids;
      FCM_TRY(ctx, fcm__resize(ctx, &a, es->tc_len, cap, sizeof(fcm_index)));
      es->tc_ids = a;
      es->tc_cap = cap;
    }
    if (q.n) memcpy(es->tc_ids + es->tc_len, q.ids, q.n * sizeof *q.ids);
    es->tc_first[t] = (fcm_index)es->tc_len;
    es->tc_n[t] = (int)q.n;
    es->tc_len += q.n;
  }
  *ids = es->tc_ids + es->tc_first[t];
  *n = (size_t)es->tc_n[t];
cleanup:
  fcm__geom_idbuf_free(ctx, &q);
  return st;
}

/* The (cell, triangle) pairs split_triangles() may clip in the cells the vertices' pieces load
 * (qcell), for every triangle that a cut crosses (crosses) or with a vertex that may lie on one
 * (maybe): a superset of those it clips, sorted. */
static fcm_status preclip_pairs(fcm_embedded_surface *es, const unsigned char *crosses,
                                const unsigned char *maybe, const unsigned char *qcell, preclip *pc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  size_t cap = 0;
  FCM_TRY(ctx, fcm__surface_cell_tree(es));
  for (fcm_index t = 0; t < es->nbt; t++) {
    const fcm_index *v = es->tri0 + 3 * t, *ids;
    size_t nids;
    if (!crosses[t] && !maybe[v[0]] && !maybe[v[1]] && !maybe[v[2]]) continue;
    FCM_TRY(ctx, tri_cells(es, t, &ids, &nids));
    for (size_t k = 0; k < nids; k++) {
      if (!qcell[ids[k]]) continue;
      if (pc->n == cap) {
        const size_t ncap = cap ? 2 * cap : 1024;
        void *q = pc->pairs;
        FCM_TRY(ctx, fcm__resize(ctx, &q, 2 * cap, 2 * ncap, sizeof(fcm_index)));
        pc->pairs = q;
        cap = ncap;
      }
      pc->pairs[2 * pc->n] = ids[k], pc->pairs[2 * pc->n + 1] = t;
      pc->n++;
    }
  }
  if (pc->n > 1) qsort(pc->pairs, pc->n, 2 * sizeof *pc->pairs, fcm__surface_cmp_pair);
  FCM_ALLOC_RAW(ctx, pc->n + 1, pc->off);
  FCM_ALLOC_RAW(ctx, pc->n + 1, pc->xoff);
  FCM_ALLOC(ctx, pc->n + 1, pc->clipped);
cleanup:
  return st;
}

/* Clip the pairs of cell c from *k on (the finder holds c's parts), but those of triangles
 * known by now to stay whole: no cut crosses them (crosses) and each vertex is either known
 * off the cuts (on_cut, once looked up: a vertex in a cell up to c, or one whose answer is
 * kept; `lookup` flags the vertices looked up in this rebuild) or not near one (maybe). A pair
 * left out here (pc->clipped[k] 0) whose triangle is split after all (a vertex found on a cut
 * that was not near one) is clipped by split_triangles(). */
static fcm_status preclip_cell(fcm_embedded_surface *es, fcm_index c, const unsigned char *crosses,
                               const unsigned char *maybe, const unsigned char *on_cut,
                               const unsigned char *lookup, preclip *pc, size_t *k)
{
  fcm_status st = FCM_OK;
  for (; *k < pc->n && pc->pairs[2 * *k] <= c; ++*k) {
    pc->off[*k] = pc->polys.n, pc->xoff[*k] = pc->polys.nx;
    if (pc->pairs[2 * *k] < c) continue;
    const fcm_index t = pc->pairs[2 * *k + 1], *v = es->tri0 + 3 * t;
    int may = crosses[t];
    for (int a = 0; a < 3 && !may; a++)
      may = lookup[v[a]] && es->cell[v[a]] > c ? maybe[v[a]] : on_cut[v[a]];
    if (!may || es->test_no_preclip) continue;
    double x[9];
    tri_coords(es, t, x);
    FCM_TRY(es->ctx, fcm__embed_finder_clip(es->finder, c, x, &pc->polys));
    pc->clipped[*k] = 1;
  }
cleanup:
  return st;
}

/* split[t] (nbt): whether a cut triangle crosses boundary triangle t (fcm__embed_finder_crosses()),
 * kept in es->cross. On rules that extend the last rebuild's (extends), whose cut triangles
 * answer as they did, only the triangles whose boxes come within es->cell_pad of a new cut
 * triangle's are tested again (the finder's tolerance is 2e-9 of a cell's size, the pad a
 * millionth of the mesh's): the others keep es->cross. */
static fcm_status cut_crossings(fcm_embedded_surface *es, int extends, unsigned char *split)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_cell_rules *R = es->space->rules;
  const fcm_aabb_tree *tris = NULL;
  fcm__idbuf ids = {NULL, 0, 0};
  unsigned char *again = NULL;
  if (extends && es->cross) {
    FCM_TRY(ctx, fcm__geom_tree(ctx, es->geom, 1, &tris));
    FCM_CHECK(tris->num_items == es->nbt, ctx, FCM_ERR_INTERNAL,
              "embedded surface: %lld boundary triangles in the geometry's tree, %lld here",
              (long long)tris->num_items, (long long)es->nbt);
    FCM_ALLOC(ctx, (size_t)es->nbt + 1, again);
    const double w = es->cell_pad;
    for (fcm_index c = es->prev_ntris; c < R->num_cut_tris; c++) {
      double lo[3], hi[3];
      for (int d = 0; d < 3; d++)
        lo[d] = R->cut_tris[c].lo[d] - w, hi[d] = R->cut_tris[c].hi[d] + w;
      FCM_TRY(ctx, fcm__geom_tree_query(ctx, tris, lo, hi, &ids));
      for (size_t k = 0; k < ids.n; k++)
        again[ids.ids[k]] = 1;
    }
  }
  for (fcm_index t = 0; t < es->nbt; t++) {
    if (again && !again[t]) {
      split[t] = es->cross[t];
      continue;
    }
    double x[9];
    int crosses;
    tri_coords(es, t, x);
    FCM_TRY(ctx, fcm__embed_finder_crosses(es->finder, x, &crosses));
    split[t] = (unsigned char)crosses;
  }
  if (!es->cross) FCM_ALLOC_RAW(ctx, (size_t)es->nbt + 1, es->cross);
  memcpy(es->cross, split, (size_t)es->nbt);
cleanup:
  fcm__free(ctx, again);
  fcm__geom_idbuf_free(ctx, &ids);
  return st;
}

/* The pieces of the boundary vertices in cells that cuts split (es->elem), and which boundary
 * triangles to split: those a cut crosses and those with a vertex on a cut (parts of two
 * pieces hold it: each triangle then takes its side). split: nbt flags. While a cell's parts
 * are at hand, the triangles split_triangles() may clip in it are clipped into *pc (a cell's
 * parts cost far more than the clipping). */
static fcm_status mark_split(fcm_embedded_surface *es, const unsigned char *changed, int extends,
                             unsigned char *split, preclip *pc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_space *s = es->space;
  fcm__embed_finder *f = es->finder;
  fcm_index *pairs = NULL, *vpiece = NULL, n = 0;
  unsigned char *on_cut = NULL, *maybe = NULL, *qcell = NULL, *lookup = NULL;
  FCM_ALLOC(ctx, (size_t)es->nb + 1, on_cut);
  FCM_ALLOC(ctx, (size_t)es->nb + 1, maybe);
  FCM_ALLOC(ctx, (size_t)es->nb + 1, lookup);
  FCM_TRY(ctx, fcm__surface_cell_tree(es)); /* cell_pad */
  FCM_ALLOC(ctx, (size_t)fcm_mesh_num_cells(es->mesh) + 1, qcell);
  FCM_ALLOC_RAW(ctx, 2 * (size_t)es->nb + 2, pairs);
  FCM_ALLOC_RAW(ctx, (size_t)es->nb + 1, vpiece);
  for (fcm_index i = 0; i < es->nb; i++) {
    const fcm_index c = es->cell[i];
    vpiece[i] = -3;
    if (s->cell_elem[c + 1] - s->cell_elem[c] <= 1) continue;
    if (es->vpiece && !changed[c] && es->vpiece[i] != -3) { /* as the last rebuild found */
      const fcm_index p = map_piece(es, c, es->vpiece[i]), e = fcm__surface_piece_element(s, c, p);
      es->elem[i] = e >= 0 ? e : fcm_space_point_element(s, c, es->xi + 3 * i);
      on_cut[i] = maybe[i] = p == -2;
      vpiece[i] = p;
      continue;
    }
    pairs[2 * n] = c, pairs[2 * n + 1] = i, n++;
    /* a vertex on a cut mostly lies on a cut triangle (the pad is far above its tolerance);
     * the pairs of one that does not are clipped by split_triangles() */
    int near = 0;
    FCM_TRY(ctx, fcm__embed_finder_near_cut(f, es->X + 3 * i, es->cell_pad, &near));
    maybe[i] = (unsigned char)near;
    lookup[i] = qcell[c] = 1;
  }
  FCM_TRY(ctx, cut_crossings(es, extends, split)); /* the cuts' triangles alone decide */
  FCM_TRY(ctx, preclip_pairs(es, split, maybe, qcell, pc));
  if (n > 1) /* one cell's parts made once */
    qsort(pairs, (size_t)n, 2 * sizeof *pairs, fcm__surface_cmp_pair);
  size_t kc = 0;
  for (fcm_index k = 0; k < n; k++) {
    const fcm_index c = pairs[2 * k], i = pairs[2 * k + 1];
    fcm_index p = -1;
    FCM_TRY(ctx, fcm__embed_finder_point(f, c, es->X + 3 * i, &p));
    const fcm_index e = fcm__surface_piece_element(s, c, p);
    es->elem[i] = e >= 0 ? e : fcm_space_point_element(s, c, es->xi + 3 * i);
    on_cut[i] = p == -2;
    vpiece[i] = p;
    if (k + 1 == n || pairs[2 * (k + 1)] != c)
      FCM_TRY(ctx, preclip_cell(es, c, split, maybe, on_cut, lookup, pc, &kc));
  }
  FCM_TRY(ctx,
          preclip_cell(es, fcm_mesh_num_cells(es->mesh), split, maybe, on_cut, lookup, pc, &kc));
  pc->off[pc->n] = pc->polys.n, pc->xoff[pc->n] = pc->polys.nx;
  fcm__free(ctx, es->vpiece);
  es->vpiece = vpiece;
  vpiece = NULL;
  for (fcm_index t = 0; t < es->nbt; t++) {
    const fcm_index *v = es->tri0 + 3 * t;
    split[t] |= on_cut[v[0]] || on_cut[v[1]] || on_cut[v[2]];
  }
cleanup:
  fcm__free(ctx, pairs);
  fcm__free(ctx, vpiece);
  fcm__free(ctx, on_cut);
  fcm__free(ctx, maybe);
  fcm__free(ctx, lookup);
  fcm__free(ctx, qcell);
  return st;
}

/* The parts of the flagged boundary triangles, cell by cell: polygon k of *polys came from
 * triangle (*src)[k] and lies in cell (*pcell)[k]. A triangle whose parts do not add up to
 * its area (it leaves the mesh) is unflagged and its parts dropped. */
static fcm_status split_triangles(fcm_embedded_surface *es, const unsigned char *changed,
                                  const preclip *pre, unsigned char *split, fcm__embed_polys *polys,
                                  fcm_index **src, fcm_index **pcell)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  fcm_index *pairs = NULL, *ps = NULL, *pc = NULL;
  size_t *poff = NULL, *xoff = NULL;
  double *area, *pxi = NULL;
  size_t n = 0, cap = 0, pcap = 0, xcap = 0;
  FCM_TRY(ctx, fcm__surface_cell_tree(es));
  for (fcm_index t = 0; t < es->nbt; t++) {
    const fcm_index *ids;
    size_t nids;
    if (!split[t]) continue;
    FCM_TRY(ctx, tri_cells(es, t, &ids, &nids));
    if (n + nids > cap) {
      size_t ncap = cap ? 2 * cap : 1024;
      while (ncap < n + nids)
        ncap *= 2;
      void *q = pairs;
      FCM_TRY(ctx, fcm__resize(ctx, &q, 2 * n, 2 * ncap, sizeof(fcm_index)));
      pairs = q;
      cap = ncap;
    }
    for (size_t k = 0; k < nids; k++, n++)
      pairs[2 * n] = ids[k], pairs[2 * n + 1] = t;
  }
  if (n > 1) /* one cell's parts made once (no pairs: a cut that split no boundary triangle) */
    qsort(pairs, n, 2 * sizeof *pairs, fcm__surface_cmp_pair);
  FCM_ALLOC_RAW(ctx, n + 1, poff);
  FCM_ALLOC_RAW(ctx, n + 1, xoff);
  for (size_t k = 0, j = 0, jp = 0; k < n; k++) {
    const fcm_index c = pairs[2 * k], t = pairs[2 * k + 1];
    const size_t n0 = polys->n;
    poff[k] = n0, xoff[k] = polys->nx;
    while (j < es->npairs && fcm__surface_cmp_pair(es->pairs + 2 * j, pairs + 2 * k) < 0)
      j++;
    while (jp < pre->n && fcm__surface_cmp_pair(pre->pairs + 2 * jp, pairs + 2 * k) < 0)
      jp++;
    const int reused =
        !changed[c] && j < es->npairs && !fcm__surface_cmp_pair(es->pairs + 2 * j, pairs + 2 * k);
    if (reused) {
      size_t first_x = es->xoff[j]; /* the parts the last rebuild clipped */
      for (size_t q = es->poff[j]; q < es->poff[j + 1]; first_x += (size_t)es->polys.nv[q++])
        FCM_TRY(ctx, fcm__embed_polys_push(ctx, polys, es->polys.x + 3 * first_x, es->polys.nv[q],
                                           map_piece(es, c, es->polys.piece[q])));
    } else if (jp < pre->n && pre->clipped[jp] &&
               !fcm__surface_cmp_pair(pre->pairs + 2 * jp, pairs + 2 * k)) {
      size_t first_x = pre->xoff[jp]; /* clipped while mark_split() had the cell's parts */
      for (size_t q = pre->off[jp]; q < pre->off[jp + 1]; first_x += (size_t)pre->polys.nv[q++])
        FCM_TRY(ctx, fcm__embed_polys_push(ctx, polys, pre->polys.x + 3 * first_x, pre->polys.nv[q],
                                           pre->polys.piece[q]));
    } else {
      double x[9];
      tri_coords(es, t, x);
      FCM_TRY(ctx, fcm__embed_finder_clip(es->finder, c, x, polys));
    }
    if (polys->nx > xcap) {
      const size_t ncap = FCM_MAX(2 * xcap, polys->nx + 1024);
      void *a = pxi;
      FCM_TRY(ctx, fcm__resize(ctx, &a, 3 * xcap, 3 * ncap, sizeof(double)));
      pxi = a;
      xcap = ncap;
    }
    if (reused && es->pxi && polys->nx > xoff[k])
      memcpy(pxi + 3 * xoff[k], es->pxi + 3 * es->xoff[j], 3 * (polys->nx - xoff[k]) * sizeof *pxi);
    else
      for (size_t q = 3 * xoff[k]; q < 3 * polys->nx; q++)
        pxi[q] = NAN;
    if (polys->n > pcap) {
      const size_t ncap = FCM_MAX(2 * pcap, polys->n + 256);
      void *a = ps, *b = pc;
      FCM_TRY(ctx, fcm__resize(ctx, &a, pcap, ncap, sizeof(fcm_index)));
      ps = a;
      FCM_TRY(ctx, fcm__resize(ctx, &b, pcap, ncap, sizeof(fcm_index)));
      pc = b;
      pcap = ncap;
    }
    for (size_t q = n0; q < polys->n; q++)
      ps[q] = t, pc[q] = c;
  }
  poff[n] = polys->n, xoff[n] = polys->nx;
  if (!pxi) FCM_ALLOC_RAW(ctx, 3, pxi);
  FCM_TRY(ctx, cache_parts(es, polys, &pairs, n, &poff, &xoff, &pxi));
  /* the parts cover each triangle: else it stays whole (es->tarea: zero between rebuilds, so
   * that its pages are not zeroed again each time) */
  if (!es->tarea) FCM_ALLOC(ctx, (size_t)es->nbt + 1, es->tarea);
  area = es->tarea;
  for (size_t j = 0, off = 0; j < polys->n; off += (size_t)polys->nv[j], j++) {
    const double *x = polys->x + 3 * off;
    for (int k = 1; k + 1 < polys->nv[j]; k++)
      area[ps[j]] += tri_area(x, x + 3 * k, x + 3 * (k + 1));
  }
  for (fcm_index t = 0; t < es->nbt; t++) {
    if (!split[t]) continue;
    double x[9];
    tri_coords(es, t, x);
    const double a = tri_area(x, x + 3, x + 6);
    if (!(fabs(area[t] - a) <= SPLIT_AREA_RTOL * a)) split[t] = 0;
  }
  for (size_t j = 0; j < polys->n; j++)
    area[ps[j]] = 0.0;
  *src = ps, *pcell = pc;
  ps = pc = NULL;
cleanup:
  fcm__free(ctx, pairs);
  fcm__free(ctx, poff);
  fcm__free(ctx, xoff);
  fcm__free(ctx, ps);
  fcm__free(ctx, pc);
  fcm__free(ctx, pxi);
  return st;
}

fcm_status fcm__surface_split(fcm_embedded_surface *es, unsigned char *split,
                              fcm__embed_polys *polys, fcm_index **src, fcm_index **pcell)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = es->ctx;
  const fcm_cell_rules *rules = es->space->rules;
  unsigned char *changed = NULL;
  preclip pre;
  memset(&pre, 0, sizeof pre);
  if (!es->finder) FCM_TRY(ctx, fcm__embed_finder_create(ctx, es->mesh, es->geom, &es->finder));
  FCM_TRY(ctx, fcm__embed_finder_set_rules(es->finder, rules));
  FCM_ALLOC_RAW(ctx, (size_t)rules->num_cells + 1, changed);
  int extends = 0;
  FCM_TRY(ctx, changed_cells(es, changed, &extends));
  FCM_TRY(ctx, mark_split(es, changed, extends, split, &pre));
  FCM_TRY(ctx, split_triangles(es, changed, &pre, split, polys, src, pcell));
  FCM_TRY(ctx, cache_rules(es));
cleanup:
  fcm__free(ctx, changed);
  preclip_free(ctx, &pre);
  return st;
}
