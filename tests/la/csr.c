/* CSR matrices: creation from a pattern, from triplets (duplicates summed) and
 * around caller arrays; pattern validation errors; entry lookup; y = a A x + b y
 * against a dense product (and, on a matrix big enough for the OpenMP path,
 * bitwise against a serial loop); the symmetry measure; allocation failures. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "alloc_loop.h"

/* 7-point Laplacian on a g^3 grid as triplets (both triangles), returns count. */
static fcm_index laplacian_triplets(int g, fcm_index *ti, fcm_index *tj, double *tv)
{
  fcm_index t = 0;
  for (int z = 0; z < g; z++)
    for (int y = 0; y < g; y++)
      for (int x = 0; x < g; x++) {
        fcm_index i = x + (fcm_index)g * (y + (fcm_index)g * z);
        ti[t] = i, tj[t] = i, tv[t++] = 6.0;
        const int nb[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
        for (int k = 0; k < 6; k++) {
          int xx = x + nb[k][0], yy = y + nb[k][1], zz = z + nb[k][2];
          if (xx < 0 || yy < 0 || zz < 0 || xx >= g || yy >= g || zz >= g) continue;
          ti[t] = i, tj[t] = xx + (fcm_index)g * (yy + (fcm_index)g * zz), tv[t++] = -1.0;
        }
      }
  return t;
}

static void test_small(fcm_ctx *ctx, rng *r)
{
  /* Random 9 x 7 matrix from 60 triplets with duplicates; dense reference. */
  enum { M = 9, N = 7, T = 60 };
  fcm_index ti[T], tj[T];
  double tv[T], dense[M][N] = {{0}};
  for (int t = 0; t < T; t++) {
    ti[t] = (fcm_index)((rng_uniform(r) + 1.0) * 0.5 * M);
    tj[t] = (fcm_index)((rng_uniform(r) + 1.0) * 0.5 * N);
    tv[t] = rng_uniform(r);
    dense[ti[t]][tj[t]] += tv[t];
  }
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, M, N, T, ti, tj, tv, FCM_CSR_GENERAL, &A));
  fcm_index nr, nc, nnz;
  fcm_csr_get_size(A, &nr, &nc, &nnz);
  TEST_TRUE(nr == M && nc == N && nnz <= T && nnz > 0);
  TEST_TRUE(fcm_csr_get_kind(A) == FCM_CSR_GENERAL);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  double *v = fcm_csr_values(A);
  /* Every stored entry equals the dense sum; every dense non-zero is stored. */
  fcm_index stored = 0;
  for (int i = 0; i < M; i++)
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++) {
      TEST_TRUE(p == rp[i] || ci[p] > ci[p - 1]);
      TEST_NEAR(v[p], dense[i][ci[p]], 0.0, 1e-15);
      TEST_TRUE(fcm_csr_position(A, i, ci[p]) == p);
      stored++;
    }
  for (int i = 0; i < M; i++)
    for (int j = 0; j < N; j++)
      if (dense[i][j] != 0.0) TEST_TRUE(fcm_csr_position(A, i, j) >= 0);
  TEST_TRUE(stored == nnz);
  TEST_TRUE(fcm_csr_position(A, -1, 0) == -1 && fcm_csr_position(A, M, 0) == -1);
  TEST_TRUE(fcm_csr_position(A, 0, N) == -1);

  /* y = 0.5 A x - 2 y, and beta = 0 ignores a NaN-filled y. */
  double x[N], y[M], yref[M];
  for (int j = 0; j < N; j++)
    x[j] = rng_uniform(r);
  for (int i = 0; i < M; i++) {
    y[i] = rng_uniform(r);
    double s = 0.0;
    for (int j = 0; j < N; j++)
      s += dense[i][j] * x[j];
    yref[i] = 0.5 * s - 2.0 * y[i];
  }
  TEST_OK(ctx, fcm_csr_apply(A, 0.5, x, -2.0, y));
  for (int i = 0; i < M; i++)
    TEST_NEAR(y[i], yref[i], 0.0, 1e-14);
  for (int i = 0; i < M; i++)
    y[i] = NAN;
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, x, 0.0, y));
  for (int i = 0; i < M; i++) {
    double s = 0.0;
    for (int j = 0; j < N; j++)
      s += dense[i][j] * x[j];
    TEST_NEAR(y[i], s, 0.0, 1e-14);
  }
  TEST_ERR(ctx, fcm_csr_apply(A, 1.0, NULL, 0.0, y), FCM_ERR_ARG, "x or y is NULL");
  double asym;
  TEST_ERR(ctx, fcm_csr_asymmetry(A, &asym), FCM_ERR_ARG, "9 x 7, not square");

  /* Same matrix around the caller's arrays (borrowed): same product, values shared. */
  fcm_index rp2[M + 1];
  int *ci2 = malloc((size_t)nnz * sizeof *ci2);
  double *v2 = malloc((size_t)nnz * sizeof *v2);
  for (int i = 0; i <= M; i++)
    rp2[i] = rp[i];
  for (fcm_index p = 0; p < nnz; p++)
    ci2[p] = ci[p], v2[p] = v[p];
  fcm_csr *W = NULL;
  TEST_OK(ctx, fcm_csr_wrap(ctx, M, N, rp2, ci2, v2, FCM_CSR_GENERAL, &W));
  TEST_TRUE(fcm_csr_values(W) == v2 && fcm_csr_col_idx(W) == ci2);
  double yw[M];
  TEST_OK(ctx, fcm_csr_apply(W, 1.0, x, 0.0, yw));
  for (int i = 0; i < M; i++)
    TEST_TRUE(yw[i] == y[i]);
  fcm_csr_set_zero(W);
  TEST_TRUE(v2[0] == 0.0 && v2[nnz - 1] == 0.0);
  fcm_csr_destroy(&W);
  TEST_TRUE(W == NULL);
  free(ci2), free(v2); /* still ours: destroy did not free them (ASan would see a double free) */

  fcm_csr_set_zero(A);
  for (fcm_index p = 0; p < nnz; p++)
    TEST_TRUE(v[p] == 0.0);
  fcm_csr_destroy(&A);
  fcm_csr_destroy(&A); /* NULL is fine */
  fcm_csr_destroy(NULL);
}

