/* fcm-scaling: the output of the scaling study — the rows on stdout and as CSV (written
 * atomically), the gnuplot PNG, the fitted exponents and the claims. */
#include "cli.h"
#include "fcm-scaling-study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const status_names[] = {"ok", "skipped", "failed"};

/* ------------------------------------------------------------- output */

/* ",v" with `digits` decimals (scientific when sci), or "," alone for a negative v. */
static void csv_field_num(FILE *f, double v, int digits, int sci)
{
  fputc(',', f);
  if (v >= 0.0 && isfinite(v)) fprintf(f, sci ? "%.*e" : "%.*f", digits, v);
}

static void write_row(FILE *f, const row *r)
{
  fprintf(f, "%s,%lld,", fcm_element_get_info(r->type)->name, (long long)r->n);
  if (r->dofs > 0) fprintf(f, "%lld", (long long)r->dofs);
  fprintf(f, ",%s,", solver_names[r->solver]);
  const int ran = r->status != ROW_SKIPPED;
  if (ran && r->iterations > 0) fprintf(f, "%d", r->iterations);
  csv_field_num(f, ran && r->solver != S_CHOLMOD ? r->factor : -1.0, 4, 0);
  csv_field_num(f, ran ? r->setup_s : -1.0, 4, 0);
  csv_field_num(f, ran ? r->solve_s : -1.0, 4, 0);
  csv_field_num(f, ran ? r->peak_mb : -1.0, 1, 0);
  fprintf(f, ",%s,%s", body_names[r->body], status_names[r->status]);
  csv_field_num(f, ran ? r->relres : -1.0, 3, 1);
  csv_field_num(f, ran ? r->diff : -1.0, 3, 1);
  csv_field_num(f, ran ? r->setup_cpu : -1.0, 4, 0);
  csv_field_num(f, ran ? r->solve_cpu : -1.0, 4, 0);
  csv_field_num(f, ran ? r->base_mb : -1.0, 1, 0);
  fputc(',', f);
  if (ran && r->levels > 0) fprintf(f, "%d", r->levels);
  fprintf(f, ",%d,%s\n", r->processes > 0 ? r->processes : 1, r->note);
}

static const char csv_header[] =
    "element,cells,dofs,solver,iterations,convergence_factor,setup_s,solve_s,peak_rss_mb,"
    "body,status,relative_residual,diff_cholmod,setup_cpu_s,solve_cpu_s,base_rss_mb,levels,"
    "processes,note\n";

void scaling_print_row(const row *r)
{
  if (r->status == ROW_SKIPPED) {
    printf("%-5s %-6s %3lld %9lld %-14s skipped: %s\n", fcm_element_get_info(r->type)->name,
           body_names[r->body], (long long)r->n, (long long)r->dofs, solver_names[r->solver],
           r->note);
  } else {
    printf("%-5s %-6s %3lld %9lld %-14s %6d %7.4f %9.3f %9.3f %8.1f %9.2e %9.2e %s%s\n",
           fcm_element_get_info(r->type)->name, body_names[r->body], (long long)r->n,
           (long long)r->dofs, solver_names[r->solver], r->iterations,
           r->factor >= 0 ? r->factor : 0.0, r->setup_s, r->solve_s, r->peak_mb, r->relres,
           r->diff >= 0 ? r->diff : 0.0, r->status == ROW_FAILED ? "FAILED: " : "", r->note);
  }
  fflush(stdout);
}

/* The next plotted series from combination *k on (element ti, body bi, solver si of the
 * settings, in that nesting): the bodies ball and hollow, with rows that ran, cholmod not in
 * the iterations panel (1). 1 with its rows in sr[0..*m), 0 after the last. */
static int next_series(const settings *o, const table *tb, int panel, int *k, int *ti, int *bi,
                       int *si, const row **sr, int *m)
{
  while (*k < o->ntypes * o->nbodies * o->nsolvers) {
    const int c = (*k)++;
    *ti = c / (o->nbodies * o->nsolvers), *bi = c / o->nsolvers % o->nbodies;
    *si = c % o->nsolvers;
    const int b = o->bodies[*bi], s = o->solvers[*si];
    if (b != B_BALL && b != B_HOLLOW) continue;
    *m = scaling_series(tb, o->types[*ti], b, s, sr, 64);
    if (*m == 0 || (panel == 1 && s == S_CHOLMOD)) continue;
    return 1;
  }
  return 0;
}

