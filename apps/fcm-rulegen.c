/* fcm-rulegen: offline generator of the standard-rule tables in quadrature_tables/
 * by node elimination from the computed (tensor / collapsed) rules. */
#include "app_env.h"
#include <fcm/fcm.h>
#include <fcm/rulegen.h>

#include "cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define RULEGEN_VERSION "0.1"

typedef struct progress_state {
  const char *shape;
  int strength;
  double last;
} progress_state;

static void progress(void *user, const fcm_rulegen_info *info)
{
  progress_state *p = user;
  if (info->seconds - p->last < 2.0 && info->num_points > 1) return;
  p->last = info->seconds;
  fprintf(stderr, "  %s %2d: %d -> %d points, residual %.1e, %lld iterations, %d failed, %.1f s\n",
          p->shape, p->strength, info->initial_points, info->num_points, info->residual,
          info->iterations, info->failed_attempts, info->seconds);
}

/* Number of points of an existing table file, 0 when absent or unreadable. */
static int existing_points(const char *path)
{
  FILE *f = fopen(path, "r");
  char line[512];
  int n = 0;
  if (!f) return 0;
  while (fgets(line, sizeof line, f) && line[0] == '#')
    if (sscanf(line, "# points: %d", &n) == 1) break;
  fclose(f);
  return n;
}

/* Read a table file written by this program as a user rule of the file's strength;
 * returns NULL when the file is absent or malformed. */
static fcm_rule *read_table(fcm_ctx *ctx, const char *path, fcm_shape shape)
{
  FILE *f = fopen(path, "r");
  char line[1024];
  int n = -1, strength = -1, rows = 0, dim = fcm_shape_dim(shape), ok = 1;
  double *x = NULL, *w = NULL;
  fcm_rule *rule = NULL;
  if (!f) return NULL;
  while (ok && fgets(line, sizeof line, f)) {
    if (line[0] == '#') {
      if (sscanf(line, "# points: %d", &n) == 1 && n > 0) {
        x = calloc((size_t)n * dim, sizeof *x);
        w = calloc((size_t)n, sizeof *w);
        ok = x && w;
      }
      sscanf(line, "# strength: %d", &strength);
      continue;
    }
    char *p = line, *end;
    double v[4];
    int k = 0;
    for (; k <= dim; k++, p = end)
      if (v[k] = strtod(p, &end), end == p) break;
    if (k == 0) continue;
    ok = k == dim + 1 && x && rows < n;
    if (!ok) break;
    for (int d = 0; d < dim; d++)
      x[rows * dim + d] = v[d];
    w[rows++] = v[dim];
  }
  fclose(f);
  if (ok && rows == n && strength >= 0 &&
      fcm_rule_create_from_arrays(ctx, shape, strength, n, x, w, &rule) != FCM_OK) {
    fcm_ctx_error_view(ctx, stderr);
    fcm_ctx_error_clear(ctx);
  }
  if (!rule) fprintf(stderr, "fcm-rulegen: cannot use %s as a start rule\n", path);
  free(x);
  free(w);
  return rule;
}

static int write_table(const char *path, const fcm_rule *rule, const char *start_desc,
                       int start_points, int start_strength, const fcm_rulegen_info *info,
                       double seconds)
{
  char date[32];
  time_t now = time(NULL);
  struct tm *tm = gmtime(&now);
  int dim = fcm_shape_dim(fcm_rule_shape(rule)), n = fcm_rule_num_points(rule);
  const double *x = fcm_rule_points(rule), *w = fcm_rule_weights(rule);
  static const char *const axis[3] = {"x", "y", "z"};
  if (!tm || !strftime(date, sizeof date, "%Y-%m-%d", tm)) snprintf(date, sizeof date, "unknown");
  cli_output *out = NULL;
  FILE *f = cli_output_open("fcm-rulegen", path, &out);
  if (!f) return 0;
  fprintf(f, "# fcm quadrature table\n");
  fprintf(f, "# shape: %s\n", fcm_shape_name(fcm_rule_shape(rule)));
  fprintf(f, "# strength: %d\n", fcm_rule_strength(rule));
  fprintf(f, "# points: %d\n", n);
  fprintf(f, "# method: node elimination from %s (%d points, strength %d), fcm-rulegen %s\n",
          start_desc, start_points, start_strength, RULEGEN_VERSION);
  fprintf(f, "# max relative moment residual: %.2e (orthonormal basis)\n", info->residual);
  fprintf(f, "# min weight / mean weight: %.3e\n", info->min_weight);
  fprintf(f, "# min distance to boundary: %.3e\n", info->min_distance);
  fprintf(f, "# generator time: %.2f s\n", seconds);
  fprintf(f, "# date: %s\n", date);
  fprintf(f, "# columns:");
  for (int k = 0; k < dim; k++)
    fprintf(f, " %s", axis[k]);
  fprintf(f, " weight\n");
  for (int i = 0; i < n; i++) {
    for (int k = 0; k < dim; k++)
      fprintf(f, "%s%.17g", k ? " " : "", x[dim * i + k]);
    fprintf(f, " %.17g\n", w[i]);
  }
  return cli_output_commit("fcm-rulegen", &out);
}

