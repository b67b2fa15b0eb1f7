/* The topology of a space built once after its numbering: the copies' incidence, the copy
 * graph, the scalar CSR pattern with per-element scatter offsets, the element colouring and
 * assembly's blocks (visit.c); of every element or of the local cells only. */
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* qsort comparator for fcm_index. */
static int cmp_index(const void *a, const void *b)
{
  fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

/* The element at local position le (a full space: le itself). */
static fcm_index local_elem(const fcm_space *s, fcm_index le)
{
  return s->local_elem ? s->local_elem[le] : le;
}

void fcm__space_sort_indices(fcm_index *list, fcm_index n)
{
  if (n > 32) {
    qsort(list, (size_t)n, sizeof *list, cmp_index);
    return;
  }
  fcm__insertion_sort(list, n);
}

/* Copy -> elements incidence over the local topology: for each of the num_local_copies copies,
 * the local positions of the local elements using it at any local node (ascending, each once),
 * as CSR. g2l maps a copy rank to its local position (NULL: the identity, a full space). The
 * threads count and place the elements in any order; each list is then sorted, so the lists
 * do not depend on the thread count. */
static fcm_status build_copy_incidence(fcm_space *s, const fcm_index *g2l, fcm_index **ptr_out,
                                       fcm_index **list_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_local_copies, nn = s->nn, ne = s->num_local_elems;
  const int nt = fcm_ctx_num_threads(ctx);
  fcm_index *ptr = NULL, *list = NULL, *fill = NULL;
  FCM_ALLOC(ctx, ncopy + 1, ptr);
  FCM_ALLOC_RAW(ctx, ncopy + 1, fill);
  for (int pass = 0; pass < 2; pass++) {
#pragma omp parallel for num_threads(nt) schedule(static)
    for (fcm_index le = 0; le < ne; le++) {
      const fcm_index *ed = s->elem_dof + local_elem(s, le) * nn;
      for (int a = 0; a < nn; a++) {
        const fcm_index k = g2l ? g2l[ed[a] / 3] : ed[a] / 3;
        int dup = 0; /* an element may use a copy at two local nodes (constrained copies) */
        for (int b = 0; b < a && !dup; b++)
          dup = ed[b] / 3 == ed[a] / 3;
        if (dup) continue;
        if (pass) {
          fcm_index at;
#pragma omp atomic capture
          at = fill[k]++;
          list[at] = le;
        } else {
#pragma omp atomic
          ptr[k + 1]++;
        }
      }
    }
    if (!pass) {
      for (fcm_index k = 0; k < ncopy; k++)
        ptr[k + 1] += ptr[k];
      memcpy(fill, ptr, sizeof *fill * (size_t)ncopy);
      FCM_ALLOC_RAW(ctx, ptr[ncopy] + 1, list);
    }
  }
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index k = 0; k < ncopy; k++)
    fcm__space_sort_indices(list + ptr[k], ptr[k + 1] - ptr[k]);
  *ptr_out = ptr, *list_out = list;
  ptr = list = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, list);
  fcm__free(ctx, fill);
  return st;
}

/* The row of local copy k in the copy graph: the ranks (global) of the copies sharing a local
 * element with it, sorted into row when row is not NULL; returns their number. mark[] (per
 * local copy) holds k for the copies seen. */
static fcm_index copy_row(const fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                          const fcm_index *cinc, fcm_index k, fcm_index *mark, fcm_index *row)
{
  const fcm_index nn = s->nn;
  fcm_index cnt = 0;
  for (fcm_index i = cptr[k]; i < cptr[k + 1]; i++) {
    const fcm_index e = local_elem(s, cinc[i]);
    for (int b = 0; b < nn; b++) {
      const fcm_index m = s->elem_dof[e * nn + b] / 3, lm = g2l ? g2l[m] : m;
      if (mark[lm] == k) continue;
      mark[lm] = k;
      if (row) row[cnt] = m;
      cnt++;
    }
  }
  if (row) qsort(row, (size_t)cnt, sizeof *row, cmp_index);
  return cnt;
}

/* Copy graph over the local topology: for each local copy, the ranks (global) of the copies
 * sharing a local element with it, sorted; with a cut map m (a cut space patched from `from`)
 * a kept copy's row is its parent's row mapped to the children (sorted again only where the
 * map reorders it: copy_kept 1). */
