/* Sparse direct solvers: CHOLMOD solves the 20^3 7-point Laplacian to a relative
 * residual of 1e-10 and refactors new values of the same pattern without a new
 * analysis (info.analyses == 1); an indefinite symmetric matrix makes CHOLMOD fail
 * with FCM_ERR_SINGULAR naming a column, after which UMFPACK solves it; UMFPACK
 * solves an unsymmetric system and reports singular ones; phase and argument
 * errors; NaN values; x == b. A caller with one OpenMP thread gets no other thread from
 * CHOLMOD's factorization, and its OpenMP dynamic-adjustment setting back. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

#include <omp.h>
#include <stdio.h>

enum { G = 20 };

/* 7-point stencil on a G^3 grid: diag d, off-diagonals -1 - skew (x direction
 * forward) and -1 + skew (x backward); skew = 0 gives a symmetric matrix. */
static fcm_csr *grid_matrix(fcm_ctx *ctx, double d, double skew, fcm_csr_kind kind)
{
  const fcm_index n = (fcm_index)G * G * G;
  fcm_index *ti = malloc((size_t)(7 * n) * sizeof *ti), *tj = malloc((size_t)(7 * n) * sizeof *tj);
  double *tv = malloc((size_t)(7 * n) * sizeof *tv);
  fcm_index t = 0;
  for (int z = 0; z < G; z++)
    for (int y = 0; y < G; y++)
      for (int x = 0; x < G; x++) {
        fcm_index i = x + (fcm_index)G * (y + (fcm_index)G * z);
        ti[t] = i, tj[t] = i, tv[t++] = d;
        const int nb[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
        for (int k = 0; k < 6; k++) {
          int xx = x + nb[k][0], yy = y + nb[k][1], zz = z + nb[k][2];
          if (xx < 0 || yy < 0 || zz < 0 || xx >= G || yy >= G || zz >= G) continue;
          ti[t] = i, tj[t] = xx + (fcm_index)G * (yy + (fcm_index)G * zz);
          tv[t++] = -1.0 + (k == 0 ? skew : k == 1 ? -skew : 0.0);
        }
      }
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, n, n, t, ti, tj, tv, kind, &A));
  free(ti), free(tj), free(tv);
  return A;
}

/* ||A x - b||_inf / (||A||_inf-ish ||x||_inf + ||b||_inf). */
static double rel_residual(const fcm_csr *A, const double *x, const double *b)
{
  fcm_index n;
  fcm_csr_get_size(A, &n, NULL, NULL);
  double *r = malloc((size_t)n * sizeof *r), rmax = 0.0, bmax = 0.0, xmax = 0.0;
  for (fcm_index i = 0; i < n; i++)
    r[i] = b[i];
  fcm_csr_apply(A, 1.0, x, -1.0, r);
  for (fcm_index i = 0; i < n; i++) {
    rmax = fmax(rmax, fabs(r[i]));
    bmax = fmax(bmax, fabs(b[i]));
    xmax = fmax(xmax, fabs(x[i]));
  }
  free(r);
  return rmax / (bmax + 12.0 * xmax);
}

