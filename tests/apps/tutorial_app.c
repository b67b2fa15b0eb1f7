/* apps/docs/tutorial.md, run as written: every ```sh block in order, in a fresh directory with
 * the programs on PATH, must exit 0; the files named by the "<!-- produces: ... -->" line after
 * a block must exist; every line of an ```output block must appear in what the block before it
 * printed (leading blanks aside). Then the log's facts the tutorial states: 20 rows, every step
 * converged (residual <= tolerance), mass rho V = 4 kg in every row, one body.
 * Arguments: the tutorial, the directory of the programs, a scratch directory. */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAX_BLOCKS 32
#define MAX_TEXT   16384

typedef struct block {
  char script[MAX_TEXT];   /* the commands */
  char expected[MAX_TEXT]; /* lines that must appear in their output ("" none) */
  char produces[1024];     /* files they make, blank-separated ("" none) */
} block;

static block blocks[MAX_BLOCKS];

/* Append a line to buf (cap bytes); 0 when it does not fit. */
static int append(char *buf, size_t cap, const char *line)
{
  const size_t n = strlen(buf), m = strlen(line);
  if (n + m + 1 >= cap) return 0;
  memcpy(buf + n, line, m + 1);
  return 1;
}

/* The blocks of the tutorial; their count, -1 on a malformed file. */
static int read_tutorial(const char *path)
{
  FILE *f = fopen(path, "r");
  char line[4096];
  int n = 0, ok = 1;
  char *into = NULL; /* the open fence's text: a script, an expected output, or ignored */
  int fenced = 0;
  if (!f) return -1;
  while (ok && fgets(line, sizeof line, f)) {
    if (!strncmp(line, "```", 3)) {
      if (fenced) {
        fenced = 0, into = NULL;
      } else {
        fenced = 1;
        if (!strcmp(line, "```sh\n")) {
          ok = n < MAX_BLOCKS;
          into = ok ? blocks[n++].script : NULL;
        } else if (!strcmp(line, "```output\n")) {
          ok = n > 0 && !blocks[n - 1].expected[0];
          into = ok ? blocks[n - 1].expected : NULL;
        }
      }
      continue;
    }
    if (fenced) {
      if (into) ok = append(into, MAX_TEXT, line);
      continue;
    }
    const char *p = strstr(line, "<!-- produces:");
    if (p) {
      const char *end = strstr(p, "-->");
      ok = n > 0 && end && !blocks[n - 1].produces[0] &&
           (size_t)(end - p) < sizeof blocks[0].produces;
      if (ok) {
        p += strlen("<!-- produces:");
        memcpy(blocks[n - 1].produces, p, (size_t)(end - p));
        blocks[n - 1].produces[end - p] = 0;
      }
    }
  }
  fclose(f);
  return ok && !fenced ? n : -1;
}

/* The whole file (NUL-terminated, malloc'd), NULL when it cannot be read. */
static char *slurp(const char *path)
{
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *buf = calloc(1 << 20, 1);
  if (buf) buf[fread(buf, 1, (1 << 20) - 1, f)] = 0;
  fclose(f);
  return buf;
}

/* Block k run in dir; the checks of its exit status, its files and its output. */
static void run_block(int k, const char *dir, const char *bin)
{
  const block *b = &blocks[k];
  char path[2400], cmd[8192], log[2400];
  snprintf(path, sizeof path, "%s/block_%02d.sh", dir, k);
  snprintf(log, sizeof log, "%s/block_%02d.log", dir, k);
  FILE *f = fopen(path, "w");
  if (!f || fputs(b->script, f) < 0) TEST_FAIL_("cannot write %s", path);
  if (f) fclose(f);
  snprintf(cmd, sizeof cmd, "cd '%s' && PATH='%s':\"$PATH\" sh -e '%s' > '%s' 2>&1", dir, bin, path,
           log);
  const int rc = app_run(cmd);
  if (rc != 0) TEST_FAIL_("block %d exited %d (its output: %s):\n%s", k, rc, log, b->script);
  char files[sizeof b->produces];
  memcpy(files, b->produces, sizeof files);
  for (char *save = NULL, *t = strtok_r(files, " \t", &save); t; t = strtok_r(NULL, " \t", &save)) {
    snprintf(path, sizeof path, "%s/%s", dir, t);
    if (!app_exists(path)) TEST_FAIL_("block %d should produce %s", k, t);
  }
  char *out = slurp(log), expected[MAX_TEXT];
  memcpy(expected, b->expected, sizeof expected);
  for (char *save = NULL, *t = strtok_r(expected, "\n", &save); t;
       t = strtok_r(NULL, "\n", &save)) {
    while (*t == ' ')
      t++;
    if (*t && (!out || !strstr(out, t)))
      TEST_FAIL_("block %d should print \"%s\" (its output: %s)", k, t, log);
  }
  free(out);
}

