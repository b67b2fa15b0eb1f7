/* The one adapter to BLAS (cblas) and LAPACK (LAPACKE): column-major wrappers
 * whose workspace comes from the context allocator and whose `info` codes become
 * fcm statuses with messages. */
#define _GNU_SOURCE /* RTLD_DEFAULT */
#include "la/la_impl.h"

#include <cblas.h>
#include <dlfcn.h>
#include <lapacke.h>
#include <math.h>
#include <string.h>

_Static_assert(sizeof(lapack_int) == sizeof(int), "fcm expects 32-bit LAPACK integers");

/* OpenBLAS extensions (declared here: not every cblas.h carries them). */
void openblas_set_num_threads(int num_threads);
int openblas_get_num_threads(void);

int fcm_blas_set_num_threads(int n)
{
  int old = openblas_get_num_threads();
  if (n >= 1) openblas_set_num_threads(n);
  return old;
}

/* A string-returning query of the BLAS found at run time (looked up in the library's own
 * scope, so a BLAS without it still links and loads), or "" when the BLAS has none. */
static const char *blas_query(const char *symbol)
{
  void *sym = dlsym(RTLD_DEFAULT, symbol);
  if (!sym) return "";
  char *(*fn)(void);
  memcpy(&fn, &sym, sizeof fn); /* object to function pointer, as POSIX allows */
  const char *s = fn();
  return s ? s : "";
}

const char *fcm__blas_core_name(void)
{
  return blas_query("openblas_get_corename");
}

const char *fcm__blas_config(void)
{
  return blas_query("openblas_get_config");
}

static CBLAS_TRANSPOSE cblas_trans(char t)
{
  return (t == 'T' || t == 't') ? CblasTrans : CblasNoTrans;
}

void fcm__gemm(char transa, char transb, int m, int n, int k, double alpha, const double *a,
               int lda, const double *b, int ldb, double beta, double *c, int ldc)
{
  if (m <= 0 || n <= 0) return;
  cblas_dgemm(CblasColMajor, cblas_trans(transa), cblas_trans(transb), m, n, k, alpha, a, lda, b,
              ldb, beta, c, ldc);
}

void fcm__gemv(char trans, int m, int n, double alpha, const double *a, int lda, const double *x,
               double beta, double *y)
{
  if (m <= 0 || n <= 0) return;
  cblas_dgemv(CblasColMajor, cblas_trans(trans), m, n, alpha, a, lda, x, 1, beta, y, 1);
}

void fcm__sgemv(char trans, int m, int n, float alpha, const float *a, int lda, const float *x,
                float beta, float *y)
{
  if (m <= 0 || n <= 0) return;
  cblas_sgemv(CblasColMajor, cblas_trans(trans), m, n, alpha, a, lda, x, 1, beta, y, 1);
}

void fcm__ger(int m, int n, double alpha, const double *x, const double *y, int incy, double *a,
              int lda)
{
  if (m <= 0 || n <= 0) return;
  cblas_dger(CblasColMajor, m, n, alpha, x, 1, y, incy, a, lda);
}

void fcm__trsv_upper(int n, const double *a, int lda, double *x)
{
  if (n <= 0) return;
  cblas_dtrsv(CblasColMajor, CblasUpper, CblasNoTrans, CblasNonUnit, n, a, lda, x, 1);
}

void fcm__trsm_right_unit_lower(int m, int n, double alpha, const double *a, int lda, double *b,
                                int ldb)
{
  if (m <= 0 || n <= 0) return;
  cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasNoTrans, CblasUnit, m, n, alpha, a, lda,
              b, ldb);
}

/* FCM_ERR_NUMERIC unless every entry of the m x n matrix (with lower_only, of
 * its lower triangle, the part symmetric routines read) is finite. */