static void test_spd(fcm_ctx *ctx, rng *r)
{
  fcm_csr *A = grid_matrix(ctx, 6.0, 0.0, FCM_CSR_SYMMETRIC);
  fcm_index n, nnz;
  fcm_csr_get_size(A, &n, NULL, &nnz);
  double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
  for (fcm_index i = 0; i < n; i++)
    b[i] = rng_uniform(r);

  fcm_direct *s = NULL;
  fcm_direct_info info;
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
  TEST_ERR(ctx, fcm_direct_factor(s, fcm_csr_values(A)), FCM_ERR_ARG, "not analyzed");
  TEST_ERR(ctx, fcm_direct_solve(s, b, x), FCM_ERR_ARG, "no valid factorization");
  TEST_OK(ctx, fcm_direct_analyze(s));
  TEST_OK(ctx, fcm_direct_analyze(s)); /* no-op */
  TEST_OK(ctx, fcm_direct_factor(s, fcm_csr_values(A)));
  TEST_OK(ctx, fcm_direct_solve(s, b, x));
  TEST_TRUE(rel_residual(A, x, b) <= 1e-10);
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.factor_nnz > (double)nnz / 2); /* fill-in: L has more than A's lower half */
  TEST_TRUE(info.rcond > 0.0 && info.rcond <= 1.0);

  /* New values, same pattern: A' = 2 A + I. The analysis is reused. */
  double *v = fcm_csr_values(A);
  const fcm_index *rp = fcm_csr_row_ptr(A);
  const int *ci = fcm_csr_col_idx(A);
  for (fcm_index i = 0; i < n; i++)
    for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
      v[p] = 2.0 * v[p] + (ci[p] == i ? 1.0 : 0.0);
  TEST_OK(ctx, fcm_direct_factor(s, v));
  for (fcm_index i = 0; i < n; i++)
    x[i] = b[i];
  TEST_OK(ctx, fcm_direct_solve(s, x, x)); /* in place */
  TEST_TRUE(rel_residual(A, x, b) <= 1e-10);
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.analyses == 1 && info.factorizations == 2 && info.solves == 2);
  TEST_TRUE(info.failed_column == -1);
  TEST_TRUE(info.time_analyze >= 0.0 && info.time_factor > 0.0 && info.time_solve > 0.0);

  /* NaN in the values. */
  double keep = v[rp[5] + 1];
  v[rp[5] + 1] = NAN;
  TEST_ERR(ctx, fcm_direct_factor(s, v), FCM_ERR_NUMERIC, "matrix entry (5, ");
  TEST_ERR(ctx, fcm_direct_solve(s, b, x), FCM_ERR_ARG, "no valid factorization");
  v[rp[5] + 1] = keep;

  /* Indefinite: shift the diagonal by -10.1 (the spectrum of 2A+I lies in (1, 25)). */
  for (fcm_index i = 0; i < n; i++)
    v[fcm_csr_position(A, i, i)] -= 10.1;
  TEST_ERR(ctx, fcm_direct_factor(s, v), FCM_ERR_SINGULAR,
           "not positive definite (pivot of column");
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.failed_column >= 0 && info.failed_column < n);
  TEST_TRUE(info.factorizations == 4 && info.analyses == 1);
  TEST_ERR(ctx, fcm_direct_solve(s, b, x), FCM_ERR_ARG, "no valid factorization");

  /* The caller falls back to UMFPACK for the same matrix. */
  fcm_direct *u = NULL;
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_UMFPACK, A, &u));
  TEST_OK(ctx, fcm_direct_analyze(u));
  TEST_OK(ctx, fcm_direct_factor(u, v));
  TEST_OK(ctx, fcm_direct_solve(u, b, x));
  TEST_TRUE(rel_residual(A, x, b) <= 1e-10);
  fcm_direct_destroy(&u);

  /* CHOLMOD recovers with positive definite values after the failure. */
  for (fcm_index i = 0; i < n; i++)
    v[fcm_csr_position(A, i, i)] += 10.1;
  TEST_OK(ctx, fcm_direct_factor(s, v));
  TEST_OK(ctx, fcm_direct_solve(s, b, x));
  TEST_TRUE(rel_residual(A, x, b) <= 1e-10);
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.analyses == 1 && info.failed_column == -1);
  fcm_direct_destroy(&s);
  TEST_TRUE(s == NULL);
  fcm_direct_destroy(&s);
  fcm_csr_destroy(&A);
  free(b), free(x);
}

static void test_unsymmetric(fcm_ctx *ctx, rng *r)
{
  fcm_csr *A = grid_matrix(ctx, 6.0, 0.4, FCM_CSR_GENERAL);
  fcm_index n;
  fcm_csr_get_size(A, &n, NULL, NULL);
  double asym;
  TEST_OK(ctx, fcm_csr_asymmetry(A, &asym));
  TEST_TRUE(asym > 0.1);
  double *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x);
  for (fcm_index i = 0; i < n; i++)
    b[i] = rng_uniform(r);
  fcm_direct *s = NULL;
  TEST_ERR(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s), FCM_ERR_ARG,
           "cholmod needs an FCM_CSR_SYMMETRIC matrix");
  TEST_TRUE(s == NULL);
  TEST_ERR(ctx, fcm_direct_create(ctx, (fcm_direct_method)9, A, &s), FCM_ERR_UNSUPPORTED,
           "unknown method 9");
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_UMFPACK, A, &s));
  TEST_OK(ctx, fcm_direct_analyze(s));
  for (int rep = 0; rep < 2; rep++) {
    TEST_OK(ctx, fcm_direct_factor(s, fcm_csr_values(A)));
    TEST_OK(ctx, fcm_direct_solve(s, b, x));
    TEST_TRUE(rel_residual(A, x, b) <= 1e-10);
  }
  /* The transpose is not what was solved: A^T x != b (guards the CSR/CSC reading). */
  {
    fcm_index nn = n;
    double *y = malloc((size_t)nn * sizeof *y), d = 0.0;
    const fcm_index *rp = fcm_csr_row_ptr(A);
    const int *ci = fcm_csr_col_idx(A);
    const double *v = fcm_csr_values(A);
    for (fcm_index i = 0; i < nn; i++)
      y[i] = -b[i];
    for (fcm_index i = 0; i < nn; i++)
      for (fcm_index p = rp[i]; p < rp[i + 1]; p++)
        y[ci[p]] += v[p] * x[i];
    for (fcm_index i = 0; i < nn; i++)
      d = fmax(d, fabs(y[i]));
    TEST_TRUE(d > 1e-3);
    free(y);
  }
  fcm_direct_info info;
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.analyses == 1 && info.factorizations == 2 && info.solves == 2);
  TEST_TRUE(info.factor_nnz > 0.0 && info.rcond > 0.0);
  fcm_direct_destroy(&s);
  fcm_csr_destroy(&A);
  free(b), free(x);
}

