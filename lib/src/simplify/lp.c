/* Simplification by one LP on all points (Longva et al. 2020 §4.4.4, eq. 10): the
 * thin SVD P = U S V^T of the M x N moment matrix, then a vertex of V_r^T w = V_r^T w0. */
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

fcm_status fcm__simplify_run_lp(fcm__attempt *a)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  const int n = a->n, M = a->box.num_basis, k = FCM_MIN(M, n);
  double *P = NULL, *vt = NULL, *rhs = NULL, *x = NULL, *work = NULL;
  fcm__lp_report rep;
  int r = 0;

  double t0 = fcm_wtime();
  FCM_ALLOC_RAW(ctx, (size_t)M * (size_t)n, P);
  FCM_ALLOC_RAW(ctx, fcm__simplify_moments_scratch(a->box.m), work);
  fcm__simplify_basis_points(&a->box, n, a->points, P, work);
  fcm__simplify_set_moments(a, n, P, a->w0);
  a->time_basis += fcm_wtime() - t0;

  FCM_ALLOC(ctx, (size_t)k * (size_t)n, vt);
  FCM_TRY(ctx, fcm__simplify_row_space(a, M, n, P, vt, &r));
  FCM_FREE(ctx, P);
  if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  a->rank = r;

  /* V_r^T w0: the first r rows of V^T (ld k). */
  FCM_ALLOC(ctx, (size_t)r, rhs);
  FCM_ALLOC(ctx, (size_t)n, x);
  fcm__gemv('N', r, n, 1.0, vt, k, a->w0, 0.0, rhs);

  t0 = fcm_wtime();
  st = fcm__simplify_lp_solve(ctx, r, n, vt, k, rhs, &a->lp, x, &rep);
  a->time_lp += fcm_wtime() - t0;
  if (st != FCM_OK) {
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  a->num_lps++;
  a->lp_iterations += rep.iterations;
  if (!rep.ok) {
    fcm__simplify_fail(a, rep.reason, "%s", rep.message);
    goto cleanup;
  }

  /* Keep the positive entries of the vertex (at most r of them are basic). */
  fcm__simplify_take_support(a, n, NULL, NULL, x, "LP vertex");
cleanup:
  fcm__free(ctx, P);
  fcm__free(ctx, vt);
  fcm__free(ctx, rhs);
  fcm__free(ctx, x);
  fcm__free(ctx, work);
  return st;
}
