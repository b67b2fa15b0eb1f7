/* Shared helpers of the material tests: a deterministic random generator,
 * random rotations, the test deformation gradients and textbook reference values. */
#ifndef FCM_MATERIAL_TEST_UTIL_H
#define FCM_MATERIAL_TEST_UTIL_H

#include "fcm/material.h"
#include "la/mat3.h"
#include "test.h"

#include <stdint.h>

static uint64_t rng_state_ = 0x9E3779B97F4A7C15ull;

/* Uniform in [lo, hi) (xorshift64*). */
static inline double urand(double lo, double hi)
{
  rng_state_ ^= rng_state_ >> 12;
  rng_state_ ^= rng_state_ << 25;
  rng_state_ ^= rng_state_ >> 27;
  uint64_t r = rng_state_ * 0x2545F4914F6CDD1Dull;
  return lo + (hi - lo) * (double)(r >> 11) * (1.0 / 9007199254740992.0);
}

/* A random proper rotation from a random unit quaternion. */
static inline void random_rotation(double R[9])
{
  double q[4], n = 0.0;
  do {
    n = 0.0;
    for (int k = 0; k < 4; k++)
      q[k] = urand(-1.0, 1.0), n += q[k] * q[k];
  } while (n < 0.1 || n > 1.0);
  n = sqrt(n);
  double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - w * z), R[2] = 2 * (x * z + w * y);
  R[3] = 2 * (x * y + w * z), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - w * x);
  R[6] = 2 * (x * z - w * y), R[7] = 2 * (y * z + w * x), R[8] = 1 - 2 * (x * x + y * y);
}

/* F = U diag(s) V^T with random rotations U, V. */
static inline void compose_F(const double s[3], double F[9])
{
  double U[9], V[9];
  random_rotation(U);
  random_rotation(V);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      F[3 * i + j] = U[3 * i] * s[0] * V[3 * j] + U[3 * i + 1] * s[1] * V[3 * j + 1] +
                     U[3 * i + 2] * s[2] * V[3 * j + 2];
}

/* Kinds of test deformation gradients. */
enum { F_GENERIC, F_INVERTED, F_NEAR_SINGULAR, F_ROTATION, F_REPEATED, F_LARGE, F_KINDS };
static const char *const f_kind_name[F_KINDS] = {"generic",  "inverted", "near-singular",
                                                 "rotation", "repeated", "large"};

/* The n-th test gradient (n = 0, 1, ...; 60 of them cycle through every kind) and its
 * kind. Inverted ones keep the two smallest magnitudes of the singular values at
 * least 0.05 apart, so that the corotated model (whose R is not differentiable where
 * the signed singular values s_1 + s_2 = 0) is smooth around them. */
static inline int test_F(int n, double F[9])
{
  static const double repeated[6][3] = {{1.3, 1.3, 0.7},  {1.2, 0.8, 0.8}, {0.9, 0.9, 0.9},
                                        {1.4, 1.4, -0.5}, {1.0, 1.0, 1.0}, {1.5, 1.5, -1.0}};
  int kind = n % F_KINDS;
  double s[3];
  switch (kind) {
  case F_GENERIC: /* I + random: det of either sign; redrawn near the corotated kink */
    for (;;) {
      double U[9], V[9], sig[3];
      for (int i = 0; i < 9; i++)
        F[i] = (i % 4 == 0 ? 1.0 : 0.0) + urand(-0.8, 0.8);
      fcm__mat3_svd(F, U, sig, V);
      if (sig[1] + sig[2] >= 0.05) return kind;
    }
  case F_INVERTED:
    s[0] = urand(0.8, 1.8), s[1] = urand(0.4, 0.8), s[2] = -urand(0.1, s[1] - 0.05);
    break;
  case F_NEAR_SINGULAR:
    s[0] = urand(0.8, 1.6), s[1] = urand(0.3, 1.0), s[2] = (n / F_KINDS) % 2 ? 1e-6 : -1e-6;
    break;
  case F_ROTATION:
    s[0] = s[1] = s[2] = 1.0;
    break;
  case F_REPEATED:
    for (int k = 0; k < 3; k++)
      s[k] = repeated[(n / F_KINDS) % 6][k];
    break;
  default: /* large stretch and compression */
    s[0] = urand(2.0, 3.0), s[1] = urand(0.2, 1.0), s[2] = urand(0.05, 0.3);
    break;
  }
  compose_F(s, F);
  return kind;
}

/* Parameter sets (E, nu): the paper's SNH scenes, a negative Poisson ratio, near
 * incompressibility, and nu = 0. */
#define NUM_PARAM_SETS 4
static const double param_sets[NUM_PARAM_SETS][2] = {
    {3e6, 0.4}, {2.5, -0.3}, {1e4, 0.49}, {5e4, 0.0}};

/* Textbook Lame parameters, written out here independently of the library. */
static inline void textbook_lame(double E, double nu, double *mu, double *lambda)
{
  *mu = E / (2.0 * (1.0 + nu));
  *lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
}

/* Small-strain elasticity tensor C_ijkl = mu (d_ik d_jl + d_il d_jk) + lambda d_ij d_kl. */
static inline void linear_tangent(double mu, double lambda, double C[81])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++)
          C[9 * (3 * i + j) + 3 * k + l] =
              mu * ((i == k && j == l) + (i == l && j == k)) + lambda * (i == j && k == l);
}

/* Model from the command line (canonical name), or -1. */
static inline int model_from_args(int argc, char **argv)
{
  if (argc < 2) return -1;
  for (int m = 0; m < FCM_MATERIAL_COUNT; m++)
    if (strcmp(argv[1], fcm_material_model_name((fcm_material_model)m)) == 0) return m;
  return -1;
}

static inline double max_abs(const double *a, int n)
{
  double m = 0.0;
  for (int i = 0; i < n; i++)
    m = fmax(m, fabs(a[i]));
  return m;
}

#endif
