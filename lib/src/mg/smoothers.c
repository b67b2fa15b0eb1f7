/* The multigrid's smoothers' structures: the rows' colours, the slab orders that let the
 * threads share a sweep with iterates that do not depend on their number (and the copies whose
 * three rows share a pattern), the block smoothers' blocks over vertices and cut cells (de
 * Prenter et al. 2020), and the check of the orders. The sweeps themselves: sweeps.c. */
#include "mg/levels_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_index(const void *a, const void *b)
{
  const fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

void fcm__mg_slabs_free(fcm_ctx *ctx, slab_order *S)
{
  fcm__free(ctx, S->ptr);
  fcm__free(ctx, S->item);
  fcm__free(ctx, S->mid);
  fcm__free(ctx, S->triple);
  memset(S, 0, sizeof *S);
}

/* Greedy colouring of the rows of the level matrix in row order (a row takes the smallest
 * colour no coupled row before it has), then the rows grouped by colour, ascending. */
fcm_status fcm__mg_level_colors(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  int *col = NULL, maxc = 0;
  fcm_index *seen = NULL, *fill = NULL;
  FCM_ALLOC(ctx, L->n + 1, col);
  fcm_index maxdeg = 0;
  for (fcm_index i = 0; i < L->n; i++)
    maxdeg = FCM_MAX(maxdeg, rp[i + 1] - rp[i]);
  FCM_ALLOC(ctx, maxdeg + 2, seen); /* seen[c] == i + 1: colour c taken for row i */
  for (fcm_index i = 0; i < L->n; i++) {
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      if (ci[p] < i && col[ci[p]] <= maxdeg) seen[col[ci[p]]] = i + 1;
    int c = 0;
    while (seen[c] == i + 1)
      c++;
    col[i] = c;
    maxc = FCM_MAX(maxc, c + 1);
  }
  L->ncolor = maxc;
  FCM_ALLOC(ctx, maxc + 1, L->color_ptr);
  FCM_ALLOC(ctx, L->n + 1, L->color_rows);
  FCM_ALLOC(ctx, maxc + 1, fill);
  for (fcm_index i = 0; i < L->n; i++)
    L->color_ptr[col[i] + 1]++;
  for (int c = 0; c < maxc; c++)
    L->color_ptr[c + 1] += L->color_ptr[c];
  for (fcm_index i = 0; i < L->n; i++)
    L->color_rows[L->color_ptr[col[i]] + fill[col[i]]++] = i;
cleanup:
  fcm__free(ctx, col);
  fcm__free(ctx, seen);
  fcm__free(ctx, fill);
  return st;
}

/* ------------------------------------------------------------------ slab orders */

/* Block slabs: a few per thread and colour on common core counts, so that whole slabs balance
 * the threads' work; fewer when the coupling reaches far in the sequence. */
#define MG_SLABS 16

/* Colours of at most this many slabs are shared between two threads by the best split. */
#define MG_SPLIT_MAX 16

/* The larger of the two threads' works when the slabs of colour c whose bits are set in `set`
 * (bit j: the colour's j-th slab) go to the second thread; w: the slabs' works. */
static double split_max(fcm_index ns, int c, const double *w, unsigned set)
{
  double t[2] = {0.0, 0.0};
  for (fcm_index k = c, j = 0; k < ns; k += 2, j++)
    t[(set >> j) & 1u] += w[k];
  return FCM_MAX(t[0], t[1]);
}

/* S->mid of the slabs of colour c from their works w: the midpoint of each slab's work within
 * its colour's, so that the threads take contiguous runs of about equal work
 * (fcm__mg_slab_mine()). Where the colour has at most MG_SPLIT_MAX slabs and another split of
 * them between two threads leaves the busier one at least 1 % less work than the runs do, the
 * two sets of that split take [0, 1/2) and [1/2, 1) instead, each slab at its midpoint within
 * its set's work. The slabs of one colour are independent: the split changes which thread
 * sweeps a slab, not the iterate. */
static void slabs_share(slab_order *S, int c, const double *w)
{
  const fcm_index ns = S->nslab;
  fcm_index m = 0;
  double tot = 0.0, before = 0.0;
  unsigned runs = 0; /* the second thread's slabs in the contiguous runs (two threads) */
  for (fcm_index k = c; k < ns; k += 2, m++)
    tot += w[k];
  for (fcm_index k = c, j = 0; k < ns; k += 2, j++) {
    S->mid[k] = tot > 0.0 ? (before + 0.5 * w[k]) / tot : 0.0;
    if (S->mid[k] >= 0.5) runs |= 1u << j;
    before += w[k];
  }
  if (m < 2 || m > MG_SPLIT_MAX) return;
  const double runs_max = split_max(ns, c, w, runs);
  unsigned best = runs;
  double best_max = runs_max;
  for (unsigned set = 1; set + 1u < (1u << m); set++) {
    const double t = split_max(ns, c, w, set);
    if (t < best_max) best_max = t, best = set;
  }
  if (best_max > 0.99 * runs_max) return;
  for (unsigned half = 0; half < 2; half++) {
    double sum = 0.0, acc = 0.0;
    for (fcm_index k = c, j = 0; k < ns; k += 2, j++)
      if (((best >> j) & 1u) == half) sum += w[k];
    for (fcm_index k = c, j = 0; k < ns; k += 2, j++)
      if (((best >> j) & 1u) == half) {
        S->mid[k] = 0.5 * half + (sum > 0.0 ? 0.5 * (acc + 0.5 * w[k]) / sum : 0.0);
        acc += w[k];
      }
  }
}

/* The slab order (see slab_order) of n items with per-item work (>= 0), in the sequence `seq`
 * (n items; NULL: ascending), given reach[t] >= t: the furthest sequence position of an item
 * adjacent (symmetrically) to the item at position t. Cut so that slab s + 2 starts past
 * every position that slab s reaches. thick = 0: slabs of at least total / MG_SLABS work
 * each, colour 0 first. thick > 0: `thick` slabs of about equal work (colour 0) separated by
 * thin slabs just wide enough to keep them apart (colour 1, swept first), or one slab when
 * the thin ones would hold more than a quarter of the work or reach the end (coupling that
 * reaches far in the sequence). */
static fcm_status slabs_create(fcm_ctx *ctx, fcm_index n, const fcm_index *seq,
                               const fcm_index *reach, const double *work, int thick, slab_order *S)
{
  fcm_status st = FCM_OK;
  fcm_index *cut = NULL;
  double *sw = NULL; /* per slab: its work */
  fcm__mg_slabs_free(ctx, S);
  FCM_ALLOC_RAW(ctx, n + 2, cut);
  double total = 0.0;
  for (fcm_index t = 0; t < n; t++)
    total += work[t];
  /* cut[s]: the first position of slab s; far: 1 + the reach of the slab before the last */
  const double target = thick > 0 ? total / thick : total / MG_SLABS;
  fcm_index ns = 0, t = 0, far = 0;
  double wthin = 0.0;
  cut[0] = 0;
  while (t < n) {
    const int thin = thick > 0 && ns % 2 == 1;
    double acc = 0.0;
    fcm_index reach_s = t;
    do {
      acc += work[seq ? seq[t] : t];
      reach_s = FCM_MAX(reach_s, reach[t]);
      t++;
    } while (t < n && ((!thin && acc < target) || t < far));
    if (thin) wthin += acc;
    cut[++ns] = t;
    far = reach_s + 1; /* the slab after the next starts past all this slab reaches */
  }
  if (thick > 0 && (ns == 2 || wthin > 0.25 * total)) ns = 1, cut[1] = n;
  S->nslab = ns;
  S->first = thick > 0 && ns > 1;
  FCM_ALLOC_RAW(ctx, ns + 1, S->ptr);
  FCM_ALLOC(ctx, ns + 1, S->mid);
  FCM_ALLOC_RAW(ctx, n + 1, S->item);
  for (fcm_index k = 0; k <= ns; k++)
    S->ptr[k] = cut[k];
  for (fcm_index q = 0; q < n; q++)
    S->item[q] = seq ? seq[q] : q;
  FCM_ALLOC(ctx, ns + 1, sw);
  for (fcm_index k = 0; k < ns; k++)
    for (fcm_index q = cut[k]; q < cut[k + 1]; q++)
      sw[k] += work[S->item[q]];
  for (int c = 0; c < 2; c++)
    slabs_share(S, c, sw);
cleanup:
  if (st) fcm__mg_slabs_free(ctx, S);
  fcm__free(ctx, cut);
  fcm__free(ctx, sw);
  return st;
}

/* The rows of a level in slabs, in row order: two thick slabs and the thin one between them
 * (adjacency: the level matrix's pattern, work: stored entries). Pointwise Gauss-Seidel is
 * sensitive to its order (the Hex8 cube's V-cycle factor 0.29 -> 0.32 with 16 slabs, the
 * hemisphere's 0.15 -> 0.23, Hex20 0.33 -> 0.55), much less so with one thin slab swept
 * first (0.29, 0.18, 0.33): the pointwise sweeps share two threads. Hex20's finest level
 * numbers the corner nodes before the mid-edge nodes; its rows couple far apart in row order
 * and stay in one slab (sequential). */
#define MG_ROW_SLABS_THICK 2

/* lead and tail of a row order (slab_order): in a sweep by two threads, one sweeps the thin
 * slab 1 alone before and after the thick slabs, the other thick slab 0 and the third slab 2
 * between them; the first rows of slab 0 that reach no row of slab 1 can be swept beside the
 * thin slab instead (their updates neither read nor write its rows, so the iterate is the
 * same). As many as make slab 0's thread's share between the barriers that of slab 2's
 * (w = W_0 - W_2, at most W_1, stored entries), cut at a copy's first row (row 0 starts slab 0,
 * so the copies' triples stay whole). */
static void row_slabs_lead(fcm_index n, const fcm_index *reach, const double *work, slab_order *S)
{
  S->lead = S->tail = 0;
  if (S->nslab != 3 || S->first != 1) return;
  double w[3] = {0.0, 0.0, 0.0};
  for (int k = 0; k < 3; k++)
    for (fcm_index q = S->ptr[k]; q < S->ptr[k + 1]; q++)
      w[k] += work[S->item[q]];
  const double want = FCM_MIN(w[1], w[0] - w[2]);
  double acc = 0.0;
  fcm_index cut = 0;
  for (fcm_index i = 0; i < S->ptr[1] && i < n; i++) {
    if (reach[i] >= S->ptr[1]) break; /* row i couples with the thin slab */
    acc += work[i];
    if (i % 3 == 2) {
      if (acc > want) break;
      cut = i + 1;
    }
  }
  S->lead = S->tail = cut;
}

fcm_status fcm__mg_row_slabs(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *work = NULL;
  fcm_index *reach = NULL;
  FCM_ALLOC_RAW(ctx, L->n + 1, work);
  FCM_ALLOC_RAW(ctx, L->n + 1, reach);
  const fcm_index n = L->n;
  /* level 0 on its space's pattern: the copy graph gives the last columns */
  const int by_space = L == &m->lev[0] && fcm__mg_space_reach(m, reach);
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) if (n > 4096)
  for (fcm_index i = 0; i < n; i++) { /* a row's columns ascend: its last reaches furthest */
    work[i] = (double)(rp[i + 1] - rp[i]);
    if (!by_space) reach[i] = rp[i + 1] > rp[i] ? FCM_MAX(i, (fcm_index)ci[rp[i + 1] - 1]) : i;
  }
  FCM_TRY(ctx, slabs_create(ctx, L->n, NULL, reach, work, MG_ROW_SLABS_THICK, &L->rows));
  row_slabs_lead(L->n, reach, work, &L->rows);
  FCM_ALLOC(ctx, L->n + 1, L->rows.triple);
  /* level 0 on its space's pattern: the space's copy graph says what the rows would */
  if (!(L == &m->lev[0] && fcm__mg_space_triples(m, L->rows.triple))) {
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) if (n > 4096)
    for (fcm_index i = 0; i < n - 2; i += 3) {
      /* the three rows one pattern, the three's own columns one after the other (diag[i]) */
      const fcm_index len = rp[i + 1] - rp[i], p = L->diag[i] - rp[i];
      const int same = rp[i + 2] - rp[i + 1] == len && rp[i + 3] - rp[i + 2] == len &&
                       p + 2 < len && ci[rp[i] + p + 1] == i + 1 && ci[rp[i] + p + 2] == i + 2 &&
                       !memcmp(ci + rp[i], ci + rp[i + 1], sizeof *ci * (size_t)len) &&
                       !memcmp(ci + rp[i], ci + rp[i + 2], sizeof *ci * (size_t)len);
      int nodes = same && len % 3 == 0;
      for (fcm_index q = rp[i]; nodes && q < rp[i + 1]; q += 3)
        nodes = ci[q] % 3 == 0 && ci[q + 1] == ci[q] + 1 && ci[q + 2] == ci[q] + 2;
      L->rows.triple[i] = (unsigned char)(!same   ? 0
                                          : nodes ? FCM__MG_TRIPLE_NODES
                                                  : FCM__MG_TRIPLE);
    }
  }
