/* fcm-condition: the kappa / MINRES tables on stdout, the CSV (written atomically) and the
 * gnuplot PNG of the conditioning study. */
#include "cli.h"
#include "fcm-condition-study.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int condition_write_csv(const char *path, const config *c, const result *res, int nres)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, path, &out);
  if (!f) return 0;
  fprintf(f, "element,preconditioner,stabilization,min_volume_fraction,condition_number,"
             "nominal_fraction,lambda_min_abs,lambda_max_abs,negative_eigenvalues,dofs,"
             "schwarz_blocks,clamped_eigenvalues,minres_iterations,minres_reason,"
             "minres_true_residual,tangent,fictitious,preconditioner_tangent\n");
  for (int k = 0; k < nres; k++) {
    const result *r = &res[k];
    fprintf(f, "%s,%s,%g,%.6e,%.6e,%g,%.6e,%.6e,%lld,%lld,%lld,%lld,%d,%s,%.3e,%s,%s,%s\n",
            fcm_element_get_info(r->element)->name, prec_names[r->prec], r->alpha, r->phi_min,
            r->kappa, r->phi_nominal, r->lmin_abs, r->lmax_abs, (long long)r->negative,
            (long long)r->dofs, (long long)r->blocks, (long long)r->clamped, r->iterations,
            fcm_krylov_reason_name(r->reason), r->true_residual,
            c->project ? "projected" : "unprojected", tangent_model_names[c->fictitious],
            tangent_model_names[c->pc_tangent]);
  }
  return cli_output_commit(PROG, &out);
}

/* Tables on stdout: one row per (element, stabilization, preconditioner), one column per
 * fraction; kappa, then MINRES iterations. */
void condition_print_tables(const config *c, const result *res, int nres)
{
  for (int table = 0; table < 2; table++) {
    printf("\n%s\n", table == 0 ? "condition number kappa(S A)"
                                : "MINRES iterations to rtol (x0 = 0, b = A 1; * = not converged)");
    printf("%-6s %-14s %-7s", "elem", "precond", "alpha");
    for (int f = 0; f < c->num_fractions; f++)
      printf(" %9.0e", c->fractions[f]);
    printf("\n");
    for (int e = 0; e < c->num_elements; e++)
      for (int sb = 0; sb < 2; sb++) {
        if (!(sb == 0 ? c->stab_on : c->stab_off)) continue;
        double alpha = sb == 0 ? c->alpha : 0.0;
        for (int p = 0; p < c->num_precs; p++) {
          printf("%-6s %-14s %-7.0e", fcm_element_get_info(c->elements[e])->name,
                 prec_names[c->precs[p]], alpha);
          for (int f = 0; f < c->num_fractions; f++) {
            const result *r = NULL;
            for (int k = 0; k < nres && !r; k++)
              if (res[k].element == c->elements[e] && res[k].prec == c->precs[p] &&
                  res[k].alpha == alpha && res[k].phi_nominal == c->fractions[f])
                r = &res[k];
            if (!r)
              printf(" %9s", "-");
            else if (table == 0)
              printf(" %9.2e", r->kappa);
            else
              printf(" %8d%c", r->iterations, r->reason == FCM_KRYLOV_CONVERGED_RTOL ? ' ' : '*');
          }
          printf("\n");
        }
      }
  }
}

