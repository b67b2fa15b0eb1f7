/* The programs' shared command-line helper (apps/cli.c): numbers refuse NaN, infinities,
 * overflow, trailing junk and out-of-range values (open and closed ends); whole numbers refuse
 * fractions and exponents; lists refuse empty items; the option table parses "--x v",
 * "--x=v", aliases, flags and positionals, refuses unknown options and missing values, and
 * prints aligned help; cli_parse_args gives the exit codes; a number option takes one value per
 * metavar word; element names and lists (repeats refused) are read; output files appear only at
 * commit, and an abort or a write error leaves the previous file untouched and no temporary behind;
 * cli_make_dirs creates missing parents and refuses a file in the way; CSV fields keep a row's
 * columns.
 * argv[1]: a scratch directory. */
#define _POSIX_C_SOURCE 200809L
#include "../../apps/cli.c"
#include "test.h"

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

static int count_entries(const char *dir)
{
  int n = 0;
  DIR *d = opendir(dir);
  if (!d) return -1;
  for (struct dirent *e; (e = readdir(d));)
    n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
  closedir(d);
  return n;
}

static int file_is(const char *path, const char *want)
{
  char buf[256];
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = '\0';
  return !strcmp(buf, want);
}

static void numbers(void)
{
  double x = -1.0;
  TEST_TRUE(cli_double("p", "--x", "1.5", 0, 2, 0, &x) && x == 1.5);
  TEST_TRUE(cli_double("p", "--x", "1e-320", 0, 1, 0, &x) && x > 0.0); /* subnormal: a number */
  const char *bad[] = {"nan", "NaN", "inf", "-inf", "1e999", "1.5x", "", " ", "1,5", "0x", "--"};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    x = 7.0;
    if (cli_double("p", "--x", bad[k], -1e300, 1e300, 0, &x) || x != 7.0)
      TEST_FAIL_("'%s' accepted as a number", bad[k]);
  }
  TEST_TRUE(!cli_double("p", "--x", NULL, 0, 1, 0, &x));
  TEST_TRUE(cli_double("p", "--x", "0", 0, 1, 0, &x)); /* closed ends */
  TEST_TRUE(cli_double("p", "--x", "1", 0, 1, 0, &x));
  TEST_TRUE(!cli_double("p", "--x", "0", 0, 1, CLI_LO_OPEN, &x)); /* open ends */
  TEST_TRUE(!cli_double("p", "--x", "1", 0, 1, CLI_HI_OPEN, &x));
  TEST_TRUE(cli_double("p", "--x", "0.5", 0, 1, CLI_LO_OPEN | CLI_HI_OPEN, &x) && x == 0.5);
  TEST_TRUE(!cli_double("p", "--x", "1.0000001", 0, 1, 0, &x));

  long long n = -5;
  TEST_TRUE(cli_int("p", "--n", "42", 1, 100, &n) && n == 42);
  TEST_TRUE(cli_int("p", "--n", "-0", 0, 0, &n) && n == 0);
  const char *bad_int[] = {"4.0", "1e3", "0x10", "12a", "", "99999999999999999999", "101", "0"};
  for (size_t k = 0; k < sizeof bad_int / sizeof *bad_int; k++) {
    n = 9;
    if (cli_int("p", "--n", bad_int[k], 1, 100, &n) || n != 9)
      TEST_FAIL_("'%s' accepted as a whole number in [1, 100]", bad_int[k]);
  }
}

static void lists(void)
{
  char tok[4][CLI_TOKEN];
  int n = -1, c = -1;
  TEST_TRUE(cli_list("p", "--l", "tet4,hex20", tok, 4, &n) && n == 2);
  TEST_TRUE(!strcmp(tok[0], "tet4") && !strcmp(tok[1], "hex20"));
  TEST_TRUE(cli_list("p", "--l", "a", tok, 1, &n) && n == 1);
  const char *bad[] = {
      "", ",", "a,", ",a", "a,,b", "a,b,c,d,e", "0123456789012345678901234567890123"};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
    if (cli_list("p", "--l", bad[k], tok, 4, &n)) TEST_FAIL_("list '%s' accepted", bad[k]);
  const char *const names[] = {"none", "jacobi", "schwarz", NULL};
  TEST_TRUE(cli_choice("p", "--c", "schwarz", names, &c) && c == 2);
  TEST_TRUE(!cli_choice("p", "--c", "Schwarz", names, &c) && c == 2);
  TEST_TRUE(!cli_choice("p", "--c", "", names, &c));
}

