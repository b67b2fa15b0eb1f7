/* fcm/version.h is generated from the CMake project version: the version string the
 * library reports at run time, the header's string and its major/minor/patch macros all
 * equal the project version CMake passes as the argument. */
#include "fcm/fcm.h"
#include "test.h"

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
  TEST_TRUE(argc == 2);
  if (argc != 2) return TEST_RESULT();
  const char *v = fcm_version();
  TEST_TRUE(v != NULL && !strcmp(v, FCM_VERSION_STRING));
  TEST_TRUE(v != NULL && !strcmp(v, argv[1]));
  char macros[64];
  snprintf(macros, sizeof macros, "%d.%d.%d", FCM_VERSION_MAJOR, FCM_VERSION_MINOR,
           FCM_VERSION_PATCH);
  TEST_TRUE(!strcmp(macros, argv[1]));
  return TEST_RESULT();
}