cleanup:
  fcm__free(ctx, work);
  fcm__free(ctx, reach);
  return st;
}

/* block_slabs()'s row reach of rows i0 .. i1 - 1 (last: per row the last block position
 * holding it, -1: none): the last block position a row's columns reach, once per row of a
 * block; the three rows of a node of one pattern (the row order's flags) read once, by the
 * first of them, whichever range holds the other two. */
static void rows_reach(const mg_level *L, const fcm_index *last, fcm_index i0, fcm_index i1,
                       fcm_index *row_reach)
{
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A), n = L->n;
  const int *ci = fcm_csr_col_idx(A);
  const unsigned char *tri = L->rows.triple;
  for (fcm_index i = i0; i < i1; i++) {
    const int three = fcm__mg_is_triple(tri, i - i % 3, n);
    if (three && i % 3 != 0) continue; /* written with row i - i % 3 */
    const int rows = three ? 3 : 1;
    fcm_index r = -1;
    if (last[i] >= 0 || (three && (last[i + 1] >= 0 || last[i + 2] >= 0)))
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
        r = FCM_MAX(r, last[ci[p]]);
    for (int c = 0; c < rows; c++)
      row_reach[i + c] = last[i + c] >= 0 ? r : -1;
  }
}

/* block_slabs()'s reach and work of block positions t0 .. t1 - 1 (seq: the blocks in order). */
static void blocks_reach(const mg_level *L, const fcm_index *seq, const fcm_index *row_reach,
                         fcm_index t0, fcm_index t1, fcm_index *reach, double *work)
{
  const fcm_index *rp = fcm_csr_row_ptr(fcm__mg_level_matrix(L));
  for (fcm_index t = t0; t < t1; t++) {
    const fcm_index *d = NULL;
    const double *S = NULL;
    const fcm_index k = seq[t];
    const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
    fcm_index r = t, entries = 0;
    for (int i = 0; i < bm; i++) {
      entries += rp[d[i] + 1] - rp[d[i]];
      r = FCM_MAX(r, row_reach[d[i]]);
    }
    reach[t] = r;
    work[k] = (double)entries + (double)bm * (double)bm;
  }
}

