/* Benchmark (label "bench"): intersection throughput, i.e. initial cut-cell points per
 * second of one core (clip, tetrahedralize, map both kinds' tet rules), for the
 * convergence-study setup (hemisphere of radius 1 on y = 0 in [-1,1] x [0,1] x [-1,1]) in
 * Tet4/Tet10/Hex8/Hex20 grids with the element's default strengths, without
 * simplification; then the cost of simplifying the stiffness rules of the Hex20 case.
 * "pts/s/core" divides by the summed per-thread wall time of the intersection phase;
 * "pts/cpu-s" (1 thread) by the process CPU time of the whole call (clock()), which is
 * robust on a busy machine but includes setup and gathering.
 *
 * Cost growth: for a fixed geometry (a ball of radius 0.8 meshed with
 * fcm_geometry_create_ball, resolution 6) in box grids of n^3 Hex8 and Hex20 cells over
 * [-1,1]^3, n = 4, 8, 16, 32, the rules time (one thread, CPU seconds of the call) against the
 * number of cut cells (n = 4, 6, 8, 12, 16, 24, 32), the time per cut cell and the
 * least-squares exponent p of
 * time ~ cut^p; the target is p <= 1.1. Without simplification (the geometric part: clip,
 * tetrahedralize, map) for every n; with simplification while the predicted time (previous
 * grid x 4) stays within GROWTH_SIMPLIFY_BUDGET seconds. Column "p local": the exponent
 * between consecutive grids (the fixed set-up, e.g. the AABB tree of the geometry, weighs
 * on the small grids, so the fit over all grids is lower than the local one at large n);
 * "pts/cut": initial points (both kinds) per cut cell, the size of the simplification
 * problems, which shrinks as the cells do.
 * Usage: embed_bench [grid resolution per unit length, default 8] [geometry n, default 8]
 *        embed_bench growth [largest n, default 32]   (only the growth sweep) */
#include "fcm/embed.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define GROWTH_SIMPLIFY_BUDGET                                                                     \
  60.0 /* seconds a simplified grid may take, predicted as the                                     \
         previous grid's time x (n / n_previous)^2 (cut cells grow                                 \
         like the surface) */

/* Least-squares slope of log y against log x. */
static double fit_exponent(int n, const double *x, const double *y)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int i = 0; i < n; i++) {
    const double lx = log(x[i]), ly = log(y[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  const double den = n * sxx - sx * sx;
  return n >= 2 && den > 0 ? (n * sxy - sx * sy) / den : NAN;
}

/* The growth sweep for one element type and simplification mode; returns 1 when p <= 1.1. */
static int growth(fcm_ctx *ctx, const fcm_geometry *g, fcm_element_type type, int simplify,
                  int nmax, int *failed)
{
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
  static const int ns[] = {4, 6, 8, 12, 16, 24, 32};
  double cut[8], t[8];
  int k = 0, nprev = 0;
  printf("%s, simplification %s:\n%6s %8s %8s %10s %10s %12s %8s\n",
         fcm_element_get_info(type)->name, simplify ? "on" : "off", "n", "cells", "cut", "pts/cut",
         "cpu-s", "ms/cut cell", "p local");
  for (size_t in = 0; in < sizeof ns / sizeof *ns && ns[in] <= nmax; in++) {
    const int n = ns[in];
    const double predicted = k > 0 ? t[k - 1] * (double)(n * n) / (double)(nprev * nprev) : 0.0;
    if (simplify && predicted > GROWTH_SIMPLIFY_BUDGET) {
      printf("%6d  (skipped with simplification: predicted %.0f s > %.0f s)\n", n, predicted,
             GROWTH_SIMPLIFY_BUDGET);
      break;
    }
    nprev = n;
    const fcm_index nn[3] = {n, n, n};
    fcm_mesh *m = NULL;
    fcm_cell_rules *r = NULL;
    fcm_cell_rules_options o = fcm_cell_rules_options_default();
    o.simplify = simplify ? FCM_CELL_SIMPLIFY_ON : FCM_CELL_SIMPLIFY_OFF;
    o.num_threads = 1;
    if (fcm_mesh_create_box(ctx, type, lo, hi, nn, &m) != FCM_OK) {
      *failed = 1;
      return 0;
    }
    const clock_t c0 = clock();
    const fcm_status st = fcm_cell_rules_create(ctx, m, g, &o, &r);
    const double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    if (st != FCM_OK) {
      fcm_ctx_error_view(ctx, stderr);
      fcm_mesh_destroy(&m);
      *failed = 1;
      return 0;
    }
    const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
    cut[k] = (double)S->num_cut, t[k] = cpu;
    char local[16] = "-";
    if (k > 0)
      snprintf(local, sizeof local, "%.3f", log(cpu / t[k - 1]) / log(cut[k] / cut[k - 1]));
    printf("%6d %8lld %8lld %10.0f %10.3f %12.4f %8s\n", n, (long long)S->num_cells,
           (long long)S->num_cut,
           (double)(S->points_initial[0] + S->points_initial[1]) / (double)S->num_cut, cpu,
           1e3 * cpu / (double)S->num_cut, local);
    k++;
    fcm_cell_rules_destroy(&r);
    fcm_mesh_destroy(&m);
  }
  const double p = fit_exponent(k, cut, t);
  const int ok = k >= 2 && p <= 1.1;
  printf("fitted exponent of time vs cut cells (%d grids): %.3f  -> %s\n\n", k, p,
         k < 2 ? "too few grids"
         : ok  ? "linear (<= 1.1)"
               : "NOT linear (> 1.1)");
  return ok;
}

static int run_growth(fcm_ctx *ctx, int nmax)
{
  const double c[3] = {0.013, 0.007, 0.003};
  fcm_geometry *g = NULL;
  int failed = 0;
  if (fcm_geometry_create_ball(ctx, c, 0.8, 6, &g) != FCM_OK) return 1;
  printf("cost growth: ball R = 0.8 (%lld tets) in n^3 grids over [-1,1]^3, one thread\n",
         (long long)fcm_geometry_num_cells(g));
  int linear = 1;
  for (int t = FCM_ELEMENT_HEX8; t <= FCM_ELEMENT_HEX20; t++)
    for (int simp = 0; simp <= 1; simp++)
      linear &= growth(ctx, g, (fcm_element_type)t, simp, nmax, &failed);
  printf("cost growth: %s (CPU time of one thread; with simplification the grids that fit in "
         "about %.0f s each)\n",
         linear ? "every fitted exponent <= 1.1" : "an exponent > 1.1 or too few grids",
         GROWTH_SIMPLIFY_BUDGET);
  fcm_geometry_destroy(&g);
  return failed;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if (argc > 1 && !strcmp(argv[1], "growth")) {
    const int rc = run_growth(ctx, argc > 2 ? atoi(argv[2]) : 32);
    fcm_ctx_destroy(&ctx);
    return rc;
  }
  const int res = argc > 1 ? atoi(argv[1]) : 8, gn = argc > 2 ? atoi(argv[2]) : 8;
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
             S->time_total, per_cpu, (long long)S->num_parts);
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
  printf("\n");
  if (run_growth(ctx, 32)) status = 1;
  fcm_ctx_destroy(&ctx);
  return status;
}
