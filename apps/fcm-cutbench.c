/* fcm-cutbench: the main program — options, the body (the generated bunny-like surface or a
 * model file), each row's scene written to a temporary directory and run through the scene
 * runner step by step (the cut events' latency split by phase from the simulation's counters,
 * the steps' times and iterations), the interactive option set run beside the defaults with
 * the displacement difference, and the table, CSV and PNG. */
#define _XOPEN_SOURCE 700 /* realpath, mkdtemp, nftw */
#include "app_env.h"
#include "cli.h"
#include "fcm-cutbench.h"

#include <errno.h>
#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The option set each row runs beside the defaults when --interactive does not give one ("":
 * none). */
static const char *const row_interactive[ROW_COUNT] = {
    /* Dick: one Newton iteration of three multigrid V-cycles a step (his 3 V-cycles) on his
     * warped tangent R K R^T (the corotated model's PSD tangent), the blocks of the cut cells
     * with a piece under half the cell and the pointwise smoothing one way, the coarse levels'
     * values every fourth step (lib/docs/cutting.md, "The interactive step") */
    "\"method\": \"multigrid\", \"fixed_cycles\": 3, \"multigrid\": {\"cycle\": \"v\", "
    "\"blocks\": \"element\", \"block_fraction\": 0.5, \"block_sweep\": \"one_way\", "
    "\"point_sweep\": \"one_way\", \"coarse_interval\": 4}, \"newton\": {\"fixed_iterations\": 1, "
    "\"project_psd\": true}",
    "\"method\": \"multigrid\", \"fixed_cycles\": 3, \"multigrid\": {\"cycle\": \"v\", "
    "\"blocks\": \"element\", \"block_fraction\": 0.5, \"block_sweep\": \"one_way\", "
    "\"point_sweep\": \"one_way\", \"coarse_interval\": 4}, \"newton\": {\"fixed_iterations\": 1, "
    "\"project_psd\": true}",
    "\"method\": \"multigrid\", \"fixed_cycles\": 3, \"multigrid\": {\"cycle\": \"v\", "
    "\"blocks\": \"element\", \"block_fraction\": 0.5, \"block_sweep\": \"one_way\", "
    "\"point_sweep\": \"one_way\", \"coarse_interval\": 4}, \"newton\": {\"fixed_iterations\": 1, "
    "\"project_psd\": true}",
    /* Koschier: one Newton iteration a step, direct solves */
    "\"newton\": {\"fixed_iterations\": 1}", "\"newton\": {\"fixed_iterations\": 1}",
    /* Ton-That: one Newton iteration a step on the PSD-projected tangent (Ton-That's
     * setting), direct solves: the exact tangent of the folding pleats is indefinite, and
     * its one iteration ends farther from the converged step (lib/docs/cutting.md) */
    "\"newton\": {\"fixed_iterations\": 1, \"project_psd\": true}",
    "\"newton\": {\"fixed_iterations\": 1, \"project_psd\": true}",
    "\"newton\": {\"fixed_iterations\": 1, \"project_psd\": true}"};

typedef struct settings {
  int quick, fill_holes, repeat;
  int dick_events; /* cut events of Dick's rows */
  double scale;
  long long triangles;
  const char *model, *rows, *interactive, *csv, *png, *write_scenes;
  int seen_triangles;
  int selected[ROW_COUNT];
} settings;

