/* The one adapter to UMFPACK (SuiteSparse 5.x): sparse LU with partial pivoting
 * of a general square CSR matrix through the SuiteSparse_long (umfpack_dl_*) interface.
 *
 * Our CSR arrays of A, read as compressed columns, describe A^T; UMFPACK factors
 * that and solves with sys = UMFPACK_At, i.e. (A^T)^T x = A x = b, so no
 * transposed copy is made. The Symbolic object is computed once and reused by
 * every umfpack_dl_numeric; solves go through umfpack_dl_wsolve with workspaces
 * allocated here, so a solve allocates nothing. UMFPACK never prints unless its
 * report functions are called (they are not); statuses are mapped to messages. */
#include "la/la_impl.h"

#include <string.h>
#include <umfpack.h>

_Static_assert(sizeof(SuiteSparse_long) == sizeof(fcm_index),
               "fcm expects SuiteSparse_long to be 64-bit like fcm_index");

typedef struct umf {
  fcm_index n, nnz;
  SuiteSparse_long *ap, *ai; /* the pattern (CSC of A^T) */
  double *ax;                /* copy of the last factored values, for iterative refinement */
  SuiteSparse_long *wi;      /* 2 n: wsolve workspace (n), P and Q of a singular factor */
  double *w;                 /* 5 n, wsolve workspace (with iterative refinement) */
  double *bcopy;             /* n, for x == b */
  void *symbolic, *numeric;
  double control[UMFPACK_CONTROL];
  double info[UMFPACK_INFO];
} umf;

static const char *status_text(SuiteSparse_long s)
{
  switch (s) {
  case UMFPACK_WARNING_singular_matrix:
    return "matrix is singular";
  case UMFPACK_ERROR_out_of_memory:
    return "out of memory";
  case UMFPACK_ERROR_invalid_Numeric_object:
    return "invalid Numeric object";
  case UMFPACK_ERROR_invalid_Symbolic_object:
    return "invalid Symbolic object";
  case UMFPACK_ERROR_argument_missing:
    return "required argument missing";
  case UMFPACK_ERROR_n_nonpositive:
    return "matrix dimension is not positive";
  case UMFPACK_ERROR_invalid_matrix:
    return "invalid matrix (pattern)";
  case UMFPACK_ERROR_different_pattern:
    return "pattern changed since the symbolic analysis";
  case UMFPACK_ERROR_invalid_system:
    return "invalid system";
  case UMFPACK_ERROR_invalid_permutation:
    return "invalid permutation";
  case UMFPACK_ERROR_ordering_failed:
    return "ordering failed";
  case UMFPACK_ERROR_internal_error:
    return "internal error";
  default:
    return "unknown status";
  }
}

/* Map an UMFPACK status of `phase`; warnings about determinant range are fine. */
static fcm_status map_status(fcm_ctx *ctx, const umf *h, const char *phase, SuiteSparse_long s)
{
  fcm_status st = FCM_OK;
  if (s == UMFPACK_OK || s == UMFPACK_WARNING_determinant_underflow ||
      s == UMFPACK_WARNING_determinant_overflow)
    goto cleanup;
  FCM_CHECK(s != UMFPACK_WARNING_singular_matrix, ctx, FCM_ERR_SINGULAR,
            "umfpack %s: matrix is singular (zero pivot, n = %lld)", phase, (long long)h->n);
  FCM_CHECK(s != UMFPACK_ERROR_out_of_memory, ctx, FCM_ERR_ALLOC,
            "umfpack %s: out of memory (n = %lld, nnz = %lld)", phase, (long long)h->n,
            (long long)h->nnz);
  FCM_CHECK(0, ctx, FCM_ERR_INTERNAL, "umfpack %s: %s (status %ld)", phase, status_text(s),
            (long)s);
cleanup:
  return st;
}

static void umf_destroy(fcm_ctx *ctx, void *impl)
{
  umf *h = impl;
  if (!h) return;
  if (h->numeric) umfpack_dl_free_numeric(&h->numeric);
  if (h->symbolic) umfpack_dl_free_symbolic(&h->symbolic);
  fcm__free(ctx, h->ap);
  fcm__free(ctx, h->ai);
  fcm__free(ctx, h->ax);
  fcm__free(ctx, h->wi);
  fcm__free(ctx, h->w);
  fcm__free(ctx, h->bcopy);
  fcm__free(ctx, h);
}

