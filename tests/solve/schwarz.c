/* Additive Schwarz: blocks covering a block-diagonal matrix give its exact inverse (CG
 * and MINRES in one iteration); with overlap and uncovered DOFs S equals
 * sum R^T C_K^{-1} R + D^{-1} computed independently by LU; an indefinite block gives an
 * SPD S_K with eigenvalues 1/|lambda|; the CLAMP and PAPER variants differ exactly on
 * the designed small eigenvalue; a block spanning more than 1/eps shows why CLAMP is
 * the default; positive definite blocks up to the Cholesky path's condition bound and beyond
 * it (eigen path) both give C_K^{-1} to their conditioning; bad input fails with named
 * blocks. */
#include "solve_test_util.h"

/* Symmetric dense n x n (column-major) -> CSR with every entry stored. */
static fcm_csr *csr_of_dense(fcm_ctx *ctx, int n, const double *M)
{
  fcm_index *ri = malloc(sizeof *ri * (size_t)(n * n)), *ci = malloc(sizeof *ci * (size_t)(n * n));
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++)
      ri[i + n * j] = i, ci[i + n * j] = j;
  fcm_csr *A = NULL;
  TEST_OK(ctx,
          fcm_csr_create_triplets(ctx, n, n, (fcm_index)n * n, ri, ci, M, FCM_CSR_SYMMETRIC, &A));
  free(ri);
  free(ci);
  return A;
}

/* Random orthogonal n x n: eigenvectors of a random symmetric matrix. */
static void random_orthogonal(fcm_ctx *ctx, int n, rng *r, double *Q)
{
  double *w = malloc(sizeof *w * (size_t)n);
  for (int j = 0; j < n; j++)
    for (int i = 0; i <= j; i++)
      Q[i + n * j] = Q[j + n * i] = rng_uniform(r);
  TEST_OK(ctx, fcm__syev(ctx, 1, n, Q, n, w));
  free(w);
}

/* M = Q diag(lam) Q^T */
static void compose(int n, const double *Q, const double *lam, double *M)
{
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double s = 0.0;
      for (int k = 0; k < n; k++)
        s += Q[i + n * k] * lam[k] * Q[j + n * k];
      M[i + n * j] = s;
    }
}

static void check_exact(fcm_ctx *ctx)
{
  enum { n = 24, nb = 6 };
  const int sizes[nb] = {3, 5, 4, 6, 2, 4};
  int perm[n];
  rng r = {5};
  for (int i = 0; i < n; i++)
    perm[i] = i;
  for (int i = n - 1; i > 0; i--) {
    int j = (int)((rng_uniform(&r) + 1.0) * 0.5 * (i + 1)) % (i + 1), t = perm[i];
    perm[i] = perm[j], perm[j] = t;
  }
  static double M[n * n], Q[n * n], lam[n], blk[n * n];
  fcm_index bptr[nb + 1] = {0}, bd[n];
  for (int b = 0, off = 0; b < nb; off += sizes[b], b++) {
    int m = sizes[b];
    random_orthogonal(ctx, m, &r, Q);
    for (int k = 0; k < m; k++)
      lam[k] = 1.0 + 4.5 * (rng_uniform(&r) + 1.0); /* [1, 10] */
    compose(m, Q, lam, blk);
    for (int i = 0; i < m; i++) {
      bd[off + i] = perm[off + i];
      for (int j = 0; j < m; j++)
        M[perm[off + i] + n * perm[off + j]] = blk[i + m * j];
    }
    bptr[b + 1] = off + m;
  }
  fcm_csr *A = csr_of_dense(ctx, n, M);
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, nb, bptr, bd, NULL, &P));
  fcm_schwarz_info si;
  fcm_schwarz_get_info(P, &si);
  TEST_TRUE(si.num_blocks == nb && si.block_dofs == n && si.outside_dofs == 0);
  TEST_TRUE(si.num_colors == 1 && si.max_block_size == 6);
  TEST_TRUE(si.negative_eigenvalues == 0 && si.clamped_eigenvalues == 0);
  /* S A = I */
  static double S[n * n], SA[n * n];
  dense_of(fcm_schwarz_operator, P, n, S);
  fcm__gemm('N', 'N', n, n, n, 1.0, S, n, M, n, 0.0, SA, n);
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++)
      TEST_NEAR(SA[i + n * j], i == j, 0.0, 1e-13);
  /* one iteration of CG and of MINRES */
  double b[n], x[n];
  for (int i = 0; i < n; i++)
    b[i] = rng_uniform(&r);
  fcm_krylov_options o = fcm_krylov_options_default();
  o.rtol = 1e-12;
  fcm_krylov_info info;
  memset(x, 0, sizeof x);
  TEST_OK(ctx, fcm_cg_solve(ctx, n, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x, &o, &info));
  TEST_TRUE(info.iterations == 1);
  memset(x, 0, sizeof x);
  TEST_OK(ctx,
          fcm_minres_solve(ctx, n, fcm_csr_operator, A, fcm_schwarz_operator, P, b, x, &o, &info));
  TEST_TRUE(info.iterations == 1);
  TEST_TRUE(true_residual(A, b, x, n) < 1e-12);
  fcm_schwarz_destroy(&P);
  fcm_csr_destroy(&A);
}