static fcm_status check_finite_part(fcm_ctx *ctx, const char *routine, int m, int n,
                                    const double *a, int lda, int lower_only)
{
  fcm_status st = FCM_OK;
  for (int j = 0; j < n; j++)
    for (int i = lower_only ? j : 0; i < m; i++)
      FCM_CHECK(isfinite(a[i + (size_t)j * lda]), ctx, FCM_ERR_NUMERIC,
                "%s: input entry (%d, %d) is %g", routine, i, j, a[i + (size_t)j * lda]);
cleanup:
  return st;
}

static fcm_status check_finite(fcm_ctx *ctx, const char *routine, int m, int n, const double *a,
                               int lda)
{
  return check_finite_part(ctx, routine, m, n, a, lda, 0);
}

/* Map a LAPACKE return value for the routine that gave it. */
static fcm_status lapack_info(fcm_ctx *ctx, const char *routine, lapack_int info)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(info != LAPACK_WORK_MEMORY_ERROR && info != LAPACK_TRANSPOSE_MEMORY_ERROR, ctx,
            FCM_ERR_ALLOC, "%s: LAPACKE ran out of memory", routine);
  FCM_CHECK(info >= 0, ctx, FCM_ERR_ARG, "%s: argument %d had an illegal value", routine,
            (int)-info);
  FCM_CHECK(info == 0, ctx, FCM_ERR_LAPACK, "%s: failed with info = %d", routine, (int)info);
cleanup:
  return st;
}

/* dsyevd's workspace query for order n (depends on n and jobz only). */
static fcm_status syev_query(fcm_ctx *ctx, char jobz, int n, lapack_int *lwork, lapack_int *liwork)
{
  fcm_status st = FCM_OK;
  double qwork = 0.0, a = 0.0, w = 0.0;
  lapack_int qiwork = 0;
  lapack_int info = LAPACKE_dsyevd_work(LAPACK_COL_MAJOR, jobz, 'L', n, &a, FCM_MAX(1, n), &w,
                                        &qwork, -1, &qiwork, -1);
  FCM_TRY(ctx, lapack_info(ctx, "dsyevd (workspace query)", info));
  *lwork = (lapack_int)qwork;
  *liwork = qiwork;
cleanup:
  return st;
}

fcm_status fcm__syev_workspace(fcm_ctx *ctx, int want_vectors, int n, size_t *lwork, size_t *liwork)
{
  fcm_status st = FCM_OK;
  lapack_int lw = 0, liw = 0;
  FCM_CHECK(n >= 0, ctx, FCM_ERR_ARG, "syev workspace: n = %d must be >= 0", n);
  if (n > 0) FCM_TRY(ctx, syev_query(ctx, want_vectors ? 'V' : 'N', n, &lw, &liw));
  *lwork = (size_t)lw + 1;
  *liwork = (size_t)liw + 1;
cleanup:
  return st;
}

fcm_status fcm__syev_work(fcm_ctx *ctx, int want_vectors, int n, double *a, int lda, double *w,
                          double *work, size_t lwork, int *iwork, size_t liwork)
{
  fcm_status st = FCM_OK;
  lapack_int qwork = 0, qiwork = 0, info;
  char jobz = want_vectors ? 'V' : 'N';
  FCM_CHECK(n >= 0 && lda >= FCM_MAX(1, n), ctx, FCM_ERR_ARG, "syev: n = %d, lda = %d", n, lda);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite_part(ctx, "dsyevd", n, n, a, lda, 1));
  /* exactly the queried sizes, whatever the caller holds: the result does not depend on it */
  FCM_TRY(ctx, syev_query(ctx, jobz, n, &qwork, &qiwork));
  FCM_CHECK((size_t)qwork < lwork && (size_t)qiwork < liwork, ctx, FCM_ERR_INTERNAL,
            "syev: workspace of %zu doubles and %zu integers, n = %d needs %lld and %lld", lwork,
            liwork, n, (long long)qwork + 1, (long long)qiwork + 1);
  info = LAPACKE_dsyevd_work(LAPACK_COL_MAJOR, jobz, 'L', n, a, lda, w, work, qwork, iwork, qiwork);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_LAPACK,
            "dsyevd: eigenvalue iteration failed to converge (info = %d) for n = %d", (int)info, n);
  FCM_TRY(ctx, lapack_info(ctx, "dsyevd", info));
