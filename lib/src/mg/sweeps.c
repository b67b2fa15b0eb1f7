/* The multigrid's sweeps, inside the cycle's parallel regions: pointwise symmetric Gauss-Seidel
 * in slab order (a copy's three rows of one pattern together), multicolour SGS, damped
 * Jacobi, and block Gauss-Seidel over the level's blocks (S_K from its lower triangle, or
 * X^T (X r) where a block holds the inverse X of its Cholesky factor, both packed by rows:
 * row i from FCM__SCHWARZ_PACKED(i, 0)); the test hook that checks them against one row at a
 * time. */
#include "core/multiversion.h"
#include "mg/levels_impl.h"

#include <string.h>

/* The sweeps run inside a parallel region of the cycle (or in a team of one, when the level is
 * too small to share; cycle.c) and end without a barrier unless said. */

/* What a slab sweep works on: the level, omega (pointwise), b, x and the thread's block
 * scratch (r, dx). */
typedef struct sweep_args {
  const mg_level *L;
  double w;
  const double *b;
  double *x;
  double *r, *dx;
  fcm__schwarz_view blk; /* block sweeps: L's blocks */
  int plain;             /* one row at a time and full S_K products (the test hook's reference) */
} sweep_args;

/* One symmetric Gauss-Seidel sweep in the slab order S (forward, then backward) by the team
 * of the enclosing region: the slabs of the colour swept first, forward; a barrier; each
 * thread's slabs of the other colour forward and at once backward (they touch no other slab
 * of their colour); a barrier; the first colour's slabs backward. The same threads run the
 * same slabs of the first colour at the start and at the end, so repeated sweeps need no
 * barrier between them; no barrier at the end. slab(a, s, back) sweeps slab s. */
static void symmetric_sweep(const slab_order *S,
                            void (*slab)(const sweep_args *a, fcm_index s, int back),
                            const sweep_args *a)
{
  const int t = omp_get_thread_num(), nt = omp_get_num_threads();
  const int c0 = S->first, c1 = 1 - S->first;
  for (fcm_index k = c0; k < S->nslab; k += 2)
    if (fcm__mg_slab_mine(S, k, t, nt)) slab(a, k, 0);
#pragma omp barrier
  for (fcm_index k = c1; k < S->nslab; k += 2)
    if (fcm__mg_slab_mine(S, k, t, nt)) {
      slab(a, k, 0);
      slab(a, k, 1);
    }
#pragma omp barrier
  for (fcm_index k = c0; k < S->nslab; k += 2)
    if (fcm__mg_slab_mine(S, k, t, nt)) slab(a, k, 1);
}

/* dx = S r for a symmetric m x m S from its lower triangle alone (packed): row i's entries
 * S_ij, j < i, serve dx_i and (as S_ji) dx_j; S streams from memory block after block and
 * its reads are most of the block product's time. Two partial sums per row, the column
 * updates in pairs. */
static inline __attribute__((always_inline)) void sym_lower_apply(const double *S, const double *r,
                                                                  int m, double *dx)
{
  for (int i = 0; i < m; i++)
    dx[i] = 0.0;
  for (int i = 0; i < m; i++) {
    const double *Si = S + FCM__SCHWARZ_PACKED(i, 0);
    const double ri = r[i];
    double s0 = 0.0, s1 = 0.0;
    int j = 0;
    for (; j + 2 <= i; j += 2) {
      s0 += Si[j] * r[j];
      s1 += Si[j + 1] * r[j + 1];
      dx[j] += Si[j] * ri;
      dx[j + 1] += Si[j + 1] * ri;
    }
    for (; j < i; j++) {
      s0 += Si[j] * r[j];
      dx[j] += Si[j] * ri;
    }
    dx[i] += (s0 + s1) + Si[i] * ri;
  }
}

/* y_i = sum_(j <= i) X_ij r_j for rows i0 .. i0 + 3 of a lower triangular X (packed), each
 * row's sum as two partial sums (s0 over the even j, s1 over the odd j, in ascending order),
 * into y[0..3]: the four rows' chains run side by side. */
