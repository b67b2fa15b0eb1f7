/* fcm-quadrature: quadrature studies and reports. Subcommands are listed in one
 * table; `tables` reports (and with --check re-verifies) the stored rule tables. */
#include "app_env.h"
#include "cli.h"
#include "fcm-quadrature.h"
#include <fcm/fcm.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- tables */

/* Best published counts of positive interior rules (Witherden–Vincent and
 * successors); 0 = not listed. */
static const int best_tet[21] = {0, 1,   4, 8,   14, 14,  24, 35,  46, 59, 79,
                                 0, 123, 0, 172, 0,  251, 0,  352, 0,  474};
static const int best_hex_odd[11] = {1, 6, 14, 34, 58, 90, 148, 199, 282, 369, 505};
static const int best_tri[21] = {0,  1,  3,  6,  6,  7,  12, 15, 16, 19, 25,
                                 28, 33, 37, 42, 49, 55, 60, 67, 73, 79};
static const int best_quad_odd[11] = {1, 4, 8, 12, 20, 28, 37, 48, 60, 72, 85};

typedef struct shape_range {
  fcm_shape shape;
  int max_strength;
} shape_range;

static const shape_range report_shapes[] = {
    {FCM_SHAPE_TET, 20}, {FCM_SHAPE_HEX, 21}, {FCM_SHAPE_TRI, 20}, {FCM_SHAPE_QUAD, 21}};

/* Best published count for strength m: the listed value; on hex and quad, whose
 * tables list odd strengths, an even m takes the count of m + 1 (a rule of
 * strength m + 1 is one of strength m). 0 when nothing is listed. */
static int best_published(fcm_shape shape, int m)
{
  switch (shape) {
  case FCM_SHAPE_TET:
    return m >= 1 && m <= 20 ? best_tet[m] : 0;
  case FCM_SHAPE_TRI:
    return m >= 1 && m <= 20 ? best_tri[m] : 0;
  case FCM_SHAPE_HEX:
    return m >= 1 && m <= 21 ? best_hex_odd[m / 2] : 0;
  case FCM_SHAPE_QUAD:
    return m >= 1 && m <= 21 ? best_quad_odd[m / 2] : 0;
  default:
    return 0;
  }
}

/* dim P_k = binom(k + d, d): no rule of strength 2k or 2k+1 has fewer points. */
static int lower_bound(int dim, int m)
{
  int k = m / 2, c = 1;
  for (int i = 1; i <= dim; i++)
    c = c * (k + i) / i;
  return c;
}

static double factorial(int k)
{
  double f = 1.0;
  for (int i = 2; i <= k; i++)
    f *= i;
  return f;
}

/* Exact integral of x^e0 y^e1 z^e2 on the reference shape, and of its modulus. */
static void monomial_integral(fcm_shape s, const int e[3], double *exact, double *absint)
{
  if (s == FCM_SHAPE_TRI || s == FCM_SHAPE_TET) {
    int dim = s == FCM_SHAPE_TRI ? 2 : 3, sum = e[0] + e[1] + (dim == 3 ? e[2] : 0);
    double v = factorial(e[0]) * factorial(e[1]) * (dim == 3 ? factorial(e[2]) : 1.0) /
               factorial(sum + dim);
    *exact = *absint = v;
    return;
  }
  int dim = fcm_shape_dim(s);
  *exact = *absint = 1.0;
  for (int d = 0; d < dim; d++) {
    *absint *= 2.0 / (e[d] + 1);
    *exact *= e[d] % 2 ? 0.0 : 2.0 / (e[d] + 1);
  }
}

/* Worst error of `rule` over all monomials of degree <= m: |Q - I| / int |f|
 * (compensated sums). Also checks positive weights and strictly interior points;
 * returns 0 when one fails. */
