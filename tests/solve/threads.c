/* Thread-count independence on vectors long enough for the parallel paths (n = 17,576):
 * MINRES with overlapping Schwarz blocks and without a preconditioner on the indefinite
 * shifted Laplacian, and the Schwarz apply, give bitwise identical results (iterates and
 * histories of 80 iterations) on 1, 2 and 3 threads; the monitored norms decrease. */
#include "solve_test_util.h"

#include <omp.h>

#define N 26

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_csr *A = NULL;
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  const fcm_index n = (fcm_index)N * N * N;
  TEST_OK(ctx, laplace3d(ctx, N, 0.37, NULL, &A)); /* smallest eigenvalue ~0.03: indefinite */
  /* blocks of 3 x 3 x 3 points at a stride of 2: neighbours overlap in a plane */
  fcm_index nb = 0, *ptr = malloc(sizeof *ptr * 4000), *dofs = malloc(sizeof *dofs * 4000 * 27);
  ptr[0] = 0;
  for (int K = 0; K + 3 <= N; K += 2)
    for (int J = 0; J + 3 <= N; J += 2)
      for (int I = 0; I + 3 <= N; I += 2) {
        if ((I + J + K) % 3 == 0) continue; /* leave some points to the diagonal */
        fcm_index q = ptr[nb];
        for (int c = 0; c < 27; c++)
          dofs[q++] = (I + c % 3) + N * ((J + c / 3 % 3) + N * (K + c / 9));
        ptr[++nb] = q;
      }
  TEST_TRUE(nb < 4000);
  double *b = malloc(sizeof *b * (size_t)n), *r = malloc(sizeof *r * (size_t)n);
  rng g = {11};
  for (fcm_index i = 0; i < n; i++) {
    b[i] = rng_uniform(&g);
    r[i] = rng_uniform(&g);
  }
  enum { T = 3, MAXIT = 80 };
  double *x[T], *y[T], *z[T], *h[T];
  fcm_krylov_info ix[T], iy[T];
  for (int t = 0; t < T; t++) {
    omp_set_num_threads(t + 1);
    x[t] = calloc((size_t)n, sizeof *x[t]);
    y[t] = calloc((size_t)n, sizeof *y[t]);
    z[t] = calloc((size_t)n, sizeof *z[t]);
    h[t] = calloc(MAXIT, sizeof *h[t]);
    TEST_OK(ctx, fcm_schwarz_create(ctx, A, nb, ptr, dofs, NULL, &P));
    TEST_OK(ctx, fcm_schwarz_apply(P, r, z[t]));
    fcm_krylov_options o = fcm_krylov_options_default();
    o.max_iterations = MAXIT;
    o.record_history = 1;
    o.history = h[t];
    o.history_capacity = MAXIT;
    o.rtol = 1e-12; /* not reached: MAXIT iterations each */
    TEST_ERR(
        ctx,
        fcm_minres_solve(ctx, n, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x[t], &o, &ix[t]),
        FCM_ERR_NOT_CONVERGED, "max_iterations");
    o.record_history = 0;
    TEST_ERR(ctx, fcm_minres_solve(ctx, n, fcm_csr_operator, A, NULL, NULL, b, y[t], &o, &iy[t]),
             FCM_ERR_NOT_CONVERGED, "max_iterations");
    fcm_schwarz_destroy(&P);
  }
  TEST_TRUE(ix[0].iterations == MAXIT && iy[0].iterations == MAXIT);
  TEST_TRUE(h[0][MAXIT - 1] < 0.5 * h[0][0] && iy[0].relative_residual < 0.9);
  for (int t = 1; t < T; t++) {
    TEST_TRUE(memcmp(z[0], z[t], sizeof *z[0] * (size_t)n) == 0);
    TEST_TRUE(ix[t].iterations == ix[0].iterations && iy[t].iterations == iy[0].iterations);
    TEST_TRUE(memcmp(x[0], x[t], sizeof *x[0] * (size_t)n) == 0);
    TEST_TRUE(memcmp(y[0], y[t], sizeof *y[0] * (size_t)n) == 0);
    TEST_TRUE(memcmp(h[0], h[t], sizeof *h[0] * (size_t)ix[0].iterations) == 0);
  }
  for (int t = 0; t < T; t++) {
    free(x[t]);
    free(y[t]);
    free(z[t]);
    free(h[t]);
  }
  free(ptr);
  free(dofs);
  free(b);
  free(r);
  fcm_csr_destroy(&A);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
