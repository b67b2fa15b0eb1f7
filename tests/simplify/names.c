/* Names of the simplification methods and failure reasons: every value has its own static
 * name, "auto"/"lp"/"recombine"/"eliminate" and "none" as documented, and a value out of range is
 * "unknown", never NULL. */
#include "fcm/simplify.h"
#include "test.h"

int main(void)
{
  const char *m[FCM_SIMPLIFY_METHOD_COUNT];
  for (int i = 0; i < FCM_SIMPLIFY_METHOD_COUNT; i++) {
    m[i] = fcm_simplify_method_name((fcm_simplify_method)i);
    TEST_TRUE(m[i] != NULL && strcmp(m[i], "unknown") != 0);
    for (int j = 0; j < i; j++)
      TEST_TRUE(m[i] && m[j] && strcmp(m[i], m[j]) != 0);
  }
  TEST_TRUE(!strcmp(fcm_simplify_method_name(FCM_SIMPLIFY_AUTO), "auto"));
  TEST_TRUE(!strcmp(fcm_simplify_method_name(FCM_SIMPLIFY_LP), "lp"));
  TEST_TRUE(!strcmp(fcm_simplify_method_name(FCM_SIMPLIFY_RECOMBINE), "recombine"));
  TEST_TRUE(!strcmp(fcm_simplify_method_name(FCM_SIMPLIFY_ELIMINATE), "eliminate"));

  enum { NR = FCM_SIMPLIFY_REASON_NO_PROGRESS + 1 };
  const char *r[NR];
  for (int i = 0; i < NR; i++) {
    r[i] = fcm_simplify_reason_name((fcm_simplify_reason)i);
    TEST_TRUE(r[i] != NULL && strcmp(r[i], "unknown") != 0);
    for (int j = 0; j < i; j++)
      TEST_TRUE(r[i] && r[j] && strcmp(r[i], r[j]) != 0);
  }
  TEST_TRUE(!strcmp(fcm_simplify_reason_name(FCM_SIMPLIFY_REASON_NONE), "none"));
  const char *bad = fcm_simplify_reason_name((fcm_simplify_reason)NR);
  TEST_TRUE(bad != NULL && !strcmp(bad, "unknown"));
  return TEST_RESULT();
}