struct cut_map;
static fcm_status node_graph(fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                             const fcm_index *cinc, const fcm_space *from, struct cut_map *m);

/* The column indices of the scalar pattern's rows (row_ptr made): three per neighbour in the
 * copy graph. */
static void fill_columns(fcm_space *s)
{
  const fcm_index nact = s->num_local_copies;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(s->ctx)) schedule(static)
  for (fcm_index k = 0; k < nact; k++)
    for (int i = 0; i < 3; i++) {
      int *cols = s->col_idx + s->row_ptr[3 * k + i];
      for (fcm_index e = s->node_ptr[k]; e < s->node_ptr[k + 1]; e++)
        for (int j = 0; j < 3; j++)
          *cols++ = (int)(3 * s->node_adj[e] + j);
    }
}

/* The scalar pattern's rows from the copy graph (the three rows of each local copy; global
 * columns), the columns in give's block when it fits (holds them and is at most twice their
 * size: give is left without columns, s->col_from names it), else in a new one with room. */
static fcm_status build_pattern_rows(fcm_space *s, fcm_space *give)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index nact = s->num_local_copies, nrow = 3 * nact;
  FCM_ALLOC_RAW(ctx, nrow + 1, s->row_ptr);
  s->row_ptr[0] = 0;
  /* the rows of copy k start at 9 node_ptr[k] (three rows of three columns a neighbour) */
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(static)
  for (fcm_index k = 0; k < nact; k++) {
    const fcm_index deg = s->node_ptr[k + 1] - s->node_ptr[k];
    for (int i = 0; i < 3; i++)
      s->row_ptr[3 * k + i + 1] = 9 * s->node_ptr[k] + 3 * (i + 1) * deg;
  }
  const size_t nnz = (size_t)s->row_ptr[nrow];
  if (give && give->col_idx && !give->col_from && nnz <= give->col_cap &&
      nnz >= give->col_cap / 2) {
    s->col_idx = give->col_idx, s->col_cap = give->col_cap, s->col_from = give;
    give->col_idx = NULL, give->col_cap = 0;
  } else {
    /* a quarter more room for a later cut's larger pattern (fcm__space_create_cut_take()):
     * address space only, for a large block, until that pattern fills it */
    s->col_cap = nnz + nnz / 4;
    FCM_ALLOC_RAW(ctx, s->col_cap + 1, s->col_idx); /* every used entry is written below */
  }
  fill_columns(s);
cleanup:
  return st;
}

/* The offsets of local element el at its node a: the position of each of its copies in the
 * graph row of the copy at node a (ka its local position). */
static void node_offsets(const fcm_space *s, fcm_index el, int a, fcm_index ka)
{
  const fcm_index *ed = s->elem_dof + local_elem(s, el) * s->nn;
  int *off = s->elem_off + ((size_t)el * s->nn + a) * s->nn;
  const fcm_index *row = s->node_adj + s->node_ptr[ka];
  const size_t len = (size_t)(s->node_ptr[ka + 1] - s->node_ptr[ka]);
  for (int b = 0; b < s->nn; b++) {
    fcm_index kb = ed[b] / 3;
    const fcm_index *hit = bsearch(&kb, row, len, sizeof *row, cmp_index);
    off[b] = hit ? (int)(hit - row) : -1; /* every copy of the element is in the row */
  }
}

/* Scalar pattern from the copy graph, and the offsets of the local elements (and, for a local
 * space, their copies' local positions). */
static fcm_status build_pattern(fcm_space *s, const fcm_index *g2l)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  FCM_TRY(ctx, build_pattern_rows(s, NULL));
  FCM_ALLOC(ctx, (size_t)s->num_local_elems * s->nn * s->nn + 1, s->elem_off);
  if (g2l) FCM_ALLOC(ctx, (size_t)s->num_local_elems * s->nn + 1, s->elem_lcopy);
  for (fcm_index el = 0; el < s->num_local_elems; el++) {
    const fcm_index *ed = s->elem_dof + local_elem(s, el) * s->nn;
    for (int a = 0; a < s->nn; a++) {
      fcm_index ka = g2l ? g2l[ed[a] / 3] : ed[a] / 3;
      if (g2l) s->elem_lcopy[(size_t)el * s->nn + a] = (int)ka;
      node_offsets(s, el, a, ka);
    }
  }
cleanup:
  return st;
}

