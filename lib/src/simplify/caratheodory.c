/* Carathéodory elimination: from weights lam >= 0 with G lam = b, weights with at most
 * rank G positive entries and the same G lam, by moving along null vectors of G until one
 * weight reaches zero (Carathéodory's theorem made constructive; Tchernychova 2016,
 * Maalouf et al. 2019 use it inside recombination).
 *
 * The null vectors come from a simplex tableau: LU with partial pivoting of G^T
 * (K x rows) picks `rows` basis columns B (the pivot rows) and gives the others as
 * g_N = G_B D, D^T = L2 inv(L1) (one triangular solve). For each non-basic column j in
 * turn, lam_j goes down and lam_B up along D[:, j]; the first weight to reach zero is
 * either lam_j (no pivot: O(rows) work) or a basic one, which then leaves the basis for j
 * (a rank-1 update of the remaining tableau rows). Cost O(K rows^2) for LU and triangular
 * solve plus at most O(rows (K - rows)^2) for the pivots, no iteration count to tune, and
 * the weights stay non-negative by construction.
 *
 * The pivots' rank-1 updates are applied `block` at a time (eliminate_blocked(), as a
 * right-looking LU delays its trailing updates): the row of the next direction and the
 * entering column are brought up to date from the delayed factors, and every `block` pivots
 * the rows below receive them as one matrix product (BLAS-3). block = 1 is the unblocked
 * elimination, a rank-1 update per pivot. */
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

#include <math.h>
#include <string.h>

/* Tableau updates with at least this many entries go through BLAS dger. */
#define ELIM_GER_MIN 4096

typedef struct tableau {
  int rows, K, kn; /* basis size, active columns, non-basic columns (K - rows) */
  double *at;      /* K x rows, ld K: LU of G^T, then D^T in rows rows..K-1 */
  int *ipiv;       /* rows */
  int *perm;       /* K: active column of each pivoted row */
  int *id_b, *id_n;
  double *lam_b, *lam_n, *f;
  /* blocked elimination: the delayed factors F (kn x block, ld kn; row r of column p is
   * f_p[r] of pivot p) and E (rows x block, ld rows; column p is the pivot row d_p with
   * its pivot entry d_q replaced by d_q - 1), the current row e (rows), x (block) */
  int block;
  double *F, *E, *e, *x;
  double flops; /* of the tableau updates */
} tableau;

/* The entering weight's step along the current row e of column j: the largest step keeping
 * the basic weights >= 0 (capped by lam_n[j]), the basic position that reaches 0 first in *q
 * (-1: lam_n[j] does); the basic weights are moved by it. */
static double step_along(tableau *t, int j, const double *e, int *q)
{
  const int rows = t->rows;
  double step = t->lam_n[j];
  *q = -1;
  for (int i = 0; i < rows; i++) {
    const double d = e[i];
    if (d < 0.0 && t->lam_b[i] < step * -d) step = t->lam_b[i] / -d, *q = i;
  }
  for (int i = 0; i < rows; i++) {
    const double v = t->lam_b[i] + step * e[i];
    t->lam_b[i] = v > 0.0 ? v : 0.0; /* rounding below zero: a weight at zero */
  }
  return step;
}

/* Eliminate along the non-basic columns in order (see the file comment), a rank-1 update
 * per pivot. */
