/* fcm-quadrature export end to end: the file of a box body cut by a plane (an OBJ) holds
 * every cell's pieces, their physical weights add up to the body's volume and split it at the
 * cut; bad arguments (a missing option, an unknown shape, an output directory that does not
 * exist, an unreadable cut) exit with status 2, say why and write nothing.
 * Usage: app_export PATH_TO_fcm-quadrature WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "rules_file.h"
#include "test.h"

#include <dirent.h>

#define BOX   "--element hex8 --box 0 0 0 3 3 3 --cells 3 3 3 --strength 3"
#define SHAPE "box:0.4,0.2,0.5,2.3,2.6,2.45,2"

/* Entries of `dir` whose name starts with `prefix` (the output and its temporaries). */
static int count_named(const char *dir, const char *prefix)
{
  int n = 0;
  DIR *d = opendir(dir);
  for (struct dirent *e; d && (e = readdir(d));)
    n += strstr(e->d_name, prefix) != NULL;
  if (d) closedir(d);
  return n;
}

/* `args` with OUT replaced by `out` and WORK by `work`, into buf. */
static void expand(const char *args, const char *out, const char *work, char *buf, size_t cap)
{
  size_t n = 0;
  for (const char *s = args; *s && n + 1 < cap;) {
    const char *with = !strncmp(s, "OUT", 3) ? out : !strncmp(s, "WORK", 4) ? work : NULL;
    if (with) {
      n += (size_t)snprintf(buf + n, cap - n, "%s", with);
      s += with == out ? 3 : 4;
    } else {
      buf[n++] = *s++;
    }
    if (n >= cap) n = cap - 1;
  }
  buf[n] = 0;
}

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  char cmd[16384], out[4096], obj[4096], err[4096];
  snprintf(out, sizeof out, "%s/export_cut.fcmr", argv[2]);
  snprintf(obj, sizeof obj, "%s/export_cut.obj", argv[2]);
  snprintf(err, sizeof err, "%s/export_err.txt", argv[2]);
  remove(out);
  FILE *f = fopen(obj, "w");
  TEST_TRUE(f != NULL);
  if (!f) return TEST_RESULT();
  fprintf(f, "v 1.3 -1 -1\nv 1.3 4 -1\nv 1.3 4 4\nv 1.3 -1 4\nf 1 2 3\nf 1 3 4\n");
  fclose(f);

  snprintf(cmd, sizeof cmd,
           "'%s' export " BOX " --geometry " SHAPE " --cut '%s' -o '%s' >/dev/null", argv[1], obj,
           out);
  TEST_TRUE(app_run(cmd) == 0);
  rf_file rf;
  TEST_TRUE(rf_load(out, &rf));
  if (rf.header) {
    long long np, n;
    int cols;
    const int64_t *off = rf_array(&rf, "stiffness/piece_offsets", &np, &cols);
    const double *x = rf_array(&rf, "stiffness/points_phys", &n, &cols);
    const double *w = rf_array(&rf, "stiffness/weights_phys", &n, &cols);
    const uint8_t *fl = rf_array(&rf, "stiffness/flags", &n, &cols);
    TEST_TRUE(off && x && w && fl && rf_number_after(rf.header, "\"num_cuts\": ") == 1);
    double left = 0.0, right = 0.0;
    int mixed = 0;
    for (long long p = 0; off && x && w && fl && p + 1 < np; p++) {
      double vl = 0.0, vr = 0.0;
      for (int64_t j = off[p]; j < off[p + 1]; j++)
        if (!fl[j]) *(x[3 * j] < 1.3 ? &vl : &vr) += w[j];
      mixed += vl > 0 && vr > 0; /* a piece on both sides of the cut */
      left += vl;
      right += vr;
    }
    TEST_TRUE(mixed == 0);
    const double yz = 2.4 * 1.95; /* the body's cross-section */
    TEST_NEAR(left, 0.9 * yz, 1e-12, 0);
    TEST_NEAR(right, 1.0 * yz, 1e-12, 0);
    rf_free(&rf);
  }

  /* refused: exit 2, a message naming the problem, no output and no temporary */
  const char *bad[][2] = {
      {"--geometry " SHAPE, "--element is required"},
      {BOX " --geometry " SHAPE, "--output is required"},
      {BOX " --geometry nosuch:1,2 -o OUT", "--geometry 'nosuch:1,2'"},
      {BOX " --geometry " SHAPE " -o WORK/none/x.fcmr", "not a file in an existing directory"},
      {BOX " --geometry " SHAPE " --cut WORK/none.obj -o OUT", "--cut"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char expanded[8192];
    expand(bad[i][0], out, argv[2], expanded, sizeof expanded);
    remove(out);
    snprintf(cmd, sizeof cmd, "'%s' export %s >/dev/null 2>'%s'", argv[1], expanded, err);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(!app_exists(out) && count_named(argv[2], "export_cut.fcmr") == 0);
    char text[4096] = "";
    f = fopen(err, "r");
    if (f) {
      text[fread(text, 1, sizeof text - 1, f)] = 0;
      fclose(f);
    }
    if (!strstr(text, bad[i][1])) TEST_FAIL_("case %zu: \"%s\" lacks \"%s\"", i, text, bad[i][1]);
  }
  return TEST_RESULT();
}
