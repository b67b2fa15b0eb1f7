/* libFuzzer target: the TetGen reader (fcm_geometry_create_from_tetgen). The input is the
 * .node file, a NUL byte, then the .ele file (no NUL: an empty .ele file); a NUL cannot be
 * part of a valid file, so the split loses nothing. */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  fcm_ctx *ctx = fuzz_ctx();
  long long live = fcm_ctx_live_allocations(ctx);
  const uint8_t *nul = size ? memchr(data, 0, size) : NULL;
  size_t nsize = nul ? (size_t)(nul - data) : size;
  const char *node = fuzz_write_file(0, "in.node", data, nsize);
  const char *ele =
      fuzz_write_file(1, "in.ele", nul ? nul + 1 : data + size, nul ? size - nsize - 1 : 0);
  fcm_geometry *geom = NULL;
  fcm_status st = fcm_geometry_create_from_tetgen(ctx, node, ele, &geom);
  fuzz_check_status(ctx, st);
  if (st == FCM_OK) (void)fcm_geometry_volume(geom);
  fcm_geometry_destroy(&geom);
  fuzz_check_no_live(ctx, live);
  return 0;
}
