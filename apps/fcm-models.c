/* fcm-models: the main program — options, the models (files, the generated bumpy sphere, the
 * example pebble), one child process per configuration (so that each one's peak memory is its
 * own), the comparison of the two paths' moments, and the ball study with its claim. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "app_env.h"
#include "cli.h"
#include "fcm-models.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef FCM_MODELS_SOURCE_DIR
#define FCM_MODELS_SOURCE_DIR "."
#endif

/* The first argument of a child process: the rest are its configuration (run_child()). */
#define CHILD_FLAG "--internal-child"

/* --model values as given, resolved after parsing. */
typedef struct model_names {
  const char *name[MODELS_MAX_MODELS];
  int n;
} model_names;

static int parse_model(const char *prog, const char *opt, const char *value, void *dest)
{
  model_names *mn = dest;
  if (mn->n >= MODELS_MAX_MODELS) {
    fprintf(stderr, "%s: %s: at most %d models\n", prog, opt, MODELS_MAX_MODELS);
    return 0;
  }
  if (!value[0]) {
    fprintf(stderr, "%s: %s: empty model name\n", prog, opt);
    return 0;
  }
  mn->name[mn->n++] = value;
  return 1;
}

static void usage(FILE *f, const cli_option *opts)
{
  fprintf(f,
          "usage: fcm-models [--model PATH|bumpy|pebble]... [--cell-sizes H1,H2] [options]\n"
          "       fcm-models --ball-study [--quick]\n"
          "\n"
          "Measures what a surface model costs on the surface path (the defaults: no volume\n"
          "mesh, cut-cell moments from the boundary triangles, \"new\") and on the volume path\n"
          "(\"volume_mesh\": true, \"moments\": \"volume\": a Gmsh volume mesh and sub-tet rules,\n"
          "\"old\"), each in its own process: the set-up's phases, cut cells, quadrature points\n"
          "per cut cell before and after simplification, peak memory, a step's time and its\n"
          "parts, and the largest difference between the two paths' global moments (every\n"
          "monomial up to the mass strength, coordinates scaled to [-1,1] over the bounding box,\n"
          "relative to the volume). The scene: the model on a fitted grid of cells H, a stable\n"
          "Neo-Hookean material, gravity, its bottom 11 %% held, dt 0.01 s.\n"
          "Built-in models: bumpy (a closed bumpy sphere of radius about 0.5 m, generated) and\n"
          "pebble (apps/scenes/models/pebble.obj). Without --model: bumpy and pebble.\n"
          "--ball-study: rule time against cut cells on a unit ball triangulated at half the cell\n"
          "size, n = 8, 16, 32, 64 cells across (--quick: 8, 12, 16); the fitted exponent must\n"
          "be <= 1.1 (exit 1 otherwise; --quick only reports).\n"
          "\n"
          "options:\n");
  cli_print_options(f, opts);
  fprintf(f, "\nExit 0 when every configuration ran, 1 when one failed (its note says why) or the\n"
             "ball study's claim fails, 2 on a usage error. The volume path needs Gmsh; without\n"
             "it the old rows are skipped with a note.\n");
}

/* ------------------------------------------------------------- models */

/* The model's name: its file stem ("dir/bunny.obj" -> "bunny"), at most 48 characters, those
 * outside [A-Za-z0-9_.-] replaced by '_' (it names the scene, with "-new" or "-old"). */
static void file_stem(const char *path, char *out, size_t cap)
{
  const char *b = strrchr(path, '/');
  b = b ? b + 1 : path;
  snprintf(out, cap < 49 ? cap : 49, "%s", b);
  char *dot = strrchr(out, '.');
  if (dot && dot != out) *dot = 0;
  for (char *c = out; *c; c++)
    if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
          *c == '_' || *c == '-' || *c == '.'))
      *c = '_';
  if (!out[0] || !strcmp(out, ".") || !strcmp(out, "..")) snprintf(out, cap, "model");
}

/* The bounding box of the model's surface after the scale; 0 with a message. */
static int model_box(fcm_ctx *ctx, model_input *m, double scale)
{
  fcm_surface *s = NULL;
  if (fcm_surface_create_from_file(ctx, m->path, &s) != FCM_OK) {
    fprintf(stderr, PROG ": --model %s: %s\n", m->name, fcm_ctx_error_message(ctx));
    return 0;
  }
  fcm_surface_bounding_box(s, m->lo, m->hi);
  for (int d = 0; d < 3; d++)
    m->lo[d] *= scale, m->hi[d] *= scale;
  fcm_surface_destroy(&s);
  return 1;
}

