/* The sparse triple product C = P^T A P (PETSc's MatPtAP): patterns once, values as often as A
 * changes, rows shared by the threads with results that do not depend on their number. */
#include "la/ptap_impl.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Sort a[0 .. n) ascending (distinct values: a row's columns): quicksort on the median of
 * three down to short runs, then insertion sort: qsort() calls its comparison through a
 * pointer, half of the pattern's time on the multigrid's Galerkin products. */
void fcm__ptap_sort_ints(int *a, fcm_index n)
{
  while (n > 16) {
    const fcm_index mid = n / 2;
    int x = a[0], y = a[mid], z = a[n - 1];
    const int piv = x < y ? (y < z ? y : (x < z ? z : x)) : (x < z ? x : (y < z ? z : y));
    fcm_index i = 0, j = n - 1;
    for (;;) {
      while (a[i] < piv)
        i++;
      while (a[j] > piv)
        j--;
      if (i >= j) break;
      const int t = a[i];
      a[i] = a[j], a[j] = t;
      i++, j--;
    }
    /* [0, j] <= piv <= [j + 1, n): recurse on the shorter part, loop on the longer */
    if (j + 1 < n - (j + 1)) {
      fcm__ptap_sort_ints(a, j + 1);
      a += j + 1, n -= j + 1;
    } else {
      fcm__ptap_sort_ints(a + j + 1, n - (j + 1));
      n = j + 1;
    }
  }
  for (fcm_index i = 1; i < n; i++) {
    const int v = a[i];
    fcm_index k = i;
    for (; k > 0 && a[k - 1] > v; k--)
      a[k] = a[k - 1];
    a[k] = v;
  }
}

/* Are P's rows node-structured: rows 3 k + 1 and 3 k + 2 row 3 k's columns (each 3 K) + 1
 * and + 2, n and nc multiples of 3? */
static int p_by_nodes(fcm_index n, fcm_index nc, const fcm_index *P_ptr, const int *P_col)
{
  if (n % 3 != 0 || nc % 3 != 0) return 0;
  for (fcm_index k = 0; k < n / 3; k++) {
    const fcm_index p0 = P_ptr[3 * k], len = P_ptr[3 * k + 1] - p0;
    if (P_ptr[3 * k + 2] - P_ptr[3 * k + 1] != len || P_ptr[3 * k + 3] - P_ptr[3 * k + 2] != len)
      return 0;
    const int *c0 = P_col + p0, *c1 = c0 + len, *c2 = c1 + len;
    for (fcm_index q = 0; q < len; q++)
      if (c0[q] % 3 != 0 || c1[q] != c0[q] + 1 || c2[q] != c0[q] + 2) return 0;
  }
  return 1;
}

/* R = P^T: row J of R lists the rows i of P with a column J, ascending. Node-structured P
 * (p_by_nodes()): rows 3 K + c of R are the rows 3 k + c of the k with a column 3 K, so each
 * node's three rows are placed together. */
fcm_status fcm__ptap_transpose_pattern(fcm_ctx *ctx, fcm_index n, fcm_index nc,
                                       const fcm_index *P_ptr, const int *P_col,
                                       const double *P_val, fcm_index **R_ptr, int **R_col,
                                       double **R_val)
{
  fcm_status st = FCM_OK;
  fcm_index *fill = NULL;
  const fcm_index nnz = P_ptr[n];
  FCM_ALLOC(ctx, nc + 2, *R_ptr);
  FCM_ALLOC_RAW(ctx, nnz + 1, *R_col); /* written in full below */
  FCM_ALLOC_RAW(ctx, nnz + 1, *R_val);
  FCM_ALLOC(ctx, nc + 1, fill);
  fcm_index *rp = *R_ptr;
  int *rc = *R_col;
  double *rv = *R_val;
  if (p_by_nodes(n, nc, P_ptr, P_col)) {
    for (fcm_index k = 0; k < n / 3; k++)
      for (fcm_index p = P_ptr[3 * k]; p < P_ptr[3 * k + 1]; p++)
        rp[P_col[p] + 1]++;
    for (fcm_index K = 0; K < nc; K += 3)
      rp[K + 2] = rp[K + 3] = rp[K + 1];
    for (fcm_index J = 0; J < nc; J++)
      rp[J + 1] += rp[J];
    for (fcm_index k = 0; k < n / 3; k++) {
      const fcm_index p0 = P_ptr[3 * k], len = P_ptr[3 * k + 1] - p0;
      for (fcm_index q = 0; q < len; q++) {
        const fcm_index J = P_col[p0 + q], f = fill[J / 3]++;
        for (int c = 0; c < 3; c++) {
          rc[rp[J + c] + f] = (int)(3 * k + c);
          rv[rp[J + c] + f] = P_val[p0 + c * len + q];
        }
      }
    }
  } else {
    for (fcm_index p = 0; p < nnz; p++)
      rp[P_col[p] + 1]++;
    for (fcm_index J = 0; J < nc; J++)
      rp[J + 1] += rp[J];
    for (fcm_index i = 0; i < n; i++)
      for (fcm_index p = P_ptr[i]; p < P_ptr[i + 1]; p++) {
        const fcm_index J = P_col[p];
        rc[rp[J] + fill[J]] = (int)i;
        rv[rp[J] + fill[J]++] = P_val[p];
      }
  }
cleanup:
  fcm__free(ctx, fill);
  return st;
}