static void eliminate(tableau *t)
{
  const int rows = t->rows, kn = t->kn, ld = t->K;
  double *dt = t->at + rows; /* D^T(j, i) = dt[j + i ld] */
  for (int j = 0; j < kn; j++) {
    if (!(t->lam_n[j] > 0.0)) continue;
    for (int i = 0; i < rows; i++)
      t->e[i] = dt[j + (size_t)i * ld];
    int q;
    const double step = step_along(t, j, t->e, &q);
    if (q < 0) {
      t->lam_n[j] = 0.0;
      continue;
    }
    /* Column j enters the basis at q; the old basic column (weight 0) leaves. */
    const double dq = dt[j + (size_t)q * ld];
    const int rest = kn - j - 1;
    double *colq = dt + (size_t)q * ld + j + 1;
    for (int r = 0; r < rest; r++)
      t->f[r] = colq[r] / dq;
    /* Rows below j: e -= f d^T (column q becomes 0 and is then set to f); BLAS for large
     * updates, a plain loop below the cost of the call. */
    t->flops += 2.0 * rest * rows;
    if ((long long)rest * rows >= ELIM_GER_MIN) {
      fcm__ger(rest, rows, -1.0, t->f, dt + j, ld, dt + j + 1, ld);
    } else {
      for (int i = 0; i < rows; i++) {
        const double di = dt[j + (size_t)i * ld];
        double *restrict col = dt + (size_t)i * ld + j + 1;
        const double *restrict f = t->f;
        if (di != 0.0)
          for (int r = 0; r < rest; r++)
            col[r] -= f[r] * di;
      }
    }
    memcpy(colq, t->f, sizeof *t->f * (size_t)rest);
    const int leaving = t->id_b[q];
    t->id_b[q] = t->id_n[j];
    t->lam_b[q] = t->lam_n[j] - step;
    t->id_n[j] = leaving;
    t->lam_n[j] = 0.0;
  }
}

/* The same pivots as eliminate(), their updates of the rows below delayed and applied
 * t->block at a time: row j is brought up to date from the nb delayed factors before it is
 * read (O(nb rows)), so is the entering column below it at a pivot (O(nb rest)), and after
 * t->block pivots the rows below receive F E^T in one dgemm. The update of pivot p,
 * e_r -= f_p[r] d_p with column q then set to f_p, is the rank-1 update by E's column p. */
static void eliminate_blocked(tableau *t)
{
  const int rows = t->rows, kn = t->kn, ld = t->K, nbmax = t->block;
  double *dt = t->at + rows, *F = t->F, *E = t->E, *e = t->e, *x = t->x;
  int nb = 0;
  for (int j = 0; j < kn; j++) {
    if (!(t->lam_n[j] > 0.0)) continue;
    for (int i = 0; i < rows; i++)
      e[i] = dt[j + (size_t)i * ld];
    for (int p = 0; p < nb; p++) { /* the delayed updates of row j */
      const double c = F[j + (size_t)p * kn];
      const double *restrict ep = E + (size_t)p * rows;
      if (c != 0.0)
        for (int i = 0; i < rows; i++)
          e[i] -= c * ep[i];
    }
    t->flops += 2.0 * nb * rows;
    int q;
    const double step = step_along(t, j, e, &q);
    if (q < 0) {
      t->lam_n[j] = 0.0;
      continue;
    }
    /* Column j enters the basis at q: f = (column q below j, up to date) / d_q. */
    const double dq = e[q];
    const int rest = kn - j - 1;
    double *f = F + (size_t)nb * kn + j + 1;
    memcpy(f, dt + (size_t)q * ld + j + 1, sizeof *f * (size_t)rest);
    if (nb > 0 && rest > 0) {
      for (int p = 0; p < nb; p++)
        x[p] = E[q + (size_t)p * rows];
      fcm__gemv('N', rest, nb, -1.0, F + j + 1, kn, x, 1.0, f);
      t->flops += 2.0 * nb * rest;
    }
    for (int r = 0; r < rest; r++)
      f[r] /= dq;
    memcpy(E + (size_t)nb * rows, e, sizeof *e * (size_t)rows);
    E[q + (size_t)nb * rows] = dq - 1.0;
    nb++;
    const int leaving = t->id_b[q];
    t->id_b[q] = t->id_n[j];
    t->lam_b[q] = t->lam_n[j] - step;
    t->id_n[j] = leaving;
    t->lam_n[j] = 0.0;
    if (nb == nbmax || j + 1 == kn) {
      if (rest > 0) {
        fcm__gemm('N', 'T', rest, rows, nb, -1.0, F + j + 1, kn, E, rows, 1.0, dt + j + 1, ld);
        t->flops += 2.0 * nb * rest * (double)rows;
      }
      nb = 0;
    }
  }
}

