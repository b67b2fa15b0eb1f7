/* Jacobi preconditioners: on a badly scaled SPD matrix D L D, CG with scalar or 3x3
 * block Jacobi needs the iterations of the unscaled L (the preconditioned spectrum does
 * not depend on D) and far fewer than plain CG; block inverses are exact; negative
 * diagonals and non-SPD blocks fall back to |diag| and are counted; bad input fails. */
#include "solve_test_util.h"

static int cg_iterations(fcm_ctx *ctx, const fcm_csr *A, fcm_jacobi *J, const double *b,
                         fcm_index n, int max_it, fcm_status *st)
{
  double *x = calloc((size_t)n, sizeof *x);
  fcm_krylov_options o = fcm_krylov_options_default();
  o.rtol = 1e-8;
  o.max_iterations = max_it;
  o.norm = FCM_KRYLOV_NORM_PRECONDITIONED; /* r^T S r: invariant under the scaling */
  fcm_krylov_info info;
  *st = fcm_cg_solve(ctx, n, fcm_csr_operator, (void *)A, J ? fcm_jacobi_operator : NULL, J, b, x,
                     &o, &info);
  fcm_ctx_error_clear(ctx);
  free(x);
  return info.iterations;
}

static void check_scaling(fcm_ctx *ctx)
{
  const int N = 9;
  const fcm_index n = N * N * N;
  fcm_csr *L = NULL, *A = NULL;
  fcm_jacobi *J[2][2] = {{NULL, NULL}, {NULL, NULL}};
  double *d = malloc(sizeof *d * (size_t)n), *b = malloc(sizeof *b * (size_t)n);
  rng r = {11};
  for (fcm_index i = 0; i < n; i++) {
    d[i] = pow(10.0, 3.0 * rng_uniform(&r)); /* 1e-3 .. 1e3 */
    b[i] = rng_uniform(&r);
  }
  TEST_OK(ctx, laplace3d(ctx, N, 0.0, NULL, &L));
  TEST_OK(ctx, laplace3d(ctx, N, 0.0, d, &A));
  int it[2][2];
  fcm_status st;
  for (int k = 0; k < 2; k++) {
    fcm_jacobi_kind kind = k ? FCM_JACOBI_BLOCK3 : FCM_JACOBI_SCALAR;
    TEST_OK(ctx, fcm_jacobi_create(ctx, L, kind, &J[k][0]));
    TEST_OK(ctx, fcm_jacobi_create(ctx, A, kind, &J[k][1]));
    TEST_TRUE(fcm_jacobi_num_fallbacks(J[k][1]) == 0);
    it[k][0] = cg_iterations(ctx, L, J[k][0], b, n, 1000, &st);
    TEST_TRUE(st == FCM_OK);
    /* the same problem in scaled coordinates: D L D x = D b has x = D^{-1} y with L y = b,
     * and the preconditioned CG iterates and S-norm residuals map one to one */
    double *bd = malloc(sizeof *bd * (size_t)n);
    for (fcm_index i = 0; i < n; i++)
      bd[i] = b[i] * d[i];
    it[k][1] = cg_iterations(ctx, A, J[k][1], bd, n, 1000, &st);
    TEST_TRUE(st == FCM_OK);
    free(bd);
    if (abs(it[k][0] - it[k][1]) > 2)
      TEST_FAIL_("jacobi kind %d: %d iterations on L, %d on D L D", k, it[k][0], it[k][1]);
  }
  double lmin, lmax;
  laplace3d_extremes(N, &lmin, &lmax);
  TEST_TRUE(it[0][0] <= cg_iteration_bound(lmax / lmin, 1e-8));
  /* plain CG on D L D: many more iterations (or none converged within 20x) */
  int plain = cg_iterations(ctx, A, NULL, b, n, 20 * it[0][1], &st);
  if (!(plain >= 5 * it[0][1]))
    TEST_FAIL_("plain CG %d iterations (%s) vs Jacobi %d", plain, fcm_status_name(st), it[0][1]);
  for (int k = 0; k < 2; k++)
    for (int q = 0; q < 2; q++)
      fcm_jacobi_destroy(&J[k][q]);
  fcm_csr_destroy(&A);
  fcm_csr_destroy(&L);
  free(d);
  free(b);
}

