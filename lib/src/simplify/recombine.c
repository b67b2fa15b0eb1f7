/* Simplification by hierarchical recombination (Litterer & Lyons 2012, Maalouf et al.
 * 2019, with an LP or a Carathéodory elimination as the inner step).
 *
 * The active points are cut into K = 2(M+1) contiguous clusters (input order keeps the
 * sub-cells of the initial rule together); each cluster becomes one column g_c =
 * sum_i w_i phi(x_i). A vertex of Q lam = Q 1, lam >= 0, with Q the orthonormal rows of
 * the row space of [g_1 .. g_K], keeps at most rank <= M clusters; their members' weights
 * are multiplied by lam_c and the others dropped. Every round halves the active set at
 * least (M of 2(M+1) clusters survive), so about log2(N/M) rounds reach K points; a last
 * LP on the single points gives the vertex. Each round preserves the moments exactly (up
 * to the LP's accuracy): sum_c lam_c g_c = sum_c g_c. Cost O(N M) for the moments plus
 * small SVDs and LPs, against O(M^2 N) for the full SVD of the plain LP path. */
#include "la/la_impl.h"
#include "simplify/simplify_impl.h"

#include <string.h>

/* The basis is evaluated once at every point and kept when it takes at most this many
 * doubles (8 MiB); above, each round evaluates it again at the active points (measured:
 * tests/simplify/bench_simplify.c). */
#define RECOMBINE_CACHE_MAX ((size_t)1 << 20)

/* Solve Q lam = Q 1, lam >= 0 for the rows x cols matrix g (destroyed, ld rows). */
static fcm_status cluster_lp(fcm__attempt *a, int rows, int cols, double *g, double *q, double *rhs,
                             double *lam)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  fcm__lp_report rep;
  const int k = FCM_MIN(rows, cols);
  int r = 0;
  if (a->eliminate) { /* lam = 1 is feasible: eliminate from there */
    for (int c = 0; c < cols; c++)
      lam[c] = 1.0;
    return fcm__simplify_reduce(a, rows, cols, g, q, lam);
  }
  FCM_TRY(ctx, fcm__simplify_row_space(a, rows, cols, g, q, &r));
  if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  a->rank = r;
  for (int i = 0; i < r; i++) {
    double s = 0.0;
    for (int c = 0; c < cols; c++)
      s += q[i + (size_t)c * (size_t)k];
    rhs[i] = s;
  }
  const double t0 = fcm_wtime();
  st = fcm__simplify_lp_solve(ctx, r, cols, q, k, rhs, &a->lp, lam, &rep);
  a->time_lp += fcm_wtime() - t0;
  if (st != FCM_OK) {
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  a->num_lps++;
  a->lp_iterations += rep.iterations;
  if (!rep.ok) fcm__simplify_fail(a, rep.reason, "%s", rep.message);
cleanup:
  return st;
}

fcm_status fcm__simplify_run_recombine(fcm__attempt *a)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = a->ctx;
  const int n = a->n, M = a->box.num_basis, K = 2 * (M + 1);
  int *idx = NULL, nact = 0;
  double *cw = NULL, *g = NULL, *q = NULL, *rhs = NULL, *lam = NULL, *acc = NULL, *phi = NULL;

  FCM_ALLOC(ctx, (size_t)n, idx);
  FCM_ALLOC(ctx, (size_t)n, cw);
  FCM_ALLOC(ctx, (size_t)M * (size_t)K, g);
  FCM_ALLOC(ctx, (size_t)M * (size_t)K, q);
  FCM_ALLOC(ctx, (size_t)M, rhs);
  FCM_ALLOC(ctx, (size_t)K, lam);
  FCM_ALLOC(ctx, fcm__simplify_moments_scratch(a->box.m), acc);
  if ((size_t)n * (size_t)M <= RECOMBINE_CACHE_MAX) { /* the basis at every point, once */
    double t0 = fcm_wtime();
    FCM_ALLOC_RAW(ctx, (size_t)n * (size_t)M, phi);
    fcm__simplify_basis_points(&a->box, n, a->points, phi, acc);
    a->time_basis += fcm_wtime() - t0;
  }
  for (int j = 0; j < n; j++)
    if (a->w0[j] > 0.0) {
      idx[nact] = j;
      cw[nact++] = a->w0[j];
    }

  while (nact > K) {
    a->rounds++;
    double t0 = fcm_wtime();
    for (int c = 0; c < K; c++) {
      const int lo = (int)((long long)c * nact / K), hi = (int)((long long)(c + 1) * nact / K);
      double *gc = g + (size_t)c * (size_t)M;
      if (phi) {
        for (int p = 0; p < M; p++)
          gc[p] = 0.0;
        for (int i = lo; i < hi; i++) {
          const double *restrict f = phi + (size_t)idx[i] * (size_t)M, wi = cw[i];
          for (int p = 0; p < M; p++)
            gc[p] += wi * f[p];
        }
      } else {
        fcm__simplify_moments(&a->box, hi - lo, a->points, idx + lo, cw + lo, gc, acc);
      }
    }
    fcm__simplify_set_moments(a, K, g, NULL); /* the first round sees every point */
    a->time_basis += fcm_wtime() - t0;
    FCM_TRY(ctx, cluster_lp(a, M, K, g, q, rhs, lam));
    if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;

    int kept = 0;
    for (int c = 0; c < K; c++) {
      const int lo = (int)((long long)c * nact / K), hi = (int)((long long)(c + 1) * nact / K);
      if (!(lam[c] > 0.0)) continue;
      for (int i = lo; i < hi; i++) {
        idx[kept] = idx[i];
        cw[kept++] = cw[i] * lam[c];
      }
    }
    if (kept == 0 || kept >= nact) {
      fcm__simplify_fail(a, FCM_SIMPLIFY_REASON_NO_PROGRESS,
                         "recombination round %d kept %d of %d points", a->rounds, kept, nact);
      goto cleanup;
    }
    nact = kept;
  }

  /* The final LP on single points (columns scaled by their current weights). */
  double t0 = fcm_wtime();
  for (int i = 0; i < nact; i++) {
    double *gi = g + (size_t)i * (size_t)M;
    if (phi)
      memcpy(gi, phi + (size_t)idx[i] * (size_t)M, sizeof *gi * (size_t)M);
    else
      fcm__simplify_basis_eval(&a->box, a->points + 3 * (size_t)idx[i], gi);
    for (int p = 0; p < M; p++)
      gi[p] *= cw[i];
  }
  fcm__simplify_set_moments(a, nact, g, NULL); /* when no round ran */
  a->time_basis += fcm_wtime() - t0;
  FCM_TRY(ctx, cluster_lp(a, M, nact, g, q, rhs, lam));
  if (a->reason != FCM_SIMPLIFY_REASON_NONE) goto cleanup;
  fcm__simplify_take_support(a, nact, idx, cw, lam, "final step");
cleanup:
  fcm__free(ctx, idx);
  fcm__free(ctx, cw);
  fcm__free(ctx, g);
  fcm__free(ctx, q);
  fcm__free(ctx, rhs);
  fcm__free(ctx, lam);
  fcm__free(ctx, acc);
  fcm__free(ctx, phi);
  return st;
}