static inline __attribute__((always_inline)) void factor_rows4(const double *X, const double *r,
                                                               int i0, double y[4])
{
  const double *Xr[4];
  fcm__mg_v2d acc[4];
  for (int k = 0; k < 4; k++) {
    Xr[k] = X + FCM__SCHWARZ_PACKED(i0 + k, 0);
    acc[k] = (fcm__mg_v2d){0.0, 0.0};
  }
  int j = 0;
  for (; j + 2 <= i0 + 1; j += 2) { /* the pairs every row of the four has */
    const fcm__mg_v2d rj = fcm__mg_load2(r + j);
    for (int k = 0; k < 4; k++)
      acc[k] += fcm__mg_load2(Xr[k] + j) * rj;
  }
  for (int k = 0; k < 4; k++) {
    const int i = i0 + k;
    double s0 = acc[k][0], s1 = acc[k][1];
    int jk = j;
    for (; jk + 2 <= i + 1; jk += 2) {
      s0 += Xr[k][jk] * r[jk];
      s1 += Xr[k][jk + 1] * r[jk + 1];
    }
    if (jk <= i) s0 += Xr[k][jk] * r[jk];
    y[k] = s0 + s1;
  }
}

/* dx = X^T X r for a lower triangular m x m X (packed; fcm__schwarz_block_factor()):
 * y = X r into r (rows descending, four at a time: y_i reads r_j, j <= i, not yet
 * overwritten), then dx = X^T y two rows of X at a time, each dx_j's sum over i ascending;
 * both read X's lower triangle, the second time from cache. */
static inline __attribute__((always_inline)) void factor_apply(const double *X, double *r, int m,
                                                               double *dx)
{
  int i = m - 1;
  for (; i >= 3; i -= 4) {
    double y[4];
    factor_rows4(X, r, i - 3, y);
    for (int k = 0; k < 4; k++)
      r[i - 3 + k] = y[k];
  }
  for (; i >= 0; i--) {
    const double *Xi = X + FCM__SCHWARZ_PACKED(i, 0);
    double s0 = 0.0, s1 = 0.0;
    int j = 0;
    for (; j + 2 <= i + 1; j += 2) {
      s0 += Xi[j] * r[j];
      s1 += Xi[j + 1] * r[j + 1];
    }
    if (j <= i) s0 += Xi[j] * r[j];
    r[i] = s0 + s1;
  }
  for (int j = 0; j < m; j++)
    dx[j] = 0.0;
  int k = 0;
  for (; k + 2 <= m; k += 2) {
    const double *Xa = X + FCM__SCHWARZ_PACKED(k, 0), *Xb = Xa + k + 1;
    const double ya = r[k], yb = r[k + 1];
    for (int j = 0; j <= k; j++)
      dx[j] = (dx[j] + Xa[j] * ya) + Xb[j] * yb;
    dx[k + 1] += Xb[k + 1] * yb;
  }
  if (k < m) {
    const double *Xa = X + FCM__SCHWARZ_PACKED(k, 0);
    for (int j = 0; j <= k; j++)
      dx[j] += Xa[j] * r[k];
  }
}

/* Entry (i, j) of the symmetric S whose lower triangle T holds packed. */
static inline double sym_entry(const double *T, int i, int j)
{
  return i >= j ? T[FCM__SCHWARZ_PACKED(i, j)] : T[FCM__SCHWARZ_PACKED(j, i)];
}

/* The reference of the test hook: dx = S r with S = X^T X for a factor block (each entry
 * formed, m^3 operations), else each of S's rows in full, one entry at a time. */
static void plain_apply(const double *S, const double *r, int m, int factor, double *dx)
{
  for (int i = 0; i < m; i++) {
    double sum = 0.0;
    for (int j = 0; j < m; j++) {
      double sij = 0.0;
      if (!factor)
        sij = sym_entry(S, i, j);
      else
        for (int k = i > j ? i : j; k < m; k++)
          sij += S[FCM__SCHWARZ_PACKED(k, i)] * S[FCM__SCHWARZ_PACKED(k, j)];
      sum += sij * r[j];
    }
    dx[i] = sum;
  }
}