cleanup:
  return st;
}

fcm_status fcm__syev(fcm_ctx *ctx, int want_vectors, int n, double *a, int lda, double *w)
{
  fcm_status st = FCM_OK;
  double *work = NULL;
  lapack_int *iwork = NULL;
  size_t lwork = 0, liwork = 0;
  FCM_CHECK(n >= 0 && lda >= FCM_MAX(1, n), ctx, FCM_ERR_ARG, "syev: n = %d, lda = %d", n, lda);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite_part(ctx, "dsyevd", n, n, a, lda, 1));
  FCM_TRY(ctx, fcm__syev_workspace(ctx, want_vectors, n, &lwork, &liwork));
  FCM_ALLOC(ctx, lwork, work);
  FCM_ALLOC(ctx, liwork, iwork);
  FCM_TRY(ctx, fcm__syev_work(ctx, want_vectors, n, a, lda, w, work, lwork, iwork, liwork));
cleanup:
  fcm__free(ctx, work);
  fcm__free(ctx, iwork);
  return st;
}

fcm_status fcm__sygv(fcm_ctx *ctx, int n, double *a, int lda, double *b, int ldb, double *w)
{
  fcm_status st = FCM_OK;
  double *work = NULL;
  lapack_int info;
  FCM_CHECK(n >= 0 && lda >= FCM_MAX(1, n) && ldb >= FCM_MAX(1, n), ctx, FCM_ERR_ARG,
            "sygv: n = %d, lda = %d, ldb = %d", n, lda, ldb);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite_part(ctx, "dsygv", n, n, a, lda, 1));
  FCM_TRY(ctx, check_finite_part(ctx, "dsygv", n, n, b, ldb, 1));
  FCM_ALLOC(ctx, 3 * (size_t)n, work);
  info = LAPACKE_dsygv_work(LAPACK_COL_MAJOR, 1, 'N', 'L', n, a, lda, b, ldb, w, work, 3 * n);
  FCM_CHECK(info <= n, ctx, FCM_ERR_SINGULAR,
            "dsygv: B is not positive definite (leading minor of order %d, n = %d)", (int)info - n,
            n);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_LAPACK, "dsygv: the eigenvalue iteration failed (info = %d)",
            (int)info);
  FCM_TRY(ctx, lapack_info(ctx, "dsygv", info));
cleanup:
  fcm__free(ctx, work);
  return st;
}

fcm_status fcm__stev(fcm_ctx *ctx, int n, double *d, double *e, double *z, int ldz)
{
  fcm_status st = FCM_OK;
  double *work = NULL;
  lapack_int info;
  FCM_CHECK(n >= 0, ctx, FCM_ERR_ARG, "stev: n = %d must be non-negative", n);
  FCM_CHECK(!z || ldz >= FCM_MAX(1, n), ctx, FCM_ERR_ARG, "stev: ldz = %d must be >= n = %d", ldz,
            n);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite(ctx, "dstev", n, 1, d, n));
  if (n > 1) FCM_TRY(ctx, check_finite(ctx, "dstev", n - 1, 1, e, n - 1));
  FCM_ALLOC(ctx, (size_t)FCM_MAX(1, 2 * n - 2), work);
  info = LAPACKE_dstev_work(LAPACK_COL_MAJOR, z ? 'V' : 'N', n, d, e, z, z ? ldz : 1, work);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_LAPACK,
            "dstev: %d off-diagonal elements failed to converge (n = %d)", (int)info, n);
  FCM_TRY(ctx, lapack_info(ctx, "dstev", info));
cleanup:
  fcm__free(ctx, work);
  return st;
}