static void table(const char *work)
{
  static const char *const modes[] = {"mass", "mass+stiffness", NULL};
  double alpha = 0.0;
  int steps = 0, quick = 0, mode = -1, seen_alpha = 0;
  const char *out = NULL, *pos[2] = {NULL, NULL};
  const cli_option opts[] = {
      {"--alpha", NULL, CLI_DOUBLE, &alpha, "A", "weight, > 0", 0, 1, CLI_LO_OPEN, NULL, NULL,
       &seen_alpha},
      {"--steps", NULL, CLI_INT, &steps, "N", "steps\nsecond line", 1, 1000, 0, NULL, NULL, NULL},
      {"--output", "-o", CLI_STRING, &out, "DIR", "output directory", 0, 0, 0, NULL, NULL, NULL},
      {"--mode", NULL, CLI_CHOICE, &mode, "MODE", "mass | mass+stiffness", 0, 0, 0, modes, NULL,
       NULL},
      {"--quick", NULL, CLI_FLAG, &quick, NULL, "reduced run", 0, 0, 0, NULL, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  char *argv[] = {"p",      "--alpha=0.25", "scene.json", "--steps", "12",     "-o",
                  "outdir", "--mode",       "mass",       "--quick", "second", NULL};
  int npos = 0;
  TEST_TRUE(cli_parse("p", opts, 11, argv, pos, 2, &npos) == CLI_OK);
  TEST_TRUE(alpha == 0.25 && seen_alpha && steps == 12 && quick == 1 && mode == 0);
  TEST_TRUE(out && !strcmp(out, "outdir") && npos == 2 && !strcmp(pos[0], "scene.json") &&
            !strcmp(pos[1], "second"));
  TEST_TRUE(cli_parse("p", opts, 11, argv, pos, 1, &npos) == CLI_ERROR); /* too many */
  struct {
    int argc;
    char *argv[4];
    cli_result want;
  } cases[] = {{2, {"p", "--help"}, CLI_HELP},
               {4, {"p", "--steps", "5", "-h"}, CLI_HELP},
               {2, {"p", "--bogus"}, CLI_ERROR},
               {2, {"p", "--steps"}, CLI_ERROR},        /* missing value */
               {3, {"p", "--alpha", "0"}, CLI_ERROR},   /* open end */
               {3, {"p", "--alpha", "nan"}, CLI_ERROR}, /* not finite */
               {3, {"p", "--steps", "2.5"}, CLI_ERROR}, /* not whole */
               {3, {"p", "--mode", "stiff"}, CLI_ERROR},
               {2, {"p", "--quick=1"}, CLI_ERROR}, /* a flag takes no value */
               {3, {"p", "-o", ""}, CLI_ERROR},    /* empty string */
               {2, {"p", "--alpha=1"}, CLI_OK}};
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++)
    if (cli_parse("p", opts, cases[k].argc, cases[k].argv, pos, 2, &npos) != cases[k].want)
      TEST_FAIL_("case %zu (%s): wrong result", k, cases[k].argv[1]);

  /* help: every option once, the help texts in one column */
  char path[4096], line[256];
  snprintf(path, sizeof path, "%s/cli-help.txt", work);
  FILE *f = fopen(path, "w+");
  TEST_TRUE(f != NULL);
  if (!f) return;
  cli_print_options(f, opts);
  rewind(f);
  int lines = 0, col = -1;
  while (fgets(line, sizeof line, f)) {
    lines++;
    const char *h = strstr(line, "weight");
    if (!h) h = strstr(line, "second line");
    if (!h) h = strstr(line, "reduced run");
    if (!h) h = strstr(line, "this text");
    if (h && col < 0) col = (int)(h - line);
    if (h) TEST_TRUE((int)(h - line) == col);
  }
  fclose(f);
  remove(path);
  TEST_TRUE(lines == 7 && col == (int)strlen("  -o, --output DIR  "));
}

static int help_calls;
static const cli_option *help_opts;
static void count_help(FILE *f, const cli_option *opts)
{
  (void)f;
  help_calls++;
  help_opts = opts;
}

/* cli_parse_args: the exit code after --help (0, the help printed once with the table) and
 * after a usage error (2), -1 when parsing went through. */
static void parse_args(void)
{
  int n = 0;
  const cli_option opts[] = {{"--n", NULL, CLI_INT, &n, "N", "count", 1, 9, 0, NULL, NULL, NULL},
                             {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  char *ok[] = {"p", "--n", "3", NULL}, *help[] = {"p", "--help", NULL},
       *bad[] = {"p", "--n", "0", NULL};
  TEST_TRUE(cli_parse_args("p", opts, 3, ok, NULL, 0, NULL, count_help) == -1 && n == 3);
  TEST_TRUE(help_calls == 0);
  TEST_TRUE(cli_parse_args("p", opts, 2, help, NULL, 0, NULL, count_help) == 0);
  TEST_TRUE(help_calls == 1 && help_opts == opts);
  TEST_TRUE(cli_parse_args("p", opts, 3, bad, NULL, 0, NULL, count_help) == 2 && help_calls == 1);
}

/* Number options with several values (one per metavar word) and element names. */
static void several_values(void)
{
  double box[6] = {0, 0, 0, 0, 0, 0};
  int cells[3] = {0, 0, 0}, seen_box = 0;
  fcm_element_type type = FCM_ELEMENT_COUNT;
  const cli_option opts[] = {
      {"--box", NULL, CLI_DOUBLE, box, "X0 Y0 Z0 X1 Y1 Z1", "corners", -10, 10, 0, NULL, NULL,
       &seen_box},
      {"--cells", NULL, CLI_INT, cells, "NX NY NZ", "cells", 1, 100, 0, NULL, NULL, NULL},
      {"--element", NULL, CLI_CUSTOM, &type, "E", "element", 0, 0, 0, NULL, cli_element, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  char *argv[] = {"p",       "--box", "-1", "-2", "-3",        "1",     "2", "3.5",
                  "--cells", "2",     "3",  "4",  "--element", "Hex20", NULL};
  TEST_TRUE(cli_parse("p", opts, 14, argv, NULL, 0, NULL) == CLI_OK);
  TEST_TRUE(seen_box && box[0] == -1 && box[1] == -2 && box[2] == -3 && box[3] == 1 &&
            box[4] == 2 && box[5] == 3.5);
  TEST_TRUE(cells[0] == 2 && cells[1] == 3 && cells[2] == 4 && type == FCM_ELEMENT_HEX20);
  struct {
    int argc;
    char *argv[5];
  } bad[] = {{4, {"p", "--cells", "2", "3"}},      /* one value missing */
             {5, {"p", "--cells", "2", "3", "0"}}, /* out of range */
             {5, {"p", "--cells", "2", "x", "4"}},
             {4, {"p", "--cells=2", "3", "4"}}, /* several values: no --name= */
             {3, {"p", "--element", "hex27"}}};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++)
    if (cli_parse("p", opts, bad[k].argc, bad[k].argv, NULL, 0, NULL) != CLI_ERROR)
      TEST_FAIL_("bad case %zu accepted", k);

  fcm_element_type list[FCM_ELEMENT_COUNT];
  int n = 0;
  TEST_TRUE(cli_element_list("p", "--e", "hex8,tet4", list, &n) && n == 2 &&
            list[0] == FCM_ELEMENT_HEX8 && list[1] == FCM_ELEMENT_TET4);
  const char *bad_list[] = {"hex8,hex8", "hex8,,tet4", "", "tet4,hex9"};
  for (size_t k = 0; k < sizeof bad_list / sizeof *bad_list; k++)
    if (cli_element_list("p", "--e", bad_list[k], list, &n) || n != 2)
      TEST_FAIL_("element list '%s' accepted", bad_list[k]);
}

static void output(const char *work)
{
  char dir[4096], path[4200];
  snprintf(dir, sizeof dir, "%s/cli-out", work);
  snprintf(path, sizeof path, "%s/table.csv", dir);
  remove(path);
  rmdir(dir);
  TEST_TRUE(mkdir(dir, 0777) == 0);
  cli_output *o = NULL;
  FILE *f = cli_output_open("p", path, &o);
  TEST_TRUE(f && o);
  if (!f) return;
  fprintf(f, "a,b\n1,2\n");
  TEST_TRUE(access(path, F_OK) != 0); /* nothing at the target before the commit */
  TEST_TRUE(cli_output_commit("p", &o) && !o);
  TEST_TRUE(file_is(path, "a,b\n1,2\n") && count_entries(dir) == 1);
  /* abort: the previous file stays, no temporary */
  f = cli_output_open("p", path, &o);
  TEST_TRUE(f != NULL);
  if (f) fprintf(f, "half");
  cli_output_abort(&o);
  TEST_TRUE(!o && file_is(path, "a,b\n1,2\n") && count_entries(dir) == 1);
  /* a write error on the stream (reading a write-only stream sets it) fails the commit */
  f = cli_output_open("p", path, &o);
  TEST_TRUE(f != NULL);
  if (f) {
    fprintf(f, "broken");
    (void)fgetc(f);
    TEST_TRUE(ferror(f));
  }
  TEST_TRUE(!cli_output_commit("p", &o) && !o);
  TEST_TRUE(file_is(path, "a,b\n1,2\n") && count_entries(dir) == 1);
  /* a missing directory */
  snprintf(path, sizeof path, "%s/no-such-dir/x.csv", dir);
  TEST_TRUE(cli_output_open("p", path, &o) == NULL && o == NULL);
  cli_output_abort(&o); /* harmless on NULL */
  snprintf(path, sizeof path, "%s/table.csv", dir);
  remove(path);
  rmdir(dir);
}

/* cli_make_dirs: missing parents are created, existing ones accepted; a file in the way, an
 * empty path and one too long are refused. */
static void make_dirs(const char *work)
{
  char top[4096], deep[4200], file[4200];
  snprintf(top, sizeof top, "%s/cli-dirs", work);
  snprintf(deep, sizeof deep, "%s/a/b", top);
  snprintf(file, sizeof file, "%s/f", top);
  remove(file);
  rmdir(deep);
  snprintf(file, sizeof file, "%s/a", top);
  rmdir(file);
  rmdir(top);
  TEST_TRUE(cli_make_dirs("p", deep));
  struct stat sb;
  TEST_TRUE(stat(deep, &sb) == 0 && S_ISDIR(sb.st_mode));
  TEST_TRUE(cli_make_dirs("p", deep)); /* already there */
  snprintf(file, sizeof file, "%s/f", top);
  FILE *f = fopen(file, "w");
  TEST_TRUE(f != NULL);
  if (f) fclose(f);
  snprintf(deep, sizeof deep, "%s/f/g", top);
  TEST_TRUE(!cli_make_dirs("p", deep));
  TEST_TRUE(!cli_make_dirs("p", ""));
  static char longpath[5000];
  memset(longpath, 'x', sizeof longpath - 1);
  TEST_TRUE(!cli_make_dirs("p", longpath));
  remove(file);
  snprintf(deep, sizeof deep, "%s/a/b", top);
  rmdir(deep);
  snprintf(file, sizeof file, "%s/a", top);
  rmdir(file);
  rmdir(top);
}

/* CSV fields: numbers at 6 digits, unmeasured ones (negative, NaN, infinite) empty; text with
 * its commas, double quotes and line breaks replaced, so a row keeps its columns. */
static void csv_fields(const char *work)
{
  char path[4096];
  snprintf(path, sizeof path, "%s/cli-csv.txt", work);
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (!f) return;
  fputs("a", f);
  cli_csv_number(f, 0.1234567);
  cli_csv_number(f, 0.0);
  cli_csv_number(f, -1.0);
  cli_csv_number(f, NAN);
  cli_csv_number(f, INFINITY);
  cli_csv_text(f, "x,\"y\"\nz");
  cli_csv_text(f, "");
  fclose(f);
  TEST_TRUE(file_is(path, "a,0.123457,0,,,,x;'y' z,"));
  remove(path);
}

int main(int argc, char **argv)
{
  if (argc != 2) return 2;
  /* the rejections print messages: stderr goes to a file, shown only if a check fails */
  char log[4096];
  snprintf(log, sizeof log, "%s/cli-stderr.txt", argv[1]);
  if (!freopen(log, "w+", stderr)) return 2;
  numbers();
  lists();
  table(argv[1]);
  several_values();
  parse_args();
  output(argv[1]);
  make_dirs(argv[1]);
  csv_fields(argv[1]);
  int rc = TEST_RESULT();
  if (rc != 0) {
    char line[512];
    rewind(stderr);
    while (fgets(line, sizeof line, stderr))
      fputs(line, stdout);
  }
  fclose(stderr);
  remove(log);
  return rc;
}
