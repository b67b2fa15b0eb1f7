/* Allocation failures in the dense adapter: fail the k-th allocation for
 * k = 0, 1, ... until the call succeeds; every failure must return
 * FCM_ERR_ALLOC with a message, leave nothing allocated, and the final
 * successful call must give the right answer. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "alloc_loop.h"

enum { M = 12, N = 7 };

typedef enum which { DO_SYEV, DO_STEV, DO_GESVD, DO_LSTSQ, DO_COUNT } which;
static const char *const names[DO_COUNT] = {"syev", "stev", "gesvd", "lstsq"};

/* Run one routine on fixed data; *check receives a number that must be ~0 on success. */
static fcm_status run(fcm_ctx *ctx, which w, double *check)
{
  double a[M * N], u[M * N], vt[N * N], s[N], d[N], e[N], b[M];
  for (int j = 0; j < N; j++)
    for (int i = 0; i < M; i++)
      a[i + j * M] = 1.0 / (1.0 + i + j) + (i == j ? 1.0 : 0.0);
  fcm_status st = FCM_OK;
  *check = 1.0;
  switch (w) {
  case DO_SYEV: /* leading N x N block (Hilbert + I, symmetric): eigenvalues in (1, 1 + pi) */
    st = fcm__syev(ctx, 1, N, a, M, s);
    if (st == FCM_OK) *check = (s[0] > 1.0 && s[N - 1] < 1.0 + LA_PI) ? 0.0 : 1.0;
    break;
  case DO_STEV:
    for (int i = 0; i < N; i++)
      d[i] = 2.0, e[i] = -1.0;
    st = fcm__stev(ctx, N, d, e, u, N);
    if (st == FCM_OK) *check = fabs(d[0] - (2.0 - 2.0 * cos(LA_PI / (N + 1))));
    break;
  case DO_GESVD:
    st = fcm__gesvd(ctx, M, N, a, M, s, u, M, vt, N);
    if (st == FCM_OK) *check = orth_error_cols(M, N, u, M);
    break;
  case DO_LSTSQ: /* b = A * ones: the solution is all ones */
    for (int i = 0; i < M; i++) {
      b[i] = 0.0;
      for (int j = 0; j < N; j++)
        b[i] += a[i + j * M];
    }
    st = fcm__lstsq(ctx, M, N, 1, a, M, b, M, -1.0, NULL);
    if (st == FCM_OK) {
      *check = 0.0;
      for (int j = 0; j < N; j++)
        *check = fmax(*check, fabs(b[j] - 1.0));
    }
    break;
  default:
    break;
  }
  return st;
}

typedef struct dense_case {
  fcm_ctx *ctx;
  which w;
} dense_case;

/* One round: the routine's answer on success, the out-of-memory message on failure. */
static fcm_status run_case(void *user)
{
  dense_case *c = user;
  double check = -1.0;
  fcm_status st = run(c->ctx, c->w, &check);
  if (st == FCM_OK) TEST_NEAR(check, 0.0, 0.0, 1e-12);
  if (st == FCM_ERR_ALLOC && !strstr(fcm_ctx_error_message(c->ctx), "out of memory"))
    TEST_FAIL_("%s: message \"%s\" lacks \"out of memory\"", names[c->w],
               fcm_ctx_error_message(c->ctx));
  return st;
}

int main(void)
{
  failing f;
  dense_case c = {failing_ctx(&f), DO_SYEV};
  TEST_TRUE(c.ctx != NULL);
  if (!c.ctx) return TEST_RESULT();
  /* each routine allocates workspace: at least one failing round */
  for (int w = 0; w < DO_COUNT; w++) {
    c.w = (which)w;
    alloc_loop(c.ctx, &f, names[w], run_case, NULL, &c, 1, 50);
  }
  fcm_ctx_destroy(&c.ctx);
  return TEST_RESULT();
}
