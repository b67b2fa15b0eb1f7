/* NNLS's matrix-vector products y = A^T x: Q^T a for each column tried (Q column-major), and
 * the gradient A^T r over the candidates in single precision (A's float copy by rows). At
 * NNLS's sizes (M = 27 to 220 rows, Q up to 390 KB, the float candidates up to 1 MB) a call is
 * a few thousand cycles, and a BLAS's kernel for any shape runs them on narrower vectors and
 * with more set-up. Q^T a takes four columns at a time (dgemv_t()); the gradient runs the
 * candidates in the lanes (sgemv_rows()). Compiled as per-CPU clones
 * (core/multiversion.h); without contraction the clones give the same bits as the baseline:
 * the same lanes, sums and order. */
#include "core/multiversion.h"
#include "simplify/simplify_impl.h"

#include <string.h>

#if defined(__GNUC__) && !defined(__clang__)
typedef double fit_v4d __attribute__((vector_size(32)));
typedef long long fit_v4i __attribute__((vector_size(32)));
typedef float fit_v8f __attribute__((vector_size(32)));

/* y[0..n) = A^T x, four columns at a time: each column's products in 4 lanes over the rows (a
 * multiple of 4), the four columns' lanes summed together in two rounds of shuffles, the rows
 * after the last multiple of 4 added in order after that; a column left over likewise alone.
 * Four accumulators of 4 doubles and the row vector fit AVX2's 16 vector registers without
 * spilling, and two rounds of shuffles per four columns cost little against the products even
 * at M = 27. The clones are static: a cloned function's dispatcher would otherwise be exported
 * from the shared library whatever the visibility (the ifunc resolver keeps default
 * visibility), so the module's entry points below only call them. */
FCM_MULTIVERSION_CLONES static void dgemv_t(int m, int n, const double *A, int lda, const double *x,
                                            double *y)
{
  const int m4 = m / 4 * 4;
  const fit_v4i e = {0, 4, 2, 6}, o = {1, 5, 3, 7}, lo = {0, 1, 4, 5}, hi = {2, 3, 6, 7};
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    const double *a0 = A + (size_t)j * (size_t)lda, *a1 = a0 + lda, *a2 = a1 + lda, *a3 = a2 + lda;
    fit_v4d c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, xv, v;
    for (int r = 0; r < m4; r += 4) {
      memcpy(&xv, x + r, sizeof xv);
      memcpy(&v, a0 + r, sizeof v);
      c0 += v * xv;
      memcpy(&v, a1 + r, sizeof v);
      c1 += v * xv;
      memcpy(&v, a2 + r, sizeof v);
      c2 += v * xv;
      memcpy(&v, a3 + r, sizeof v);
      c3 += v * xv;
    }
    const fit_v4d p0 = __builtin_shuffle(c0, c1, e) + __builtin_shuffle(c0, c1, o),
                  p1 = __builtin_shuffle(c2, c3, e) + __builtin_shuffle(c2, c3, o),
                  out = __builtin_shuffle(p0, p1, lo) + __builtin_shuffle(p0, p1, hi);
    double t[4];
    memcpy(t, &out, sizeof t);
    for (int r = m4; r < m; r++)
      t[0] += a0[r] * x[r], t[1] += a1[r] * x[r], t[2] += a2[r] * x[r], t[3] += a3[r] * x[r];
    memcpy(y + j, t, sizeof t);
  }
  for (; j < n; j++) {
    const double *a = A + (size_t)j * (size_t)lda;
    fit_v4d c = {0}, xv, v;
    for (int r = 0; r < m4; r += 4) {
      memcpy(&xv, x + r, sizeof xv);
      memcpy(&v, a + r, sizeof v);
      c += v * xv;
    }
    double t = (c[0] + c[1]) + (c[2] + c[3]);
    for (int r = m4; r < m; r++)
      t += a[r] * x[r];
    y[j] = t;
  }
}

/* y[0..n) = sum over i of x[i] times row i of A (m x n, by rows, leading dimension ldr): the
 * columns side by side in the vectors' lanes, 32 at a time, each lane the sum over the rows in
 * their order. No lane is summed with another, so any vector width gives the scalar loop's bits,
 * and a call costs the multiply-adds alone: no horizontal sums, which at few rows would cost as
 * much as the products. */
FCM_MULTIVERSION_CLONES static void sgemv_rows(int m, int n, const float *A, int ldr,
                                               const float *x, float *y)
{
  int j = 0;
  for (; j + 32 <= n; j += 32) {
    fit_v8f c0 = {0}, c1 = {0}, c2 = {0}, c3 = {0}, a0, a1, a2, a3;
    for (int i = 0; i < m; i++) {
      const float *a = A + (size_t)i * (size_t)ldr + j, t = x[i];
      const fit_v8f xv = {t, t, t, t, t, t, t, t};
      memcpy(&a0, a, sizeof a0);
      memcpy(&a1, a + 8, sizeof a1);
      memcpy(&a2, a + 16, sizeof a2);
      memcpy(&a3, a + 24, sizeof a3);
      c0 += a0 * xv, c1 += a1 * xv, c2 += a2 * xv, c3 += a3 * xv;
    }
    memcpy(y + j, &c0, sizeof c0);
    memcpy(y + j + 8, &c1, sizeof c1);
    memcpy(y + j + 16, &c2, sizeof c2);
    memcpy(y + j + 24, &c3, sizeof c3);
  }
  for (; j + 8 <= n; j += 8) {
    fit_v8f c0 = {0}, a0;
    for (int i = 0; i < m; i++) {
      const float t = x[i];
      const fit_v8f xv = {t, t, t, t, t, t, t, t};
      memcpy(&a0, A + (size_t)i * (size_t)ldr + j, sizeof a0);
      c0 += a0 * xv;
    }
    memcpy(y + j, &c0, sizeof c0);
  }
  for (; j < n; j++) {
    float t = 0.0f;
    for (int i = 0; i < m; i++)
      t += A[(size_t)i * (size_t)ldr + j] * x[i];
    y[j] = t;
  }
}

void fcm__fit_dgemv_t(int m, int n, const double *A, int lda, const double *x, double *y)
{
  dgemv_t(m, n, A, lda, x, y);
}

void fcm__fit_sgemv_rows(int m, int n, const float *A, int ldr, const float *x, float *y)
{
  sgemv_rows(m, n, A, ldr, x, y);
}
#else
void fcm__fit_dgemv_t(int m, int n, const double *A, int lda, const double *x, double *y)
{
  for (int j = 0; j < n; j++) {
    double t = 0.0;
    for (int r = 0; r < m; r++)
      t += A[(size_t)j * (size_t)lda + r] * x[r];
    y[j] = t;
  }
}

void fcm__fit_sgemv_rows(int m, int n, const float *A, int ldr, const float *x, float *y)
{
  for (int j = 0; j < n; j++) {
    float t = 0.0f;
    for (int i = 0; i < m; i++)
      t += A[(size_t)i * (size_t)ldr + j] * x[i];
    y[j] = t;
  }
}
#endif
