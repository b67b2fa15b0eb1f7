/* fcm__mat3_svd (rotation variant) and fcm__mat3_polar: on random F (both signs
 * of det F) and degenerate ones (zero, rank one and two, repeated singular values,
 * reflections, tiny and huge scales): U, V proper rotations, |sigma| equal to
 * LAPACK's singular values, sigma[0] >= sigma[1] >= |sigma[2]|, sign(sigma[2]) =
 * sign(det F), U diag(sigma) V^T = F and R S = F to 1e-13 relative, R a rotation,
 * S symmetric and, for det F > 0, equal to LAPACK's (F^T F)^{1/2}. */
#include "la/la_impl.h"
#include "la/mat3.h"
#include "la_test_util.h"
#include "test.h"

static int max_sweeps = 0;

static void check_rotation(const double Q[9])
{
  double Qt[9], QtQ[9];
  fcm__mat3_transpose(Q, Qt);
  fcm__mat3_mul(Qt, Q, QtQ);
  for (int i = 0; i < 9; i++)
    TEST_NEAR(QtQ[i], (i % 4 == 0) ? 1.0 : 0.0, 0.0, 4e-15);
  TEST_NEAR(fcm__mat3_det(Q), 1.0, 0.0, 6e-15);
}

static void check(fcm_ctx *ctx, const double F[9])
{
  double U[9], V[9], sig[3], s_ref[3], a[9];
  int sweeps = fcm__mat3_svd(F, U, sig, V);
  TEST_TRUE(sweeps >= 0);
  if (sweeps > max_sweeps) max_sweeps = sweeps;
  double fnorm = norm3_safe(F), det = fcm__mat3_det(F);
  check_rotation(U);
  check_rotation(V);
  /* LAPACK is column-major: pass F^T, whose singular values are those of F. */
  for (int i = 0; i < 9; i++)
    a[i] = F[i];
  TEST_OK(ctx, fcm__gesvd(ctx, 3, 3, a, 3, s_ref, NULL, 1, NULL, 1));
  for (int k = 0; k < 3; k++)
    TEST_NEAR(fabs(sig[k]), s_ref[k], 0.0, 1e-14 * fnorm);
  TEST_TRUE(sig[0] >= sig[1] && sig[1] >= fabs(sig[2]));
  /* The sign of sigma[2] is that of det F whenever det F is clearly non-zero. */
  if (fabs(det) > 1e-8 * fnorm * fnorm * fnorm) TEST_TRUE((sig[2] < 0) == (det < 0));
  double US[9], Vt[9], G[9];
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      US[3 * i + k] = U[3 * i + k] * sig[k];
  fcm__mat3_transpose(V, Vt);
  fcm__mat3_mul(US, Vt, G);
  for (int i = 0; i < 9; i++)
    TEST_NEAR(G[i], F[i], 0.0, 1e-13 * fnorm);

  double R[9], S[9];
  TEST_TRUE(fcm__mat3_polar(F, R, S) >= 0);
  check_rotation(R);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      TEST_TRUE(S[3 * i + j] == S[3 * j + i]);
  fcm__mat3_mul(R, S, G);
  for (int i = 0; i < 9; i++)
    TEST_NEAR(G[i], F[i], 0.0, 1e-13 * fnorm);
  if (det > 1e-6 * fnorm * fnorm * fnorm) {
    /* Unique polar factor: S = (F^T F)^{1/2} from LAPACK's eigen-decomposition. */
    double C[9], Ft[9], w[3], Sref[9];
    fcm__mat3_transpose(F, Ft);
    fcm__mat3_mul(Ft, F, C);
    TEST_OK(ctx, fcm__syev(ctx, 1, 3, C, 3, w)); /* C symmetric: row/column major agree */
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        double s = 0.0;
        for (int k = 0; k < 3; k++)
          s += C[i + 3 * k] * sqrt(fmax(w[k], 0.0)) * C[j + 3 * k];
        Sref[3 * i + j] = s;
      }
    for (int i = 0; i < 9; i++)
      TEST_NEAR(S[i], Sref[i], 0.0, 1e-12 * fnorm);
  }
  if (det < -1e-6 * fnorm * fnorm * fnorm) {
    /* Inverted: S has exactly one negative eigenvalue (det S = det F). */
    TEST_NEAR(fcm__mat3_det(S), det, 1e-12, 0.0);
  }
}

