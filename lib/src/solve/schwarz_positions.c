/* Where the additive Schwarz blocks' entries lie in the matrix's rows (the positions the
 * set-up gathers through): found from the pattern alone, a node's three rows of one pattern
 * read once, or copied from an earlier block smoother's blocks over a renumbering (a cut)
 * where a block and its rows are the old ones mapped. */
#include "solve/schwarz_impl.h"

#include <omp.h>
#include <string.h>

/* Do block rows i, i + 1, i + 2 hold a node's three DOFs (d[i] = 3 k, d[i + 1] = 3 k + 1,
 * d[i + 2] = 3 k + 2) whose rows of C share one pattern (tri: C's rows' flags,
 * FCM__SCHWARZ_ROWS_SAME at 3 k, or NULL: compared here)? */
static int rows_triple(const fcm_index *rp, const int *ci, const unsigned char *tri, int m,
                       const fcm_index *d, int i)
{
  const fcm_index r = d[i];
  if (r % 3 != 0 || i + 2 >= m || d[i + 1] != r + 1 || d[i + 2] != r + 2) return 0;
  if (tri) return tri[r] != 0;
  const fcm_index len = rp[r + 1] - rp[r];
  return rp[r + 2] - rp[r + 1] == len && rp[r + 3] - rp[r + 2] == len &&
         !memcmp(ci + rp[r], ci + rp[r + 1], sizeof *ci * (size_t)len) &&
         !memcmp(ci + rp[r], ci + rp[r + 2], sizeof *ci * (size_t)len);
}

/* Row r's positions of the block's columns 0 .. last into row (-1 where none; loc: DOF ->
 * block column + 1); cnt[t]: those new in columns 0 .. i + t. Where the row's columns come in
 * whole nodes and so do the block's DOFs (nodes), one look-up a node: a node's first DOF
 * outside the block has its other two outside too, and inside, they follow it. */
static void scan_row(const fcm_index *rp, const int *ci, fcm_index r, const int *loc, int nodes,
                     int i, int last, int *row, size_t cnt[3])
{
  const int step = nodes ? 3 : 1;
  for (fcm_index p = rp[r]; p < rp[r + 1]; p += step) {
    const int k = loc[ci[p]];
    if (!k) continue;
    for (int c = 0; c < step && k - 1 + c <= last; c++) {
      const int j = k - 1 + c;
      if (row[j] < 0)
        for (int t = FCM_MAX(j - i, 0); t < 3; t++)
          cnt[t]++;
      row[j] = (int)(p + c - rp[r]);
    }
  }
}

/* gather_scan()'s positions (pos, *full) from C's pattern alone (tri: C's rows' flags, or
 * NULL). Where rows i, i + 1, i + 2 are a node's three (rows_triple()), rows i + 1 and i + 2
 * of pos begin with row i's (a position is counted from its row's start): row i is read once,
 * to the block's column i + 2, into packed row i + 2, whose beginnings rows i and i + 1 take. */
static void scan_pattern(const fcm_csr *C, const unsigned char *tri, int m, const fcm_index *d,
                         int *loc, int *pos, unsigned char *full)
{
  const fcm_index *rp = fcm_csr_row_ptr(C);
  const int *ci = fcm_csr_col_idx(C);
  size_t stored = 0;
  int whole = tri && m % 3 == 0; /* the block's DOFs come in whole nodes */
  for (int j = 0; whole && j < m; j += 3)
    whole = d[j] % 3 == 0 && d[j + 1] == d[j] + 1 && d[j + 2] == d[j] + 2;
  for (size_t e = 0; e < FCM__SCHWARZ_PACKED(m, 0); e++)
    pos[e] = -1;
  for (int j = 0; j < m; j++)
    loc[d[j]] = j + 1;
  for (int i = 0; i < m; i++) {
    const int triple = rows_triple(rp, ci, tri, m, d, i), last = triple ? i + 2 : i;
    const int nodes = whole && triple && tri[d[i]] == FCM__SCHWARZ_ROWS_NODES;
    int *row = pos + FCM__SCHWARZ_PACKED(last, 0);
    size_t cnt[3] = {0, 0, 0}; /* stored in rows i, i + 1, i + 2 */
    scan_row(rp, ci, d[i], loc, nodes, i, last, row, cnt);
    stored += cnt[0];
    if (triple) {
      memcpy(pos + FCM__SCHWARZ_PACKED(i, 0), row, sizeof *row * (size_t)(i + 1));
      memcpy(pos + FCM__SCHWARZ_PACKED(i + 1, 0), row, sizeof *row * (size_t)(i + 2));
      stored += cnt[1] + cnt[2];
      i += 2;
    }
  }
  for (int j = 0; j < m; j++)
    loc[d[j]] = 0;
  *full = stored == FCM__SCHWARZ_PACKED(m, 0);
}

