/* fcm__gesvd: thin SVD of random m x n matrices, tall and wide: A = U S Vt to
 * 1e-13 relative, orthonormal U columns and Vt rows, singular values descending
 * and non-negative; values-only mode agrees; a rank-deficient matrix shows zeros. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

static void check_svd(fcm_ctx *ctx, rng *r, int m, int n)
{
  int k = m < n ? m : n, lda = m + 1, ldu = m + 2, ldvt = k + 1;
  double *a = calloc((size_t)lda * n, sizeof *a), *a0 = calloc((size_t)lda * n, sizeof *a0);
  double *u = calloc((size_t)ldu * k, sizeof *u), *vt = calloc((size_t)ldvt * n, sizeof *vt);
  double *s = calloc((size_t)k, sizeof *s), *s2 = calloc((size_t)k, sizeof *s2);
  for (int i = 0; i < lda * n; i++)
    a[i] = a0[i] = rng_uniform(r);
  TEST_OK(ctx, fcm__gesvd(ctx, m, n, a, lda, s, u, ldu, vt, ldvt));
  double anorm = dense_maxabs(m, n, a0, lda), err = 0.0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < m; i++) {
      double x = 0.0;
      for (int l = 0; l < k; l++)
        x += u[i + l * ldu] * s[l] * vt[l + j * ldvt];
      err = fmax(err, fabs(x - a0[i + j * lda]));
    }
  TEST_TRUE(err <= 1e-13 * anorm * k);
  TEST_TRUE(orth_error_cols(m, k, u, ldu) <= 1e-13 * k);
  /* rows of Vt orthonormal: (Vt Vt^T)_ab */
  double oe = 0.0;
  for (int p = 0; p < k; p++)
    for (int q = 0; q < k; q++) {
      double x = 0.0;
      for (int j = 0; j < n; j++)
        x += vt[p + j * ldvt] * vt[q + j * ldvt];
      oe = fmax(oe, fabs(x - (p == q ? 1.0 : 0.0)));
    }
  TEST_TRUE(oe <= 1e-13 * k);
  for (int l = 0; l < k; l++)
    TEST_TRUE(s[l] >= 0.0 && (l == 0 || s[l] <= s[l - 1]));
  /* Frobenius norm^2 = sum of s^2. */
  double f2 = 0.0, s2sum = 0.0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < m; i++)
      f2 += a0[i + j * lda] * a0[i + j * lda];
  for (int l = 0; l < k; l++)
    s2sum += s[l] * s[l];
  TEST_NEAR(s2sum, f2, 1e-13, 0.0);
  /* Values only. */
  for (int i = 0; i < lda * n; i++)
    a[i] = a0[i];
  TEST_OK(ctx, fcm__gesvd(ctx, m, n, a, lda, s2, NULL, 1, NULL, 1));
  for (int l = 0; l < k; l++)
    TEST_NEAR(s2[l], s[l], 0.0, 1e-13 * s[0]);
  free(a), free(a0), free(u), free(vt), free(s), free(s2);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {777};
  const int shapes[][2] = {{1, 1}, {5, 3}, {3, 5}, {40, 7}, {7, 40}, {30, 30}, {64, 20}, {1, 9}};
  for (size_t c = 0; c < sizeof shapes / sizeof shapes[0]; c++)
    check_svd(ctx, &r, shapes[c][0], shapes[c][1]);

  /* Rank 2 (6 x 4, outer products): two zero singular values. */
  {
    enum { M = 6, N = 4 };
    double a[M * N], s[N], x[M], y[N], p[M], q[N];
    for (int i = 0; i < M; i++)
      x[i] = rng_uniform(&r), p[i] = rng_uniform(&r);
    for (int j = 0; j < N; j++)
      y[j] = rng_uniform(&r), q[j] = rng_uniform(&r);
    for (int j = 0; j < N; j++)
      for (int i = 0; i < M; i++)
        a[i + j * M] = x[i] * y[j] + p[i] * q[j];
    TEST_OK(ctx, fcm__gesvd(ctx, M, N, a, M, s, NULL, 1, NULL, 1));
    TEST_TRUE(s[1] > 1e-3 * s[0]);
    TEST_TRUE(s[2] <= 1e-14 * s[0] && s[3] <= 1e-14 * s[0]);
  }

  /* Errors. */
  {
    double a[4] = {1.0, 2.0, INFINITY, 4.0}, s[2];
    TEST_ERR(ctx, fcm__gesvd(ctx, 2, 2, a, 2, s, NULL, 1, NULL, 1), FCM_ERR_NUMERIC,
             "dgesvd: input entry (0, 1) is inf");
    TEST_ERR(ctx, fcm__gesvd(ctx, 2, 2, a, 1, s, NULL, 1, NULL, 1), FCM_ERR_ARG, "lda = 1");
    a[2] = 3.0;
    double u[4], vt[4];
    TEST_ERR(ctx, fcm__gesvd(ctx, 2, 2, a, 2, s, u, 1, vt, 2), FCM_ERR_ARG, "ldu = 1");
    TEST_ERR(ctx, fcm__gesvd(ctx, 2, 2, a, 2, s, u, 2, vt, 1), FCM_ERR_ARG, "ldvt = 1");
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
