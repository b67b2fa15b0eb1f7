/* fcm__mat3_sym_eig: on random symmetric matrices and degenerate ones (repeated
 * and triple eigenvalues, zero, rank one, indefinite, tiny and huge scales) the
 * eigenvalues match LAPACK's fcm__syev, come ascending, Q is orthonormal with
 * det +1, and Q diag(lambda) Q^T reproduces A to 1e-13 relative. */
#include "la/la_impl.h"
#include "la/mat3.h"
#include "la_test_util.h"
#include "test.h"

static int max_sweeps = 0;

static void check(fcm_ctx *ctx, const double A[9])
{
  double lam[3], Q[9], w[3], a[9];
  int sweeps = fcm__mat3_sym_eig(A, lam, Q);
  TEST_TRUE(sweeps >= 0);
  if (sweeps > max_sweeps) max_sweeps = sweeps;
  double anorm = norm3_safe(A);
  for (int i = 0; i < 9; i++)
    a[i] = A[i];
  TEST_OK(ctx, fcm__syev(ctx, 0, 3, a, 3, w));
  for (int k = 0; k < 3; k++)
    TEST_NEAR(lam[k], w[k], 0.0, 1e-14 * anorm);
  TEST_TRUE(lam[0] <= lam[1] && lam[1] <= lam[2]);
  double QtQ[9], Qt[9], R[9], D[9] = {0};
  fcm__mat3_transpose(Q, Qt);
  fcm__mat3_mul(Qt, Q, QtQ);
  for (int i = 0; i < 9; i++)
    TEST_NEAR(QtQ[i], (i % 4 == 0) ? 1.0 : 0.0, 0.0, 2e-15);
  TEST_NEAR(fcm__mat3_det(Q), 1.0, 0.0, 4e-15);
  for (int k = 0; k < 3; k++)
    D[4 * k] = lam[k];
  double QD[9];
  fcm__mat3_mul(Q, D, QD);
  fcm__mat3_mul(QD, Qt, R);
  for (int i = 0; i < 9; i++)
    TEST_NEAR(R[i], A[i], 0.0, 1e-13 * anorm);
  /* Each column is an eigenvector: A q_k = lambda_k q_k. */
  for (int k = 0; k < 3; k++) {
    double q[3] = {Q[k], Q[3 + k], Q[6 + k]}, Aq[3];
    fcm__mat3_mulv(A, q, Aq);
    for (int i = 0; i < 3; i++)
      TEST_NEAR(Aq[i], lam[k] * q[i], 0.0, 1e-14 * anorm);
  }
}

/* A = R diag(d) R^T with a random rotation R from a random SVD-free construction. */
static void rotated_diag(rng *r, const double d[3], double A[9])
{
  double B[9], lam[3], R[9];
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++)
      B[3 * i + j] = B[3 * j + i] = rng_uniform(r);
  fcm__mat3_sym_eig(B, lam, R); /* any orthonormal frame will do */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = 0.0;
      for (int k = 0; k < 3; k++)
        s += R[3 * i + k] * d[k] * R[3 * j + k];
      A[3 * i + j] = s;
    }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < i; j++)
      A[3 * i + j] = A[3 * j + i]; /* exactly symmetric */
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {31337};
  double A[9];
  for (int t = 0; t < 2000; t++) {
    for (int i = 0; i < 3; i++)
      for (int j = i; j < 3; j++)
        A[3 * i + j] = A[3 * j + i] = rng_uniform(&r);
    check(ctx, A);
  }
  const double spectra[][3] = {{2, 2, 5},        {-1, 3, 3},   {4, 4, 4},
                               {0, 0, 1},        {0, 0, 0},    {-2, 0, 2},
                               {1, 1e-9, 1e-18}, {-7, -7, -7}, {1, 1 + 1e-14, 1 - 1e-14}};
  for (size_t c = 0; c < sizeof spectra / sizeof spectra[0]; c++)
    for (int t = 0; t < 20; t++) {
      rotated_diag(&r, spectra[c], A);
      check(ctx, A);
    }
  /* Exact special matrices. */
  const double zero[9] = {0}, ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double diag[9] = {3, 0, 0, 0, -1, 0, 0, 0, 2};
  check(ctx, zero);
  check(ctx, ident);
  check(ctx, diag);
  {
    double lam[3], Q[9];
    fcm__mat3_sym_eig(diag, lam, Q);
    TEST_TRUE(lam[0] == -1.0 && lam[1] == 2.0 && lam[2] == 3.0); /* already diagonal: exact */
  }
  /* Rank one u u^T, and scaled copies far from 1. */
  {
    double u[3] = {0.3, -1.2, 0.7};
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        A[3 * i + j] = u[i] * u[j];
    check(ctx, A);
    const double scales[] = {1e-200, 1e-30, 1e30, 1e200};
    for (size_t s = 0; s < 4; s++) {
      double B[9];
      for (int t = 0; t < 10; t++) {
        for (int i = 0; i < 3; i++)
          for (int j = i; j < 3; j++)
            B[3 * i + j] = B[3 * j + i] = scales[s] * rng_uniform(&r);
        check(ctx, B);
      }
    }
  }
  /* The symmetric part is used: an antisymmetric perturbation changes nothing. */
  {
    double S[9] = {2, 1, 0, 1, 3, 1, 0, 1, 4}, N[9], l1[3], l2[3], Q1[9], Q2[9];
    for (int i = 0; i < 9; i++)
      N[i] = S[i];
    N[1] += 0.5, N[3] -= 0.5;
    fcm__mat3_sym_eig(S, l1, Q1);
    fcm__mat3_sym_eig(N, l2, Q2);
    for (int k = 0; k < 3; k++)
      TEST_NEAR(l2[k], l1[k], 0.0, 1e-15 * 8);
  }
  /* Non-finite input. */
  {
    double B[9] = {1, 0, 0, 0, NAN, 0, 0, 0, 1}, lam[3], Q[9];
    TEST_TRUE(fcm__mat3_sym_eig(B, lam, Q) == -1);
    TEST_TRUE(isnan(lam[0]) && Q[0] == 1.0 && Q[1] == 0.0);
  }
  TEST_TRUE(max_sweeps <= 12);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
