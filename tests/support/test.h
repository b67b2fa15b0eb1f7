/* Minimal test assertions: a passing test prints nothing and exits 0; a failing
 * check prints file:line with the numbers and the test exits 1 at the end. */
#ifndef FCM_TEST_H
#define FCM_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__)
__attribute__((unused))
#endif
static int test_failures_ = 0;

#define TEST_FAIL_(...)                                                                            \
  do {                                                                                             \
    fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                                                \
    fprintf(stderr, __VA_ARGS__);                                                                  \
    fputc('\n', stderr);                                                                           \
    test_failures_++;                                                                              \
  } while (0)

/* Check a condition. */
#define TEST_TRUE(cond)                                                                            \
  do {                                                                                             \
    if (!(cond)) TEST_FAIL_("check failed: %s", #cond);                                            \
  } while (0)

/* |a - b| <= atol + rtol |b|, and neither is NaN. */
#define TEST_NEAR(a, b, rtol, atol)                                                                \
  do {                                                                                             \
    double ta_ = (double)(a), tb_ = (double)(b);                                                   \
    if (!(fabs(ta_ - tb_) <= (atol) + (rtol)*fabs(tb_)))                                           \
      TEST_FAIL_("%s = %.17g, expected %s = %.17g (diff %.3g, rtol %g, atol %g)", #a, ta_, #b,     \
                 tb_, fabs(ta_ - tb_), (double)(rtol), (double)(atol));                            \
  } while (0)

/* A call returning fcm_status must succeed; on failure print the context error. */
#define TEST_OK(ctx, call)                                                                         \
  do {                                                                                             \
    fcm_status ts_ = (call);                                                                       \
    if (ts_ != FCM_OK) {                                                                           \
      TEST_FAIL_("%s returned %s", #call, fcm_status_name(ts_));                                   \
      fcm_ctx_error_view((ctx), stderr);                                                           \
    }                                                                                              \
  } while (0)

/* A call must fail with `code` and a message containing `substr`. */
#define TEST_ERR(ctx, call, code, substr)                                                          \
  do {                                                                                             \
    fcm_status ts_ = (call);                                                                       \
    if (ts_ != (code))                                                                             \
      TEST_FAIL_("%s returned %s, expected %s", #call, fcm_status_name(ts_), #code);               \
    else if (!strstr(fcm_ctx_error_message(ctx), (substr)))                                        \
      TEST_FAIL_("%s: message \"%s\" lacks \"%s\"", #call, fcm_ctx_error_message(ctx), (substr));  \
    fcm_ctx_error_clear(ctx);                                                                      \
  } while (0)

/* Exit status of a test's main(). */
/* main's exit code: `return TEST_RESULT();` (a result left unused is a compile error under
 * -Werror, so a failed check cannot end in exit code 0) */
#if defined(__GNUC__)
static inline int test_result_(void) __attribute__((warn_unused_result));
#endif
static inline int test_result_(void)
{
  if (test_failures_) fprintf(stderr, "%d check(s) failed\n", test_failures_);
  return test_failures_ ? 1 : 0;
}
#define TEST_RESULT() test_result_()

#endif
