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

/* The NNLS polish works on at most this many columns (5 M for M <= 84, strength 6). */
#define FCM__FIT_MAX_PASSIVE 420

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

/* Non-negative least squares min ||A x - b||, x >= 0 (Lawson and Hanson 1974, ch. 23): A is
 * M x k (ld M), x (k) receives the solution, whose positive entries are the columns of its
 * passive set (linearly independent: at most M). Least squares on the passive set through
 * fcm__lstsq; at most 3 k outer steps. */
static fcm_status nnls(fcm_ctx *ctx, int M, int k, const double *A, const double *b, double *x)
{
  fcm_status st = FCM_OK;
  const int ld = FCM_MAX(M, k);
  double *r = NULL, *Ap = NULL, *z = NULL;
  int *pass = NULL, np = 0;
  FCM_ALLOC(ctx, (size_t)M, r);
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, Ap);
  FCM_ALLOC(ctx, (size_t)ld, z);
  FCM_ALLOC(ctx, (size_t)k, pass);
  double bmax = 0.0, amax = 0.0;
  for (int i = 0; i < M; i++)
    bmax = fmax(bmax, fabs(b[i]));
  for (size_t i = 0; i < (size_t)M * (size_t)k; i++)
    amax = fmax(amax, fabs(A[i]));
  const double wtol = 1e-13 * amax * bmax;
  memset(x, 0, (size_t)k * sizeof *x);
  for (int outer = 0; outer < 3 * k; outer++) {
    memcpy(r, b, (size_t)M * sizeof *r); /* r = b - A x */
    fcm__gemv('N', M, k, -1.0, A, M, x, 1.0, r);
    int t = -1;
    double wbest = wtol;
    for (int j = 0; j < k; j++) { /* the most promising column outside the passive set */
      if (pass[j]) continue;
      double w = 0.0;
      for (int i = 0; i < M; i++)
        w += A[i + (size_t)j * (size_t)M] * r[i];
      if (w > wbest) wbest = w, t = j;
    }
    if (t < 0) break;
    pass[t] = 1, np++;
    for (int inner = 0; inner < k; inner++) {
      int c = 0, idx[FCM__FIT_MAX_PASSIVE];
      for (int j = 0; j < k && c < FCM__FIT_MAX_PASSIVE; j++)
        if (pass[j]) {
          idx[c] = j;
          memcpy(Ap + (size_t)c * (size_t)M, A + (size_t)j * (size_t)M, (size_t)M * sizeof *Ap);
          c++;
        }
      memcpy(z, b, (size_t)M * sizeof *z);
      st = fcm__lstsq(ctx, M, c, 1, Ap, M, z, ld, -1.0, NULL);
      if (st != FCM_OK) goto cleanup;
      double alpha = 1.0;
      int neg = 0;
      for (int q = 0; q < c; q++)
        if (!(z[q] > 0.0)) {
          neg = 1;
          const double xi = x[idx[q]], d = xi - z[q];
          if (d > 0.0) alpha = fmin(alpha, xi / d);
        }
      if (!neg) {
        for (int q = 0; q < c; q++)
          x[idx[q]] = z[q];
        break;
      }
      for (int q = 0; q < c; q++) { /* step towards z until a weight reaches 0; drop those */
        const int j = idx[q];
        x[j] += alpha * (z[q] - x[j]);
        if (!(x[j] > 1e-15 * bmax)) x[j] = 0.0, pass[j] = 0, np--;
      }
    }
  }
cleanup:
  fcm__free(ctx, r);
  fcm__free(ctx, Ap);
  fcm__free(ctx, z);
  fcm__free(ctx, pass);
  return st;
}

/* After a failed re-fit: NNLS on the vertex's support and up to 4 M other candidates spread
 * over the list (a degenerate vertex has fewer than M positive weights, which no re-fit on
 * its support can make exact). */
static fcm_status polish(fcm_ctx *ctx, int M, int n, const double *P, fcm__fit *f, const double *b,
                         double scale, double tol, double floor, int *ok)
{
  fcm_status st = FCM_OK;
  const int extra = FCM_MIN(n, 4 * M), k0 = f->count;
  int *sel = NULL, k = 0;
  unsigned char *in = NULL;
  double *A = NULL, *x = NULL, *bs = NULL;
  *ok = 0;
  FCM_ALLOC(ctx, (size_t)(k0 + extra), sel);
  FCM_ALLOC(ctx, (size_t)n, in);
  for (int c = 0; c < k0; c++)
    sel[k++] = f->idx[c], in[f->idx[c]] = 1;
  for (int i = 0; i < extra; i++) {
    const int j = (int)(((long long)i * n) / extra);
    if (!in[j]) sel[k++] = j, in[j] = 1;
  }
  FCM_ALLOC(ctx, (size_t)M * (size_t)k, A);
  FCM_ALLOC(ctx, (size_t)k, x);
  FCM_ALLOC(ctx, (size_t)M, bs);
  for (int c = 0; c < k; c++)
    memcpy(A + (size_t)c * (size_t)M, P + (size_t)sel[c] * (size_t)M, (size_t)M * sizeof *A);
  for (int i = 0; i < M; i++)
    bs[i] = scale * b[i];
  FCM_TRY(ctx, nnls(ctx, M, FCM_MIN(k, FCM__FIT_MAX_PASSIVE), A, bs, x));
  int count = 0, idx[FCM__FIT_MAX_PASSIVE];
  double w[FCM__FIT_MAX_PASSIVE];
  for (int c = 0; c < FCM_MIN(k, FCM__FIT_MAX_PASSIVE); c++)
    if (x[c] > 0.0 && count < M) idx[count] = sel[c], w[count++] = x[c] / scale;
  const double r = fit_residual(M, P, count, idx, w, b, floor);
  if (count > 0 && count <= M && r <= tol) {
    /* ascending candidate order, as the LP's support */
    for (int a = 1; a < count; a++)
      for (int c = a; c > 0 && idx[c - 1] > idx[c]; c--) {
        const int ti = idx[c];
        const double tw = w[c];
        idx[c] = idx[c - 1], w[c] = w[c - 1];
        idx[c - 1] = ti, w[c - 1] = tw;
      }
    memcpy(f->idx, idx, (size_t)count * sizeof *idx);
    memcpy(f->w, w, (size_t)count * sizeof *w);
    f->count = count;
    f->residual = r;
    *ok = 1;
  }
cleanup:
  fcm__free(ctx, sel);
  fcm__free(ctx, in);
  fcm__free(ctx, A);
  fcm__free(ctx, x);
  fcm__free(ctx, bs);
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
    if (!ok && M <= FCM__FIT_MAX_PASSIVE / 5)
      FCM_TRY(ctx, polish(ctx, M, n, P, f, b, scale, tol, floor, &ok));
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
