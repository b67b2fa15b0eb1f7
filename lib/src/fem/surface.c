/* The embedded surface for output: the boundary triangles of the geometry located in a space,
 * every point moving with the element (the material piece) that holds it, and both sides of
 * the cut faces. Where cuts split the body, a point goes to the piece whose material holds
 * it, and a boundary triangle that a cut crosses is replaced by its parts, split exactly as
 * the cut cells' pieces are (the same parts, made again: fcm__embed_finder), so no triangle
 * joins points of two pieces. Triangles no cut crosses keep their vertices and order. */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* A split triangle's parts must add up to its area to this relative tolerance; otherwise (a
 * triangle partly outside the mesh) it is kept whole. */
#define SPLIT_AREA_RTOL 1e-9

/* Points and triangles a surface is made with room for, per boundary vertex and triangle
 * (surface_reserve()): Dick's Bunny 2 holds 2.8 points and 1.3 triangles per boundary vertex
 * and triangle after its four cuts. */
#define ROOM_POINTS    3
#define ROOM_TRIANGLES 2

/* The element of cell c integrating rules piece p; -1 when none does. */
static fcm_index piece_element(const fcm_space *s, fcm_index c, fcm_index p)
{
  if (p < 0) return -1;
  for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++)
    if (s->elem_piece[e] == p) return e;
  return -1;
}

static int cmp_pair(const void *a, const void *b)
{
  const fcm_index *x = a, *y = b;
  if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
  return (x[1] > y[1]) - (x[1] < y[1]);
}

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

/* The search tree of the mesh's cells, and a millionth of the mesh's size. */
static fcm_status cell_tree(fcm_embedded_surface *es)
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
  FCM_TRY(ctx, cell_tree(es));
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
static void cache_clear(fcm_embedded_surface *es)
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
  if (st != FCM_OK) cache_clear(es);
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
  memcpy(copy.x, polys->x, 3 * polys->nx * sizeof *copy.x);
  memcpy(copy.nv, polys->nv, polys->n * sizeof *copy.nv);
  memcpy(copy.piece, polys->piece, polys->n * sizeof *copy.piece);
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