/* Resolve the --model names into o->models (the bumpy sphere written to `bumpy_path`, a
 * temporary); 0 with a message. */
static int resolve_models(fcm_ctx *ctx, const model_names *mn, models_settings *o, char *bumpy_path,
                          size_t cap)
{
  static const char *const defaults[2] = {"bumpy", "pebble"};
  const int n = mn->n ? mn->n : 2;
  for (int i = 0; i < n; i++) {
    const char *name = mn->n ? mn->name[i] : defaults[i];
    model_input *m = &o->models[o->nmodels++];
    double scale = o->scale;
    if (!strcmp(name, "bumpy")) {
      snprintf(m->name, sizeof m->name, "bumpy");
      if (!bumpy_path[0]) { /* <tmp>/fcm-models-XXXXXX/bumpy.obj */
        const char *tmp = getenv("TMPDIR");
        char dir[4000];
        snprintf(dir, sizeof dir, "%s/fcm-models-XXXXXX", tmp && *tmp ? tmp : "/tmp");
        if (!mkdtemp(dir)) {
          fprintf(stderr, PROG ": bumpy: cannot create a temporary directory %s: %s\n", dir,
                  strerror(errno));
          return 0;
        }
        snprintf(bumpy_path, cap, "%s/bumpy.obj", dir);
        if (!models_write_bumpy(bumpy_path, o->bumpy_triangles)) return 0;
      }
      snprintf(m->path, sizeof m->path, "%s", bumpy_path);
      scale = 1.0;
    } else if (!strcmp(name, "pebble")) {
      snprintf(m->name, sizeof m->name, "pebble");
      snprintf(m->path, sizeof m->path, "%s/apps/scenes/models/pebble.obj", FCM_MODELS_SOURCE_DIR);
      if (access(m->path, R_OK) != 0) {
        fprintf(stderr,
                PROG ": --model pebble: %s not found (a program moved away from its source "
                     "tree): give the file, --model PATH/pebble.obj\n",
                m->path);
        return 0;
      }
      scale = 1.0;
    } else {
      file_stem(name, m->name, sizeof m->name);
      char *abs = realpath(name, NULL);
      if (!abs) {
        fprintf(stderr, PROG ": --model %s: %s\n", name, strerror(errno));
        return 0;
      }
      snprintf(m->path, sizeof m->path, "%s", abs);
      free(abs);
    }
    m->scale = scale;
    m->fill_holes = strcmp(name, "bumpy") && strcmp(name, "pebble") ? o->fill_holes : 0;
    if (!model_box(ctx, m, scale)) return 0;
  }
  return 1;
}

/* ------------------------------------------------------------- child processes */

/* Run one configuration in a child process (this program again, CHILD_FLAG) and read what it
 * measured through a pipe; a child that dies leaves a note. */
static void run_child(const model_input *m, double h, const models_settings *o, int path,
                      model_run *r)
{
  memset(r, 0, sizeof *r);
  r->ran = 1;
  int fds[2];
  if (pipe(fds) != 0) {
    snprintf(r->note, sizeof r->note, "pipe: %s", strerror(errno));
    return;
  }
  char a[16][64];
  snprintf(a[0], 64, "%d", fds[1]);
  for (int d = 0; d < 3; d++) {
    snprintf(a[1 + d], 64, "%a", m->lo[d]);
    snprintf(a[4 + d], 64, "%a", m->hi[d]);
  }
  snprintf(a[7], 64, "%a", h);
  snprintf(a[8], 64, "%s", fcm_element_get_info(o->element)->name);
  snprintf(a[9], 64, "%s", path == PATH_OLD ? "old" : "new");
  snprintf(a[10], 64, "%d", m->fill_holes);
  snprintf(a[11], 64, "%a", m->scale);
  snprintf(a[12], 64, "%d", o->steps);
  char *argv[20] = {"fcm-models", CHILD_FLAG, (char *)m->path, (char *)m->name};
  for (int k = 0; k < 13; k++)
    argv[4 + k] = a[k];
  argv[17] = NULL;
  fflush(stdout);
  fflush(stderr);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    execv("/proc/self/exe", argv);
    _exit(127);
  }
  close(fds[1]);
  size_t got = 0;
  while (pid > 0 && got < sizeof *r) {
    const ssize_t k = read(fds[0], (char *)r + got, sizeof *r - got);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) break;
    got += (size_t)k;
  }
  close(fds[0]);
  int st = 0;
  if (pid < 0) {
    snprintf(r->note, sizeof r->note, "fork: %s", strerror(errno));
  } else if (waitpid(pid, &st, 0) < 0 || got != sizeof *r) {
    memset(r, 0, sizeof *r);
    r->ran = 1;
    if (WIFSIGNALED(st))
      snprintf(r->note, sizeof r->note, "the child process died of signal %d%s", WTERMSIG(st),
               WTERMSIG(st) == 9 ? " (out of memory?)" : "");
    else
      snprintf(r->note, sizeof r->note, "the child process exited with %d and no result",
               WIFEXITED(st) ? WEXITSTATUS(st) : -1);
  }
}

