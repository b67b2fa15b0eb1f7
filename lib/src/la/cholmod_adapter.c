/* The one adapter to CHOLMOD (SuiteSparse 5.x): supernodal Cholesky L L^T of a
 * symmetric positive definite CSR matrix through the SuiteSparse_long interface.
 *
 * Our CSR arrays of a symmetric A, read as compressed columns, are A itself; we
 * hand CHOLMOD stype = +1 (only entries with row <= column are read), so both
 * stored triangles are fine. The symbolic analysis (fill-reducing ordering,
 * supernodes) is done once; each factorization reuses it with new values. CHOLMOD
 * never prints (Common->print = 0, no error handler): its Common->status is
 * mapped to fcm statuses after every call.
 *
 * CHOLMOD 3.x (SuiteSparse 5.x) runs loops of its supernodal factorization in OpenMP teams
 * of CHOLMOD_OMP_NUM_THREADS threads, a number fixed when it was built (4 in Debian's),
 * whatever the caller's thread count: on 2 shared cores their forks and joins cost a solve
 * of 46,875 DOFs a fifth of its time (lib/docs/performance.md). The factorization runs with
 * the OpenMP runtime's dynamic adjustment on for the calling thread (its own setting is
 * restored), which lets the runtime give those teams no more threads than the caller's
 * thread count and the free cores; each entry is still computed by one thread, the same way. */
#include "la/la_impl.h"

#include <cholmod.h>
#include <omp.h>
#include <string.h>
#include <math.h>

_Static_assert(sizeof(SuiteSparse_long) == sizeof(fcm_index),
               "fcm expects SuiteSparse_long to be 64-bit like fcm_index");

typedef struct chol {
  cholmod_common c;
  int started;
  cholmod_sparse A;          /* header over ap, ai (and the values during factor) */
  SuiteSparse_long *ap, *ai; /* the pattern, as CHOLMOD's integer type */
  cholmod_factor *L;         /* symbolic after analyze, numeric after factor */
  SuiteSparse_long *given;   /* n: the ordering to analyze with (NULL: CHOLMOD's own) */
  cholmod_dense *X, *Y, *E;  /* solve workspaces, allocated once by cholmod_l_solve2 */
  /* the lower triangle of P A P^T (P: the analysis's ordering) as CHOLMOD's supernodal
   * numeric factorization reads it, made once per analysis: S's values are gathered from A's
   * through smap (entry k of S is A's entry smap[k]) instead of CHOLMOD transposing A into a
   * new matrix at every factorization */
  SuiteSparse_long *sp, *si, *smap;
  SuiteSparse_long *diag; /* n: the position of each row's diagonal entry in A (-1: none) */
  double *sx;
  cholmod_sparse S;
  fcm_index n;
} chol;

/* Map CHOLMOD's status after a failed or warned call in `phase`. */
static fcm_status map_status(fcm_ctx *ctx, const chol *h, const char *phase)
{
  fcm_status st = FCM_OK;
  int s = h->c.status;
  long long n = (long long)h->n;
  FCM_CHECK(s != CHOLMOD_OUT_OF_MEMORY, ctx, FCM_ERR_ALLOC, "cholmod %s: out of memory (n = %lld)",
            phase, n);
  FCM_CHECK(s != CHOLMOD_TOO_LARGE, ctx, FCM_ERR_UNSUPPORTED,
            "cholmod %s: problem too large, integer overflow (n = %lld)", phase, n);
  FCM_CHECK(s != CHOLMOD_NOT_INSTALLED, ctx, FCM_ERR_UNSUPPORTED,
            "cholmod %s: required CHOLMOD module not installed", phase);
  FCM_CHECK(s != CHOLMOD_INVALID, ctx, FCM_ERR_INTERNAL, "cholmod %s: invalid input (n = %lld)",
            phase, n);
  FCM_CHECK(s >= CHOLMOD_OK, ctx, FCM_ERR_INTERNAL, "cholmod %s: failed with status %d", phase, s);
cleanup:
  return st;
}

static void chol_destroy(fcm_ctx *ctx, void *impl)
{
  chol *h = impl;
  if (!h) return;
  if (h->started) {
    cholmod_l_free_factor(&h->L, &h->c);
    cholmod_l_free_dense(&h->X, &h->c);
    cholmod_l_free_dense(&h->Y, &h->c);
    cholmod_l_free_dense(&h->E, &h->c);
    cholmod_l_finish(&h->c);
  }
  fcm__free(ctx, h->ap);
  fcm__free(ctx, h->ai);
  fcm__free(ctx, h->given);
  fcm__free(ctx, h->sp);
  fcm__free(ctx, h->si);
  fcm__free(ctx, h->smap);
  fcm__free(ctx, h->diag);
  fcm__free(ctx, h->sx);
  fcm__free(ctx, h);
}

