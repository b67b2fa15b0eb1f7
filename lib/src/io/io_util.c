/* Small helpers shared by the io writers: string checks and copies, the host byte
 * order, locale-proof number formatting. */
#include "io/io_impl.h"

#include <stdint.h>
#include <string.h>

int fcm__io_printable(const char *s)
{
  if (!s || !*s) return 0;
  for (const unsigned char *p = (const unsigned char *)s; *p; p++)
    if (*p < 0x20 || *p == 0x7f) return 0;
  return 1;
}

fcm_status fcm__io_strdup(fcm_ctx *ctx, const char *s, char **out)
{
  fcm_status st = FCM_OK;
  size_t len = strlen(s);
  char *copy = NULL;
  FCM_ALLOC(ctx, len + 1, copy);
  memcpy(copy, s, len + 1);
  *out = copy;
cleanup:
  return st;
}

const char *fcm__io_byte_order(void)
{
  const uint16_t one = 1;
  unsigned char first;
  memcpy(&first, &one, 1);
  return first ? "LittleEndian" : "BigEndian";
}

void fcm__io_format_double(double x, char buf[32])
{
  snprintf(buf, 32, "%.17g", x);
  for (char *p = buf; *p; p++)
    if (*p == ',') *p = '.'; /* a caller's setlocale() must not break the XML */
}
