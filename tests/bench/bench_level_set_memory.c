/* Benchmark of the level-set build's memory: the peak bytes of
 * fcm_geometry_create_from_level_set() (a counting allocator) per sub-cell it triangulates
 * (fcm_level_set_info.subcells) for spheres and gyroids at refinements 1-32, the figure
 * behind FCM_LEVEL_SET_SUBCELL_BYTES and the default max_subcells. Prints a table; asserts
 * that every case stays within FCM_LEVEL_SET_SUBCELL_BYTES per sub-cell. */
#include "fcm/fcm.h"
#include "fcm/levelset.h"
#include "test.h"

#include <stdlib.h>

static size_t live, peak;

static void *count_alloc(void *user, size_t n)
{
  (void)user;
  size_t *p = malloc(n + 16);
  if (!p) return NULL;
  p[0] = n;
  live += n;
  if (live > peak) peak = live;
  return (char *)p + 16;
}

static void count_release(void *user, void *q)
{
  (void)user;
  if (!q) return;
  size_t *p = (size_t *)((char *)q - 16);
  live -= p[0];
  free(p);
}

int main(void)
{
  static const struct {
    const char *kind; /* sphere, solid (gyroid), sheet (gyroid) */
    int r, n;
    double size; /* radius or period */
  } cases[] = {{"sphere", 1, 64, 0.45}, {"sphere", 1, 16, 0.4}, {"sphere", 2, 16, 0.4},
               {"sphere", 4, 6, 0.4},   {"sphere", 6, 6, 0.4},  {"sphere", 16, 8, 0.4},
               {"sphere", 32, 4, 0.4},  {"solid", 1, 16, 0.2},  {"solid", 2, 8, 0.3},
               {"solid", 8, 4, 0.1},    {"sheet", 3, 8, 0.25}};
  fcm_ctx_options co = fcm_ctx_options_default();
  co.allocator.alloc = count_alloc, co.allocator.release = count_release;
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(&co, &ctx));
  if (!ctx) return TEST_RESULT();
  printf("%-7s %3s %4s %6s %9s %10s %10s %9s %8s\n", "body", "r", "n", "size", "subcells", "tets",
         "peak MB", "B/sub", "time s");
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    fcm_implicit q = {0};
    if (cases[k].kind[1] == 'p') {
      q.kind = FCM_IMPLICIT_SPHERE, q.radius = cases[k].size;
      q.center[0] = q.center[1] = q.center[2] = 0.5;
    } else {
      q.kind = FCM_IMPLICIT_GYROID, q.period = cases[k].size, q.sheet = cases[k].kind[1] == 'h';
      q.thickness = q.sheet ? q.period / 10 : 0;
      for (int d = 0; d < 3; d++)
        q.min[d] = -1, q.max[d] = 2;
    }
    fcm_implicit_tree t = {1, &q};
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const fcm_index n[3] = {cases[k].n, cases[k].n, cases[k].n};
    fcm_level_set_options o = fcm_level_set_options_default();
    o.refinement = cases[k].r, o.max_subcells = 0;
    fcm_level_set_info info;
    fcm_geometry *g = NULL;
    const size_t base = live;
    peak = live;
    const double t0 = fcm_wtime();
    TEST_OK(ctx, fcm_geometry_create_from_level_set(ctx, fcm_implicit_eval, &t, lo, hi, n, &o, &g,
                                                    &info));
    const double el = fcm_wtime() - t0;
    if (g) {
      const double per = (double)(peak - base) / (double)info.subcells;
      printf("%-7s %3d %4d %6g %9lld %10lld %10.1f %9.0f %8.2f\n", cases[k].kind, cases[k].r,
             cases[k].n, cases[k].size, (long long)info.subcells, (long long)info.num_tets,
             (double)(peak - base) / 1e6, per, el);
      if (!(per <= FCM_LEVEL_SET_SUBCELL_BYTES))
        TEST_FAIL_("%s r %d n %d: %.0f bytes per sub-cell, above FCM_LEVEL_SET_SUBCELL_BYTES %d",
                   cases[k].kind, cases[k].r, cases[k].n, per, FCM_LEVEL_SET_SUBCELL_BYTES);
    }
    fcm_geometry_destroy(&g);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
