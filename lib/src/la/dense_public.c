/* Public dense symmetric spectra (fcm/dense.h): eigenvalues of A or of S A through the
 * congruence L^T A L with S = L L^T, on the internal LAPACK adapter. */
#include "fcm/dense.h"

#include "la/la_impl.h"

#include <math.h>
#include <string.h>

/* B = G^T A G (all n x n, column-major; T is workspace). */
static void congruence(int n, const double *A, const double *G, double *T, double *B)
{
  fcm__gemm('N', 'N', n, n, n, 1.0, A, n, G, n, 0.0, T, n);
  fcm__gemm('T', 'N', n, n, n, 1.0, G, n, T, n, 0.0, B, n);
  for (int j = 0; j < n; j++) /* symmetrize: dsyevd reads the lower triangle */
    for (int i = j + 1; i < n; i++) {
      double v = 0.5 * (B[i + (size_t)j * n] + B[j + (size_t)i * n]);
      B[i + (size_t)j * n] = B[j + (size_t)i * n] = v;
    }
}

fcm_status fcm_dense_spectrum_eval(fcm_ctx *ctx, int n, const double *A, const double *S, double *w,
                                   fcm_dense_spectrum_info *info)
{
  fcm_status st = FCM_OK;
  double *B = NULL, *G = NULL, *T = NULL;
  fcm_dense_spectrum_info inf = {0, 0, 0.0, 0.0, 0.0};
  const double t0 = fcm_wtime();
  FCM_CHECK(A && w, ctx, FCM_ERR_ARG, "dense_spectrum: NULL argument (A %p, w %p)", (const void *)A,
            (void *)w);
  FCM_CHECK(n >= 0 && n <= 46340, ctx, FCM_ERR_ARG,
            "dense_spectrum: n = %d out of range [0, 46340]", n);
  if (n == 0) goto cleanup;
  const size_t nn = (size_t)n * (size_t)n;
  FCM_ALLOC(ctx, nn, B);
  if (!S) {
    memcpy(B, A, nn * sizeof *B);
    FCM_TRY(ctx, fcm__syev(ctx, 0, n, B, n, w));
    goto cleanup;
  }
  FCM_ALLOC(ctx, nn, G);
  FCM_ALLOC(ctx, nn, T);
  memcpy(G, S, nn * sizeof *G);
  st = fcm__potrf(ctx, n, G, n);
  if (st == FCM_OK) {
    inf.cholesky = 1;
    for (int j = 1; j < n; j++) /* dpotrf leaves the strict upper triangle of S */
      memset(G + (size_t)j * n, 0, (size_t)j * sizeof *G);
  } else if (st == FCM_ERR_SINGULAR) {
    fcm_ctx_error_clear(ctx);
    st = FCM_OK;
    memcpy(G, S, nn * sizeof *G);
    FCM_TRY(ctx, fcm__syev(ctx, 1, n, G, n, w)); /* G = V, w = s ascending */
    inf.s_min = w[0];
    inf.s_max = w[n - 1];
    for (int k = 0; k < n; k++) {
      double s = w[k];
      if (!(s > 0.0)) inf.s_nonpositive++;
      s = s > 0.0 ? sqrt(s) : 0.0;
      for (int i = 0; i < n; i++)
        G[i + (size_t)k * n] *= s;
    }
  } else {
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  congruence(n, A, G, T, B);
  FCM_TRY(ctx, fcm__syev(ctx, 0, n, B, n, w));
cleanup:
  fcm__free(ctx, B);
  fcm__free(ctx, G);
  fcm__free(ctx, T);
  inf.time = fcm_wtime() - t0;
  if (info) *info = inf;
  return st;
}