/* Append polygon j of `from` (its piece p) to `to`. */
static fcm_status polys_append(fcm_ctx *ctx, fcm__embed_polys *to, const fcm__embed_polys *from,
                               size_t j, size_t first_x, fcm_index p)
{
  fcm_status st = FCM_OK;
  const int n = from->nv[j];
  if (to->n + 1 > to->cap) {
    const size_t cap = to->cap ? 2 * to->cap : 64;
    void *a = to->nv, *b = to->piece;
    FCM_TRY(ctx, fcm__resize(ctx, &a, to->n, cap, sizeof(int)));
    to->nv = a;
    FCM_TRY(ctx, fcm__resize(ctx, &b, to->n, cap, sizeof(fcm_index)));
    to->piece = b;
    to->cap = cap;
  }
  if (to->nx + (size_t)n > to->capx) {
    size_t cap = to->capx ? 2 * to->capx : 256;
    while (cap < to->nx + (size_t)n)
      cap *= 2;
    void *a = to->x;
    FCM_TRY(ctx, fcm__resize(ctx, &a, 3 * to->nx, 3 * cap, sizeof(double)));
    to->x = a;
    to->capx = cap;
  }
  memcpy(to->x + 3 * to->nx, from->x + 3 * first_x, 3 * (size_t)n * sizeof *to->x);
  to->nv[to->n] = n;
  to->piece[to->n] = p;
  to->n++;
  to->nx += (size_t)n;
cleanup:
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
  FCM_TRY(ctx, cell_tree(es));
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
  if (pc->n > 1) qsort(pc->pairs, pc->n, 2 * sizeof *pc->pairs, cmp_pair);
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
  FCM_TRY(ctx, cell_tree(es)); /* cell_pad */
  FCM_ALLOC(ctx, (size_t)fcm_mesh_num_cells(es->mesh) + 1, qcell);
  FCM_ALLOC_RAW(ctx, 2 * (size_t)es->nb + 2, pairs);
  FCM_ALLOC_RAW(ctx, (size_t)es->nb + 1, vpiece);
  for (fcm_index i = 0; i < es->nb; i++) {
    const fcm_index c = es->cell[i];
    vpiece[i] = -3;
    if (s->cell_elem[c + 1] - s->cell_elem[c] <= 1) continue;
    if (es->vpiece && !changed[c] && es->vpiece[i] != -3) { /* as the last rebuild found */
      const fcm_index p = map_piece(es, c, es->vpiece[i]), e = piece_element(s, c, p);
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
  qsort(pairs, (size_t)n, 2 * sizeof *pairs, cmp_pair); /* one cell's parts made once */
  size_t kc = 0;
  for (fcm_index k = 0; k < n; k++) {
    const fcm_index c = pairs[2 * k], i = pairs[2 * k + 1];
    fcm_index p = -1;
    FCM_TRY(ctx, fcm__embed_finder_point(f, c, es->X + 3 * i, &p));
    const fcm_index e = piece_element(s, c, p);
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
  FCM_TRY(ctx, cell_tree(es));
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
  qsort(pairs, n, 2 * sizeof *pairs, cmp_pair); /* one cell's parts made once */
  FCM_ALLOC_RAW(ctx, n + 1, poff);
  FCM_ALLOC_RAW(ctx, n + 1, xoff);
  for (size_t k = 0, j = 0, jp = 0; k < n; k++) {
    const fcm_index c = pairs[2 * k], t = pairs[2 * k + 1];
    const size_t n0 = polys->n;
    poff[k] = n0, xoff[k] = polys->nx;
    while (j < es->npairs && cmp_pair(es->pairs + 2 * j, pairs + 2 * k) < 0)
      j++;
    while (jp < pre->n && cmp_pair(pre->pairs + 2 * jp, pairs + 2 * k) < 0)
      jp++;
    const int reused = !changed[c] && j < es->npairs && !cmp_pair(es->pairs + 2 * j, pairs + 2 * k);
    if (reused) {
      size_t first_x = es->xoff[j]; /* the parts the last rebuild clipped */
      for (size_t q = es->poff[j]; q < es->poff[j + 1]; first_x += (size_t)es->polys.nv[q++])
        FCM_TRY(ctx, polys_append(ctx, polys, &es->polys, q, first_x,
                                  map_piece(es, c, es->polys.piece[q])));
    } else if (jp < pre->n && pre->clipped[jp] && !cmp_pair(pre->pairs + 2 * jp, pairs + 2 * k)) {
      size_t first_x = pre->xoff[jp]; /* clipped while mark_split() had the cell's parts */
      for (size_t q = pre->off[jp]; q < pre->off[jp + 1]; first_x += (size_t)pre->polys.nv[q++])
        FCM_TRY(ctx, polys_append(ctx, polys, &pre->polys, q, first_x, pre->polys.piece[q]));
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
  FCM_TRY(es->ctx, cell_tree(es));
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
    es->elem[i] = piece_element(s, c, piece[i - v]);
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
  unsigned char *split = NULL, *changed = NULL;
  fcm__embed_polys polys = {NULL, NULL, NULL, 0, 0, 0, 0};
  preclip pre;
  fcm_index *src = NULL, *pcell = NULL, *order = NULL, *ppiece = NULL, *by_tri = NULL;
  memset(&pre, 0, sizeof pre);
  size_t *first_x = NULL, *xat = NULL;
  fcm_index ncf = 0;
  for (fcm_index p = 0; p < npieces; p++)
    ncf += fcm_cell_rules_get_piece_cut_faces(rules, p, NULL);
  const int cuts = rules && fcm_cell_rules_num_cuts(rules) > 0;
  for (fcm_index i = 0; i < es->nb; i++) {
    const fcm_index c = es->cell[i];
    es->flag[i] = 0;
    /* with cuts, mark_split() gives the vertices in cells of several elements theirs */
    if (cuts && c >= 0 && c < s->num_cells && s->cell_elem[c + 1] - s->cell_elem[c] > 1) continue;
    es->elem[i] = fcm_space_point_element(s, c, es->xi + 3 * i);
    FCM_CHECK(es->elem[i] >= 0, ctx, FCM_ERR_ARG,
              "embedded surface: vertex %lld lies in cell %lld, which has no element in this "
              "space (another mesh or active set?)",
              (long long)i, (long long)es->cell[i]);
  }
  FCM_ALLOC(ctx, (size_t)es->nbt + 1, split);
  if (rules && fcm_cell_rules_num_cuts(rules) > 0) {
    if (!es->finder) FCM_TRY(ctx, fcm__embed_finder_create(ctx, es->mesh, es->geom, &es->finder));
    FCM_TRY(ctx, fcm__embed_finder_set_rules(es->finder, rules));
    FCM_ALLOC_RAW(ctx, (size_t)rules->num_cells + 1, changed);
    int extends = 0;
    FCM_TRY(ctx, changed_cells(es, changed, &extends));
    FCM_TRY(ctx, mark_split(es, changed, extends, split, &pre));
    FCM_TRY(ctx, split_triangles(es, changed, &pre, split, &polys, &src, &pcell));
    FCM_TRY(ctx, cache_rules(es));
  } else {
    cache_clear(es);
  }
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
  if (nkeep > 1) qsort(by_tri, (size_t)nkeep, 2 * sizeof *by_tri, cmp_pair);
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
    const fcm_index c = fcm_cell_rules_piece_cell(rules, p), e = piece_element(s, c, p);
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
  if (st != FCM_OK) cache_clear(es);
  /* the finder's parts and cut triangles' tree are the rules': freed per call (per cut); what
   * it holds for the mesh and geometry stays, as does the cells' tree (the mesh's, which a new
   * space keeps: fcm_embedded_surface_set_space()) */
  fcm__embed_finder_release(es->finder);
  fcm__free(ctx, split);
  fcm__free(ctx, changed);
  fcm__free(ctx, src);
  fcm__free(ctx, pcell);
  fcm__free(ctx, order);
  fcm__free(ctx, by_tri);
  fcm__free(ctx, first_x);
  fcm__free(ctx, ppiece);
  fcm__free(ctx, xat);
  fcm__embed_polys_free(ctx, &polys);
  preclip_free(ctx, &pre);
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
  cache_clear(es);
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
