/* Allocation failures in the dense adapter: fail the k-th allocation for
 * k = 0, 1, ... until the call succeeds; every failure must return
 * FCM_ERR_ALLOC with a message, leave nothing allocated, and the final
 * successful call must give the right answer. */
#include "la/la_impl.h"
#include "la_test_util.h"
#include "test.h"

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

int main(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  TEST_TRUE(ctx != NULL);
  for (int w = 0; w < DO_COUNT; w++) {
    int succeeded = 0, failures = 0;
    for (long long k = 0; k < 50 && !succeeded; k++) {
      f.count = 0;
      f.fail_at = k;
      double check;
      fcm_status st = run(ctx, (which)w, &check);
      f.fail_at = -1;
      if (st == FCM_OK) {
        succeeded = 1;
        TEST_NEAR(check, 0.0, 0.0, 1e-12);
      } else {
        failures++;
        if (st != FCM_ERR_ALLOC)
          fprintf(stderr, "%s, k = %lld: status %s\n", names[w], k, fcm_status_name(st));
        TEST_TRUE(st == FCM_ERR_ALLOC);
        TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "out of memory") != NULL);
        fcm_ctx_error_clear(ctx);
      }
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
    }
    TEST_TRUE(succeeded);
    TEST_TRUE(failures >= 1); /* each routine allocates workspace, so the loop tested something */
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
