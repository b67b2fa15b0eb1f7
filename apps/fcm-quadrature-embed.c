/* fcm-quadrature subcommands on embedded rules: `accuracy` (Longva et al. 2020
 * Fig. 4: monomials over a rotated cuboid in [-1,1]^3, initial vs simplified
 * rules) and `embed` (a background grid, an embedded geometry, the statistics). */
#include "cli.h"
#include "fcm-quadrature.h"

#include <fcm/fcm.h>

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ helpers */

static int cmp_double(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* -------------------------------------------------------------- accuracy */

/* The cuboid in its local frame: [lo, hi] with lo > 0 so no monomial integral
 * vanishes; mapped into [-1,1]^3 by x = R y + t (R a rotation, centre near 0). */
static const double cub_lo[3] = {0.30, 0.45, 0.20}, cub_hi[3] = {1.05, 1.00, 0.80};

/* Rotation by angle about a unit axis (Rodrigues), row-major. */
static void rotation(const double axis[3], double angle, double R[9])
{
  double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  double k[3] = {axis[0] / n, axis[1] / n, axis[2] / n}, c = cos(angle), s = sin(angle);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      R[3 * i + j] = (1 - c) * k[i] * k[j] + (i == j ? c : 0.0);
  R[1] -= s * k[2], R[2] += s * k[1], R[3] += s * k[2];
  R[5] -= s * k[0], R[6] -= s * k[1], R[7] += s * k[0];
}

/* Relative errors of the rule (cell 0 of `rules`, identity map) on every monomial
 * y^a of total degree <= m in the cuboid frame y = R^T (x - t). */
static int monomial_errors(const fcm_cell_rules *rules, int m, const double R[9], const double t[3],
                           double *err, int *npts)
{
  int np = 0, count = 0;
  const double *pts = NULL, *w = NULL;
  if (fcm_cell_rules_get(rules, 0, FCM_RULE_STIFFNESS, &np, &pts, &w, NULL) != FCM_OK) return -1;
  *npts = np;
  for (int a = 0; a <= m; a++)
    for (int b = 0; a + b <= m; b++)
      for (int c = 0; a + b + c <= m; c++) {
        int e[3] = {a, b, c};
        double exact = 1.0, q = 0.0;
        for (int d = 0; d < 3; d++)
          exact *= (pow(cub_hi[d], e[d] + 1) - pow(cub_lo[d], e[d] + 1)) / (e[d] + 1);
        for (int p = 0; p < np; p++) {
          double x[3], y[3];
          for (int d = 0; d < 3; d++)
            x[d] = pts[3 * p + d] - t[d];
          for (int d = 0; d < 3; d++)
            y[d] = R[d] * x[0] + R[3 + d] * x[1] + R[6 + d] * x[2];
          /* reference [-1,1]^3 = physical [-1,1]^3: det J = 1 */
          q += w[p] * pow(y[0], a) * pow(y[1], b) * pow(y[2], c);
        }
        err[count++] = fabs(q - exact) / fabs(exact);
      }
  return count;
}

static void accuracy_usage(FILE *f, const cli_option *opts)
{
  fprintf(f, "usage: fcm-quadrature accuracy [--max-strength M] [--csv FILE]\n"
             "\n"
             "Longva et al. 2020, Fig. 4: a cuboid, rotated and translated, embedded in the\n"
             "reference hexahedron [-1,1]^3. For every strength m = 1..M, every monomial of\n"
             "total degree <= m in the cuboid's local frame (translated so that no integral\n"
             "vanishes) is integrated with the initial cut-cell rule (tetrahedralized\n"
             "intersection) and the simplified rule (<= (m+3 choose 3) positive points), and\n"
             "compared with its analytic value.\n"
             "\n");
  cli_print_options(f, opts);
}

int fcm_quadrature_cmd_accuracy(int argc, char **argv)
{
  int maxm = 10, rc = 1;
  const char *csv = NULL;
  const cli_option opts[] = {{"--max-strength", NULL, CLI_INT, &maxm, "M", "1..20 (default 10)", 1,
                              20, 0, NULL, NULL, NULL},
                             {"--csv", NULL, CLI_STRING, &csv, "FILE",
                              "write strength,rule,points,max_rel_error,median_rel_error", 0, 0, 0,
                              NULL, NULL, NULL},
                             {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  const int prc = fcm_quadrature_parse(opts, argc, argv, accuracy_usage);
  if (prc >= 0) return prc;
  fcm_ctx *ctx = NULL;
  fcm_mesh *cell = NULL;
  fcm_geometry *box = NULL, *cuboid = NULL;
  double *err = NULL;
  FILE *out = NULL;
  cli_output *outf = NULL;
  const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, axis[3] = {1.0, 2.0, 0.5};
  const fcm_index one[3] = {1, 1, 1}, nb[3] = {2, 2, 2};
  double R[9], t[3], c[3];
  rotation(axis, 0.7, R);
  for (int d = 0; d < 3; d++)
    c[d] = 0.5 * (cub_lo[d] + cub_hi[d]);
  for (int d = 0; d < 3; d++) /* the cuboid's centre goes to (0.03, -0.02, 0.05) */
    t[d] = (d == 0   ? 0.03
            : d == 1 ? -0.02
                     : 0.05) -
           (R[3 * d] * c[0] + R[3 * d + 1] * c[1] + R[3 * d + 2] * c[2]);
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if (fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, one, &cell) != FCM_OK ||
      fcm_geometry_create_box(ctx, cub_lo, cub_hi, nb, &box) != FCM_OK ||
      fcm_geometry_create_transformed(ctx, box, R, t, &cuboid) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    goto done;
  }
  {
    double glo[3], ghi[3];
    fcm_geometry_bounding_box(cuboid, glo, ghi);
    for (int d = 0; d < 3; d++)
      if (glo[d] <= -1 || ghi[d] >= 1) {
        fprintf(stderr, "fcm-quadrature: internal: the cuboid leaves [-1,1]^3\n");
        goto done;
      }
  }
  err = malloc(sizeof *err * 2000);
  if (!err) goto done;
  if (csv && !(out = cli_output_open("fcm-quadrature", csv, &outf))) goto done;
  if (out) fprintf(out, "strength,rule,points,max_rel_error,median_rel_error\n");
  printf("%8s %10s %7s %7s %14s %14s\n", "strength", "rule", "points", "M", "max_rel_err",
         "median_rel_err");
  for (int m = 1; m <= maxm; m++) {
    for (int simplify = 0; simplify <= 1; simplify++) {
      fcm_cell_rules_options ro = fcm_cell_rules_options_default();
      fcm_cell_rules *rules = NULL;
      ro.strength[FCM_RULE_STIFFNESS] = m;
      ro.strength[FCM_RULE_MASS] = m;
      ro.simplify = simplify;
      ro.stabilization.mode = FCM_STABILIZATION_OFF;
      if (fcm_cell_rules_create(ctx, cell, cuboid, &ro, &rules) != FCM_OK) {
        fcm_ctx_error_view(ctx, stderr);
        goto done;
      }
      int np = 0, count = monomial_errors(rules, m, R, t, err, &np);
      const fcm_cell_rules_stats *st = fcm_cell_rules_get_stats(rules);
      int fallback = st->simplify_fallbacks[FCM_RULE_STIFFNESS] > 0;
      fcm_cell_rules_destroy(&rules);
      if (count <= 0) goto done;
      double mx = 0.0;
      for (int k = 0; k < count; k++)
        mx = fmax(mx, err[k]);
      qsort(err, (size_t)count, sizeof *err, cmp_double);
      double med = count % 2 ? err[count / 2] : 0.5 * (err[count / 2 - 1] + err[count / 2]);
      const char *name = simplify ? "simplified" : "initial";
      printf("%8d %10s %7d %7d %14.3e %14.3e%s\n", m, name, np, (m + 1) * (m + 2) * (m + 3) / 6, mx,
             med, fallback ? "  (simplification fell back)" : "");
      if (out) fprintf(out, "%d,%s,%d,%.6e,%.6e\n", m, name, np, mx, med);
      fflush(stdout);
    }
  }
  if (out) {
    out = NULL;
    if (!cli_output_commit("fcm-quadrature", &outf)) goto done;
  }
  rc = 0;
done:
  cli_output_abort(&outf); /* after a failure: the temporary goes, the target stays */
  free(err);
  fcm_geometry_destroy(&cuboid);
  fcm_geometry_destroy(&box);
  fcm_mesh_destroy(&cell);
  fcm_ctx_destroy(&ctx);
  return rc;
}

/* ----------------------------------------------------------------- embed */

static void embed_usage(FILE *f, const cli_option *opts)
{
  fprintf(f, "usage: fcm-quadrature embed --element {tet4,tet10,hex8,hex20}\n"
             "           --box X0 Y0 Z0 X1 Y1 Z1 --cells NX NY NZ --geometry FILE|SHAPE\n"
             "           --strength M [--mass-strength M] [--no-simplify] [--stabilization A]\n"
             "           [--min-fraction PHI] [--dump FILE] [--fill-holes] [--max-volume V]\n"
             "\n"
             "Builds the background grid, embeds the geometry, builds the cut-cell rules and\n"
             "prints their statistics (cells per class, points before and after\n"
             "simplification, fallbacks, residual, volumes, time per phase).\n"
             "\n");
  cli_print_options(f, opts);
}

/* The background grid, the geometry and the cell rules with their statistics on stdout (and
 * the points into --dump); the exit code. */
static int embed_run(const fcm_quadrature_grid *a, const char *dump)
{
  int rc = 1;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_cell_rules *rules = NULL;
  FILE *out = NULL;
  cli_output *outf = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  if ((rc = fcm_quadrature_grid_build(ctx, a, "embed", &mesh, &geom)) != 0) goto done;
  rc = 1;
  const fcm_cell_rules_options ro = fcm_quadrature_grid_rules_options(a);
  fprintf(stderr, "fcm-quadrature embed: %lld background cells, %lld embedded cells ...\n",
          (long long)fcm_mesh_num_cells(mesh), (long long)fcm_geometry_num_cells(geom));
  if (fcm_cell_rules_create(ctx, mesh, geom, &ro, &rules) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    goto done;
  }
  fcm_cell_rules_view(rules, stdout);
  if (dump) {
    if (!(out = cli_output_open("fcm-quadrature", dump, &outf))) goto done;
    if (fcm_cell_rules_view_points(rules, mesh, FCM_RULE_STIFFNESS, out) != FCM_OK) {
      fcm_ctx_error_view(ctx, stderr);
      goto done;
    }
    out = NULL;
    if (!cli_output_commit("fcm-quadrature", &outf)) goto done;
  }
  rc = 0;
done:
  cli_output_abort(&outf); /* after a failure: the temporary goes, the target stays */
  fcm_cell_rules_destroy(&rules);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  fcm_ctx_destroy(&ctx);
  return rc;
}

int fcm_quadrature_cmd_embed(int argc, char **argv)
{
  fcm_quadrature_grid g;
  const char *dump = NULL;
  cli_option opts[FCM_QUADRATURE_GRID_OPTIONS + 2];
  fcm_quadrature_grid_init(&g, opts);
  const cli_option own[] = {{"--dump", NULL, CLI_STRING, &dump, "FILE",
                             "one line per stiffness point:\n"
                             "cell xi eta zeta X Y Z w_ref w_phys flag\n"
                             "(w_phys = w_ref |J|; flag 0 embedded, 1 stabilization)",
                             0, 0, 0, NULL, NULL, NULL},
                            {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(opts + FCM_QUADRATURE_GRID_OPTIONS, own, sizeof own);
  const int prc = fcm_quadrature_parse(opts, argc, argv, embed_usage);
  if (prc >= 0) return prc;
  const int crc = fcm_quadrature_grid_check(&g, "embed");
  if (crc >= 0) return crc;
  return embed_run(&g, dump);
}
