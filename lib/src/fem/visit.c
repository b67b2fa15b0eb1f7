/* Assembly's visiting order: blocks of FCM__SPACE_BLOCK cells in the Morton order of their
 * centres, each block's local elements cell by cell, and the blocks' colouring by the mesh
 * nodes they touch (struct fcm_space, fem_impl.h). They depend on the active (local) cells
 * and the constrained elements' copies alone, so a cut space takes them from the space before
 * the cut. */
#include "fem/fem_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_COLORS = 4096 };

/* The element at local position le (a full space: le itself). */
static fcm_index local_elem(const fcm_space *s, fcm_index le)
{
  return s->local_elem ? s->local_elem[le] : le;
}

/* A cell with the Morton key of its centre. */
typedef struct morton_cell {
  uint64_t key;
  fcm_index cell;
} morton_cell;

static int cmp_morton(const void *a, const void *b)
{
  const morton_cell *x = a, *y = b;
  if (x->key != y->key) return (x->key > y->key) - (x->key < y->key);
  return (x->cell > y->cell) - (x->cell < y->cell);
}

/* The 21 low bits of v spread to every third bit. */
static uint64_t spread3(uint64_t v)
{
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

uint64_t fcm__morton_key(const double x[3], const double lo[3], const double hi[3])
{
  uint64_t key = 0;
  for (int d = 0; d < 3; d++) {
    const double t = hi[d] > lo[d] ? (x[d] - lo[d]) / (hi[d] - lo[d]) : 0.0;
    key |= spread3((uint64_t)(fmin(fmax(t, 0.0), 1.0) * 2097151.0)) << d;
  }
  return key;
}

/* 1 when cell c takes part in the blocks: active, and local in a local space. */
static int block_cell(const fcm_space *s, fcm_index c)
{
  return s->cell_local ? s->cell_local[c] != 0 : s->active[c] != 0;
}

/* block_cells: the cells of the blocks in the Morton (Z-curve) order of their centres on a
 * 2^21 grid over the centres' bounding box (ties by cell id), so that runs of
 * FCM__SPACE_BLOCK of them are compact clusters. */
static fcm_status build_block_cells(fcm_space *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const int nn = s->nn;
  fcm_index nbc = 0;
  morton_cell *m = NULL;
  double *ctr = NULL, X[3 * FCM_ELEMENT_MAX_NODES], lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL},
         hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (fcm_index c = 0; c < s->num_cells; c++)
    nbc += block_cell(s, c);
  FCM_ALLOC(ctx, nbc + 1, m);
  FCM_ALLOC(ctx, 3 * nbc + 1, ctr);
  for (fcm_index c = 0, i = 0; c < s->num_cells; c++) {
    if (!block_cell(s, c)) continue;
    fcm_mesh_cell_coords(s->mesh, c, X);
    for (int d = 0; d < 3; d++) {
      double x = 0.0;
      for (int a = 0; a < nn; a++)
        x += X[3 * a + d];
      ctr[3 * i + d] = x / nn;
      lo[d] = fmin(lo[d], x / nn), hi[d] = fmax(hi[d], x / nn);
    }
    m[i++].cell = c;
  }
  for (fcm_index i = 0; i < nbc; i++)
    m[i].key = fcm__morton_key(ctr + 3 * i, lo, hi);
  qsort(m, (size_t)nbc, sizeof *m, cmp_morton);
  FCM_ALLOC(ctx, nbc + 1, s->block_cells);
  for (fcm_index i = 0; i < nbc; i++)
    s->block_cells[i] = m[i].cell;
  s->num_block_cells = nbc;
  s->num_blocks = (nbc + FCM__SPACE_BLOCK - 1) / FCM__SPACE_BLOCK;
cleanup:
  fcm__free(ctx, m);
  fcm__free(ctx, ctr);
  return st;
}

/* block_ptr and block_elems from block_cells: each block's cells' local elements, cell by
 * cell. */
static fcm_status build_block_elems(fcm_space *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index nb = s->num_blocks, nbc = s->num_block_cells;
  fcm_index *first = NULL, j = 0; /* a local space: the first local position of each cell */
  if (s->local_elem) {
    FCM_ALLOC_RAW(ctx, (size_t)s->num_cells + 1, first);
    for (fcm_index le = s->num_local_elems - 1; le >= 0; le--)
      first[s->elem_cell[s->local_elem[le]]] = le;
  }
  FCM_ALLOC_RAW(ctx, (size_t)nb + 1, s->block_ptr);
  FCM_ALLOC_RAW(ctx, (size_t)s->num_local_elems + 1, s->block_elems);
  s->block_ptr[0] = 0;
  for (fcm_index b = 0; b < nb; b++) {
    for (fcm_index i = b * FCM__SPACE_BLOCK; i < FCM_MIN(nbc, (b + 1) * FCM__SPACE_BLOCK); i++) {
      const fcm_index c = s->block_cells[i], n = s->cell_elem[c + 1] - s->cell_elem[c];
      const fcm_index e0 = first ? first[c] : s->cell_elem[c];
      FCM_CHECK(j + n <= s->num_local_elems, ctx, FCM_ERR_INTERNAL,
                "space: the blocks' cells hold more than the %lld local elements",
                (long long)s->num_local_elems);
      for (fcm_index e = 0; e < n; e++)
        s->block_elems[j++] = e0 + e;
    }
    s->block_ptr[b + 1] = j;
  }
  FCM_CHECK(j == s->num_local_elems, ctx, FCM_ERR_INTERNAL,
            "space: the blocks hold %lld of the %lld local elements", (long long)j,
            (long long)s->num_local_elems);
cleanup:
  fcm__free(ctx, first);
  return st;
}