/* The positions of every block's entries in C's rows, as gather_scan() finds them, from C's
 * pattern alone (a creation without values): the first setup gathers the blocks whose entries
 * are all stored through them (the same values as a scan), and scans the others. Blocks shared
 * by the threads, each with its DOF map (zero between blocks). */
void fcm__schwarz_scan_positions(fcm_schwarz *P, const fcm_csr *C, const unsigned char *tri)
{
  const fcm_index nb = P->num_blocks;
#pragma omp parallel num_threads(P->nt) if (P->nt > 1 && nb > SCAN_PARALLEL_BLOCKS)
  {
    int *loc = P->loc + (size_t)P->n * (size_t)omp_get_thread_num();
#pragma omp for schedule(dynamic, 64)
    for (fcm_index b = 0; b < nb; b++)
      scan_pattern(C, tri, (int)(P->block_ptr[b + 1] - P->block_ptr[b]), P->dofs + P->block_ptr[b],
                   loc, P->pos + P->pos_off[b], &P->full[b]);
  }
}

/* The old blocks by their first DOF (CSR over old's rows), for fcm__schwarz_positions_from(). */
static fcm_status old_by_first(fcm_ctx *ctx, const fcm_schwarz *old, fcm_index **ptr_out,
                               fcm_index **blk_out)
{
  fcm_status st = FCM_OK;
  fcm_index *ptr = NULL, *blk = NULL;
  const fcm_index nb = old->num_blocks;
  FCM_ALLOC(ctx, old->n + 2, ptr);
  FCM_ALLOC_RAW(ctx, nb + 1, blk); /* every entry written below */
  for (fcm_index b = 0; b < nb; b++)
    ptr[old->dofs[old->block_ptr[b]] + 2]++;
  for (fcm_index i = 0; i < old->n; i++)
    ptr[i + 2] += ptr[i + 1];
  for (fcm_index b = 0; b < nb; b++)
    blk[ptr[old->dofs[old->block_ptr[b]] + 1]++] = b;
  *ptr_out = ptr, *blk_out = blk;
  ptr = blk = NULL;
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, blk);
  return st;
}

/* The old block whose positions are block b's (-1: none): its DOFs block b's mapped
 * (row_old) one by one, and every row of block b the old one's mapped, column for column in
 * the same order (same, per node: 3 rows; the positions, counted from a row's start, are then
 * the same). */
static fcm_index old_block(const fcm_schwarz *P, const fcm__schwarz_prior *pr,
                           const fcm_index *optr, const fcm_index *oblk, fcm_index b)
{
  const fcm_schwarz *old = pr->old;
  const fcm_index *d = P->dofs + P->block_ptr[b], m = P->block_ptr[b + 1] - P->block_ptr[b];
  const fcm_index f = pr->row_old[d[0]];
  if (f < 0) return -1;
  for (fcm_index j = 0; j < m; j++)
    if (!pr->same[d[j] / 3]) return -1;
  for (fcm_index q = optr[f]; q < optr[f + 1]; q++) {
    const fcm_index ob = oblk[q], *od = old->dofs + old->block_ptr[ob];
    if (old->block_ptr[ob + 1] - old->block_ptr[ob] != m) continue;
    fcm_index j = 1;
    while (j < m && pr->row_old[d[j]] == od[j])
      j++;
    if (j == m) return ob;
  }
  return -1;
}

/* Blocks b0 .. b1 - 1 of fcm__schwarz_positions_from() (loc: the running thread's DOF map):
 * copied where old_block() finds their old block, else scanned; the number copied. */