/* Overlapping blocks and uncovered DOFs against an LU-based construction. */
static void check_additive(fcm_ctx *ctx)
{
  enum { n = 12 };
  static double M[n * n], S[n * n], E[n * n];
  rng r = {9};
  for (int j = 0; j < n; j++)
    for (int i = 0; i <= j; i++)
      M[i + n * j] = M[j + n * i] = rng_uniform(&r) + (i == j ? 13.0 : 0.0); /* SPD by Gershgorin */
  fcm_csr *A = csr_of_dense(ctx, n, M);
  const fcm_index bptr[4] = {0, 5, 9, 11}, bd[11] = {0, 1, 2, 3, 4, 6, 3, 5, 4, 10, 9};
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, 3, bptr, bd, NULL, &P));
  fcm_schwarz_info si;
  fcm_schwarz_get_info(P, &si);
  TEST_TRUE(si.num_colors == 2 && si.outside_dofs == 3 && si.block_dofs == 11);
  dense_of(fcm_schwarz_operator, P, n, S);
  /* expected: LU inverse of each block, scattered and summed; 1/a_ii on 7, 8, 11 */
  for (int b = 0; b < 3; b++) {
    int m = (int)(bptr[b + 1] - bptr[b]), ipiv[8];
    double C[64], I[64];
    for (int i = 0; i < m; i++)
      for (int j = 0; j < m; j++) {
        C[i + m * j] = M[bd[bptr[b] + i] + n * bd[bptr[b] + j]];
        I[i + m * j] = i == j;
      }
    TEST_OK(ctx, fcm__getrf(ctx, m, C, m, ipiv));
    TEST_OK(ctx, fcm__getrs(ctx, m, m, C, m, ipiv, I, m));
    for (int i = 0; i < m; i++)
      for (int j = 0; j < m; j++)
        E[bd[bptr[b] + i] + n * bd[bptr[b] + j]] += I[i + m * j];
  }
  const int outside[3] = {7, 8, 11};
  for (int k = 0; k < 3; k++)
    E[outside[k] * (n + 1)] = 1.0 / M[outside[k] * (n + 1)];
  for (int i = 0; i < n * n; i++)
    TEST_NEAR(S[i], E[i], 1e-12, 1e-14);
  fcm_schwarz_destroy(&P);
  fcm_csr_destroy(&A);
}