/* Rows per chunk of the symbolic product: the unit a thread takes at a time (a multiple of 3,
 * so that a node's three rows lie in one chunk). */
#define PATTERN_CHUNK 255

/* What the threads of product_pattern() share. Each thread t appends the columns of the chunks
 * it takes to its own buffer buf[t] (cap[t] entries, len[t] used); chunk c's rows, but those
 * repeating the row before (dup), lie at buf[thr[c]] + off[c], rows in order, and row i's count
 * in Cp[i + 1]. */
typedef struct pattern_work {
  fcm_index nrow, ncol;
  const fcm_index *Ap, *Bp;
  const int *Ac, *Bc;
  int sorted;
  const unsigned char *dup;     /* per row (NULL: none): its pattern is the row before's */
  const unsigned char *bnode;   /* per node g of B's rows (NULL: none): rows 3 g + 1, 3 g + 2 are
                                   row 3 g's with each column + 1, + 2, which are 3 G */
  const unsigned char *bclosed; /* per row of B (NULL: none): its columns come as 3 G, 3 G + 1,
                                   3 G + 2 together */
  unsigned char *closed;        /* per row of C (NULL: not recorded): found by row_by_nodes() */
  fcm_index *Cp;
  fcm_index *mark, *stamp; /* per thread: ncol marks, and the stamp of its current row */
  int *row;                /* per thread: ncol + 1 columns of the current row */
  int **buf;
  size_t *cap, *len;
  int *thr;
  size_t *off;
} pattern_work;

/* Is row i of chunk c the row before's pattern (both in the chunk)? */
static int pattern_dup(const pattern_work *w, fcm_index c, fcm_index i)
{
  return w->dup && i > c * PATTERN_CHUNK && w->dup[i];
}

/* Does row i of A go by row_by_nodes()? Its columns a node's three after the other's, each node
 * with rows of B shifted per component (bnode). */
static int row_of_nodes(const pattern_work *w, fcm_index i)
{
  const fcm_index p0 = w->Ap[i], p1 = w->Ap[i + 1];
  if (!w->bnode || (p1 - p0) % 3 != 0) return 0;
  for (fcm_index p = p0; p < p1; p += 3) {
    const fcm_index k = w->Ac[p];
    if (k % 3 != 0 || w->Ac[p + 1] != k + 1 || w->Ac[p + 2] != k + 2 || !w->bnode[k / 3]) return 0;
  }
  return 1;
}

/* Row i's columns as the plain loop finds them (first reached, A's row order, then B's), a
 * node at a time: the new columns 3 G of row 3 k of B, then their 3 G + 1 (row 3 k + 1 reaches
 * them in that order, and 3 G + 1 is new exactly where 3 G was: every node of the row adds a
 * column's three together), then 3 G + 2. Marks the columns 3 G only. */
static fcm_index row_by_nodes(const pattern_work *w, fcm_index i, fcm_index *mk, fcm_index tag,
                              int *row)
{
  fcm_index cnt = 0;
  for (fcm_index p = w->Ap[i]; p < w->Ap[i + 1]; p += 3) {
    const fcm_index k = w->Ac[p], start = cnt;
    for (fcm_index q = w->Bp[k]; q < w->Bp[k + 1]; q++) {
      const fcm_index j = w->Bc[q];
      if (mk[j] == tag) continue;
      mk[j] = tag;
      row[cnt++] = (int)j;
    }
    const fcm_index added = cnt - start;
    for (int c = 1; c < 3; c++)
      for (fcm_index t = 0; t < added; t++)
        row[cnt++] = row[start + t] + c;
  }
  return cnt;
}

/* Does row i of A (sorted output) go by row_by_closed()? Every row of B it reaches closed. */
static int row_of_closed(const pattern_work *w, fcm_index i)
{
  if (!w->bclosed || !w->sorted) return 0;
  for (fcm_index p = w->Ap[i]; p < w->Ap[i + 1]; p++)
    if (!w->bclosed[w->Ac[p]]) return 0;
  return 1;
}

/* Row i's columns sorted when every row of B it reaches holds a node's three columns together:
 * the nodes' first columns 3 G reached, sorted, each followed by 3 G + 1 and 3 G + 2 (the plain
 * loop's set, in order). Marks the columns 3 G only. */