typedef struct config {
  const char *out;
  int starts, from_next, force, dry_run;
  fcm_rulegen_options opts;
} config;

/* Generate one table; returns 0 on a hard error. */
static int generate(fcm_ctx *ctx, const config *cfg, fcm_shape shape, int m)
{
  const char *sname = fcm_shape_name(shape);
  fcm_rule *best = NULL;
  fcm_rulegen_info best_info;
  char best_desc[160] = "", dir[900], path[1000];
  int best_start_n = 0, best_start_m = 0, ok = 1;
  double t0 = fcm_wtime();
  memset(&best_info, 0, sizeof best_info);
  for (int s = 0; s < cfg->starts + cfg->from_next; s++) {
    int ms = m + 2 * s;
    fcm_rule *start = NULL, *rule = NULL;
    fcm_rulegen_info info;
    progress_state ps = {sname, m, -1e30};
    fcm_rulegen_options o = cfg->opts;
    char start_desc[160];
    o.progress = progress;
    o.progress_user = &ps;
    if (s == cfg->starts) { /* the stored table of strength m + 1 */
      snprintf(path, sizeof path, "%s/%s/%s_%02d.txt", cfg->out, sname, sname, m + 1);
      if (!(start = read_table(ctx, path, shape))) continue;
      ms = fcm_rule_strength(start);
      snprintf(start_desc, sizeof start_desc, "table %s_%02d", sname, m + 1);
    } else if (fcm_rule_create_computed(ctx, shape, ms, &start) != FCM_OK) {
      fcm_ctx_error_view(ctx, stderr);
      return 0;
    } else {
      snprintf(start_desc, sizeof start_desc, "%s", fcm_rule_description(start));
    }
    fcm_status st = fcm_rule_eliminate_nodes(ctx, start, m, &o, &info, &rule);
    if (st != FCM_OK) {
      fprintf(stderr, "fcm-rulegen: %s %d from strength %d failed\n", sname, m, ms);
      fcm_ctx_error_view(ctx, stderr);
      fcm_ctx_error_clear(ctx);
    } else {
      fprintf(stderr, "  %s %2d: start %s (%d points): %d points, residual %.1e, %.1f s\n", sname,
              m, start_desc, fcm_rule_num_points(start), fcm_rule_num_points(rule), info.residual,
              info.seconds);
      if (!best || fcm_rule_num_points(rule) < fcm_rule_num_points(best) ||
          (fcm_rule_num_points(rule) == fcm_rule_num_points(best) &&
           info.residual < best_info.residual)) {
        fcm_rule_destroy(&best);
        best = rule;
        rule = NULL;
        best_info = info;
        snprintf(best_desc, sizeof best_desc, "%s", start_desc);
        best_start_n = fcm_rule_num_points(start);
        best_start_m = ms;
      }
    }
    fcm_rule_destroy(&rule);
    fcm_rule_destroy(&start);
  }
  double seconds = fcm_wtime() - t0;
  if (!best) { /* reported above; go on with the other tables */
    fprintf(stderr, "fcm-rulegen: no rule for %s strength %d\n", sname, m);
    return 1;
  }
  snprintf(dir, sizeof dir, "%s/%s", cfg->out, sname);
  snprintf(path, sizeof path, "%s/%s_%02d.txt", dir, sname, m);
  int old = existing_points(path), n = fcm_rule_num_points(best);
  printf("%s %2d: %d points (start %d), residual %.1e, %.1f s", sname, m, n, best_start_n,
         best_info.residual, seconds);
  if (cfg->dry_run) {
    printf(", not written (dry run)\n");
  } else if (old > 0 && old < n && !cfg->force) {
    printf(", kept %s (%d points)\n", path, old);
  } else {
    ok = cli_make_dirs("fcm-rulegen", dir) &&
         write_table(path, best, best_desc, best_start_n, best_start_m, &best_info, seconds);
    printf(ok ? ", wrote %s\n" : ", FAILED to write %s\n", path);
  }
  fflush(stdout);
  fcm_rule_destroy(&best);
  return ok;
}

