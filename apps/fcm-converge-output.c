/* fcm-converge: rate fits, the tables on stdout, the CSV files (written atomically) and
 * the gnuplot PNG plots of the convergence / accuracy-versus-time study. */
#include "cli.h"
#include "fcm-converge-study.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *cv_method_name(cv_method m)
{
  return m == CV_FCM ? "fcm" : m == CV_NITSCHE ? "fcm-nitsche" : "fem";
}

static const char *ename(fcm_element_type t)
{
  return fcm_element_get_info(t)->name;
}

static double rel(double err, double norm)
{
  return norm > 0.0 ? err / norm : NAN;
}

/* ---------------------------------------------------------------- rates */

static int cmp_h_desc(const void *a, const void *b)
{
  const cv_result *x = *(const cv_result *const *)a, *y = *(const cv_result *const *)b;
  return x->h < y->h ? 1 : x->h > y->h ? -1 : 0;
}

int cv_rates_compute(const cv_result *res, int nres, int fit, cv_rate *rates)
{
  int nr = 0;
  const cv_result **sel = malloc(sizeof *sel * (size_t)(nres > 0 ? nres : 1));
  if (!sel) return 0;
  for (int e = 0; e < FCM_ELEMENT_COUNT; e++)
    for (int m = 0; m < CV_METHOD_COUNT; m++) {
      int n = 0;
      for (int k = 0; k < nres; k++)
        if ((int)res[k].element == e && (int)res[k].method == m && !res[k].failed)
          sel[n++] = &res[k];
      if (n == 0) continue;
      qsort(sel, (size_t)n, sizeof *sel, cmp_h_desc); /* coarse to fine */
      for (int norm = 0; norm < 2; norm++) {
        double h[64], err[64];
        const int use = n < fit ? n : fit;
        int mono = 1;
        for (int k = 0; k + 1 < n; k++) {
          const double a = norm ? sel[k]->err_h1 : sel[k]->err_l2;
          const double b = norm ? sel[k + 1]->err_h1 : sel[k + 1]->err_l2;
          if (!(b < a)) mono = 0;
        }
        for (int k = 0; k < use && k < 64; k++) {
          const cv_result *r = sel[n - use + k];
          h[k] = r->h;
          err[k] = norm ? r->err_h1 : r->err_l2;
        }
        cv_rate *R = &rates[nr++];
        R->element = (fcm_element_type)e;
        R->method = (cv_method)m;
        R->norm = norm;
        R->rate = cv_fit_rate(use, h, err);
        R->levels = use;
        R->monotone = mono;
        R->h_max = h[0];
        R->h_min = h[use - 1];
      }
    }
  free(sel);
  return nr;
}

/* ---------------------------------------------------------------- tables */

void cv_print_levels(FILE *f, const cv_result *res, int nres)
{
  fprintf(f, "\n%-5s %-11s %4s %7s %8s %7s %6s %9s %3s %8s %8s %8s %8s %8s %9s %9s %6s\n", "elem",
          "meth", "res", "h", "dofs", "cells", "cut", "points", "m", "t_rules", "t_asm", "t_solve",
          "t_total", "cpu_tot", "rel_L2", "rel_H1", "meas");
  for (int k = 0; k < nres; k++) {
    const cv_result *r = &res[k];
    fprintf(f,
            "%-5s %-11s %4d %7.4f %8lld %7lld %6lld %9lld %3d %8.3f %8.3f %8.3f %8.3f %8.3f %9.3e "
            "%9.3e %6.4f%s%s\n",
            ename(r->element), cv_method_name(r->method), r->res, r->h, (long long)r->dofs,
            (long long)r->active_cells, (long long)r->cut_cells, (long long)r->points, r->strength,
            r->t_rules, r->t_assembly, r->t_solve, r->t_total, r->c_total,
            rel(r->err_l2, r->norm_l2), rel(r->err_h1, r->norm_h1),
            r->domain_volume > 0 ? r->measured_volume / r->domain_volume : 0.0,
            r->failed    ? "  FAILED: "
            : r->note[0] ? "  "
                         : "",
            r->note);
  }
}