/* Eigenvalues of S_K for one block covering a designed 5 x 5 matrix. */
static void check_clamp(fcm_ctx *ctx)
{
  enum { n = 5 };
  static double Q[n * n], M[n * n], S[n * n], W[n * n], w[n];
  const double lam[n] = {4.0, -2.0, 1.0, 1e-15, -0.5}; /* eps lambda_max = 4e-13 */
  rng r = {21};
  random_orthogonal(ctx, n, &r, Q);
  compose(n, Q, lam, M);
  fcm_csr *A = csr_of_dense(ctx, n, M);
  const fcm_index bptr[2] = {0, n}, bd[n] = {4, 2, 0, 1, 3};
  double expect_small[2] = {1.0 / (1e-13 * 4.0), 1e-13 / 4.0}; /* CLAMP, PAPER */
  double rq[2][n];
  for (int v = 0; v < 2; v++) {
    fcm_schwarz_options o = fcm_schwarz_options_default();
    o.clamp = v ? FCM_SCHWARZ_PAPER : FCM_SCHWARZ_CLAMP;
    fcm_schwarz *P = NULL;
    TEST_OK(ctx, fcm_schwarz_create(ctx, A, 1, bptr, bd, &o, &P));
    fcm_schwarz_info si;
    fcm_schwarz_get_info(P, &si);
    TEST_TRUE(si.clamped_eigenvalues == 1);
    TEST_TRUE(si.negative_eigenvalues >= 2 &&
              si.negative_eigenvalues <= 3); /* 1e-15: sign is noise */
    dense_of(fcm_schwarz_operator, P, n, S);
    memcpy(W, S, sizeof S);
    TEST_OK(ctx, fcm__syev(ctx, 0, n, W, n, w));
    TEST_TRUE(w[0] > 0.0); /* SPD although A is indefinite */
    /* Rayleigh quotients on the designed eigenvectors */
    for (int k = 0; k < n; k++) {
      double s = 0.0;
      for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
          s += Q[i + n * k] * S[i + n * j] * Q[j + n * k];
      rq[v][k] = s;
      /* rounding in forming S is ~ n eps max(s_k): 1e-3 absolute for CLAMP */
      double smax = v ? 2.0 : expect_small[0];
      if (k == 3)
        TEST_NEAR(s, expect_small[v], 0.1, 0.0);
      else
        TEST_NEAR(s, 1.0 / fabs(lam[k]), 1e-12, 5e-15 * smax);
    }
    fcm_schwarz_destroy(&P);
  }
  /* the variants agree off the clamped direction, and differ by 1/eps^2 on it */
  for (int k = 0; k < n; k++)
    if (k != 3) TEST_NEAR(rq[0][k], rq[1][k], 1e-12, 5e-15 * expect_small[0]);
  TEST_NEAR(rq[0][3] / rq[1][3], 1e26, 0.2, 0.0);
  fcm_csr_destroy(&A);

  /* a random indefinite block without clamping: eig(S_K) = 1/|eig(C_K)| */
  enum { m = 7 };
  static double Qm[m * m], Mm[m * m], Sm[m * m], lm[m], inv[m], wm[m];
  random_orthogonal(ctx, m, &r, Qm);
  for (int k = 0; k < m; k++)
    lm[k] = (k % 2 ? -1.0 : 1.0) * (0.5 + k);
  compose(m, Qm, lm, Mm);
  A = csr_of_dense(ctx, m, Mm);
  fcm_index bp[2] = {0, m}, bdm[m] = {0, 1, 2, 3, 4, 5, 6};
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, 1, bp, bdm, NULL, &P));
  dense_of(fcm_schwarz_operator, P, m, Sm);
  TEST_OK(ctx, fcm__syev(ctx, 0, m, Sm, m, wm));
  for (int k = 0; k < m; k++)
    inv[k] = 1.0 / (0.5 + (m - 1 - k)); /* ascending */
  for (int k = 0; k < m; k++)
    TEST_NEAR(wm[k], inv[k], 1e-12, 0.0);
  fcm_schwarz_destroy(&P);
  fcm_csr_destroy(&A);
}

/* Why CLAMP: a block whose spectrum spans more than 1/eps (a tiny cut cell without
 * stabilization), A = diag(1, 0.5, 1e-14) plus an uncovered DOF. kappa(SA): CLAMP maps
 * 1e-14 to 1e-14 / (eps lambda_max) = 0.1, so kappa = 10; PAPER maps it to
 * 1e-14 eps / lambda_max = 1e-27, so kappa = 1e27. */