static fcm_index row_by_closed(const pattern_work *w, fcm_index i, fcm_index *mk, fcm_index tag,
                               int *row)
{
  fcm_index cnt = 0;
  for (fcm_index p = w->Ap[i]; p < w->Ap[i + 1]; p++) {
    const fcm_index k = w->Ac[p];
    for (fcm_index q = w->Bp[k]; q < w->Bp[k + 1]; q++) {
      const fcm_index j = w->Bc[q];
      if (j % 3 != 0 || mk[j] == tag) continue;
      mk[j] = tag;
      row[cnt++] = (int)j;
    }
  }
  fcm__ptap_sort_ints(row, cnt);
  for (fcm_index t = cnt - 1; t >= 0; t--) { /* from the back: row[t] read before overwritten */
    const int j = row[t];
    row[3 * t] = j, row[3 * t + 1] = j + 1, row[3 * t + 2] = j + 2;
  }
  return 3 * cnt;
}

/* Chunk c's rows by thread t into its buffer: 1, or 0 (nothing kept) when they do not fit. A
 * row's columns are those first reached (A's row order, then B's), sorted when asked; a row
 * repeating the row before is counted, not stored. */
static int pattern_chunk(pattern_work *w, int t, fcm_index c)
{
  fcm_index *mk = w->mark + (size_t)t * (size_t)w->ncol;
  int *row = w->row + (size_t)t * (size_t)(w->ncol + 1);
  const size_t off = w->len[t];
  const fcm_index i1 = FCM_MIN(w->nrow, (c + 1) * PATTERN_CHUNK);
  fcm_index cnt = 0;
  for (fcm_index i = c * PATTERN_CHUNK; i < i1; i++) {
    if (pattern_dup(w, c, i)) {
      w->Cp[i + 1] = cnt;
      if (w->closed) w->closed[i] = w->closed[i - 1];
      continue;
    }
    const fcm_index tag = w->stamp[t]++;
    cnt = 0;
    const int by_nodes = row_of_nodes(w, i), by_closed = !by_nodes && row_of_closed(w, i);
    if (w->closed) w->closed[i] = (unsigned char)by_nodes;
    if (by_nodes) cnt = row_by_nodes(w, i, mk, tag, row);
    if (by_closed) cnt = row_by_closed(w, i, mk, tag, row);
    for (fcm_index p = w->Ap[i]; p < w->Ap[i + 1] && !by_nodes && !by_closed; p++) {
      const fcm_index k = w->Ac[p];
      for (fcm_index q = w->Bp[k]; q < w->Bp[k + 1]; q++) {
        const fcm_index j = w->Bc[q];
        if (mk[j] == tag) continue;
        mk[j] = tag;
        row[cnt++] = (int)j;
      }
    }
    if (w->len[t] + (size_t)cnt > w->cap[t]) {
      w->len[t] = off;
      return 0;
    }
    if (w->sorted && !by_closed) fcm__ptap_sort_ints(row, cnt);
    memcpy(w->buf[t] + w->len[t], row, sizeof *row * (size_t)cnt);
    w->len[t] += (size_t)cnt;
    w->Cp[i + 1] = cnt;
  }
  w->thr[c] = t, w->off[c] = off;
  return 1;
}

/* Chunk c's columns from its buffer into Cc (Cp summed), the repeated rows copied. */
static void pattern_gather(const pattern_work *w, fcm_index c, int *Cc)
{
  const int *from = w->buf[w->thr[c]] + w->off[c];
  const fcm_index i1 = FCM_MIN(w->nrow, (c + 1) * PATTERN_CHUNK);
  for (fcm_index i = c * PATTERN_CHUNK; i < i1; i++) {
    const fcm_index len = w->Cp[i + 1] - w->Cp[i];
    if (pattern_dup(w, c, i)) {
      memcpy(Cc + w->Cp[i], Cc + w->Cp[i - 1], sizeof *Cc * (size_t)len);
    } else {
      memcpy(Cc + w->Cp[i], from, sizeof *Cc * (size_t)len);
      from += len;
    }
  }
}

/* Chunks of rows shared by nt threads in one pass: a thread whose buffer is full leaves its
 * chunks for another round after the buffer has grown (from `guess` entries in all, or A's
 * entries and a quarter when 0). */