/* The blocks of a level's block smoother in slabs, in the sequence of their first DOFs (ties
 * by index), so that it follows the rows. Blocks j and k are adjacent when a DOF of one couples
 * with (or is) a DOF of the other, i.e. when one's update reads what the other writes; work:
 * the residual's and the block product's entries. */
static fcm_status block_slabs(fcm_mg *m, mg_level *L)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_index nb = fcm__schwarz_num_blocks(L->blk), n = L->n;
  fcm_index *first = NULL, *seq = NULL, *last = NULL, *reach = NULL, *row_reach = NULL;
  double *work = NULL;
  /* the blocks by their smallest DOF, ties in block order: a counting sort (stable) */
  FCM_ALLOC_RAW(ctx, nb + 1, first);
  FCM_ALLOC_RAW(ctx, nb + 1, seq);
  FCM_ALLOC_RAW(ctx, nb + 1, reach);
  FCM_ALLOC_RAW(ctx, nb + 1, work);
  FCM_ALLOC(ctx, n + 2, last); /* first the count of each smallest DOF, then the map below */
  for (fcm_index k = 0; k < nb; k++) {
    const fcm_index *d = NULL;
    const double *S = NULL;
    const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
    fcm_index f = n;
    for (int i = 0; i < bm; i++)
      f = FCM_MIN(f, d[i]);
    first[k] = f;
    last[f + 1]++;
  }
  for (fcm_index i = 0; i < n; i++)
    last[i + 1] += last[i];
  for (fcm_index k = 0; k < nb; k++)
    seq[last[first[k]]++] = k;
  for (fcm_index i = 0; i < n; i++)
    last[i] = -1;
  for (fcm_index t = 0; t < nb; t++) { /* last[i]: the last position of a block holding row i */
    const fcm_index *d = NULL;
    const double *S = NULL;
    const int bm = fcm__schwarz_block(L->blk, seq[t], &d, &S);
    for (int i = 0; i < bm; i++)
      last[d[i]] = t;
  }
  /* the last block position a row's columns reach, once per row of a block (the blocks
   * overlap: a cut cell's row lies in up to nine of them); the three rows of a node of one
   * pattern (the row order's flags) read once */
  FCM_ALLOC_RAW(ctx, n + 1, row_reach);
  if (omp_in_parallel() && omp_get_num_threads() > 1) {
    /* from a task of an active team (a cut's structure made beside other work, mg.c
     * create_beside()): in tasks that any thread of the team takes when it is free */
    const fcm_index nch = 8 * (fcm_index)omp_get_num_threads();
#pragma omp taskloop default(shared) grainsize(1)
    for (size_t c = 0; c < (size_t)nch; c++) /* size_t: clang's task loop counts so */
      rows_reach(L, last, n * (fcm_index)c / nch, n * (fcm_index)(c + 1) / nch, row_reach);
#pragma omp taskloop default(shared) grainsize(1)
    for (size_t c = 0; c < (size_t)nch; c++)
      blocks_reach(L, seq, row_reach, nb * (fcm_index)c / nch, nb * (fcm_index)(c + 1) / nch, reach,
                   work);
  } else {
    const fcm_index chunk = 4096;
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) if (n > chunk)
    for (fcm_index i0 = 0; i0 < n; i0 += chunk)
      rows_reach(L, last, i0, FCM_MIN(n, i0 + chunk), row_reach);
