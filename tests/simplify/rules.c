/* Simplification of positive rules for strengths m = 1..argv[2] (default 10) with the path
 * given as argv[1] ("lp", "recombine" or "eliminate"; argv[3]: the elimination_block option,
 * default FCM_DEFAULT): random rules in a box, unions of conical
 * rules on red-refined sub-tets of the unit tet (whole, and cut by a sphere). Each result has at
 * most M points, is an ascending subset of the input (hence inside the tet), has
 * positive weights and integrates every monomial of degree <= m like the input. */
#include "simplify_util.h"

/* Relative monomial tolerance (to sum w0 |mono|), the contract's 1e-12. */
#define RTOL 1e-12

static int block = FCM_DEFAULT; /* fcm_simplify_options.elimination_block */

static void run(fcm_ctx *ctx, fcm_simplify_method method, const char *what, int m, int n,
                const double *pts, const double *w)
{
  char label[96];
  fcm_simplify_options o = fcm_simplify_options_default();
  fcm_simplify_result res;
  fcm_simplify_info info;
  o.method = method;
  o.elimination_block = block;
  snprintf(label, sizeof label, "%s m=%d N=%d %s", what, m, n, fcm_simplify_method_name(method));
  TEST_OK(ctx, fcm_simplify(ctx, m, n, pts, w, &o, &res, &info));
  if (info.fallback || info.attempts != 1 || info.method_used != method || info.skipped)
    TEST_FAIL_("%s: fallback %d, attempts %d, method %s, skipped %d: %s", label, info.fallback,
               info.attempts, fcm_simplify_method_name(info.method_used), info.skipped,
               info.message);
  TEST_TRUE(info.residual <= 1e-12);
  TEST_TRUE(info.kept == res.count && info.n == n && info.num_basis == util_num_basis(m));
  TEST_TRUE(info.rank >= 1 && info.rank <= info.num_basis && res.count <= info.rank);
  if (method == FCM_SIMPLIFY_ELIMINATE)
    TEST_TRUE(info.num_eliminations >= 1 && info.num_lps == 0);
  else
    TEST_TRUE(info.num_lps >= 1 && info.lp_iterations >= 0 && info.num_eliminations == 0);
  TEST_TRUE(method != FCM_SIMPLIFY_LP || info.rounds == 0);
  util_check(label, m, n, pts, w, &res, n, RTOL);
  if (getenv("FCM_TEST_VERBOSE"))
    fprintf(stderr,
            "%s: kept %lld rank %d residual %.2e lps %d its %lld eliminations %d rounds %d "
            "%.2f ms\n",
            label, (long long)res.count, info.rank, info.residual, info.num_lps, info.lp_iterations,
            info.num_eliminations, info.rounds, 1e3 * info.time_total);
  fcm_simplify_result_destroy(&res);
  TEST_TRUE(res.indices == NULL && res.weights == NULL && res.count == 0);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_simplify_method method = FCM_SIMPLIFY_LP;
  if (argc > 1 && !strcmp(argv[1], "recombine")) method = FCM_SIMPLIFY_RECOMBINE;
  if (argc > 1 && !strcmp(argv[1], "eliminate")) method = FCM_SIMPLIFY_ELIMINATE;
  const int mmax = argc > 2 ? atoi(argv[2]) : 10;
  if (argc > 3) block = atoi(argv[3]);
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();

  for (int m = 1; m <= mmax; m++) {
    const int M = util_num_basis(m);
    /* Random rules: the unit box around the origin and a small box far from it. */
    const int n = 4 * M + 7;
    double *pts = malloc(3 * (size_t)n * sizeof *pts), *w = malloc((size_t)n * sizeof *w);
    const double lo0[3] = {-1, -1, -1}, lo1[3] = {0.3, -0.8, 0.55};
    util_random_box((uint64_t)m, n, lo0, 2.0, 1.0, pts, w);
    run(ctx, method, "box", m, n, pts, w);
    util_random_box((uint64_t)m + 100, n, lo1, 0.05, 1.0, pts, w);
    run(ctx, method, "small box", m, n, pts, w);
    free(pts);
    free(w);

    /* Unions of conical rules: enough sub-tets for N well above M. */
    const int k = (m + 2) / 2, r = k * k * k * 8 >= 3 * M ? 1 : 2;
    for (int cut = 0; cut <= 1; cut++) {
      const int nt = util_tet_union(ctx, m, r + (cut && m <= 7), cut ? 0.62 : 0.0, &pts, &w);
      for (int j = 0; j < nt; j++) /* inside the unit tet: the subset property carries it */
        TEST_TRUE(pts[3 * j] > 0 && pts[3 * j + 1] > 0 && pts[3 * j + 2] > 0 &&
                  pts[3 * j] + pts[3 * j + 1] + pts[3 * j + 2] < 1);
      TEST_TRUE(nt > M);
      run(ctx, method, cut ? "sphere-cut tet" : "tet", m, nt, pts, w);
      free(pts);
      free(w);
    }
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
