/* fcm-cutbench: the output — the table on stdout (a line per run, fcm's figures with the
 * paper's beside them), the verdicts against the targets, the CSV (written atomically) and a
 * gnuplot PNG of cut and step times against the papers'. */
#include "cli.h"
#include "fcm-cutbench.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const cutbench_run *cutbench_judged(const cutbench_row *r)
{
  return r->run[1].ok ? &r->run[1] : &r->run[0];
}

/* The targets on run q: 1 holds, 0 fails, -1 no figure to compare with. */
static int cut_holds(const cutbench_paper *p, const cutbench_run *q)
{
  if (!q->ok || p->cut_s <= 0.0 || q->events == 0) return -1;
  return q->cut_max <= p->cut_s;
}

static int step_holds(const cutbench_paper *p, const cutbench_run *q)
{
  if (!q->ok) return -1;
  return q->step_mean <= p->step_factor * p->step_s;
}

static const char *yes_no(int v)
{
  return v < 0 ? "-" : v ? "yes" : "NO";
}

/* ------------------------------------------------------------- table */

void cutbench_print_header(void)
{
  printf(
      "%-15s %-11s %7s %7s %7s %3s %8s %8s %7s %7s %7s %7s %7s %7s %8s %8s %6s %7s | %8s %8s %6s "
      "%6s %4s %4s %9s\n",
      "row", "solver", "cells", "dofs0", "dofs1", "cut", "cut_s", "cut_max", "rules", "space",
      "integ", "struct", "other", "fact", "step_s", "step_max", "newton", "linear", "paper_c",
      "paper_s", "c/p", "s/p", "c_ok", "s_ok", "disp_diff");
  fflush(stdout);
}

static void print_run(const cutbench_row *r, int k)
{
  const cutbench_paper *p = &cutbench_papers[r->id];
  const cutbench_run *q = &r->run[k];
  const char *solver = k ? "interactive" : "defaults";
  if (!q->ok) {
    printf("%-15s %-11s %s: %s\n", p->row, solver, q->skipped ? "skipped" : "FAILED", q->note);
    return;
  }
  printf("%-15s %-11s %7lld %7lld %7lld %3d %8.4f %8.4f %7.4f %7.4f %7.4f %7.4f %7.4f %7.4f "
         "%8.4f %8.4f %6.2f %7.1f | ",
         p->row, solver, q->cells, q->dofs_before, q->dofs_after, q->events, q->cut_mean,
         q->cut_max, q->cut_rules, q->cut_space, q->cut_integ, q->cut_solver, q->cut_other,
         q->cut_factor, q->step_mean, q->step_max, q->newton, q->linear);
  if (p->cut_s > 0.0)
    printf("%8.4f ", p->cut_s);
  else
    printf("%8s ", "-");
  printf("%8.4f ", p->step_s);
  if (p->cut_s > 0.0)
    printf("%6.2f ", q->cut_max / p->cut_s);
  else
    printf("%6s ", "-");
  printf("%6.2f %4s %4s ", q->step_mean / p->step_s, yes_no(cut_holds(p, q)),
         yes_no(step_holds(p, q)));
  if (k == 1 && r->disp_diff >= 0.0)
    printf("%9.2e\n", r->disp_diff);
  else
    printf("%9s\n", "-");
  if (q->runs > 1) {
    printf("%-15s %-11s medians of %d runs; the largest cut ", "", "", q->runs);
    if (q->events > 0)
      printf("%.4f to %.4f s", q->cut_max_lo, q->cut_max_hi);
    else
      printf("-");
    printf(", the mean step %.4f to %.4f s\n", q->step_mean_lo, q->step_mean_hi);
  }
}

void cutbench_print_row(const cutbench_row *r)
{
  for (int k = 0; k < 2; k++)
    if (r->run[k].ran || r->run[k].skipped) print_run(r, k);
  fflush(stdout);
}