static void test_singular(fcm_ctx *ctx)
{
  /* 4 x 4 with row 2 stored but all zero: exactly singular. */
  const fcm_index rp[5] = {0, 2, 4, 6, 8};
  const int ci[8] = {0, 1, 0, 1, 2, 3, 2, 3};
  double v[8] = {4, 1, 1, 3, 0, 0, 1, 2};
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_wrap(ctx, 4, 4, rp, ci, v, FCM_CSR_GENERAL, &A));
  fcm_direct *s = NULL;
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_UMFPACK, A, &s));
  TEST_OK(ctx, fcm_direct_analyze(s));
  TEST_ERR(ctx, fcm_direct_factor(s, v), FCM_ERR_SINGULAR,
           "umfpack factor: matrix is singular (zero pivot at row 2,");
  fcm_direct_info info;
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.failed_column >= 2 && info.failed_column <= 3);
  double b[4] = {1, 1, 1, 1}, x[4];
  TEST_ERR(ctx, fcm_direct_solve(s, b, x), FCM_ERR_ARG, "no valid factorization");
  /* Row 2 = row 3 (exactly dependent) is singular too; a regular matrix then works. */
  v[4] = 1, v[5] = 2;
  TEST_ERR(ctx, fcm_direct_factor(s, v), FCM_ERR_SINGULAR, "matrix is singular");
  v[4] = 5, v[5] = 2;
  TEST_OK(ctx, fcm_direct_factor(s, v));
  TEST_OK(ctx, fcm_direct_solve(s, b, x));
  TEST_NEAR(4 * x[0] + x[1], 1.0, 0.0, 1e-14);
  TEST_NEAR(x[0] + 3 * x[1], 1.0, 0.0, 1e-14);
  TEST_NEAR(5 * x[2] + 2 * x[3], 1.0, 0.0, 1e-14);
  TEST_NEAR(x[2] + 2 * x[3], 1.0, 0.0, 1e-14);
  fcm_direct_destroy(&s);
  fcm_csr_destroy(&A);

  /* A 0 x 0 system goes through every phase. */
  const fcm_index rp0[1] = {0};
  TEST_OK(ctx, fcm_csr_create(ctx, 0, 0, rp0, NULL, FCM_CSR_SYMMETRIC, &A));
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
  TEST_OK(ctx, fcm_direct_analyze(s));
  TEST_OK(ctx, fcm_direct_factor(s, NULL));
  TEST_OK(ctx, fcm_direct_solve(s, NULL, NULL));
  fcm_direct_destroy(&s);
  fcm_csr_destroy(&A);
  TEST_TRUE(!strcmp(fcm_direct_method_name(FCM_DIRECT_UMFPACK), "umfpack"));
  TEST_TRUE(!strcmp(fcm_direct_method_name((fcm_direct_method)5), "unknown"));
}

/* CHOLMOD names the failing column: a 1-D Laplacian (n = 12) in which column 7
 * is decoupled and has a negative diagonal; everything else is positive definite. */
static void test_failed_column(fcm_ctx *ctx)
{
  enum { N = 12, BAD = 7 };
  fcm_index ti[3 * N], tj[3 * N];
  double tv[3 * N];
  int t = 0;
  for (int i = 0; i < N; i++) {
    ti[t] = i, tj[t] = i, tv[t++] = (i == BAD) ? -2.0 : 2.0;
    if (i > 0 && i != BAD && i - 1 != BAD) ti[t] = i, tj[t] = i - 1, tv[t++] = -1.0;
    if (i + 1 < N && i != BAD && i + 1 != BAD) ti[t] = i, tj[t] = i + 1, tv[t++] = -1.0;
  }
  fcm_csr *A = NULL;
  fcm_direct *s = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, N, N, t, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
  TEST_OK(ctx, fcm_direct_analyze(s));
  TEST_ERR(ctx, fcm_direct_factor(s, fcm_csr_values(A)), FCM_ERR_SINGULAR,
           "not positive definite (pivot of column 7, n = 12)");
  fcm_direct_info info;
  fcm_direct_get_info(s, &info);
  TEST_TRUE(info.failed_column == BAD);
  fcm_direct_destroy(&s);
  fcm_csr_destroy(&A);
}