void cv_print_rates(FILE *f, const cv_rate *rates, int nrates)
{
  fprintf(f, "\nfitted rates (least squares of log err vs log h over the finest levels)\n");
  fprintf(f, "%-5s %-11s %8s %8s %9s %14s\n", "elem", "meth", "L2", "H1", "monotone", "h range");
  for (int k = 0; k + 1 < nrates; k += 2) {
    const cv_rate *a = &rates[k], *b = &rates[k + 1];
    fprintf(f, "%-5s %-11s %8.3f %8.3f %4s/%-4s %6.4f-%-6.4f (%d levels)\n", ename(a->element),
            cv_method_name(a->method), a->rate, b->rate, a->monotone ? "yes" : "no",
            b->monotone ? "yes" : "no", a->h_min, a->h_max, a->levels);
  }
}

/* Cheapest run (total time) reaching each relative L2 target, per element x method. */
void cv_print_pareto(FILE *f, const cv_result *res, int nres, int cpu)
{
  static const double targets[] = {3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5};
  const int nt = (int)(sizeof targets / sizeof *targets);
  fprintf(f,
          "\naccuracy versus time: least total %s time [s] (rules + assembly + solve) of a "
          "run\nreaching the relative L2 error in the column head ('-': none reached it)\n",
          cpu ? "CPU" : "wall-clock");
  fprintf(f, "%-5s %-11s", "elem", "meth");
  for (int t = 0; t < nt; t++)
    fprintf(f, " %8.0e", targets[t]);
  fprintf(f, "\n");
  for (int e = 0; e < FCM_ELEMENT_COUNT; e++)
    for (int m = 0; m < CV_METHOD_COUNT; m++) {
      int any = 0;
      for (int k = 0; k < nres; k++)
        any |= (int)res[k].element == e && (int)res[k].method == m;
      if (!any) continue;
      fprintf(f, "%-5s %-11s", ename((fcm_element_type)e), cv_method_name((cv_method)m));
      for (int t = 0; t < nt; t++) {
        double best = HUGE_VAL;
        for (int k = 0; k < nres; k++) {
          const cv_result *r = &res[k];
          if ((int)r->element != e || (int)r->method != m || r->failed) continue;
          if (rel(r->err_l2, r->norm_l2) <= targets[t])
            best = fmin(best, cpu ? r->c_total : r->t_total);
        }
        if (isfinite(best))
          fprintf(f, " %8.3f", best);
        else
          fprintf(f, " %8s", "-");
      }
      fprintf(f, "\n");
    }
}

void cv_print_sweep(FILE *f, const cv_result *res, int nres)
{
  if (nres == 0) return;
  fprintf(f,
          "\nquadrature strength sweep: %s FCM, res %d (h = %.4f), cut-cell stiffness strength m\n",
          ename(res[0].element), res[0].res, res[0].h);
  fprintf(f, "%3s %9s %8s %8s %8s %8s %8s %9s %9s\n", "m", "points", "t_rules", "t_asm", "t_solve",
          "t_total", "cpu_tot", "rel_L2", "rel_H1");
  for (int k = 0; k < nres; k++) {
    const cv_result *r = &res[k];
    fprintf(f, "%3d %9lld %8.3f %8.3f %8.3f %8.3f %8.3f %9.3e %9.3e%s%s\n", r->strength,
            (long long)r->points, r->t_rules, r->t_assembly, r->t_solve, r->t_total, r->c_total,
            rel(r->err_l2, r->norm_l2), rel(r->err_h1, r->norm_h1),
            r->failed    ? "  FAILED: "
            : r->note[0] ? "  "
                         : "",
            r->note);
  }
}

/* ---------------------------------------------------------------- CSV */

/* The note without commas or quotes (CSV field). */
static void csv_note(FILE *f, const char *note)
{
  for (const char *p = note; *p; p++)
    fputc(*p == ',' || *p == '"' || *p == '\n' ? ';' : *p, f);
}