int cutbench_print_verdicts(const cutbench_row *rows, int n)
{
  int fails = 0;
  printf("\ntargets: the largest cut <= the paper's cut; the mean step <= paper/2 (Dick) or "
         "paper/10 (Koschier, Ton-That)\n");
  for (int i = 0; i < n; i++) {
    const cutbench_paper *p = &cutbench_papers[rows[i].id];
    const cutbench_run *q = cutbench_judged(&rows[i]);
    if (!q->ok) {
      printf("  %-15s did not run\n", p->row);
      fails++;
      continue;
    }
    const int c = cut_holds(p, q), s = step_holds(p, q);
    printf("  %-15s (%s, %s; %s; fcm %lld -> %lld DOFs, %lld cells): ", p->row, p->paper, p->model,
           p->size, q->dofs_before, q->dofs_after, q->cells);
    if (c < 0)
      printf("cut %.4f s (the paper gives none); ", q->cut_max);
    else
      printf("cut %.4f s <= %.4f s %s; ", q->cut_max, p->cut_s, c ? "holds" : "FAILS");
    printf("mean step %.4f s <= %.4f s (paper/%g) %s", q->step_mean, p->step_factor * p->step_s,
           1.0 / p->step_factor, s ? "holds" : "FAILS");
    if (q->runs > 1) printf(" (medians of %d runs)", q->runs);
    printf("\n");
    if (c == 0 || s == 0) fails++;
    if (rows[i].disp_diff >= 0.0)
      printf("  %-15s interactive against defaults: max |du| %.3e m (max |u| %.3e m)\n", "",
             rows[i].disp_diff, rows[i].disp_max);
  }
  fflush(stdout);
  return fails;
}

/* ------------------------------------------------------------- CSV */

static const char csv_header[] =
    "row,paper,model,paper_size,element,material,solver,status,cell_size,cells,dofs_before,"
    "dofs_after,cut_events,cut_s_mean,cut_s_max,cut_rules_s,cut_space_s,cut_integrator_s,"
    "cut_solver_s,cut_other_s,cut_factor_s,setup_s,steps,step_s_mean,step_s_max,newton_per_step,"
    "linear_per_step,paper_cut_s,paper_step_s,paper_step_max_s,paper_machine,cut_ratio,step_ratio,"
    "step_target_s,cut_ok,step_ok,disp_diff_m,disp_max_m,runs,cut_s_max_lo,cut_s_max_hi,"
    "step_s_mean_lo,step_s_mean_hi,options,note\n";

static void csv_run(FILE *f, const cutbench_row *r, int k)
{
  const cutbench_paper *p = &cutbench_papers[r->id];
  const cutbench_run *q = &r->run[k];
  const int ok = q->ok;
  fprintf(f, "%s", p->row);
  cli_csv_text(f, p->paper), cli_csv_text(f, p->model), cli_csv_text(f, p->size),
      cli_csv_text(f, p->element), cli_csv_text(f, p->material);
  cli_csv_text(f, k ? "interactive" : "defaults");
  cli_csv_text(f, ok ? "ok" : q->skipped ? "skipped" : "failed");
  cli_csv_number(f, r->h);
  const double v[19] = {(double)q->cells,
                        (double)q->dofs_before,
                        (double)q->dofs_after,
                        q->events,
                        q->cut_mean,
                        q->cut_max,
                        q->cut_rules,
                        q->cut_space,
                        q->cut_integ,
                        q->cut_solver,
                        q->cut_other,
                        q->cut_factor,
                        q->setup_s,
                        (double)q->steps,
                        q->step_mean,
                        q->step_max,
                        q->newton,
                        q->linear,
                        0};
  for (int i = 0; i < 18; i++)
    cli_csv_number(f, ok ? v[i] : -1.0);
  cli_csv_number(f, p->cut_s > 0.0 ? p->cut_s : -1.0);
  cli_csv_number(f, p->step_s);
  cli_csv_number(f, p->step_max_s > 0.0 ? p->step_max_s : -1.0);
  cli_csv_text(f, p->machine);
  cli_csv_number(f, ok && p->cut_s > 0.0 && q->events > 0 ? q->cut_max / p->cut_s : -1.0);
  cli_csv_number(f, ok ? q->step_mean / p->step_s : -1.0);
  cli_csv_number(f, p->step_factor * p->step_s);
  const int c = cut_holds(p, q), s = step_holds(p, q);
  cli_csv_text(f, c < 0 ? "" : c ? "yes" : "no");
  cli_csv_text(f, s < 0 ? "" : s ? "yes" : "no");
  cli_csv_number(f, k == 1 ? r->disp_diff : -1.0);
  cli_csv_number(f, k == 0 ? r->disp_max : -1.0);
  cli_csv_number(f, ok ? q->runs : -1.0);
  cli_csv_number(f, ok && q->events > 0 ? q->cut_max_lo : -1.0);
  cli_csv_number(f, ok && q->events > 0 ? q->cut_max_hi : -1.0);
  cli_csv_number(f, ok ? q->step_mean_lo : -1.0);
  cli_csv_number(f, ok ? q->step_mean_hi : -1.0);
  cli_csv_text(f, k ? r->interactive : "");
  cli_csv_text(f, ok ? "" : q->note);
  fputc('\n', f);
}