fcm_status fcm__ptap_product_pattern(fcm_ctx *ctx, int nt, fcm_index nrow, const fcm_index *Ap,
                                     const int *Ac, const fcm_index *Bp, const int *Bc,
                                     fcm_index ncol, int sorted, const unsigned char *dup,
                                     const unsigned char *bnode, unsigned char *closed,
                                     const unsigned char *bclosed, fcm_index guess,
                                     fcm_index **Cp_out, int **Cc_out)
{
  fcm_status st = FCM_OK;
  const fcm_index nchunk = (nrow + PATTERN_CHUNK - 1) / PATTERN_CHUNK;
  fcm_index *pending = NULL, npending = nchunk;
  unsigned char *full = NULL, *left = NULL;
  int *Cc = NULL;
  pattern_work w = {.nrow = nrow,
                    .ncol = ncol,
                    .Ap = Ap,
                    .Bp = Bp,
                    .Ac = Ac,
                    .Bc = Bc,
                    .sorted = sorted,
                    .dup = dup,
                    .bnode = bnode,
                    .bclosed = bclosed,
                    .closed = closed};
  FCM_ALLOC(ctx, nrow + 1, w.Cp);
  FCM_ALLOC_RAW(ctx, (size_t)nt * (size_t)ncol + 1, w.mark);
  FCM_ALLOC(ctx, nt, w.stamp);
  FCM_ALLOC_RAW(ctx, (size_t)nt * (size_t)(ncol + 1), w.row);
  FCM_ALLOC(ctx, nt, w.buf);
  FCM_ALLOC(ctx, nt, w.cap);
  FCM_ALLOC(ctx, nt, w.len);
  FCM_ALLOC(ctx, nt, full);
  FCM_ALLOC_RAW(ctx, nchunk + 1, w.thr);
  FCM_ALLOC_RAW(ctx, nchunk + 1, w.off);
  FCM_ALLOC_RAW(ctx, nchunk + 1, pending);
  FCM_ALLOC(ctx, nchunk + 1, left);
  for (size_t j = 0; j < (size_t)nt * (size_t)ncol; j++)
    w.mark[j] = -1;
  for (fcm_index c = 0; c < nchunk; c++)
    pending[c] = c;
  /* a first guess of each thread's share: A's entries and a quarter (A P has about as many) */
  if (guess <= 0) guess = 5 * (Ap[nrow] / 4);
  for (int t = 0; t < nt; t++) {
    w.cap[t] = (size_t)FCM_MAX(guess / nt, 4096);
    FCM_ALLOC_RAW(ctx, w.cap[t], w.buf[t]);
  }
  while (npending > 0) {
#pragma omp parallel num_threads(nt) if (nt > 1 && npending > 1)
    {
      const int t = omp_get_thread_num();
#pragma omp for schedule(dynamic, 1)
      for (fcm_index q = 0; q < npending; q++) {
        left[q] = (unsigned char)(full[t] || !pattern_chunk(&w, t, pending[q]));
        if (left[q]) full[t] = 1;
      }
    }
    fcm_index nleft = 0;
    for (fcm_index q = 0; q < npending; q++)
      if (left[q]) pending[nleft++] = pending[q];
    npending = nleft;
    for (int t = 0; t < nt; t++)
      if (full[t]) {
        FCM_TRY(ctx, fcm__resize(ctx, (void **)&w.buf[t], w.cap[t], 2 * w.cap[t], sizeof(int)));
        w.cap[t] *= 2, full[t] = 0;
      }
  }
  for (fcm_index i = 0; i < nrow; i++)
    w.Cp[i + 1] += w.Cp[i];
  FCM_ALLOC_RAW(ctx, w.Cp[nrow] + 1, Cc); /* every entry copied below */
#pragma omp parallel for num_threads(nt) schedule(static) if (nt > 1 && nchunk > 1)
  for (fcm_index c = 0; c < nchunk; c++)
    pattern_gather(&w, c, Cc);
  *Cp_out = w.Cp, *Cc_out = Cc;
  w.Cp = NULL, Cc = NULL;
cleanup:
  for (int t = 0; w.buf && t < nt; t++)
    fcm__free(ctx, w.buf[t]);
  fcm__free(ctx, w.Cp);
  fcm__free(ctx, Cc);
  fcm__free(ctx, w.mark);
  fcm__free(ctx, w.stamp);
  fcm__free(ctx, w.row);
  fcm__free(ctx, w.buf);
  fcm__free(ctx, w.cap);
  fcm__free(ctx, w.len);
  fcm__free(ctx, w.thr);
  fcm__free(ctx, w.off);
  fcm__free(ctx, full);
  fcm__free(ctx, pending);
  fcm__free(ctx, left);
  return st;
}

/* Insert the missing diagonal entries into a square pattern (rows sorted), in place by
 * reallocation. */
fcm_status fcm__ptap_add_diagonal(fcm_ctx *ctx, fcm_index n, fcm_index **ptr, int **col)
{
  fcm_status st = FCM_OK;
  fcm_index *p = *ptr, *np = NULL;
  int *c = *col, *nc = NULL;
  fcm_index missing = 0;
  for (fcm_index i = 0; i < n; i++) { /* rows sorted: the diagonal by bisection */
    fcm_index lo = p[i], hi = p[i + 1];
    while (lo < hi) {
      const fcm_index mid = lo + (hi - lo) / 2;
      if (c[mid] < i)
        lo = mid + 1;
      else
        hi = mid;
    }
    missing += !(lo < p[i + 1] && c[lo] == i);
  }
  if (missing == 0) goto cleanup;
  FCM_ALLOC(ctx, n + 1, np);
  FCM_ALLOC(ctx, p[n] + missing + 1, nc);
  fcm_index out = 0;
  for (fcm_index i = 0; i < n; i++) {
    int done = 0;
    for (fcm_index q = p[i]; q < p[i + 1]; q++) {
      if (!done && c[q] > i) nc[out++] = (int)i, done = 1;
      if (c[q] == i) done = 1;
      nc[out++] = c[q];
    }
    if (!done) nc[out++] = (int)i;
    np[i + 1] = out;
  }
  fcm__free(ctx, p);
  fcm__free(ctx, c);
  *ptr = np, *col = nc;
  np = NULL, nc = NULL;
cleanup:
  fcm__free(ctx, np);
  fcm__free(ctx, nc);
  return st;
}

