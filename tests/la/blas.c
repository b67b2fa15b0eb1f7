/* fcm__gemm and fcm__gemv against naive triple loops, for every transpose
 * combination, padded leading dimensions, alpha/beta and degenerate sizes. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

#define LD_PAD 3

/* op(A)(i, l) of a column-major matrix stored with leading dimension lda. */
static double op_at(char t, const double *a, int lda, int i, int l)
{
  return (t == 'T') ? a[l + (size_t)i * lda] : a[i + (size_t)l * lda];
}

int main(void)
{
  rng r = {0x9e3779b97f4a7c15ULL};
  const int sizes[][3] = {{1, 1, 1}, {3, 4, 5}, {7, 2, 9}, {17, 13, 11}, {32, 1, 20}, {5, 6, 0}};
  const char ts[2] = {'N', 'T'};
  for (size_t c = 0; c < sizeof sizes / sizeof sizes[0]; c++) {
    int m = sizes[c][0], n = sizes[c][1], k = sizes[c][2];
    for (int ta = 0; ta < 2; ta++)
      for (int tb = 0; tb < 2; tb++) {
        char opa = ts[ta], opb = ts[tb];
        /* A is m x k (or k x m stored), B is k x n (or n x k stored). */
        int ar = opa == 'N' ? m : k, ac = opa == 'N' ? k : m;
        int br = opb == 'N' ? k : n, bc = opb == 'N' ? n : k;
        int lda = ar + LD_PAD, ldb = br + LD_PAD, ldc = m + LD_PAD;
        double *a = calloc((size_t)lda * (ac ? ac : 1), sizeof *a);
        double *b = calloc((size_t)ldb * (bc ? bc : 1), sizeof *b);
        double *cm = calloc((size_t)ldc * n, sizeof *cm),
               *ref = calloc((size_t)ldc * n, sizeof *ref);
        for (int i = 0; i < lda * ac; i++)
          a[i] = rng_uniform(&r);
        for (int i = 0; i < ldb * bc; i++)
          b[i] = rng_uniform(&r);
        for (int i = 0; i < ldc * n; i++)
          cm[i] = ref[i] = rng_uniform(&r);
        const double alpha = 0.75, beta = -1.25;
        for (int j = 0; j < n; j++)
          for (int i = 0; i < m; i++) {
            double s = 0.0;
            for (int l = 0; l < k; l++)
              s += op_at(opa, a, lda, i, l) * op_at(opb, b, ldb, l, j);
            ref[i + j * ldc] = alpha * s + beta * ref[i + j * ldc];
          }
        fcm__gemm(opa, opb, m, n, k, alpha, a, lda, b, ldb, beta, cm, ldc);
        for (int j = 0; j < n; j++)
          for (int i = 0; i < ldc; i++) /* padding rows must be untouched too */
            TEST_NEAR(cm[i + j * ldc], ref[i + j * ldc], 1e-14, 1e-14 * (k + 1));

        /* GEMV with op(A) of size m x k: y = alpha op(A) x + beta y. */
        int xlen = k, ylen = m;
        double *x = calloc((size_t)(xlen ? xlen : 1), sizeof *x);
        double *y = calloc((size_t)ylen, sizeof *y), *yref = calloc((size_t)ylen, sizeof *yref);
        for (int i = 0; i < xlen; i++)
          x[i] = rng_uniform(&r);
        for (int i = 0; i < ylen; i++)
          y[i] = yref[i] = rng_uniform(&r);
        for (int i = 0; i < m; i++) {
          double s = 0.0;
          for (int l = 0; l < k; l++)
            s += op_at(opa, a, lda, i, l) * x[l];
          yref[i] = alpha * s + beta * yref[i];
        }
        /* fcm__gemv takes the stored matrix's size (ar x ac) and the transpose flag. */
        if (ar > 0 && ac > 0) {
          fcm__gemv(opa, ar, ac, alpha, a, lda, x, beta, y);
          for (int i = 0; i < m; i++)
            TEST_NEAR(y[i], yref[i], 1e-14, 1e-14 * (k + 1));
        }
        free(a), free(b), free(cm), free(ref), free(x), free(y), free(yref);
      }
  }

  /* m == 0 or n == 0: nothing is touched. */
  double c0 = 42.0, one = 1.0;
  fcm__gemm('N', 'N', 0, 1, 1, 1.0, &one, 1, &one, 1, 0.0, &c0, 1);
  fcm__gemm('N', 'N', 1, 0, 1, 1.0, &one, 1, &one, 1, 0.0, &c0, 1);
  fcm__gemv('N', 0, 1, 1.0, &one, 1, &one, 0.0, &c0);
  TEST_TRUE(c0 == 42.0);
  return TEST_RESULT();
}