int cutbench_write_csv(const char *path, const cutbench_row *rows, int n)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, path, &out);
  if (!f) return 0;
  fputs(csv_header, f);
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 2; k++)
      if (rows[i].run[k].ran || rows[i].run[k].skipped) csv_run(f, &rows[i], k);
  return cli_output_commit(PROG, &out);
}

/* ------------------------------------------------------------- PNG */

int cutbench_write_png(const char *path, const cutbench_row *rows, int n)
{
  static cutbench_text sc;
  sc.n = 0, sc.ok = 1;
  static const char *const titles[2] = {"largest cut (s)", "mean step (s)"};
  cutbench_put(
      &sc,
      "set multiplot layout 1,2 title 'fcm-cutbench: fcm beside the papers (log scale)'\n"
      "set datafile missing '?'\nset style data histograms\nset style histogram clustered gap 1\n"
      "set style fill solid 0.8 border -1\nset logscale y\nset grid ytics\nset tmargin 4\n"
      "set xtics rotate by -30 font ',9'\nset key outside bottom center horizontal\n"
      "set xrange [-0.6:%d.6]\n", /* the groups only: no empty slot beside them */
      n - 1);
  for (int panel = 0; panel < 2; panel++) {
    cutbench_put(
        &sc,
        "set title '%s'\nplot '-' using 2:xtic(1) title 'fcm' lc rgb '#1f77b4', '-' using 2 "
        "title 'paper' lc rgb '#7f7f7f', '-' using 2 title 'target' lc rgb '#2ca02c'\n",
        titles[panel]);
    for (int series = 0; series < 3; series++) {
      for (int i = 0; i < n; i++) {
        const cutbench_paper *p = &cutbench_papers[rows[i].id];
        const cutbench_run *q = cutbench_judged(&rows[i]);
        double v;
        if (panel == 0)
          v = series == 0 ? (q->ok ? q->cut_max : NAN) : p->cut_s > 0.0 ? p->cut_s : NAN;
        else
          v = series == 0   ? (q->ok ? q->step_mean : NAN)
              : series == 1 ? p->step_s
                            : p->step_factor * p->step_s;
        if (isfinite(v) && v > 0.0)
          cutbench_put(&sc, "\"%s\" %.6g\n", p->row, v);
        else
          cutbench_put(&sc, "\"%s\" ?\n", p->row);
      }
      cutbench_put(&sc, "e\n");
    }
  }
  cutbench_put(&sc, "unset multiplot\n");
  if (!sc.ok) {
    fprintf(stderr, PROG ": --png: the plot script grew too large\n");
    return 0;
  }
  return cli_gnuplot_png(PROG, "1300,550 font ',10'", path, sc.s);
}
