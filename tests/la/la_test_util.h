/* Helpers shared by the la tests: a reproducible random generator, a failing
 * allocator for allocation-failure loops, and small dense-matrix checks. */
#ifndef FCM_LA_TEST_UTIL_H
#define FCM_LA_TEST_UTIL_H

#include "fcm/core.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define LA_PI 3.14159265358979323846

/* xorshift64*: uniform doubles in [-1, 1). */
typedef struct rng {
  uint64_t s;
} rng;

static inline double rng_uniform(rng *r)
{
  r->s ^= r->s >> 12;
  r->s ^= r->s << 25;
  r->s ^= r->s >> 27;
  uint64_t x = r->s * 2685821657736338717ULL;
  return (double)(x >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

/* Allocator counting its calls and failing call number fail_at (0-based after
 * count was reset); fail_at = -1: never. */
typedef struct failing {
  long long count, fail_at;
} failing;

static inline void *failing_alloc(void *user, size_t size)
{
  failing *f = user;
  long long k = f->count++;
  if (f->fail_at >= 0 && k == f->fail_at) return NULL;
  return malloc(size);
}

static inline void failing_release(void *user, void *p)
{
  (void)user;
  free(p);
}

/* A context whose allocator is `f` (f->fail_at = -1 until the loop arms it). */
static inline fcm_ctx *failing_ctx(failing *f)
{
  fcm_ctx_options o = fcm_ctx_options_default();
  o.allocator.alloc = failing_alloc;
  o.allocator.release = failing_release;
  o.allocator.user = f;
  f->count = 0;
  f->fail_at = -1;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(&o, &ctx) != FCM_OK) return NULL;
  return ctx;
}

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