static fcm_status chol_create(fcm_ctx *ctx, const fcm_csr *A, void **impl)
{
  fcm_status st = FCM_OK;
  chol *h = NULL;
  FCM_ALLOC(ctx, 1, h);
  h->n = A->nrows;
  FCM_ALLOC(ctx, A->nrows + 1, h->ap);
  FCM_ALLOC(ctx, A->nnz, h->ai);
  for (fcm_index i = 0; i <= A->nrows; i++)
    h->ap[i] = (SuiteSparse_long)A->row_ptr[i];
  for (fcm_index p = 0; p < A->nnz; p++)
    h->ai[p] = (SuiteSparse_long)A->col_idx[p];
  FCM_ALLOC(ctx, FCM_MAX(A->nrows, 1), h->diag);
  for (fcm_index i = 0; i < A->nrows; i++) {
    h->diag[i] = -1;
    for (SuiteSparse_long q = h->ap[i]; q < h->ap[i + 1]; q++)
      if (h->ai[q] == (SuiteSparse_long)i) h->diag[i] = q;
  }
  FCM_CHECK(cholmod_l_start(&h->c), ctx, FCM_ERR_INTERNAL, "cholmod start: failed with status %d",
            h->c.status);
  h->started = 1;
  h->c.print = 0;
  h->c.error_handler = NULL;
  h->c.supernodal = CHOLMOD_SUPERNODAL;
  h->c.quick_return_if_not_posdef = 1; /* a failed factor is discarded anyway */
  /* AMD and METIS both, the one with the smaller factor kept: CHOLMOD's default tries METIS
   * only when AMD's factor is dense, and on the FCM systems of 3-D bodies cut into parts it
   * kept AMD's with 26 % more flops (lib/docs/cutting.md) */
  h->c.nmethods = 2;
  h->c.method[0].ordering = CHOLMOD_AMD;
  h->c.method[1].ordering = CHOLMOD_METIS;

  cholmod_sparse *S = &h->A;
  S->nrow = (size_t)A->nrows;
  S->ncol = (size_t)A->nrows;
  S->nzmax = (size_t)A->nnz;
  S->p = h->ap;
  S->i = h->ai;
  S->nz = NULL;
  S->x = NULL;
  S->z = NULL;
  S->stype = 1;
  S->itype = CHOLMOD_LONG;
  S->xtype = CHOLMOD_PATTERN;
  S->dtype = CHOLMOD_DOUBLE;
  S->sorted = 1;
  S->packed = 1;
  *impl = h;
  h = NULL;
cleanup:
  chol_destroy(ctx, h);
  return st;
}

static fcm_status chol_analyze(fcm_ctx *ctx, void *impl, fcm_direct_info *info)
{
  fcm_status st = FCM_OK;
  chol *h = impl;
  h->c.status = CHOLMOD_OK;
  if (h->given) { /* the given ordering alone (CHOLMOD still postorders it) */
    h->c.nmethods = 1;
    h->c.method[0].ordering = CHOLMOD_GIVEN;
    h->L = cholmod_l_analyze_p(&h->A, h->given, NULL, 0, &h->c);
  } else {
    h->L = cholmod_l_analyze(&h->A, &h->c);
  }
  if (!h->L) FCM_TRY(ctx, map_status(ctx, h, "analyze"));
  FCM_CHECK(h->L, ctx, FCM_ERR_INTERNAL, "cholmod analyze: no factor returned (status %d)",
            h->c.status);
  info->analyses++;
  info->factor_nnz = h->c.lnz;
  info->factor_flops = h->c.fl;
cleanup:
  return st;
}

/* Rank check of a completed factor: CHOLMOD accepts a numerically singular
 * positive semi-definite matrix whenever rounding leaves its zero pivots positive, and
 * its rcond ((min/max diag L)^2) is no help because it mixes the scales of all rows. The
 * pivot of column j of P A P^T relative to that column's diagonal,
 * r_j = L_jj^2 / A_pp (p = Perm[j]) in (0, 1], is invariant under diagonal scaling and
 * equals the ratio of the smallest energy of a vector with unit p entry (others
 * free, among the columns eliminated before j) to A_pp: it is ~ n eps for a direction
 * that is singular in exact arithmetic (a rigid mode, an hourglass mode of a too weak
 * rule, a DOF with no quadrature point) and is bounded below for stabilized FCM
 * systems (the alpha-scaled full-cell rule keeps every cut-cell block definite).
 * Returns min_j r_j and the original column where it occurs. */