static fcm_status umf_create(fcm_ctx *ctx, const fcm_csr *A, void **impl)
{
  fcm_status st = FCM_OK;
  umf *h = NULL;
  FCM_ALLOC(ctx, 1, h);
  h->n = A->nrows;
  h->nnz = A->nnz;
  FCM_ALLOC(ctx, h->n + 1, h->ap);
  FCM_ALLOC(ctx, h->nnz, h->ai);
  FCM_ALLOC(ctx, h->nnz, h->ax);
  FCM_ALLOC(ctx, 2 * h->n, h->wi);
  FCM_ALLOC(ctx, 5 * h->n, h->w);
  FCM_ALLOC(ctx, h->n, h->bcopy);
  for (fcm_index i = 0; i <= h->n; i++)
    h->ap[i] = (SuiteSparse_long)A->row_ptr[i];
  for (fcm_index p = 0; p < h->nnz; p++)
    h->ai[p] = (SuiteSparse_long)A->col_idx[p];
  umfpack_dl_defaults(h->control);
  h->control[UMFPACK_PRL] = 0; /* print nothing, even on error */
  *impl = h;
  h = NULL;
cleanup:
  umf_destroy(ctx, h);
  return st;
}

static fcm_status umf_analyze(fcm_ctx *ctx, void *impl, fcm_direct_info *info)
{
  fcm_status st = FCM_OK;
  umf *h = impl;
  SuiteSparse_long s = umfpack_dl_symbolic((SuiteSparse_long)h->n, (SuiteSparse_long)h->n, h->ap,
                                           h->ai, NULL, &h->symbolic, h->control, h->info);
  FCM_TRY(ctx, map_status(ctx, h, "analyze", s));
  FCM_CHECK(h->symbolic, ctx, FCM_ERR_INTERNAL, "umfpack analyze: no Symbolic object returned");
  info->analyses++;
  info->factor_nnz = h->info[UMFPACK_LNZ_ESTIMATE] + h->info[UMFPACK_UNZ_ESTIMATE];
  info->factor_flops = h->info[UMFPACK_FLOPS_ESTIMATE];
cleanup:
  return st;
}

static fcm_status umf_factor(fcm_ctx *ctx, void *impl, const double *values, fcm_direct_info *info)
{
  fcm_status st = FCM_OK;
  umf *h = impl;
  if (h->numeric) umfpack_dl_free_numeric(&h->numeric);
  h->numeric = NULL;
  memcpy(h->ax, values, (size_t)h->nnz * sizeof *values);
  SuiteSparse_long s =
      umfpack_dl_numeric(h->ap, h->ai, h->ax, h->symbolic, &h->numeric, h->control, h->info);
  info->rcond = h->info[UMFPACK_RCOND];
  if (s == UMFPACK_WARNING_singular_matrix) {
    /* A Numeric object exists but would divide by zero: name the first zero
     * pivot, then discard it. We factor P A^T Q = L U, so pivot k couples row
     * Q[k] and column P[k] of A. The solve workspaces hold P, Q and diag(U). */
    SuiteSparse_long *pp = h->wi, *qq = h->wi + h->n;
    double *udiag = h->w;
    fcm_index row = -1, col = -1;
    if (umfpack_dl_get_numeric(NULL, NULL, NULL, NULL, NULL, NULL, pp, qq, udiag, NULL, NULL,
                               h->numeric) == UMFPACK_OK) {
      for (fcm_index k = 0; k < h->n && col < 0; k++)
        if (udiag[k] == 0.0) row = (fcm_index)qq[k], col = (fcm_index)pp[k];
    }
    umfpack_dl_free_numeric(&h->numeric);
    h->numeric = NULL;
    info->failed_column = col;
    FCM_CHECK(0, ctx, FCM_ERR_SINGULAR,
              "umfpack factor: matrix is singular (zero pivot at row %lld, column %lld; n = %lld)",
              (long long)row, (long long)col, (long long)h->n);
  }
  FCM_TRY(ctx, map_status(ctx, h, "factor", s));
  FCM_CHECK(h->numeric, ctx, FCM_ERR_INTERNAL, "umfpack factor: no Numeric object returned");
  info->factor_nnz = h->info[UMFPACK_LNZ] + h->info[UMFPACK_UNZ];
  info->factor_flops = h->info[UMFPACK_FLOPS];
cleanup:
  return st;
}

static fcm_status umf_solve(fcm_ctx *ctx, void *impl, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  umf *h = impl;
  if (b == x) {
    memcpy(h->bcopy, b, (size_t)h->n * sizeof *b);
    b = h->bcopy;
  }
  SuiteSparse_long s = umfpack_dl_wsolve(UMFPACK_At, h->ap, h->ai, h->ax, x, b, h->numeric,
                                         h->control, h->info, h->wi, h->w);
  FCM_TRY(ctx, map_status(ctx, h, "solve", s));
cleanup:
  return st;
}

const fcm__direct_ops fcm__umfpack_ops = {"umfpack", umf_create, umf_analyze, NULL,
                                          NULL,      umf_factor, umf_solve,   umf_destroy};