/* Grow the attempt's scratch to nd doubles and ni ints (kept across rounds and attempts:
 * one allocation per call of fcm_simplify instead of one per elimination). */
static fcm_status reserve(fcm__attempt *a, size_t nd, size_t ni)
{
  fcm_status st = FCM_OK;
  if (nd > a->ws_cap) {
    FCM_FREE(a->ctx, a->ws);
    a->ws_cap = 0;
    FCM_ALLOC_RAW(a->ctx, nd, a->ws);
    a->ws_cap = nd;
  }
  if (ni > a->iws_cap) {
    FCM_FREE(a->ctx, a->iws);
    a->iws_cap = 0;
    FCM_ALLOC_RAW(a->ctx, ni, a->iws);
    a->iws_cap = ni;
  }
cleanup:
  return st;
}

fcm_status fcm__simplify_caratheodory(fcm__attempt *a, int rows, int ncols, const double *g,
                                      int ldg, double *lam, int *deficient)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  tableau t;
  memset(&t, 0, sizeof t);
  *deficient = 0;

  /* Scratch: act, ipiv, perm, id_b, id_n (ints); the tableau, lam_b, lam_n, f, e and the
   * blocked elimination's F, E, x (doubles). */
  const size_t nc = (size_t)ncols, nr = (size_t)rows;
  const int block = a->elim_block > 1 ? a->elim_block : 1;
  const size_t nblk = block > 1 ? (size_t)block : 0;
  FCM_TRY(ctx, reserve(a, nc * nr + 3 * nc + nr + nblk * (nc + nr + 1), 4 * nc + 2 * nr));
  int *act = a->iws;
  int K = 0;
  for (int c = 0; c < ncols; c++)
    if (lam[c] > 0.0)
      act[K++] = c;
    else
      lam[c] = 0.0;
  if (K <= rows) goto cleanup; /* already at most `rows` positive weights */
  t.rows = rows, t.K = K, t.kn = K - rows;
  t.at = a->ws;
  t.lam_b = t.at + (size_t)K * nr;
  t.lam_n = t.lam_b + nr;
  t.f = t.lam_n + t.kn;
  t.e = t.f + t.kn;
  t.block = block;
  if (block > 1) {
    t.F = t.e + nr;
    t.E = t.F + (size_t)t.kn * nblk;
    t.x = t.E + nr * nblk;
  }
  t.ipiv = act + K;
  t.perm = t.ipiv + rows;
  t.id_b = t.perm + K;
  t.id_n = t.id_b + rows;

  double t0 = fcm_wtime();
  for (int c = 0; c < K; c++) {
    const double *gc = g + (size_t)act[c] * (size_t)ldg;
    for (int i = 0; i < rows; i++)
      t.at[c + (size_t)i * K] = gc[i];
  }
  st = fcm__getrf_tall(ctx, K, rows, t.at, K, t.ipiv);
  if (st != FCM_OK) {
    a->time_svd += fcm_wtime() - t0;
    FCM_TRY(ctx, fcm__simplify_soften(a, st, "LU of the moment matrix"));
    goto cleanup;
  }
  /* A pivot at rounding level: the basis is not a basis (rank-deficient moments). */
  double umax = 0.0;
  for (int i = 0; i < rows; i++)
    umax = fmax(umax, fabs(t.at[i + (size_t)i * K]));
  for (int i = 0; i < rows; i++)
    if (!(fabs(t.at[i + (size_t)i * K]) > a->pivot_tol * umax)) *deficient = 1;
  if (*deficient) {
    a->time_svd += fcm_wtime() - t0;
    goto cleanup;
  }
  for (int c = 0; c < K; c++)
    t.perm[c] = c;
  for (int i = 0; i < rows; i++) {
    const int p = t.ipiv[i] - 1, tmp = t.perm[i];
    t.perm[i] = t.perm[p];
    t.perm[p] = tmp;
  }
  fcm__trsm_right_unit_lower(t.kn, rows, 1.0, t.at, K, t.at + rows, K);
  a->flops += (2.0 * K - 2.0 / 3.0 * rows) * nr * nr + (double)t.kn * nr * nr;
  a->time_svd += fcm_wtime() - t0;

  t0 = fcm_wtime();
  for (int i = 0; i < rows; i++) {
    t.id_b[i] = act[t.perm[i]];
    t.lam_b[i] = lam[t.id_b[i]];
  }
  for (int j = 0; j < t.kn; j++) {
    t.id_n[j] = act[t.perm[rows + j]];
    t.lam_n[j] = lam[t.id_n[j]];
  }
  if (block > 1)
    eliminate_blocked(&t);
  else
    eliminate(&t);
  a->flops += t.flops;
  for (int c = 0; c < K; c++)
    lam[act[c]] = 0.0;
  for (int i = 0; i < rows; i++)
    lam[t.id_b[i]] = t.lam_b[i];
  a->time_lp += fcm_wtime() - t0;
  a->num_eliminations++;