/* The mesh nodes block b touches, each once (mark[n] == b once seen), into nodes (NULL:
 * counted only): its cells' nodes and the nodes of the copies its elements use in another
 * node's place (constrained copies, node_of). Returns their number. */
static fcm_index block_nodes(const fcm_space *s, fcm_index b, const fcm_index *node_of,
                             fcm_index *mark, fcm_index *nodes)
{
  const fcm_index *cells = fcm_mesh_cells(s->mesh);
  const fcm_index nbc = s->num_block_cells;
  fcm_index cnt = 0;
  for (fcm_index i = b * FCM__SPACE_BLOCK; i < FCM_MIN(nbc, (b + 1) * FCM__SPACE_BLOCK); i++)
    for (int a = 0; a < s->nn; a++) {
      const fcm_index n = cells[s->block_cells[i] * s->nn + a];
      if (mark[n] == b) continue;
      mark[n] = b;
      if (nodes) nodes[cnt] = n;
      cnt++;
    }
  for (fcm_index j = s->block_ptr[b]; node_of && j < s->block_ptr[b + 1]; j++) {
    const fcm_index e = local_elem(s, s->block_elems[j]);
    for (int a = 0; a < s->nn; a++) {
      if (!s->elem_con[e * s->nn + a]) continue;
      const fcm_index n = node_of[s->elem_dof[e * s->nn + a] / 3];
      if (mark[n] == b) continue;
      mark[n] = b;
      if (nodes) nodes[cnt] = n;
      cnt++;
    }
  }
  return cnt;
}

/* The nodes of each block (bn_ptr, bn) and the blocks at each node (nb_ptr, nbl, ascending). */
typedef struct block_graph {
  fcm_index *bn_ptr, *bn, *nb_ptr, *nbl;
} block_graph;

static fcm_status build_block_graph(const fcm_space *s, block_graph *g)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index nb = s->num_blocks, np = s->num_nodes;
  fcm_index *mark = NULL, *node_of = NULL, *fill = NULL;
  FCM_ALLOC_RAW(ctx, (size_t)np + 1, mark);
  if (s->elem_con) { /* the node of each copy */
    FCM_ALLOC_RAW(ctx, (size_t)s->num_dofs / 3 + 1, node_of);
    for (fcm_index n = 0; n < np; n++)
      for (fcm_index c = 0; c < s->node_ncopy[n]; c++)
        node_of[s->node_dof[n] / 3 + c] = n;
  }
  for (fcm_index n = 0; n < np; n++)
    mark[n] = -1;
  FCM_ALLOC(ctx, nb + 1, g->bn_ptr);
  for (fcm_index b = 0; b < nb; b++)
    g->bn_ptr[b + 1] = g->bn_ptr[b] + block_nodes(s, b, node_of, mark, NULL);
  FCM_ALLOC_RAW(ctx, (size_t)g->bn_ptr[nb] + 1, g->bn);
  FCM_ALLOC(ctx, np + 1, g->nb_ptr);
  for (fcm_index n = 0; n < np; n++)
    mark[n] = -1;
  for (fcm_index b = 0; b < nb; b++) {
    block_nodes(s, b, node_of, mark, g->bn + g->bn_ptr[b]);
    for (fcm_index i = g->bn_ptr[b]; i < g->bn_ptr[b + 1]; i++)
      g->nb_ptr[g->bn[i] + 1]++;
  }
  for (fcm_index n = 0; n < np; n++)
    g->nb_ptr[n + 1] += g->nb_ptr[n];
  FCM_ALLOC_RAW(ctx, (size_t)g->nb_ptr[np] + 1, g->nbl);
  FCM_ALLOC(ctx, np + 1, fill);
  for (fcm_index b = 0; b < nb; b++)
    for (fcm_index i = g->bn_ptr[b]; i < g->bn_ptr[b + 1]; i++)
      g->nbl[g->nb_ptr[g->bn[i]] + fill[g->bn[i]]++] = b;