static double min_pivot_ratio(const chol *h, const double *values, fcm_index *col)
{
  const cholmod_factor *L = h->L;
  const SuiteSparse_long *perm = L->Perm;
  const double *Lx = L->x;
  double best = HUGE_VAL;
  *col = -1;
  for (fcm_index j = 0, s = 0; j < h->n; j++) {
    double piv;
    if (L->is_super) {
      const SuiteSparse_long *super = L->super, *pi = L->pi, *px = L->px;
      while (super[s + 1] <= (SuiteSparse_long)j)
        s++;
      const SuiteSparse_long k = (SuiteSparse_long)j - super[s], nsrow = pi[s + 1] - pi[s];
      const double d = Lx[px[s] + k + k * nsrow];
      piv = d * d;
    } else {
      const double d = Lx[((const SuiteSparse_long *)L->p)[j]];
      piv = L->is_ll ? d * d : d;
    }
    const fcm_index p = perm ? (fcm_index)perm[j] : j;
    const double app = h->diag[p] >= 0 ? values[h->diag[p]] : 0.0;
    const double r = app > 0.0 ? piv / app : (piv > 0.0 ? HUGE_VAL : 0.0);
    if (r < best) {
      best = r;
      *col = p;
    }
  }
  return best;
}

/* S = tril(P A P^T) of the entries CHOLMOD reads (A's CSR rows as columns, the entries with
 * row <= column: stype +1), column by column in A's order: what cholmod_l_factorize() would
 * pass to the supernodal numeric factorization, up to the order within a column. */
static fcm_status permuted_lower(fcm_ctx *ctx, chol *h)
{
  fcm_status st = FCM_OK;
  const fcm_index n = h->n;
  const SuiteSparse_long *perm = h->L->Perm, *ap = h->ap, *ai = h->ai;
  SuiteSparse_long *pinv = NULL, *next = NULL;
  FCM_ALLOC(ctx, n, pinv);
  FCM_ALLOC(ctx, n + 1, next);
  FCM_ALLOC(ctx, n + 1, h->sp);
  for (fcm_index k = 0; k < n; k++)
    pinv[perm ? perm[k] : k] = (SuiteSparse_long)k;
  SuiteSparse_long m = 0;
  for (fcm_index j = 0; j < n; j++)
    for (SuiteSparse_long q = ap[j]; q < ap[j + 1]; q++)
      if (ai[q] <= (SuiteSparse_long)j) {
        const SuiteSparse_long a = pinv[ai[q]], b = pinv[j];
        h->sp[(a < b ? a : b) + 1]++;
        m++;
      }
  for (fcm_index k = 0; k < n; k++)
    h->sp[k + 1] += h->sp[k];
  FCM_ALLOC(ctx, FCM_MAX(m, 1), h->si);
  FCM_ALLOC(ctx, FCM_MAX(m, 1), h->smap);
  FCM_ALLOC(ctx, FCM_MAX(m, 1), h->sx);
  memcpy(next, h->sp, sizeof *next * (size_t)(n + 1));
  for (fcm_index j = 0; j < n; j++)
    for (SuiteSparse_long q = ap[j]; q < ap[j + 1]; q++)
      if (ai[q] <= (SuiteSparse_long)j) {
        const SuiteSparse_long a = pinv[ai[q]], b = pinv[j];
        const SuiteSparse_long e = next[a < b ? a : b]++;
        h->si[e] = a < b ? b : a;
        h->smap[e] = q;
      }
  cholmod_sparse *S = &h->S;
  memset(S, 0, sizeof *S);
  S->nrow = S->ncol = (size_t)n;
  S->nzmax = (size_t)FCM_MAX(m, 1);
  S->p = h->sp;
  S->i = h->si;
  S->x = h->sx;
  S->stype = -1;
  S->itype = CHOLMOD_LONG;
  S->xtype = CHOLMOD_REAL;
  S->dtype = CHOLMOD_DOUBLE;
  S->sorted = 0;
  S->packed = 1;
cleanup:
  fcm__free(ctx, pinv);
  fcm__free(ctx, next);
  return st;
}

/* The numeric factorization: through the kept S (permuted_lower()) and CHOLMOD's supernodal
 * numeric step for a supernodal analysis, else cholmod_l_factorize(). */