/* Gauss-Seidel over the rows i, i + 1, i + 2 of one copy (fcm__mg_row_dot3()), in order
 * (back: in reverse): the three sums from the x before the first update, each corrected by the
 * earlier rows' updates through the three's own 3 x 3 block (A_(i..i+2, i..i+2), stored
 * consecutively from the diagonal's position in each row). The same iterate as three single
 * updates, up to the order of the sums. */
static inline __attribute__((always_inline)) void sgs_triple(const mg_level *L, const double *v,
                                                             const int *ci, const fcm_index *rp,
                                                             fcm_index i, double w, const double *b,
                                                             double *x, int back)
{
  const fcm_index len = rp[i + 1] - rp[i], o = L->diag[i] - rp[i];
  const double *A0 = v + rp[i] + o, *A1 = A0 + len, *A2 = A1 + len; /* A_(i+r, i..i+2) */
  double s[3], d0, d1, d2;
  fcm__mg_row_dot3(v, ci, rp[i], len, L->rows.triple[i] == FCM__MG_TRIPLE_NODES, x, s);
  if (!back) {
    d0 = w * (b[i] - s[0]) * L->dinv[i];
    d1 = w * (b[i + 1] - (s[1] + A1[0] * d0)) * L->dinv[i + 1];
    d2 = w * (b[i + 2] - (s[2] + (A2[0] * d0 + A2[1] * d1))) * L->dinv[i + 2];
  } else {
    d2 = w * (b[i + 2] - s[2]) * L->dinv[i + 2];
    d1 = w * (b[i + 1] - (s[1] + A1[2] * d2)) * L->dinv[i + 1];
    d0 = w * (b[i] - (s[0] + (A0[2] * d2 + A0[1] * d1))) * L->dinv[i];
  }
  x[i] += d0;
  x[i + 1] += d1;
  x[i + 2] += d2;
}

/* Gauss-Seidel over the rows at positions [q0, q1) of the row order, forward (ascending) or
 * backward; a copy's three rows of one pattern together (sgs_triple()). */
FCM_MULTIVERSION_CLONES
static void sgs_range(const sweep_args *a, fcm_index q0, fcm_index q1, int back)
{
  const mg_level *L = a->L;
  const double w = a->w, *b = a->b;
  double *x = a->x;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const unsigned char *triple = a->plain ? NULL : L->rows.triple;
  const fcm_index *item = L->rows.item;
  if (!back) {
    for (fcm_index q = q0; q < q1;) {
      const fcm_index i = item[q];
      if (triple && q + 2 < q1 && item[q + 2] == i + 2 && triple[i]) {
        sgs_triple(L, v, ci, rp, i, w, b, x, 0);
        q += 3;
      } else {
        x[i] += w * (b[i] - fcm__mg_row_dot(v, ci, rp[i], rp[i + 1], x)) * L->dinv[i];
        q++;
      }
    }
    return;
  }
  for (fcm_index q = q1; q > q0;) {
    const fcm_index i = item[q - 1];
    if (triple && q - 3 >= q0 && i >= 2 && item[q - 3] == i - 2 && triple[i - 2]) {
      sgs_triple(L, v, ci, rp, i - 2, w, b, x, 1);
      q -= 3;
    } else {
      x[i] += w * (b[i] - fcm__mg_row_dot(v, ci, rp[i], rp[i + 1], x)) * L->dinv[i];
      q--;
    }
  }
}

/* Gauss-Seidel over the rows of slab s (sgs_range()). */
static void sgs_slab(const sweep_args *a, fcm_index s, int back)
{
  sgs_range(a, a->L->rows.ptr[s], a->L->rows.ptr[s + 1], back);
}