/* The index of `name` in the CSV header line, -1 when absent. */
static int column(const char *header, const char *name)
{
  char buf[64];
  for (int k = 0; k < 256; k++) {
    field(header, k, buf, sizeof buf);
    if (!strcmp(buf, name)) return k;
    if (!buf[0]) return -1;
  }
  return -1;
}

/* The log's facts the tutorial states (section 5). */
static void check_log(const char *dir)
{
  char path[2400], header[4096], line[4096], buf[64];
  snprintf(path, sizeof path, "%s/beam-out/beam_log.csv", dir);
  FILE *f = fopen(path, "r");
  if (!f || !fgets(header, sizeof header, f)) {
    TEST_FAIL_("cannot read %s", path);
    if (f) fclose(f);
    return;
  }
  const int res = column(header, "residual"), tol = column(header, "tolerance"),
            mass = column(header, "mass"), pieces = column(header, "pieces");
  TEST_TRUE(res >= 0 && tol >= 0 && mass >= 0 && pieces >= 0);
  int rows = 0, converged = 0, mass_ok = 0, one_body = 0;
  while (res >= 0 && tol >= 0 && mass >= 0 && pieces >= 0 && fgets(line, sizeof line, f)) {
    double r, t, m, p;
    field(line, res, buf, sizeof buf), r = atof(buf);
    field(line, tol, buf, sizeof buf), t = atof(buf);
    field(line, mass, buf, sizeof buf), m = atof(buf);
    field(line, pieces, buf, sizeof buf), p = atof(buf);
    rows++;
    converged += r <= t && t > 0.0;
    mass_ok += fabs(m - 4.0) <= 1e-9 * 4.0; /* 1000 kg/m^3 x 0.4 x 0.1 x 0.1 m^3 */
    one_body += p == 1.0;
  }
  fclose(f);
  TEST_TRUE(rows == 20 && converged == 20 && mass_ok == 20 && one_body == 20);
}

int main(int argc, char **argv)
{
  if (argc != 4) {
    fprintf(stderr, "usage: tutorial_app TUTORIAL.md BINDIR WORKDIR\n");
    return 2;
  }
  const int n = read_tutorial(argv[1]);
  /* the tutorial's steps: the model, the scene, --preview, --check, the run, the log */
  if (n < 6) {
    fprintf(stderr, "%s: %d sh blocks read, expected at least 6 (or a malformed fence)\n", argv[1],
            n);
    return 1;
  }
  char dir[1024];
  if (strlen(argv[3]) > 900) return fprintf(stderr, "%s: too long\n", argv[3]), 1;
  snprintf(dir, sizeof dir, "%s/tutorial-XXXXXX", argv[3]);
  if (!mkdtemp(dir)) {
    perror(dir);
    return 1;
  }
  int with_output = 0, with_files = 0;
  for (int k = 0; k < n; k++) {
    run_block(k, dir, argv[2]);
    with_output += blocks[k].expected[0] != 0;
    with_files += blocks[k].produces[0] != 0;
  }
  TEST_TRUE(with_output >= 3 && with_files >= 4);
  check_log(dir);
  if (!test_failures_) {
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    TEST_TRUE(app_run(cmd) == 0);
  }
  return TEST_RESULT();
}