static void check_clamp_study(fcm_ctx *ctx)
{
  const fcm_index ri[4] = {0, 1, 2, 3};
  const double d[4] = {1.0, 0.5, 1e-14, 2.0};
  fcm_csr *A = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 4, 4, 4, ri, ri, d, FCM_CSR_SYMMETRIC, &A));
  const fcm_index bptr[2] = {0, 3}, bd[3] = {2, 0, 1};
  double kappa[2];
  for (int v = 0; v < 2; v++) {
    fcm_schwarz_options o = fcm_schwarz_options_default();
    o.clamp = v ? FCM_SCHWARZ_PAPER : FCM_SCHWARZ_CLAMP;
    fcm_schwarz *P = NULL;
    double S[16], lo = HUGE_VAL, hi = 0.0;
    TEST_OK(ctx, fcm_schwarz_create(ctx, A, 1, bptr, bd, &o, &P));
    dense_of(fcm_schwarz_operator, P, 4, S);
    for (int i = 0; i < 4; i++) {
      for (int j = 0; j < 4; j++)
        if (i != j) TEST_TRUE(S[i + 4 * j] == 0.0); /* diagonal: eigenvectors are unit vectors */
      double e = S[5 * i] * d[i];
      lo = fmin(lo, e), hi = fmax(hi, e);
    }
    kappa[v] = hi / lo;
    fcm_schwarz_destroy(&P);
  }
  TEST_NEAR(kappa[0], 10.0, 1e-12, 0.0);
  TEST_NEAR(kappa[1], 1e27, 1e-12, 0.0);
  fcm_csr_destroy(&A);
}

/* A positive definite 24 x 24 block with eigenvalues spread geometrically over [1/kappa, 1]:
 * S_K = C_K^{-1} to 24 kappa times the unit round-off (relative, Frobenius), without clamped
 * or negative eigenvalues, on both sides of the Cholesky path's bound (kappa = 1e2, 1e8: the
 * Cholesky inverse; 1e12: the eigen-inverse). */
static void check_conditioned(fcm_ctx *ctx)
{
  enum { m = 24 };
  static double Q[m * m], M[m * m], S[m * m], E[m * m], lam[m], inv[m];
  const double kappas[3] = {1e2, 1e8, 1e12};
  rng r = {33};
  for (int t = 0; t < 3; t++) {
    random_orthogonal(ctx, m, &r, Q);
    for (int k = 0; k < m; k++) {
      lam[k] = pow(kappas[t], -(double)k / (m - 1));
      inv[k] = 1.0 / lam[k];
    }
    compose(m, Q, lam, M);
    compose(m, Q, inv, E);
    fcm_csr *A = csr_of_dense(ctx, m, M);
    const fcm_index bptr[2] = {0, m};
    fcm_index bd[m];
    for (int i = 0; i < m; i++)
      bd[i] = (7 * i) % m; /* any order */
    fcm_schwarz *P = NULL;
    TEST_OK(ctx, fcm_schwarz_create(ctx, A, 1, bptr, bd, NULL, &P));
    fcm_schwarz_info si;
    fcm_schwarz_get_info(P, &si);
    TEST_TRUE(si.clamped_eigenvalues == 0 && si.negative_eigenvalues == 0);
    dense_of(fcm_schwarz_operator, P, m, S);
    double d = 0.0, e = 0.0;
    for (int i = 0; i < m * m; i++)
      d += (S[i] - E[i]) * (S[i] - E[i]), e += E[i] * E[i];
    printf("schwarz: kappa %.0e, |S - C^-1|_F / |C^-1|_F = %.2e\n", kappas[t], sqrt(d / e));
    TEST_TRUE(sqrt(d / e) <= 24.0 * kappas[t] * 1.2e-16);
    fcm_schwarz_destroy(&P);
    fcm_csr_destroy(&A);
  }
}