/* symmetric_sweep() of a row order of three slabs by a team of two, slab 0 thread 0's and
 * slabs 1 (thin, swept first) and 2 thread 1's, the first rows of slab 0 (lead, tail;
 * slab_order) swept while thread 1 sweeps slab 1: the same updates in the same order where
 * they touch one another, so the same iterate, and between the barriers each thread about half
 * of the work instead of thread 0 idle while slab 1 is swept. Repeated sweeps need no barrier
 * between them: the rows thread 0 sweeps beside slab 1 reach none of its rows. */
static void row_sweep_split(const slab_order *S, const sweep_args *a)
{
  const fcm_index p0 = S->ptr[0], p1 = S->ptr[1];
  if (omp_get_thread_num() == 0) {
    sgs_range(a, p0, p0 + S->lead, 0);
#pragma omp barrier
    sgs_range(a, p0 + S->lead, p1, 0);
    sgs_range(a, p0 + S->tail, p1, 1);
#pragma omp barrier
    sgs_range(a, p0, p0 + S->tail, 1);
    return;
  }
  sgs_slab(a, 1, 0);
#pragma omp barrier
  sgs_slab(a, 2, 0);
  sgs_slab(a, 2, 1);
#pragma omp barrier
  sgs_slab(a, 1, 1);
}

/* One way through the slab order S by the team: forward, the slabs of the colour swept first
 * and then the other's (a barrier between); backward, the reverse, its adjoint. No barrier at
 * the end. */
static void one_way_sweep(const slab_order *S,
                          void (*slab)(const sweep_args *a, fcm_index s, int back),
                          const sweep_args *a, int back)
{
  const int t = omp_get_thread_num(), nt = omp_get_num_threads();
  for (int pass = 0; pass < 2; pass++) {
    const int c = (pass == 0) != back ? S->first : 1 - S->first;
    if (pass == 1) {
#pragma omp barrier
    }
    for (fcm_index k = c; k < S->nslab; k += 2)
      if (fcm__mg_slab_mine(S, k, t, nt)) slab(a, k, back);
  }
}

/* one_way_sweep() of a row order of three slabs by a team of two as row_sweep_split(): forward,
 * slab 0's lead beside the thin slab 1, then the rest of slab 0 beside slab 2; backward, the
 * reverse (slab 0 down to its tail beside slab 2, then the tail's rows beside slab 1). The same
 * updates in the same order where they touch one another as one_way_sweep(), so the same
 * iterate. No barrier at the end. */
static void row_sweep_split_one_way(const slab_order *S, const sweep_args *a, int back)
{
  const fcm_index p0 = S->ptr[0], p1 = S->ptr[1];
  if (omp_get_thread_num() == 0) {
    if (!back) {
      sgs_range(a, p0, p0 + S->lead, 0);
#pragma omp barrier
      sgs_range(a, p0 + S->lead, p1, 0);
    } else {
      sgs_range(a, p0 + S->tail, p1, 1);
#pragma omp barrier
      sgs_range(a, p0, p0 + S->tail, 1);
    }
    return;
  }
  sgs_slab(a, back ? 2 : 1, back);
#pragma omp barrier
  sgs_slab(a, back ? 1 : 2, back);
}

/* Does row_sweep_split() apply to S in the enclosing team: three slabs, the thin one first,
 * a lead, two threads owning the slabs as it assumes? */
static int row_split_applies(const slab_order *S)
{
  return S->nslab == 3 && S->first == 1 && S->lead > 0 && omp_get_num_threads() == 2 &&
         fcm__mg_slab_mine(S, 0, 0, 2) && fcm__mg_slab_mine(S, 1, 1, 2) &&
         fcm__mg_slab_mine(S, 2, 1, 2);
}

/* One smoothing step. SGS: a forward then a backward sweep, S = (I - B^-1 A)(I - F^-1 A),
 * which is A-self-adjoint (B = F^T); pre- and post-smoothing both apply S, so the cycle is
 * symmetric (post-smoothing must be the adjoint of pre-smoothing: backward-then-forward
 * would not be). With point_sweep one way, the forward sweep alone before the coarse
 * correction (post = 0) and the backward one, its adjoint, after it (post = 1). SGS runs in the
 * slab order of the rows (symmetric_sweep()), the coloured SGS colour after colour (a barrier
 * each), Jacobi in two loops over the rows. */