/* The colour lists (color_ptr, color_elems) of the colours color[le] of the local elements. */
static fcm_status color_lists(fcm_space *s, const int *color, int ncol)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ne = s->num_local_elems;
  fcm_index *fill = NULL;
  s->num_colors = ncol;
  FCM_ALLOC(ctx, ncol + 1, s->color_ptr);
  for (fcm_index e = 0; e < ne; e++)
    s->color_ptr[color[e] + 1]++;
  for (int k = 0; k < ncol; k++)
    s->color_ptr[k + 1] += s->color_ptr[k];
  FCM_ALLOC(ctx, s->color_ptr[ncol] + 1, s->color_elems);
  FCM_ALLOC(ctx, ncol + 1, fill);
  for (fcm_index e = 0; e < ne; e++)
    s->color_elems[s->color_ptr[color[e]] + fill[color[e]]++] = e;
cleanup:
  fcm__free(ctx, fill);
  return st;
}

enum { MAX_COLORS = 4096 };

/* The greedy colour of local element e: the smallest colour no element sharing a copy with it
 * has yet (color[] -1 for the elements not coloured yet); forbid holds MAX_COLORS marks. */
static fcm_status greedy_color(const fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                               const fcm_index *cinc, fcm_index e, int *color, fcm_index *forbid)
{
  fcm_status st = FCM_OK;
  const fcm_index *ed = s->elem_dof + local_elem(s, e) * s->nn;
  for (int a = 0; a < s->nn; a++) {
    const fcm_index k = g2l ? g2l[ed[a] / 3] : ed[a] / 3;
    for (fcm_index i = cptr[k]; i < cptr[k + 1]; i++)
      if (color[cinc[i]] >= 0) forbid[color[cinc[i]]] = e;
  }
  int k = 0;
  while (k < MAX_COLORS && forbid[k] == e)
    k++;
  FCM_CHECK(k < MAX_COLORS, s->ctx, FCM_ERR_UNSUPPORTED,
            "space: cell %lld needs more than %d colours (a node shared by too many cells)",
            (long long)s->elem_cell[local_elem(s, e)], MAX_COLORS);
  color[e] = k;
cleanup:
  return st;
}

/* Greedy colouring of the local elements: an element takes the smallest colour not used by an
 * element sharing a copy (elements sharing a node but using different copies of it may share a
 * colour). color_elems holds local element positions (a full space: element ids). */
static fcm_status build_colors(fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                               const fcm_index *cinc)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ne = s->num_local_elems;
  int *color = NULL, ncol = 0;
  fcm_index *forbid = NULL;
  FCM_ALLOC(ctx, ne + 1, color);
  FCM_ALLOC(ctx, MAX_COLORS, forbid);
  for (int k = 0; k < MAX_COLORS; k++)
    forbid[k] = -1;
  for (fcm_index e = 0; e < ne; e++)
    color[e] = -1;
  for (fcm_index e = 0; e < ne; e++) {
    FCM_TRY(ctx, greedy_color(s, g2l, cptr, cinc, e, color, forbid));
    ncol = FCM_MAX(ncol, color[e] + 1);
  }
  FCM_TRY(ctx, color_lists(s, color, ncol));
cleanup:
  fcm__free(ctx, color);
  fcm__free(ctx, forbid);
  return st;
}

void fcm__space_cut_give_back(fcm_space *s)
{
  fcm_space *from = s ? s->col_from : NULL;
  if (!from) return;
  from->col_idx = s->col_idx, from->col_cap = s->col_cap;
  s->col_idx = NULL, s->col_cap = 0, s->col_from = NULL;
  fill_columns(from); /* its rows as they were: the same bits */
}

void fcm__space_cut_keep(fcm_space *s)
{
  if (s) s->col_from = NULL;
}

/* Release the topology (copy graph, pattern, offsets, colours, local lists); columns taken from
 * another space go back to it. */
