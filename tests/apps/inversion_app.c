/* fcm-sim and inverted elements: a soft embedded block, held at its base, whose top is driven
 * down at 1.3 m/s through the held base (static, 4 steps of 0.25 s: the top passes the base at
 * t = 0.77 s). With the default "on_inversion": "warn" the run ends (exit 0); the log's
 * inverted_points column is 0 after the first step (30 % compression) and not after the last
 * (the top lies 0.3 m below the base), nonfinite_stresses is positive in a frame after an
 * inverted step; stderr warns once, on the first inverted step, with the count the log holds,
 * and once on the first frame with NaN stresses; the summary gives the inverted steps, the
 * first and the worst as the log has them. With "stop" the run exits 1 at that first inverted
 * step, naming the step, the time, the count and the first point; the frames before it exist
 * and the output directory's files are whole (PVD, VTU, log). A gentle push (0.2 m/s) reports
 * zero everywhere and warns of nothing. Usage: inversion_app FCM_SIM WORKDIR */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "output_check.h"
#include "app_run.h"
#include "test.h"

#include <stdio.h>
#include <string.h>

static char *slurp(const char *path)
{
  FILE *f = fopen(path, "r");
  if (!f) return NULL;
  char *buf = calloc(1 << 20, 1);
  if (buf) buf[fread(buf, 1, (1 << 20) - 1, f)] = '\0';
  fclose(f);
  return buf;
}

static int file_has(const char *path, const char *needle)
{
  char *t = slurp(path);
  const int has = t && strstr(t, needle) != NULL;
  free(t);
  return has;
}

/* Occurrences of needle in the file. */
static int file_count(const char *path, const char *needle)
{
  char *t = slurp(path);
  int n = 0;
  for (const char *p = t; p && (p = strstr(p, needle)) != NULL; p += strlen(needle))
    n++;
  free(t);
  return n;
}

static void write_scene(const char *path, const char *dir, double speed, const char *solver)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (!f) return;
  fprintf(f,
          "{\"version\": 1, \"name\": \"squash\", \"output\": {\"directory\": \"%s\"},"
          " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
          " \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
          " \"geometry\": {\"shape\": \"box\", \"min\": [0.1, 0.1, 0], \"max\": [0.9, 0.9, 1]},"
          " \"material\": {\"model\": \"snh\", \"young\": 1e4, \"poisson\": 0.3},"
          " %s \"time\": {\"static\": true, \"dt\": 0.25, \"steps\": 4},"
          " \"effects\": ["
          "  {\"fixed\": {\"region\": {\"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 0]}}}},"
          "  {\"motion\": {\"region\": {\"box\": {\"min\": [0, 0, 1], \"max\": [1, 1, 1]}},"
          "   \"velocity\": [0, 0, %g]}}]}",
          dir, solver, -speed);
  fclose(f);
}

/* The log's rows: inverted_points and nonfinite_stresses (NaN: no frame) per step. */
typedef struct log_rows {
  int n;
  double time[16], inverted[16], nonfinite[16];
} log_rows;

