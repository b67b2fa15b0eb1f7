/* Benchmark (label "bench"): intersection throughput, i.e. initial cut-cell points per
 * second of one core (clip, tetrahedralize, map both kinds' tet rules), for the
 * convergence-study setup (hemisphere of radius 1 on y = 0 in [-1,1] x [0,1] x [-1,1]) in
 * Tet4/Tet10/Hex8/Hex20 grids with the element's default strengths, without
 * simplification; then the cost of simplifying the stiffness rules of the Hex20 case.
 * "pts/s/core" divides by the summed per-thread wall time of the intersection phase;
 * "pts/cpu-s" (1 thread) by the process CPU time of the whole call (clock()), which is
 * robust on a busy machine but includes setup and gathering.
 * Usage: embed_bench [grid resolution per unit length, default 8] [geometry n, default 8] */
#include "fcm/embed.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

int main(int argc, char **argv)
{
  const int res = argc > 1 ? atoi(argv[1]) : 8, gn = argc > 2 ? atoi(argv[2]) : 8;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const double c0[3] = {0, 0, 0}, lo[3] = {-1, 0, -1}, hi[3] = {1, 1, 1};
  const fcm_index n[3] = {2 * res, res, 2 * res};
  fcm_geometry *g = NULL;
  if (fcm_geometry_create_hemisphere(ctx, c0, 1.0, gn, &g) != FCM_OK) return 1;
  printf("hemisphere: %lld tets; grid %lld x %lld x %lld\n", (long long)fcm_geometry_num_cells(g),
         (long long)n[0], (long long)n[1], (long long)n[2]);
  printf("%-6s %7s %6s %4s %11s %11s %8s %11s %8s %11s %8s\n", "type", "cells", "cut", "thr",
         "pts(stiff)", "pts(mass)", "core-s", "pts/s/core", "wall-s", "pts/cpu-s", "pieces");
  int status = 0;
  for (int t = 0; t < FCM_ELEMENT_COUNT; t++) {
    fcm_mesh *m = NULL;
    if (fcm_mesh_create_box(ctx, (fcm_element_type)t, lo, hi, n, &m) != FCM_OK) return 1;
    for (int threads = 1; threads <= 2; threads++) {
      fcm_cell_rules_options o = fcm_cell_rules_options_default();
      o.simplify = 0;
      o.stabilization.mode = FCM_STABILIZATION_OFF;
      o.num_threads = threads;
      fcm_cell_rules *r = NULL;
      const clock_t cstart = clock();
      const fcm_status st = fcm_cell_rules_create(ctx, m, g, &o, &r);
      const double cpu = (double)(clock() - cstart) / CLOCKS_PER_SEC;
      if (st != FCM_OK) {
        fcm_ctx_error_view(ctx, stderr);
        status = 1;
        break;
      }
      const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
      const double pts = (double)(S->points_initial[0] + S->points_initial[1]);
      char per_cpu[32] = "-";
      if (threads == 1) snprintf(per_cpu, sizeof per_cpu, "%.3g", pts / cpu);
      printf("%-6s %7lld %6lld %4d %11lld %11lld %8.3f %11.3g %8.3f %11s %8lld\n",
             fcm_element_get_info((fcm_element_type)t)->name, (long long)S->num_cells,
             (long long)S->num_cut, threads, (long long)S->points_initial[0],
             (long long)S->points_initial[1], S->time_intersect, pts / S->time_intersect,
             S->time_total, per_cpu, (long long)S->num_pieces);
      fcm_cell_rules_destroy(&r);
    }
    if (t == FCM_ELEMENT_HEX20) { /* simplification of the stiffness rules (mass: 1) */
      fcm_cell_rules_options o = fcm_cell_rules_options_default();
      o.strength[FCM_RULE_MASS] = 1;
      o.num_threads = 2;
      fcm_cell_rules *r = NULL;
      if (fcm_cell_rules_create(ctx, m, g, &o, &r) == FCM_OK) {
        const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
        printf("hex20 stiffness strength %d simplified: %lld -> %lld points in %lld cut cells, "
               "%.3f core-s (%.1f ms per cell), fallbacks %lld, max residual %.2g, wall %.3f s\n",
               fcm_cell_rules_strength(r, FCM_RULE_STIFFNESS), (long long)S->points_initial[0],
               (long long)S->points_simplified[0], (long long)S->num_cut, S->time_simplify,
               1e3 * S->time_simplify / S->num_cut, (long long)S->simplify_fallbacks[0],
               S->max_residual[0], S->time_total);
      }
      fcm_cell_rules_destroy(&r);
    }
    fcm_mesh_destroy(&m);
  }
  fcm_geometry_destroy(&g);
  fcm_ctx_destroy(&ctx);
  return status;
}