void fcm__space_free_topology(fcm_space *s)
{
  fcm_ctx *ctx = s->ctx;
  fcm__space_cut_give_back(s);
  void *arrays[] = {s->node_ptr,   s->node_adj,    s->row_ptr,      s->col_idx,
                    s->elem_off,   s->elem_lcopy,  s->color_ptr,    s->color_elems,
                    s->local_copy, s->local_elem,  s->cell_local,   s->block_color_ptr,
                    s->block_list, s->block_elems, s->cut_row_from, s->block_ptr,
                    s->block_cells};
  for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
    fcm__free(ctx, arrays[i]);
  s->node_ptr = s->node_adj = s->row_ptr = s->local_copy = s->local_elem = NULL;
  s->color_ptr = s->color_elems = NULL;
  s->col_idx = s->elem_off = s->elem_lcopy = NULL;
  s->cell_local = NULL;
  s->block_color_ptr = s->block_list = s->block_elems = s->block_ptr = s->block_cells = NULL;
  s->num_blocks = s->num_block_cells = 0;
  s->blocks_kept = 0;
  s->cut_row_from = NULL, s->cut_from = NULL;
  s->cut_from_dofs = s->cut_from_elems = 0;
  s->num_colors = s->num_block_colors = 0;
  s->cut_kept_rows = 0;
  s->col_cap = 0;
  s->num_local_copies = s->num_local_elems = 0;
}

/* The topology of the elements of the cells flagged in cell_mask (local; cell_mask NULL: none)
 * or of every element (!local, the full space's): their copies, the copy graph, the pattern,
 * the offsets and the colours. The local copies and elements are listed in ascending order,
 * so a mask of every active cell gives the full space's arrays. */
fcm_status fcm__space_build_topology(fcm_space *s, int local, const unsigned char *cell_mask)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3;
  fcm_index *g2l = NULL, *cptr = NULL, *cinc = NULL;
  fcm__space_free_topology(s);
  if (local) {
    fcm_index ne = 0, nl = 0;
    FCM_ALLOC(ctx, s->num_cells + 1, s->cell_local);
    for (fcm_index c = 0; c < s->num_cells; c++) {
      s->cell_local[c] = cell_mask && cell_mask[c] != 0 && s->active[c];
      if (s->cell_local[c]) ne += s->cell_elem[c + 1] - s->cell_elem[c];
    }
    FCM_ALLOC(ctx, ne + 1, s->local_elem);
    FCM_ALLOC(ctx, ncopy + 1, g2l); /* transient O(copies): the numbering's size */
    for (fcm_index k = 0; k < ncopy; k++)
      g2l[k] = -1;
    for (fcm_index c = 0; c < s->num_cells; c++) {
      if (!s->cell_local[c]) continue;
      for (fcm_index e = s->cell_elem[c]; e < s->cell_elem[c + 1]; e++) {
        s->local_elem[s->num_local_elems++] = e;
        for (int a = 0; a < s->nn; a++)
          g2l[s->elem_dof[e * s->nn + a] / 3] = 0;
      }
    }
    for (fcm_index k = 0; k < ncopy; k++)
      nl += g2l[k] == 0;
    FCM_ALLOC(ctx, nl + 1, s->local_copy);
    for (fcm_index k = 0; k < ncopy; k++)
      if (g2l[k] == 0) {
        s->local_copy[s->num_local_copies] = k;
        g2l[k] = s->num_local_copies++;
      }
  } else {
    s->num_local_elems = s->num_elems;
    s->num_local_copies = ncopy;
  }
  FCM_TRY(ctx, build_copy_incidence(s, g2l, &cptr, &cinc));
  FCM_TRY(ctx, node_graph(s, g2l, cptr, cinc, NULL, NULL));
  FCM_TRY(ctx, build_pattern(s, g2l));
  FCM_TRY(ctx, build_colors(s, g2l, cptr, cinc));
  FCM_TRY(ctx, fcm__space_build_blocks(s, NULL));
cleanup:
  if (st != FCM_OK) fcm__space_free_topology(s);
  fcm__free(ctx, g2l);
  fcm__free(ctx, cptr);
  fcm__free(ctx, cinc);
  return st;
}

/* ---- The topology of a cut space patched from the space before the cut. Element e of the cut
 * space is "kept" when its cell has as many elements in both spaces, its parent element sits at
 * the same place among them, and at every node it uses the only child of the copy its parent
 * uses there (the same constraint flags): the cut did not touch it. A copy k is kept when it has
 * a parent p with no other child, every element using it is kept, and as many elements use k
 * as use p: its elements are then exactly the children of p's, so its graph row is p's row with
 * every copy replaced by its child (a kept element's copies all have single children). */

/* What the patch reads besides the two spaces: the parent element of each new element, the
 * parent of each new copy, the only child of each old copy (-1: none, -2: several), the
 * elements using each old copy, the kept flags of the new elements and copies. */