static void test_validation(fcm_ctx *ctx)
{
  fcm_csr *A = NULL;
  const fcm_index rp_ok[4] = {0, 2, 3, 5};
  const int ci_ok[5] = {0, 1, 1, 0, 2};
  const fcm_index rp_bad0[4] = {1, 2, 3, 5}, rp_dec[4] = {0, 3, 2, 5};
  const int ci_range[5] = {0, 1, 1, 0, 3}, ci_unsorted[5] = {1, 0, 1, 0, 2},
            ci_dup[5] = {0, 1, 1, 2, 2};
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_bad0, ci_ok, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "row_ptr[0] = 1 must be 0");
  TEST_TRUE(A == NULL);
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_dec, ci_ok, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "row_ptr[2] = 2 is less than row_ptr[1] = 3");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_ok, ci_range, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "row 2: column index 3 out of range [0, 3)");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_ok, ci_unsorted, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "row 0: column 0 follows column 1");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_ok, ci_dup, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "row 2: column 2 follows column 2");
  /* (0,1) is stored but (1,0) is not. */
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_ok, ci_ok, FCM_CSR_SYMMETRIC, &A), FCM_ERR_ARG,
           "has entry (0, 1) but not (1, 0)");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 4, rp_ok, ci_ok, FCM_CSR_SYMMETRIC, &A), FCM_ERR_ARG,
           "must be square, got 3 x 4");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, (fcm_index)INT_MAX + 1, rp_ok, ci_ok, FCM_CSR_GENERAL, &A),
           FCM_ERR_UNSUPPORTED, "exceeds the column index range");
  TEST_ERR(ctx, fcm_csr_create(ctx, -1, 3, rp_ok, ci_ok, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "must be non-negative");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_ok, ci_ok, (fcm_csr_kind)7, &A), FCM_ERR_ARG,
           "kind = 7");
  TEST_ERR(ctx, fcm_csr_create(ctx, 3, 3, rp_ok, NULL, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "col_idx is NULL");
  TEST_ERR(ctx, fcm_csr_wrap(ctx, 3, 3, rp_ok, ci_range, (double[5]){0}, FCM_CSR_GENERAL, &A),
           FCM_ERR_ARG, "column index 3 out of range");
  TEST_ERR(ctx, fcm_csr_wrap(ctx, 3, 3, rp_ok, ci_ok, NULL, FCM_CSR_GENERAL, &A), FCM_ERR_ARG,
           "values is NULL");
  const fcm_index ti[2] = {0, 3}, tj[2] = {0, 0};
  TEST_ERR(ctx, fcm_csr_create_triplets(ctx, 3, 3, 2, ti, tj, NULL, FCM_CSR_GENERAL, &A),
           FCM_ERR_ARG, "triplet 1 at (3, 0) is outside 3 x 3");
  TEST_TRUE(A == NULL);
  /* An empty matrix is fine; so is a 0 x 0 one. */
  const fcm_index rp0[4] = {0, 0, 0, 0};
  TEST_OK(ctx, fcm_csr_create(ctx, 3, 3, rp0, NULL, FCM_CSR_SYMMETRIC, &A));
  double x[3] = {1, 2, 3}, y[3] = {1, 1, 1};
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, x, 0.0, y));
  TEST_TRUE(y[0] == 0.0 && y[2] == 0.0);
  fcm_csr_destroy(&A);
  TEST_OK(ctx, fcm_csr_create(ctx, 0, 0, rp0, NULL, FCM_CSR_GENERAL, &A));
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, NULL, 0.0, NULL));
  fcm_csr_destroy(&A);
}

