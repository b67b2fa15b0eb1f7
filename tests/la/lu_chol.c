/* Dense LU (fcm__getrf/getrs) and Cholesky (fcm__potrf/potrs) solves judged by
 * their residuals; an indefinite matrix makes potrf fail with FCM_ERR_SINGULAR
 * naming the minor, a singular one makes getrf fail naming the zero pivot, and
 * NaN input gives FCM_ERR_NUMERIC. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

enum { NRHS = 3 };

/* max |A X - B| / (max|A| max|X| n) over all right-hand sides. */
static double residual(int n, const double *a, int lda, const double *x, const double *b, int ldb)
{
  double r = 0.0, xmax = dense_maxabs(n, NRHS, x, ldb), amax = dense_maxabs(n, n, a, lda);
  for (int c = 0; c < NRHS; c++)
    for (int i = 0; i < n; i++) {
      double s = 0.0;
      for (int j = 0; j < n; j++)
        s += a[i + j * lda] * x[j + c * ldb];
      r = fmax(r, fabs(s - b[i + c * ldb]));
    }
  return r / (amax * xmax * n);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {2024};
  const int ns[] = {1, 4, 17, 50};
  for (size_t c = 0; c < sizeof ns / sizeof ns[0]; c++) {
    int n = ns[c], lda = n + 1, ldb = n + 2;
    double *a = calloc((size_t)lda * n, sizeof *a), *f = calloc((size_t)lda * n, sizeof *f);
    double *b = calloc((size_t)ldb * NRHS, sizeof *b), *x = calloc((size_t)ldb * NRHS, sizeof *x);
    int *ipiv = calloc((size_t)n, sizeof *ipiv);
    for (int i = 0; i < ldb * NRHS; i++)
      b[i] = rng_uniform(&r);

    /* General (unsymmetric) matrix: LU. */
    for (int i = 0; i < lda * n; i++)
      a[i] = f[i] = rng_uniform(&r);
    for (int i = 0; i < ldb * NRHS; i++)
      x[i] = b[i];
    TEST_OK(ctx, fcm__getrf(ctx, n, f, lda, ipiv));
    TEST_OK(ctx, fcm__getrs(ctx, n, NRHS, f, lda, ipiv, x, ldb));
    TEST_TRUE(residual(n, a, lda, x, b, ldb) <= 1e-14);

    /* SPD matrix B^T B + n I: Cholesky. */
    for (int j = 0; j < n; j++)
      for (int i = 0; i < n; i++) {
        double s = (i == j) ? n : 0.0;
        for (int l = 0; l < n; l++)
          s += f[l + i * lda] * f[l + j * lda];
        a[i + j * lda] = s;
      }
    for (int i = 0; i < lda * n; i++)
      f[i] = a[i];
    for (int i = 0; i < ldb * NRHS; i++)
      x[i] = b[i];
    TEST_OK(ctx, fcm__potrf(ctx, n, f, lda));
    TEST_OK(ctx, fcm__potrs(ctx, n, NRHS, f, lda, x, ldb));
    TEST_TRUE(residual(n, a, lda, x, b, ldb) <= 1e-14);
    free(a), free(f), free(b), free(x), free(ipiv);
  }

  /* Indefinite: diag(1, 2, -1, 4) -> the leading minor of order 3 fails. */
  {
    double a[16] = {0};
    a[0] = 1.0, a[5] = 2.0, a[10] = -1.0, a[15] = 4.0;
    TEST_ERR(ctx, fcm__potrf(ctx, 4, a, 4), FCM_ERR_SINGULAR,
             "not positive definite (leading minor of order 3");
  }
  /* Singular: third column = first + second (exact in binary) -> zero pivot. */
  {
    double a[9] = {1.0, 2.0, 4.0, 0.5, 1.0, 3.0, 1.5, 3.0, 7.0};
    int ipiv[3];
    TEST_ERR(ctx, fcm__getrf(ctx, 3, a, 3, ipiv), FCM_ERR_SINGULAR,
             "matrix is singular, pivot U(2,2)");
  }
  /* NaN input. */
  {
    double a[4] = {1.0, 0.0, 0.0, 1.0};
    int ipiv[2];
    a[1] = NAN;
    TEST_ERR(ctx, fcm__getrf(ctx, 2, a, 2, ipiv), FCM_ERR_NUMERIC,
             "dgetrf: input entry (1, 0) is nan");
    TEST_ERR(ctx, fcm__potrf(ctx, 2, a, 2), FCM_ERR_NUMERIC, "dpotrf: input entry (1, 0) is nan");
    double b[2] = {1.0, 1.0};
    TEST_ERR(ctx, fcm__potrs(ctx, 2, 1, a, 2, b, 1), FCM_ERR_ARG, "ldb = 1");
    TEST_ERR(ctx, fcm__getrs(ctx, 2, 1, a, 1, ipiv, b, 2), FCM_ERR_ARG, "lda = 1");
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