#pragma omp parallel for num_threads(fcm__mg_team(m)) schedule(static) if (nb > 1024)
    for (fcm_index t = 0; t < nb; t++)
      blocks_reach(L, seq, row_reach, t, t + 1, reach, work);
  }
  FCM_TRY(ctx, slabs_create(ctx, nb, seq, reach, work, 0, &L->blocks));
cleanup:
  fcm__free(ctx, first);
  fcm__free(ctx, seq);
  fcm__free(ctx, last);
  fcm__free(ctx, reach);
  fcm__free(ctx, row_reach);
  fcm__free(ctx, work);
  return st;
}

/* ------------------------------------------------------------------ block smoothers */

/* On a space with hanging nodes the level-0 matrix is the constrained operator, whose hanging
 * rows are identity rows: a block's hanging DOFs carry none of the functions the block is to
 * resolve, their masters do (the constrained functions of a cut element are those of its free
 * DOFs and of its hanging DOFs' masters). Each block's hanging DOFs are replaced by their
 * masters' (T of fcm_space_hanging_matrix_create()), each block's DOFs sorted and unique. */
static fcm_status blocks_masters(fcm_ctx *ctx, const fcm_space *sp, fcm_index *nb, fcm_index *ptr,
                                 fcm_index **dofs)
{
  fcm_status st = FCM_OK;
  const fcm_index n = fcm_space_num_dofs(sp);
  fcm_index *free_dof = NULL, *col_dof = NULL, *out = NULL, nfree = 0;
  fcm_csr *T = NULL;
  FCM_ALLOC(ctx, n + 1, free_dof);
  FCM_TRY(ctx, fcm_space_hanging_matrix_create(sp, free_dof, &T));
  fcm_csr_get_size(T, NULL, &nfree, NULL);
  FCM_ALLOC(ctx, nfree + 1, col_dof);
  for (fcm_index d = 0; d < n; d++)
    if (free_dof[d] >= 0) col_dof[free_dof[d]] = d;
  const fcm_index *tp = fcm_csr_row_ptr(T);
  const int *tc = fcm_csr_col_idx(T);
  fcm_index total = 0;
  for (fcm_index q = 0; q < ptr[*nb]; q++) {
    const fcm_index d = (*dofs)[q];
    total += free_dof[d] >= 0 ? 1 : tp[d + 1] - tp[d];
  }
  FCM_ALLOC(ctx, total + 1, out);
  fcm_index w = 0, p0 = 0, kept = 0;
  for (fcm_index k = 0; k < *nb; k++) {
    const fcm_index w0 = w;
    for (fcm_index q = p0; q < ptr[k + 1]; q++) {
      const fcm_index d = (*dofs)[q];
      if (free_dof[d] >= 0)
        out[w++] = d;
      else
        for (fcm_index e = tp[d]; e < tp[d + 1]; e++)
          out[w++] = col_dof[tc[e]];
    }
    qsort(out + w0, (size_t)(w - w0), sizeof *out, cmp_index);
    fcm_index u = w0;
    for (fcm_index q = w0; q < w; q++)
      if (u == w0 || out[q] != out[u - 1]) out[u++] = out[q];
    p0 = ptr[k + 1];
    w = u;
    if (w > w0) ptr[++kept] = w; /* a block of hanging DOFs without masters: none */
  }
  *nb = kept;
  fcm__free(ctx, *dofs);
  *dofs = out;
  out = NULL;
cleanup:
  fcm_csr_destroy(&T);
  fcm__free(ctx, free_dof);
  fcm__free(ctx, col_dof);
  fcm__free(ctx, out);
  return st;
}

/* Sort the pairs (v, k) (v < nv) lexicographically: a counting sort by v, then each v's few
 * pairs by k (*pairs replaced). */