typedef struct cut_map {
  fcm_index *parent_elem; /* the element of from holding each new element's parent piece */
  fcm_index *parent, *child, *old_uses;
  unsigned char *elem_kept, *copy_kept; /* copy_kept 2: kept and its mapped row sorted as is */
} cut_map;

/* Elements using each copy of s (each element once, as build_copy_incidence() counts). */
static void count_uses(const fcm_space *s, fcm_index *uses)
{
  const int nn = s->nn;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(s->ctx)) schedule(static)
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const fcm_index *ed = s->elem_dof + e * nn;
    for (int a = 0; a < nn; a++) {
      int dup = 0;
      for (int b = 0; b < a && !dup; b++)
        dup = ed[b] / 3 == ed[a] / 3;
      if (dup) continue;
#pragma omp atomic
      uses[ed[a] / 3]++;
    }
  }
}

/* The kept flags of the elements of s (after the cut) against from's. */
static void mark_kept_elements(const fcm_space *from, const fcm_space *s, cut_map *m)
{
  const int nn = s->nn;
#pragma omp parallel for num_threads(fcm_ctx_num_threads(s->ctx)) schedule(static)
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const fcm_index c = s->elem_cell[e], fe = m->parent_elem[e];
    int kept =
        fe >= 0 &&
        from->cell_elem[c + 1] - from->cell_elem[c] == s->cell_elem[c + 1] - s->cell_elem[c] &&
        fe - from->cell_elem[c] == e - s->cell_elem[c];
    for (int a = 0; a < nn && kept; a++) {
      const fcm_index k = s->elem_dof[e * nn + a] / 3, p = from->elem_dof[fe * nn + a] / 3;
      const int con = s->elem_con ? s->elem_con[e * nn + a] : 0,
                fcon = from->elem_con ? from->elem_con[fe * nn + a] : 0;
      kept = con == fcon && m->parent[k] == p && m->child[p] == k;
    }
    m->elem_kept[e] = (unsigned char)kept;
  }
}

/* The parents, children and kept flags of the cut space s against from. */
static fcm_status build_cut_map(const fcm_space *from, const fcm_space *s, const fcm_index *cptr,
                                const fcm_index *cinc, cut_map *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3, nold = from->num_dofs / 3;
  const int nt = fcm_ctx_num_threads(ctx);
  /* every entry is written below but old_uses' (counts) */
  FCM_ALLOC_RAW(ctx, ncopy + 1, m->parent);
  FCM_ALLOC_RAW(ctx, nold + 1, m->child);
  FCM_ALLOC(ctx, nold + 1, m->old_uses);
  FCM_ALLOC_RAW(ctx, s->num_elems + 1, m->elem_kept);
  FCM_ALLOC_RAW(ctx, ncopy + 1, m->copy_kept);
  FCM_ALLOC_RAW(ctx, s->num_elems + 1, m->parent_elem);
  FCM_TRY(ctx, fcm__space_cut_parents_with(from, s, m->parent, m->parent_elem));
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index p = 0; p < nold; p++)
    m->child[p] = -1;
  for (fcm_index k = 0; k < ncopy; k++) {
    const fcm_index p = m->parent[k];
    if (p >= 0) m->child[p] = m->child[p] == -1 ? k : -2; /* -2: several children */
  }
  mark_kept_elements(from, s, m);
  count_uses(from, m->old_uses);
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index k = 0; k < ncopy; k++) {
    const fcm_index p = m->parent[k];
    int kept = p >= 0 && m->child[p] == k && cptr[k + 1] - cptr[k] == m->old_uses[p];
    for (fcm_index i = cptr[k]; i < cptr[k + 1] && kept; i++)
      kept = m->elem_kept[cinc[i]];
    m->copy_kept[k] = (unsigned char)kept;
  }
cleanup:
  return st;
}

static void free_cut_map(fcm_ctx *ctx, cut_map *m)
{
  fcm__free(ctx, m->parent_elem);
  fcm__free(ctx, m->parent);
  fcm__free(ctx, m->child);
  fcm__free(ctx, m->old_uses);
  fcm__free(ctx, m->elem_kept);
  fcm__free(ctx, m->copy_kept);
}

/* Row k of the copy graph of a cut space from a kept copy's parent row (node_adj from base;
 * row NULL: only its length). Returns the length, or -1 - i when the parent row's neighbour i
 * has no single child. */