/* The child: argv = prog CHILD_FLAG PATH NAME LO0 LO1 LO2 HI0 HI1 HI2 H ELEMENT new|old FILL
 * SCALE STEPS, FD first after the flag (see run_child()). */
static int child_main(int argc, char **argv)
{
  if (argc != 17) return 2;
  model_input m;
  memset(&m, 0, sizeof m);
  snprintf(m.path, sizeof m.path, "%s", argv[2]);
  snprintf(m.name, sizeof m.name, "%s", argv[3]);
  const int fd = atoi(argv[4]);
  for (int d = 0; d < 3; d++) {
    m.lo[d] = strtod(argv[5 + d], NULL);
    m.hi[d] = strtod(argv[8 + d], NULL);
  }
  const double h = strtod(argv[11], NULL);
  fcm_element_type type;
  if (fcm_element_type_from_name(argv[12], &type) != FCM_OK) return 2;
  const int path = !strcmp(argv[13], "old") ? PATH_OLD : PATH_NEW;
  m.fill_holes = atoi(argv[14]);
  m.scale = strtod(argv[15], NULL);
  static model_run r;
  models_run_config(&m, h, type, path, atoi(argv[16]), &r);
  size_t put = 0;
  while (put < sizeof r) {
    const ssize_t k = write(fd, (const char *)&r + put, sizeof r - put);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return 1;
    put += (size_t)k;
  }
  close(fd);
  return 0;
}

/* max_k |a_k - b_k| / |volume of b|; -1 when not comparable. */
static double moment_diff(const model_run *a, const model_run *b)
{
  if (!a->ok || !b->ok || a->num_moments != b->num_moments || a->num_moments == 0 ||
      !(fabs(b->volume) > 0.0))
    return -1.0;
  double d = 0.0;
  for (int k = 0; k < a->num_moments; k++)
    d = fmax(d, fabs(a->moments[k] - b->moments[k]));
  return d / fabs(b->volume);
}

/* ------------------------------------------------------------- options */

typedef struct raw_options {
  model_names models;
  const char *sizes, *element;
  int seen_sizes, seen_models, seen_element, seen_steps, seen_bumpy;
} raw_options;