static void read_log(const char *path, log_rows *L)
{
  char line[4096];
  int col_inv = -1, col_nan = -1;
  L->n = 0;
  FILE *f = fopen(path, "r");
  TEST_TRUE(f != NULL);
  if (!f) return;
  if (fgets(line, sizeof line, f)) {
    int c = 0;
    for (char *tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), c++) {
      if (!strcmp(tok, "inverted_points")) col_inv = c;
      if (!strcmp(tok, "nonfinite_stresses")) col_nan = c;
    }
  }
  TEST_TRUE(col_inv > 0 && col_nan == col_inv + 1);
  while (L->n < 16 && col_inv > 0 && fgets(line, sizeof line, f)) {
    int c = 0;
    for (char *tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), c++) {
      char *end;
      const double v = strtod(tok, &end);
      TEST_TRUE(end != tok && *end == '\0'); /* every field a number ("nan" included) */
      if (c == 1) L->time[L->n] = v;
      if (c == col_inv) L->inverted[L->n] = v;
      if (c == col_nan) L->nonfinite[L->n] = v;
    }
    /* then the Newton tolerance, the energies (kinetic, elastic, load work) and the wall time */
    TEST_TRUE(c == col_nan + 6);
    L->n++;
  }
  fclose(f);
}

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  const char *sim = argv[1], *work = argv[2];
  char scene[1024], dir[512], err[1024], out[1024], cmd[8192], path[2048], text[1024];
  snprintf(scene, sizeof scene, "%s/squash.json", work);
  snprintf(err, sizeof err, "%s/squash-stderr.txt", work);
  snprintf(out, sizeof out, "%s/squash-stdout.txt", work);

  /* warn (the default): the run goes on to the end */
  snprintf(dir, sizeof dir, "%s/squash-warn", work);
  write_scene(scene, dir, 1.3, "");
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && '%s' '%s' 2> '%s' > '%s'", dir, sim, scene, err, out);
  TEST_TRUE(app_run(cmd) == 0);
  log_rows L;
  snprintf(path, sizeof path, "%s/squash_log.csv", dir);
  read_log(path, &L);
  TEST_TRUE(L.n == 4);
  if (L.n == 4) {
    int first = -1, steps = 0, worst = 0, frames_nan = 0;
    for (int k = 0; k < 4; k++) {
      if (L.inverted[k] > 0 && first < 0) first = k;
      steps += L.inverted[k] > 0;
      if (L.inverted[k] > L.inverted[worst]) worst = k;
      TEST_TRUE(L.nonfinite[k] >= 0); /* a frame after every step */
      frames_nan += L.nonfinite[k] > 0;
    }
    TEST_TRUE(L.inverted[0] == 0 && L.inverted[3] > 0 && first > 0);
    TEST_TRUE(frames_nan > 0 && L.nonfinite[0] == 0);
    TEST_TRUE(file_count(err, "inverted quadrature point") == 1);
    snprintf(text, sizeof text,
             "fcm-sim: warning: step %d (t = %g s) ended with %.0f inverted quadrature point",
             first + 1, L.time[first], L.inverted[first]);
    TEST_TRUE(file_has(err, text));
    TEST_TRUE(file_has(err, ", the first in cell "));
    TEST_TRUE(file_count(err, "NaN or infinite von Mises") == 1);
    snprintf(text, sizeof text,
             "  inversion WARNING: %d of 4 steps ended with inverted quadrature points (J = det F "
             "<= 0): first step %d (t = %g s, cell ",
             steps, first + 1, L.time[first]);
    TEST_TRUE(file_has(out, text));
    snprintf(text, sizeof text, "most %.0f points (step %d)\n", L.inverted[worst], worst + 1);
    TEST_TRUE(file_has(out, text));
    snprintf(text, sizeof text, "  stresses  WARNING: %d of 5 frames hold NaN", frames_nan);
    TEST_TRUE(file_has(out, text));

    /* stop: exit 1 at that step, its frame not written, the files before it whole */
    snprintf(dir, sizeof dir, "%s/squash-stop", work);
    write_scene(scene, dir, 1.3, "\"solver\": {\"on_inversion\": \"stop\"},");
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && '%s' '%s' 2> '%s' > '%s'", dir, sim, scene, err, out);
    TEST_TRUE(app_run(cmd) == 1);
    snprintf(text, sizeof text,
             "simulation squash: step %d (t = %g s) ended with %.0f inverted quadrature points "
             "(J = det F <= 0), the first in cell ",
             first + 1, L.time[first], L.inverted[first]);
    TEST_TRUE(file_has(err, text));
    TEST_TRUE(file_has(err, "stopped because solver.on_inversion is \"stop\""));
    log_rows S;
    snprintf(path, sizeof path, "%s/squash_log.csv", dir);
    read_log(path, &S);
    TEST_TRUE(S.n == first + 1 && S.n > 0 && S.inverted[S.n - 1] == L.inverted[first]);
    for (int k = 0; k <= first + 1; k++) { /* frames 0 .. first (the states before the stop) */
      snprintf(path, sizeof path, "%s/squash_background_%04d.vtu", dir, k);
      TEST_TRUE(app_exists(path) == (k <= first));
      snprintf(path, sizeof path, "%s/squash_surface_%04d.vtu", dir, k);
      TEST_TRUE(app_exists(path) == (k <= first));
    }
    fcm_ctx *ctx = NULL;
    fcm_scene *sc = NULL;
    TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
    TEST_OK(ctx, fcm_scene_create_from_file(ctx, scene, &sc));
    if (sc) {
      oc_counts oc = oc_check_dir(dir, ctx, sc);
      TEST_TRUE(oc.bad == 0 && oc.vtu == 2 * (first + 1) && oc.pvd == 2 && oc.csv == 1);
      if (oc.bad) fprintf(stderr, "%s\n", oc.first_error);
    }
    fcm_scene_destroy(&sc);
    fcm_ctx_destroy(&ctx);
  }

  /* a gentle push: nothing inverts, nothing is NaN, no warning */
  snprintf(dir, sizeof dir, "%s/squash-gentle", work);
  write_scene(scene, dir, 0.2, "\"solver\": {\"on_inversion\": \"stop\"},");
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && '%s' '%s' 2> '%s' > '%s'", dir, sim, scene, err, out);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(path, sizeof path, "%s/squash_log.csv", dir);
  read_log(path, &L);
  TEST_TRUE(L.n == 4);
  for (int k = 0; k < L.n; k++)
    TEST_TRUE(L.inverted[k] == 0 && L.nonfinite[k] == 0);
  TEST_TRUE(!app_has_warning(err));
  TEST_TRUE(file_has(out, "  inversion none: no quadrature point with J = det F <= 0 after any "
                          "of the 4 steps\n"));
  TEST_TRUE(file_has(out, "  stresses  finite in every frame written (5)\n"));
  return TEST_RESULT();
}