static int verify_rule(const fcm_rule *rule, int m, double *max_err)
{
  fcm_shape s = fcm_rule_shape(rule);
  int dim = fcm_shape_dim(s), n = fcm_rule_num_points(rule), ok = 1;
  const double *x = fcm_rule_points(rule), *w = fcm_rule_weights(rule);
  *max_err = 0.0;
  for (int i = 0; i < n; i++) {
    double rest = 1.0;
    ok = ok && w[i] > 0.0 && isfinite(w[i]);
    for (int d = 0; d < dim; d++) {
      double c = x[(size_t)i * dim + d];
      if (s == FCM_SHAPE_TRI || s == FCM_SHAPE_TET)
        ok = ok && c > 0.0, rest -= c;
      else
        ok = ok && fabs(c) < 1.0;
    }
    if (s == FCM_SHAPE_TRI || s == FCM_SHAPE_TET) ok = ok && rest > 0.0;
  }
  int m2 = dim > 1 ? m : 0, m3 = dim > 2 ? m : 0;
  for (int a = 0; a <= m; a++)
    for (int b = 0; b <= m2 && a + b <= m; b++)
      for (int c = 0; c <= m3 && a + b + c <= m; c++) {
        int e[3] = {a, b, c};
        double sum = 0.0, comp = 0.0, exact, absint;
        for (int i = 0; i < n; i++) {
          double t = w[i];
          for (int d = 0; d < dim; d++)
            t *= pow(x[(size_t)i * dim + d], e[d]);
          double s1 = sum + t;
          comp += fabs(sum) >= fabs(t) ? (sum - s1) + t : (t - s1) + sum;
          sum = s1;
        }
        monomial_integral(s, e, &exact, &absint);
        double err = fabs(sum + comp - exact) / absint;
        if (!(err <= *max_err)) *max_err = err; /* NaN propagates */
      }
  return ok && *max_err <= 1e-13;
}

static void tables_help(FILE *f, const cli_option *opts)
{
  fprintf(f, "usage: fcm-quadrature tables [--check] [--csv FILE]\n"
             "Per shape and strength (tet 1..20, hex 1..21, tri 1..20, quad 1..21): the point\n"
             "count of the catalogue rule (stored table, else computed), the best published\n"
             "count of a positive interior rule and the ratio. Hex and quad even strengths are\n"
             "compared with the published count of the next odd strength; '-' = not listed.\n");
  cli_print_options(f, opts);
}