/* Two panels: setup + solve time against DOFs (log-log, the fitted exponents in the legend) and
 * iterations against DOFs, one line per (element, body, solver) of the bodies ball and
 * hollow. The data go inline into the script. */
int scaling_write_png(const settings *o, const table *tb)
{
  size_t cap = 1 << 16, len = 0;
  char *body = malloc(cap);
  if (!body) return 0;
  int ok = 1;
#define ADD(...)                                                                                   \
  do {                                                                                             \
    int k_ = snprintf(body + len, cap - len, __VA_ARGS__);                                         \
    if (k_ < 0 || (size_t)k_ >= cap - len) {                                                       \
      ok = 0;                                                                                      \
      goto out;                                                                                    \
    }                                                                                              \
    len += (size_t)k_;                                                                             \
  } while (0)
  const char *colors[NSOLVER] = {"#000000", "#1f77b4", "#2ca02c", "#d62728",
                                 "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"};
  for (int panel = 0; panel < 2; panel++) {
    if (panel == 0)
      ADD("set multiplot layout 1,2\nset logscale xy\nset xlabel 'DOFs'\nset ylabel '%s seconds, "
          "setup + solve'\nset key top left font ',8'\nset grid\nset title 'fcm-scaling: time to "
          "the solution (legend: fitted exponents of setup+solve / solve alone)'\n",
          o->clock == CLOCK_CPU ? "CPU" : "wall");
    else
      ADD("set logscale xy\nset ylabel 'iterations (cycles)'\nset title "
          "'iterations to rtol %.0e'\nset key top left font ',8'\n",
          o->rtol);
    int first = 1, k = 0, ti = 0, bi = 0, si = 0, m = 0;
    const row *sr[64];
    while (next_series(o, tb, panel, &k, &ti, &bi, &si, sr, &m)) {
      const int b = o->bodies[bi], s = o->solvers[si];
      const double e = scaling_series_exponent(tb, o->types[ti], b, s, o->clock, 0);
      const double e1 = scaling_series_exponent(tb, o->types[ti], b, s, o->clock, 1);
      char expo[40] = "";
      if (panel == 0 && isfinite(e)) snprintf(expo, sizeof expo, " (%.2f / %.2f)", e, e1);
      ADD("%s '-' using 1:2 with linespoints lc rgb '%s' pt %d dt %d title '%s %s %s%s'",
          first ? "plot" : ",", colors[s], 4 + 2 * bi, 1 + ti,
          fcm_element_get_info(o->types[ti])->name, body_names[b], solver_names[s], expo);
      first = 0;
    }
    if (first) {
      ADD("plot 1 title 'no data'\n");
      continue;
    }
    ADD("\n");
    for (k = 0; next_series(o, tb, panel, &k, &ti, &bi, &si, sr, &m);) {
      for (int i = 0; i < m; i++)
        ADD("%lld %.6g\n", (long long)sr[i]->dofs,
            panel == 0 ? fmax(scaling_row_time(sr[i], o->clock, 0), 1e-4)
                       : (double)sr[i]->iterations);
      ADD("e\n");
    }
  }
  ADD("unset multiplot\n");
#undef ADD
  ok = cli_gnuplot_png(PROG, "1400,650 font ',10'", o->png, body);
out:
  if (!ok) fprintf(stderr, PROG ": --png: the plot script grew too large\n");
  free(body);
  return ok;
}

/* ------------------------------------------------------------- summary and claims */

static int claim(const char *what, int holds, int measured)
{
  printf("  %-74s %s\n", what, !measured ? "NOT MEASURED" : holds ? "holds" : "FAILS");
  return measured && holds;
}

