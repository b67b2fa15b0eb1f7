/* fcm__lstsq: an overdetermined consistent system is solved exactly (rank n);
 * a rank-deficient one [B B] (duplicated columns) reports rank n/2 and returns the
 * minimum-norm solution (y/2, y/2) where B y = b; an underdetermined full-rank
 * system returns the minimum-norm solution A^T (A A^T)^{-1} b; an inconsistent
 * one satisfies the normal equations. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {99};
  int rank = -1;

  /* Overdetermined, consistent: b = A x_true. */
  {
    enum { M = 30, N = 8 };
    double a[M * N], a0[M * N], b[M], x[N];
    for (int i = 0; i < M * N; i++)
      a[i] = a0[i] = rng_uniform(&r);
    for (int j = 0; j < N; j++)
      x[j] = rng_uniform(&r);
    for (int i = 0; i < M; i++) {
      b[i] = 0.0;
      for (int j = 0; j < N; j++)
        b[i] += a0[i + j * M] * x[j];
    }
    TEST_OK(ctx, fcm__lstsq(ctx, M, N, 1, a, M, b, M, -1.0, &rank));
    TEST_TRUE(rank == N);
    for (int j = 0; j < N; j++)
      TEST_NEAR(b[j], x[j], 0.0, 1e-13);
  }

  /* Inconsistent: residual orthogonal to the columns (A^T (A x - b) = 0). */
  {
    enum { M = 25, N = 6 };
    double a[M * N], a0[M * N], b[M], b0[M];
    for (int i = 0; i < M * N; i++)
      a[i] = a0[i] = rng_uniform(&r);
    for (int i = 0; i < M; i++)
      b[i] = b0[i] = rng_uniform(&r);
    TEST_OK(ctx, fcm__lstsq(ctx, M, N, 1, a, M, b, M, -1.0, &rank));
    TEST_TRUE(rank == N);
    for (int j = 0; j < N; j++) {
      double g = 0.0;
      for (int i = 0; i < M; i++) {
        double res = -b0[i];
        for (int l = 0; l < N; l++)
          res += a0[i + l * M] * b[l];
        g += a0[i + j * M] * res;
      }
      TEST_NEAR(g, 0.0, 0.0, 1e-13);
    }
  }

  /* Rank-deficient: A = [B B], B 20 x 5 full rank, b = B y. */
  {
    enum { M = 20, K = 5, N = 2 * K };
    double bm[M * K], a[M * N], b[M], y[K];
    for (int i = 0; i < M * K; i++)
      bm[i] = rng_uniform(&r);
    for (int j = 0; j < N; j++)
      for (int i = 0; i < M; i++)
        a[i + j * M] = bm[i + (j % K) * M];
    for (int j = 0; j < K; j++)
      y[j] = rng_uniform(&r);
    for (int i = 0; i < M; i++) {
      b[i] = 0.0;
      for (int j = 0; j < K; j++)
        b[i] += bm[i + j * M] * y[j];
    }
    TEST_OK(ctx, fcm__lstsq(ctx, M, N, 1, a, M, b, M, 1e-10, &rank));
    TEST_TRUE(rank == K);
    for (int j = 0; j < K; j++) {
      TEST_NEAR(b[j], 0.5 * y[j], 0.0, 1e-13);
      TEST_NEAR(b[j + K], 0.5 * y[j], 0.0, 1e-13);
    }
  }

  /* Underdetermined, full row rank, two right-hand sides: x = A^T z with
   * A A^T z = b; check A x = b and x in the row space (x = A^T z exactly). */
  {
    enum { M = 4, N = 9, NR = 2 };
    double a[M * N], a0[M * N], b[N * NR], b0[M * NR];
    for (int i = 0; i < M * N; i++)
      a[i] = a0[i] = rng_uniform(&r);
    for (int c = 0; c < NR; c++)
      for (int i = 0; i < M; i++)
        b[i + c * N] = b0[i + c * M] = rng_uniform(&r);
    TEST_OK(ctx, fcm__lstsq(ctx, M, N, NR, a, M, b, N, -1.0, &rank));
    TEST_TRUE(rank == M);
    for (int c = 0; c < NR; c++) {
      const double *x = b + c * N;
      for (int i = 0; i < M; i++) {
        double s = 0.0;
        for (int j = 0; j < N; j++)
          s += a0[i + j * M] * x[j];
        TEST_NEAR(s, b0[i + c * M], 0.0, 1e-13);
      }
      /* z from the normal equations of the row space: (A A^T) z = A x, then x - A^T z = 0. */
      double g[M * M], z[M];
      int ipiv[M];
      for (int i = 0; i < M; i++) {
        z[i] = 0.0;
        for (int j = 0; j < N; j++)
          z[i] += a0[i + j * M] * x[j];
        for (int l = 0; l < M; l++) {
          g[i + l * M] = 0.0;
          for (int j = 0; j < N; j++)
            g[i + l * M] += a0[i + j * M] * a0[l + j * M];
        }
      }
      TEST_OK(ctx, fcm__getrf(ctx, M, g, M, ipiv));
      TEST_OK(ctx, fcm__getrs(ctx, M, 1, g, M, ipiv, z, M));
      for (int j = 0; j < N; j++) {
        double s = 0.0;
        for (int i = 0; i < M; i++)
          s += a0[i + j * M] * z[i];
        TEST_NEAR(x[j], s, 0.0, 1e-13);
      }
    }
  }

  /* Errors. */
  {
    double a[6] = {1, 2, 3, 4, 5, NAN}, b[3] = {1, 2, 3};
    TEST_ERR(ctx, fcm__lstsq(ctx, 3, 2, 1, a, 3, b, 3, -1.0, &rank), FCM_ERR_NUMERIC,
             "dgelsd: input entry (2, 1) is nan");
    TEST_ERR(ctx, fcm__lstsq(ctx, 3, 2, 1, a, 3, b, 2, -1.0, &rank), FCM_ERR_ARG, "ldb = 2");
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