static fcm_status sort_pairs(fcm_ctx *ctx, fcm_index np, fcm_index nv, fcm_index **pairs)
{
  fcm_status st = FCM_OK;
  fcm_index *start = NULL, *out = NULL;
  const fcm_index *in = *pairs;
  FCM_ALLOC(ctx, nv + 2, start);
  FCM_ALLOC_RAW(ctx, 2 * np + 1, out); /* every pair placed below */
  for (fcm_index i = 0; i < np; i++)
    start[in[2 * i] + 2]++;
  for (fcm_index v = 0; v < nv; v++)
    start[v + 2] += start[v + 1];
  for (fcm_index i = 0; i < np; i++) { /* start[v + 1]: the next place of v's pairs */
    const fcm_index q = start[in[2 * i] + 1]++;
    out[2 * q] = in[2 * i], out[2 * q + 1] = in[2 * i + 1];
  }
  for (fcm_index v = 0; v < nv; v++) /* v's pairs: [start[v], start[v + 1]) */
    for (fcm_index i = start[v] + 1; i < start[v + 1]; i++) {
      const fcm_index k = out[2 * i + 1];
      fcm_index j = i;
      for (; j > start[v] && out[2 * j - 1] > k; j--)
        out[2 * j + 1] = out[2 * j - 1];
      out[2 * j + 1] = k;
    }
  fcm__free(ctx, *pairs);
  *pairs = out;
  out = NULL;
cleanup:
  fcm__free(ctx, start);
  fcm__free(ctx, out);
  return st;
}

/* Block smoothers (block_smoothing). Level 0: one block per grid vertex of the cut cells
 * block_cells() selects (de Prenter et al. 2020): the DOFs of the copies whose support lies
 * in the vertex's patch of 8 cells, the vertex's own and (Hex20) those of the mid-edge nodes
 * of the edges at the vertex, all copies together; then one block per element of such a cell
 * (all its DOFs).
 * Coarser levels: one block per coarse cell that is not all material (its 8 corner copies).
 * Each block is inverted by the clamped eigen-inverse of fcm_schwarz (Longva et al. 2020,
 * §5.2). Vertex blocks resolve the nearly dependent functions of one vertex's patch (Hex20:
 * 0.96 -> 0.2-0.3 per V-cycle), element blocks those of the corners of a sliver cell (Hex8
 * hollow ball), coarse blocks the same on the Galerkin levels, where thin walls become
 * cells with little material (the hollow ball's V-cycle grew with n without them). On octree
 * spaces level 0's blocks take the masters of their hanging DOFs (blocks_masters()), and the
 * octree levels of a cut space the images of the finer blocks (blocks_image()). */
/* The cut cells that get the finest level's blocks (m->opts.block_fraction): those one of whose
 * pieces holds less than that fraction of the cell (its pieces' volumes against the cell's,
 * the material's volume over its fraction); every cut cell at 1, or without the rules. *out:
 * m->cut_cell itself, or an array of the caller's to free. */
static fcm_status block_cells(const fcm_mg *m, unsigned char **out)
{
  fcm_status st = FCM_OK;
  const fcm_cell_rules *R = fcm_space_cell_rules(m->space);
  const double theta = m->opts.block_fraction;
  *out = m->cut_cell;
  if (theta >= 1.0 || !R) return FCM_OK;
  const fcm_index nc = fcm_mesh_num_cells(fcm_space_mesh(m->space));
  unsigned char *sel = NULL;
  FCM_ALLOC(m->ctx, (size_t)nc + 1, sel);
  for (fcm_index c = 0; c < nc; c++) {
    if (!m->cut_cell[c]) continue;
    fcm_index p0 = 0;
    const fcm_index np = fcm_cell_rules_cell_pieces(R, c, &p0);
    double total = 0.0, least = HUGE_VAL;
    for (fcm_index q = p0; q < p0 + np; q++) {
      const double v = fcm_cell_rules_piece_volume(R, q);
      total += v, least = fmin(least, v);
    }
    const double fraction = fcm_cell_rules_volume_fraction(R, c);
    /* least / |K| < theta, |K| = total / fraction; a cell without pieces keeps its blocks */
    sel[c] = (unsigned char)(np == 0 || !(total > 0.0) || least * fraction < theta * total);
  }
  *out = sel;
cleanup:
  return st;
}