/* Prints the exponents, the V-cycle factors and the claims; returns 1 when every claim holds. */
int scaling_summary(const settings *o, const table *tb)
{
  printf("\nfitted exponents of time against DOFs (least squares in log-log over the sizes that "
         "ran; %s clock): setup+solve / solve alone\n",
         clock_names[o->clock]);
  for (int ti = 0; ti < o->ntypes; ti++)
    for (int bi = 0; bi < o->nbodies; bi++) {
      const int b = o->bodies[bi];
      if (b != B_BALL && b != B_HOLLOW) continue;
      printf("  %-5s %-6s", fcm_element_get_info(o->types[ti])->name, body_names[b]);
      for (int si = 0; si < o->nsolvers; si++) {
        const int s = o->solvers[si];
        const double e1 = scaling_series_exponent(tb, o->types[ti], b, s, o->clock, 0);
        const double e2 = scaling_series_exponent(tb, o->types[ti], b, s, o->clock, 1);
        printf("  %s %.2f / %.2f", solver_names[s], e1, e2);
      }
      printf("\n");
    }
  printf("\nmultigrid convergence factor per cycle (mg rows: V-cycles on cube and cut, W-cycles, "
         "the default, on ball and hollow; Dick et al. 2011 Fig. 10, V: 0.66 uncut, 0.75 cut)\n");
  for (int ti = 0; ti < o->ntypes; ti++)
    for (int b = 0; b < NBODY; b++) {
      const row *sr[64];
      const int m = scaling_series(tb, o->types[ti], b, S_MG, sr, 64);
      if (m == 0) continue;
      printf("  %-5s %-6s", fcm_element_get_info(o->types[ti])->name, body_names[b]);
      for (int i = 0; i < m; i++)
        printf("  n=%lld: %.3f (%d levels)", (long long)sr[i]->n, sr[i]->factor, sr[i]->levels);
      printf("\n");
    }
  printf("\nclaims (per element; bodies ball and hollow, the V-factor on cut; times "
         "setup+solve, %s clock)\n",
         clock_names[o->clock]);
  int all = 1;
  for (int ti = 0; ti < o->ntypes; ti++) {
    const fcm_element_type t = o->types[ti];
    const char *en = fcm_element_get_info(t)->name;
    char what[200];
    for (int bi = 0; bi < o->nbodies; bi++) {
      const int b = o->bodies[bi];
      if (b != B_BALL && b != B_HOLLOW) continue;
      const row *mg[64], *ch[64];
      const int m = scaling_series(tb, t, b, S_CGMG, mg, 64),
                mc = scaling_series(tb, t, b, S_CHOLMOD, ch, 64);
      int lo = 1 << 30, hi = 0;
      for (int i = 0; i < m; i++)
        lo = mg[i]->iterations < lo ? mg[i]->iterations : lo,
        hi = mg[i]->iterations > hi ? mg[i]->iterations : hi;
      snprintf(what, sizeof what, "%s %s: cg-mg iterations flat within 1.5x (%d..%d, n=%lld..%lld)",
               en, body_names[b], m ? lo : 0, hi, m ? (long long)mg[0]->n : 0LL,
               m ? (long long)mg[m - 1]->n : 0LL);
      all &= claim(what, hi <= 1.5 * lo, m >= 2);
      const double ec = scaling_series_exponent(tb, t, b, S_CGMG, o->clock, 0);
      const double eh = scaling_series_exponent(tb, t, b, S_CHOLMOD, o->clock, 0);
      snprintf(what, sizeof what, "%s %s: cg-mg time exponent %.2f <= 1.2 and below cholmod's %.2f",
               en, body_names[b], ec, eh);
      all &= claim(what, ec <= 1.2 && ec < eh, isfinite(ec) && isfinite(eh));
      /* the largest size where both ran */
      const row *a = NULL, *c = NULL;
      for (int i = m - 1; i >= 0 && !a; i--)
        for (int j = 0; j < mc; j++)
          if (ch[j]->n == mg[i]->n) a = mg[i], c = ch[j];
      snprintf(what, sizeof what,
               "%s %s: cg-mg faster than cholmod at the largest n both ran (%lld: %.3g vs %.3g s)",
               en, body_names[b], a ? (long long)a->n : 0LL,
               a ? scaling_row_time(a, o->clock, 0) : 0.0,
               c ? scaling_row_time(c, o->clock, 0) : 0.0);
      all &= claim(what, a && scaling_row_time(a, o->clock, 0) < scaling_row_time(c, o->clock, 0),
                   a != NULL);
    }
    for (int bi = 0; bi < o->nbodies; bi++) {
      if (o->bodies[bi] != B_CUT) continue;
      const row *sr[64];
      const int m = scaling_series(tb, t, B_CUT, S_MG, sr, 64);
      double worst = 0.0;
      int k = 0;
      for (int i = 0; i < m; i++)
        if (sr[i]->iterations >= 2 && sr[i]->levels >= 2) /* a factor needs 2 cycles */
          worst = fmax(worst, sr[i]->factor), k++;
      snprintf(what, sizeof what,
               "%s cut: V-cycle factor <= 0.8 at every n with 2+ levels (worst %.3f of %d)", en,
               worst, k);
      all &= claim(what, worst <= 0.8, k >= 1);
    }
  }
  return all;
}

