/* The run-time library version (fcm/version.h is generated from the CMake project version). */
#include "fcm/version.h"

const char *fcm_version(void)
{
  return FCM_VERSION_STRING;
}
