/* Moment fitting: a positive rule of at most M points chosen among candidate points, whose
 * moments equal given ones (computed elsewhere, e.g. exactly from a boundary surface). The
 * moment matrix P (M x n) of the candidates is reduced to its row space by a thin SVD,
 * P = U S V^T, and one LP finds a vertex of {w >= 0 : V_r^T w = S_r^-1 U_r^T b}, which has at
 * most r <= M positive entries; the weights are then verified (and re-fitted on their support
 * by least squares when the vertex misses the tolerance) against P w = b. */
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

#include <math.h>
#include <string.h>

/* Singular values of the candidates' moment matrix below this fraction of the largest are
 * dropped: the moments given carry rounding, and dividing it by a tiny singular value would
 * make the LP's right-hand side noise. What is dropped is checked by the residual. */
#define FIT_RANK_TOL 1e-11

/* max_i |(P_S w)_i - b_i| / max(max_i |b_i|, atol / tol) over the support S (columns idx of P,
 * ld M): relative to the moments, or to the floor below which they are rounding. */
static double fit_residual(int M, const double *P, int count, const int *idx, const double *w,
                           const double *b, double floor)
{
  double num = 0.0, den = 0.0;
  for (int i = 0; i < M; i++) {
    double s = 0.0;
    for (int c = 0; c < count; c++)
      s += P[i + (size_t)idx[c] * (size_t)M] * w[c];
    num = fmax(num, fabs(s - b[i]));
    den = fmax(den, fabs(b[i]));
  }
  den = fmax(den, floor);
  const double r = den > 0.0 ? num / den : num;
  return isnan(r) ? INFINITY : r;
}

/* Least squares on the support; 1 when the weights come out positive and verify. */
static fcm_status refit(fcm_ctx *ctx, int M, const double *P, fcm__fit *f, const double *b,
                        double tol, double floor, int *ok)
{
  fcm_status st = FCM_OK;
  const int k = f->count, ld = FCM_MAX(M, k);
  double *A = NULL, *x = NULL;
  *ok = 0;
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, A);
  FCM_ALLOC(ctx, (size_t)ld, x);
  for (int c = 0; c < k; c++)
    memcpy(A + (size_t)c * (size_t)M, P + (size_t)f->idx[c] * (size_t)M, (size_t)M * sizeof *A);
  memcpy(x, b, (size_t)M * sizeof *x);
  st = fcm__lstsq(ctx, M, k, 1, A, M, x, ld, -1.0, NULL);
  if (st == FCM_ERR_ALLOC) goto cleanup;
  if (st != FCM_OK) { /* a failed least-squares solve is a failed re-fit, not an error */
    st = FCM_OK;
    goto cleanup;
  }
  for (int c = 0; c < k; c++)
    if (!(x[c] > 0.0) || !isfinite(x[c])) goto cleanup;
  const double r = fit_residual(M, P, k, f->idx, x, b, floor);
  if (r <= tol) {
    memcpy(f->w, x, (size_t)k * sizeof *x);
    f->residual = r;
    *ok = 1;
  }
cleanup:
  fcm__free(ctx, A);
  fcm__free(ctx, x);
  return st;
}

fcm_status fcm__simplify_fit(fcm_ctx *ctx, const fcm__cheb_box *box, int n, const double *pts,
                             const double *b, double tol, double atol, fcm__fit *f)
{
  fcm_status st = FCM_OK;
  const int M = box->num_basis, k = FCM_MIN(M, n);
  double *P = NULL, *G = NULL, *s = NULL, *u = NULL, *vt = NULL, *rhs = NULL, *x = NULL,
         *work = NULL;
  fcm__lp_report rep;
  f->count = 0;
  f->ok = 0;
  f->residual = INFINITY;
  f->message[0] = '\0';
  if (n < 1) {
    snprintf(f->message, sizeof f->message, "no candidate points");
    return FCM_OK;
  }
  FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)n, P);
  FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)n, G);
  FCM_ALLOC_RAW(ctx, fcm__simplify_moments_scratch(box->m), work);
  fcm__simplify_basis_points(box, n, pts, P, work);
  memcpy(G, P, (size_t)M * (size_t)n * sizeof *G);
  FCM_ALLOC(ctx, (size_t)k, s);
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, u);
  FCM_ALLOC(ctx, (size_t)k * (size_t)n, vt);
  st = fcm__gesvd(ctx, M, n, G, M, s, u, M, vt, k);
  if (st == FCM_ERR_ALLOC) goto cleanup;
  if (st != FCM_OK || !(s[0] > 0.0) || !isfinite(s[0])) {
    st = FCM_OK;
    snprintf(f->message, sizeof f->message, "SVD of the candidates' moment matrix failed");
    goto cleanup;
  }
  int r = 0;
  while (r < k && s[r] > FIT_RANK_TOL * s[0])
    r++;
  FCM_ALLOC(ctx, (size_t)r, rhs);
  FCM_ALLOC(ctx, (size_t)n, x);
  /* weights of mean 1 for the LP (its tolerances are absolute): b scaled by n / b_0, b_0 being
   * the measure's total (the basis' first function is 1) */
  const double scale = b[0] > 0.0 ? n / b[0] : 1.0;
  for (int i = 0; i < r; i++) {
    double t = 0.0;
    for (int j = 0; j < M; j++)
      t += u[j + (size_t)i * (size_t)M] * b[j];
    rhs[i] = scale * t / s[i];
  }
  const fcm__lp_params prm = {20 * M + 1000, 0.0, 0};
  FCM_TRY(ctx, fcm__simplify_lp_solve(ctx, r, n, vt, k, rhs, &prm, x, &rep));
  if (!rep.ok) {
    snprintf(f->message, sizeof f->message, "no positive combination of the %d candidates: %.100s",
             n, rep.message);
    goto cleanup;
  }
  for (int j = 0; j < n; j++)
    if (x[j] > 0.0) {
      if (f->count == M) {
        snprintf(f->message, sizeof f->message, "LP vertex has more than M = %d points", M);
        goto cleanup;
      }
      f->idx[f->count] = j;
      f->w[f->count++] = x[j] / scale;
    }
  const double floor = atol / tol;
  f->residual = fit_residual(M, P, f->count, f->idx, f->w, b, floor);
  if (f->residual <= tol) {
    f->ok = 1;
  } else {
    int ok;
    FCM_TRY(ctx, refit(ctx, M, P, f, b, tol, floor, &ok));
    f->ok = ok;
    if (!ok)
      snprintf(f->message, sizeof f->message, "moment residual %.3g above %.3g (rank %d of %d)",
               f->residual, tol, r, M);
  }
cleanup:
  fcm__free(ctx, P);
  fcm__free(ctx, G);
  fcm__free(ctx, s);
  fcm__free(ctx, u);
  fcm__free(ctx, vt);
  fcm__free(ctx, rhs);
  fcm__free(ctx, x);
  fcm__free(ctx, work);
  return st;
}
