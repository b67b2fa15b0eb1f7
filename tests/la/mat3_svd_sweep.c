/* fcm__mat3_svd on many random and adversarial F: uniform entries of both signs of
 * det F, near-identity perturbations down to 1e-14, exact rotations and their
 * negatives, permutations, prescribed spectra with repeated, clustered, tiny and zero
 * singular values and negative ones (inverted F), ill-conditioned triangular
 * matrices, rank-one matrices with noise, each at scales from 1e-300 to 1e300.
 * Asserted on F / amax (amax a power of two, so the scaling is exact):
 *   U, V orthogonal, max |(Q^T Q - I)_ij| <= 1e-14, det U = det V = 1 to 1e-14;
 *   |U diag(sigma) V^T - F|_F <= 1e-14 |F|_F;
 *   sigma[0] >= sigma[1] >= |sigma[2]|, sigma[2] < 0 exactly when det F < 0 (where
 *   |det F| > 1e-12 |F|^3, so its computed sign is certain);
 *   for a prescribed spectrum, |sigma_k - d_k| <= 1e-14 |F| (Weyl: F is R1 diag(d) R2
 *   up to a rounding of a few eps |F|);
 *   at most 12 sweeps. */
#include "la/mat3.h"
#include "la_test_util.h"
#include "test.h"

static int max_sweeps = 0, checked = 0, inverted = 0;

static void check_rotation(const double Q[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = Q[i] * Q[j] + Q[3 + i] * Q[3 + j] + Q[6 + i] * Q[6 + j];
      TEST_NEAR(s, i == j ? 1.0 : 0.0, 0.0, 1e-14);
    }
  TEST_NEAR(fcm__mat3_det(Q), 1.0, 0.0, 1e-14);
}

/* Checks F; d (or NULL) the prescribed singular values in sigma's order and signs. */
static void check(const double F[9], const double *d)
{
  double U[9], V[9], sig[3], amax = 0.0, G[9], fn = 0.0;
  int sweeps = fcm__mat3_svd(F, U, sig, V), e = 0;
  TEST_TRUE(sweeps >= 0);
  if (sweeps > max_sweeps) max_sweeps = sweeps;
  checked++;
  for (int i = 0; i < 9; i++)
    amax = fmax(amax, fabs(F[i]));
  check_rotation(U);
  check_rotation(V);
  TEST_TRUE(sig[0] >= sig[1] && sig[1] >= fabs(sig[2]));
  if (amax == 0.0) {
    TEST_TRUE(sig[0] == 0.0 && sig[1] == 0.0 && sig[2] == 0.0);
    return;
  }
  frexp(amax, &e);
  double s[3];
  for (int i = 0; i < 9; i++) {
    G[i] = ldexp(F[i], -e);
    fn += G[i] * G[i];
  }
  fn = sqrt(fn);
  for (int k = 0; k < 3; k++)
    s[k] = ldexp(sig[k], -e);
  double r = 0.0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double x = -G[3 * i + j];
      for (int k = 0; k < 3; k++)
        x += U[3 * i + k] * s[k] * V[3 * j + k];
      r += x * x;
    }
  TEST_NEAR(sqrt(r), 0.0, 0.0, 1e-14 * fn);
  double det = fcm__mat3_det(G);
  if (fabs(det) > 1e-12 * fn * fn * fn) {
    TEST_TRUE((s[2] < 0.0) == (det < 0.0));
    if (det < 0.0) inverted++;
  }
  if (d)
    for (int k = 0; k < 3; k++)
      TEST_NEAR(s[k], ldexp(d[k], -e), 0.0, 1e-14 * fn);
}

/* A random rotation: the polar factor of a random matrix. */
static void rotation(rng *r, double R[9])
{
  double A[9], S[9];
  for (int i = 0; i < 9; i++)
    A[i] = rng_uniform(r);
  fcm__mat3_polar(A, R, S);
}

/* F = R1 diag(d) R2 * scale. */
static void make(rng *r, const double d[3], double scale, double F[9])
{
  double R1[9], R2[9], T[9];
  rotation(r, R1);
  rotation(r, R2);
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      T[3 * i + k] = R1[3 * i + k] * d[k] * scale;
  fcm__mat3_mul(T, R2, F);
}

static void scaled(const double F[9], double scale, double out[9])
{
  for (int i = 0; i < 9; i++)
    out[i] = F[i] * scale;
}

