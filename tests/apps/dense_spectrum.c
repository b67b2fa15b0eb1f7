/* fcm_dense_spectrum_eval (the dense spectra behind fcm-condition): with S = L L^T and
 * A = L^{-T} D L^{-1}, the spectrum of S A is D (indefinite D, Cholesky path); S = NULL
 * gives the spectrum of Q D Q^T; an indefinite "S" takes the eigendecomposition fallback
 * (its negative eigenvalue used as 0); bad arguments and NaN are rejected with messages; an
 * allocation-failure loop frees everything. */
#include "fcm/dense.h"
#include "test.h"

#include "../la/la_test_util.h"

enum { N = 9 };

/* Q = I - 2 v v^T / v^T v (orthogonal, symmetric) */
static void householder(rng *r, double *Q)
{
  double v[N], vv = 0.0;
  for (int i = 0; i < N; i++) {
    v[i] = rng_uniform(r) + (i == 0 ? 2.0 : 0.0);
    vv += v[i] * v[i];
  }
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++)
      Q[i + j * N] = (i == j) - 2.0 * v[i] * v[j] / vv;
}

/* M = Q diag(d) Q^T */
static void compose(const double *Q, const double *d, double *M)
{
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      double s = 0.0;
      for (int k = 0; k < N; k++)
        s += Q[i + k * N] * d[k] * Q[j + k * N];
      M[i + j * N] = s;
    }
}

static int cmp(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(void)
{
  rng r = {12345};
  double L[N * N] = {0}, Li[N * N] = {0}, S[N * N], A[N * N], Q[N * N], w[N], d[N];
  static const double dvals[N] = {-3.0, -1e-3, 2e-6, 0.5, 1.0, 1.0, 7.0, 40.0, 1e4};
  fcm_ctx *ctx = NULL;
  fcm_dense_spectrum_info info;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));

  /* L lower triangular with diagonal in [1, 3); Li = L^{-1} by forward substitution */
  for (int j = 0; j < N; j++)
    for (int i = j; i < N; i++)
      L[i + j * N] = i == j ? 2.0 + rng_uniform(&r) : rng_uniform(&r);
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      double s = i == j ? 1.0 : 0.0;
      for (int k = 0; k < i; k++)
        s -= L[i + k * N] * Li[k + j * N];
      Li[i + j * N] = s / L[i + i * N];
    }
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++) {
      double s = 0.0, a = 0.0;
      for (int k = 0; k < N; k++) {
        s += L[i + k * N] * L[j + k * N];
        a += Li[k + i * N] * dvals[k] * Li[k + j * N]; /* (L^{-T} D L^{-1})_ij */
      }
      S[i + j * N] = s;
      A[i + j * N] = a;
    }
  for (int j = 0; j < N; j++) /* exact symmetry, as a caller assembling A would have */
    for (int i = j + 1; i < N; i++) {
      A[i + j * N] = A[j + i * N] = 0.5 * (A[i + j * N] + A[j + i * N]);
      S[i + j * N] = S[j + i * N];
    }
  TEST_OK(ctx, fcm_dense_spectrum_eval(ctx, N, A, S, w, &info));
  TEST_TRUE(info.cholesky == 1 && info.s_nonpositive == 0);
  for (int k = 0; k < N; k++)
    TEST_NEAR(w[k], dvals[k], 1e-9, 1e-11 * 1e4);

  /* S = NULL: the eigenvalues of A itself */
  householder(&r, Q);
  compose(Q, dvals, A);
  TEST_OK(ctx, fcm_dense_spectrum_eval(ctx, N, A, NULL, w, NULL));
  for (int k = 0; k < N; k++)
    TEST_NEAR(w[k], dvals[k], 1e-12, 1e-11);

  /* indefinite S: fallback; with A = I the spectrum is max(s, 0) */
  static const double svals[N] = {-1e-3, 0.1, 0.2, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0};
  compose(Q, svals, S);
  for (int j = 0; j < N; j++)
    for (int i = 0; i < N; i++)
      A[i + j * N] = i == j;
  TEST_OK(ctx, fcm_dense_spectrum_eval(ctx, N, A, S, w, &info));
  TEST_TRUE(info.cholesky == 0 && info.s_nonpositive == 1);
  TEST_NEAR(info.s_min, -1e-3, 1e-9, 0.0);
  TEST_NEAR(info.s_max, 5.0, 1e-12, 0.0);
  for (int k = 0; k < N; k++)
    d[k] = fmax(svals[k], 0.0);
  qsort(d, N, sizeof *d, cmp);
  for (int k = 0; k < N; k++)
    TEST_NEAR(w[k], d[k], 1e-12, 1e-13);

  /* errors */
  TEST_ERR(ctx, fcm_dense_spectrum_eval(ctx, N, NULL, S, w, NULL), FCM_ERR_ARG, "NULL argument");
  TEST_ERR(ctx, fcm_dense_spectrum_eval(ctx, -1, A, S, w, NULL), FCM_ERR_ARG,
           "n = -1 out of range");
  TEST_OK(ctx, fcm_dense_spectrum_eval(ctx, 0, A, S, w, NULL));
  A[3] = NAN;
  TEST_ERR(ctx, fcm_dense_spectrum_eval(ctx, N, A, NULL, w, NULL), FCM_ERR_NUMERIC, "input entry");
  TEST_ERR(ctx, fcm_dense_spectrum_eval(ctx, N, A, S, w, NULL), FCM_ERR_NUMERIC, "input entry");
  A[3] = 0.0;
  fcm_ctx_destroy(&ctx);

  /* allocation failures on the fallback path (the longest): fail the k-th allocation */
  failing f;
  ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  int done = 0;
  for (long long k = 0; k < 100 && !done && ctx; k++) {
    f.count = 0;
    f.fail_at = k;
    fcm_status st = fcm_dense_spectrum_eval(ctx, N, A, S, w, NULL);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    if (st == FCM_OK) {
      done = 1;
      TEST_TRUE(k > 0);
      for (int i = 0; i < N; i++)
        TEST_NEAR(w[i], d[i], 1e-12, 1e-13);
    } else {
      TEST_TRUE(st == FCM_ERR_ALLOC);
      fcm_ctx_error_clear(ctx);
    }
  }
  TEST_TRUE(done);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