/* Row i of C = A B on C's pattern into Cv, through spa (zero on entry and exit). */
static void product_row(fcm_index i, const fcm_index *Ap, const int *Ac, const double *Av,
                        const fcm_index *Bp, const int *Bc, const double *Bv, const fcm_index *Cp,
                        const int *Cc, double *Cv, double *spa)
{
  for (fcm_index p = Ap[i]; p < Ap[i + 1]; p++) {
    const fcm_index k = Ac[p];
    const double a = Av[p];
    for (fcm_index q = Bp[k]; q < Bp[k + 1]; q++)
      spa[Bc[q]] += a * Bv[q];
  }
  for (fcm_index p = Cp[i]; p < Cp[i + 1]; p++) {
    Cv[p] = spa[Cc[p]];
    spa[Cc[p]] = 0.0;
  }
}

/* Whether rows i, i + 1, i + 2 (< the row count) hold one pattern. */
int fcm__ptap_same_pattern3(fcm_index i, const fcm_index *Ap, const int *Ac)
{
  const fcm_index len = Ap[i + 1] - Ap[i];
  return Ap[i + 2] - Ap[i + 1] == len && Ap[i + 3] - Ap[i + 2] == len &&
         memcmp(Ac + Ap[i], Ac + Ap[i + 1], sizeof *Ac * (size_t)len) == 0 &&
         memcmp(Ac + Ap[i], Ac + Ap[i + 2], sizeof *Ac * (size_t)len) == 0;
}

/* Rows i, i + 1, i + 2 of C = A B when the three rows of A have one pattern (a node's three
 * DOFs): each row of B read once for the three, whose sums go to spa3's interleaved slots
 * (3 j + r: row i + r, column j; zero on entry and exit), each in product_row()'s order.
 * The three rows must hold one pattern (fcm__ptap_same_pattern3()). */
static void product_triple(fcm_index i, const fcm_index *Ap, const int *Ac, const double *Av,
                           const fcm_index *Bp, const int *Bc, const double *Bv,
                           const fcm_index *Cp, const int *Cc, double *Cv, double *spa3)
{
  const fcm_index len = Ap[i + 1] - Ap[i];
  for (fcm_index p = Ap[i]; p < Ap[i + 1]; p++) {
    const fcm_index k = Ac[p];
    const double a0 = Av[p], a1 = Av[p + len], a2 = Av[p + 2 * len];
    for (fcm_index q = Bp[k]; q < Bp[k + 1]; q++) {
      double *t = spa3 + 3 * (size_t)Bc[q];
      const double b = Bv[q];
      t[0] += a0 * b;
      t[1] += a1 * b;
      t[2] += a2 * b;
    }
  }
  for (int r = 0; r < 3; r++)
    for (fcm_index p = Cp[i + r]; p < Cp[i + r + 1]; p++) {
      double *t = spa3 + 3 * (size_t)Cc[p] + r;
      Cv[p] = *t;
      *t = 0.0;
    }
}

/* Rows i, i + 1, i + 2 of C = A B when row i + r of A is row i's with each column j + r and
 * the same values, and rows j, j + 1, j + 2 of B (j a column of row i) hold one pattern (R's
 * rows of a coarse node, the rows of A P of a fine node): each column index of B read once for
 * the three, into spa3 as product_triple(), each entry in product_row()'s order. */
static void product_shifted(fcm_index i, const fcm_index *Ap, const int *Ac, const double *Av,
                            const fcm_index *Bp, const int *Bc, const double *Bv,
                            const fcm_index *Cp, const int *Cc, double *Cv, double *spa3)
{
  for (fcm_index p = Ap[i]; p < Ap[i + 1]; p++) {
    const fcm_index k = Ac[p], len = Bp[k + 1] - Bp[k];
    const double a = Av[p];
    for (fcm_index q = Bp[k]; q < Bp[k + 1]; q++) {
      double *t = spa3 + 3 * (size_t)Bc[q];
      t[0] += a * Bv[q];
      t[1] += a * Bv[q + len];
      t[2] += a * Bv[q + 2 * len];
    }
  }
  for (int r = 0; r < 3; r++)
    for (fcm_index p = Cp[i + r]; p < Cp[i + r + 1]; p++) {
      double *t = spa3 + 3 * (size_t)Cc[p] + r;
      Cv[p] = *t;
      *t = 0.0;
    }
}

