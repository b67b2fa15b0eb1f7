/* The allocation-failure loop as a function: run `call` with the k-th allocation failing,
 * k = 0, 1, 2, ... until it succeeds. Each failing round must return FCM_ERR_ALLOC (and the
 * context must record it) and, once `release` has freed what the round made, leave as many
 * live allocations as before. A `call` that sees its output set on failure returns
 * FCM_ERR_INTERNAL, which the loop reports as a wrong status. */
#ifndef FCM_TEST_ALLOC_LOOP_H
#define FCM_TEST_ALLOC_LOOP_H

#include "test.h"
#include "test_alloc.h"

typedef fcm_status (*alloc_call)(void *user);
typedef void (*alloc_release)(void *user);

/* Returns the number of failing rounds (the test fails when none succeeds within
 * max_rounds, or when fewer than min_failures rounds failed). */
static inline long alloc_loop(fcm_ctx *ctx, failing *f, const char *name, alloc_call call,
                              alloc_release release, void *user, long min_failures, long max_rounds)
{
  const long long live = fcm_ctx_live_allocations(ctx);
  long failures = 0;
  int ok = 0;
  for (long k = 0; k < max_rounds && !ok; k++) {
    f->count = 0;
    f->fail_at = k;
    fcm_status st = call(user);
    f->fail_at = -1;
    if (st == FCM_OK) {
      ok = 1;
    } else {
      failures++;
      if (st != FCM_ERR_ALLOC || fcm_ctx_error_status(ctx) != FCM_ERR_ALLOC) {
        TEST_FAIL_("%s, allocation %ld failing: %s (%s)", name, k, fcm_status_name(st),
                   fcm_ctx_error_message(ctx));
        ok = -1;
      }
    }
    if (release) release(user);
    fcm_ctx_error_clear(ctx);
    if (fcm_ctx_live_allocations(ctx) != live) {
      TEST_FAIL_("%s, allocation %ld failing: %lld allocations leaked", name, k,
                 fcm_ctx_live_allocations(ctx) - live);
      ok = -1;
    }
  }
  if (ok == 0) TEST_FAIL_("%s: no success within %ld rounds", name, max_rounds);
  if (ok == 1 && failures < min_failures)
    TEST_FAIL_("%s: %ld failing allocations, expected at least %ld", name, failures, min_failures);
  return failures;
}

#endif
