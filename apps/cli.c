/* apps/cli: shared command-line helpers of the fcm programs (see cli.h). */
#include "cli.h"

#include <fcm/core.h>
#include <fcm/io.h>

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int cli_double(const char *prog, const char *opt, const char *s, double lo, double hi,
               unsigned bounds, double *out)
{
  char *end = NULL;
  const double v = s ? strtod(s, &end) : NAN;
  /* overflow gives an infinity (refused); underflow to a subnormal or zero is a number */
  if (!s || end == s || *end || !isfinite(v)) {
    fprintf(stderr, "%s: %s: '%s' is not a finite number\n", prog, opt, s ? s : "");
    return 0;
  }
  const int lo_ok = bounds & CLI_LO_OPEN ? v > lo : v >= lo;
  const int hi_ok = bounds & CLI_HI_OPEN ? v < hi : v <= hi;
  if (!lo_ok || !hi_ok) {
    fprintf(stderr, "%s: %s: %s is outside %c%g, %g%c\n", prog, opt, s,
            bounds & CLI_LO_OPEN ? '(' : '[', lo, hi, bounds & CLI_HI_OPEN ? ')' : ']');
    return 0;
  }
  *out = v;
  return 1;
}

int cli_int(const char *prog, const char *opt, const char *s, long long lo, long long hi,
            long long *out)
{
  char *end = NULL;
  errno = 0;
  const long long v = s ? strtoll(s, &end, 10) : 0;
  if (!s || end == s || *end || errno == ERANGE || v < lo || v > hi) {
    fprintf(stderr, "%s: %s: '%s' is not a whole number in [%lld, %lld]\n", prog, opt, s ? s : "",
            lo, hi);
    return 0;
  }
  *out = v;
  return 1;
}

int cli_list(const char *prog, const char *opt, const char *s, char tok[][CLI_TOKEN], int cap,
             int *n)
{
  *n = 0;
  if (!s || !*s) {
    fprintf(stderr, "%s: %s: empty list\n", prog, opt);
    return 0;
  }
  for (;;) {
    const char *c = strchr(s, ',');
    const size_t len = c ? (size_t)(c - s) : strlen(s);
    if (len == 0 || len >= CLI_TOKEN || *n >= cap) {
      fprintf(stderr,
              "%s: %s: malformed list (empty item, item longer than %d characters or more than "
              "%d items)\n",
              prog, opt, CLI_TOKEN - 1, cap);
      return 0;
    }
    memcpy(tok[*n], s, len);
    tok[*n][len] = '\0';
    (*n)++;
    if (!c) return 1;
    s = c + 1;
  }
}

int cli_choice(const char *prog, const char *opt, const char *s, const char *const *names, int *out)
{
  for (int k = 0; names[k]; k++)
    if (s && !strcmp(s, names[k])) {
      *out = k;
      return 1;
    }
  fprintf(stderr, "%s: %s: '%s' is not one of", prog, opt, s ? s : "");
  for (int k = 0; names[k]; k++)
    fprintf(stderr, "%s %s", k ? "," : "", names[k]);
  fprintf(stderr, "\n");
  return 0;
}

int cli_element(const char *prog, const char *opt, const char *s, void *dest)
{
  if (s && fcm_element_type_from_name(s, (fcm_element_type *)dest) == FCM_OK) return 1;
  fprintf(stderr, "%s: %s: unknown element '%s' (tet4, tet10, hex8, hex20)\n", prog, opt,
          s ? s : "");
  return 0;
}

int cli_element_list(const char *prog, const char *opt, const char *s,
                     fcm_element_type out[FCM_ELEMENT_COUNT], int *n)
{
  char tok[FCM_ELEMENT_COUNT][CLI_TOKEN];
  int count = 0;
  if (!cli_list(prog, opt, s, tok, FCM_ELEMENT_COUNT, &count)) return 0;
  for (int k = 0; k < count; k++) {
    if (!cli_element(prog, opt, tok[k], &out[k])) return 0;
    for (int j = 0; j < k; j++)
      if (out[j] == out[k]) {
        fprintf(stderr, "%s: %s: '%s' given twice\n", prog, opt, tok[k]);
        return 0;
      }
  }
  *n = count;
  return 1;
}

/* ---------------------------------------------------------------- option tables */

/* The number of values `o` takes: the words of a number option's metavar, else 1. */
static int num_values(const cli_option *o)
{
  int n = 1;
  if ((o->kind == CLI_DOUBLE || o->kind == CLI_INT || o->kind == CLI_LLONG) && o->metavar)
    for (const char *c = o->metavar; *c; c++)
      n += *c == ' ' && c[1] && c[1] != ' ';
  return n;
}