static fcm_index kept_row(const fcm_space *from, cut_map *m, fcm_index k, fcm_index *row)
{
  const fcm_index p = m->parent[k], *prow = from->node_adj + from->node_ptr[p];
  const fcm_index cnt = from->node_ptr[p + 1] - from->node_ptr[p];
  if (!row) return cnt;
  int sorted = 1;
  for (fcm_index i = 0; i < cnt; i++) {
    if (m->child[prow[i]] < 0) return -1 - i;
    row[i] = m->child[prow[i]];
    sorted &= i == 0 || row[i] > row[i - 1];
  }
  if (!sorted) qsort(row, (size_t)cnt, sizeof *row, cmp_index);
  m->copy_kept[k] = (unsigned char)(sorted ? 2 : 1);
  return cnt;
}

/* The rows are made by the threads, each with its own marks (mark: nt arrays of ncopy, a
 * thread's set to -1 when it first makes a row that is not kept: untouched, its pages cost
 * nothing). */
static fcm_status node_graph(fcm_space *s, const fcm_index *g2l, const fcm_index *cptr,
                             const fcm_index *cinc, const fcm_space *from, cut_map *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_local_copies;
  const int nt = fcm_ctx_num_threads(ctx);
  fcm_index *mark = NULL, bad = ncopy, kept_rows = 0;
  FCM_ALLOC_RAW(ctx, (size_t)nt * (size_t)(ncopy + 1), mark);
  FCM_ALLOC(ctx, ncopy + 1, s->node_ptr);
  for (int pass = 0; pass < 2; pass++) {
#pragma omp parallel num_threads(nt) reduction(min : bad) reduction(+ : kept_rows)
    {
      fcm_index *mk = mark + (size_t)omp_get_thread_num() * (size_t)(ncopy + 1);
      int marks_set = 0;
#pragma omp for schedule(dynamic, 256)
      for (fcm_index k = 0; k < ncopy; k++) {
        fcm_index *row = pass ? s->node_adj + s->node_ptr[k] : NULL, cnt;
        if (m && m->copy_kept[k]) {
          cnt = kept_row(from, m, k, row);
          if (cnt < 0) {
            bad = FCM_MIN(bad, k);
            continue;
          }
          kept_rows += pass;
        } else {
          if (!marks_set) {
            for (fcm_index j = 0; j < ncopy; j++)
              mk[j] = -1;
            marks_set = 1;
          }
          cnt = copy_row(s, g2l, cptr, cinc, k, mk, row);
        }
        if (!pass) s->node_ptr[k + 1] = cnt;
      }
    }
    if (bad < ncopy) {
      const fcm_index i = -1 - kept_row(from, m, bad, s->node_adj + s->node_ptr[bad]);
      FCM_CHECK(0, ctx, FCM_ERR_INTERNAL,
                "cut space: copy %lld is kept but its neighbour %lld before the cut has no "
                "single child",
                (long long)bad, (long long)from->node_adj[from->node_ptr[m->parent[bad]] + i]);
    }
    if (!pass) {
      for (fcm_index k = 0; k < ncopy; k++)
        s->node_ptr[k + 1] += s->node_ptr[k];
      FCM_ALLOC_RAW(ctx, s->node_ptr[ncopy] + 1, s->node_adj);
    }
  }
  s->cut_kept_rows += kept_rows;
cleanup:
  fcm__free(ctx, mark);
  return st;
}

/* The offsets of the cut space's elements: a kept element's at a node whose copy's row is its
 * parent's in the same order are its parent element's; the others are looked up. */
static fcm_status patch_offsets(fcm_space *s, const fcm_space *from, const cut_map *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const int nn = s->nn;
  FCM_ALLOC_RAW(ctx, (size_t)s->num_elems * nn * nn + 1, s->elem_off); /* all written below */
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(static)
  for (fcm_index e = 0; e < s->num_elems; e++) {
    const fcm_index fe = m->elem_kept[e] ? m->parent_elem[e] : -1;
    for (int a = 0; a < nn; a++) {
      const fcm_index k = s->elem_dof[e * nn + a] / 3;
      if (fe >= 0 && m->copy_kept[k] == 2)
        memcpy(s->elem_off + ((size_t)e * nn + a) * nn, from->elem_off + ((size_t)fe * nn + a) * nn,
               sizeof(int) * (size_t)nn);
      else
        node_offsets(s, e, a, k);
    }
  }
cleanup:
  return st;
}

