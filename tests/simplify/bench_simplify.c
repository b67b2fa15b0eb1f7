/* Benchmark of the simplification (label "bench"): microseconds per cell on one core for
 * the default path (Carathéodory elimination) beside the GLPK path the default used before
 * (the plain LP up to N = 12 M, hierarchical recombination with LPs above), their ratio
 * and the target of each case:
 *   M = 20  (m = 3),  N ~ 70:      Tet10-like cut cells,              target 30 us
 *   M = 35  (m = 4),  N ~ 2,900:   the paper's Hex20 case (73 ms per cell per core in
 *                                  Longva et al. 2020),                target 0.5 ms
 *   M = 120 (m = 7),  N ~ 360:                                         target 1.5 ms
 *   M = 165 (m = 8),  N = 64,000:  a Hex20 mass rule of a finely cut cell, target 40 ms
 *   M = 286 (m = 10), N = 110,592: the unit tet red-refined three times, target 0.2 s
 * Inputs are unions of conical rules on (sphere-cut) red-refined sub-tets of the unit tet,
 * the cut-cell situation. Best of `reps` runs per cell (the machine may be shared); every
 * result is checked against the monomial moments of its input.
 * Usage: simplify_bench [--csv FILE] [--quick] (quick: the three small cases only).
 * The CSV has one row per case and path: M,N,method,us_per_cell,fallbacks,max_residual. */
#include "fcm/io.h"
#include "simplify_util.h"

typedef struct stats {
  double us;      /* mean over cells of the best time */
  double part[5]; /* mean us in basis, factorizations, LP/elimination, re-fit, total */
  double res;     /* worst residual */
  double kept;    /* mean kept */
  int fallbacks;  /* cells that fell back */
} stats;

typedef struct bench_case {
  int m, r;               /* strength, red refinements of the unit tet */
  double radius, dradius; /* sphere cut of cell c: radius + c * dradius (0: whole tet) */
  int cells, reps;
  double target_us;
} bench_case;

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
          s.part[k] += 1e6 * part[k] / cells;
        util_check(fcm_simplify_method_name(method), m, n[c], pts[c], w[c], &res, util_num_basis(m),
                   1e-12);
      }
      fcm_simplify_result_destroy(&res);
    }
    s.us += 1e6 * best / cells;
  }
  return s;
}

static void csv_row(FILE *csv, int M, double n, const char *method, const stats *s)
{
  if (csv) fprintf(csv, "%d,%.0f,%s,%.3f,%d,%.3e\n", M, n, method, s->us, s->fallbacks, s->res);
}

int main(int argc, char **argv)
{
  const char *csv_path = NULL;
  int quick = 0;
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--csv") && i + 1 < argc)
      csv_path = argv[++i];
    else if (!strcmp(argv[i], "--quick"))
      quick = 1;
    else {
      fprintf(stderr, "usage: simplify_bench [--csv FILE] [--quick]\n");
      return 2;
    }
  }
  fcm_ctx *ctx = NULL;
  fcm_atomic_file *af = NULL;
  FILE *csv = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  if (csv_path) {
    TEST_OK(ctx, fcm_atomic_file_open(ctx, csv_path, &af));
    if (!af) return TEST_RESULT();
    csv = fcm_atomic_file_stream(af);
    fprintf(csv, "M,N,method,us_per_cell,fallbacks,max_residual\n");
  }
  const char *threads = getenv("OPENBLAS_NUM_THREADS");
  printf("fcm_simplify benchmark, one call per cell, best of reps (OPENBLAS_NUM_THREADS=%s)\n",
         threads ? threads : "unset");
  printf("'before' is the GLPK path the default took before (LP up to N = 12 M, else "
         "recombination with LPs), measured in this run\n");
  printf("%4s %7s %5s %12s %12s %8s %10s %4s %6s %9s %s\n", "M", "N", "cells", "default us",
         "before us", "speedup", "target us", "met", "kept", "max res", "fallbacks");

  const bench_case cases[] = {
      {3, 2, 0.33, 0.002, 16, 20, 30.0}, {4, 3, 0.40, 0.002, 8, 5, 500.0},
      {7, 1, 0.62, 0.002, 8, 5, 1500.0}, {8, 3, 0.0, 0.0, 1, 1, 40000.0},
      {10, 3, 0.0, 0.0, 1, 1, 200000.0},
  };
  const int ncases = quick ? 3 : (int)(sizeof cases / sizeof cases[0]);
  stats def[8];
  int met = 0;
  for (int k = 0; k < ncases; k++) {
    const bench_case *bc = &cases[k];
    const int M = util_num_basis(bc->m);
    int n[32];
    double *p[32], *w[32], nmean = 0.0;
    for (int c = 0; c < bc->cells; c++) {
      const double radius = bc->radius > 0.0 ? bc->radius + c * bc->dradius : 0.0;
      n[c] = util_tet_union(ctx, bc->m, bc->r, radius, &p[c], &w[c]);
      nmean += (double)n[c] / bc->cells;
    }
    const fcm_simplify_method before = nmean > 12.0 * M ? FCM_SIMPLIFY_RECOMBINE : FCM_SIMPLIFY_LP;
    def[k] = run(ctx, FCM_SIMPLIFY_AUTO, bc->m, bc->cells, n, p, w, bc->reps);
    const stats old = run(ctx, before, bc->m, bc->cells, n, p, w, bc->reps);
    const int ok = def[k].us <= bc->target_us && def[k].fallbacks == 0 && def[k].res <= 1e-12;
    met += ok;
    printf("%4d %7.0f %5d %12.1f %12.1f %8.1f %10.0f %4s %6.1f %9.2e %d/%d (before: %s)\n", M,
           nmean, bc->cells, def[k].us, old.us, old.us / def[k].us, bc->target_us,
           ok ? "yes" : "NO", def[k].kept, fmax(def[k].res, old.res), def[k].fallbacks,
           old.fallbacks, fcm_simplify_method_name(before));
    fflush(stdout);
    csv_row(csv, M, nmean, "eliminate (default)", &def[k]);
    csv_row(csv, M, nmean, fcm_simplify_method_name(before), &old);
    for (int c = 0; c < bc->cells; c++) {
      free(p[c]);
      free(w[c]);
    }
  }
  printf("targets met: %d of %d\n", met, ncases);
  printf("\ndefault path, us per cell (first run): basis+moments / LU / elimination / re-fit / "
         "total\n");
  for (int k = 0; k < ncases; k++)
    printf("M = %4d %12.1f %12.1f %12.1f %12.1f %12.1f\n", util_num_basis(cases[k].m),
           def[k].part[0], def[k].part[1], def[k].part[2], def[k].part[3], def[k].part[4]);
  if (af) {
    if (TEST_RESULT() == 0)
      TEST_OK(ctx, fcm_atomic_file_commit(&af));
    else
      fcm_atomic_file_abort(&af);
  }
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