#define MODELS_NUM_OPTIONS 14
static void option_table(models_settings *o, raw_options *w, cli_option opts[MODELS_NUM_OPTIONS])
{
  const cli_option t[MODELS_NUM_OPTIONS] = {
      {"--model", NULL, CLI_CUSTOM, &w->models, "PATH",
       "a surface model (.obj, .stl, .off, .ply), or bumpy or\n"
       "pebble; repeatable (default: bumpy and pebble)",
       0, 0, 0, NULL, parse_model, &w->seen_models},
      {"--cell-sizes", NULL, CLI_STRING, &w->sizes, "H1,H2",
       "background cell sizes in m (default 0.1,0.05)", 0, 0, 0, NULL, NULL, &w->seen_sizes},
      {"--element", NULL, CLI_STRING, &w->element, "E", "hex8 (default) or hex20", 0, 0, 0, NULL,
       NULL, &w->seen_element},
      {"--fill-holes", NULL, CLI_FLAG, &o->fill_holes, NULL,
       "close the holes of the models given by path", 0, 0, 0, NULL, NULL, NULL},
      {"--scale", NULL, CLI_DOUBLE, &o->scale, "S",
       "scale the models given by path by S (default 1)", 0, 1e6, CLI_LO_OPEN, NULL, NULL, NULL},
      {"--steps", NULL, CLI_INT, &o->steps, "N", "dynamic steps per run (default 3)", 1, 1000, 0,
       NULL, NULL, &w->seen_steps},
      {"--bumpy-triangles", NULL, CLI_LLONG, &o->bumpy_triangles, "N",
       "triangles of the bumpy sphere (default 50000)", 48, 5e6, 0, NULL, NULL, &w->seen_bumpy},
      {"--new-only", NULL, CLI_FLAG, &o->new_only, NULL, "skip the volume path (old)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--ball-study", NULL, CLI_FLAG, &o->ball_study, NULL,
       "rule time against cut cells on a refining ball", 0, 0, 0, NULL, NULL, NULL},
      {"--quick", NULL, CLI_FLAG, &o->quick, NULL, "--ball-study on n = 8, 12, 16 only", 0, 0, 0,
       NULL, NULL, NULL},
      {"--csv", NULL, CLI_STRING, &o->csv, "FILE", "write the rows as CSV (atomically)", 0, 0, 0,
       NULL, NULL, NULL},
      {"--png", NULL, CLI_STRING, &o->png, "FILE", "plot them with gnuplot", 0, 0, 0, NULL, NULL,
       NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(opts, t, sizeof t);
}

/* The cell sizes: a comma list of distinct positive numbers. */
static int parse_sizes(const char *s, models_settings *o)
{
  char tok[MODELS_MAX_SIZES][CLI_TOKEN];
  if (!cli_list(PROG, "--cell-sizes", s, tok, MODELS_MAX_SIZES, &o->nsizes)) return 0;
  for (int i = 0; i < o->nsizes; i++) {
    if (!cli_double(PROG, "--cell-sizes", tok[i], 0.0, 1e6, CLI_LO_OPEN, &o->sizes[i])) return 0;
    for (int j = 0; j < i; j++)
      if (o->sizes[j] == o->sizes[i]) {
        fprintf(stderr, PROG ": --cell-sizes: %s given twice\n", tok[i]);
        return 0;
      }
  }
  return 1;
}

/* -1 when parsed into o and w, else the exit code. */
static int parse_options(int argc, char **argv, models_settings *o, raw_options *w)
{
  memset(o, 0, sizeof *o);
  memset(w, 0, sizeof *w);
  o->element = FCM_ELEMENT_HEX8, o->steps = 3, o->scale = 1.0, o->bumpy_triangles = 50000;
  cli_option opts[MODELS_NUM_OPTIONS];
  option_table(o, w, opts);
  const int rc = cli_parse_args(PROG, opts, argc, argv, NULL, 0, NULL, usage);
  if (rc >= 0) return rc;
  if (w->element) {
    if (!cli_element(PROG, "--element", w->element, &o->element)) return 2;
    if (o->element != FCM_ELEMENT_HEX8 && o->element != FCM_ELEMENT_HEX20) {
      fprintf(stderr, PROG ": --element: %s: only hex8 and hex20 (fitted grids)\n", w->element);
      return 2;
    }
  }
  if (o->ball_study) {
    if (w->seen_models || w->seen_sizes || w->seen_steps || w->seen_bumpy || o->new_only ||
        o->fill_holes || o->scale != 1.0) {
      fprintf(stderr, PROG ": --ball-study takes only --quick, --element, --csv and --png\n");
      return 2;
    }
    return -1;
  }
  if (o->quick) {
    fprintf(stderr, PROG ": --quick: only with --ball-study\n");
    return 2;
  }
  o->sizes[0] = 0.1, o->sizes[1] = 0.05, o->nsizes = 2;
  if (w->sizes && !parse_sizes(w->sizes, o)) return 2;
  return -1;
}

/* ------------------------------------------------------------- the studies */

static int ball_main(const models_settings *o)
{
  static const int full[4] = {8, 16, 32, 64}, quick[3] = {8, 12, 16};
  const int *n = o->quick ? quick : full, count = o->quick ? 3 : 4;
  ball_row rows[MODELS_MAX_BALL];
  printf("fcm-models --ball-study%s: a unit ball triangulated at half the cell size, %s, rules "
         "with the library's defaults\n",
         o->quick ? " --quick" : "", fcm_element_get_info(o->element)->name);
  const int ran = models_ball_study(n, count, o->element, rows);
  printf("%4s %10s %10s %10s %10s %12s %12s\n", "n", "triangles", "cells", "cut_cells", "rules_s",
         "us/cut_cell", "points/cut");
  double x[MODELS_MAX_BALL], y[MODELS_MAX_BALL];
  for (int i = 0; i < count; i++) {
    const ball_row *b = &rows[i];
    x[i] = b->ok ? (double)b->cut_cells : -1.0, y[i] = b->ok ? b->rules_s : -1.0;
    if (!b->ok) {
      printf("%4d FAILED: %s\n", b->n, b->note);
      continue;
    }
    printf("%4d %10lld %10lld %10lld %10.3f %12.1f %12.1f\n", b->n, b->triangles, b->cells,
           b->cut_cells, b->rules_s, 1e6 * b->rules_s / (double)(b->cut_cells ? b->cut_cells : 1),
           b->points_final);
  }
  const double e = models_fit_exponent(x, y, count);
  const int holds = isfinite(e) && e <= 1.1;
  printf("\nfitted exponent of rule time against cut cells (least squares, log-log, n = %d..%d): "
         "%.3f\n",
         n[0], n[count - 1], e);
  if (o->quick)
    printf("claim exponent <= 1.1 (n = 8..64): %s\n",
           holds ? "consistent at this range (the full study shows it)"
                 : "NOT shown: at n = 8..16 the fixed costs per call weigh too much for the fit "
                   "to show it; run without --quick");
  else
    printf("claim exponent <= 1.1: %s\n", holds ? "holds" : "FAILS");
  int ok = ran;
  if (o->csv && !models_write_ball_csv(o->csv, rows, count)) ok = 0;
  if (o->png && !models_write_ball_png(o->png, rows, count, e)) ok = 0;
  return ok && (o->quick || holds) ? 0 : 1;
}

static int models_main(models_settings *o, const model_names *mn)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  char bumpy[4096] = "";
  int code = 0;
  static model_pair pairs[MODELS_MAX_MODELS * MODELS_MAX_SIZES];
  int npairs = 0;
  if (!resolve_models(ctx, mn, o, bumpy, sizeof bumpy)) {
    code = 2;
    goto done;
  }
  const int gmsh = fcm_surface_meshing_available();
  printf("fcm-models: %d model(s) x %d cell size(s), %s, %d steps; new = surface path (the "
         "defaults), old = volume mesh + sub-tet rules%s\n",
         o->nmodels, o->nsizes, fcm_element_get_info(o->element)->name, o->steps,
         o->new_only ? " (skipped: --new-only)"
         : gmsh      ? ""
                     : " (skipped: fcm has no Gmsh)");
  models_print_header();
  for (int i = 0; i < o->nmodels; i++)
    for (int j = 0; j < o->nsizes; j++) {
      model_pair *p = &pairs[npairs++];
      memset(p, 0, sizeof *p);
      p->model = i, p->h = o->sizes[j];
      for (int path = 0; path < NPATH; path++) {
        model_run *r = &p->run[path];
        if (path == PATH_OLD && (o->new_only || !gmsh)) {
          memset(r, 0, sizeof *r);
          snprintf(r->note, sizeof r->note, "%s",
                   o->new_only ? "--new-only"
                               : "the volume path needs Gmsh "
                                 "(fcm_surface_meshing_available() is 0)");
          continue;
        }
        fprintf(stderr, PROG ": %s h = %g %s ...\n", o->models[i].name, p->h,
                path == PATH_OLD ? "old" : "new");
        run_child(&o->models[i], p->h, o, path, r);
        fprintf(stderr, PROG ": %s h = %g %s: %.1f s%s%s\n", o->models[i].name, p->h,
                path == PATH_OLD ? "old" : "new", r->wall, r->ok ? "" : ", FAILED: ", r->note);
        if (!r->ok) code = 1;
      }
      p->moment_diff = moment_diff(&p->run[PATH_NEW], &p->run[PATH_OLD]);
      models_print_pair(o, p);
    }
  double worst = -1.0;
  for (int i = 0; i < npairs; i++)
    worst = fmax(worst, pairs[i].moment_diff);
  if (worst >= 0.0)
    printf("\nlargest difference of the two paths' global moments: %.2e of the volume (%s 1e-12, "
           "the exactness both paths claim)\n",
           worst, worst <= 1e-12 ? "within" : "ABOVE");
  if (o->csv && !models_write_csv(o, pairs, npairs)) code = 1;
  if (o->png && !models_write_png(o, pairs, npairs)) code = 1;
done:
  if (bumpy[0]) { /* the temporary and its directory */
    remove(bumpy);
    char *slash = strrchr(bumpy, '/');
    *slash = 0;
    rmdir(bumpy);
  }
  fcm_ctx_destroy(&ctx);
  return code;
}

int main(int argc, char **argv)
{
  app_env_init(argc, argv);
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  if (argc > 1 && !strcmp(argv[1], CHILD_FLAG)) return child_main(argc, argv);
  static models_settings o;
  raw_options w;
  const int rc = parse_options(argc, argv, &o, &w);
  if (rc >= 0) return rc;
  return o.ball_study ? ball_main(&o) : models_main(&o, &w.models);
}
