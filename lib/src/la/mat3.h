/* Small fixed-size 3x3 helpers for hot loops (internal). The inline ones live
 * here; the iterative decompositions (eigen, SVD, polar) are in mat3.c.
 * Matrices are row-major double[9]: A[3*i + j]. */
#ifndef FCM_MAT3_H
#define FCM_MAT3_H

#include <math.h>

static inline double fcm__mat3_det(const double A[9])
{
  return A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
         A[2] * (A[3] * A[7] - A[4] * A[6]);
}

/* Cofactor matrix C (C = det(A) A^{-T}); well defined for singular A. */
static inline void fcm__mat3_cofactor(const double A[9], double C[9])
{
  C[0] = A[4] * A[8] - A[5] * A[7];
  C[1] = A[5] * A[6] - A[3] * A[8];
  C[2] = A[3] * A[7] - A[4] * A[6];
  C[3] = A[2] * A[7] - A[1] * A[8];
  C[4] = A[0] * A[8] - A[2] * A[6];
  C[5] = A[1] * A[6] - A[0] * A[7];
  C[6] = A[1] * A[5] - A[2] * A[4];
  C[7] = A[2] * A[3] - A[0] * A[5];
  C[8] = A[0] * A[4] - A[1] * A[3];
}

/* Ainv = A^{-1}; returns det(A). Ainv is left untouched when det(A) == 0. */
static inline double fcm__mat3_inv(const double A[9], double Ainv[9])
{
  double C[9];
  fcm__mat3_cofactor(A, C);
  double det = A[0] * C[0] + A[1] * C[1] + A[2] * C[2];
  if (det == 0.0) return det;
  double s = 1.0 / det;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      Ainv[3 * i + j] = s * C[3 * j + i];
  return det;
}

/* y = A x */
static inline void fcm__mat3_mulv(const double A[9], const double x[3], double y[3])
{
  double t0 = A[0] * x[0] + A[1] * x[1] + A[2] * x[2];
  double t1 = A[3] * x[0] + A[4] * x[1] + A[5] * x[2];
  double t2 = A[6] * x[0] + A[7] * x[1] + A[8] * x[2];
  y[0] = t0, y[1] = t1, y[2] = t2;
}

/* y = A^T x */
static inline void fcm__mat3_tmulv(const double A[9], const double x[3], double y[3])
{
  double t0 = A[0] * x[0] + A[3] * x[1] + A[6] * x[2];
  double t1 = A[1] * x[0] + A[4] * x[1] + A[7] * x[2];
  double t2 = A[2] * x[0] + A[5] * x[1] + A[8] * x[2];
  y[0] = t0, y[1] = t1, y[2] = t2;
}

/* C = A B (C may not alias A or B). */
static inline void fcm__mat3_mul(const double A[9], const double B[9], double C[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* B = A^T (B may not alias A). */
static inline void fcm__mat3_transpose(const double A[9], double B[9])
{
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      B[3 * i + j] = A[3 * j + i];
}

/* Frobenius norm. */
static inline double fcm__mat3_norm(const double A[9])
{
  double s = 0.0;
  for (int i = 0; i < 9; i++)
    s += A[i] * A[i];
  return sqrt(s);
}

/* Symmetric eigen-decomposition A = Q diag(lambda) Q^T of the symmetric part
 * (A + A^T)/2 by cyclic Jacobi rotations, iterated until every off-diagonal entry
 * is negligible against its diagonal pair (relative accuracy ~ machine epsilon).
 * lambda ascending; the columns of Q (Q[3*i + k] = component i of eigenvector k)
 * are orthonormal and right-handed (det Q = +1). Returns the number of sweeps
 * (>= 0), or -1 for NaN/Inf input (lambda = NaN, Q = I). No allocation. */
int fcm__mat3_sym_eig(const double A[9], double lambda[3], double Q[9]);

/* Singular value decomposition F = U diag(sigma) V^T, rotation variant: U and V
 * are proper rotations (det +1), sigma[0] >= sigma[1] >= |sigma[2]|, and sigma[2]
 * carries the sign of det F (negative for inverted F). One-sided Jacobi on the
 * columns of F, to machine precision, robust for rank-deficient F. Returns the
 * number of sweeps (>= 0), or -1 for NaN/Inf input (sigma = NaN, U = V = I). */
int fcm__mat3_svd(const double F[9], double U[9], double sigma[3], double V[9]);

/* Polar decomposition F = R S with R a proper rotation (det R = +1, also for
 * det F <= 0) and S = V diag(sigma) V^T symmetric (positive definite when
 * det F > 0; its smallest eigenvalue is negative when det F < 0). Built from
 * fcm__mat3_svd, whose return value it passes on. */
int fcm__mat3_polar(const double F[9], double R[9], double S[9]);

#endif /* FCM_MAT3_H */