int cv_write_levels_csv(const char *path, const cv_result *res, int nres)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(CV_PROG, path, &out);
  if (!f) return 0;
  fprintf(f, "element,method,res,h,dofs,active_cells,cut_cells,points,strength,t_rules,"
             "t_assembly,t_solve,t_total,err_l2,err_h1,norm_l2,norm_h1,rel_l2,rel_h1,"
             "measured_volume,domain_volume,failed,note,cpu_rules,cpu_assembly,cpu_solve,"
             "cpu_total\n");
  for (int k = 0; k < nres; k++) {
    const cv_result *r = &res[k];
    fprintf(f,
            "%s,%s,%d,%.17g,%lld,%lld,%lld,%lld,%d,%.6f,%.6f,%.6f,%.6f,%.10e,%.10e,%.10e,"
            "%.10e,%.6e,%.6e,%.12g,%.12g,%d,",
            ename(r->element), cv_method_name(r->method), r->res, r->h, (long long)r->dofs,
            (long long)r->active_cells, (long long)r->cut_cells, (long long)r->points, r->strength,
            r->t_rules, r->t_assembly, r->t_solve, r->t_total, r->err_l2, r->err_h1, r->norm_l2,
            r->norm_h1, rel(r->err_l2, r->norm_l2), rel(r->err_h1, r->norm_h1), r->measured_volume,
            r->domain_volume, r->failed);
    csv_note(f, r->note);
    fprintf(f, ",%.6f,%.6f,%.6f,%.6f\n", r->c_rules, r->c_assembly, r->c_solve, r->c_total);
  }
  return cli_output_commit(CV_PROG, &out);
}

int cv_write_rates_csv(const char *path, const cv_rate *rates, int nrates)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(CV_PROG, path, &out);
  if (!f) return 0;
  fprintf(f, "element,method,norm,rate\n");
  for (int k = 0; k < nrates; k++)
    fprintf(f, "%s,%s,%s,%.6f\n", ename(rates[k].element), cv_method_name(rates[k].method),
            rates[k].norm ? "H1" : "L2", rates[k].rate);
  return cli_output_commit(CV_PROG, &out);
}

int cv_write_sweep_csv(const char *path, const cv_result *res, int nres)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(CV_PROG, path, &out);
  if (!f) return 0;
  fprintf(f,
          "element,method,res,h,strength,points,dofs,t_rules,t_assembly,t_solve,t_total,"
          "err_l2,err_h1,rel_l2,rel_h1,failed,note,cpu_rules,cpu_assembly,cpu_solve,cpu_total\n");
  for (int k = 0; k < nres; k++) {
    const cv_result *r = &res[k];
    fprintf(f, "%s,%s,%d,%.17g,%d,%lld,%lld,%.6f,%.6f,%.6f,%.6f,%.10e,%.10e,%.6e,%.6e,%d,",
            ename(r->element), cv_method_name(r->method), r->res, r->h, r->strength,
            (long long)r->points, (long long)r->dofs, r->t_rules, r->t_assembly, r->t_solve,
            r->t_total, r->err_l2, r->err_h1, rel(r->err_l2, r->norm_l2),
            rel(r->err_h1, r->norm_h1), r->failed);
    csv_note(f, r->note);
    fprintf(f, ",%.6f,%.6f,%.6f,%.6f\n", r->c_rules, r->c_assembly, r->c_solve, r->c_total);
  }
  return cli_output_commit(CV_PROG, &out);
}

/* ---------------------------------------------------------------- plots */

int cv_have_gnuplot(void)
{
  static int have = -1;
  if (have < 0) {
    have = system(NULL) != 0 && system("gnuplot --version > /dev/null 2>&1") == 0;
    if (!have)
      fprintf(stderr, CV_PROG ": gnuplot not found (Debian package gnuplot-nox): no PNG plots "
                              "are written; the CSV files carry every number\n");
  }
  return have;
}

static const char *const elem_colors[FCM_ELEMENT_COUNT] = {"#1f77b4", "#2ca02c", "#ff7f0e",
                                                           "#d62728"};

/* Open the script `path`.gp.tmp, with the PNG going to `path`.tmp. */
static FILE *script_open(const char *path, char *script, char *tmp, size_t cap)
{
  if (snprintf(tmp, cap, "%s.tmp", path) >= (int)cap ||
      snprintf(script, cap, "%s.gp.tmp", path) >= (int)cap || strpbrk(path, "'\\\"")) {
    fprintf(stderr, CV_PROG ": %s: path too long or contains quotes/backslashes\n", path);
    return NULL;
  }
  FILE *f = fopen(script, "w");
  if (!f) fprintf(stderr, CV_PROG ": cannot write %s: %s\n", script, strerror(errno));
  return f;
}

/* PNG terminal: cairo when this gnuplot has it (dashed lines), else libgd. */
static void script_terminal(FILE *f, int w, int h, const char *tmp)
{
  fprintf(f,
          "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
          "  set terminal pngcairo size %d,%d font ',10'\n"
          "} else {\n"
          "  set terminal png size %d,%d font ',11'\n"
          "}\n"
          "set termoption noenhanced\nset output '%s'\n",
          w, h, w, h, tmp);
}

