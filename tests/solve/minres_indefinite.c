/* MINRES on the symmetric indefinite shifted Laplacian L - sigma I: agrees with a dense
 * LU solve within the condition-number bound, with and without SPD preconditioners
 * (Jacobi, Schwarz on indefinite blocks); the monitored norm is non-increasing; the true
 * residuals of nested runs (x_k for k = 1, 2, ...) are non-increasing in the S-norm and
 * equal the recurrence value phibar. */
#include "solve_test_util.h"

#define N  6
#define NN (N * N * N)

/* ||b - A x||_S with S given as an operator (NULL: identity). */
static double s_norm_residual(const fcm_csr *A, fcm_operator_fn S, void *Su, const double *b,
                              const double *x)
{
  double r[NN], z[NN], s = 0.0;
  fcm_csr_apply(A, 1.0, x, 0.0, r);
  for (int i = 0; i < NN; i++)
    r[i] = b[i] - r[i];
  if (S)
    S(Su, r, z);
  else
    memcpy(z, r, sizeof r);
  for (int i = 0; i < NN; i++)
    s += r[i] * z[i];
  return sqrt(s);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_csr *L = NULL, *A = NULL;
  fcm_krylov *ws = NULL;
  fcm_jacobi *J = NULL;
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_krylov_create(ctx, NN, &ws));

  /* sigma halfway between two distinct eigenvalues about a third up the spectrum */
  static double dense[NN * NN], lam[NN], lu[NN * NN];
  TEST_OK(ctx, laplace3d(ctx, N, 0.0, NULL, &L));
  dense_of(fcm_csr_operator, L, NN, dense);
  TEST_OK(ctx, fcm__syev(ctx, 1, NN, dense, NN, lam)); /* columns: eigenvectors */
  int j = NN / 3;
  while (lam[j + 1] - lam[j] < 1e-3)
    j++;
  const double sigma = 0.5 * (lam[j] + lam[j + 1]);
  double amin = HUGE_VAL, amax = 0.0;
  for (int i = 0; i < NN; i++) {
    amin = fmin(amin, fabs(lam[i] - sigma));
    amax = fmax(amax, fabs(lam[i] - sigma));
  }
  const double kappa = amax / amin;
  TEST_TRUE(lam[0] < sigma && sigma < lam[NN - 1]); /* indefinite */
  TEST_OK(ctx, laplace3d(ctx, N, sigma, NULL, &A));

  /* dense reference */
  static double b[NN], xd[NN], x[NN];
  static int ipiv[NN];
  rng r = {3};
  for (int i = 0; i < NN; i++)
    b[i] = xd[i] = rng_uniform(&r);
  dense_of(fcm_csr_operator, A, NN, lu);
  TEST_OK(ctx, fcm__getrf(ctx, NN, lu, NN, ipiv));
  TEST_OK(ctx, fcm__getrs(ctx, NN, 1, lu, NN, ipiv, xd, NN));

  /* preconditioners: none, Jacobi, Schwarz on 2x2x2 sub-cubes (8 DOFs each, indefinite) */
  TEST_OK(ctx, fcm_jacobi_create(ctx, A, FCM_JACOBI_SCALAR, &J));
  static fcm_index bptr[28], bdofs[NN];
  int nb = 0, nd = 0;
  for (int K = 0; K < N; K += 2)
    for (int J2 = 0; J2 < N; J2 += 2)
      for (int I = 0; I < N; I += 2) {
        for (int c = 0; c < 8; c++)
          bdofs[nd++] = (I + (c & 1)) + N * ((J2 + (c >> 1 & 1)) + N * (K + (c >> 2)));
        bptr[++nb] = nd;
      }
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, nb, bptr, bdofs, NULL, &P));
  fcm_schwarz_info sinfo;
  fcm_schwarz_get_info(P, &sinfo);
  TEST_TRUE(sinfo.negative_eigenvalues > 0 && sinfo.outside_dofs == 0);

  fcm_operator_fn S[3] = {NULL, fcm_jacobi_operator, fcm_schwarz_operator};
  void *Su[3] = {NULL, J, P};
  const double rtol = 1e-10;
  for (int p = 0; p < 3; p++) {
    memset(x, 0, sizeof x);
    fcm_krylov_options o = fcm_krylov_options_default();
    o.rtol = rtol;
    o.record_history = 1;
    o.check_true_residual = 1;
    fcm_krylov_info info;
    TEST_OK(ctx, fcm_krylov_minres(ws, fcm_csr_operator, A, S[p], Su[p], b, x, &o, &info));
    /* n iterations in exact arithmetic; finite precision may delay (the reflected block
     * inverses spread the spectrum of S A over both signs) */
    if (!(info.reason == FCM_KRYLOV_CONVERGED_RTOL && info.iterations <= 2 * NN))
      TEST_FAIL_("preconditioner %d: %s after %d iterations", p,
                 fcm_krylov_reason_name(info.reason), info.iterations);
    /* the recurrence norm is the S-norm of the true residual */
    TEST_NEAR(info.residual_norm, s_norm_residual(A, S[p], Su[p], b, x), 1e-3,
              1e-12 * info.rhs_norm);
    /* ||x - x_lu|| / ||x_lu|| <= kappa(A) ||r|| / ||b||, and the S-norm bound turns into
     * the 2-norm one with kappa(S) <= 1e3 here (generous) */
    double err = 0.0;
    for (int i = 0; i < NN; i++)
      err += (x[i] - xd[i]) * (x[i] - xd[i]);
    err = sqrt(err) / norm2(xd, NN);
    if (!(err <= kappa * info.true_residual * 1.001 && info.true_residual <= 1e3 * rtol))
      TEST_FAIL_("preconditioner %d: error %.3e, true residual %.3e, kappa %.1f", p, err,
                 info.true_residual, kappa);
    /* monotone monitored norm */
    TEST_TRUE(info.history_length == info.iterations);
    TEST_TRUE(info.history[0] <= info.initial_residual);
    for (int k = 1; k < info.history_length; k++)
      if (!(info.history[k] <= info.history[k - 1]))
        TEST_FAIL_("preconditioner %d: history rises at %d: %.17g > %.17g", p, k, info.history[k],
                   info.history[k - 1]);

    /* nested runs: x_k minimizes ||b - A x||_S over K_k, so the true S-norm residual of
     * x_1, x_2, ... does not increase */
    double prev = HUGE_VAL;
    int kmax = info.iterations < 40 ? info.iterations : 40;
    for (int k = 1; k <= kmax; k++) {
      o.max_iterations = k;
      o.record_history = 0;
      o.check_true_residual = 0;
      memset(x, 0, sizeof x);
      fcm_status st = fcm_krylov_minres(ws, fcm_csr_operator, A, S[p], Su[p], b, x, &o, &info);
      TEST_TRUE(st == FCM_OK || st == FCM_ERR_NOT_CONVERGED);
      fcm_ctx_error_clear(ctx);
      double rk = s_norm_residual(A, S[p], Su[p], b, x);
      if (!(rk <= prev * (1 + 1e-12) + 1e-13 * info.rhs_norm))
        TEST_FAIL_("preconditioner %d: true residual rises at k = %d: %.17g > %.17g", p, k, rk,
                   prev);
      TEST_NEAR(rk, info.residual_norm, 1e-6, 1e-13 * info.rhs_norm);
      prev = rk;
    }
  }

  /* finite termination on the 5^3 grid: at most one iteration per distinct eigenvalue */
  {
    fcm_csr *A5 = NULL;
    fcm_krylov *ws5 = NULL;
    double b5[125], x5[125];
    for (int i = 0; i < 125; i++)
      b5[i] = rng_uniform(&r), x5[i] = 0.0;
    TEST_OK(ctx, laplace3d(ctx, 5, 3.1, NULL, &A5));
    TEST_OK(ctx, fcm_krylov_create(ctx, 125, &ws5));
    fcm_krylov_options o = fcm_krylov_options_default();
    o.rtol = 1e-8; /* at step 25 the residual drops from ~1e-2 to ~1e-9 */
    fcm_krylov_info i5;
    TEST_OK(ctx, fcm_krylov_minres(ws5, fcm_csr_operator, A5, NULL, NULL, b5, x5, &o, &i5));
    if (i5.iterations > laplace3d_distinct(5))
      TEST_FAIL_("minres: %d iterations > %d distinct eigenvalues", i5.iterations,
                 laplace3d_distinct(5));
    TEST_TRUE(true_residual(A5, b5, x5, 125) <= 1e-8);
    fcm_krylov_destroy(&ws5);
    fcm_csr_destroy(&A5);
  }

  /* CG with b along the eigenvector of the lowest eigenvalue lambda_0 - sigma < 0:
   * p^T A p < 0 in the first iteration, a breakdown; x keeps the initial guess */
  memset(x, 0, sizeof x);
  fcm_krylov_info info;
  TEST_ERR(ctx, fcm_krylov_cg(ws, fcm_csr_operator, A, NULL, NULL, dense, x, NULL, &info),
           FCM_ERR_NOT_CONVERGED, "p^T A p");
  TEST_TRUE(info.reason == FCM_KRYLOV_BREAKDOWN && info.iterations == 0);
  TEST_TRUE(norm2(x, NN) == 0.0);
  /* MINRES solves it in one iteration: x = b / (lambda_0 - sigma) */
  TEST_OK(ctx, fcm_krylov_minres(ws, fcm_csr_operator, A, NULL, NULL, dense, x, NULL, &info));
  TEST_TRUE(info.iterations == 1);
  for (int i = 0; i < NN; i++)
    TEST_NEAR(x[i], dense[i] / (lam[0] - sigma), 1e-9, 1e-12);

  fcm_schwarz_destroy(&P);
  fcm_jacobi_destroy(&J);
  fcm_krylov_destroy(&ws);
  fcm_csr_destroy(&A);
  fcm_csr_destroy(&L);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