int condition_write_png(const config *c, const char *path, const result *res, int nres)
{
  char tmp[4096], script[4096], cmd[8400];
  if (system(NULL) == 0 || system("gnuplot --version > /dev/null 2>&1") != 0) {
    fprintf(stderr,
            PROG ": gnuplot not found (Debian package gnuplot-nox): %s not written; "
                 "the CSV is unaffected\n",
            path);
    return 1;
  }
  if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp ||
      snprintf(script, sizeof script, "%s.gp.tmp", path) >= (int)sizeof script) {
    fprintf(stderr, PROG ": --png: path too long\n");
    return 0;
  }
  FILE *f = fopen(script, "w");
  if (!f) {
    fprintf(stderr, PROG ": cannot write %s: %s\n", script, strerror(errno));
    return 0;
  }
  static const char *const colors[PREC_COUNT] = {"#000000", "#1f77b4", "#d62728", "#2ca02c",
                                                 "#9467bd"};
  /* one datablock per (stabilization, element, preconditioner) series with finite values;
   * panels: rows = stabilization settings run, columns = element shapes run */
  int series = 0, ids[2][4][PREC_COUNT], row_on[2] = {0, 0}, col_on[2] = {0, 0};
  for (int sb = 0; sb < 2; sb++)
    for (int e = 0; e < 4; e++)
      for (int p = 0; p < PREC_COUNT; p++) {
        ids[sb][e][p] = -1;
        int any = 0;
        for (int k = 0; k < nres; k++) {
          const result *r = &res[k];
          if ((int)r->element != e || r->prec != p || (r->alpha > 0.0) != (sb == 0)) continue;
          row_on[sb] = col_on[fcm_element_get_info(r->element)->shape == FCM_SHAPE_TET ? 0 : 1] = 1;
          if (!isfinite(r->kappa)) continue;
          if (!any) fprintf(f, "$S%d << EOD\n", series);
          any = 1;
          fprintf(f, "%.6e %.6e\n", r->phi_min, r->kappa);
        }
        if (any) {
          fprintf(f, "EOD\n");
          ids[sb][e][p] = series++;
        }
      }
  const int nrows = row_on[0] + row_on[1], ncols = col_on[0] + col_on[1];
  fprintf(f, "set terminal png size %d,%d font ',11'\nset output '%s'\n", 200 + 600 * ncols,
          100 + 450 * nrows, tmp);
  fprintf(f, "set logscale xy\nset xrange [*:*] reverse\nset format x '10^{%%L}'\n"
             "set format y '10^{%%L}'\nset grid\nset key top left font ',9'\n"
             "set xlabel 'smallest volume fraction'\nset ylabel 'kappa(SA)'\n");
  fprintf(f,
          "set multiplot layout %d,%d title 'kappa(S (M + dt^2 K)), 4x4x4 grid, box "
          "[0,1+eps/3]^3 (Longva et al. 2020, Fig. 5)'\n",
          nrows, ncols);
  for (int sb = 0; sb < 2; sb++)
    for (int shape = 0; shape < 2; shape++) {
      if (!row_on[sb] || !col_on[shape]) continue;
      /* the linear and the quadratic element of this shape */
      int e0 = -1, e1 = -1;
      for (int e = 0; e < 4; e++) {
        const fcm_element_info *in = fcm_element_get_info((fcm_element_type)e);
        if (!in || (in->shape == FCM_SHAPE_TET) != (shape == 0)) continue;
        if (in->order == 1)
          e0 = e;
        else
          e1 = e;
      }
      fprintf(f, "set title '%s, %s'\n", shape == 0 ? "tetrahedra" : "hexahedra",
              sb == 0 ? "with stabilization" : "without stabilization");
      int first = 1;
      for (int which = 0; which < 2; which++) {
        int e = which == 0 ? e0 : e1;
        if (e < 0) continue;
        /* schwarz-paper under schwarz, wider, so coinciding curves stay visible */
        static const int order[PREC_COUNT] = {PREC_NONE, PREC_JACOBI, PREC_EXACT,
                                              PREC_SCHWARZ_PAPER, PREC_SCHWARZ};
        for (int q = 0; q < PREC_COUNT; q++) {
          int p = order[q], id = ids[sb][e][p];
          if (id < 0) continue;
          fprintf(f,
                  "%s $S%d using 1:2 with linespoints lw %g dt %d pt %d lc rgb '%s' title '%s %s'",
                  first ? "plot" : ",", id, p == PREC_SCHWARZ_PAPER ? 5.0 : 2.0, which == 0 ? 2 : 1,
                  which == 0 ? 6 : 7, colors[p], fcm_element_get_info((fcm_element_type)e)->name,
                  prec_names[p]);
          first = 0;
        }
      }
      if (first) /* nothing finite to draw: keep the panel, say so */
        fprintf(f, "plot [1e-12:1] 1 lc rgb '#ffffff' title 'no finite values'");
      fprintf(f, "\n");
    }
  fprintf(f, "unset multiplot\nset output\n");
  (void)c;
  if (ferror(f) | (fclose(f) != 0)) {
    fprintf(stderr, PROG ": cannot write %s\n", script);
    remove(script);
    return 0;
  }
  snprintf(cmd, sizeof cmd, "gnuplot '%s'", script);
  int rc = system(cmd);
  remove(script);
  if (rc != 0 || rename(tmp, path) != 0) {
    fprintf(stderr, PROG ": gnuplot failed (status %d) or %s could not be renamed\n", rc, tmp);
    remove(tmp);
    return 0;
  }
  return 1;
}