/* Value `k` of option `o` from `v`. */
static int read_value(const char *prog, const cli_option *o, int k, const char *v)
{
  long long n = 0;
  switch (o->kind) {
  case CLI_DOUBLE:
    return cli_double(prog, o->name, v, o->lo, o->hi, o->bounds, (double *)o->dest + k);
  case CLI_INT:
    if (!cli_int(prog, o->name, v, (long long)o->lo, (long long)o->hi, &n)) return 0;
    ((int *)o->dest)[k] = (int)n;
    return 1;
  case CLI_LLONG:
    return cli_int(prog, o->name, v, (long long)o->lo, (long long)o->hi, (long long *)o->dest + k);
  case CLI_STRING:
    if (!*v) {
      fprintf(stderr, "%s: %s: empty value\n", prog, o->name);
      return 0;
    }
    *(const char **)o->dest = v;
    return 1;
  case CLI_CHOICE:
    return cli_choice(prog, o->name, v, o->choices, (int *)o->dest);
  case CLI_CUSTOM:
    return o->parse(prog, o->name, v, o->dest);
  case CLI_FLAG:
    break;
  }
  return 0;
}

cli_result cli_parse(const char *prog, const cli_option *opts, int argc, char **argv,
                     const char **pos, int max_pos, int *npos)
{
  int np = 0;
  if (npos) *npos = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) return CLI_HELP;
    if (a[0] != '-' || !a[1]) { /* positional ("-" alone too: standard input or a default) */
      if (np >= max_pos) {
        fprintf(stderr, "%s: unexpected argument '%s' (see --help)\n", prog, a);
        return CLI_ERROR;
      }
      pos[np++] = a;
      if (npos) *npos = np;
      continue;
    }
    const char *eq = a[1] == '-' ? strchr(a, '=') : NULL;
    const size_t len = eq ? (size_t)(eq - a) : strlen(a);
    const cli_option *o = opts;
    for (; o->name; o++)
      if ((strlen(o->name) == len && !strncmp(a, o->name, len)) ||
          (o->alias && strlen(o->alias) == len && !strncmp(a, o->alias, len)))
        break;
    if (!o->name) {
      fprintf(stderr, "%s: unknown option '%.*s' (see --help)\n", prog, (int)len, a);
      return CLI_ERROR;
    }
    if (o->kind == CLI_FLAG) {
      if (eq) {
        fprintf(stderr, "%s: %s takes no value\n", prog, o->name);
        return CLI_ERROR;
      }
      *(int *)o->dest = 1;
    } else {
      const int nv = num_values(o);
      if (eq && nv > 1) {
        fprintf(stderr, "%s: %s takes %d values as separate arguments: %s %s\n", prog, o->name, nv,
                o->name, o->metavar);
        return CLI_ERROR;
      }
      for (int k = 0; k < nv; k++) {
        const char *v = eq ? eq + 1 : i + 1 < argc ? argv[++i] : NULL;
        if (!v) {
          if (nv > 1)
            fprintf(stderr, "%s: %s needs %d values %s (see --help)\n", prog, o->name, nv,
                    o->metavar);
          else
            fprintf(stderr, "%s: %s needs a value %s (see --help)\n", prog, o->name,
                    o->metavar ? o->metavar : "");
          return CLI_ERROR;
        }
        if (!read_value(prog, o, k, v)) return CLI_ERROR;
      }
    }
    if (o->seen) *o->seen = 1;
  }
  return CLI_OK;
}

int cli_parse_args(const char *prog, const cli_option *opts, int argc, char **argv,
                   const char **pos, int max_pos, int *npos,
                   void (*help)(FILE *f, const cli_option *opts))
{
  switch (cli_parse(prog, opts, argc, argv, pos, max_pos, npos)) {
  case CLI_HELP:
    help(stdout, opts);
    return 0;
  case CLI_ERROR:
    return 2;
  case CLI_OK:
    break;
  }
  return -1;
}

void cli_print_options(FILE *f, const cli_option *opts)
{
  char head[128];
  int col = 0;
  for (const cli_option *o = opts; o->name; o++) { /* the help column: longest head + 2 */
    int n =
        snprintf(head, sizeof head, "  %s%s%s%s%s", o->alias ? o->alias : "", o->alias ? ", " : "",
                 o->name, o->metavar ? " " : "", o->metavar ? o->metavar : "");
    if (n > col) col = n;
  }
  if (col < (int)strlen("  -h, --help")) col = (int)strlen("  -h, --help");
  col += 2;
  for (const cli_option *o = opts; o->name; o++) {
    int n =
        snprintf(head, sizeof head, "  %s%s%s%s%s", o->alias ? o->alias : "", o->alias ? ", " : "",
                 o->name, o->metavar ? " " : "", o->metavar ? o->metavar : "");
    fprintf(f, "%s%*s", head, col - n, "");
    for (const char *h = o->help ? o->help : ""; *h;) {
      const char *nl = strchr(h, '\n');
      const int len = nl ? (int)(nl - h) : (int)strlen(h);
      fprintf(f, "%.*s\n", len, h);
      if (!nl) break;
      h = nl + 1;
      fprintf(f, "%*s", col, "");
    }
    if (!o->help || !*o->help) fprintf(f, "\n");
  }
  fprintf(f, "  -h, --help%*sthis text\n", col - (int)strlen("  -h, --help"), "");
}

