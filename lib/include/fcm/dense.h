/* fcm — dense symmetric spectra for studies and tests: the eigenvalues of a small dense
 * symmetric matrix A, or of S A (= those of S^{1/2} A S^{1/2}) for a symmetric positive
 * definite preconditioner S, e.g. to measure condition numbers kappa(S A) (Longva §5.4). */
#ifndef FCM_DENSE_H
#define FCM_DENSE_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** How fcm_dense_spectrum_eval() went. */
typedef struct fcm_dense_spectrum_info {
  int cholesky;        /**< 1: S = L L^T by Cholesky; 0: by an eigendecomposition of S
                            (Cholesky failed, S numerically semi-definite), or S NULL */
  int s_nonpositive;   /**< eigenvalues of S <= 0 (rounding) used as 0 (fallback only) */
  double s_min, s_max; /**< extreme eigenvalues of S (fallback only; else 0) */
  double time;         /**< wall-clock seconds */
} fcm_dense_spectrum_info;

/** Eigenvalues of S A for symmetric A and symmetric positive definite S, computed as the
 * spectrum of the symmetric B = L^T A L with S = L L^T (Cholesky); if the Cholesky factor
 * fails, S = V diag(s) V^T and B = G^T A G with G = V diag(sqrt(max(s, 0))). S == NULL:
 * the eigenvalues of A. LAPACK dpotrf/dsyevd and BLAS dgemm, O(n^3) flops, 3 n^2 doubles.
 * @param[in]  n    order, 0 <= n <= 46340 (n^2 fits an int)
 * @param[in]  A    n x n, both triangles stored (symmetric, so row- and column-major agree)
 * @param[in]  S    n x n as A, or NULL
 * @param[out] w    n eigenvalues, ascending
 * @param[out] info may be NULL
 * @return FCM_OK, FCM_ERR_ARG (NULL, n out of range), FCM_ERR_NUMERIC (NaN/Inf in A or S),
 *         FCM_ERR_LAPACK (no convergence), FCM_ERR_ALLOC. Allocates workspace; thread safe
 *         for distinct outputs (BLAS threads as configured). */
FCM_API fcm_status fcm_dense_spectrum_eval(fcm_ctx *ctx, int n, const double *A, const double *S,
                                           double *w, fcm_dense_spectrum_info *info);

#ifdef __cplusplus
}
#endif
#endif /* FCM_DENSE_H */