/* Level 0: the vertex blocks, then the element blocks of the cut cells block_cells() selects. */
static fcm_status blocks_level0(fcm_mg *m, fcm_index *nb_out, fcm_index **ptr_out,
                                fcm_index **dofs_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const fcm_space *sp = m->space;
  const fcm_mesh *mesh = fcm_space_mesh(sp);
  const fcm_element_info *info = fcm_element_get_info(fcm_mesh_element_type(mesh));
  const int npc = info->num_nodes, mid = npc > 8;
  const fcm_index *cells = fcm_mesh_cells(mesh), nnode = fcm_mesh_num_nodes(mesh);
  const fcm_index ne = fcm_space_num_elements(sp);
  fcm_index nb = 0, np = 0, nu = 0, neb = 0, ned = 0, *ptr = NULL, *dofs = NULL, *pairs = NULL;
  unsigned char *mark = NULL, *sel = NULL;
  FCM_TRY(ctx, block_cells(m, &sel));
  FCM_ALLOC(ctx, nnode + 1, mark);
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e);
    if (!sel[c]) continue;
    for (int a = 0; a < 8; a++)
      mark[cells[(fcm_index)npc * c + a]] = 1;
  }
  FCM_ALLOC_RAW(ctx, 2 * (size_t)ne * 8 * (mid ? 4 : 1) + 1, pairs); /* read up to np */
  for (fcm_index e = 0; e < ne; e++) {
    const fcm_index c = fcm_space_element_cell(sp, e), *ed = fcm_space_element_dofs(sp, e);
    for (int a = 0; a < 8; a++) {
      const fcm_index v = cells[(fcm_index)npc * c + a];
      if (!mark[v]) continue;
      pairs[2 * np] = v, pairs[2 * np + 1] = ed[a] / 3, np++;
      for (int j = 0; mid && j < info->num_edges; j++)
        if (info->edge_nodes[j][0] == a || info->edge_nodes[j][1] == a)
          pairs[2 * np] = v, pairs[2 * np + 1] = ed[info->edge_nodes[j][2]] / 3, np++;
    }
  }
  FCM_TRY(ctx, sort_pairs(ctx, np, nnode, &pairs));
  for (fcm_index i = 0; i < np; i++)
    if (i == 0 || pairs[2 * i] != pairs[2 * nu - 2] || pairs[2 * i + 1] != pairs[2 * nu - 1])
      pairs[2 * nu] = pairs[2 * i], pairs[2 * nu + 1] = pairs[2 * i + 1], nu++;
  if (m->opts.blocks == FCM_MG_BLOCKS_ELEMENT) nu = 0;
  for (fcm_index i = 0; i < nu; i++)
    nb += i == 0 || pairs[2 * i] != pairs[2 * i - 2];
  if (m->opts.blocks != FCM_MG_BLOCKS_VERTEX)
    FCM_TRY(ctx, fcm_space_cell_blocks(sp, sel, &neb, &ned, NULL, NULL));
  FCM_ALLOC(ctx, nb + neb + 1, ptr);
  FCM_ALLOC(ctx, 3 * nu + ned + 1, dofs);
  for (fcm_index i = 0, k = 0; i < nu; i++) {
    if (i > 0 && pairs[2 * i] != pairs[2 * i - 2]) ptr[++k] = 3 * i;
    for (int d = 0; d < 3; d++)
      dofs[3 * i + d] = 3 * pairs[2 * i + 1] + d;
  }
  ptr[nb] = 3 * nu;
  if (neb > 0) {
    FCM_TRY(ctx, fcm_space_cell_blocks(sp, sel, &neb, &ned, ptr + nb, dofs + 3 * nu));
    for (fcm_index k = nb; k <= nb + neb; k++) /* offsets after the vertex blocks */
      ptr[k] += 3 * nu;
  }
  nb += neb;
  if (fcm_mesh_num_hanging(mesh) > 0) FCM_TRY(ctx, blocks_masters(ctx, sp, &nb, ptr, &dofs));
  *nb_out = nb, *ptr_out = ptr, *dofs_out = dofs;
  ptr = dofs = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  fcm__free(ctx, pairs);
  fcm__free(ctx, mark);
  if (sel != m->cut_cell) fcm__free(ctx, sel);
  return st;
}

/* A coarse level: the cells that are not all material, their distinct corner copies. */
static fcm_status blocks_coarse(fcm_mg *m, const mg_level *L, fcm_index *nb_out,
                                fcm_index **ptr_out, fcm_index **dofs_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_index nb = 0, *ptr = NULL, *dofs = NULL;
  const fcm_index ncell = L->full ? L->ncell : 0; /* an octree level has no grid cells */
  for (fcm_index c = 0; c < ncell; c++)
    nb += !L->full[c];
  FCM_ALLOC(ctx, nb + 1, ptr);
  FCM_ALLOC(ctx, 24 * nb + 1, dofs);
  fcm_index k = 0, q = 0;
  for (fcm_index c = 0; c < ncell; c++) {
    if (L->full[c]) continue;
    const fcm_index q0 = q;
    for (int b = 0; b < 8; b++) {
      const fcm_index K = L->corner[8 * c + b];
      int dup = 0;
      for (fcm_index t = q0; t < q && !dup; t += 3)
        dup = dofs[t] == 3 * K;
      for (int d = 0; !dup && d < 3; d++)
        dofs[q++] = 3 * K + d;
    }
    ptr[++k] = q;
  }
  *nb_out = nb, *ptr_out = ptr, *dofs_out = dofs;
  ptr = dofs = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  return st;
}

/* A block's hash (FNV-1a over its DOFs) with its index, to find identical blocks. */
typedef struct block_key {
  unsigned long long h;
  fcm_index b;
} block_key;

static int cmp_block_key(const void *pa, const void *pb)
{
  const block_key *a = pa, *b = pb;
  if (a->h != b->h) return (a->h > b->h) - (a->h < b->h);
  return (a->b > b->b) - (a->b < b->b);
}

/* Drop the blocks identical to an earlier one (in place; the order of the others kept). */
static fcm_status blocks_unique(fcm_ctx *ctx, fcm_index *nb, fcm_index *ptr, fcm_index *dofs)
{
  fcm_status st = FCM_OK;
  block_key *key = NULL;
  unsigned char *drop = NULL;
  FCM_ALLOC(ctx, *nb + 1, key);
  FCM_ALLOC(ctx, *nb + 1, drop);
  for (fcm_index k = 0; k < *nb; k++) {
    unsigned long long h = 1469598103934665603ULL;
    for (fcm_index q = ptr[k]; q < ptr[k + 1]; q++)
      h = (h ^ (unsigned long long)dofs[q]) * 1099511628211ULL;
    key[k].h = h, key[k].b = k;
  }
  qsort(key, (size_t)*nb, sizeof *key, cmp_block_key);
  for (fcm_index i = 1, first = 0; i < *nb; i++) {
    if (key[i].h != key[first].h) {
      first = i;
      continue;
    }
    const fcm_index a = key[first].b, b = key[i].b, m = ptr[a + 1] - ptr[a];
    drop[b] =
        m == ptr[b + 1] - ptr[b] && !memcmp(dofs + ptr[a], dofs + ptr[b], (size_t)m * sizeof *dofs);
  }
  fcm_index w = 0, kept = 0;
  for (fcm_index k = 0, p0 = 0; k < *nb; k++) {
    const fcm_index p1 = ptr[k + 1];
    if (!drop[k]) {
      memmove(dofs + w, dofs + p0, (size_t)(p1 - p0) * sizeof *dofs);
      w += p1 - p0;
      ptr[++kept] = w;
    }
    p0 = p1;
  }
  *nb = kept;
cleanup:
  fcm__free(ctx, key);
  fcm__free(ctx, drop);
  return st;
}