/* The element colouring of the cut space, greedy_color() only where it may differ from the
 * space before the cut. An element whose copies are all kept has the children of its parent's
 * neighbours for neighbours, in the same order; while none of those before it has another
 * colour than its parent's, the greedy colouring gives it its parent's colour. So the other
 * elements are coloured anew, and with them the elements sharing a copy with an element whose
 * colour is not its parent's (or that has no parent). */
static fcm_status patch_colors(fcm_space *s, const fcm_space *from, const fcm_index *cptr,
                               const fcm_index *cinc, const cut_map *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ne = s->num_elems;
  const int nn = s->nn;
  int *color = NULL, *old = NULL, ncol = 0;
  unsigned char *dirty = NULL;
  fcm_index *forbid = NULL;
  const int nt = fcm_ctx_num_threads(ctx);
  /* every entry is written below (every element of from has a colour) */
  FCM_ALLOC_RAW(ctx, ne + 1, color);
  FCM_ALLOC_RAW(ctx, ne + 1, dirty);
  FCM_ALLOC_RAW(ctx, from->num_elems + 1, old);
  FCM_ALLOC(ctx, MAX_COLORS, forbid);
  for (int k = 0; k < MAX_COLORS; k++)
    forbid[k] = -1;
  for (int c = 0; c < from->num_colors; c++) {
    const fcm_index i0 = from->color_ptr[c], i1 = from->color_ptr[c + 1];
#pragma omp parallel for num_threads(nt) schedule(static) if (i1 - i0 > 4096)
    for (fcm_index i = i0; i < i1; i++)
      old[from->color_elems[i]] = c;
  }
#pragma omp parallel for num_threads(nt) schedule(static)
  for (fcm_index e = 0; e < ne; e++) {
    int stable = m->elem_kept[e];
    for (int a = 0; a < nn && stable; a++)
      stable = m->copy_kept[s->elem_dof[e * nn + a] / 3] != 0;
    dirty[e] = (unsigned char)!stable;
    color[e] = -1;
  }
  for (fcm_index e = 0; e < ne; e++) {
    const int prev = m->elem_kept[e] ? old[m->parent_elem[e]] : -1;
    if (dirty[e]) {
      FCM_TRY(ctx, greedy_color(s, NULL, cptr, cinc, e, color, forbid));
      for (int a = 0; a < nn && color[e] != prev; a++) {
        const fcm_index k = s->elem_dof[e * nn + a] / 3;
        for (fcm_index i = cptr[k]; i < cptr[k + 1]; i++)
          dirty[cinc[i]] = 1;
      }
    } else {
      color[e] = prev;
    }
    ncol = FCM_MAX(ncol, color[e] + 1);
  }
  FCM_TRY(ctx, color_lists(s, color, ncol));
cleanup:
  fcm__free(ctx, color);
  fcm__free(ctx, dirty);
  fcm__free(ctx, old);
  fcm__free(ctx, forbid);
  return st;
}

/* rank[e]: the position of element e in the assembly's visit of the full space s (colour by
 * colour, the blocks of a colour in order, each block's elements in order). Two elements
 * adding to one matrix entry share a copy, so they lie in one block or in blocks of different
 * colours: their terms are summed in the order of their ranks. */
static void visit_ranks(const fcm_space *s, fcm_index *rank)
{
  fcm_index r = 0;
  for (int c = 0; c < s->num_block_colors; c++)
    for (fcm_index k = s->block_color_ptr[c]; k < s->block_color_ptr[c + 1]; k++) {
      const fcm_index b = s->block_list[k];
      for (fcm_index j = s->block_ptr[b]; j < s->block_ptr[b + 1]; j++)
        rank[s->block_elems[j]] = r++;
    }
}

/* 1 when the elements of copy k (cinc[i0..i1), each kept) are visited in the same order as
 * their parent elements: sorted by their ranks in s, their parents' ranks in from ascend. */
static int same_visit(const fcm_index *cinc, fcm_index i0, fcm_index i1, const fcm_index *rank,
                      const fcm_index *old_rank, const cut_map *m, fcm_index *buf)
{
  const fcm_index n = i1 - i0;
  for (fcm_index i = 0; i < n; i++) { /* insertion sort by the new rank (a few elements) */
    const fcm_index e = cinc[i0 + i];
    fcm_index j = i;
    for (; j > 0 && rank[buf[j - 1]] > rank[e]; j--)
      buf[j] = buf[j - 1];
    buf[j] = e;
  }
  for (fcm_index i = 1; i < n; i++)
    if (old_rank[m->parent_elem[buf[i]]] <= old_rank[m->parent_elem[buf[i - 1]]]) return 0;
  return 1;
}