static int script_run(FILE *f, const char *script, const char *tmp, const char *path)
{
  char cmd[4200];
  if (ferror(f) | (fclose(f) != 0)) {
    fprintf(stderr, CV_PROG ": cannot write %s\n", script);
    remove(script);
    return 0;
  }
  snprintf(cmd, sizeof cmd, "gnuplot '%s'", script);
  const int rc = system(cmd);
  remove(script);
  if (rc != 0 || rename(tmp, path) != 0) {
    fprintf(stderr, CV_PROG ": gnuplot failed (status %d) or %s could not be renamed\n", rc, tmp);
    remove(tmp);
    return 0;
  }
  return 1;
}

/* Datablock $D<e><m> per (element, method) with columns
 * h dofs time rel_l2 rel_h1 err_l2 err_h1 (time: total wall or CPU seconds), coarse to
 * fine; returns the blocks written. */
static int write_blocks(FILE *f, const cv_result *res, int nres, int cpu,
                        int have[FCM_ELEMENT_COUNT][CV_METHOD_COUNT])
{
  int nb = 0;
  for (int e = 0; e < FCM_ELEMENT_COUNT; e++)
    for (int m = 0; m < CV_METHOD_COUNT; m++) {
      have[e][m] = 0;
      for (int k = 0; k < nres; k++) {
        const cv_result *r = &res[k];
        if ((int)r->element != e || (int)r->method != m || r->failed) continue;
        if (!have[e][m]) fprintf(f, "$D%d%d << EOD\n", e, m);
        have[e][m] = 1;
        fprintf(f, "%.10e %lld %.6e %.6e %.6e %.6e %.6e\n", r->h, (long long)r->dofs,
                fmax(cpu ? r->c_total : r->t_total, 1e-4), rel(r->err_l2, r->norm_l2),
                rel(r->err_h1, r->norm_h1), r->err_l2, r->err_h1);
      }
      if (have[e][m]) fprintf(f, "EOD\n"), nb++;
    }
  return nb;
}

static void plot_series(FILE *f, int have[FCM_ELEMENT_COUNT][CV_METHOD_COUNT], const char *xcol,
                        const char *ycol, const cv_rate *rates, int nrates, int norm)
{
  int first = 1;
  for (int e = 0; e < FCM_ELEMENT_COUNT; e++)
    for (int m = 0; m < CV_METHOD_COUNT; m++) {
      if (!have[e][m]) continue;
      char label[64];
      double rate = NAN;
      for (int k = 0; k < nrates; k++)
        if ((int)rates[k].element == e && (int)rates[k].method == m && rates[k].norm == norm)
          rate = rates[k].rate;
      if (rates && isfinite(rate))
        snprintf(label, sizeof label, "%s %s (rate %.2f)", ename((fcm_element_type)e),
                 cv_method_name((cv_method)m), rate);
      else
        snprintf(label, sizeof label, "%s %s", ename((fcm_element_type)e),
                 cv_method_name((cv_method)m));
      fprintf(f, "%s $D%d%d using %s:%s with linespoints lw %s dt %d pt %d lc rgb '%s' title '%s'",
              first ? "plot" : ",", e, m, xcol, ycol, m != CV_FEM ? "2" : "1.5",
              m != CV_FEM ? 1 : 2, m != CV_FEM ? 7 : 6, elem_colors[e], label);
      first = 0;
    }
  if (first) fprintf(f, "plot 1/0 notitle");
  fprintf(f, "\n");
}

int cv_plot_convergence(const char *path, const cv_result *res, int nres, const cv_rate *rates,
                        int nrates, const char *title)
{
  char script[4096], tmp[4096];
  int have[FCM_ELEMENT_COUNT][CV_METHOD_COUNT];
  if (!cv_have_gnuplot()) return 1;
  FILE *f = script_open(path, script, tmp, sizeof tmp);
  if (!f) return 0;
  write_blocks(f, res, nres, 0, have);
  script_terminal(f, 1400, 620, tmp);
  fprintf(f, "set logscale xy\nset grid\nset key bottom right font ',9'\n"
             "set format y '%%.0e'\nset xlabel 'h'\n");
  fprintf(f, "set multiplot layout 1,2 title '%s'\n", title);
  fprintf(f, "set title 'L2 error (relative)'\nset ylabel '||u_h - u|| / ||u||'\n");
  plot_series(f, have, "1", "4", rates, nrates, 0);
  fprintf(f, "set title 'H1 seminorm error (relative)'\nset ylabel '|u_h - u|_1 / |u|_1'\n");
  plot_series(f, have, "1", "5", rates, nrates, 1);
  fprintf(f, "unset multiplot\nset output\n");
  return script_run(f, script, tmp, path);
}