/* A coarser octree level of a hierarchy with separated bodies (its cells are no grid cells):
 * the images of the finer level's blocks (level 0: vertex and cut-element blocks) under
 * P_{l-1}, each the coarse DOFs its rows read: the coarse copies (of one body, masters for
 * hanging nodes) of the coarse cells around the cut cells' vertices and of those holding the
 * cut cells. A cut's sliver pieces stay on the coarser octrees (a leaf above the deepest level
 * is a leaf there too) with their nearly dependent functions, which pointwise smoothing cannot
 * resolve (Hex20, the cut hemisphere at depth 2: CG + V-cycle 27 iterations with pointwise
 * smoothing there, 26 with the element blocks' images alone, 19 with these; the uncut Hex20
 * octree gains nothing from them and pays 30 % more time: lib/docs/octree.md). Identical
 * images once. */
static fcm_status blocks_image(fcm_mg *m, int l, fcm_index *nb_out, fcm_index **ptr_out,
                               fcm_index **dofs_out)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  const mg_level *F = &m->lev[l - 1];
  fcm_index fnb = 0, *fptr = NULL, *fdofs = NULL, *ptr = NULL, *dofs = NULL, total = 0, w = 0;
  if (l == 1)
    FCM_TRY(ctx, blocks_level0(m, &fnb, &fptr, &fdofs));
  else
    FCM_TRY(ctx, blocks_image(m, l - 1, &fnb, &fptr, &fdofs));
  for (fcm_index q = 0; q < fptr[fnb]; q++)
    total += F->P_ptr[fdofs[q] + 1] - F->P_ptr[fdofs[q]];
  FCM_ALLOC(ctx, fnb + 1, ptr);
  FCM_ALLOC(ctx, total + 1, dofs);
  fcm_index nb = 0;
  for (fcm_index k = 0; k < fnb; k++) {
    const fcm_index w0 = w;
    for (fcm_index q = fptr[k]; q < fptr[k + 1]; q++)
      for (fcm_index p = F->P_ptr[fdofs[q]]; p < F->P_ptr[fdofs[q] + 1]; p++)
        dofs[w++] = F->P_col[p];
    qsort(dofs + w0, (size_t)(w - w0), sizeof *dofs, cmp_index);
    fcm_index u = w0;
    for (fcm_index q = w0; q < w; q++)
      if (u == w0 || dofs[q] != dofs[u - 1]) dofs[u++] = dofs[q];
    w = u;
    if (w > w0) ptr[++nb] = w;
  }
  FCM_TRY(ctx, blocks_unique(ctx, &nb, ptr, dofs));
  *nb_out = nb, *ptr_out = ptr, *dofs_out = dofs;
  ptr = dofs = NULL;
cleanup:
  fcm__free(ctx, fptr);
  fcm__free(ctx, fdofs);
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  return st;
}

fcm_status fcm__mg_level_blocks(fcm_mg *m, int l, fcm_index *nb, fcm_index **ptr, fcm_index **dofs)
{
  if (l == 0) return blocks_level0(m, nb, ptr, dofs);
  if (m->lev[l].oct_node) return blocks_image(m, l, nb, ptr, dofs);
  return blocks_coarse(m, &m->lev[l], nb, ptr, dofs);
}

fcm_status fcm__mg_level_block_smoother(fcm_mg *m, fcm_mg *old, const unsigned char *same,
                                        const struct mg_carry *carry, int l, fcm_index *bmax,
                                        fcm_index *carried)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  fcm_index nb = 0, *ptr = NULL, *dofs = NULL;
  unsigned char *rows_same = NULL;
  fcm__schwarz_prior prior;
  mg_level *L = &m->lev[l];
  int has_prior = 0, kept = 0;
  *bmax = *carried = 0;
  if (m->values_pending)
    FCM_TRY(ctx, fcm__mg_carry_blocks_prior(m, carry, l, &prior, &rows_same, &has_prior));
  FCM_TRY(ctx, fcm__mg_level_blocks(m, l, &nb, &ptr, &dofs));
  for (fcm_index k = 0; k < nb; k++)
    *bmax = FCM_MAX(*bmax, ptr[k + 1] - ptr[k]);
  if (nb > 0 && old && same[l]) FCM_TRY(ctx, fcm__mg_keep_blocks(old, m, l, nb, ptr, dofs, &kept));
  if (nb > 0 && !kept) {
    if (m->values_pending) { /* the row order's flags spare the scans' comparisons */
      FCM_TRY(ctx, fcm__schwarz_create_blocks_pattern(ctx, fcm__mg_level_matrix(L), nb, ptr, dofs,
                                                      L->rows.triple, has_prior ? &prior : NULL,
                                                      &L->blk));
      *carried = fcm__schwarz_carried(L->blk);
    } else {
      FCM_TRY(ctx,
              fcm__schwarz_create_blocks(ctx, fcm__mg_level_matrix(L), nb, ptr, dofs, &L->blk));
    }
    FCM_TRY(ctx, block_slabs(m, L));
  }
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  fcm__free(ctx, rows_same);
  return st;
}

fcm_status fcm__mg_block_smoothers_create(fcm_mg *m, fcm_mg *old, const unsigned char *same,
                                          const struct mg_carry *carry, int first)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  for (int l = first; l + 1 < m->nlev; l++) {
    fcm_index bmax = 0, carried = 0;
    FCM_TRY(ctx, fcm__mg_level_block_smoother(m, old, same, carry, l, &bmax, &carried));
    m->blk_max = FCM_MAX(m->blk_max, bmax);
    m->kept.carried_blocks += carried;
  }