void fcm__mg_smooth(const fcm_mg *m, mg_level *L, const double *b, double *x, int post)
{
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const double w = m->opts.omega;
  const fcm_index n = L->n;
  if (m->opts.smoother == FCM_MG_SMOOTHER_JACOBI) {
#pragma omp for schedule(static)
    for (fcm_index i = 0; i < n; i++) {
      double sum = 0.0;
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
        sum += v[p] * x[ci[p]];
      L->r[i] = b[i] - sum;
    }
#pragma omp for schedule(static)
    for (fcm_index i = 0; i < n; i++)
      x[i] += w * L->r[i] * L->dinv[i];
    return;
  }
  if (m->opts.smoother == FCM_MG_SMOOTHER_SGS_COLORED) {
    for (int t = 0; t < 2 * L->ncolor; t++) {
      const int c = t < L->ncolor ? t : 2 * L->ncolor - 1 - t;
      const fcm_index r0 = L->color_ptr[c], r1 = L->color_ptr[c + 1];
#pragma omp for schedule(static)
      for (fcm_index q = r0; q < r1; q++) {
        const fcm_index i = L->color_rows[q];
        double sum = b[i];
        for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
          sum -= v[p] * x[ci[p]];
        x[i] += w * sum * L->dinv[i];
      }
    }
    return;
  }
  const sweep_args a = {L, w, b, x, NULL, NULL, {0}, 0};
  if (m->opts.point_sweep) {
    if (row_split_applies(&L->rows))
      row_sweep_split_one_way(&L->rows, &a, post);
    else
      one_way_sweep(&L->rows, sgs_slab, &a, post);
    return;
  }
  if (row_split_applies(&L->rows))
    row_sweep_split(&L->rows, &a);
  else
    symmetric_sweep(&L->rows, sgs_slab, &a);
}

/* Block Gauss-Seidel over the blocks of slab s, forward or backward: x_K += S_K (b - A x)_K,
 * block after block. */
FCM_MULTIVERSION_CLONES
static void block_slab(const sweep_args *a, fcm_index s, int back)
{
  const mg_level *L = a->L;
  const double *b = a->b;
  double *x = a->x, *r = a->r, *dx = a->dx;
  const fcm_csr *A = fcm__mg_level_matrix(L);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values_read(A);
  const unsigned char *triple = a->plain ? NULL : L->rows.triple;
  const fcm_index n = L->n;
  const fcm_index q0 = L->blocks.ptr[s], q1 = L->blocks.ptr[s + 1];
  for (fcm_index t = 0; t < q1 - q0; t++) {
    const fcm_index k = L->blocks.item[back ? q1 - 1 - t : q0 + t];
    const fcm_index *d = a->blk.dofs + a->blk.ptr[k];
    const double *S = a->blk.S + a->blk.s_off[k];
    const int bm = (int)(a->blk.ptr[k + 1] - a->blk.ptr[k]);
    /* S_K's lower triangle is fetched while the residual's rows are read */
    for (size_t e = 0; e < FCM__SCHWARZ_PACKED(bm, 0); e += 8)
      __builtin_prefetch(S + e, 0, 0);
    for (int i = 0; i < bm;) {
      const fcm_index di = d[i];
      if (i + 2 < bm && d[i + 2] == di + 2 && d[i + 1] == di + 1 &&
          fcm__mg_is_triple(triple, di, n)) {
        double dot[3];
        fcm__mg_row_dot3(v, ci, rp[di], rp[di + 1] - rp[di], triple[di] == FCM__MG_TRIPLE_NODES, x,
                         dot);
        r[i] = b[di] - dot[0];
        r[i + 1] = b[di + 1] - dot[1];
        r[i + 2] = b[di + 2] - dot[2];
        i += 3;
      } else {
        r[i] = b[di] - fcm__mg_row_dot(v, ci, rp[di], rp[di + 1], x);
        i++;
      }
    }
    const int factor = a->blk.factor && a->blk.factor[k];
    if (a->plain)
      plain_apply(S, r, bm, factor, dx);
    else if (factor)
      factor_apply(S, r, bm, dx);
    else
      sym_lower_apply(S, r, bm, dx);
    for (int i = 0; i < bm; i++)
      x[d[i]] += dx[i];
  }
}

