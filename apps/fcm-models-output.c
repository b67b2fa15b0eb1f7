/* fcm-models: the output — the table on stdout (new, old and their ratio per model and cell
 * size), the CSV (written atomically), the gnuplot PNGs, and the ball study's CSV and PNG. */
#include "cli.h"
#include "fcm-models.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const path_names[NPATH] = {"new", "old"};

/* ------------------------------------------------------------- table */

void models_print_header(void)
{
  printf("%-14s %6s %-7s %7s %6s %8s %8s %7s %7s %8s %9s %9s %6s %6s %8s %8s %7s %7s %7s %7s "
         "%9s\n",
         "model", "h", "path", "dofs", "cut", "geom_s", "rules_s", "space_s", "integ_s", "setup_s",
         "init_K/c", "init_M/c", "fin_K", "fin_M", "peak_MB", "step_s", "asm_s", "fact_s",
         "solve_s", "log_s", "mom_diff");
  fflush(stdout);
}

/* a / b, or NaN when either is not positive. */
static double ratio(double a, double b)
{
  return a > 0.0 && b > 0.0 ? a / b : NAN;
}

void models_print_pair(const models_settings *o, const model_pair *p)
{
  const char *name = o->models[p->model].name;
  for (int k = 0; k < NPATH; k++) {
    const model_run *r = &p->run[k];
    if (!r->ran || !r->ok) {
      printf("%-14s %6g %-7s %s: %s\n", name, p->h, path_names[k], r->ran ? "FAILED" : "skipped",
             r->note);
      continue;
    }
    printf("%-14s %6g %-7s %7lld %6lld %8.3f %8.3f %7.3f %7.3f %8.3f %9.1f %9.1f %6.1f %6.1f "
           "%8.1f %8.4f %7.4f %7.4f %7.4f %7.4f ",
           name, p->h, path_names[k], r->dofs, r->cut_cells, r->t_geometry, r->t_rules, r->t_space,
           r->t_integrator, r->t_setup, r->points_initial[0], r->points_initial[1],
           r->points_final[0], r->points_final[1], r->peak_mb, r->step_s, r->assembly_s,
           r->factor_s, r->solve_s, r->log_s);
    if (p->moment_diff >= 0.0)
      printf("%9.2e\n", p->moment_diff);
    else
      printf("%9s\n", "-");
  }
  const model_run *n = &p->run[PATH_NEW], *d = &p->run[PATH_OLD];
  if (n->ok && d->ok)
    printf("%-14s %6g %-7s %7s %6s %8.2f %8.2f %7.2f %7.2f %8.2f %9.1f %9.1f %6.2f %6.2f %8.2f "
           "%8.2f %7.2f %7.2f %7.2f %7.2f\n",
           name, p->h, "old/new", "", "", ratio(d->t_geometry, n->t_geometry),
           ratio(d->t_rules, n->t_rules), ratio(d->t_space, n->t_space),
           ratio(d->t_integrator, n->t_integrator), ratio(d->t_setup, n->t_setup),
           ratio(d->points_initial[0], n->points_initial[0]),
           ratio(d->points_initial[1], n->points_initial[1]),
           ratio(d->points_final[0], n->points_final[0]),
           ratio(d->points_final[1], n->points_final[1]), ratio(d->peak_mb, n->peak_mb),
           ratio(d->step_s, n->step_s), ratio(d->assembly_s, n->assembly_s),
           ratio(d->factor_s, n->factor_s), ratio(d->solve_s, n->solve_s),
           ratio(d->log_s, n->log_s));
  fflush(stdout);
}

/* ------------------------------------------------------------- CSV */

static const char csv_header[] =
    "model,cell_size,element,path,status,dofs,cells,cut_cells,setup_geometry_s,setup_rules_s,"
    "setup_space_s,setup_integrator_s,setup_s,initial_points_stiffness,initial_points_mass,"
    "final_points_stiffness,final_points_mass,strength_stiffness,strength_mass,peak_rss_mb,"
    "steps,step_s,step_assembly_s,step_factor_s,step_solve_s,log_s,moment_diff,note\n";

