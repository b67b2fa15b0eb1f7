/* libFuzzer target: the triangle surface readers (fcm_surface_create_from_file). The first
 * byte of the input picks the format (its value mod 4: obj, off, stl, ply), the rest is the
 * file; a successful read is checked for ids in range and finite coordinates. */
#include "fuzz_util.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  static const char *const names[4] = {"in.obj", "in.off", "in.stl", "in.ply"};
  if (size == 0) return 0;
  fcm_ctx *ctx = fuzz_ctx();
  long long live = fcm_ctx_live_allocations(ctx);
  const char *path = fuzz_write_file(0, names[data[0] % 4], data + 1, size - 1);
  fcm_surface *s = NULL;
  fcm_status st = fcm_surface_create_from_file(ctx, path, &s);
  fuzz_check_status(ctx, st);
  if (st == FCM_OK) {
    fcm_index nv = fcm_surface_num_vertices(s), nt = fcm_surface_num_triangles(s);
    const double *x = fcm_surface_coords(s);
    const fcm_index *t = fcm_surface_triangles(s);
    if (nv <= 0 || nt <= 0) abort();
    for (fcm_index i = 0; i < 3 * nv; i++)
      if (!isfinite(x[i])) abort();
    for (fcm_index i = 0; i < 3 * nt; i++)
      if (t[i] < 0 || t[i] >= nv) abort();
  }
  fcm_surface_destroy(&s);
  fuzz_check_no_live(ctx, live);
  return 0;
}