/* ---------------------------------------------------------------- options */

#define MAX_SHAPES 16

typedef struct shape_list {
  fcm_shape shape[MAX_SHAPES];
  int count;
} shape_list;

/* --shape: a comma list appended to the shapes given so far (the option may repeat). */
static int parse_shapes(const char *prog, const char *opt, const char *s, void *dest)
{
  static const char *const names[] = {"line", "tri", "quad", "tet", "hex", NULL};
  static const fcm_shape shapes[] = {FCM_SHAPE_LINE, FCM_SHAPE_TRI, FCM_SHAPE_QUAD, FCM_SHAPE_TET,
                                     FCM_SHAPE_HEX};
  shape_list *l = dest;
  char tok[MAX_SHAPES][CLI_TOKEN];
  int n = 0, which = 0;
  if (!cli_list(prog, opt, s, tok, MAX_SHAPES, &n)) return 0;
  if (l->count + n > MAX_SHAPES) {
    fprintf(stderr, "%s: %s: more than %d shapes in all\n", prog, opt, MAX_SHAPES);
    return 0;
  }
  for (int k = 0; k < n; k++) {
    if (!cli_choice(prog, opt, tok[k], names, &which)) return 0;
    l->shape[l->count++] = shapes[which];
  }
  return 1;
}

/* --strength: A or A:B (inclusive) with 1 <= A <= B <= 40 into int[2]. */
static int parse_strengths(const char *prog, const char *opt, const char *s, void *dest)
{
  int *m = dest;
  long long lo = 0, hi = 0;
  char buf[64];
  if (snprintf(buf, sizeof buf, "%s", s) >= (int)sizeof buf) {
    fprintf(stderr, "%s: %s: '%s' is not A or A:B\n", prog, opt, s);
    return 0;
  }
  char *colon = strchr(buf, ':');
  if (colon) *colon = '\0';
  if (!cli_int(prog, opt, buf, 1, 40, &lo) ||
      !cli_int(prog, opt, colon ? colon + 1 : buf, 1, 40, &hi))
    return 0;
  if (hi < lo) {
    fprintf(stderr, "%s: %s: the range %lld:%lld is empty\n", prog, opt, lo, hi);
    return 0;
  }
  m[0] = (int)lo, m[1] = (int)hi;
  return 1;
}