/* ---------------------------------------------------------------- atomic output */

struct cli_output {
  fcm_ctx *ctx;
  fcm_atomic_file *file;
};

FILE *cli_output_open(const char *prog, const char *path, cli_output **out)
{
  cli_output *o = calloc(1, sizeof *o);
  *out = NULL;
  if (!o) {
    fprintf(stderr, "%s: out of memory\n", prog);
    return NULL;
  }
  if (fcm_ctx_create(NULL, &o->ctx) != FCM_OK) {
    fprintf(stderr, "%s: cannot create an fcm context to write %s\n", prog, path);
    free(o);
    return NULL;
  }
  if (fcm_atomic_file_open(o->ctx, path, &o->file) != FCM_OK) {
    fprintf(stderr, "%s: %s\n", prog, fcm_ctx_error_message(o->ctx));
    fcm_ctx_destroy(&o->ctx);
    free(o);
    return NULL;
  }
  *out = o;
  return fcm_atomic_file_stream(o->file);
}

int cli_output_commit(const char *prog, cli_output **out)
{
  if (!out || !*out) return 0;
  cli_output *o = *out;
  *out = NULL;
  const int ok = fcm_atomic_file_commit(&o->file) == FCM_OK;
  if (!ok) fprintf(stderr, "%s: %s\n", prog, fcm_ctx_error_message(o->ctx));
  fcm_ctx_destroy(&o->ctx);
  free(o);
  return ok;
}

void cli_output_abort(cli_output **out)
{
  if (!out || !*out) return;
  fcm_atomic_file_abort(&(*out)->file);
  fcm_ctx_destroy(&(*out)->ctx);
  free(*out);
  *out = NULL;
}

/* dir into buf (4096 bytes); 0 after saying why it does not fit. */
static int copy_dir(const char *prog, const char *dir, char buf[4096])
{
  const size_t n = strlen(dir);
  if (n == 0 || n >= 4096) {
    fprintf(stderr, "%s: bad output directory '%s'\n", prog, dir);
    return 0;
  }
  memcpy(buf, dir, n + 1);
  return 1;
}

int cli_make_dirs(const char *prog, const char *dir)
{
  char buf[4096];
  if (!copy_dir(prog, dir, buf)) return 0;
  const size_t n = strlen(buf);
  for (size_t k = 1; k <= n; k++) {
    if (buf[k] != '/' && buf[k] != '\0') continue;
    const char c = buf[k];
    buf[k] = '\0';
    struct stat sb;
    if (stat(buf, &sb) != 0) {
      if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: cannot create output directory '%s': %s\n", prog, buf,
                strerror(errno));
        return 0;
      }
    } else if (!S_ISDIR(sb.st_mode)) {
      fprintf(stderr, "%s: output path '%s' exists and is not a directory\n", prog, buf);
      return 0;
    }
    buf[k] = c;
  }
  return 1;
}

int cli_check_output_dir(const char *prog, const char *dir)
{
  char buf[4096];
  if (!copy_dir(prog, dir, buf)) return 0;
  for (;;) { /* the path itself, then each parent up to the first that exists */
    struct stat sb;
    if (stat(buf, &sb) == 0) {
      if (!S_ISDIR(sb.st_mode)) {
        fprintf(stderr, "%s: output path '%s' exists and is not a directory\n", prog, buf);
        return 0;
      }
      if (access(buf, W_OK | X_OK) != 0) {
        fprintf(stderr, "%s: cannot write into the output directory '%s': %s\n", prog, buf,
                strerror(errno));
        return 0;
      }
      return 1;
    }
    char *slash = strrchr(buf, '/');
    if (slash == buf) return 1; /* "/x": the root exists */
    if (!slash) { /* a relative path none of whose parts exists: the current directory */
      buf[0] = '.', buf[1] = '\0';
      continue;
    }
    *slash = '\0';
  }
}

void cli_report_scene_error(const char *prog, const char *name, const char *message)
{
  const size_t n = strlen(name);
  if (!strncmp(message, "scene ", 6) && !strncmp(message + 6, name, n) &&
      (message[6 + n] == ':' || message[6 + n] == ' '))
    fprintf(stderr, "%s: %s\n", prog, message);
  else
    fprintf(stderr, "%s: scene %s: %s\n", prog, name, message);
}