/* Two nodes: an SPD 3x3 block (exact inverse) and an indefinite one (fallback). */
static void check_blocks(fcm_ctx *ctx)
{
  const double B0[9] = {4, 1, 0.5, 1, 3, -1, 0.5, -1, 5};
  const double B1[9] = {1, 2, 0, 2, 1, 0, 0, 0, -4};
  fcm_index ri[18], ci[18];
  double v[18];
  for (int k = 0; k < 2; k++)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        int t = 9 * k + 3 * i + j;
        ri[t] = 3 * k + i, ci[t] = 3 * k + j, v[t] = (k ? B1 : B0)[3 * i + j];
      }
  fcm_csr *A = NULL;
  fcm_jacobi *J = NULL, *Js = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 6, 6, 18, ri, ci, v, FCM_CSR_SYMMETRIC, &A));
  TEST_OK(ctx, fcm_jacobi_create(ctx, A, FCM_JACOBI_BLOCK3, &J));
  TEST_TRUE(fcm_jacobi_num_fallbacks(J) == 1);
  TEST_OK(ctx, fcm_jacobi_create(ctx, A, FCM_JACOBI_SCALAR, &Js));
  TEST_TRUE(fcm_jacobi_num_fallbacks(Js) == 1); /* the -4 */
  double rr[6] = {1, -2, 3, 0.5, -1, 2}, z[6], y[3];
  TEST_OK(ctx, fcm_jacobi_apply(J, rr, z));
  for (int i = 0; i < 3; i++) {
    y[i] = 0.0;
    for (int j = 0; j < 3; j++)
      y[i] += B0[3 * i + j] * z[j];
    TEST_NEAR(y[i], rr[i], 1e-14, 1e-14); /* B0 z = r */
  }
  for (int i = 0; i < 3; i++)
    TEST_NEAR(z[3 + i], rr[3 + i] / fabs(B1[4 * i]), 1e-15, 0.0);
  TEST_OK(ctx, fcm_jacobi_operator(Js, rr, z));
  for (int i = 0; i < 6; i++)
    TEST_NEAR(z[i], rr[i] / fabs(v[9 * (i / 3) + 4 * (i % 3)]), 1e-15, 0.0);

  /* errors */
  fcm_jacobi *bad = NULL;
  TEST_ERR(ctx, fcm_jacobi_create(ctx, A, (fcm_jacobi_kind)7, &bad), FCM_ERR_ARG, "kind = 7");
  TEST_TRUE(bad == NULL);
  TEST_ERR(ctx, fcm_jacobi_create(ctx, NULL, FCM_JACOBI_SCALAR, &bad), FCM_ERR_ARG, "NULL");
  TEST_ERR(ctx, fcm_jacobi_apply(J, rr, rr), FCM_ERR_ARG, "different");
  double *vals = fcm_csr_values(A);
  vals[fcm_csr_position(A, 4, 4)] = 0.0; /* zero diagonal: block falls back, then fails */
  TEST_ERR(ctx, fcm_jacobi_setup(J, A), FCM_ERR_SINGULAR, "row 4 is zero");
  TEST_ERR(ctx, fcm_jacobi_apply(J, rr, z), FCM_ERR_ARG, "setup failed");
  vals[fcm_csr_position(A, 4, 4)] = NAN;
  TEST_ERR(ctx, fcm_jacobi_setup(Js, A), FCM_ERR_NUMERIC, "row 4");
  fcm_csr *A5 = NULL;
  fcm_index r5[5] = {0, 1, 2, 3, 4};
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 5, 5, 5, r5, r5, NULL, FCM_CSR_SYMMETRIC, &A5));
  TEST_ERR(ctx, fcm_jacobi_create(ctx, A5, FCM_JACOBI_BLOCK3, &bad), FCM_ERR_ARG, "divisible by 3");
  TEST_ERR(ctx, fcm_jacobi_setup(J, A5), FCM_ERR_ARG, "5 x 5");
  fcm_csr_destroy(&A5);
  fcm_jacobi_destroy(&J);
  fcm_jacobi_destroy(&Js);
  fcm_csr_destroy(&A);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  check_scaling(ctx);
  check_blocks(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