static const double scales[] = {1.0,     1e-300,  1e-200, 0x1p-126, 0x1p-127,
                                0x1p126, 0x1p127, 1e200,  1e300};
#define NSCALES (int)(sizeof scales / sizeof scales[0])

int main(void)
{
  rng r = {20261129};
  double F[9], H[9];
  /* Uniform entries, both signs of det F. */
  for (int t = 0; t < 20000; t++) {
    for (int i = 0; i < 9; i++)
      F[i] = rng_uniform(&r);
    scaled(F, scales[t % NSCALES], H);
    check(H, NULL);
  }
  /* Near identity, and near a rotation. */
  const double eps_pert[] = {1e-3, 1e-8, 1e-14};
  for (int p = 0; p < 3; p++)
    for (int t = 0; t < 2000; t++) {
      double R[9], P[9];
      rotation(&r, R);
      for (int i = 0; i < 9; i++)
        P[i] = (t % 2 ? R[i] : (i % 4 == 0)) + eps_pert[p] * rng_uniform(&r);
      scaled(P, scales[t % NSCALES], H);
      check(H, NULL);
    }
  /* Exact rotations and their negatives (det -1), permutations of both signs. */
  for (int t = 0; t < 2000; t++) {
    rotation(&r, F);
    check(F, (const double[3]){1, 1, 1});
    scaled(F, -1.0, H);
    check(H, (const double[3]){1, 1, -1});
  }
  const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int p = 0; p < 6; p++)
    for (int sgn = 0; sgn < 8; sgn++) {
      double P[9] = {0};
      for (int i = 0; i < 3; i++)
        P[3 * i + perm[p][i]] = (sgn >> i) & 1 ? -1.0 : 1.0;
      check(P, NULL);
    }
  /* Prescribed spectra (sigma's order, the sign on the last). */
  const double spectra[][3] = {{1, 1, 1},
                               {2, 2, 1},
                               {2, 1, 1},
                               {1, 1, -1},
                               {3, 2, -1},
                               {1, 1e-8, 1e-8},
                               {1, 1, 1e-12},
                               {1, 1e-10, 0},
                               {1, 1, 0},
                               {1, 0, 0},
                               {1, 1e-16, -1e-16},
                               {1, 1e-300, 1e-300},
                               {1 + 1e-15, 1, 1 - 1e-15},
                               {1, 1 - 1e-13, -(1 - 2e-13)},
                               {4, 4, -4},
                               {1e8, 1, 1e-8},
                               {1, 1e-5, -1e-10},
                               {5, 5, 5e-17}};
  for (size_t c = 0; c < sizeof spectra / sizeof spectra[0]; c++)
    for (int t = 0; t < 300; t++) {
      double sc = scales[t % NSCALES], d[3];
      make(&r, spectra[c], sc, F);
      for (int k = 0; k < 3; k++)
        d[k] = spectra[c][k] * sc;
      check(F, d);
    }
  /* Ill-conditioned triangular, rank one with noise, one zero column, a single entry. */
  for (int t = 0; t < 300; t++) {
    double a = pow(10.0, 8.0 * rng_uniform(&r)), R[9];
    double T[9] = {1, a, 0, 0, 1, a, 0, 0, t % 2 ? 1 : -1};
    for (int s = 0; s < NSCALES; s++) {
      scaled(T, scales[s], H);
      check(H, NULL);
    }
    double x[3], y[3], n = pow(10.0, -16.0 * (rng_uniform(&r) + 1.0) / 2.0);
    for (int i = 0; i < 3; i++)
      x[i] = rng_uniform(&r), y[i] = rng_uniform(&r);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        F[3 * i + j] = x[i] * y[j] + n * rng_uniform(&r);
    check(F, NULL);
    rotation(&r, R);
    for (int i = 0; i < 3; i++)
      R[3 * i + t % 3] = 0.0;
    check(R, NULL);
    double E[9] = {0};
    E[t % 9] = rng_uniform(&r) * scales[t % NSCALES];
    check(E, NULL);
  }
  check((const double[9]){0}, NULL);
  TEST_TRUE(inverted > 5000); /* det F < 0 was exercised */
  TEST_TRUE(max_sweeps <= 12);
  printf("%d matrices, %d inverted, at most %d sweeps\n", checked, inverted, max_sweeps);
  return TEST_RESULT();
}