/* A block Gauss-Seidel sweep over the level's blocks in their slab order: symmetric (forward,
 * then backward; symmetric_sweep()), or with block_sweep one way, forward before the coarse
 * correction (post = 0) and backward after it (post = 1). */
static void block_smooth(const fcm_mg *m, const mg_level *L, const double *b, double *x, int post,
                         int plain)
{
  const size_t t = (size_t)omp_get_thread_num();
  sweep_args a = {
      L,   0.0,  b, x, m->blk_r + t * (size_t)m->blk_max, m->blk_dx + t * (size_t)m->blk_max,
      {0}, plain};
  fcm__schwarz_get_view(L->blk, &a.blk);
  if (m->opts.block_sweep)
    one_way_sweep(&L->blocks, block_slab, &a, post);
  else
    symmetric_sweep(&L->blocks, block_slab, &a);
}

void fcm__mg_block_smooth(const fcm_mg *m, const mg_level *L, const double *b, double *x, int post)
{
  block_smooth(m, L, b, x, post, 0);
}

fcm_status fcm__mg_smooth_paths(fcm_mg *mg, int level, const double *b, const double *x,
                                double *x_fast, double *x_plain, fcm_index *triples,
                                fcm_index *factor_blocks)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = mg ? mg->ctx : NULL;
  FCM_CHECK(mg && b && x && x_fast && x_plain && triples && factor_blocks, ctx, FCM_ERR_ARG,
            "mg_smooth_paths: NULL argument");
  FCM_CHECK(level >= 0 && level + 1 < mg->nlev, ctx, FCM_ERR_ARG,
            "mg_smooth_paths: level %d outside [0, %d)", level, mg->nlev - 1);
  FCM_CHECK(mg->opts.smoother == FCM_MG_SMOOTHER_SGS && mg->lev[level].rows.ptr, ctx, FCM_ERR_ARG,
            "mg_smooth_paths: the smoother is not SGS");
  mg_level *L = &mg->lev[level];
  *triples = 0, *factor_blocks = 0;
  for (fcm_index k = 0; L->blk && k < fcm__schwarz_num_blocks(L->blk); k++)
    *factor_blocks += fcm__schwarz_block_factor(L->blk, k);
  for (fcm_index i = 0; L->rows.triple && i < L->n; i++)
    *triples += L->rows.triple[i] != 0;
  memcpy(x_fast, x, sizeof *x * (size_t)L->n);
  memcpy(x_plain, x, sizeof *x * (size_t)L->n);
#pragma omp parallel num_threads(1)
  {
    const sweep_args f = {L, mg->opts.omega, b, x_fast, NULL, NULL, {0}, 0};
    const sweep_args p = {L, mg->opts.omega, b, x_plain, NULL, NULL, {0}, 1};
    symmetric_sweep(&L->rows, sgs_slab, &f);
    symmetric_sweep(&L->rows, sgs_slab, &p);
    if (L->blk) {
      block_smooth(mg, L, b, x_fast, 0, 0);
      block_smooth(mg, L, b, x_plain, 0, 1);
    }
  }
cleanup:
  return st;
}

void fcm__mg_block_apply_paths(const double *S, int m, int factor, double *r, double *dx_fast,
                               double *dx_plain)
{
  plain_apply(S, r, m, factor, dx_plain);
  if (factor)
    factor_apply(S, r, m, dx_fast);
  else
    sym_lower_apply(S, r, m, dx_fast);
}
