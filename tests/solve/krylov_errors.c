/* Krylov failure paths: too few iterations (FCM_ERR_NOT_CONVERGED, reason, history of
 * one entry per iteration), NaN/Inf in b, x0 or the operator (FCM_ERR_NUMERIC), an
 * indefinite or singular preconditioner, a failing callback, b = 0, absolute tolerance,
 * history buffers, and invalid arguments with their messages. */
#include "solve_test_util.h"

#define N  4
#define NN (N * N * N)

typedef struct wrap {
  fcm_csr *A;
  int calls, nan_at, fail_at;
} wrap;

/* y = A x, with NaN injected or an error returned at chosen calls */
static fcm_status op(void *user, const double *x, double *y)
{
  wrap *w = user;
  int c = w->calls++;
  if (c == w->fail_at) return FCM_ERR_UNSUPPORTED;
  fcm_status st = fcm_csr_apply(w->A, 1.0, x, 0.0, y);
  if (c == w->nan_at) y[3] = NAN;
  return st;
}

static double scale_s = -1.0;
static fcm_status scaled_identity(void *user, const double *r, double *z)
{
  (void)user;
  for (int i = 0; i < NN; i++)
    z[i] = scale_s * r[i];
  return FCM_OK;
}

typedef fcm_status (*solver_fn)(fcm_krylov *, fcm_operator_fn, void *, fcm_operator_fn, void *,
                                const double *, double *, const fcm_krylov_options *,
                                fcm_krylov_info *);

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_csr *A = NULL;
  fcm_krylov *ws = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, laplace3d(ctx, N, 0.0, NULL, &A));
  TEST_OK(ctx, fcm_krylov_create(ctx, NN, &ws));
  double b[NN], x[NN];
  rng r = {1};
  for (int i = 0; i < NN; i++)
    b[i] = rng_uniform(&r);
  const solver_fn solvers[2] = {fcm_krylov_cg, fcm_krylov_minres};
  const char *names[2] = {"cg:", "minres:"};
  fcm_krylov_info info;

  for (int s = 0; s < 2; s++) {
    solver_fn solve = solvers[s];
    fcm_krylov_options o = fcm_krylov_options_default();
    /* too few iterations */
    o.max_iterations = 3;
    o.record_history = 1;
    memset(x, 0, sizeof x);
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info),
             FCM_ERR_NOT_CONVERGED, "max_iterations = 3");
    TEST_TRUE(info.reason == FCM_KRYLOV_MAX_ITERATIONS && info.iterations == 3);
    TEST_TRUE(info.history_length == 3 && info.history);
    TEST_TRUE(info.relative_residual > o.rtol && info.relative_residual < 1.0);
    TEST_NEAR(true_residual(A, b, x, NN), info.relative_residual, 1e-8, 0.0); /* x is the iterate */
    o.max_iterations = 0;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info),
             FCM_ERR_NOT_CONVERGED, names[s]);
    TEST_TRUE(info.iterations == 0 && info.history_length == 0);
    /* caller history buffer shorter than the iteration count */
    double hbuf[2] = {-1, -1};
    o = fcm_krylov_options_default();
    o.record_history = 1;
    o.history = hbuf;
    o.history_capacity = 2;
    memset(x, 0, sizeof x);
    TEST_OK(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info));
    TEST_TRUE(info.iterations > 2 && info.history_length == 2 && info.history == hbuf);
    TEST_TRUE(hbuf[0] > 0.0 && hbuf[1] > 0.0 && hbuf[0] < 1.0);
    o.history_capacity = 0;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_ARG,
             "history_capacity = 0");

    /* NaN / Inf */
    o = fcm_krylov_options_default();
    b[7] = NAN;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_NUMERIC,
             "right-hand side");
    TEST_TRUE(info.reason == FCM_KRYLOV_NAN);
    b[7] = INFINITY;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_NUMERIC,
             "right-hand side");
    b[7] = 0.25;
    x[2] = NAN;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_NUMERIC,
             "NaN or Inf at iteration 0");
    wrap w = {A, 0, 3, -1};
    memset(x, 0, sizeof x);
    TEST_ERR(ctx, solve(ws, op, &w, NULL, NULL, b, x, &o, &info), FCM_ERR_NUMERIC, "NaN or Inf");
    TEST_TRUE(info.reason == FCM_KRYLOV_NAN);
    /* failing callback: its status comes back */
    w.calls = 0, w.nan_at = -1, w.fail_at = 2;
    memset(x, 0, sizeof x);
    TEST_TRUE(solve(ws, op, &w, NULL, NULL, b, x, &o, &info) == FCM_ERR_UNSUPPORTED);
    TEST_TRUE(info.reason == FCM_KRYLOV_CALLBACK_ERROR && info.operator_applications == 3);
    fcm_ctx_error_clear(ctx);

    /* indefinite (S = -I) and singular (S = 0) preconditioners */
    scale_s = -1.0;
    memset(x, 0, sizeof x);
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, scaled_identity, NULL, b, x, &o, &info),
             FCM_ERR_NOT_CONVERGED, "not positive definite");
    TEST_TRUE(info.reason == FCM_KRYLOV_INDEFINITE_PRECONDITIONER);
    scale_s = 0.0;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, scaled_identity, NULL, b, x, &o, &info),
             FCM_ERR_NOT_CONVERGED, "not positive definite");
    TEST_TRUE(info.reason == FCM_KRYLOV_INDEFINITE_PRECONDITIONER);

    /* b = 0: x = 0 whatever the initial guess */
    double zero[NN] = {0};
    for (int i = 0; i < NN; i++)
      x[i] = 1.0;
    TEST_OK(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, zero, x, &o, &info));
    TEST_TRUE(info.reason == FCM_KRYLOV_CONVERGED_ATOL && info.iterations == 0 &&
              norm2(x, NN) == 0.0);
    /* absolute tolerance above the initial residual */
    o.atol = 2.0 * norm2(b, NN);
    TEST_OK(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info));
    TEST_TRUE(info.reason == FCM_KRYLOV_CONVERGED_ATOL && info.iterations == 0);

    /* invalid arguments */
    o = fcm_krylov_options_default();
    o.rtol = -1.0;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_ARG,
             "rtol = -1");
    o.rtol = NAN;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_ARG,
             "rtol = nan");
    o = fcm_krylov_options_default();
    o.max_iterations = -2;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_ARG,
             "max_iterations = -2");
    o = fcm_krylov_options_default();
    o.norm = (fcm_krylov_norm)9;
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info), FCM_ERR_ARG,
             "norm = 9");
    TEST_TRUE(solve(NULL, fcm_csr_operator, A, NULL, NULL, b, x, NULL, &info) == FCM_ERR_ARG);
    TEST_ERR(ctx, solve(ws, NULL, A, NULL, NULL, b, x, NULL, &info), FCM_ERR_ARG,
             "operator callback");
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, b, (double *)b, NULL, &info),
             FCM_ERR_ARG, "different arrays");
    TEST_ERR(ctx, solve(ws, fcm_csr_operator, A, NULL, NULL, NULL, x, NULL, &info), FCM_ERR_ARG,
             "b or x is NULL");
  }
  fcm_krylov_options o = fcm_krylov_options_default();
  o.norm = FCM_KRYLOV_NORM_UNPRECONDITIONED;
  scale_s = 1.0;
  TEST_ERR(ctx, fcm_krylov_minres(ws, fcm_csr_operator, A, scaled_identity, NULL, b, x, &o, &info),
           FCM_ERR_ARG, "preconditioned residual norm");
  o.record_history = 1;
  TEST_ERR(ctx, fcm_cg_solve(ctx, NN, fcm_csr_operator, A, NULL, NULL, b, x, &o, &info),
           FCM_ERR_ARG, "caller buffer");
  fcm_krylov *bad = NULL;
  TEST_ERR(ctx, fcm_krylov_create(ctx, -1, &bad), FCM_ERR_ARG, "n = -1");
  TEST_TRUE(bad == NULL);
  TEST_TRUE(strcmp(fcm_krylov_reason_name(FCM_KRYLOV_MAX_ITERATIONS), "max-iterations") == 0);
  TEST_TRUE(strcmp(fcm_krylov_reason_name((fcm_krylov_reason)99), "unknown") == 0);

  /* an empty system */
  fcm_krylov *ws0 = NULL;
  TEST_OK(ctx, fcm_krylov_create(ctx, 0, &ws0));
  TEST_OK(ctx, fcm_krylov_minres(ws0, fcm_csr_operator, A, NULL, NULL, NULL, NULL, NULL, &info));
  TEST_TRUE(info.iterations == 0);
  fcm_krylov_destroy(&ws0);
  fcm_krylov_destroy(&ws);
  fcm_krylov_destroy(&ws); /* idempotent */
  fcm_csr_destroy(&A);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