static void csv_run(FILE *f, const models_settings *o, const model_pair *p, int k)
{
  const model_run *r = &p->run[k];
  const int ok = r->ran && r->ok;
  fprintf(f, "%s,%.6g,%s,%s,%s,", o->models[p->model].name, p->h,
          fcm_element_get_info(o->element)->name, path_names[k],
          ok       ? "ok"
          : r->ran ? "failed"
                   : "skipped");
  if (ok)
    fprintf(f, "%lld,%lld,%lld", r->dofs, r->cells, r->cut_cells);
  else
    fputs(",,", f);
  const double v[11] = {r->t_geometry,        r->t_rules,         r->t_space,
                        r->t_integrator,      r->t_setup,         r->points_initial[0],
                        r->points_initial[1], r->points_final[0], r->points_final[1],
                        r->strength[0],       r->strength[1]};
  for (int i = 0; i < 11; i++)
    cli_csv_number(f, ok ? v[i] : -1.0);
  cli_csv_number(f, ok ? r->peak_mb : -1.0);
  fputc(',', f);
  if (ok) fprintf(f, "%lld", r->steps);
  const double s[5] = {r->step_s, r->assembly_s, r->factor_s, r->solve_s, r->log_s};
  for (int i = 0; i < 5; i++)
    cli_csv_number(f, ok ? s[i] : -1.0);
  fputc(',', f);
  if (p->moment_diff >= 0.0) fprintf(f, "%.3e", p->moment_diff);
  cli_csv_text(f, ok ? "" : r->note);
  fputc('\n', f);
}

/* The ratio row old/new: the times, points and memory divided, counts empty. */
static void csv_ratio(FILE *f, const models_settings *o, const model_pair *p)
{
  const model_run *n = &p->run[PATH_NEW], *d = &p->run[PATH_OLD];
  fprintf(f, "%s,%.6g,%s,old/new,ratio,,,", o->models[p->model].name, p->h,
          fcm_element_get_info(o->element)->name);
  const double a[9] = {d->t_geometry,        d->t_rules,         d->t_space,
                       d->t_integrator,      d->t_setup,         d->points_initial[0],
                       d->points_initial[1], d->points_final[0], d->points_final[1]};
  const double b[9] = {n->t_geometry,        n->t_rules,         n->t_space,
                       n->t_integrator,      n->t_setup,         n->points_initial[0],
                       n->points_initial[1], n->points_final[0], n->points_final[1]};
  for (int i = 0; i < 9; i++)
    cli_csv_number(f, ratio(a[i], b[i]));
  fputs(",,", f);
  cli_csv_number(f, ratio(d->peak_mb, n->peak_mb));
  fputc(',', f);
  cli_csv_number(f, ratio(d->step_s, n->step_s));
  cli_csv_number(f, ratio(d->assembly_s, n->assembly_s));
  cli_csv_number(f, ratio(d->factor_s, n->factor_s));
  cli_csv_number(f, ratio(d->solve_s, n->solve_s));
  cli_csv_number(f, ratio(d->log_s, n->log_s));
  fputs(",,\n", f);
}

int models_write_csv(const models_settings *o, const model_pair *pairs, int npairs)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, o->csv, &out);
  if (!f) return 0;
  fputs(csv_header, f);
  for (int i = 0; i < npairs; i++) {
    for (int k = 0; k < NPATH; k++)
      csv_run(f, o, &pairs[i], k);
    if (pairs[i].run[PATH_NEW].ok && pairs[i].run[PATH_OLD].ok) csv_ratio(f, o, &pairs[i]);
  }
  return cli_output_commit(PROG, &out);
}

