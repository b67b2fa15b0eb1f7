/* Benchmark of the simplification (label "bench"): milliseconds per cell for the plain
 * LP and the hierarchical recombination, side by side with their ratio, for
 *   M = 35  (m = 4),  N ~ 2,900: the paper's Hex20 case, 5.23 s on 28 cores for 2,016
 *                                cells = 73 ms of one core per cell (Longva et al. 2020);
 *   M = 286 (m = 10), N ~ 110,000: the unit tet red-refined three times, conical rules.
 * Inputs are unions of conical rules on sphere-cut sub-tets (the cut-cell situation).
 * Best of `reps` runs per cell (the machine may be shared). Also checks every result. */
#include "simplify_util.h"

typedef struct stats {
  double ms;      /* mean over cells of the best time */
  double part[5]; /* mean ms in basis, SVD, LP, re-fit, total (first run) */
  double res;     /* worst residual */
  double kept;    /* mean kept */
  int fallbacks;  /* cells that fell back */
} stats;

static stats run(fcm_ctx *ctx, fcm_simplify_method method, int m, int cells, int *n, double **pts,
                 double **w, int reps)
{
  stats s = {0, {0, 0, 0, 0, 0}, 0, 0, 0};
  fcm_simplify_options o = fcm_simplify_options_default();
  o.method = method;
  for (int c = 0; c < cells; c++) {
    double best = INFINITY;
    for (int r = 0; r < reps; r++) {
      fcm_simplify_result res;
      fcm_simplify_info info;
      const double t0 = fcm_wtime();
      TEST_OK(ctx, fcm_simplify(ctx, m, n[c], pts[c], w[c], &o, &res, &info));
      const double t = fcm_wtime() - t0;
      best = t < best ? t : best;
      if (r == 0) {
        s.res = fmax(s.res, info.residual);
        s.kept += (double)res.count / cells;
        s.fallbacks += info.fallback;
        const double part[5] = {info.time_basis, info.time_svd, info.time_lp, info.time_refit,
                                info.time_total};
        for (int k = 0; k < 5; k++)
          s.part[k] += 1e3 * part[k] / cells;
        util_check(fcm_simplify_method_name(method), m, n[c], pts[c], w[c], &res, util_num_basis(m),
                   1e-12);
      }
      fcm_simplify_result_destroy(&res);
    }
    s.ms += 1e3 * best / cells;
  }
  return s;
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  const char *threads = getenv("OMP_NUM_THREADS");
  printf("fcm_simplify benchmark (single call per cell; BLAS threads: OMP_NUM_THREADS=%s)\n",
         threads ? threads : "unset");
  printf("%-5s %4s %8s %6s %12s %12s %8s %6s %9s %s\n", "m", "M", "N", "cells", "LP ms/cell",
         "recomb ms", "LP/rec", "kept", "max res", "fallbacks");

  /* m = 4: cells cut from the unit tet after 3 refinements (27 points per sub-tet). */
  enum { CELLS4 = 8 };
  int n4[CELLS4];
  double *p4[CELLS4], *w4[CELLS4], nmean = 0;
  for (int c = 0; c < CELLS4; c++) {
    n4[c] = util_tet_union(ctx, 4, 3, 0.40 + 0.002 * c, &p4[c], &w4[c]);
    nmean += (double)n4[c] / CELLS4;
  }
  stats a = run(ctx, FCM_SIMPLIFY_LP, 4, CELLS4, n4, p4, w4, 5);
  stats b = run(ctx, FCM_SIMPLIFY_RECOMBINE, 4, CELLS4, n4, p4, w4, 5);
  printf("%-5d %4d %8.0f %6d %12.2f %12.2f %8.2f %6.1f %9.2e %d/%d\n", 4, 35, nmean, CELLS4, a.ms,
         b.ms, a.ms / b.ms, b.kept, fmax(a.res, b.res), a.fallbacks, b.fallbacks);
  printf("      paper anchor: 73 ms per cell per core (GLOP primal, 28 cores): LP %.1fx, "
         "recombination %.1fx faster\n",
         73.0 / a.ms, 73.0 / b.ms);
  for (int c = 0; c < CELLS4; c++) {
    free(p4[c]);
    free(w4[c]);
  }

  /* m = 10: the whole unit tet after 3 refinements, 512 x 216 = 110,592 points. */
  int n10;
  double *p10, *w10;
  n10 = util_tet_union(ctx, 10, 3, 0.0, &p10, &w10);
  stats c10 = run(ctx, FCM_SIMPLIFY_LP, 10, 1, &n10, &p10, &w10, 1);
  stats d10 = run(ctx, FCM_SIMPLIFY_RECOMBINE, 10, 1, &n10, &p10, &w10, 1);
  printf("%-5d %4d %8d %6d %12.0f %12.0f %8.2f %6.1f %9.2e %d/%d\n", 10, 286, n10, 1, c10.ms,
         d10.ms, c10.ms / d10.ms, d10.kept, fmax(c10.res, d10.res), c10.fallbacks, d10.fallbacks);
  free(p10);
  free(w10);
  /* Crossover for FCM_SIMPLIFY_AUTO: random rules in a box with N = ratio * M. */
  printf("\ncrossover (random box rules, best of 3): ms LP / ms recombination\n%-5s %4s", "m", "M");
  const int ratios[5] = {2, 4, 8, 16, 32};
  for (int k = 0; k < 5; k++)
    printf("      N=%dM     ", ratios[k]);
  printf("\n");
  for (int m = 2; m <= 10; m += 2) {
    const int M = util_num_basis(m);
    printf("%-5d %4d", m, M);
    for (int k = 0; k < 5; k++) {
      int n = ratios[k] * M;
      double *p = malloc(3 * (size_t)n * sizeof *p), *w = malloc((size_t)n * sizeof *w);
      const double lo[3] = {-1, -1, -1};
      util_random_box((uint64_t)(m * 10 + k), n, lo, 2.0, 1.0, p, w);
      stats e = run(ctx, FCM_SIMPLIFY_LP, m, 1, &n, &p, &w, 3);
      stats f = run(ctx, FCM_SIMPLIFY_RECOMBINE, m, 1, &n, &p, &w, 3);
      printf(" %7.1f/%-7.1f", e.ms, f.ms);
      fflush(stdout);
      free(p);
      free(w);
    }
    printf("\n");
  }

  printf("\nbreakdown, ms per cell (first run): basis / SVD / LP / re-fit / total\n");
  const stats *all[4] = {&a, &b, &c10, &d10};
  const char *names[4] = {"m=4 lp", "m=4 recombine", "m=10 lp", "m=10 recombine"};
  for (int k = 0; k < 4; k++)
    printf("%-15s %10.2f %10.2f %10.2f %10.2f %10.2f\n", names[k], all[k]->part[0], all[k]->part[1],
           all[k]->part[2], all[k]->part[3], all[k]->part[4]);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
