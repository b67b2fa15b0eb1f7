/* libFuzzer target: the triangle surface readers (fcm_surface_create_from_file). The first
 * byte of the input picks the format (its value mod 4: obj, off, stl, ply), the rest is the
 * file; a successful read is checked for ids in range and finite coordinates, then run
 * through the checks (fcm_surface_check), reorientation and hole filling. */
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
    fcm_surface_report r;
    fcm_surface *o = NULL, *f = NULL;
    fcm_surface_fill_info fi;
    st = fcm_surface_check(s, NULL, &r);
    fuzz_check_status(ctx, st);
    if (st == FCM_OK && (r.num_boundary_edges < 0 || r.num_degenerate < 0 ||
                         r.num_boundary_loops > r.num_boundary_edges))
      abort();
    st = fcm_surface_create_oriented(ctx, s, &o, NULL);
    fuzz_check_status(ctx, st);
    if (st == FCM_OK && fcm_surface_num_triangles(o) != nt) abort();
    st = fcm_surface_create_filled(ctx, s, NULL, &f, &fi);
    fuzz_check_status(ctx, st);
    if (st == FCM_OK && (fi.num_filled > fi.num_loops || fcm_surface_num_triangles(f) < nt))
      abort();
    fcm_surface_destroy(&o);
    fcm_surface_destroy(&f);
  }
  fcm_surface_destroy(&s);
  fuzz_check_no_live(ctx, live);
  return 0;
}