static void usage(FILE *f, const cli_option *opts)
{
  fprintf(f,
          "usage: fcm-cutbench [--quick] [--rows R1,R2] [--scale F] [--model FILE] [options]\n"
          "       fcm-cutbench --write-scenes DIR [--scale F] [--model FILE]\n"
          "\n"
          "Runs the cutting scenarios of three papers as scenes and measures each cut's latency\n"
          "split by phase (cut surface and rules, space, integrator, solver: the linear\n"
          "solver's new structure (the direct solver's symbolic analysis, the multigrid\n"
          "hierarchy without values), other: the embedded surface split again; and the\n"
          "factorization or first multigrid set-up of the step after it; on two threads the\n"
          "multigrid structure is made beside the integrator and the surface, integ and\n"
          "struct each its own wall time, so the phases may add up to more than the cut and\n"
          "other is the rest, at least 0), the mean and largest step time (cuts excluded),\n"
          "Newton and linear iterations per step, DOFs before and after, beside the papers'\n"
          "figures, with the targets: cut <= the paper's; mean step <= paper/2 (Dick) or\n"
          "paper/10 (Koschier, Ton-That). Rows:\n"
          "  dick-bunny3, dick-bunny2, dick-bunny  Dick 2011 Table 1: a grid of blades pushed\n"
          "      into the bunny in four steps (--dick-events); 5.48k, 26.1k, 118k active Hex8\n"
          "      cells; corotated\n"
          "  koschier-bunny  Koschier 2017 7: a groove carved into the turning bunny, then\n"
          "      peeled off; 5,326 DOFs; Stable Neo-Hookean\n"
          "  koschier-plate  Koschier 2017 7: a plate with attached objects (a generated\n"
          "      body) cut along its length by a long bumpy surface in five steps; 47,643 DOFs\n"
          "  tonthat-slab  Ton-That 2024 Table 2: a slab cut into thin sheets by cuts\n"
          "      re-entering the same cells, then across; 7.2k DOFs; Stable Neo-Hookean\n"
          "  tonthat-accordion  Ton-That 2024 Table 2: a hanging cube cut half through at eight\n"
          "      levels from alternate sides, then a vertical cut rips the top layers; 22.8k DOFs\n"
          "  tonthat-octopus  Ton-That 2024 Table 2: a generated octopus, a wavy mouth carved,\n"
          "      a cut across it drops the jaw, then the tentacles cut; 20.8k DOFs\n"
          "The rows after the first of each paper are left out of --quick.\n"
          "The bunny rows' body is a generated closed bunny-like surface (--surface-triangles)\n"
          "unless --model gives a file; the plate and the octopus generate their own (as many\n"
          "triangles). Each row runs the accurate defaults and then its interactive\n"
          "option set (Dick: 3 multigrid V-cycles and one Newton iteration a step; Koschier:\n"
          "one Newton iteration; Ton-That: one on the PSD-projected tangent; skipped where\n"
          "this build lacks those keys; --interactive replaces them, as members of the\n"
          "scene's \"solver\" object) and reports the largest displacement difference between\n"
          "the two.\n"
          "\n"
          "options:\n");
  cli_print_options(f, opts);
  fprintf(f, "\nExit 0 when every row ran (whether the targets hold is reported, not an error),\n"
             "1 when a row failed, 2 on a usage error (nothing is written).\n");
}

