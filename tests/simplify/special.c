/* Special inputs, every path (LP, recombination, elimination): N <= M returns the rule unchanged;
 * coplanar points (on an axis plane: degenerate box axis; on a tilted plane: rank-deficient P) give
 * a valid rule of at most (m+2 choose 2) points; a slab 1e-9 thick (box-scaled, full rank) a valid
 * rule of at most M; weights of scale 1e-14 and 1e+14 (normalized before the LP) valid rules;
 * points of zero weight are never kept. */
#include "simplify_util.h"

#define RTOL 1e-12

static void simplify(fcm_ctx *ctx, fcm_simplify_method method, int m, int n, const double *pts,
                     const double *w, fcm_simplify_result *res, fcm_simplify_info *info)
{
  fcm_simplify_options o = fcm_simplify_options_default();
  o.method = method;
  TEST_OK(ctx, fcm_simplify(ctx, m, n, pts, w, &o, res, info));
  if (info->fallback)
    TEST_FAIL_("m=%d N=%d %s fell back: %s", m, n, fcm_simplify_method_name(method), info->message);
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const double lo[3] = {-0.9, -0.7, -0.5};
  enum { NMAX = 2000 };
  double *pts = malloc(3 * NMAX * sizeof *pts), *w = malloc(NMAX * sizeof *w);
  double *w2 = malloc(NMAX * sizeof *w2);
  char label[96];

  for (int mi = FCM_SIMPLIFY_LP; mi < FCM_SIMPLIFY_METHOD_COUNT; mi++) {
    const fcm_simplify_method method = (fcm_simplify_method)mi;
    const char *name = fcm_simplify_method_name(method);
    fcm_simplify_result res;
    fcm_simplify_info info;

    /* N <= M: unchanged, not a fallback. */
    for (int n = 1; n <= 20; n += 19) {
      util_random_box(7, n, lo, 1.5, 1.0, pts, w);
      simplify(ctx, method, 3, n, pts, w, &res, &info);
      TEST_TRUE(info.skipped == 1 && info.fallback == 0 && res.count == n && info.kept == n);
      for (int j = 0; j < res.count; j++)
        TEST_TRUE(res.indices[j] == j && res.weights[j] == w[j]);
      fcm_simplify_result_destroy(&res);
    }

    for (int m = 1; m <= 6; m++) {
      const int M = util_num_basis(m), M2 = (m + 1) * (m + 2) / 2, n = 3 * M + 11;
      /* Coplanar on z = 0.25 (degenerate box axis) and on x + 2y + 3z = 0.7 (tilted). */
      for (int tilted = 0; tilted <= 1; tilted++) {
        util_random_box(100 + (uint64_t)m, n, lo, 1.5, 1.0, pts, w);
        for (int j = 0; j < n; j++)
          pts[3 * j + 2] = tilted ? (0.7 - pts[3 * j] - 2.0 * pts[3 * j + 1]) / 3.0 : 0.25;
        simplify(ctx, method, m, n, pts, w, &res, &info);
        snprintf(label, sizeof label, "%s plane m=%d %s", tilted ? "tilted" : "axis", m, name);
        TEST_TRUE(info.rank == M2); /* P restricted to a plane: the 2-D polynomial space */
        util_check(label, m, n, pts, w, &res, M2, RTOL);
        fcm_simplify_result_destroy(&res);
      }

      /* A slab 1e-9 thick: the box scaling keeps the full-rank basis well conditioned. */
      util_random_box(300 + (uint64_t)m, n, lo, 1.5, 1.0, pts, w);
      for (int j = 0; j < n; j++)
        pts[3 * j + 2] = 0.3 + 1e-9 * pts[3 * j + 2];
      simplify(ctx, method, m, n, pts, w, &res, &info);
      snprintf(label, sizeof label, "thin slab m=%d %s", m, name);
      util_check(label, m, n, pts, w, &res, M, RTOL);
      fcm_simplify_result_destroy(&res);

      /* Tiny and huge weights (unnormalized, GLPK would return w = 0 for tiny ones). */
      util_random_box(200 + (uint64_t)m, n, lo, 1.5, 1.0, pts, w);
      simplify(ctx, method, m, n, pts, w, &res, &info);
      util_check("unit weights", m, n, pts, w, &res, M, RTOL);
      for (int e = -14; e <= 14; e += 28) {
        fcm_simplify_result r2;
        const double f = pow(10.0, e);
        for (int j = 0; j < n; j++)
          w2[j] = w[j] * f;
        simplify(ctx, method, m, n, pts, w2, &r2, &info);
        snprintf(label, sizeof label, "weights 1e%+d m=%d %s", e, m, name);
        util_check(label, m, n, pts, w2, &r2, M, RTOL);
        fcm_simplify_result_destroy(&r2);
      }
      fcm_simplify_result_destroy(&res);

      /* Every other weight zero: those points are never kept. */
      for (int j = 0; j < n; j += 2)
        w[j] = 0.0;
      simplify(ctx, method, m, n, pts, w, &res, &info);
      util_check("zero weights", m, n, pts, w, &res, M, RTOL);
      for (int c = 0; c < res.count; c++)
        TEST_TRUE(res.indices[c] % 2 == 1);
      fcm_simplify_result_destroy(&res);
    }
  }
  free(pts);
  free(w);
  free(w2);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