#define NUM_OPTIONS 13
static void option_table(config *c, shape_list *shapes, int strengths[2], cli_option t[NUM_OPTIONS])
{
  fcm_rulegen_options *o = &c->opts;
  const cli_option opts[NUM_OPTIONS] = {
      {"--shape", NULL, CLI_CUSTOM, shapes, "S",
       "tet, hex, tri, quad, line; repeat or use a comma list\n(default: tet,hex,tri,quad)", 0, 0,
       0, NULL, parse_shapes, NULL},
      {"--strength", NULL, CLI_CUSTOM, strengths, "A[:B]",
       "strength or inclusive range in [1, 40] (default 1:10)", 0, 0, 0, NULL, parse_strengths,
       NULL},
      {"--out", NULL, CLI_STRING, &c->out, "DIR", "output directory (default quadrature_tables)", 0,
       0, 0, NULL, NULL, NULL},
      {"--starts", NULL, CLI_INT, &c->starts, "K",
       "try K start rules (computed rules of strength m, m+2, ...) and keep\n"
       "the smallest result (default 1; 0 needs --from-next)",
       0, 1e6, 0, NULL, NULL, NULL},
      {"--from-next", NULL, CLI_FLAG, &c->from_next, NULL,
       "also start from the table of strength m+1 in DIR, if present", 0, 0, 0, NULL, NULL, NULL},
      {"--candidates", NULL, CLI_INT, &o->max_candidates, "N",
       "single points tried per removal before stopping (default 12)", 1, 1e6, 0, NULL, NULL, NULL},
      {"--iterations", NULL, CLI_INT, &o->max_iterations, "N",
       "Levenberg-Marquardt iterations per attempt (default 60)", 1, 1e6, 0, NULL, NULL, NULL},
      {"--batch", NULL, CLI_DOUBLE, &o->max_batch, "F",
       "largest fraction of points removed at once early on, in [0, 1]\n(default 0.05)", 0, 1, 0,
       NULL, NULL, NULL},
      {"--margin", NULL, CLI_DOUBLE, &o->margin, "D",
       "smallest distance of a point to the boundary, in [0, 1] (default 1e-9)", 0, 1, 0, NULL,
       NULL, NULL},
      {"--tol", NULL, CLI_DOUBLE, &o->tol, "T",
       "moment residual accepted after a removal, in [0, 1] (default 1e-14)", 0, 1, 0, NULL, NULL,
       NULL},
      {"--force", NULL, CLI_FLAG, &c->force, NULL,
       "overwrite a table even when it has fewer points than the new rule", 0, 0, 0, NULL, NULL,
       NULL},
      {"--dry-run", NULL, CLI_FLAG, &c->dry_run, NULL, "do not write files", 0, 0, 0, NULL, NULL,
       NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(t, opts, sizeof opts);
}

static void usage(FILE *f, const cli_option *opts)
{
  fprintf(f, "usage: fcm-rulegen [options]\n"
             "Generates small positive interior rules by node elimination (Xiao & Gimbutas 2010)\n"
             "from the computed rules and writes one table per shape and strength as\n"
             "DIR/<shape>/<shape>_<mm>.txt. Progress lines go to stderr.\n");
  cli_print_options(f, opts);
}

/* Parse the command line into `c`, the shapes and the strength range: -1 to go on, else the
 * exit code (0 after --help, 2 on a usage error). */
static int parse_args(int argc, char **argv, config *c, shape_list *shapes, int strengths[2])
{
  cli_option opts[NUM_OPTIONS];
  option_table(c, shapes, strengths, opts);
  const int rc = cli_parse_args("fcm-rulegen", opts, argc, argv, NULL, 0, NULL, usage);
  if (rc >= 0) return rc;
  if (shapes->count == 0) {
    static const fcm_shape def[] = {FCM_SHAPE_TET, FCM_SHAPE_HEX, FCM_SHAPE_TRI, FCM_SHAPE_QUAD};
    memcpy(shapes->shape, def, sizeof def);
    shapes->count = 4;
  }
  if (c->starts == 0 && !c->from_next) {
    fprintf(stderr, "fcm-rulegen: --starts 0 needs --from-next\n");
    return 2;
  }
  return -1;
}

int main(int argc, char **argv)
{
  app_env_init(argc, argv); /* OpenMP waiting, the CPU's BLAS kernels, huge pages (app_env.h) */
  config cfg;
  shape_list shapes = {{FCM_SHAPE_LINE}, 0};
  int strengths[2] = {1, 10};
  memset(&cfg, 0, sizeof cfg);
  cfg.out = "quadrature_tables";
  cfg.starts = 1;
  cfg.opts = fcm_rulegen_options_default();
  const int parsed = parse_args(argc, argv, &cfg, &shapes, strengths);
  if (parsed >= 0) return parsed;
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-rulegen: cannot create context\n");
    return 1;
  }
  int ok = 1;
  double t0 = fcm_wtime();
  for (int m = strengths[0]; m <= strengths[1] && ok; m++)
    for (int s = 0; s < shapes.count && ok; s++)
      ok = generate(ctx, &cfg, shapes.shape[s], m);
  fprintf(stderr, "fcm-rulegen: total %.1f s\n", fcm_wtime() - t0);
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