cleanup:
  return st;
}

fcm_status fcm__simplify_reduce(fcm__attempt *a, int rows, int ncols, double *g, double *q,
                                double *lam)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  int deficient = 0, r = 0;
  FCM_TRY(ctx, fcm__simplify_caratheodory(a, rows, ncols, g, rows, lam, &deficient));
  a->rank = rows;
  if (!deficient || a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  /* Dependent rows: the same null space through the orthonormal rows of the row space. */
  FCM_TRY(ctx, fcm__simplify_row_space(a, rows, ncols, g, q, &r));
  if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  a->rank = r;
  FCM_TRY(ctx, fcm__simplify_caratheodory(a, r, ncols, q, FCM_MIN(rows, ncols), lam, &deficient));
  if (deficient && a->reason == FCM_SIMPLIFY_REASON_NONE)
    fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_NUMERIC,
                       "elimination: rank %d row space still has a pivot below %.1e of the largest",
                       r, a->pivot_tol);
cleanup:
  return st;
}

/* Elimination on all points up to this many per basis function (one LU of n x M); above,
 * recombination rounds (measured: tests/simplify/bench_simplify.c). */
#define ELIMINATE_ALL_RATIO 4

fcm_status fcm__simplify_run_eliminate(fcm__attempt *a)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  const int n = a->n, M = a->box.num_basis;
  double *g = NULL, *q = NULL, *lam = NULL, *work = NULL;
  if (n > ELIMINATE_ALL_RATIO * M) {
    a->eliminate = 1;
    FCM_TRY(ctx, fcm__simplify_run_recombine(a));
    goto cleanup;
  }
  double t0 = fcm_wtime();
  FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)n, g);
  FCM_ALLOC_RAW(ctx, (size_t)FCM_MIN(M, n) * (size_t)n, q);
  FCM_ALLOC_RAW(ctx, (size_t)n, lam);
  FCM_ALLOC_RAW(ctx, fcm__simplify_moments_scratch(a->box.m), work);
  fcm__simplify_basis_points(&a->box, n, a->points, g, work);
  memcpy(lam, a->w0, sizeof *lam * (size_t)n);
  fcm__simplify_set_moments(a, n, g, lam);
  a->time_basis += fcm_wtime() - t0;
  FCM_TRY(ctx, fcm__simplify_reduce(a, M, n, g, q, lam));
  if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  fcm__simplify_take_support(a, n, NULL, NULL, lam, "elimination");
cleanup:
  fcm__free(ctx, g);
  fcm__free(ctx, q);
  fcm__free(ctx, lam);
  fcm__free(ctx, work);
  return st;
}