const char *const cli_palette[CLI_PALETTE_SIZE] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                                   "#9467bd", "#8c564b", "#e377c2", "#17becf",
                                                   "#bcbd22", "#7f7f7f", "#000080", "#800000"};

/* 1 when `gnuplot` runs, else 0 after saying so (naming the Debian package and what is not
 * written). */
static int gnuplot_found(const char *prog, const char *path)
{
  if (system(NULL) != 0 && system("gnuplot --version > /dev/null 2>&1") == 0) return 1;
  fprintf(stderr, "%s: gnuplot not found (Debian package gnuplot-nox): %s not written\n", prog,
          path);
  return 0;
}

/* Write the script `script` drawing `body` into `out` (PNG terminal of `size`); 1 on success. */
static int gnuplot_write_script(const char *prog, const char *script, const char *size,
                                const char *out, const char *head, const char *body)
{
  FILE *f = fopen(script, "w");
  if (!f) {
    fprintf(stderr, "%s: cannot write %s\n", prog, script);
    return 0;
  }
  fprintf(f, "%sset terminal png size %s\nset output '%s'\n%s\nset output\n", head, size, out,
          body);
  const int werr = ferror(f);
  if (fclose(f) != 0 || werr) {
    fprintf(stderr, "%s: cannot write %s\n", prog, script);
    remove(script);
    return 0;
  }
  return 1;
}

/* Run gnuplot on `script`; 1 when it succeeded. */
static int gnuplot_run(const char *script)
{
  char cmd[4200];
  if (snprintf(cmd, sizeof cmd, "gnuplot '%s' 2>/dev/null", script) >= (int)sizeof cmd) return 0;
  return system(cmd) == 0;
}

int cli_gnuplot_png(const char *prog, const char *size, const char *path, const char *body)
{
  char tmp[4096], script[4096];
  if (!gnuplot_found(prog, path)) return 1;
  if (snprintf(tmp, sizeof tmp, "%s.tmp.png", path) >= (int)sizeof tmp ||
      snprintf(script, sizeof script, "%s.gp.tmp", path) >= (int)sizeof script) {
    fprintf(stderr, "%s: --png: path too long\n", prog);
    return 0;
  }
  if (!gnuplot_write_script(prog, script, size, tmp, "", body)) return 0;
  const int ran = gnuplot_run(script);
  remove(script);
  if (!ran || rename(tmp, path) != 0) {
    remove(tmp);
    fprintf(stderr, "%s: gnuplot failed; %s not written\n", prog, path);
    return 0;
  }
  return 1;
}

int cli_gnuplot_script_png(const char *prog, const char *script, const char *size, const char *path,
                           const char *body)
{
  char head[4400];
  snprintf(head, sizeof head, "# Draws %s; re-draw with: gnuplot %s\n", path, script);
  if (!gnuplot_write_script(prog, script, size, path, head, body)) return 0;
  if (!gnuplot_found(prog, path)) return 1;
  if (!gnuplot_run(script)) {
    remove(path);
    fprintf(stderr, "%s: gnuplot failed on %s; %s not written\n", prog, script, path);
    return 0;
  }
  return 1;
}

void cli_split_petsc_args(int *argc, char **argv, int *pargc, char **pargv)
{
  int petsc = 0, n = 1, m = 1;
  for (int i = 1; i < *argc; i++)
    if (strcmp(argv[i], "--backend=petsc") == 0 ||
        (strcmp(argv[i], "--backend") == 0 && i + 1 < *argc && strcmp(argv[i + 1], "petsc") == 0))
      petsc = 1;
  pargv[0] = argv[0];
  *pargc = 1;
  pargv[1] = NULL;
  if (!petsc) return;
  for (int i = 1; i < *argc; i++) {
    const char *a = argv[i];
    const int opt = a[0] == '-' && a[1] != '-' && a[1] != '\0' && a[2] != '\0';
    if (!opt) {
      argv[n++] = argv[i];
      continue;
    }
    pargv[m++] = argv[i];
    const char *b = i + 1 < *argc ? argv[i + 1] : NULL;
    if (b && !(b[0] == '-' &&
               ((b[1] >= 'a' && b[1] <= 'z') || (b[1] >= 'A' && b[1] <= 'Z') || b[1] == '-')))
      pargv[m++] = argv[++i];
  }
  *argc = n;
  *pargc = m;
  pargv[m] = NULL;
}

void cli_csv_number(FILE *f, double v)
{
  fputc(',', f);
  if (v >= 0.0 && isfinite(v)) fprintf(f, "%.6g", v);
}

void cli_csv_text(FILE *f, const char *s)
{
  fputc(',', f);
  for (; *s; s++)
    fputc(*s == ',' ? ';' : *s == '"' ? '\'' : *s == '\n' || *s == '\r' ? ' ' : *s, f);
}
