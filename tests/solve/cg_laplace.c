/* CG on the 3-D Laplacian: converges to the known solution within the condition-number
 * error bound, in no more iterations than the Chebyshev bound and (small grids) than the
 * number of distinct eigenvalues; history, counters, norms,
 * warm start, one-shot form; bitwise identical results on 1 and 2 threads. */
#include "solve_test_util.h"

#include <omp.h>

static void check_solve(fcm_ctx *ctx, int N)
{
  fcm_csr *A = NULL;
  fcm_krylov *ws = NULL;
  fcm_jacobi *J = NULL;
  fcm_index n = (fcm_index)N * N * N;
  double lmin, lmax;
  laplace3d_extremes(N, &lmin, &lmax);
  const double kappa = lmax / lmin, rtol = 1e-10;
  TEST_OK(ctx, laplace3d(ctx, N, 0.0, NULL, &A));
  TEST_OK(ctx, fcm_krylov_create(ctx, n, &ws));
  double *xs = malloc(sizeof *xs * (size_t)n), *b = malloc(sizeof *b * (size_t)n);
  double *x = calloc((size_t)n, sizeof *x), *x2 = calloc((size_t)n, sizeof *x2);
  rng r = {42};
  for (fcm_index i = 0; i < n; i++)
    xs[i] = rng_uniform(&r);
  TEST_OK(ctx, fcm_csr_apply(A, 1.0, xs, 0.0, b));

  fcm_krylov_options o = fcm_krylov_options_default();
  o.rtol = rtol;
  o.record_history = 1;
  o.check_true_residual = 1;
  fcm_krylov_info info;
  TEST_OK(ctx, fcm_krylov_cg(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info));
  TEST_TRUE(info.reason == FCM_KRYLOV_CONVERGED_RTOL);
  int bound = cg_iteration_bound(kappa, rtol);
  if (!(info.iterations >= 1 && info.iterations <= bound))
    TEST_FAIL_("N = %d: %d iterations, bound %d (kappa %.1f)", N, info.iterations, bound, kappa);
  /* finite termination: at most as many iterations as distinct eigenvalues */
  int distinct = laplace3d_distinct(N);
  if (N <= 5 && info.iterations > distinct)
    TEST_FAIL_("N = %d: %d iterations > %d distinct eigenvalues", N, info.iterations, distinct);
  TEST_TRUE(info.relative_residual <= rtol);
  TEST_NEAR(info.rhs_norm, norm2(b, n), 1e-14, 0.0);
  TEST_NEAR(info.initial_residual, 1.0, 1e-15, 0.0);
  double tr = true_residual(A, b, x, n);
  TEST_NEAR(info.true_residual, tr, 1e-10, 1e-16);
  TEST_TRUE(tr <= 10 * rtol);
  /* ||x - x*|| / ||x*|| <= kappa ||b - A x|| / ||b|| */
  double err = 0.0;
  for (fcm_index i = 0; i < n; i++)
    err += (x[i] - xs[i]) * (x[i] - xs[i]);
  err = sqrt(err) / norm2(xs, n);
  if (!(err <= kappa * tr * (1 + 1e-6)))
    TEST_FAIL_("error %.3e > kappa * residual %.3e", err, kappa * tr);
  /* history: one entry per iteration, the last is the final residual */
  TEST_TRUE(info.history != NULL && info.history_length == info.iterations);
  if (info.history_length > 0)
    TEST_NEAR(info.history[info.history_length - 1], info.relative_residual, 0.0, 0.0);
  /* no wasted applications: one A per iteration (+1 for the true residual), one S per
   * iteration is not counted without a preconditioner */
  TEST_TRUE(info.operator_applications == info.iterations + 1);
  TEST_TRUE(info.preconditioner_applications == 0);

  /* one-shot form gives the same iterate bit for bit */
  fcm_krylov_options o1 = o;
  o1.record_history = 0;
  fcm_krylov_info info1;
  TEST_OK(ctx, fcm_cg_solve(ctx, n, fcm_csr_operator, A, NULL, NULL, b, x2, &o1, &info1));
  TEST_TRUE(info1.iterations == info.iterations && info1.history == NULL);
  TEST_TRUE(memcmp(x, x2, sizeof *x * (size_t)n) == 0);

  /* warm start near the solution: fewer iterations, small initial residual */
  for (fcm_index i = 0; i < n; i++)
    x2[i] = xs[i] + 1e-6 * rng_uniform(&r);
  TEST_OK(ctx, fcm_krylov_cg(ws, fcm_csr_operator, A, NULL, NULL, b, x2, &o, &info1));
  TEST_TRUE(info1.initial_residual < 1e-5 && info1.iterations <= info.iterations);
  TEST_TRUE(true_residual(A, b, x2, n) <= 10 * rtol);

  /* Jacobi (S = I/6) with the preconditioned norm: ||b||_S = ||b|| / sqrt(6); the
   * preconditioned iteration is the unpreconditioned one scaled, same count +-1 */
  TEST_OK(ctx, fcm_jacobi_create(ctx, A, FCM_JACOBI_SCALAR, &J));
  o1.norm = FCM_KRYLOV_NORM_PRECONDITIONED;
  memset(x2, 0, sizeof *x2 * (size_t)n);
  TEST_OK(ctx, fcm_krylov_cg(ws, fcm_csr_operator, A, fcm_jacobi_operator, J, b, x2, &o1, &info1));
  TEST_NEAR(info1.rhs_norm, norm2(b, n) / sqrt(6.0), 1e-13, 0.0);
  TEST_TRUE(abs(info1.iterations - info.iterations) <= 1);
  TEST_TRUE(info1.preconditioner_applications == info1.iterations + 1);
  TEST_TRUE(true_residual(A, b, x2, n) <= 10 * rtol);

  free(xs);
  free(b);
  free(x);
  free(x2);
  fcm_jacobi_destroy(&J);
  fcm_krylov_destroy(&ws);
  fcm_csr_destroy(&A);
}

/* The same solve on 1 and 2 threads (vectors long enough for the parallel paths). */
static void check_threads(fcm_ctx *ctx)
{
  const int N = 30;
  fcm_index n = (fcm_index)N * N * N;
  fcm_csr *A = NULL;
  fcm_jacobi *J = NULL;
  TEST_OK(ctx, laplace3d(ctx, N, -0.5, NULL, &A));
  TEST_OK(ctx, fcm_jacobi_create(ctx, A, FCM_JACOBI_SCALAR, &J));
  double *b = malloc(sizeof *b * (size_t)n), *x[2];
  rng r = {7};
  for (fcm_index i = 0; i < n; i++)
    b[i] = rng_uniform(&r);
  fcm_krylov_info info[2];
  fcm_krylov_options o = fcm_krylov_options_default();
  for (int t = 0; t < 2; t++) {
    omp_set_num_threads(t + 1);
    x[t] = calloc((size_t)n, sizeof *x[t]);
    TEST_OK(ctx, fcm_cg_solve(ctx, n, fcm_csr_operator, A, fcm_jacobi_operator, J, b, x[t], &o,
                              &info[t]));
  }
  TEST_TRUE(info[0].iterations == info[1].iterations);
  TEST_TRUE(info[0].residual_norm == info[1].residual_norm);
  TEST_TRUE(memcmp(x[0], x[1], sizeof *b * (size_t)n) == 0);
  free(b);
  free(x[0]);
  free(x[1]);
  fcm_jacobi_destroy(&J);
  fcm_csr_destroy(&A);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  check_solve(ctx, 3);
  check_solve(ctx, 5);
  check_solve(ctx, 12);
  check_threads(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