fcm_status fcm__gesvd(fcm_ctx *ctx, int m, int n, double *a, int lda, double *s, double *u, int ldu,
                      double *vt, int ldvt)
{
  fcm_status st = FCM_OK;
  double *work = NULL, qwork, dummy = 0.0;
  lapack_int info;
  char jobu = u ? 'S' : 'N', jobvt = vt ? 'S' : 'N';
  FCM_CHECK(m >= 0 && n >= 0 && lda >= FCM_MAX(1, m), ctx, FCM_ERR_ARG,
            "gesvd: m = %d, n = %d, lda = %d", m, n, lda);
  /* Checked here so that LAPACK's xerbla (which prints) is never reached. */
  FCM_CHECK(!u || ldu >= FCM_MAX(1, m), ctx, FCM_ERR_ARG, "gesvd: ldu = %d must be >= m = %d", ldu,
            m);
  FCM_CHECK(!vt || ldvt >= FCM_MAX(1, FCM_MIN(m, n)), ctx, FCM_ERR_ARG,
            "gesvd: ldvt = %d must be >= min(m, n) = %d", ldvt, FCM_MIN(m, n));
  if (m == 0 || n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite(ctx, "dgesvd", m, n, a, lda));
  if (!u) u = &dummy, ldu = 1;
  if (!vt) vt = &dummy, ldvt = 1;
  info = LAPACKE_dgesvd_work(LAPACK_COL_MAJOR, jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt,
                             &qwork, -1);
  FCM_TRY(ctx, lapack_info(ctx, "dgesvd (workspace query)", info));
  FCM_ALLOC(ctx, (size_t)qwork + 1, work);
  info = LAPACKE_dgesvd_work(LAPACK_COL_MAJOR, jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt, work,
                             (lapack_int)qwork);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_LAPACK,
            "dgesvd: %d superdiagonals failed to converge (%d x %d matrix)", (int)info, m, n);
  FCM_TRY(ctx, lapack_info(ctx, "dgesvd", info));
cleanup:
  fcm__free(ctx, work);
  return st;
}

fcm_status fcm__getrf(fcm_ctx *ctx, int n, double *a, int lda, int *ipiv)
{
  fcm_status st = FCM_OK;
  lapack_int info;
  FCM_CHECK(n >= 0 && lda >= FCM_MAX(1, n), ctx, FCM_ERR_ARG, "getrf: n = %d, lda = %d", n, lda);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite(ctx, "dgetrf", n, n, a, lda));
  info = LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, n, n, a, lda, ipiv);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_SINGULAR,
            "dgetrf: matrix is singular, pivot U(%d,%d) is exactly zero (n = %d)", (int)info - 1,
            (int)info - 1, n);
  FCM_TRY(ctx, lapack_info(ctx, "dgetrf", info));
cleanup:
  return st;
}

fcm_status fcm__getrf_tall(fcm_ctx *ctx, int m, int n, double *a, int lda, int *ipiv)
{
  fcm_status st = FCM_OK;
  lapack_int info;
  FCM_CHECK(m >= n && n >= 0 && lda >= FCM_MAX(1, m), ctx, FCM_ERR_ARG,
            "getrf: m = %d, n = %d, lda = %d", m, n, lda);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite(ctx, "dgetrf", m, n, a, lda));
  info = LAPACKE_dgetrf_work(LAPACK_COL_MAJOR, m, n, a, lda, ipiv);
  if (info > 0) info = 0; /* an exact zero pivot: U says so */
  FCM_TRY(ctx, lapack_info(ctx, "dgetrf", info));
cleanup:
  return st;
}

fcm_status fcm__getrs(fcm_ctx *ctx, int n, int nrhs, const double *lu, int lda, const int *ipiv,
                      double *b, int ldb)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(n >= 0 && nrhs >= 0 && lda >= FCM_MAX(1, n) && ldb >= FCM_MAX(1, n), ctx, FCM_ERR_ARG,
            "getrs: n = %d, nrhs = %d, lda = %d, ldb = %d", n, nrhs, lda, ldb);
  if (n == 0 || nrhs == 0) goto cleanup;
  FCM_TRY(ctx,
          lapack_info(ctx, "dgetrs",
                      LAPACKE_dgetrs_work(LAPACK_COL_MAJOR, 'N', n, nrhs, lu, lda, ipiv, b, ldb)));