/* Whether rows i, i + 1, i + 2 (< A's row count) of A = R may go by product_shifted() with
 * B = A P, whose groups of three rows b_same3 flags as one pattern each; Av NULL: the
 * pattern's part of the test alone (the three rows of A B then have one pattern); b_same3
 * NULL: the three rows' columns alone (row i + r is row i's with each column + r, all 3 G). */
int fcm__ptap_shifted3(fcm_index i, const fcm_index *Ap, const int *Ac, const double *Av,
                       const unsigned char *b_same3)
{
  const fcm_index len = Ap[i + 1] - Ap[i];
  if (Ap[i + 2] - Ap[i + 1] != len || Ap[i + 3] - Ap[i + 2] != len) return 0;
  for (fcm_index q = 0; q < len; q++) {
    const fcm_index p = Ap[i] + q, p1 = Ap[i + 1] + q, p2 = Ap[i + 2] + q;
    if (Ac[p] % 3 != 0 || (b_same3 && !b_same3[Ac[p] / 3]) || Ac[p1] != Ac[p] + 1 ||
        Ac[p2] != Ac[p] + 2 || (Av && (Av[p1] != Av[p] || Av[p2] != Av[p])))
      return 0;
  }
  return 1;
}

/* Values of C = A B on C's pattern, rows shared by the threads of the enclosing region (ends
 * with a barrier), three at a time where they are a node's: kind per group of three rows
 * (KIND_TRIPLE: product_triple(), KIND_SHIFTED: product_shifted(), KIND_ROWS: one at a
 * time), or NULL: KIND_TRIPLE where the three hold one pattern, checked here;
 * spa: the calling thread's accumulator, 3 (B's columns + 1) doubles (zero on entry and exit).
 * Each entry is summed in A's row order, then B's. */
static void product_values(fcm_index nrow, const fcm_index *Ap, const int *Ac, const double *Av,
                           const fcm_index *Bp, const int *Bc, const double *Bv,
                           const fcm_index *Cp, const int *Cc, double *Cv, double *spa,
                           const unsigned char *kind)
{
  const fcm_index ng = (nrow + 2) / 3;
#pragma omp for schedule(dynamic, 22)
  for (fcm_index g = 0; g < ng; g++) {
    const fcm_index i = 3 * g;
    const int k = i + 2 >= nrow ? KIND_ROWS : kind ? kind[g] : fcm__ptap_same_pattern3(i, Ap, Ac);
    if (k == KIND_TRIPLE) {
      product_triple(i, Ap, Ac, Av, Bp, Bc, Bv, Cp, Cc, Cv, spa);
      continue;
    }
    if (k == KIND_SHIFTED) {
      product_shifted(i, Ap, Ac, Av, Bp, Bc, Bv, Cp, Cc, Cv, spa);
      continue;
    }
    for (fcm_index r = i; r < i + 3 && r < nrow; r++)
      product_row(r, Ap, Ac, Av, Bp, Bc, Bv, Cp, Cc, Cv, spa);
  }
}

void fcm__ptap_destroy(fcm__ptap **plan)
{
  if (!plan || !*plan) return;
  fcm__ptap *t = *plan;
  fcm_ctx *ctx = t->ctx;
  fcm__free(ctx, t->R_ptr);
  fcm__free(ctx, t->R_col);
  fcm__free(ctx, t->R_val);
  fcm__free(ctx, t->AP_ptr);
  fcm__free(ctx, t->AP_col);
  fcm__free_large(ctx, t->AP_val);
  fcm__free(ctx, t->spa);
  fcm__free(ctx, t->same3);
  fcm__free(ctx, t->r_kind);
  fcm__free(ctx, t);
  *plan = NULL;
}

fcm_status fcm__ptap_begin(fcm_ctx *ctx, const fcm_csr *A, fcm_index nc, const fcm_index *P_ptr,
                           const int *P_col, const double *P_val, int nt, const char *who,
                           fcm__ptap **plan)
{
  fcm_status st = FCM_OK;
  fcm__ptap *t = NULL;
  fcm_index n = 0, ncol = 0;
  fcm_csr_get_size(A, &n, &ncol, NULL);
  FCM_CHECK(n == ncol, ctx, FCM_ERR_ARG, "%s: A is %lld x %lld, not square", who, (long long)n,
            (long long)ncol);
  for (fcm_index p = 0; p < P_ptr[n]; p++)
    FCM_CHECK(P_col[p] >= 0 && P_col[p] < nc, ctx, FCM_ERR_ARG,
              "%s: P entry %lld has column %d outside [0, %lld)", who, (long long)p, P_col[p],
              (long long)nc);
  t = fcm__calloc(ctx, 1, sizeof *t);
  FCM_CHECK(t, ctx, FCM_ERR_ALLOC, "%s: out of memory", who);
  t->ctx = ctx, t->n = n, t->nc = nc, t->nt = nt;
  t->P_ptr = P_ptr, t->P_col = P_col, t->P_val = P_val;
  FCM_TRY(ctx, fcm__ptap_transpose_pattern(ctx, n, nc, P_ptr, P_col, P_val, &t->R_ptr, &t->R_col,
                                           &t->R_val));
  FCM_ALLOC(ctx, n / 3 + 1, t->same3);
  *plan = t;
  t = NULL;
cleanup:
  fcm__ptap_destroy(&t);
  return st;
}