static int cmd_tables(int argc, char **argv)
{
  int check = 0, failures = 0, missing = 0;
  const char *csv_path = NULL;
  double worst_low = 0.0;
  const cli_option opts[] = {
      {"--check", NULL, CLI_FLAG, &check, NULL,
       "re-verify every rule: all monomials up to the strength exact to\n"
       "1e-13 (|Q - I| / int |f|), weights positive, points strictly inside;\n"
       "exit status 1 if any fails",
       0, 0, 0, NULL, NULL, NULL},
      {"--csv", NULL, CLI_STRING, &csv_path, "FILE",
       "also write shape,strength,points,best_published,ratio", 0, 0, 0, NULL, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  const int rc = fcm_quadrature_parse(opts, argc, argv, tables_help);
  if (rc >= 0) return rc;
  FILE *csv = NULL;
  cli_output *csv_out = NULL;
  if (csv_path && !(csv = cli_output_open("fcm-quadrature", csv_path, &csv_out))) return 1;
  if (csv) fprintf(csv, "shape,strength,points,best_published,ratio\n");
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-quadrature: cannot create context\n");
    cli_output_abort(&csv_out);
    return 1;
  }
  printf("%-5s %3s %7s %-8s %8s %9s %6s %6s%s\n", "shape", "m", "points", "origin", "computed",
         "published", "ratio", "bound", check ? "  max monomial error" : "");
  for (size_t s = 0; s < sizeof report_shapes / sizeof report_shapes[0]; s++) {
    fcm_shape shape = report_shapes[s].shape;
    const char *name = fcm_shape_name(shape);
    for (int m = 1; m <= report_shapes[s].max_strength; m++) {
      fcm_rule *rule = NULL, *comp = NULL;
      if (fcm_rule_create(ctx, shape, m, &rule) != FCM_OK ||
          fcm_rule_create_computed(ctx, shape, m, &comp) != FCM_OK) {
        fcm_ctx_error_view(ctx, stderr);
        failures++;
        fcm_rule_destroy(&rule);
        continue;
      }
      int n = fcm_rule_num_points(rule), best = best_published(shape, m);
      int table = fcm_rule_get_origin(rule) == FCM_RULE_TABLE;
      double ratio = best > 0 ? (double)n / best : 0.0;
      char ratio_s[16] = "-", best_s[16] = "-";
      if (best > 0) {
        snprintf(ratio_s, sizeof ratio_s, "%.3f", ratio);
        snprintf(best_s, sizeof best_s, "%d", best);
      }
      if (!table) missing++;
      if (m <= 10 && (shape == FCM_SHAPE_TET || shape == FCM_SHAPE_HEX) && ratio > worst_low)
        worst_low = ratio;
      printf("%-5s %3d %7d %-8s %8d %9s %6s %6d", name, m, n, table ? "table" : "computed",
             fcm_rule_num_points(comp), best_s, ratio_s, lower_bound(fcm_shape_dim(shape), m));
      if (check) {
        double err;
        int ok = verify_rule(rule, m, &err);
        failures += !ok;
        printf("  %.2e %s", err, ok ? "ok" : "FAILED");
      }
      printf("\n");
      if (csv) {
        fprintf(csv, "%s,%d,%d,", name, m, n);
        if (best > 0)
          fprintf(csv, "%d,%.4f\n", best, ratio);
        else
          fprintf(csv, ",\n");
      }
      fcm_rule_destroy(&rule);
      fcm_rule_destroy(&comp);
    }
  }
  printf("largest ratio for tet and hex strengths <= 10: %.3f; rules without a table: %d",
         worst_low, missing);
  if (check) printf("; verification failures: %d", failures);
  printf("\n");
  fcm_ctx_destroy(&ctx);
  if (csv && !cli_output_commit("fcm-quadrature", &csv_out)) return 1;
  return failures ? 1 : 0;
}

/* ---------------------------------------------------------------- driver */

int fcm_quadrature_parse(const cli_option *opts, int argc, char **argv,
                         void (*help)(FILE *f, const cli_option *opts))
{
  char prog[64];
  snprintf(prog, sizeof prog, "fcm-quadrature %s", argv[0]);
  return cli_parse_args(prog, opts, argc, argv, NULL, 0, NULL, help);
}

typedef struct subcommand {
  const char *name;
  const char *summary;
  int (*run)(int argc, char **argv); /* argv[0]: the subcommand name */
} subcommand;

static const subcommand commands[] = {
    {"accuracy", "Longva Fig. 4: monomials over a rotated cuboid, initial vs simplified",
     fcm_quadrature_cmd_accuracy},
    {"embed", "embed a geometry in a background grid, print the cut-cell rule statistics",
     fcm_quadrature_cmd_embed},
    {"export", "write every cell's rules (points, weights, pieces, surface) for other codes",
     fcm_quadrature_cmd_export},
    {"tables", "stored rule tables: counts vs best published, --check re-verifies", cmd_tables},
};

static void usage(FILE *f)
{
  fprintf(f, "usage: fcm-quadrature COMMAND [options]   (COMMAND --help for its options)\n");
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
    fprintf(f, "  %-10s %s\n", commands[i].name, commands[i].summary);
}

int main(int argc, char **argv)
{
  app_env_init(argc, argv);    /* OpenMP waiting, the CPU's BLAS kernels, huge pages (app_env.h) */
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
    if (!strcmp(argv[1], commands[i].name)) return commands[i].run(argc - 1, argv + 1);
  fprintf(stderr, "fcm-quadrature: unknown command '%s'\n", argv[1]);
  usage(stderr);
  return 2;
}