/* F = R1 diag(d) R2 for random rotations R1, R2 (from symmetric eigenvectors). */
static void make(rng *r, const double d[3], double F[9])
{
  double B[9], lam[3], R1[9], R2[9], T[9];
  for (int t = 0; t < 2; t++) {
    for (int i = 0; i < 3; i++)
      for (int j = i; j < 3; j++)
        B[3 * i + j] = B[3 * j + i] = rng_uniform(r);
    fcm__mat3_sym_eig(B, lam, t ? R2 : R1);
  }
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      T[3 * i + k] = R1[3 * i + k] * d[k];
  fcm__mat3_mul(T, R2, F);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  rng r = {4242};
  double F[9];
  int inverted = 0;
  for (int t = 0; t < 3000; t++) {
    for (int i = 0; i < 9; i++)
      F[i] = rng_uniform(&r);
    if (fcm__mat3_det(F) < 0) inverted++;
    check(ctx, F);
  }
  TEST_TRUE(inverted > 1000); /* both signs of det F were exercised */
  /* Near-identity deformation gradients (the common case in a simulation). */
  for (int t = 0; t < 500; t++) {
    for (int i = 0; i < 9; i++)
      F[i] = (i % 4 == 0 ? 1.0 : 0.0) + 1e-3 * rng_uniform(&r);
    check(ctx, F);
  }
  const double spectra[][3] = {
      {3, 2, 1}, {2, 2, 1},       {1, 1, 1},  {1, 1, -1},  {2, 1, -1e-3}, {1, 0, 0},    {0, 0, 0},
      {5, 5, 0}, {1, 1e-8, 1e-8}, {4, 4, -4}, {1, -1, -1}, {-1, -1, -1},  {1, 1e-15, 0}};
  for (size_t c = 0; c < sizeof spectra / sizeof spectra[0]; c++)
    for (int t = 0; t < 30; t++) {
      make(&r, spectra[c], F);
      check(ctx, F);
    }
  /* Exact special cases. */
  {
    const double zero[9] = {0}, refl[9] = {1, 0, 0, 0, 1, 0, 0, 0, -1};
    const double swap[9] = {0, 1, 0, 1, 0, 0, 0, 0, 1}; /* det -1 permutation */
    const double rank1[9] = {1, 2, 3, 2, 4, 6, -1, -2, -3};
    check(ctx, zero);
    check(ctx, refl);
    check(ctx, swap);
    check(ctx, rank1);
    double U[9], V[9], sig[3];
    fcm__mat3_svd(refl, U, sig, V);
    TEST_TRUE(sig[0] == 1.0 && sig[1] == 1.0 && sig[2] == -1.0);
    fcm__mat3_svd(zero, U, sig, V);
    TEST_TRUE(sig[0] == 0.0 && sig[1] == 0.0 && sig[2] == 0.0 && U[0] == 1.0 && V[8] == 1.0);
    /* A proper rotation is its own polar factor, S = I. */
    double Q[9], R[9], S[9];
    make(&r, (const double[3]){1, 1, 1}, Q);
    fcm__mat3_polar(Q, R, S);
    for (int i = 0; i < 9; i++)
      TEST_NEAR(R[i], Q[i], 0.0, 1e-15 * 4);
    for (int i = 0; i < 9; i++)
      TEST_NEAR(S[i], (i % 4 == 0) ? 1.0 : 0.0, 0.0, 1e-15 * 4);
  }
  /* Tiny and huge scales: no under- or overflow. */
  const double scales[] = {1e-250, 1e-100, 1e100, 1e250};
  for (size_t s = 0; s < 4; s++)
    for (int t = 0; t < 20; t++) {
      for (int i = 0; i < 9; i++)
        F[i] = scales[s] * rng_uniform(&r);
      check(ctx, F);
    }
  /* Non-finite input. */
  {
    double B[9] = {1, 0, 0, 0, INFINITY, 0, 0, 0, 1}, U[9], V[9], sig[3];
    TEST_TRUE(fcm__mat3_svd(B, U, sig, V) == -1);
    TEST_TRUE(isnan(sig[0]) && U[0] == 1.0 && V[4] == 1.0);
  }
  TEST_TRUE(max_sweeps <= 12);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