cleanup:
  return st;
}

fcm_status fcm__potrf(fcm_ctx *ctx, int n, double *a, int lda)
{
  fcm_status st = FCM_OK;
  lapack_int info;
  FCM_CHECK(n >= 0 && lda >= FCM_MAX(1, n), ctx, FCM_ERR_ARG, "potrf: n = %d, lda = %d", n, lda);
  if (n == 0) goto cleanup;
  FCM_TRY(ctx, check_finite_part(ctx, "dpotrf", n, n, a, lda, 1));
  info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, a, lda);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_SINGULAR,
            "dpotrf: matrix is not positive definite (leading minor of order %d, n = %d)",
            (int)info, n);
  FCM_TRY(ctx, lapack_info(ctx, "dpotrf", info));
cleanup:
  return st;
}

fcm_status fcm__potrs(fcm_ctx *ctx, int n, int nrhs, const double *l, int lda, double *b, int ldb)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(n >= 0 && nrhs >= 0 && lda >= FCM_MAX(1, n) && ldb >= FCM_MAX(1, n), ctx, FCM_ERR_ARG,
            "potrs: n = %d, nrhs = %d, lda = %d, ldb = %d", n, nrhs, lda, ldb);
  if (n == 0 || nrhs == 0) goto cleanup;
  FCM_TRY(ctx, lapack_info(ctx, "dpotrs",
                           LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, nrhs, l, lda, b, ldb)));
cleanup:
  return st;
}

fcm_status fcm__lstsq(fcm_ctx *ctx, int m, int n, int nrhs, double *a, int lda, double *b, int ldb,
                      double rcond, int *rank)
{
  fcm_status st = FCM_OK;
  double *s = NULL, *work = NULL, qwork;
  lapack_int *iwork = NULL, qiwork, info, r = 0;
  FCM_CHECK(m >= 0 && n >= 0 && nrhs >= 0 && lda >= FCM_MAX(1, m) &&
                ldb >= FCM_MAX(1, FCM_MAX(m, n)),
            ctx, FCM_ERR_ARG, "lstsq: m = %d, n = %d, nrhs = %d, lda = %d, ldb = %d", m, n, nrhs,
            lda, ldb);
  if (m == 0 || n == 0 || nrhs == 0) goto cleanup;
  FCM_TRY(ctx, check_finite(ctx, "dgelsd", m, n, a, lda));
  FCM_TRY(ctx, check_finite(ctx, "dgelsd", m, nrhs, b, ldb));
  FCM_ALLOC(ctx, (size_t)FCM_MIN(m, n), s);
  info = LAPACKE_dgelsd_work(LAPACK_COL_MAJOR, m, n, nrhs, a, lda, b, ldb, s, rcond, &r, &qwork, -1,
                             &qiwork);
  FCM_TRY(ctx, lapack_info(ctx, "dgelsd (workspace query)", info));
  FCM_ALLOC(ctx, (size_t)qwork + 1, work);
  FCM_ALLOC(ctx, (size_t)qiwork + 1, iwork);
  info = LAPACKE_dgelsd_work(LAPACK_COL_MAJOR, m, n, nrhs, a, lda, b, ldb, s, rcond, &r, work,
                             (lapack_int)qwork, iwork);
  FCM_CHECK(info <= 0, ctx, FCM_ERR_LAPACK, "dgelsd: SVD failed to converge (info = %d)",
            (int)info);
  FCM_TRY(ctx, lapack_info(ctx, "dgelsd", info));
cleanup:
  if (rank) *rank = (int)r;
  fcm__free(ctx, s);
  fcm__free(ctx, work);
  fcm__free(ctx, iwork);
  return st;
}