fcm_status fcm__ptap_finish(fcm__ptap *t, const fcm_csr *A, const unsigned char *ap3,
                            int with_diagonal, fcm_index **cp, int **cc, fcm_csr **C)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = t->ctx;
  const fcm_index nc = t->nc;
  if (with_diagonal) FCM_TRY(ctx, fcm__ptap_add_diagonal(ctx, nc, cp, cc));
  FCM_ALLOC(ctx, (size_t)t->nt * 3 * (size_t)(nc + 1), t->spa);
  FCM_ALLOC(ctx, (size_t)(nc / 3 + 1), t->r_kind);
  for (fcm_index g = 0; 3 * g + 2 < nc; g++)
    t->r_kind[g] =
        fcm__ptap_shifted3(3 * g, t->R_ptr, t->R_col, t->R_val, ap3) ? KIND_SHIFTED : KIND_ROWS;
  /* rows sorted and in range by construction, symmetric with A's pattern */
  FCM_TRY(ctx, fcm__csr_adopt_pattern(ctx, nc, nc, cp, cc, fcm_csr_get_kind(A), C));
cleanup:
  return st;
}

fcm_status fcm__ptap_create(fcm_ctx *ctx, const fcm_csr *A, fcm_index nc, const fcm_index *P_ptr,
                            const int *P_col, const double *P_val, int with_diagonal, int nt,
                            fcm__ptap **plan, fcm_csr **C)
{
  fcm_status st = FCM_OK;
  fcm__ptap *t = NULL;
  fcm_index *cp = NULL;
  int *cc = NULL;
  unsigned char *dup = NULL, *ap3 = NULL, *pnode = NULL, *closed = NULL;
  FCM_CHECK(ctx && A && P_ptr && (P_ptr[0] == 0) && plan && C && nc >= 0 && nt >= 1, ctx,
            FCM_ERR_ARG, "ptap_create: NULL argument, nc = %lld < 0 or nt = %d < 1", (long long)nc,
            nt);
  *plan = NULL, *C = NULL;
  FCM_TRY(ctx, fcm__ptap_begin(ctx, A, nc, P_ptr, P_col, P_val, nt, "ptap_create", &t));
  const fcm_index n = t->n;
  /* the node's three rows of one pattern in A: every product keeps A's pattern */
#pragma omp parallel for num_threads(nt) schedule(static) if (nt > 1 && n > 4096)
  for (fcm_index g = 0; g < n / 3; g++)
    t->same3[g] =
        (unsigned char)fcm__ptap_same_pattern3(3 * g, fcm_csr_row_ptr(A), fcm_csr_col_idx(A));
  FCM_ALLOC(ctx, FCM_MAX(n, nc) + 1, dup);
  for (fcm_index g = 0; 3 * g + 2 < n; g++)
    dup[3 * g + 1] = dup[3 * g + 2] = t->same3[g];
  FCM_ALLOC(ctx, n + 1, closed);    /* the rows of A P found a node at a time */
  FCM_ALLOC(ctx, n / 3 + 1, pnode); /* P's rows of a node shifted per component */
  for (fcm_index g = 0; 3 * g + 2 < n; g++)
    pnode[g] = (unsigned char)fcm__ptap_shifted3(3 * g, P_ptr, P_col, NULL, NULL);
  /* A P's rows unsorted: each entry of C takes one term from each row of A P it sums, wherever
   * that row holds the column, so C's values do not depend on the order (nor do A P's) */
  FCM_TRY(ctx, fcm__ptap_product_pattern(ctx, nt, n, fcm_csr_row_ptr(A), fcm_csr_col_idx(A), P_ptr,
                                         P_col, nc, 0, dup, pnode, closed, NULL, 0, &t->AP_ptr,
                                         &t->AP_col));
  /* every product writes all of it; a large array, which a successor may take
   * (fcm__ptap_take_scratch()) */
  FCM__ALLOC_WITH(fcm__malloc_large, ctx, t->AP_ptr[n] + 1, t->AP_val);
  /* A P's groups of three rows of one pattern: those of A's (the same columns in the same
   * order, dup above) and any other whose rows agree */
  FCM_ALLOC(ctx, n / 3 + 1, ap3);
#pragma omp parallel for num_threads(nt) schedule(static) if (nt > 1 && n > 4096)
  for (fcm_index g = 0; g < n / 3; g++)
    ap3[g] = (unsigned char)(t->same3[g] || fcm__ptap_same_pattern3(3 * g, t->AP_ptr, t->AP_col));
  /* R's rows 3 J + 1 and 3 J + 2 reach the same columns as row 3 J where they are its rows
   * shifted by one and two to rows of A P of one pattern */
  memset(dup, 0, (size_t)FCM_MAX(n, nc) + 1);
  for (fcm_index g = 0; 3 * g + 2 < nc; g++)
    dup[3 * g + 1] = dup[3 * g + 2] =
        (unsigned char)fcm__ptap_shifted3(3 * g, t->R_ptr, t->R_col, NULL, ap3);
  FCM_TRY(ctx, fcm__ptap_product_pattern(ctx, nt, nc, t->R_ptr, t->R_col, t->AP_ptr, t->AP_col, nc,
                                         1, dup, NULL, NULL, closed, 0, &cp, &cc));
  FCM_TRY(ctx, fcm__ptap_finish(t, A, ap3, with_diagonal, &cp, &cc, C));
  *plan = t;
  t = NULL;
cleanup:
  fcm__free(ctx, cp);
  fcm__free(ctx, cc);
  fcm__free(ctx, dup);
  fcm__free(ctx, ap3);
  fcm__free(ctx, pnode);
  fcm__free(ctx, closed);
  fcm__ptap_destroy(&t);
  return st;
}