static void test_large(fcm_ctx *ctx, rng *r)
{
  /* 30^3 Laplacian: nnz ~ 1.9e5, above the parallel threshold. */
  const int g = 30;
  const fcm_index n = (fcm_index)g * g * g, tmax = 7 * n;
  fcm_index *ti = malloc((size_t)tmax * sizeof *ti), *tj = malloc((size_t)tmax * sizeof *tj);
  double *tv = malloc((size_t)tmax * sizeof *tv);
  fcm_index nt = laplacian_triplets(g, ti, tj, tv);
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, n, n, nt, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
  fcm_index nnz;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  TEST_TRUE(nnz == nt && nnz >= 32768);
  double asym = -1.0;
  TEST_OK(ctx, fcm_csr_asymmetry(A, &asym));
  TEST_TRUE(asym == 0.0);
  double *x = malloc((size_t)n * sizeof *x), *y = malloc((size_t)n * sizeof *y);
  double *yref = malloc((size_t)n * sizeof *yref);
  for (fcm_index i = 0; i < n; i++)
    x[i] = rng_uniform(r), y[i] = yref[i] = rng_uniform(r);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  const double *v = fcm_csr_values(A);
  for (fcm_index i = 0; i < n; i++) {
    double s = 0.0;
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      s += v[p] * x[ci[p]];
    yref[i] = 2.0 * s + 0.25 * yref[i];
  }
  TEST_OK(ctx, fcm_csr_apply(A, 2.0, x, 0.25, y));
  fcm_index mismatches = 0;
  for (fcm_index i = 0; i < n; i++)
    mismatches += (y[i] != yref[i]);
  TEST_TRUE(mismatches == 0); /* same summation order in every thread layout */
  /* Row sums of the Laplacian: 6 - (number of neighbours) >= 0; A * ones. */
  for (fcm_index i = 0; i < n; i++)
    x[i] = 1.0;
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, x, 0.0, y));
  TEST_TRUE(y[0] == 3.0 && y[15 + g * (15 + g * 15)] == 0.0);
  /* A perturbed mirror entry shows in the asymmetry. */
  double *vw = fcm_csr_values(A);
  fcm_index p01 = fcm_csr_position(A, 0, 1);
  TEST_TRUE(p01 >= 0);
  vw[p01] = -1.5;
  TEST_OK(ctx, fcm_csr_asymmetry(A, &asym));
  TEST_NEAR(asym, 0.5 / 6.0, 1e-15, 0.0);
  fcm_csr_destroy(&A);
  free(ti), free(tj), free(tv), free(x), free(y), free(yref);
}

typedef struct triplets_case {
  fcm_ctx *ctx;
  fcm_csr *A;
} triplets_case;

static fcm_status create_triplets(void *user)
{
  triplets_case *c = user;
  const fcm_index ti[5] = {0, 1, 1, 2, 0}, tj[5] = {0, 1, 0, 2, 1};
  const double tv[5] = {1, 2, 3, 4, 5};
  fcm_status st = fcm_csr_create_triplets(c->ctx, 3, 3, 5, ti, tj, tv, FCM_CSR_SYMMETRIC, &c->A);
  if (st == FCM_OK) TEST_TRUE(fcm_csr_values(c->A)[fcm_csr_position(c->A, 0, 1)] == 5.0);
  return st != FCM_OK && c->A ? FCM_ERR_INTERNAL : st;
}

static void destroy_triplets(void *user)
{
  fcm_csr_destroy(&((triplets_case *)user)->A);
}

static void test_alloc(void)
{
  failing f;
  triplets_case c = {failing_ctx(&f), NULL};
  alloc_loop(c.ctx, &f, "fcm_csr_create_triplets", create_triplets, destroy_triplets, &c, 5, 40);
  fcm_ctx_destroy(&c.ctx);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {55};
  test_small(ctx, &r);
  test_validation(ctx);
  test_large(ctx, &r);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  test_alloc();
  return TEST_RESULT();
}