int cv_plot_pareto(const char *path, const cv_result *res, int nres, int cpu, const char *title)
{
  char script[4096], tmp[4096];
  int have[FCM_ELEMENT_COUNT][CV_METHOD_COUNT];
  if (!cv_have_gnuplot()) return 1;
  FILE *f = script_open(path, script, tmp, sizeof tmp);
  if (!f) return 0;
  write_blocks(f, res, nres, cpu, have);
  script_terminal(f, 1400, 1100, tmp);
  fprintf(f, "set logscale xy\nset grid\nset key top right font ',9'\nset format y '%%.0e'\n");
  fprintf(f, "set multiplot layout 2,2 title '%s'\n", title);
  fprintf(f,
          "set title 'L2 error vs total %s time'\nset xlabel 'rules + assembly + solve [s]'\n"
          "set ylabel 'relative L2 error'\n",
          cpu ? "CPU" : "wall-clock");
  plot_series(f, have, "3", "4", NULL, 0, 0);
  fprintf(f, "set title 'L2 error vs DOFs'\nset xlabel 'DOFs'\n");
  plot_series(f, have, "2", "4", NULL, 0, 0);
  fprintf(f,
          "set title 'H1 error vs total %s time'\nset xlabel 'rules + assembly + solve [s]'\n"
          "set ylabel 'relative H1 seminorm error'\n",
          cpu ? "CPU" : "wall-clock");
  plot_series(f, have, "3", "5", NULL, 0, 0);
  fprintf(f, "set title 'H1 error vs DOFs'\nset xlabel 'DOFs'\n");
  plot_series(f, have, "2", "5", NULL, 0, 0);
  fprintf(f, "unset multiplot\nset output\n");
  return script_run(f, script, tmp, path);
}

int cv_plot_sweep(const char *path, const cv_result *res, int nres, const char *title)
{
  char script[4096], tmp[4096];
  if (!cv_have_gnuplot()) return 1;
  FILE *f = script_open(path, script, tmp, sizeof tmp);
  if (!f) return 0;
  fprintf(f, "$S << EOD\n");
  for (int k = 0; k < nres; k++) {
    const cv_result *r = &res[k];
    if (r->failed) continue;
    fprintf(f, "%d %.6e %.6e %.6e %.6e %.6e %lld\n", r->strength, rel(r->err_l2, r->norm_l2),
            rel(r->err_h1, r->norm_h1), fmax(r->t_rules, 1e-4), fmax(r->t_assembly, 1e-4),
            fmax(r->t_total, 1e-4), (long long)r->points);
  }
  fprintf(f, "EOD\n");
  script_terminal(f, 1400, 620, tmp);
  fprintf(f, "set grid\nset key top right font ',9'\nset xlabel 'strength m'\n"
             "set logscale y\nset format y '%%.0e'\nset xtics 1\n");
  fprintf(f, "set multiplot layout 1,2 title '%s'\n", title);
  fprintf(f, "set title 'error vs m'\nset ylabel 'relative error'\n"
             "plot $S using 1:2 with linespoints lw 2 pt 7 title 'L2', "
             "$S using 1:3 with linespoints lw 2 pt 5 title 'H1 seminorm'\n");
  fprintf(f,
          "set title 'time and points vs m'\nset ylabel 'seconds'\nset y2label 'points'\n"
          "set logscale y2\nset y2tics\nset format y2 '%%.0e'\n"
          "plot $S using 1:4 with linespoints lw 2 pt 7 title 'rules', "
          "$S using 1:5 with linespoints lw 2 pt 5 title 'assembly', "
          "$S using 1:6 with linespoints lw 2 pt 9 title 'total', "
          "$S using 1:7 axes x1y2 with linespoints lw 2 dt 2 pt 6 title 'points (right axis)'\n");
  fprintf(f, "unset multiplot\nset output\n");
  return script_run(f, script, tmp, path);
}
