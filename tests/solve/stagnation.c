/* CG and MINRES on a singular positive semi-definite system: the graph Laplacian of an
 * N^3 grid (free boundary; its null space is exactly the constant vectors).
 * 1. b with a constant part (not in the range): with a stagnation window both methods stop
 *    with FCM_KRYLOV_STAGNATED and FCM_ERR_NOT_CONVERGED whose message says so, long before
 *    max_iterations; no residual can go below the constant part of b (the least-squares
 *    floor), and MINRES, which minimizes the residual, stops within 0.1 % of it. With
 *    Jacobi preconditioning too (CG), and the same with the window off: MINRES runs into
 *    max_iterations instead.
 * 2. b in the range (mean zero): both converge to rtol with the window on (no false alarm).
 * 3. A negative window is refused naming the option. */
#include "solve_test_util.h"

/* Graph Laplacian of the N^3 grid: degree on the diagonal, -1 to each grid neighbour. */
static fcm_status neumann3d(fcm_ctx *ctx, int N, fcm_csr **A)
{
  fcm_index n = (fcm_index)N * N * N, cap = 7 * n, nt = 0;
  fcm_index *ri = malloc(sizeof *ri * (size_t)cap), *ci = malloc(sizeof *ci * (size_t)cap);
  double *v = malloc(sizeof *v * (size_t)cap);
  for (int k = 0; k < N; k++)
    for (int j = 0; j < N; j++)
      for (int i = 0; i < N; i++) {
        const fcm_index r = i + (fcm_index)N * (j + (fcm_index)N * k), diag = nt++;
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                              {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        int deg = 0;
        for (int q = 0; q < 6; q++) {
          if (nb[q][0] < 0 || nb[q][0] >= N || nb[q][1] < 0 || nb[q][1] >= N || nb[q][2] < 0 ||
              nb[q][2] >= N)
            continue;
          ri[nt] = r, ci[nt] = nb[q][0] + (fcm_index)N * (nb[q][1] + (fcm_index)N * nb[q][2]);
          v[nt++] = -1.0;
          deg++;
        }
        ri[diag] = r, ci[diag] = r, v[diag] = deg;
      }
  fcm_status st = fcm_csr_create_triplets(ctx, n, n, nt, ri, ci, v, FCM_CSR_SYMMETRIC, A);
  free(ri);
  free(ci);
  free(v);
  return st;
}

typedef fcm_status (*method_fn)(fcm_krylov *, fcm_operator_fn, void *, fcm_operator_fn, void *,
                                const double *, double *, const fcm_krylov_options *,
                                fcm_krylov_info *);

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_csr *A = NULL;
  fcm_krylov *ws = NULL;
  fcm_jacobi *J = NULL;
  const int N = 8;
  const fcm_index n = (fcm_index)N * N * N;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, neumann3d(ctx, N, &A));
  TEST_OK(ctx, fcm_krylov_create(ctx, n, &ws));
  TEST_OK(ctx, fcm_jacobi_create(ctx, A, FCM_JACOBI_SCALAR, &J));
  double *b = malloc(sizeof *b * (size_t)n), *b0 = malloc(sizeof *b0 * (size_t)n);
  double *x = malloc(sizeof *x * (size_t)n);
  rng r = {7};
  double mean = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    b0[i] = rng_uniform(&r) - 0.5;
    mean += b0[i] / (double)n;
  }
  for (fcm_index i = 0; i < n; i++)
    b0[i] -= mean; /* in the range: orthogonal to the constants */
  for (fcm_index i = 0; i < n; i++)
    b[i] = b0[i] + 0.3; /* plus a constant part: inconsistent */
  /* the least-squares floor ||P_null b|| / ||b|| (2-norm; CG monitors it unpreconditioned) */
  const double floor2 = 0.3 * sqrt((double)n) / norm2(b, n);

  const method_fn methods[2] = {fcm_krylov_cg, fcm_krylov_minres};
  const char *names[2] = {"cg", "minres"};
  for (int m = 0; m < 2; m++)
    for (int pc = 0; pc < 2; pc++) {
      fcm_operator_fn S = pc ? fcm_jacobi_operator : NULL;
      fcm_krylov_options o = fcm_krylov_options_default();
      fcm_krylov_info info;
      o.stagnation_window = 20;
      o.record_history = 1;
      /* 1. inconsistent: stagnation */
      memset(x, 0, sizeof *x * (size_t)n);
      TEST_ERR(ctx, methods[m](ws, fcm_csr_operator, A, S, J, b, x, &o, &info),
               FCM_ERR_NOT_CONVERGED, "stagnated");
      if (info.reason != FCM_KRYLOV_STAGNATED || info.iterations >= o.max_iterations / 2)
        TEST_FAIL_("%s (pc %d): reason %s after %d iterations", names[m], pc,
                   fcm_krylov_reason_name(info.reason), info.iterations);
      TEST_TRUE(info.iterations % o.stagnation_window == 0);
      double best = HUGE_VAL;
      for (int k = 0; k < info.history_length; k++)
        best = info.history[k] < best ? info.history[k] : best;
      if (S == NULL) {
        /* no residual below the floor; MINRES (monotone) ends within 0.1 % of it */
        if (!(best >= floor2 * (1 - 1e-9)))
          TEST_FAIL_("%s: residual %.6e below the least-squares floor %.6e", names[m], best,
                     floor2);
        if (m == 1) TEST_NEAR(info.relative_residual, floor2, 1e-3, 0.0);
      }
      /* the window off: MINRES goes on to max_iterations (CG breaks down or hits it) */
      o.stagnation_window = 0;
      o.max_iterations = 300;
      memset(x, 0, sizeof *x * (size_t)n);
      fcm_status st = methods[m](ws, fcm_csr_operator, A, S, J, b, x, &o, &info);
      TEST_TRUE(st == FCM_ERR_NOT_CONVERGED && info.reason != FCM_KRYLOV_STAGNATED);
      if (m == 1) TEST_TRUE(info.reason == FCM_KRYLOV_MAX_ITERATIONS && info.iterations == 300);
      fcm_ctx_error_clear(ctx);
      /* 2. consistent: converges with the window on */
      o = fcm_krylov_options_default();
      o.stagnation_window = 20;
      o.check_true_residual = 1;
      memset(x, 0, sizeof *x * (size_t)n);
      TEST_OK(ctx, methods[m](ws, fcm_csr_operator, A, S, J, b0, x, &o, &info));
      TEST_TRUE(info.reason == FCM_KRYLOV_CONVERGED_RTOL && info.true_residual < 1e-6);
    }
  /* 3. option check */
  {
    fcm_krylov_options o = fcm_krylov_options_default();
    o.stagnation_window = -1;
    TEST_TRUE(o.stagnation_window == -1 && fcm_krylov_options_default().stagnation_window == 0);
    TEST_ERR(ctx, fcm_krylov_cg(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, NULL), FCM_ERR_ARG,
             "stagnation_window = -1");
    TEST_TRUE(!strcmp(fcm_krylov_reason_name(FCM_KRYLOV_STAGNATED), "stagnated"));
  }
  free(b);
  free(b0);
  free(x);
  fcm_jacobi_destroy(&J);
  fcm_krylov_destroy(&ws);
  fcm_csr_destroy(&A);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
