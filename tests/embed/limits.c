/* Hard cases of fcm_cell_rules_create:
 * - volume fractions never exceed 1 (sums of clipped volumes of a geometry covering the
 *   cells can round to 1 + 2.4e-15 in hundreds of cells), and the embedded volume of
 *   a covered mesh equals the mesh volume;
 * - thin geometry: a slab of thickness t = 1e-6 ... 1e-14 of the cell size, inside a cell
 *   or across a cell face, keeps its volume (relative error <= 1e-12; not lost
 *   as "slivers" below 1e-13, nor doubled at 1e-12 across a face);
 * - memory: a cell whose rule building would exceed max_rule_memory is refused before
 *   allocating, FCM_ERR_UNSUPPORTED naming the cell, the estimate and the limit; 0 lifts
 *   the limit; the scene key quadrature.max_rule_memory_gib (default 4, [0, 2^20]) sets it;
 * - errors of the parallel build are reported once and deterministically: when every cell
 *   fails, the lowest-numbered cell is named, for 1, 2 and 4 threads, on every run. */
#include "fcm/embed.h"
#include "fcm/scene.h"
#include "test.h"

#include <omp.h>

static void fractions(fcm_ctx *ctx)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {4, 4, 4};
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  int over = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 12 && m; trial++) {
    const double gl[3] = {-0.37 - 0.01 * trial, -0.29, -0.31},
                 gh[3] = {1.33, 1.41 + 0.013 * trial, 1.27};
    const fcm_index gn[3] = {3 + trial % 4, 5, 4 + trial % 3};
    fcm_geometry *g = NULL;
    fcm_cell_rules *R = NULL;
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.simplify = 0;
    TEST_OK(ctx, fcm_geometry_create_box(ctx, gl, gh, gn, &g));
    TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &R));
    for (fcm_index c = 0; R && c < 64; c++) {
      const double f = fcm_cell_rules_volume_fraction(R, c);
      over += f > 1.0;
      worst = fmax(worst, f - 1.0);
      TEST_TRUE(fcm_cell_rules_class(R, c) == FCM_CELL_UNCUT);
    }
    if (R) TEST_NEAR(fcm_cell_rules_get_stats(R)->embedded_volume, 1.0, 1e-13, 0.0);
    fcm_cell_rules_destroy(&R);
    fcm_geometry_destroy(&g);
  }
  TEST_TRUE(over == 0);
  if (over) fprintf(stderr, "%d fractions above 1, by up to %.3g\n", over, worst);
  fcm_mesh_destroy(&m);
}

static void thin(fcm_ctx *ctx)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2, 2, 2}, gn[3] = {1, 1, 1};
  fcm_mesh *m = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  const double ts[] = {1e-6, 1e-9, 1e-11, 1e-12, 1e-13, 1e-14};
  for (int across = 0; across < 2 && m; across++)
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
      const double t = ts[i], z0 = across ? 0.5 - 0.3 * t : 0.3; /* across: the face z = 0.5 */
      const double gl[3] = {0.1, 0.1, z0}, gh[3] = {0.9, 0.9, z0 + t};
      fcm_geometry *g = NULL;
      fcm_cell_rules *R = NULL;
      fcm_cell_rules_options o = fcm_cell_rules_options_default();
      o.min_fraction = 0.0;
      o.simplify = 0;
      TEST_OK(ctx, fcm_geometry_create_box(ctx, gl, gh, gn, &g));
      TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &R));
      if (R) {
        const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(R);
        const double exact = fcm_geometry_volume(g);
        TEST_NEAR(S->embedded_volume, exact, 1e-12, 0.0);
        TEST_TRUE(S->num_slivers == 0 && S->sliver_volume == 0.0);
        /* the cut-cell rules integrate 1 to the same volume (reference weights x |K|/|ref|) */
        double w = 0.0;
        for (fcm_index c = 0; c < 8; c++)
          w += fcm_cell_rules_volume_fraction(R, c) * 0.125;
        TEST_NEAR(w, exact, 1e-12, 0.0);
      }
      fcm_cell_rules_destroy(&R);
      fcm_geometry_destroy(&g);
    }
  fcm_mesh_destroy(&m);
}

/* 16 hex cells in a row, each cut by a fine geometry (about 1,300 tets per cell, about
 * 1.3 MB of rules to build without simplification). */
static void crowded(fcm_ctx *ctx)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {16, 1, 1}, gl[3] = {0.05, 0.05, 0.05},
               gh[3] = {15.95, 0.95, 0.95};
  const fcm_index n[3] = {16, 1, 1}, gn[3] = {96, 6, 6};
  fcm_mesh *m = NULL;
  fcm_geometry *g = NULL;
  fcm_cell_rules *R = NULL;
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, n, &m));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, gl, gh, gn, &g));
  if (!m || !g) return;
  fcm_cell_rules_options o = fcm_cell_rules_options_default();
  o.simplify = 0;
  o.max_rule_memory = 1e6; /* 1 MB: each cut cell needs more */
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &R), FCM_ERR_UNSUPPORTED,
           "embed: background cell 0 holds ");
  TEST_TRUE(R == NULL);
  TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &R), FCM_ERR_UNSUPPORTED,
           "above the limit of 0.000931 GiB (fcm_cell_rules_options.max_rule_memory");
  /* the lowest failing cell, whatever the threads */
  const int threads[3] = {1, 2, 4};
  for (int run = 0; run < 15; run++) {
    o.num_threads = threads[run % 3];
    TEST_ERR(ctx, fcm_cell_rules_create(ctx, m, g, &o, &R), FCM_ERR_UNSUPPORTED,
             "background cell 0 holds");
  }
  /* no limit: the same cells build */
  o.max_rule_memory = 0.0;
  TEST_OK(ctx, fcm_cell_rules_create(ctx, m, g, &o, &R));
  TEST_TRUE(R && fcm_cell_rules_get_stats(R)->num_cut == 16);
  fcm_cell_rules_destroy(&R);
  fcm_geometry_destroy(&g);
  fcm_mesh_destroy(&m);
}

/* The scene key: default 4 GiB, read back, range-checked. */
static void scene_key(fcm_ctx *ctx)
{
#define SCENE(q)                                                                                   \
  "{\"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, "   \
  "\"cells\": [1, 1, 1]}, \"material\": {\"young\": 1e6, \"poisson\": 0.3}" q "}"
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, SCENE(""), "t.json", &s));
  if (s) TEST_TRUE(fcm_scene_get_quadrature(s)->max_rule_memory_gib == 4.0);
  fcm_scene_destroy(&s);
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx, SCENE(", \"quadrature\": {\"max_rule_memory_gib\": 0.5}"), "t.json", &s));
  if (s) TEST_TRUE(fcm_scene_get_quadrature(s)->max_rule_memory_gib == 0.5);
  fcm_scene_destroy(&s);
  TEST_ERR(ctx,
           fcm_scene_create_from_string(
               ctx, SCENE(", \"quadrature\": {\"max_rule_memory_gib\": -1}"), "t.json", &s),
           FCM_ERR_ARG, "max_rule_memory_gib");
  TEST_TRUE(s == NULL);
#undef SCENE
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  fractions(ctx);
  thin(ctx);
  crowded(ctx);
  scene_key(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