cleanup:
  return st;
}

fcm_status fcm__mg_block_buffers(fcm_mg *m)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m->ctx;
  FCM_ALLOC(ctx, (size_t)m->nt * (size_t)m->blk_max + 1, m->blk_r);
  FCM_ALLOC(ctx, (size_t)m->nt * (size_t)m->blk_max + 1, m->blk_dx);
cleanup:
  return st;
}

/* ------------------------------------------------------------------ slab check */

/* Slab of each item (-1: none; FCM_ERR_INTERNAL when an item is listed twice). */
static fcm_status slab_of_items(fcm_ctx *ctx, const slab_order *S, fcm_index n, int level,
                                const char *what, fcm_index **out)
{
  fcm_status st = FCM_OK;
  fcm_index *of = NULL;
  FCM_ALLOC_RAW(ctx, n + 1, of);
  for (fcm_index i = 0; i < n; i++)
    of[i] = -1;
  for (fcm_index k = 0; k < S->nslab; k++)
    for (fcm_index q = S->ptr[k]; q < S->ptr[k + 1]; q++) {
      const fcm_index i = S->item[q];
      FCM_CHECK(i >= 0 && i < n && of[i] < 0, ctx, FCM_ERR_INTERNAL,
                "mg: level %d: %s %lld listed twice or out of range [0, %lld) (slab %lld)", level,
                what, (long long)i, (long long)n, (long long)k);
      of[i] = k;
    }
  *out = of;
  of = NULL;
cleanup:
  fcm__free(ctx, of);
  return st;
}

fcm_status fcm__mg_slabs_check(const fcm_mg *m, int level, fcm_index *row_slabs,
                               fcm_index *block_slabs)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = m ? m->ctx : NULL;
  fcm_index *rs = NULL, *bs = NULL, *rb_ptr = NULL, *rb = NULL, *fill = NULL;
  FCM_CHECK(m && level >= 0 && level + 1 < m->nlev, ctx, FCM_ERR_ARG,
            "mg_slabs_check: NULL argument or level %d outside [0, %d)", level,
            m ? m->nlev - 1 : 0);
  const mg_level *L = &m->lev[level];
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const fcm_index n = L->n;
  if (row_slabs) *row_slabs = L->rows.nslab;
  if (block_slabs) *block_slabs = L->blocks.nslab;
  if (L->rows.nslab > 0) {
    FCM_TRY(ctx, slab_of_items(ctx, &L->rows, n, level, "row", &rs));
    for (fcm_index i = 0; i < n; i++) {
      FCM_CHECK(rs[i] >= 0, ctx, FCM_ERR_INTERNAL, "mg: level %d: row %lld in no slab", level,
                (long long)i);
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++) {
        const fcm_index j = ci[p];
        FCM_CHECK(rs[j] == rs[i] || (rs[j] - rs[i]) % 2 != 0, ctx, FCM_ERR_INTERNAL,
                  "mg: level %d: rows %lld and %lld are coupled but lie in slabs %lld and %lld "
                  "of one colour",
                  level, (long long)i, (long long)j, (long long)rs[i], (long long)rs[j]);
      }
    }
  }
  if (L->blocks.nslab > 0) {
    const fcm_index nb = fcm__schwarz_num_blocks(L->blk);
    FCM_TRY(ctx, slab_of_items(ctx, &L->blocks, nb, level, "block", &bs));
    /* the blocks of each row */
    FCM_ALLOC(ctx, n + 1, rb_ptr);
    FCM_ALLOC(ctx, n + 1, fill);
    for (fcm_index k = 0; k < nb; k++) {
      const fcm_index *d = NULL;
      const double *S = NULL;
      const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
      FCM_CHECK(bs[k] >= 0, ctx, FCM_ERR_INTERNAL, "mg: level %d: block %lld in no slab", level,
                (long long)k);
      for (int i = 0; i < bm; i++)
        rb_ptr[d[i] + 1]++;
    }
    for (fcm_index i = 0; i < n; i++)
      rb_ptr[i + 1] += rb_ptr[i];
    FCM_ALLOC(ctx, rb_ptr[n] + 1, rb);
    for (fcm_index k = 0; k < nb; k++) {
      const fcm_index *d = NULL;
      const double *S = NULL;
      const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
      for (int i = 0; i < bm; i++)
        rb[rb_ptr[d[i]] + fill[d[i]]++] = k;
    }
    for (fcm_index k = 0; k < nb; k++) {
      const fcm_index *d = NULL;
      const double *S = NULL;
      const int bm = fcm__schwarz_block(L->blk, k, &d, &S);
      for (int i = 0; i < bm; i++)
        for (fcm_index p = rp[d[i]]; p < rp[d[i] + 1]; p++)
          for (fcm_index q = rb_ptr[ci[p]]; q < rb_ptr[ci[p] + 1]; q++) {
            const fcm_index j = rb[q];
            FCM_CHECK(bs[j] == bs[k] || (bs[j] - bs[k]) % 2 != 0, ctx, FCM_ERR_INTERNAL,
                      "mg: level %d: blocks %lld and %lld touch (DOFs %lld, %lld) but lie in "
                      "slabs %lld and %lld of one colour",
                      level, (long long)k, (long long)j, (long long)d[i], (long long)ci[p],
                      (long long)bs[k], (long long)bs[j]);
          }
    }
  }
cleanup:
  fcm__free(ctx, rs);
  fcm__free(ctx, bs);
  fcm__free(ctx, rb_ptr);
  fcm__free(ctx, rb);
  fcm__free(ctx, fill);
  return st;
}