void fcm__ptap_apply(fcm__ptap *t, const fcm_csr *A, fcm_csr *C, int nt)
{
  const fcm_index n = t->n, nc = t->nc;
  const fcm_index *cp = fcm_csr_row_ptr(C);
  const int *cc = fcm_csr_col_idx(C);
  double *cv = fcm_csr_values(C);
  nt = nt < 1 ? 1 : nt > t->nt ? t->nt : nt;
#pragma omp parallel num_threads(nt) if (nt > 1)
  {
    double *spa = t->spa + (size_t)omp_get_thread_num() * 3 * (size_t)(nc + 1);
    product_values(n, fcm_csr_row_ptr(A), fcm_csr_col_idx(A), fcm_csr_values_read(A), t->P_ptr,
                   t->P_col, t->P_val, t->AP_ptr, t->AP_col, t->AP_val, spa, t->same3);
    product_values(nc, t->R_ptr, t->R_col, t->R_val, t->AP_ptr, t->AP_col, t->AP_val, cp, cc, cv,
                   spa, t->r_kind);
  }
}

int fcm__ptap_take_scratch(fcm__ptap *t, fcm__ptap *give)
{
  if (!t || !give || t == give) return 0;
  void *from = give->AP_val;
  double *v = fcm__large_take(&from, (size_t)t->AP_ptr[t->n] + 1, sizeof *v);
  if (!v) return 0;
  fcm__free_large(t->ctx, t->AP_val);
  t->AP_val = v;
  give->AP_val = NULL;
  return 1;
}

const double *fcm__ptap_scratch(const fcm__ptap *t)
{
  return t ? t->AP_val : NULL;
}

void fcm__ptap_transpose(const fcm__ptap *t, const fcm_index **R_ptr, const int **R_col,
                         const double **R_val)
{
  *R_ptr = t->R_ptr, *R_col = t->R_col, *R_val = t->R_val;
}

fcm_status fcm_csr_create_ptap(fcm_ctx *ctx, const fcm_csr *A, const fcm_csr *P, fcm_csr **C)
{
  fcm_status st = FCM_OK;
  fcm__ptap *plan = NULL;
  FCM_CHECK(ctx && A && P && C, ctx, FCM_ERR_ARG,
            "csr_create_ptap: ctx, A, P and C must not be NULL");
  *C = NULL;
  FCM_CHECK(P->nrows == A->nrows, ctx, FCM_ERR_ARG,
            "csr_create_ptap: P has %lld rows, A has %lld; they must agree", (long long)P->nrows,
            (long long)A->nrows);
  FCM_TRY(ctx,
          fcm__ptap_create(ctx, A, P->ncols, P->row_ptr, P->col_idx, P->values, 1, 1, &plan, C));
  fcm__ptap_apply(plan, A, *C, 1);
  if ((*C)->kind == FCM_CSR_SYMMETRIC) /* average the pairs rounding left unequal */
    for (fcm_index i = 0; i < (*C)->nrows; i++)
      for (fcm_index p = (*C)->row_ptr[i]; p < (*C)->row_ptr[i + 1]; p++) {
        const fcm_index j = (*C)->col_idx[p];
        if (j <= i) continue;
        const fcm_index q = fcm_csr_position(*C, j, i);
        const double m = 0.5 * ((*C)->values[p] + (*C)->values[q]);
        (*C)->values[p] = (*C)->values[q] = m;
      }
cleanup:
  fcm__ptap_destroy(&plan);
  if (st != FCM_OK && C) fcm_csr_destroy(C);
  return st;
}
