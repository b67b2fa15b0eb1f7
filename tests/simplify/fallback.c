/* The fallback path: with every LP forced to fail (GLPK stopped by an iteration limit of
 * 0, or driven into a fatal error that its error hook turns into a return) and every
 * elimination finding its LU pivots too small, fcm_simplify
 * returns FCM_OK, info->fallback = 1 with the reason and GLPK's words, and the rule equal
 * to the input. GLPK prints nothing (stdout goes to a file that must stay empty), the
 * process survives, and the next normal call in the same thread succeeds. Each fallback is
 * logged once at FCM_LOG_WARNING through the ctx's log callback; a normal call logs nothing. */
#include "simplify/simplify_impl.h"
#include "simplify_util.h"

typedef struct log_count {
  int warnings, others;
  char last[512];
} log_count;

static void count_log(void *user, fcm_log_level level, const char *msg)
{
  log_count *c = user;
  if (level == FCM_LOG_WARNING) {
    c->warnings++;
    snprintf(c->last, sizeof c->last, "%s", msg);
  } else {
    c->others++;
  }
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  log_count logged = {0, 0, ""};
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = count_log;
  co.log_user = &logged;
  const char *capture = "simplify_fallback_stdout.txt";
  if (!freopen(capture, "w", stdout)) return 1;
  TEST_OK(ctx, fcm_ctx_create(&co, &ctx));
  if (!ctx) return TEST_RESULT();
  const int m = 3, M = util_num_basis(m), n = 5 * M;
  const double lo[3] = {-1, -1, -1};
  double *pts = malloc(3 * (size_t)n * sizeof *pts), *w = malloc((size_t)n * sizeof *w);
  util_random_box(3, n, lo, 2.0, 1.0, pts, w);

  for (int mi = FCM_SIMPLIFY_AUTO; mi < FCM_SIMPLIFY_METHOD_COUNT; mi++)
    for (int force = 1; force <= 2; force++) {
      fcm_simplify_options o = fcm_simplify_options_default();
      fcm_simplify_result res;
      fcm_simplify_info info;
      o.method = (fcm_simplify_method)mi;
      logged.warnings = 0;
      TEST_OK(ctx, fcm__simplify_hooked(ctx, m, n, pts, w, &o, force, &res, &info));
      TEST_TRUE(logged.warnings == 1 && logged.others == 0);
      TEST_TRUE(strstr(logged.last, "simplify:") && strstr(logged.last, "input rule is kept"));
      TEST_TRUE(info.fallback == 1 && info.skipped == 0 && info.attempts == 3);
      /* AUTO and ELIMINATE: elimination first, a GLPK path second, elimination third. */
      const int elim_first = mi == FCM_SIMPLIFY_AUTO || mi == FCM_SIMPLIFY_ELIMINATE;
      const fcm_simplify_reason glpk_reason =
          force == 1 ? FCM_SIMPLIFY_REASON_LP : FCM_SIMPLIFY_REASON_LP_ERROR;
      TEST_TRUE(info.reason == (elim_first ? FCM_SIMPLIFY_REASON_NUMERIC : glpk_reason));
      TEST_TRUE(strstr(info.message, force == 1 ? "iteration limit" : "GLPK fatal error") != NULL);
      if (elim_first) TEST_TRUE(strstr(info.message, "elimination") && strstr(info.message, "[2 "));
      TEST_TRUE(strstr(info.message, "[1 ") && strstr(info.message, "[3 "));
      TEST_TRUE(info.residual == 0.0 && info.kept == n);
      if (getenv("FCM_TEST_VERBOSE")) fprintf(stderr, "%s\n", info.message);
      TEST_TRUE(res.count == n);
      for (int j = 0; j < res.count; j++)
        if (res.indices[j] != j || res.weights[j] != w[j])
          TEST_FAIL_("fallback rule differs from the input at %d", j);
      fcm_simplify_result_destroy(&res);

      /* GLPK's environment is usable again. */
      TEST_OK(ctx, fcm_simplify(ctx, m, n, pts, w, &o, &res, &info));
      TEST_TRUE(info.fallback == 0 && info.attempts == 1);
      TEST_TRUE(logged.warnings == 1); /* nothing new */
      util_check("after forced failure", m, n, pts, w, &res, M, 1e-12);
      fcm_simplify_result_destroy(&res);
    }
  free(pts);
  free(w);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);

  fflush(stdout);
  FILE *f = fopen(capture, "r");
  TEST_TRUE(f != NULL);
  if (f) {
    if (fgetc(f) != EOF) TEST_FAIL_("GLPK wrote to stdout");
    fclose(f);
  }
  remove(capture);
  return TEST_RESULT();
}