/* --backend petsc: the serial summary (printed, not claimed), the PETSc rows' cost per DOF,
 * and their claims: every PETSc row that ran agrees with the serial solution (CHOLMOD's, else
 * cg-mg's) within --agree and reports its iterations. 1 when every claim holds. */
int scaling_summary_petsc(const settings *o, const table *tb)
{
  (void)scaling_summary(o, tb);
  printf("(with --backend petsc the claims above are printed, not checked)\n");
  printf("\nPETSc rows on %d process%s (peak - base RSS summed over the processes; CPU seconds "
         "summed; per DOF)\n",
         o->size, o->size == 1 ? "" : "es");
  for (int i = 0; i < tb->nrows; i++) {
    const row *r = &tb->rows[i];
    if (!IS_PETSC(r->solver) || r->status != ROW_OK || r->dofs <= 0) continue;
    const double d = (double)r->dofs;
    printf("  %-5s %-6s n=%-3lld %-12s %9lld dofs: %7.0f bytes/dof, setup %.2e s/dof, solve "
           "%.2e s/dof (wall), %.2e s/dof (CPU); %s\n",
           fcm_element_get_info(r->type)->name, body_names[r->body], (long long)r->n,
           solver_names[r->solver], (long long)r->dofs,
           r->peak_mb >= 0.0 ? (r->peak_mb - r->base_mb) * 1048576.0 / d : 0.0, r->setup_s / d,
           r->solve_s / d, (r->setup_cpu + r->solve_cpu) / d, r->note);
  }
  printf("\nclaims of the PETSc rows\n");
  int all = 1;
  for (int ti = 0; ti < o->ntypes; ti++)
    for (int si = 0; si < o->nsolvers; si++) {
      const int s = o->solvers[si];
      if (!IS_PETSC(s)) continue;
      const fcm_element_type t = o->types[ti];
      int ran = 0, agree = 0, with_ref = 0, its = 0;
      double worst = 0.0;
      for (int i = 0; i < tb->nrows; i++) {
        const row *r = &tb->rows[i];
        if (r->type != t || r->solver != s || r->status == ROW_SKIPPED) continue;
        ran++;
        its += r->iterations >= 1;
        if (r->diff >= 0.0) with_ref++, agree += r->diff <= o->agree, worst = fmax(worst, r->diff);
      }
      char what[200];
      snprintf(what, sizeof what,
               "%s %s: agrees with the serial solution within %.0e (%d of %d rows, worst %.2e)",
               fcm_element_get_info(t)->name, solver_names[s], o->agree, agree, ran, worst);
      all &= claim(what, agree == ran, ran > 0 && with_ref == ran);
      snprintf(what, sizeof what, "%s %s: iterations reported (%d of %d rows)",
               fcm_element_get_info(t)->name, solver_names[s], its, ran);
      all &= claim(what, its == ran, ran > 0);
    }
  return all;
}

/* The rows so far into --csv (atomically: a temporary renamed over the file); called after
 * every row, so an interrupted run leaves the rows it finished. 1 on success. */
int scaling_write_csv(const settings *o, const table *tb)
{
  if (!o->csv || o->rank != 0) return 1;
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, o->csv, &out);
  if (!f) return 0;
  fputs(csv_header, f);
  for (int i = 0; i < tb->nrows; i++)
    write_row(f, &tb->rows[i]);
  return cli_output_commit(PROG, &out);
}
