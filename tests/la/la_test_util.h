/* Helpers shared by the la tests: a reproducible random generator, a failing
 * allocator for allocation-failure loops, and small dense-matrix checks. */
#ifndef FCM_LA_TEST_UTIL_H
#define FCM_LA_TEST_UTIL_H

#include "fcm/core.h"
#include "test_alloc.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define LA_PI 3.14159265358979323846

/* Frobenius norm of a 3x3 matrix without under- or overflow. */
static inline double norm3_safe(const double A[9])
{
  double amax = 0.0, s = 0.0;
  for (int i = 0; i < 9; i++)
    amax = fmax(amax, fabs(A[i]));
  if (amax == 0.0) return 0.0;
  for (int i = 0; i < 9; i++)
    s += (A[i] / amax) * (A[i] / amax);
  return amax * sqrt(s);
}

/* max_ij |A_ij| of a column-major m x n matrix. */
static inline double dense_maxabs(int m, int n, const double *a, int lda)
{
  double s = 0.0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < m; i++)
      s = fmax(s, fabs(a[i + (size_t)j * lda]));
  return s;
}

/* max_ij |(Q^T Q - I)_ij| for the m x k column-major Q (orthonormal columns). */
static inline double orth_error_cols(int m, int k, const double *q, int ldq)
{
  double e = 0.0;
  for (int a = 0; a < k; a++)
    for (int b = 0; b < k; b++) {
      double s = 0.0;
      for (int i = 0; i < m; i++)
        s += q[i + (size_t)a * ldq] * q[i + (size_t)b * ldq];
      e = fmax(e, fabs(s - (a == b ? 1.0 : 0.0)));
    }
  return e;
}

#endif