static fcm_status numeric(fcm_ctx *ctx, chol *h, const double *values, int *ok)
{
  fcm_status st = FCM_OK;
  if (!h->L->is_super) {
    h->A.x = (void *)values; /* read only: cholmod_l_factorize does not write A */
    h->A.xtype = CHOLMOD_REAL;
    *ok = cholmod_l_factorize(&h->A, h->L, &h->c);
    h->A.x = NULL;
    h->A.xtype = CHOLMOD_PATTERN;
    return FCM_OK;
  }
  if (!h->sp) FCM_TRY(ctx, permuted_lower(ctx, h));
  for (SuiteSparse_long k = 0, m = h->sp[h->n]; k < m; k++)
    h->sx[k] = values[h->smap[k]];
  double beta[2] = {0.0, 0.0};
  *ok = cholmod_l_super_numeric(&h->S, NULL, beta, h->L, &h->c);
cleanup:
  return st;
}

static fcm_status chol_factor(fcm_ctx *ctx, void *impl, const double *values, fcm_direct_info *info)
{
  fcm_status st = FCM_OK;
  chol *h = impl;
  h->c.status = CHOLMOD_OK;
  const int dynamic = omp_get_dynamic(); /* a data-environment setting: this thread's only */
  omp_set_dynamic(1);
  int ok = 0;
  st = numeric(ctx, h, values, &ok);
  omp_set_dynamic(dynamic);
  FCM_TRY(ctx, st);
  if (h->c.status == CHOLMOD_NOT_POSDEF) {
    /* L->minor is the failing column in the permuted order; report the original. */
    size_t k = h->L->minor;
    const SuiteSparse_long *perm = h->L->Perm;
    fcm_index col = (k < (size_t)h->n) ? (perm ? (fcm_index)perm[k] : (fcm_index)k) : -1;
    info->failed_column = col;
    FCM_CHECK(0, ctx, FCM_ERR_SINGULAR,
              "cholmod factor: matrix is not positive definite (pivot of column %lld, n = %lld); "
              "an indefinite symmetric matrix needs umfpack",
              (long long)col, (long long)h->n);
  }
  if (!ok || h->c.status < CHOLMOD_OK) FCM_TRY(ctx, map_status(ctx, h, "factor"));
  FCM_CHECK(ok, ctx, FCM_ERR_INTERNAL, "cholmod factor: failed with status %d", h->c.status);
  info->factor_nnz = h->c.lnz;
  info->factor_flops = h->c.fl;
  info->rcond = cholmod_l_rcond(h->L, &h->c);
  {
    fcm_index col = -1;
    const double r = min_pivot_ratio(h, values, &col);
    info->min_pivot_ratio = r;
    FCM_CHECK(!(r < FCM__SINGULAR_PIVOT_RATIO), ctx, FCM_ERR_SINGULAR,
              "cholmod factor: matrix is numerically singular: the pivot of column %lld is %.3g "
              "times its diagonal (threshold %.0e, n = %lld); %s",
              (long long)col, r, FCM__SINGULAR_PIVOT_RATIO, (long long)h->n, FCM__SINGULAR_HINT);
  }
cleanup:
  return st;
}

static fcm_status chol_solve(fcm_ctx *ctx, void *impl, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  chol *h = impl;
  cholmod_dense B;
  B.nrow = (size_t)h->n;
  B.ncol = 1;
  B.nzmax = (size_t)h->n;
  B.d = (size_t)h->n;
  B.x = (void *)b; /* read only */
  B.z = NULL;
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  h->c.status = CHOLMOD_OK;
  int ok = cholmod_l_solve2(CHOLMOD_A, h->L, &B, NULL, &h->X, NULL, &h->Y, &h->E, &h->c);
  if (!ok || h->c.status < CHOLMOD_OK) FCM_TRY(ctx, map_status(ctx, h, "solve"));
  FCM_CHECK(ok, ctx, FCM_ERR_INTERNAL, "cholmod solve: failed with status %d", h->c.status);
  memcpy(x, h->X->x, (size_t)h->n * sizeof *x);
cleanup:
  return st;
}

static fcm_status chol_set_ordering(fcm_ctx *ctx, void *impl, const fcm_index *perm)
{
  fcm_status st = FCM_OK;
  chol *h = impl;
  if (!h->given) FCM_ALLOC(ctx, h->n, h->given);
  for (fcm_index k = 0; k < h->n; k++)
    h->given[k] = (SuiteSparse_long)perm[k];
cleanup:
  return st;
}

static void chol_get_ordering(const void *impl, fcm_index *perm)
{
  const chol *h = impl;
  const SuiteSparse_long *p = h->L->Perm;
  for (fcm_index k = 0; k < h->n; k++)
    perm[k] = p ? (fcm_index)p[k] : k;
}

const fcm__direct_ops fcm__cholmod_ops = {"cholmod",         chol_create,       chol_analyze,
                                          chol_set_ordering, chol_get_ordering, chol_factor,
                                          chol_solve,        chol_destroy};