int models_write_ball_csv(const char *path, const ball_row *rows, int count)
{
  cli_output *out = NULL;
  FILE *f = cli_output_open(PROG, path, &out);
  if (!f) return 0;
  fputs("n,triangles,cells,cut_cells,rules_s,us_per_cut_cell,points_per_cut_cell,"
        "strength_stiffness,strength_mass,status,note\n",
        f);
  for (int i = 0; i < count; i++) {
    const ball_row *b = &rows[i];
    if (b->ok)
      fprintf(f, "%d,%lld,%lld,%lld,%.6g,%.6g,%.6g,%d,%d,ok,\n", b->n, b->triangles, b->cells,
              b->cut_cells, b->rules_s,
              1e6 * b->rules_s / (double)(b->cut_cells > 0 ? b->cut_cells : 1), b->points_final,
              b->strength[0], b->strength[1]);
    else {
      fprintf(f, "%d,,,,,,,,,failed", b->n);
      cli_csv_text(f, b->note);
      fputc('\n', f);
    }
  }
  return cli_output_commit(PROG, &out);
}

/* ------------------------------------------------------------- PNG */

/* A growing gnuplot script. */
typedef struct script {
  char *s;
  size_t len, cap;
  int ok;
} script;

static void add(script *sc, const char *fmt, ...)
{
  if (!sc->ok) return;
  va_list ap;
  va_start(ap, fmt);
  const int k = vsnprintf(sc->s + sc->len, sc->cap - sc->len, fmt, ap);
  va_end(ap);
  if (k < 0 || (size_t)k >= sc->cap - sc->len)
    sc->ok = 0;
  else
    sc->len += (size_t)k;
}

int models_write_png(const models_settings *o, const model_pair *pairs, int npairs)
{
  script sc = {malloc(1 << 18), 0, 1 << 18, 1};
  if (!sc.s) return 0;
  static const char *const titles[3] = {"set-up (s)", "peak RSS (MB)", "one step (s)"};
  add(&sc,
      "set multiplot layout 1,3 title 'fcm-models: surface path (new) and volume path "
      "(old), %s'\n"
      "set style data histograms\nset style histogram clustered gap 1\n"
      "set style fill solid 0.8 border -1\nset logscale y\nset grid ytics\nset tmargin 4\n"
      "set xtics rotate by -30 font ',9'\nset key top left\n",
      fcm_element_get_info(o->element)->name);
  for (int panel = 0; panel < 3; panel++) {
    add(&sc,
        "set title '%s'\nplot '-' using 2:xtic(1) title 'new' lc rgb '#1f77b4', '-' using 2 "
        "title 'old' lc rgb '#d62728'\n",
        titles[panel]);
    for (int k = 0; k < NPATH; k++) {
      for (int i = 0; i < npairs; i++) {
        const model_run *r = &pairs[i].run[k];
        const double v = !r->ok       ? NAN
                         : panel == 0 ? r->t_setup
                         : panel == 1 ? r->peak_mb
                                      : r->step_s;
        add(&sc, "\"%s %g\" %.6g\n", o->models[pairs[i].model].name, pairs[i].h,
            isfinite(v) && v > 0.0 ? v : 1e-9);
      }
      add(&sc, "e\n");
    }
  }
  add(&sc, "unset multiplot\n");
  int ok = sc.ok;
  if (!ok)
    fprintf(stderr, PROG ": --png: the plot script grew too large\n");
  else
    ok = cli_gnuplot_png(PROG, "1500,550 font ',10'", o->png, sc.s);
  free(sc.s);
  return ok;
}

int models_write_ball_png(const char *path, const ball_row *rows, int count, double exponent)
{
  script sc = {malloc(1 << 16), 0, 1 << 16, 1};
  if (!sc.s) return 0;
  add(&sc,
      "set logscale xy\nset grid\nset xlabel 'cut cells'\nset ylabel 'cell rules, wall seconds'\n"
      "set key top left\nset title 'fcm-models --ball-study: rule time against cut cells'\n"
      "plot '-' using 1:2 with linespoints pt 7 title 'surface path (fitted exponent %.2f)'\n",
      exponent);
  for (int i = 0; i < count; i++)
    if (rows[i].ok && rows[i].cut_cells > 0 && rows[i].rules_s > 0.0)
      add(&sc, "%lld %.6g\n", rows[i].cut_cells, rows[i].rules_s);
  add(&sc, "e\n");
  int ok = sc.ok;
  if (ok) ok = cli_gnuplot_png(PROG, "900,600 font ',11'", path, sc.s);
  free(sc.s);
  return ok;
}
