/* fcm-rulegen: offline generator of the standard-rule tables in quadrature_tables/
 * by node elimination from the computed (tensor / collapsed) rules. */
#define _POSIX_C_SOURCE 200809L /* mkdir */
#include "app_env.h"
#include <fcm/fcm.h>
#include <fcm/rulegen.h>

#include "cli.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#define RULEGEN_VERSION "0.1"

static void usage(FILE *f)
{
  fprintf(f,
          "usage: fcm-rulegen [options]\n"
          "Generates small positive interior rules by node elimination (Xiao & Gimbutas 2010)\n"
          "from the computed rules and writes one table per shape and strength as\n"
          "DIR/<shape>/<shape>_<mm>.txt. Progress lines go to stderr.\n"
          "  --shape S        tet, hex, tri, quad, line; repeat or use a comma list (default:\n"
          "                   tet,hex,tri,quad)\n"
          "  --strength A[:B] strength or inclusive range (default 1:10)\n"
          "  --out DIR        output directory (default quadrature_tables)\n"
          "  --starts K       try K start rules (computed rules of strength m, m+2, ...) and keep\n"
          "                   the smallest result (default 1)\n"
          "  --from-next      also start from the table of strength m+1 in DIR, if present\n"
          "  --candidates N   single points tried per removal before stopping (default 12)\n"
          "  --iterations N   Levenberg-Marquardt iterations per attempt (default 60)\n"
          "  --batch F        largest fraction of points removed at once early on (default 0.05)\n"
          "  --margin D       smallest distance of a point to the boundary (default 1e-9)\n"
          "  --tol T          moment residual accepted after a removal (default 1e-14)\n"
          "  --force          overwrite a table even when it has fewer points than the new rule\n"
          "  --dry-run        do not write files\n"
          "  --help           this text\n");
}

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

static int parse_shape(const char *s, fcm_shape *out)
{
  static const struct {
    const char *name;
    fcm_shape shape;
  } names[] = {{"line", FCM_SHAPE_LINE},
               {"tri", FCM_SHAPE_TRI},
               {"quad", FCM_SHAPE_QUAD},
               {"tet", FCM_SHAPE_TET},
               {"hex", FCM_SHAPE_HEX}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (!strcmp(s, names[i].name)) {
      *out = names[i].shape;
      return 1;
    }
  return 0;
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

static int ensure_dir(const char *path)
{
  if (mkdir(path, 0777) == 0 || errno == EEXIST) return 1;
  fprintf(stderr, "fcm-rulegen: cannot create directory %s: %s\n", path, strerror(errno));
  return 0;
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
    ok = ensure_dir(cfg->out) && ensure_dir(dir) &&
         write_table(path, best, best_desc, best_start_n, best_start_m, &best_info, seconds);
    printf(ok ? ", wrote %s\n" : ", FAILED to write %s\n", path);
  }
  fflush(stdout);
  fcm_rule_destroy(&best);
  return ok;
}

/* An int or a finite double from all of `s` in [lo, hi] (messages name `opt`). */
static int parse_int(const char *opt, const char *s, long long lo, long long hi, int *v)
{
  long long n = 0;
  if (!cli_int("fcm-rulegen", opt, s, lo, hi, &n)) return 0;
  *v = (int)n;
  return 1;
}

static int parse_double(const char *opt, const char *s, double lo, double hi, double *v)
{
  return cli_double("fcm-rulegen", opt, s, lo, hi, 0, v);
}

int main(int argc, char **argv)
{
  app_env_init(argc, argv); /* passive OpenMP waiting unless the user chose */
  config cfg;
  fcm_shape shapes[16];
  int nshapes = 0, mlo = 1, mhi = 10;
  memset(&cfg, 0, sizeof cfg);
  cfg.out = "quadrature_tables";
  cfg.starts = 1;
  cfg.opts = fcm_rulegen_options_default();
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    int bad = 0;
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
      usage(stdout);
      return 0;
    } else if (!strcmp(a, "--force")) {
      cfg.force = 1;
    } else if (!strcmp(a, "--from-next")) {
      cfg.from_next = 1;
    } else if (!strcmp(a, "--dry-run")) {
      cfg.dry_run = 1;
    } else if (!v) {
      bad = 1;
    } else if (!strcmp(a, "--shape")) {
      char buf[256];
      snprintf(buf, sizeof buf, "%s", v);
      for (char *tok = strtok(buf, ","); tok && !bad; tok = strtok(NULL, ",")) {
        if (nshapes >= 16 || !parse_shape(tok, &shapes[nshapes++])) bad = 1;
      }
      i++;
    } else if (!strcmp(a, "--strength")) {
      char buf[64], *colon;
      snprintf(buf, sizeof buf, "%s", v);
      colon = strchr(buf, ':');
      if (colon) *colon = '\0';
      bad = !parse_int(a, buf, 1, 40, &mlo) || !parse_int(a, colon ? colon + 1 : buf, 1, 40, &mhi);
      i++;
    } else if (!strcmp(a, "--out")) {
      cfg.out = v;
      i++;
    } else if (!strcmp(a, "--starts")) {
      bad = !parse_int(a, v, 0, 1000000, &cfg.starts);
      i++;
    } else if (!strcmp(a, "--candidates")) {
      bad = !parse_int(a, v, 1, 1000000, &cfg.opts.max_candidates);
      i++;
    } else if (!strcmp(a, "--iterations")) {
      bad = !parse_int(a, v, 1, 1000000, &cfg.opts.max_iterations);
      i++;
    } else if (!strcmp(a, "--batch")) {
      bad = !parse_double(a, v, 0.0, 1.0, &cfg.opts.max_batch);
      i++;
    } else if (!strcmp(a, "--margin")) {
      bad = !parse_double(a, v, 0.0, 1.0, &cfg.opts.margin);
      i++;
    } else if (!strcmp(a, "--tol")) {
      bad = !parse_double(a, v, 0.0, 1.0, &cfg.opts.tol);
      i++;
    } else {
      bad = 1;
    }
    if (bad) {
      fprintf(stderr, "fcm-rulegen: bad or incomplete argument '%s%s%s'\n", a, v ? " " : "",
              v ? v : "");
      usage(stderr);
      return 2;
    }
  }
  if (nshapes == 0) {
    shapes[nshapes++] = FCM_SHAPE_TET;
    shapes[nshapes++] = FCM_SHAPE_HEX;
    shapes[nshapes++] = FCM_SHAPE_TRI;
    shapes[nshapes++] = FCM_SHAPE_QUAD;
  }
  if (cfg.starts == 0 && !cfg.from_next) {
    fprintf(stderr, "fcm-rulegen: --starts 0 needs --from-next\n");
    return 2;
  }
  if (mlo < 1 || mhi < mlo || mhi > 40) {
    fprintf(stderr, "fcm-rulegen: strength range %d:%d outside [1, 40]\n", mlo, mhi);
    return 2;
  }
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-rulegen: cannot create context\n");
    return 1;
  }
  int ok = 1;
  double t0 = fcm_wtime();
  for (int m = mlo; m <= mhi && ok; m++)
    for (int s = 0; s < nshapes && ok; s++)
      ok = generate(ctx, &cfg, shapes[s], m);
  fprintf(stderr, "fcm-rulegen: total %.1f s\n", fcm_wtime() - t0);
  fcm_ctx_destroy(&ctx);
  return ok ? 0 : 1;
}
