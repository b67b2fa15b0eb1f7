/* The time of a hierarchy's structure after a cut: created on the cut space's pattern
 * (fcm__mg_create_pattern()) against carried from the hierarchy before the cut
 * (fcm__mg_create_pattern_cut()), the minimum of `reps` runs each, alternating. The embedded
 * hemisphere of mg_util.h on n x n/2 x n Hex8 cells, cut by a partial plane.
 * usage: mg_carry_bench [n [reps [mode]]]; mode: both (default), plain, carry (one kind
 * only, for a profiler). */
#include "fem/fem_impl.h"
#include "mg/levels_impl.h"
#include "mg_compare.h"
#include "mg_util.h"

#include <stdio.h>

int main(int argc, char **argv)
{
  const fcm_index n = argc > 1 ? atoi(argv[1]) : 32;
  const int reps = argc > 2 ? atoi(argv[2]) : 5;
  const char *mode = argc > 3 ? argv[3] : "both";
  const int plain = strcmp(mode, "carry") != 0, carry = strcmp(mode, "plain") != 0;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  problem base;
  problem_hemisphere_of(ctx, FCM_ELEMENT_HEX8, n, 0, fcm_space_options_default().constrain_ratio,
                        &base);
  fcm_mg_options o = fcm_mg_options_default();
  fcm_mg *old = NULL;
  TEST_OK(ctx, fcm_mg_create(ctx, base.space, base.A, &o, &old));
  fcm_surface *s = NULL;
  fcm_cell_rules *rules = NULL;
  const double pt[3] = {0.05, 0, 0}, nrm[3] = {1, 0, 0}, lo[3] = {-0.1, 0.4, -2},
               hi[3] = {0.2, 2, 2};
  TEST_OK(ctx, fcm_surface_create_plane(ctx, pt, nrm, lo, hi, &s));
  TEST_OK(ctx, fcm_cell_rules_create_cut(ctx, base.mesh, base.geom, base.rules0, s, &rules));
  problem next;
  memset(&next, 0, sizeof next);
  next.mesh = base.mesh;
  fcm_space_options so = fcm_space_options_default();
  TEST_OK(ctx, fcm__space_create_cut(ctx, base.mesh, rules, &so, base.space, &next.space));
  finish_space(ctx, &next, 0);
  const double flo[3] = {-2, 0, -2}, fhi[3] = {2, 0, 2};
  clamp_box(ctx, &next, flo, fhi);
  unsigned char *inactive = mgc_eliminated(next.A, next.n);
  double best[2] = {1e30, 1e30};
  fcm__mg_kept kept;
  memset(&kept, 0, sizeof kept);
  for (int r = 0; r < reps; r++)
    for (int k = 0; k < 2; k++) {
      if (!(k ? carry : plain)) continue;
      fcm_mg *mg = NULL, *none = NULL;
      const double t0 = fcm_wtime();
      if (k)
        TEST_OK(ctx, fcm__mg_create_pattern_cut(ctx, old, base.space, next.space, next.A, inactive,
                                                &o, &mg));
      else
        TEST_OK(ctx, fcm__mg_create_pattern(ctx, &none, next.space, next.A, inactive, &o, &mg));
      const double t = fcm_wtime() - t0;
      best[k] = t < best[k] ? t : best[k];
      if (k) fcm__mg_get_kept(mg, &kept);
      fcm_mg_destroy(&mg);
    }
  printf("hemisphere n = %lld: %lld -> %lld DOFs, %d threads; structure after the cut, min of %d: "
         "created %.4f s, carried %.4f s; rows of A P taken %lld, coarse rows %lld\n",
         (long long)n, (long long)base.n, (long long)next.n, fcm_ctx_num_threads(ctx), reps,
         plain ? best[0] : 0.0, carry ? best[1] : 0.0, (long long)kept.carried_ap_rows,
         (long long)kept.carried_coarse_rows);
  free(inactive);
  fcm_mg_destroy(&old);
  fcm_csr_destroy(&next.A);
  fcm_space_destroy(&next.space);
  free(next.b);
  fcm_cell_rules_destroy(&rules);
  fcm_surface_destroy(&s);
  problem_free(&base);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
