/* fcm__syev on random symmetric matrices (A V = V diag(w), V orthonormal, w
 * ascending, values-only mode agrees) and fcm__stev on the 1-D Laplacian, whose
 * eigenpairs are known: 2 - 2 cos(k pi / (n+1)) with sine eigenvectors. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

static void check_syev(fcm_ctx *ctx, rng *r, int n, int lda)
{
  double *a = calloc((size_t)lda * n, sizeof *a), *v = calloc((size_t)lda * n, sizeof *v);
  double *w = calloc((size_t)n, sizeof *w), *w2 = calloc((size_t)n, sizeof *w2);
  for (int j = 0; j < n; j++)
    for (int i = j; i < n; i++)
      a[i + j * lda] = a[j + i * lda] = rng_uniform(r);
  for (int i = 0; i < lda * n; i++)
    v[i] = a[i];
  TEST_OK(ctx, fcm__syev(ctx, 1, n, v, lda, w));
  double anorm = dense_maxabs(n, n, a, lda);
  /* Residual A v_k - w_k v_k, relative to max |A| (and n for the sums). */
  double res = 0.0;
  for (int k = 0; k < n; k++)
    for (int i = 0; i < n; i++) {
      double s = 0.0;
      for (int l = 0; l < n; l++)
        s += a[i + l * lda] * v[l + k * lda];
      res = fmax(res, fabs(s - w[k] * v[i + k * lda]));
    }
  TEST_TRUE(res <= 1e-12 * anorm * n);
  TEST_TRUE(orth_error_cols(n, n, v, lda) <= 1e-13 * n);
  for (int k = 0; k + 1 < n; k++)
    TEST_TRUE(w[k] <= w[k + 1]);
  /* Trace = sum of eigenvalues. */
  double tr = 0.0, sw = 0.0;
  for (int k = 0; k < n; k++)
    tr += a[k + k * lda], sw += w[k];
  TEST_NEAR(sw, tr, 0.0, 1e-12 * anorm * n);
  /* Values only: same spectrum; the lower triangle alone is read. */
  for (int i = 0; i < lda * n; i++)
    v[i] = a[i];
  for (int j = 1; j < n; j++)
    for (int i = 0; i < j; i++)
      v[i + j * lda] = NAN;
  TEST_OK(ctx, fcm__syev(ctx, 0, n, v, lda, w2));
  for (int k = 0; k < n; k++)
    TEST_NEAR(w2[k], w[k], 0.0, 1e-13 * anorm * n);
  free(a), free(v), free(w), free(w2);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {12345};
  const int ns[] = {1, 2, 3, 8, 25, 60};
  for (size_t c = 0; c < sizeof ns / sizeof ns[0]; c++) {
    check_syev(ctx, &r, ns[c], ns[c]);
    check_syev(ctx, &r, ns[c], ns[c] + 2);
  }

  /* Repeated eigenvalue: the identity times 3 plus a rank-one term. */
  {
    enum { N = 6 };
    double a[N * N], w[N], u[N];
    for (int i = 0; i < N; i++)
      u[i] = 1.0 / sqrt((double)N);
    for (int j = 0; j < N; j++)
      for (int i = 0; i < N; i++)
        a[i + j * N] = (i == j ? 3.0 : 0.0) + 2.0 * u[i] * u[j];
    TEST_OK(ctx, fcm__syev(ctx, 1, N, a, N, w));
    for (int k = 0; k < N - 1; k++)
      TEST_NEAR(w[k], 3.0, 0.0, 1e-14);
    TEST_NEAR(w[N - 1], 5.0, 0.0, 1e-14);
    TEST_TRUE(orth_error_cols(N, N, a, N) <= 1e-14);
  }

  /* Tridiagonal 1-D Laplacian: d = 2, e = -1. */
  const int tn[] = {1, 2, 5, 40, 200};
  for (size_t c = 0; c < sizeof tn / sizeof tn[0]; c++) {
    int n = tn[c];
    double *d = calloc((size_t)n, sizeof *d), *e = calloc((size_t)n, sizeof *e);
    double *z = calloc((size_t)n * n, sizeof *z);
    for (int i = 0; i < n; i++)
      d[i] = 2.0, e[i] = -1.0;
    TEST_OK(ctx, fcm__stev(ctx, n, d, e, z, n));
    for (int k = 0; k < n; k++) {
      double exact = 2.0 - 2.0 * cos((k + 1) * LA_PI / (n + 1));
      TEST_NEAR(d[k], exact, 0.0, 1e-13);
      /* eigenvector: sin(i (k+1) pi / (n+1)), up to sign and normalization */
      double dotp = 0.0, nn = 0.0;
      for (int i = 0; i < n; i++) {
        double s = sin((i + 1) * (k + 1) * LA_PI / (n + 1));
        dotp += s * z[i + k * n], nn += s * s;
      }
      TEST_NEAR(fabs(dotp) / sqrt(nn), 1.0, 0.0, 1e-12);
    }
    TEST_TRUE(orth_error_cols(n, n, z, n) <= 1e-13 * n);
    /* Eigenvalues only. */
    for (int i = 0; i < n; i++)
      d[i] = 2.0, e[i] = -1.0;
    TEST_OK(ctx, fcm__stev(ctx, n, d, e, NULL, 1));
    for (int k = 0; k < n; k++)
      TEST_NEAR(d[k], 2.0 - 2.0 * cos((k + 1) * LA_PI / (n + 1)), 0.0, 1e-13);
    free(d), free(e), free(z);
  }

  /* Errors: NaN/Inf input, bad sizes. */
  {
    double a[4] = {1.0, NAN, NAN, 1.0}, w[2], d[2] = {1.0, INFINITY}, e[1] = {0.0};
    TEST_ERR(ctx, fcm__syev(ctx, 1, 2, a, 2, w), FCM_ERR_NUMERIC, "dsyevd: input entry (1, 0)");
    TEST_ERR(ctx, fcm__syev(ctx, 1, 2, a, 1, w), FCM_ERR_ARG, "lda = 1");
    TEST_ERR(ctx, fcm__stev(ctx, 2, d, e, NULL, 1), FCM_ERR_NUMERIC,
             "dstev: input entry (1, 0) is inf");
    TEST_ERR(ctx, fcm__stev(ctx, -1, d, e, NULL, 1), FCM_ERR_ARG, "n = -1");
    TEST_OK(ctx, fcm__syev(ctx, 1, 0, a, 1, w));
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
