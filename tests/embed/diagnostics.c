/* Embedding diagnostics and progress: a box half outside the background beyond +x reports
 * half its volume outside, on the +x side only, and an embedded / geometry ratio of 1/2; a
 * box beyond a corner counts for each side it is beyond; a body wholly outside fails naming
 * both bounding boxes; the progress callback runs on the calling thread, never decreases and
 * ends with done == total; a negative interval is refused. Also checks voxel and level-set
 * geometries embed with the volume they report. */
#include "fcm/embed.h"
#include "fcm/levelset.h"
#include "fcm/voxels.h"
#include "test.h"

#include <omp.h>

typedef struct progress_log {
  fcm_index calls, last, total;
  int decreasing, wrong_thread;
} progress_log;

static void on_progress(fcm_index done, fcm_index total, void *user)
{
  progress_log *p = user;
  p->decreasing |= done < p->last;
  p->wrong_thread |= omp_get_thread_num() != 0;
  p->calls++, p->last = done, p->total = total;
}

static fcm_cell_rules *embed(fcm_ctx *ctx, const fcm_mesh *m, const double lo[3],
                             const double hi[3], fcm_status expect, const char *msg)
{
  const fcm_index one[3] = {1, 1, 1};
  fcm_geometry *g = NULL;
  fcm_cell_rules *r = NULL;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.simplify = FCM_CELL_SIMPLIFY_OFF;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, lo, hi, one, &g));
  if (expect == FCM_OK)
    TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r));
  else
    TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), expect, msg);
  fcm_geometry_destroy(&g);
  return r;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {4, 4, 4};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  if (!m) return TEST_RESULT();

  /* half outside beyond +x: [0.5, 1.5] x [0.2, 0.7] x [0.1, 0.9] */
  const double a0[3] = {0.5, 0.2, 0.1}, a1[3] = {1.5, 0.7, 0.9};
  fcm_cell_rules *r = embed(ctx, m, a0, a1, FCM_OK, NULL);
  if (r) {
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    const double v = 1.0 * 0.5 * 0.8;
    TEST_NEAR(S->geometry_volume, v, 1e-14, 0);
    TEST_NEAR(S->outside_volume, v / 2, 1e-12, 0);
    TEST_NEAR(S->outside_side_volume[1], v / 2, 1e-12, 0);
    for (int k = 0; k < 6; k++)
      if (k != 1) TEST_TRUE(S->outside_side_volume[k] == 0.0);
    TEST_NEAR(S->volume_ratio, 0.5, 1e-12, 0);
    TEST_TRUE(S->mesh_hi[0] == 1 && S->geometry_hi[0] == 1.5 && S->geometry_lo[1] == 0.2);
    FILE *f = tmpfile();
    TEST_TRUE(f != NULL);
    if (f) {
      char text[4096];
      fcm_cell_rules_view(r, f);
      rewind(f);
      size_t got = fread(text, 1, sizeof text - 1, f);
      text[got] = '\0';
      fclose(f);
      TEST_TRUE(strstr(text, "embedded / geometry volume 0.500000; outside the background mesh "
                             "0.2, beyond +x 0.2\n") != NULL);
    }
    fcm_cell_rules_destroy(&r);
  }
  /* beyond the (-x, -y) edge: [-0.5, 0.5] x [-0.25, 0.75] x [0.2, 0.6] */
  const double b0[3] = {-0.5, -0.25, 0.2}, b1[3] = {0.5, 0.75, 0.6};
  r = embed(ctx, m, b0, b1, FCM_OK, NULL);
  if (r) {
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    const double inside = 0.5 * 0.75 * 0.4;
    TEST_NEAR(S->outside_volume, 0.4 - inside, 1e-12, 0);
    TEST_NEAR(S->outside_side_volume[0], 0.5 * 1.0 * 0.4, 1e-12, 0);
    TEST_NEAR(S->outside_side_volume[2], 1.0 * 0.25 * 0.4, 1e-12, 0);
    TEST_TRUE(S->outside_side_volume[1] == 0 && S->outside_side_volume[3] == 0);
    fcm_cell_rules_destroy(&r);
  }
  /* inside: nothing outside, ratio 1 */
  const double c0[3] = {0.1, 0.2, 0.3}, c1[3] = {0.9, 0.8, 0.7};
  r = embed(ctx, m, c0, c1, FCM_OK, NULL);
  if (r) {
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    TEST_TRUE(S->outside_volume == 0.0);
    TEST_NEAR(S->volume_ratio, 1.0, 1e-12, 0);
    fcm_cell_rules_destroy(&r);
  }
  /* wholly outside */
  const double d0[3] = {2, 0, 0}, d1[3] = {3, 1, 0.5};
  r = embed(ctx, m, d0, d1, FCM_ERR_GEOMETRY,
            "lies wholly outside the background mesh: geometry bounding box [2, 3] x [0, 1] x "
            "[0, 0.5], background mesh bounding box [0, 1] x [0, 1] x [0, 1]");
  TEST_TRUE(r == NULL);

  /* progress */
  fcm_geometry *g = NULL;
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, (const double[3]){0.5, 0.5, 0.5}, 0.4, 3, &g));
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  progress_log log = {0};
  o.progress = on_progress, o.progress_user = &log, o.progress_interval = 0;
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, 2));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r));
  TEST_OK(ctx, fcm_ctx_set_num_threads(ctx, FCM_DEFAULT));
  TEST_TRUE(log.calls >= 2 && log.last == 64 && log.total == 64);
  TEST_TRUE(!log.decreasing && !log.wrong_thread);
  fcm_cell_rules_destroy(&r);
  o.progress_interval = -1;
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &r), FCM_ERR_ARG, "progress_interval = -1");
  fcm_geometry_destroy(&g);

  /* a voxel block and a level-set ball embed with the volume they report */
  double vals[27];
  for (int i = 0; i < 27; i++)
    vals[i] = i == 13 ? 0 : 1; /* a hollow 3^3 block */
  const fcm_index dims[3] = {3, 3, 3};
  const double axes[9] = {0.25, 0, 0, 0, 0.25, 0, 0, 0, 0.25}, org[3] = {0.3, 0.3, 0.3};
  fcm_voxel_image *img = NULL;
  TEST_OK(ctx, fcm_voxel_image_create(ctx, dims, axes, org, vals, &img));
  if (img) TEST_OK(ctx, fcm_geometry_create_from_voxels(ctx, img, NULL, &g, NULL));
  fcm_voxel_image_destroy(&img);
  if (g) {
    TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, NULL, &r));
    if (r) TEST_NEAR(fcm_cell_rules_get_stats(r)->embedded_volume, 26.0 / 64, 1e-12, 0);
    fcm_cell_rules_destroy(&r);
    fcm_geometry_destroy(&g);
  }
  fcm_implicit s = {0};
  s.kind = FCM_IMPLICIT_SPHERE, s.radius = 0.3, s.center[0] = s.center[1] = s.center[2] = 0.5;
  fcm_implicit_tree t = {1, &s};
  fcm_level_set_info li;
  TEST_OK(ctx,
          fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, n, NULL, &g, &li));
  if (g) {
    TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, NULL, &r));
    if (r) TEST_NEAR(fcm_cell_rules_get_stats(r)->embedded_volume, li.volume, 1e-12, 0);
    fcm_cell_rules_destroy(&r);
    fcm_geometry_destroy(&g);
  }
  fcm_mesh_destroy(&m);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