/* Fail each of our allocations in turn through create, analyze, factor, solve. */
static void test_alloc(fcm_direct_method method)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  /* 1-D Laplacian, n = 50, symmetric. */
  enum { N = 50 };
  fcm_index ti[3 * N], tj[3 * N];
  double tv[3 * N], b[N], x[N];
  int t = 0;
  for (int i = 0; i < N; i++) {
    ti[t] = i, tj[t] = i, tv[t++] = 2.0;
    if (i > 0) ti[t] = i, tj[t] = i - 1, tv[t++] = -1.0;
    if (i + 1 < N) ti[t] = i, tj[t] = i + 1, tv[t++] = -1.0;
    b[i] = 1.0;
  }
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, N, N, t, ti, tj, tv, FCM_CSR_SYMMETRIC, &A));
  long long base = fcm_ctx_live_allocations(ctx);
  int ok = 0, failures = 0;
  for (long long k = 0; k < 60 && !ok; k++) {
    f.count = 0;
    f.fail_at = k;
    fcm_direct *s = NULL;
    fcm_status st = fcm_direct_create(ctx, method, A, &s);
    if (st == FCM_OK) st = fcm_direct_analyze(s);
    if (st == FCM_OK) st = fcm_direct_factor(s, fcm_csr_values(A));
    if (st == FCM_OK) st = fcm_direct_solve(s, b, x);
    f.fail_at = -1;
    if (st == FCM_OK) {
      ok = 1;
      /* exact solution of the 1-D Laplacian with unit load: x_i = (i+1)(N-i)/2 */
      for (int i = 0; i < N; i++)
        TEST_NEAR(x[i], 0.5 * (i + 1) * (N - i), 1e-12, 0.0);
      /* Further factorizations and solves allocate nothing through the ctx. */
      long long before = f.count;
      TEST_OK(ctx, fcm_direct_factor(s, fcm_csr_values(A)));
      TEST_OK(ctx, fcm_direct_solve(s, b, x));
      TEST_OK(ctx, fcm_direct_solve(s, x, x));
      TEST_TRUE(f.count == before);
    } else {
      failures++;
      TEST_TRUE(st == FCM_ERR_ALLOC);
      TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "out of memory") != NULL);
      fcm_ctx_error_clear(ctx);
    }
    fcm_direct_destroy(&s);
    TEST_TRUE(fcm_ctx_live_allocations(ctx) == base);
  }
  TEST_TRUE(ok && failures >= 3);
  fcm_csr_destroy(&A);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
}

/* The threads of this process (Linux: /proc/self/status), -1 when unknown. */
static int process_threads(void)
{
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  int n = -1;
  if (!f) return -1;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, "Threads: %d", &n) == 1) break;
  fclose(f);
  return n;
}

/* CHOLMOD runs loops of its factorization in OpenMP teams of a size fixed when it was built
 * (4 in Debian's SuiteSparse 5); fcm lets the runtime fit them to the caller's thread count.
 * Called first, before any OpenMP team of this process: with one OpenMP thread the process
 * has no more threads after factorizations of the 20^3 Laplacian than before them (the BLAS
 * may have its own), and the caller's dynamic-adjustment setting (off, then on) is as it
 * was. */
static void test_threads(fcm_ctx *ctx)
{
  const int before = omp_get_max_threads(), dynamic = omp_get_dynamic();
  const int base = process_threads();
  omp_set_num_threads(1);
  for (int dyn = 0; dyn <= 1; dyn++) {
    omp_set_dynamic(dyn);
    fcm_csr *A = grid_matrix(ctx, 6.0, 0.0, FCM_CSR_SYMMETRIC);
    fcm_direct *s = NULL;
    TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, A, &s));
    TEST_OK(ctx, fcm_direct_analyze(s));
    TEST_OK(ctx, fcm_direct_factor(s, fcm_csr_values(A)));
    TEST_TRUE(omp_get_dynamic() == dyn);
    TEST_TRUE(process_threads() == base);
    fcm_direct_destroy(&s);
    fcm_csr_destroy(&A);
  }
  omp_set_dynamic(dynamic);
  omp_set_num_threads(before);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {8675309};
  test_threads(ctx);
  test_spd(ctx, &r);
  test_unsymmetric(ctx, &r);
  test_singular(ctx);
  test_failed_column(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  test_alloc(FCM_DIRECT_CHOLMOD);
  test_alloc(FCM_DIRECT_UMFPACK);
  return TEST_RESULT();
}
