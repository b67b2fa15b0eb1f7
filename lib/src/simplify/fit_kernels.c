/* NNLS's matrix-vector products y = A^T x (A column-major): Q^T a for each column tried, and
 * the gradient A^T r over the candidates in single precision. At NNLS's sizes (M = 120 rows,
 * Q 115 KB and the float candidates 300 KB, both from L2) a call is a few thousand cycles, and
 * a BLAS's kernel for any shape runs them on narrower vectors and with more set-up: these
 * take eight columns at a time, each an accumulator of 8 doubles or 16 floats over the rows,
 * and sum the accumulators' lanes together in one tree of shuffles. Compiled as per-CPU clones
 * (core/multiversion.h); without contraction the clones give the same bits as the baseline:
 * the same lanes, sums and order. */
#include "core/multiversion.h"
#include "simplify/simplify_impl.h"

#include <string.h>

#if defined(__GNUC__) && !defined(__clang__)
typedef double fit_v8d __attribute__((vector_size(64)));
typedef long long fit_v8i __attribute__((vector_size(64)));
typedef float fit_v16f __attribute__((vector_size(64)));
typedef float fit_v8f __attribute__((vector_size(32)));
typedef int fit_v8fi __attribute__((vector_size(32)));

/* The lanes' sums of eight vectors, lane j of the result the sum of c[j]: pairs interleaved,
 * then quadruples, then the halves. */
#define FIT_TREE(V, I, c, out)                                                                     \
  do {                                                                                             \
    const I e_ = {0, 8, 2, 10, 4, 12, 6, 14}, o_ = {1, 9, 3, 11, 5, 13, 7, 15};                    \
    const I lo_ = {0, 1, 8, 9, 4, 5, 12, 13}, hi_ = {2, 3, 10, 11, 6, 7, 14, 15};                  \
    const I l4_ = {0, 1, 2, 3, 8, 9, 10, 11}, h4_ = {4, 5, 6, 7, 12, 13, 14, 15};                  \
    V p_[4], q_[2];                                                                                \
    for (int t_ = 0; t_ < 4; t_++)                                                                 \
      p_[t_] = __builtin_shuffle(c[2 * t_], c[2 * t_ + 1], e_) +                                   \
               __builtin_shuffle(c[2 * t_], c[2 * t_ + 1], o_);                                    \
    for (int t_ = 0; t_ < 2; t_++)                                                                 \
      q_[t_] = __builtin_shuffle(p_[2 * t_], p_[2 * t_ + 1], lo_) +                                \
               __builtin_shuffle(p_[2 * t_], p_[2 * t_ + 1], hi_);                                 \
    out = __builtin_shuffle(q_[0], q_[1], l4_) + __builtin_shuffle(q_[0], q_[1], h4_);             \
  } while (0)

/* y[0..8) = A[:, 0..8)^T x over rows [0, m8) (a multiple of 8), the rest of the rows added
 * after the vector sums. */
static inline __attribute__((always_inline)) void dcols8(int m, const double *A, int lda,
                                                         const double *x, double *y)
{
  const int m8 = m / 8 * 8;
  fit_v8d c[8] = {{0}}, xv, a, out;
  for (int r = 0; r < m8; r += 8) {
    memcpy(&xv, x + r, sizeof xv);
    for (int j = 0; j < 8; j++) {
      memcpy(&a, A + (size_t)j * (size_t)lda + r, sizeof a);
      c[j] += a * xv;
    }
  }
  FIT_TREE(fit_v8d, fit_v8i, c, out);
  for (int j = 0; j < 8; j++) {
    double t = out[j];
    for (int r = m8; r < m; r++)
      t += A[(size_t)j * (size_t)lda + r] * x[r];
    y[j] = t;
  }
}

/* The clones are static: a cloned function's dispatcher would otherwise be exported from the
 * shared library whatever the visibility (the ifunc resolver keeps default visibility), so the
 * module's entry points below only call them. */
FCM_MULTIVERSION_CLONES static void dgemv_t(int m, int n, const double *A, int lda, const double *x,
                                            double *y)
{
  int j = 0;
  for (; j + 8 <= n; j += 8)
    dcols8(m, A + (size_t)j * (size_t)lda, lda, x, y + j);
  for (; j < n; j++) {
    const double *a = A + (size_t)j * (size_t)lda;
    double t = 0.0;
    for (int r = 0; r < m; r++)
      t += a[r] * x[r];
    y[j] = t;
  }
}

/* As dcols8() in single precision, rows in vectors of 16 (m a multiple of 16: the caller pads). */
static inline __attribute__((always_inline)) void scols8(int m, const float *A, int lda,
                                                         const float *x, float *y)
{
  fit_v16f c[8] = {{0}}, xv, a;
  for (int r = 0; r < m; r += 16) {
    memcpy(&xv, x + r, sizeof xv);
    for (int j = 0; j < 8; j++) {
      memcpy(&a, A + (size_t)j * (size_t)lda + r, sizeof a);
      c[j] += a * xv;
    }
  }
  fit_v8f h[8], out;
  for (int j = 0; j < 8; j++) {
    fit_v8f l, u;
    memcpy(&l, &c[j], sizeof l);
    memcpy(&u, (const float *)&c[j] + 8, sizeof u);
    h[j] = l + u;
  }
  FIT_TREE(fit_v8f, fit_v8fi, h, out);
  memcpy(y, &out, sizeof out);
}

FCM_MULTIVERSION_CLONES static void sgemv_t(int m, int n, const float *A, int lda, const float *x,
                                            float *y)
{
  int j = 0;
  for (; j + 8 <= n; j += 8)
    scols8(m, A + (size_t)j * (size_t)lda, lda, x, y + j);
  for (; j < n; j++) {
    const float *a = A + (size_t)j * (size_t)lda;
    float t = 0.0f;
    for (int r = 0; r < m; r++)
      t += a[r] * x[r];
    y[j] = t;
  }
}

void fcm__fit_dgemv_t(int m, int n, const double *A, int lda, const double *x, double *y)
{
  dgemv_t(m, n, A, lda, x, y);
}

void fcm__fit_sgemv_t(int m, int n, const float *A, int lda, const float *x, float *y)
{
  sgemv_t(m, n, A, lda, x, y);
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

void fcm__fit_sgemv_t(int m, int n, const float *A, int lda, const float *x, float *y)
{
  for (int j = 0; j < n; j++) {
    float t = 0.0f;
    for (int r = 0; r < m; r++)
      t += A[(size_t)j * (size_t)lda + r] * x[r];
    y[j] = t;
  }
}
#endif