static void check_errors(fcm_ctx *ctx)
{
  const fcm_index ri[4] = {0, 1, 2, 3};
  double d[4] = {1.0, 2.0, 0.0, 3.0};
  fcm_csr *A = NULL;
  fcm_schwarz *P = NULL;
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 4, 4, 4, ri, ri, d, FCM_CSR_SYMMETRIC, &A));
  fcm_index bptr[3] = {0, 2, 4}, bd[4] = {0, 1, 2, 3};
  bd[1] = 0;
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 2, bptr, bd, NULL, &P), FCM_ERR_ARG,
           "block 0 lists DOF 0 twice");
  TEST_TRUE(P == NULL);
  bd[1] = 4;
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 2, bptr, bd, NULL, &P), FCM_ERR_ARG,
           "DOF 4 out of range [0, 4)");
  bd[1] = 1;
  bptr[1] = 0;
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 2, bptr, bd, NULL, &P), FCM_ERR_ARG,
           "block 0 has 0 DOFs");
  bptr[1] = 2;
  fcm_schwarz_options o = fcm_schwarz_options_default();
  o.epsilon = 1.5;
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 2, bptr, bd, &o, &P), FCM_ERR_ARG, "epsilon = 1.5");
  o = fcm_schwarz_options_default();
  o.clamp = (fcm_schwarz_clamp)3;
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 2, bptr, bd, &o, &P), FCM_ERR_ARG, "clamp = 3");
  /* zero diagonal outside the blocks (DOF 2 in none) */
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 1, bptr, bd, NULL, &P), FCM_ERR_SINGULAR,
           "row 2 (outside all blocks) is zero");
  /* a zero block: DOF 2 alone */
  const fcm_index bp2[3] = {0, 2, 3}, bd2[3] = {0, 1, 2};
  TEST_ERR(ctx, fcm_schwarz_create(ctx, A, 2, bp2, bd2, NULL, &P), FCM_ERR_SINGULAR,
           "block 1 (1 DOFs, first DOF 2) is zero");
  /* NaN in a block, then recovery by a new setup */
  d[2] = 1.0;
  fcm_csr_destroy(&A);
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 4, 4, 4, ri, ri, d, FCM_CSR_SYMMETRIC, &A));
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, 2, bp2, bd2, NULL, &P));
  double *vals = fcm_csr_values(A), r[4] = {1, 1, 1, 1}, z[4];
  vals[1] = NAN;
  TEST_ERR(ctx, fcm_schwarz_setup(P, A), FCM_ERR_NUMERIC,
           "block 0 (2 DOFs, first DOF 0) contains NaN");
  TEST_ERR(ctx, fcm_schwarz_apply(P, r, z), FCM_ERR_ARG, "setup failed");
  vals[1] = 4.0;
  TEST_OK(ctx, fcm_schwarz_setup(P, A));
  TEST_OK(ctx, fcm_schwarz_apply(P, r, z));
  TEST_NEAR(z[1], 0.25, 1e-15, 0.0);
  TEST_ERR(ctx, fcm_schwarz_apply(P, r, r), FCM_ERR_ARG, "different arrays");
  fcm_csr *B = NULL;
  fcm_schwarz *Q = NULL;
  fcm_index ci[3] = {0, 1, 2};
  TEST_OK(ctx, fcm_csr_create_triplets(ctx, 3, 4, 3, ci, ci, NULL, FCM_CSR_GENERAL, &B));
  TEST_ERR(ctx, fcm_schwarz_create(ctx, B, 0, NULL, NULL, NULL, &Q), FCM_ERR_ARG, "not square");
  TEST_TRUE(Q == NULL);
  TEST_ERR(ctx, fcm_schwarz_setup(P, B), FCM_ERR_ARG, "3 x 4");
  fcm_csr_destroy(&B);
  fcm_schwarz_destroy(&P);
  /* no blocks at all: plain Jacobi */
  TEST_OK(ctx, fcm_schwarz_create(ctx, A, 0, NULL, NULL, NULL, &P));
  TEST_OK(ctx, fcm_schwarz_apply(P, r, z));
  for (int i = 0; i < 4; i++)
    TEST_NEAR(z[i], 1.0 / vals[i], 1e-15, 0.0);
  fcm_schwarz_destroy(&P);
  fcm_csr_destroy(&A);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  check_exact(ctx);
  check_additive(ctx);
  check_clamp(ctx);
  check_clamp_study(ctx);
  check_conditioned(ctx);
  check_errors(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
