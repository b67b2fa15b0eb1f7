/* fcm-sim --plot end to end. Modes:
 *   sim_plot_app plot FCM_SIM WORK_DIR       a short scene (gravity, one fixed effect) with
 *                                            --plot: the log, the script <name>_log.gp whose
 *                                            data block has one row per log row (the time
 *                                            column the log's), and, with gnuplot
 *                                            installed, <name>_log.png: a PNG of the stated
 *                                            1200 x 900 pixels (four panels), named on the
 *                                            summary's output line
 *   sim_plot_app no-gnuplot FCM_SIM WORK_DIR the same run with a PATH that holds no gnuplot:
 *                                            exit 0, the log and the script written, no PNG,
 *                                            and stderr says gnuplot was not found */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "test.h"

static const char plot_scene[] =
    "{\"version\": 1, \"name\": \"plotted\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1.5, 0.5, "
    "0.5]}, \"cells\": [3, 1, 1]},"
    " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1.2, 0.5, 0.5],"
    "   \"cells\": [3, 1, 1]},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.01, \"steps\": 7},"
    " \"output\": {\"directory\": \"unused-by-test\", \"frame_interval\": 7},"
    " \"effects\": [{\"gravity\": {}},"
    "  {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0], \"normal\": [-1, 0, "
    "0]}}}}]}";

/* The times of the log's rows (after its header) into t; their count. */
static int log_times(const char *path, double *t, int cap)
{
  char line[8192], buf[64];
  int n = 0;
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  if (!fgets(line, sizeof line, f)) n = -1;
  while (n >= 0 && fgets(line, sizeof line, f))
    if (n < cap) {
      field(line, 1, buf, sizeof buf); /* step,time,... */
      t[n++] = strtod(buf, NULL);
    } else {
      n++;
    }
  fclose(f);
  return n;
}

/* The rows of the data block $LOG of the script (comment lines aside): their first column into
 * t, their count; -1 without the block. */
static int script_times(const char *path, double *t, int cap)
{
  char line[8192];
  int n = -1;
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  while (fgets(line, sizeof line, f)) {
    if (n < 0) {
      if (!strncmp(line, "$LOG << EOD", 11)) n = 0;
      continue;
    }
    if (!strncmp(line, "EOD", 3)) break;
    if (line[0] == '#') continue;
    if (n < cap) t[n] = strtod(line, NULL);
    n++;
  }
  fclose(f);
  return n;
}

static int run(const char *sim, const char *work, const char *tag, const char *env)
{
  char cmd[8192], scene[1024], dir[1024], err[1100], logpath[1200], gp[1200], png[1200];
  snprintf(scene, sizeof scene, "%s/plotted.json", work);
  snprintf(dir, sizeof dir, "%s/plot-%s", work, tag);
  snprintf(err, sizeof err, "%s/plot-%s.err", work, tag);
  snprintf(logpath, sizeof logpath, "%s/plotted_log.csv", dir);
  snprintf(gp, sizeof gp, "%s/plotted_log.gp", dir);
  snprintf(png, sizeof png, "%s/plotted_log.png", dir);
  FILE *f = fopen(scene, "w");
  TEST_TRUE(f != NULL);
  if (!f) return TEST_RESULT();
  fputs(plot_scene, f);
  fclose(f);
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && %s '%s' '%s' -o '%s' --plot > '%s.out' 2> '%s'", dir,
           env, sim, scene, dir, err, err);
  TEST_TRUE(app_run(cmd) == 0);
  double tl[64], ts[64];
  const int nl = log_times(logpath, tl, 64), ns = script_times(gp, ts, 64);
  TEST_TRUE(nl == 7);
  TEST_TRUE(ns == nl);
  for (int k = 0; k < nl && k < ns && k < 64; k++)
    TEST_TRUE(ts[k] == tl[k]); /* the log's text, copied */
  const int have_gnuplot = !*env && app_run("gnuplot --version > /dev/null 2>&1") == 0;
  if (have_gnuplot) {
    unsigned long w = 0, h = 0;
    TEST_TRUE(app_png_size(png, &w, &h));
    TEST_TRUE(w == 1200 && h == 900);
    /* the summary's output line names the picture */
    char out[1200], line[4096];
    int named = 0;
    snprintf(out, sizeof out, "%s.out", err);
    f = fopen(out, "r");
    while (f && fgets(line, sizeof line, f))
      named |= !strncmp(line, "  output", 8) && strstr(line, "plotted_log.png") != NULL;
    if (f) fclose(f);
    TEST_TRUE(named);
  } else {
    TEST_TRUE(!app_exists(png));
    f = fopen(err, "r");
    char line[4096];
    int said = 0;
    while (f && fgets(line, sizeof line, f))
      said |= strstr(line, "gnuplot not found") != NULL;
    if (f) fclose(f);
    TEST_TRUE(said);
  }
  return TEST_RESULT();
}

int main(int argc, char **argv)
{
  if (argc != 4) {
    fprintf(stderr, "usage: sim_plot_app plot|no-gnuplot FCM_SIM WORK_DIR\n");
    return 2;
  }
  if (!strcmp(argv[1], "plot")) return run(argv[2], argv[3], "plot", "");
  if (!strcmp(argv[1], "no-gnuplot"))
    return run(argv[2], argv[3], "nognuplot", "PATH=/nonexistent");
  fprintf(stderr, "sim_plot_app: unknown mode %s\n", argv[1]);
  return 2;
}