#define NUM_OPTIONS 14
static void option_table(settings *o, cli_option opts[NUM_OPTIONS])
{
  const cli_option t[NUM_OPTIONS] = {
      {"--quick", NULL, CLI_FLAG, &o->quick, NULL,
       "only the smallest row of each paper (dick-bunny3,\nkoschier-bunny, tonthat-slab)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--rows", NULL, CLI_STRING, &o->rows, "R1,R2", "the rows to run (default: all)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--scale", NULL, CLI_DOUBLE, &o->scale, "F",
       "size the rows to F times the papers' cells or DOFs\n(default 1)", 0, 4, CLI_LO_OPEN, NULL,
       NULL, NULL},
      {"--model", NULL, CLI_STRING, &o->model, "FILE",
       "the bunny rows' body surface (OBJ, STL, OFF, PLY)\ninstead of the generated one", 0, 0, 0,
       NULL, NULL, NULL},
      {"--fill-holes", NULL, CLI_FLAG, &o->fill_holes, NULL, "close the holes of --model", 0, 0, 0,
       NULL, NULL, NULL},
      {"--surface-triangles", NULL, CLI_LLONG, &o->triangles, "N",
       "triangles of the generated bodies: the bunny, the\nplate, the octopus (default 70000)", 48,
       5e6, 0, NULL, NULL, &o->seen_triangles},
      {"--dick-events", NULL, CLI_INT, &o->dick_events, "N",
       "Dick's rows: the blades pushed in N cut events, each\nthe next band of depth (1: the whole "
       "depth at once;\ndefault 4)",
       1, CUTBENCH_MAX_EVENTS, 0, NULL, NULL, NULL},
      {"--interactive", NULL, CLI_STRING, &o->interactive, "MEMBERS",
       "an option set run beside the defaults, as members of\nthe scene's \"solver\" object, "
       "e.g. '\"method\": \"cg\"'",
       0, 0, 0, NULL, NULL, NULL},
      {"--repeat", NULL, CLI_INT, &o->repeat, "N",
       "run each option set of a row N times, alternating\nthe sets; every figure the median of "
       "the runs, the\nlargest cut's and the mean step's range beside it\n(default 1)",
       1, 99, 0, NULL, NULL, NULL},
      {"--csv", NULL, CLI_STRING, &o->csv, "FILE", "write the rows as CSV (atomically)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--png", NULL, CLI_STRING, &o->png, "FILE",
       "plot cut and step times against the papers (gnuplot)", 0, 0, 0, NULL, NULL, NULL},
      {"--write-scenes", NULL, CLI_STRING, &o->write_scenes, "DIR",
       "write the rows' scenes (DIR/cutbench_<row>.json, the\nbody and cut surfaces under "
       "DIR/models) and stop",
       0, 0, 0, NULL, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(opts, t, sizeof t);
}

/* -1 when parsed, else the exit code. */
static int parse_options(int argc, char **argv, settings *o)
{
  memset(o, 0, sizeof *o);
  o->scale = 1.0, o->triangles = 70000, o->repeat = 1, o->dick_events = 4;
  cli_option opts[NUM_OPTIONS];
  option_table(o, opts);
  const int rc = cli_parse_args(PROG, opts, argc, argv, NULL, 0, NULL, usage);
  if (rc >= 0) return rc;
  if (o->rows && o->quick) {
    fprintf(stderr, PROG ": --rows and --quick: give one of them\n");
    return 2;
  }
  if (o->model && o->seen_triangles) {
    fprintf(stderr, PROG ": --surface-triangles: only for the generated body (no --model)\n");
    return 2;
  }
  if (o->fill_holes && !o->model) {
    fprintf(stderr, PROG ": --fill-holes: only with --model\n");
    return 2;
  }
  if (o->interactive && (strchr(o->interactive, '{') == o->interactive)) {
    fprintf(stderr, PROG ": --interactive: give the members without the braces: '\"key\": "
                         "value, ...'\n");
    return 2;
  }
  for (int r = 0; r < ROW_COUNT; r++)
    o->selected[r] = o->rows ? 0 : o->quick ? cutbench_papers[r].quick : 1;
  if (o->rows) {
    char tok[ROW_COUNT * 2][CLI_TOKEN];
    int n = 0;
    if (!cli_list(PROG, "--rows", o->rows, tok, ROW_COUNT * 2, &n)) return 2;
    for (int i = 0; i < n; i++) {
      int r = 0;
      while (r < ROW_COUNT && strcmp(tok[i], cutbench_papers[r].row))
        r++;
      if (r == ROW_COUNT) {
        fprintf(stderr, PROG ": --rows: %s: not a row (", tok[i]);
        for (int k = 0; k < ROW_COUNT; k++)
          fprintf(stderr, "%s%s", k ? ", " : "", cutbench_papers[k].row);
        fprintf(stderr, ")\n");
        return 2;
      }
      o->selected[r] = 1;
    }
  }
  return -1;
}

/* ------------------------------------------------------------- one run */

/* The library's warnings on stderr. */
static void print_warning(void *user, fcm_log_level level, const char *msg)
{
  (void)user;
  if (level == FCM_LOG_WARNING) fprintf(stderr, PROG ": warning: %s\n", msg);
}

/* Run the scene step by step: each step's counters against the previous ones give its cut
 * events (the cuts applied before it) and its own time. With `skip_invalid` a scene that does
 * not parse is skipped (r->skipped, the parser's message in the note) rather than failed. */
static void run_scene(const char *json, int steps, const char *label, int skip_invalid,
                      cutbench_run *r)
{
  memset(r, 0, sizeof *r);
  r->ran = 1;
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = print_warning;
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  if (fcm_ctx_create(&co, &ctx) != FCM_OK) {
    snprintf(r->note, sizeof r->note, "cannot create a context");
    return;
  }
  if (fcm_scene_create_from_file(ctx, json, &scene) != FCM_OK) {
    if (!skip_invalid) goto failed;
    r->ran = 0, r->skipped = 1;
    snprintf(r->note, sizeof r->note, "the option set is not accepted by this build: %s",
             fcm_ctx_error_message(ctx));
    fprintf(stderr, PROG ": %s: skipped: %s\n", label, r->note);
    goto done;
  }
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = steps;
  double t0 = fcm_wtime();
  if (fcm_simulation_create(ctx, scene, &so, &sim) != FCM_OK) goto failed;
  r->setup_s = fcm_wtime() - t0;
  fcm_simulation_counters b, a;
  fcm_simulation_get_counters(sim, &b);
  r->dofs_before = (long long)b.num_dofs;
  r->cells = (long long)fcm_space_num_elements(fcm_simulation_space(sim));
  fprintf(stderr, PROG ": %s: set up in %.2f s: %lld cells, %lld DOFs\n", label, r->setup_s,
          r->cells, r->dofs_before);
  for (int k = 0; k < steps; k++) {
    const fcm_status st = fcm_simulation_step(sim, NULL);
    fcm_simulation_get_counters(sim, &a);
    const double cut = a.time_cuts - b.time_cuts;
    const double step = a.time_steps - b.time_steps - cut;
    if (a.cuts > b.cuts) {
      r->events++;
      r->cut_mean += cut, r->cut_max = fmax(r->cut_max, cut);
      r->cut_rules += a.time_cut_rules - b.time_cut_rules;
      r->cut_space += a.time_cut_space - b.time_cut_space;
      r->cut_integ += a.time_cut_integrator - b.time_cut_integrator;
      r->cut_solver += a.time_cut_solver - b.time_cut_solver;
      r->cut_other += a.time_cut_other - b.time_cut_other;
      r->cut_factor += a.time_step_factor - b.time_step_factor;
      fprintf(stderr,
              PROG ": %s: step %d: cut %.3f s (rules %.3f, space %.3f, integrator %.3f, "
                   "solver %.3f, other %.3f), %lld DOFs; the step %.3f s (factorization %.3f)\n",
              label, k + 1, cut, a.time_cut_rules - b.time_cut_rules,
              a.time_cut_space - b.time_cut_space, a.time_cut_integrator - b.time_cut_integrator,
              a.time_cut_solver - b.time_cut_solver, a.time_cut_other - b.time_cut_other,
              (long long)a.num_dofs, step, a.time_step_factor - b.time_step_factor);
    }
    if (st != FCM_OK) goto failed;
    r->steps++;
    r->step_mean += step, r->step_max = fmax(r->step_max, step);
    r->newton += (double)(a.newton_iterations - b.newton_iterations);
    r->linear += (double)(a.linear_iterations - b.linear_iterations);
    b = a;
  }
  r->dofs_after = (long long)a.num_dofs;
  if (r->events > 0) {
    r->cut_mean /= r->events, r->cut_rules /= r->events, r->cut_space /= r->events;
    r->cut_integ /= r->events, r->cut_other /= r->events, r->cut_factor /= r->events;
    r->cut_solver /= r->events;
  }
  r->step_mean /= (double)r->steps, r->newton /= (double)r->steps;
  r->linear /= (double)r->steps;
  if (!fcm_simulation_state_finite(sim)) {
    snprintf(r->note, sizeof r->note, "the state is not finite after %lld steps", r->steps);
    goto done;
  }
  {
    fcm_integrator *I = fcm_simulation_integrator(sim);
    r->n = (long long)fcm_integrator_num_dofs(I);
    r->u = malloc(sizeof *r->u * (size_t)(r->n > 0 ? r->n : 1));
    if (!r->u) {
      snprintf(r->note, sizeof r->note, "out of memory");
      goto done;
    }
    memcpy(r->u, fcm_integrator_displacement(I), sizeof *r->u * (size_t)r->n);
  }
  r->ok = 1;
  goto done;
failed:
  fprintf(stderr, PROG ": %s: %s\n", label, fcm_ctx_error_message(ctx));
  snprintf(r->note, sizeof r->note, "%s", fcm_ctx_error_message(ctx));
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
}

/* ------------------------------------------------------------- the body */

/* The model's name: its file stem, [A-Za-z0-9_.-] only, at most 48 characters. */
static void file_stem(const char *path, char *out, size_t cap)
{
  const char *b = strrchr(path, '/');
  b = b ? b + 1 : path;
  size_t n = 0;
  for (; b[n] && n + 1 < cap && n < 48; n++) {
    const char c = b[n];
    out[n] = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                     c == '_' || c == '-' || c == '.'
                 ? c
                 : '_';
  }
  out[n] = 0;
  char *dot = strrchr(out, '.');
  if (dot && dot != out) *dot = 0;
}

/* The body into m: the model file, or the generated surface written to `gen` (a path). */
static int make_body(fcm_ctx *ctx, const settings *o, const char *gen, cutbench_model *m)
{
  memset(m, 0, sizeof *m);
  m->triangles = o->model ? 70000 : o->triangles;
  if (o->model) {
    char *abs = realpath(o->model, NULL);
    if (!abs) {
      fprintf(stderr, PROG ": --model %s: %s\n", o->model, strerror(errno));
      return 0;
    }
    snprintf(m->path, sizeof m->path, "%s", abs);
    free(abs);
    if (strpbrk(m->path, "\"\\")) {
      fprintf(stderr, PROG ": --model %s: a path with quotes or backslashes\n", m->path);
      return 0;
    }
    file_stem(m->path, m->name, sizeof m->name);
    m->fill_holes = o->fill_holes;
  } else {
    snprintf(m->path, sizeof m->path, "%s", gen);
    snprintf(m->name, sizeof m->name, "lobed-%lldk", (o->triangles + 500) / 1000);
    if (!cutbench_write_lobed(m->path, o->triangles)) return 0;
  }
  return cutbench_model_measure(ctx, m);
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
  (void)sb, (void)flag, (void)ftw;
  return remove(path);
}

/* ------------------------------------------------------------- main */

/* Write the selected rows' scenes for the examples: DIR/cutbench_<row>.json, the generated
 * body DIR/models/cutbench_body.obj (a --model is named by its absolute path), the cut
 * surfaces under DIR/models/cutbench. */
static int write_scenes(fcm_ctx *ctx, const settings *o)
{
  char gen[8192];
  snprintf(gen, sizeof gen, "%s/models/cutbench_body.obj", o->write_scenes);
  char models[8192];
  snprintf(models, sizeof models, "%s/models", o->write_scenes);
  if (!cli_make_dirs(PROG, models)) return 1;
  cutbench_model m;
  if (!make_body(ctx, o, gen, &m)) return 1;
  for (int r = 0; r < ROW_COUNT; r++) {
    if (!o->selected[r]) continue;
    char name[128];
    snprintf(name, sizeof name, "cutbench_%s", cutbench_papers[r].row);
    for (char *c = name; *c; c++)
      if (*c == '-') *c = '_';
    cutbench_scene sc;
    if (!cutbench_write_scene((cutbench_row_id)r, &m,
                              o->model ? m.path : "models/cutbench_body.obj", o->scale,
                              o->dick_events, "", o->write_scenes, "models/cutbench", name, &sc))
      return 1;
    printf("%s: h = %.6g m, %d steps, %d cut events\n", sc.json_path, sc.h, sc.steps, sc.events);
  }
  return 0;
}

/* The k-th smallest of v[0 .. n) (k < n; v reordered). */
static double kth(double *v, int n, int k)
{
  for (int i = 1; i < n; i++) /* a few runs: insertion sort */
    for (int j = i; j > 0 && v[j - 1] > v[j]; j--) {
      const double t = v[j];
      v[j] = v[j - 1], v[j - 1] = t;
    }
  return v[k];
}

/* The figures of n runs of one option set into out: the medians (the lower one for an even n,
 * so each is a run's own figure), the phases of the run whose mean cut is the median (they add
 * up to it), the ranges of the largest cut and of the mean step. Every run must end as the
 * first did, with its DOFs, events, steps, iterations and displacement bit for bit (a scene's
 * run is deterministic), else out failed with a note saying which run differs. A failed run
 * makes out that run. The runs' displacements are freed but out's. */
static void combine_runs(cutbench_run *runs, int n, cutbench_run *out)
{
  int base = 0;
  for (int i = 0; i < n; i++)
    if (!runs[i].ok) {
      base = i;
      goto done;
    }
  for (int i = 1; i < n; i++) {
    const cutbench_run *a = &runs[0], *b = &runs[i];
    if (a->dofs_before != b->dofs_before || a->dofs_after != b->dofs_after ||
        a->events != b->events || a->steps != b->steps || a->newton != b->newton ||
        a->linear != b->linear || a->n != b->n ||
        memcmp(a->u, b->u, sizeof *a->u * (size_t)a->n) != 0) {
      runs[0].ok = 0;
      snprintf(runs[0].note, sizeof runs[0].note,
               "run %d of %d ended otherwise than the first (DOFs, cut events, steps, "
               "iterations or displacement): the runs are not repeatable",
               i + 1, n);
      goto done;
    }
  }
  {
    double v[99];
    const int mid = (n - 1) / 2;
    for (int i = 0; i < n; i++)
      v[i] = runs[i].cut_mean;
    const double cut_mean = kth(v, n, mid);
    for (int i = 0; i < n; i++)
      if (runs[i].cut_mean == cut_mean) base = i;
#define MEDIAN_OF(field)                                                                           \
  do {                                                                                             \
    for (int i = 0; i < n; i++)                                                                    \
      v[i] = runs[i].field;                                                                        \
    runs[base].field = kth(v, n, mid);                                                             \
  } while (0)
    MEDIAN_OF(setup_s);
    MEDIAN_OF(cut_factor);
    MEDIAN_OF(step_max);
    for (int i = 0; i < n; i++)
      v[i] = runs[i].cut_max;
    const double cut_max = kth(v, n, mid);
    runs[base].cut_max_lo = v[0], runs[base].cut_max_hi = v[n - 1];
    for (int i = 0; i < n; i++)
      v[i] = runs[i].step_mean;
    const double step_mean = kth(v, n, mid);
    runs[base].step_mean_lo = v[0], runs[base].step_mean_hi = v[n - 1];
    runs[base].cut_max = cut_max, runs[base].step_mean = step_mean;
#undef MEDIAN_OF
  }
done:
  for (int i = 0; i < n; i++)
    if (i != base) free(runs[i].u), runs[i].u = NULL;
  *out = runs[base];
  out->runs = n;
  if (n == 1 || !out->ok)
    out->cut_max_lo = out->cut_max_hi = out->cut_max,
    out->step_mean_lo = out->step_mean_hi = out->step_mean;
}

/* Run one row: the defaults, then the interactive set when there is one, each o->repeat
 * times, alternating. */
static int run_row(const settings *o, const cutbench_model *m, const char *dir, cutbench_row *row)
{
  const cutbench_paper *p = &cutbench_papers[row->id];
  const char *inter = o->interactive ? o->interactive : row_interactive[row->id];
  const int sets = inter[0] ? 2 : 1, nrep = o->repeat;
  snprintf(row->interactive, sizeof row->interactive, "%s", inter);
  row->disp_diff = row->disp_max = -1.0;
  cutbench_scene sc[2];
  int written[2] = {0, 0}, nrun[2] = {0, 0}, stop[2] = {0, 0}, ok = 1;
  static cutbench_run runs[2][99]; /* this row's runs of each set, nrun[k] of them */
  memset(runs, 0, sizeof runs);
  for (int k = 0; k < sets; k++) {
    char name[128];
    snprintf(name, sizeof name, "%s%s", p->row, k ? "-interactive" : "");
    written[k] = cutbench_write_scene(row->id, m, m->path, o->scale, o->dick_events, k ? inter : "",
                                      dir, "cuts", name, &sc[k]);
    if (!written[k]) {
      row->run[k].ran = 1;
      snprintf(row->run[k].note, sizeof row->run[k].note, "the scene could not be written");
      ok = 0;
    }
  }
  for (int rep = 0; rep < nrep; rep++)
    for (int k = 0; k < sets; k++) {
      if (!written[k] || stop[k]) continue;
      char label[192];
      if (nrep > 1)
        snprintf(label, sizeof label, "%s (%s, run %d of %d)", p->row,
                 k ? "interactive" : "defaults", rep + 1, nrep);
      else
        snprintf(label, sizeof label, "%s (%s)", p->row, k ? "interactive" : "defaults");
      row->h = sc[k].h;
      fprintf(stderr, PROG ": %s: h = %.4g m, %d steps, cuts before steps", label, sc[k].h,
              sc[k].steps);
      for (int e = 0; e < sc[k].events; e++)
        fprintf(stderr, " %d", sc[k].event_step[e]);
      fprintf(stderr, "\n");
      /* the program's own option sets may name keys this build lacks: skipped, said so */
      cutbench_run *r = &runs[k][nrun[k]++];
      run_scene(sc[k].json_path, sc[k].steps, label, k == 1 && !o->interactive, r);
      stop[k] = !r->ok; /* a set skipped or failed once is not run again */
    }
  for (int k = 0; k < sets; k++) {
    if (!written[k]) continue;
    if (runs[k][0].skipped)
      row->run[k] = runs[k][0];
    else
      combine_runs(runs[k], nrun[k], &row->run[k]);
    if (!row->run[k].ok && !row->run[k].skipped) {
      ok = 0;
      if (nrun[k] > 1) fprintf(stderr, PROG ": %s: %s\n", p->row, row->run[k].note);
    }
  }
  const cutbench_run *a = &row->run[0], *b = &row->run[1];
  if (a->ok) {
    row->disp_max = 0.0;
    for (long long i = 0; i < a->n; i++)
      row->disp_max = fmax(row->disp_max, fabs(a->u[i]));
  }
  if (a->ok && b->ok && a->n == b->n) {
    row->disp_diff = 0.0;
    for (long long i = 0; i < a->n; i++)
      row->disp_diff = fmax(row->disp_diff, fabs(a->u[i] - b->u[i]));
  }
  return ok;
}

static int bench_main(fcm_ctx *ctx, const settings *o)
{
  const char *tmp = getenv("TMPDIR");
  char dir[4096];
  snprintf(dir, sizeof dir, "%s/fcm-cutbench-XXXXXX", tmp && *tmp ? tmp : "/tmp");
  if (!mkdtemp(dir)) {
    fprintf(stderr, PROG ": cannot create a temporary directory %s: %s\n", dir, strerror(errno));
    return 1;
  }
  char gen[8192];
  snprintf(gen, sizeof gen, "%s/body.obj", dir);
  static cutbench_row rows[ROW_COUNT];
  int n = 0, code = 0;
  cutbench_model m;
  if (!make_body(ctx, o, gen, &m)) {
    code = 1;
    goto done;
  }
  printf("fcm-cutbench%s: body %s (%lld x %lld x %lld mm, %.4g l), sizes %g x the papers'",
         o->quick ? " --quick: the smallest row of each paper only" : "", m.name,
         (long long)lround(1e3 * (m.hi[0] - m.lo[0])), (long long)lround(1e3 * (m.hi[1] - m.lo[1])),
         (long long)lround(1e3 * (m.hi[2] - m.lo[2])), 1e3 * m.volume, o->scale);
  if (o->repeat > 1)
    printf("; each figure the median of %d runs, the largest cut's and the mean step's range "
           "below each row",
           o->repeat);
  printf("\n");
  cutbench_print_header();
  for (int r = 0; r < ROW_COUNT; r++) {
    if (!o->selected[r]) continue;
    cutbench_row *row = &rows[n++];
    memset(row, 0, sizeof *row);
    row->id = (cutbench_row_id)r;
    if (!run_row(o, &m, dir, row)) code = 1;
    cutbench_print_row(row);
  }
  cutbench_print_verdicts(rows, n);
  if (o->csv && !cutbench_write_csv(o->csv, rows, n)) code = 1;
  if (o->png && !cutbench_write_png(o->png, rows, n)) code = 1;
  for (int i = 0; i < n; i++)
    for (int k = 0; k < 2; k++)
      free(rows[i].run[k].u);
done:
  nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
  return code;
}

int main(int argc, char **argv)
{
  app_env_init(argc, argv);
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  static settings o;
  const int rc = parse_options(argc, argv, &o);
  if (rc >= 0) return rc;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const int code = o.write_scenes ? write_scenes(ctx, &o) : bench_main(ctx, &o);
  fcm_ctx_destroy(&ctx);
  return code;
}