cleanup:
  fcm__free(ctx, mark);
  fcm__free(ctx, node_of);
  fcm__free(ctx, fill);
  return st;
}

static void free_block_graph(fcm_ctx *ctx, block_graph *g)
{
  fcm__free(ctx, g->bn_ptr);
  fcm__free(ctx, g->bn);
  fcm__free(ctx, g->nb_ptr);
  fcm__free(ctx, g->nbl);
}

/* Greedy colouring of the blocks: a block takes the smallest colour not used by a block
 * touching one of its nodes (block_nodes()). Two elements sharing a copy touch its node, so
 * blocks of one colour share no copy. */
static fcm_status colour_blocks(fcm_space *s)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index nb = s->num_blocks;
  int *color = NULL, ncol = 0;
  fcm_index *forbid = NULL, *fill = NULL;
  block_graph g;
  memset(&g, 0, sizeof g);
  FCM_TRY(ctx, build_block_graph(s, &g));
  FCM_ALLOC(ctx, nb + 1, color);
  FCM_ALLOC(ctx, MAX_COLORS, forbid);
  for (int k = 0; k < MAX_COLORS; k++)
    forbid[k] = -1;
  for (fcm_index b = 0; b < nb; b++)
    color[b] = -1;
  for (fcm_index b = 0; b < nb; b++) {
    for (fcm_index i = g.bn_ptr[b]; i < g.bn_ptr[b + 1]; i++) {
      const fcm_index n = g.bn[i];
      for (fcm_index j = g.nb_ptr[n]; j < g.nb_ptr[n + 1] && g.nbl[j] < b; j++)
        forbid[color[g.nbl[j]]] = b;
    }
    int k = 0;
    while (k < MAX_COLORS && forbid[k] == b)
      k++;
    FCM_CHECK(k < MAX_COLORS, ctx, FCM_ERR_UNSUPPORTED,
              "space: element block %lld needs more than %d colours (a node shared by too many "
              "cells)",
              (long long)b, MAX_COLORS);
    color[b] = k;
    ncol = FCM_MAX(ncol, k + 1);
  }
  s->num_block_colors = ncol;
  FCM_ALLOC(ctx, ncol + 1, s->block_color_ptr);
  for (fcm_index b = 0; b < nb; b++)
    s->block_color_ptr[color[b] + 1]++;
  for (int k = 0; k < ncol; k++)
    s->block_color_ptr[k + 1] += s->block_color_ptr[k];
  FCM_ALLOC(ctx, nb + 1, s->block_list);
  FCM_ALLOC(ctx, ncol + 1, fill);
  for (fcm_index b = 0; b < nb; b++)
    s->block_list[s->block_color_ptr[color[b]] + fill[color[b]]++] = b;
cleanup:
  free_block_graph(ctx, &g);
  fcm__free(ctx, color);
  fcm__free(ctx, forbid);
  fcm__free(ctx, fill);
  return st;
}

/* 1 when the full space s after a cut may take the blocks of the full space `from`: the same
 * active cells (so the same block cells in the same order), neither with constrained copies
 * (so the same nodes per block and the same colours). */
static int can_keep_blocks(const fcm_space *s, const fcm_space *from)
{
  return from && from->block_cells && from->block_list && !from->local_elem && !s->local_elem &&
         !from->cell_local && !s->cell_local && !from->elem_con && !s->elem_con &&
         from->num_cells == s->num_cells &&
         memcmp(from->active, s->active, (size_t)s->num_cells) == 0;
}

fcm_status fcm__space_build_blocks(fcm_space *s, const fcm_space *from)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  s->blocks_kept = can_keep_blocks(s, from);
  if (s->blocks_kept) {
    const int ncol = from->num_block_colors;
    s->num_block_cells = from->num_block_cells, s->num_blocks = from->num_blocks;
    s->num_block_colors = ncol;
    FCM_ALLOC_RAW(ctx, (size_t)s->num_block_cells + 1, s->block_cells);
    FCM_ALLOC_RAW(ctx, (size_t)ncol + 1, s->block_color_ptr);
    FCM_ALLOC_RAW(ctx, (size_t)s->num_blocks + 1, s->block_list);
    memcpy(s->block_cells, from->block_cells, sizeof(fcm_index) * (size_t)s->num_block_cells);
    memcpy(s->block_color_ptr, from->block_color_ptr, sizeof(fcm_index) * ((size_t)ncol + 1));
    memcpy(s->block_list, from->block_list, sizeof(fcm_index) * (size_t)s->num_blocks);
    FCM_TRY(ctx, build_block_elems(s));
  } else {
    FCM_TRY(ctx, build_block_cells(s));
    FCM_TRY(ctx, build_block_elems(s));
    FCM_TRY(ctx, colour_blocks(s));
  }
cleanup:
  return st;
}