/* s->cut_row_from: the copies whose rows are their parents' in the same order (copy_kept 2)
 * and whose elements keep their parents' order of visit. With the blocks and colours taken
 * from `from` (blocks_kept) every kept element keeps its place in the visit (the same cell, so
 * the same block and colour and place among the block's cells, and the same place among its
 * cell's elements), so the elements of a copy_kept copy, all kept, keep their order. */
static fcm_status mark_cut_rows(fcm_space *s, const fcm_space *from, const fcm_index *cptr,
                                const fcm_index *cinc, const cut_map *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  const fcm_index ncopy = s->num_dofs / 3;
  fcm_index *rank = NULL, *old_rank = NULL, *buf = NULL, most = 1;
  FCM_ALLOC_RAW(ctx, (size_t)ncopy + 1, s->cut_row_from);
  s->cut_from = from;
  s->cut_from_dofs = from->num_dofs;
  s->cut_from_elems = from->num_elems;
  if (s->blocks_kept) {
#pragma omp parallel for num_threads(fcm_ctx_num_threads(ctx)) schedule(static)
    for (fcm_index k = 0; k < ncopy; k++)
      s->cut_row_from[k] = m->copy_kept[k] == 2 ? m->parent[k] : -1;
    return FCM_OK;
  }
  for (fcm_index k = 0; k < ncopy; k++)
    most = FCM_MAX(most, cptr[k + 1] - cptr[k]);
  FCM_ALLOC_RAW(ctx, (size_t)s->num_elems + 1, rank);
  FCM_ALLOC_RAW(ctx, (size_t)from->num_elems + 1, old_rank);
  FCM_ALLOC_RAW(ctx, (size_t)most, buf);
  visit_ranks(s, rank);
  visit_ranks(from, old_rank);
  for (fcm_index k = 0; k < ncopy; k++)
    s->cut_row_from[k] =
        m->copy_kept[k] == 2 && same_visit(cinc, cptr[k], cptr[k + 1], rank, old_rank, m, buf)
            ? m->parent[k]
            : -1;
cleanup:
  fcm__free(ctx, rank);
  fcm__free(ctx, old_rank);
  fcm__free(ctx, buf);
  return st;
}

/* 1 when from is a full space whose topology s (full, after a cut) can patch. */
static int can_patch(const fcm_space *from, const fcm_space *s)
{
  if (!from || from->is_local || s->is_local || !from->node_ptr || !from->elem_off ||
      from->nn != s->nn || from->mesh != s->mesh || !from->rules || !s->rules)
    return 0;
  return fcm_cell_rules_parent_num_pieces(s->rules) == fcm_cell_rules_num_pieces(from->rules) &&
         fcm_cell_rules_parent_num_pieces(s->rules) > 0;
}

fcm_status fcm__space_build_topology_cut(fcm_space *s, const fcm_space *from, fcm_space *give)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = s->ctx;
  fcm_index *cptr = NULL, *cinc = NULL;
  cut_map m;
  memset(&m, 0, sizeof m);
  if (!can_patch(from, s)) return fcm__space_build_topology(s, 0, NULL);
  fcm__space_free_topology(s);
  s->num_local_elems = s->num_elems;
  s->num_local_copies = s->num_dofs / 3;
  FCM_TRY(ctx, build_copy_incidence(s, NULL, &cptr, &cinc));
  FCM_TRY(ctx, build_cut_map(from, s, cptr, cinc, &m));
  FCM_TRY(ctx, node_graph(s, NULL, cptr, cinc, from, &m));
  FCM_TRY(ctx, build_pattern_rows(s, give == from ? give : NULL));
  FCM_TRY(ctx, patch_offsets(s, from, &m));
  FCM_TRY(ctx, patch_colors(s, from, cptr, cinc, &m));
  FCM_TRY(ctx, fcm__space_build_blocks(s, from));
  FCM_TRY(ctx, mark_cut_rows(s, from, cptr, cinc, &m));
cleanup:
  if (st != FCM_OK) fcm__space_free_topology(s);
  free_cut_map(ctx, &m);
  fcm__free(ctx, cptr);
  fcm__free(ctx, cinc);
  return st;
}