static fcm_index positions_range(fcm_schwarz *P, const fcm_csr *C, const unsigned char *tri,
                                 const fcm__schwarz_prior *pr, const fcm_index *optr,
                                 const fcm_index *oblk, fcm_index b0, fcm_index b1, int *loc)
{
  fcm_index carried = 0;
  for (fcm_index b = b0; b < b1; b++) {
    const fcm_index ob = old_block(P, pr, optr, oblk, b);
    const int m = (int)(P->block_ptr[b + 1] - P->block_ptr[b]);
    if (ob >= 0) {
      memcpy(P->pos + P->pos_off[b], pr->old->pos + pr->old->pos_off[ob],
             sizeof *P->pos * FCM__SCHWARZ_PACKED(m, 0));
      P->full[b] = pr->old->full[ob];
      carried++;
    } else {
      scan_pattern(C, tri, m, P->dofs + P->block_ptr[b], loc, P->pos + P->pos_off[b], &P->full[b]);
    }
  }
  return carried;
}

/* fcm__schwarz_scan_positions(), the positions of the blocks that are old blocks mapped
 * (old_block()) copied from them. Called from a task of an active team (a cut's structure
 * made beside other work: mg/mg.c create_beside()), the blocks go in tasks that any thread of
 * the team takes when it is free; else in a parallel loop of the creation's threads. */
fcm_status fcm__schwarz_positions_from(fcm_schwarz *P, const fcm_csr *C, const unsigned char *tri,
                                       const fcm__schwarz_prior *pr)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = P->ctx;
  fcm_index *optr = NULL, *oblk = NULL, carried = 0;
  const fcm_index nb = P->num_blocks;
  FCM_TRY(ctx, old_by_first(ctx, pr->old, &optr, &oblk));
  if (omp_in_parallel() && omp_get_num_threads() <= P->nt && nb > SCAN_PARALLEL_BLOCKS) {
    const fcm_index nch = 8 * (fcm_index)omp_get_num_threads();
#pragma omp taskloop default(shared) grainsize(1)
    for (size_t c = 0; c < (size_t)nch; c++) { /* size_t: clang's task loop counts so */
      const fcm_index k = positions_range(P, C, tri, pr, optr, oblk, nb * (fcm_index)c / nch,
                                          nb * (fcm_index)(c + 1) / nch,
                                          P->loc + (size_t)P->n * (size_t)omp_get_thread_num());
#pragma omp atomic
      carried += k;
    }
  } else {
#pragma omp parallel num_threads(P->nt) if (P->nt > 1 && nb > SCAN_PARALLEL_BLOCKS) \
    reduction(+ : carried)
    {
      int *loc = P->loc + (size_t)P->n * (size_t)omp_get_thread_num();
#pragma omp for schedule(dynamic, 64)
      for (fcm_index b = 0; b < nb; b++)
        carried += positions_range(P, C, tri, pr, optr, oblk, b, b + 1, loc);
    }
  }
  P->carried = carried;
cleanup:
  fcm__free(ctx, optr);
  fcm__free(ctx, oblk);
  return st;
}

fcm_index fcm__schwarz_carried(const fcm_schwarz *P)
{
  return P ? P->carried : 0;
}

int fcm__schwarz_same_positions(const fcm_schwarz *a, const fcm_schwarz *b)
{
  if (!a || !b || a->num_blocks != b->num_blocks || !a->pos || !b->pos) return 0;
  const fcm_index nb = a->num_blocks;
  if (memcmp(a->block_ptr, b->block_ptr, sizeof *a->block_ptr * (size_t)(nb + 1)) != 0 ||
      memcmp(a->dofs, b->dofs, sizeof *a->dofs * (size_t)a->block_ptr[nb]) != 0 ||
      memcmp(a->full, b->full, (size_t)nb) != 0)
    return 0;
  return memcmp(a->pos, b->pos, sizeof *a->pos * a->pos_off[nb]) == 0;
}

int *fcm__schwarz_positions(fcm_schwarz *P, size_t *count)
{
  *count = P && P->pos ? P->pos_off[P->num_blocks] : 0;
  return P ? P->pos : NULL;
}
