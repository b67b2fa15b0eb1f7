/* fcm-sim with the geometry diagnostics: a body half outside the background runs (exit 0)
 * and prints a warning with the lost volume (half the body) and the side (+x); a body
 * wholly outside exits 2 naming the scene section and both bounding boxes, without a
 * traceback unless --debug; a malformed voxel image exits 2 naming geometry.voxels and the
 * file:line of the bad header field; a body smaller than min_fraction of every cell exits 2
 * saying so; --progress prints the cell-rule and level-set progress off a terminal and ends
 * at all cells and sub-cells. Guards: NaN voxels run with a warning and are counted in the
 * summary; a missing detached data file names the header that refers to it; a level-set
 * feature below the sampling spacing and a build above max_subcells are refused at once
 * (exit 2, naming the key, the value and the spacing, or the estimate, the limit and the
 * option); a surface vertex at 1e308 is refused as out of range; a cut surface of only
 * zero-area triangles is refused; a singular static system fails its step (exit 1) with the
 * message and its hint, the library's traceback only with --debug. The set-up's phases: with
 * --progress off a terminal an open surface closed by fill_holes prints a line per phase with
 * its time, in the set-up's order, the hole-filling warning between the reading and the
 * filling's end, a start line for the cell rules, and the phases' times add up to at most the
 * set-up's; without --progress no phase line but the warning still.
 * Usage: sim_geometry_app FCM_SIM WORKDIR */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "test.h"

#include "fcm/core.h"

#include <stdio.h>
#include <string.h>

static void write_file(const char *path, const char *text)
{
  FILE *f = fopen(path, "w");
  TEST_TRUE(f != NULL);
  if (f) fputs(text, f), fclose(f);
}

static int file_has(const char *path, const char *needle)
{
  static char buf[1 << 16];
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = '\0';
  return strstr(buf, needle) != NULL;
}

/* A 1 x 1 x 1 Hex8 grid of 2^3 cells, a geometry section and effects after gravity (the
 * bottom face held when `effects` is NULL). */
static void scene_with(const char *path, const char *geometry, const char *effects)
{
  char text[4096];
  snprintf(text, sizeof text,
           "{\"version\": 1, \"name\": \"geo\", \"output\": {\"directory\": \"geo-out\"},"
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           " \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"geometry\": %s,"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
           " \"time\": {\"static\": true, \"steps\": 1},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}}%s]}",
           geometry,
           effects ? effects
                   : ", {\"fixed\": {\"region\": {\"box\": {\"min\": [-1, -1, -1], "
                     "\"max\": [2, 2, 0]}}}}");
  write_file(path, text);
}

static void scene(const char *path, const char *geometry)
{
  scene_with(path, geometry, NULL);
}

/* The guards of the geometry inputs and of run-time failures. */
static void guards(const char *sim, const char *work, const char *path, const char *err,
                   const char *out)
{
  char cmd[8192], file[1024];
  /* NaN voxels: a warning with the count and the first one, and the summary counts them */
  snprintf(file, sizeof file, "%s/geo-nan.nrrd", work);
  write_file(file, "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nspacings: 0.25 0.25 0.25\n"
                   "space origin: (0.375,0.375,0.375)\nencoding: ascii\n\n1 1 nan 1 1 nan 1 1\n");
  scene(path, "{\"voxels\": \"geo-nan.nrrd\"}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > '%s'", sim, path, err, out);
  TEST_TRUE(app_run(cmd) == 0);
  TEST_TRUE(file_has(err, "fcm-sim: warning: voxels: 2 of 8 voxel values are NaN and count as "
                          "outside the body (never selected); the first is voxel (0, 1, 0)"));
  TEST_TRUE(file_has(out, "6 of 2 x 2 x 2 selected") &&
            file_has(out, "; 2 NaN values counted as outside"));

  /* a detached data file that is missing: the header and its line are named with it */
  snprintf(file, sizeof file, "%s/geo-detached.nhdr", work);
  write_file(file, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
                   "data file: geo-missing.raw\n");
  scene(path, "{\"voxels\": \"geo-detached.nhdr\"}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "geo-detached.nhdr:6: data file: cannot open '") &&
            file_has(err, "/geo-missing.raw': No such file"));

  /* a gyroid period of 1e-9 at refinement 64: refused when the scene is read, at once */
  scene(path, "{\"level_set\": {\"gyroid\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1], "
              "\"period\": 1e-9, \"type\": \"solid\"}}, \"refinement\": 64}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  const double t0 = fcm_wtime();
  TEST_TRUE(app_run(cmd) == 2);
  const double took = fcm_wtime() - t0;
  TEST_TRUE(took < 5.0); /* refused before anything is sampled */
  TEST_TRUE(file_has(err, "geometry.level_set.gyroid.period: period = 1e-09 is below twice the "
                          "sampling spacing h = 0.0078125"));
  /* more sub-cells than max_subcells: the estimate, the limit and the option */
  scene(path, "{\"level_set\": {\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.4}}, "
              "\"max_subcells\": 10}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "geometry.level_set: level set: the build would triangulate ") &&
            file_has(err, "more than max_subcells = 10 (") && file_has(err, "raise max_subcells"));

  /* a vertex at 1e308: out of range, naming the file, the vertex and the value */
  snprintf(file, sizeof file, "%s/geo-far.obj", work);
  write_file(file, "v 0 0 0\nv 1e308 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  scene(path, "{\"surface\": \"geo-far.obj\"}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "geo-far.obj: vertex 2 (1-based, as the file's faces number them): "
                          "coordinate x = 1e+308 is outside the supported range"));
  TEST_TRUE(!file_has(err, "degenerate"));

  /* a cut surface of zero-area triangles cuts nothing: refused before the run */
  snprintf(file, sizeof file, "%s/geo-flat.obj", work);
  write_file(file, "v 0 0.5 0\nv 0.5 0.5 0\nv 1 0.5 0\nf 1 2 3\n");
  scene_with(
      path, "{\"shape\": \"box\", \"min\": [0.1, 0.1, 0.1], \"max\": [0.9, 0.9, 0.9]}",
      ", {\"fixed\": {\"region\": {\"box\": {\"min\": [-1, -1, -1], \"max\": [2, 2, 0.2]}}}},"
      " {\"cut\": {\"surface\": {\"mesh\": \"geo-flat.obj\"}}}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "effects[2].cut.surface.mesh") &&
            file_has(err, "all 1 triangle(s) of the cut surface have zero area"));

  /* a singular static system (nothing held): the step fails with the message and its hint;
   * the traceback of the library's frames only with --debug */
  scene_with(path, "{\"shape\": \"box\", \"min\": [0.1, 0.1, 0.1], \"max\": [0.9, 0.9, 0.9]}", "");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 1);
  TEST_TRUE(file_has(err, "singular") && file_has(err, "rigid"));
  TEST_TRUE(file_has(err, "fcm-sim: --debug shows where in the library it failed"));
  TEST_TRUE(!file_has(err, ".c:") && !file_has(err, "fcm error:"));
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check --debug 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 1);
  TEST_TRUE(file_has(err, "fcm error: ") && file_has(err, "  [0] ") && file_has(err, ".c:"));
}

/* The seconds of the first phase-end line "fcm-sim: <what>: <seconds> s" of `text` that
 * starts with `what` (-1: none; a start line "...: running" is passed over), and where it is
 * (*at). */
static double phase_seconds(const char *text, const char *what, const char **at)
{
  char key[256];
  snprintf(key, sizeof key, "\nfcm-sim: %s", what);
  for (const char *p = strstr(text, key); p; p = strstr(p + 1, key)) {
    const char *end = strchr(p + 1, '\n');
    const char *colon = NULL;
    for (const char *q = p + 1; end && q < end; q++)
      if (q[0] == ':' && q[1] == ' ') colon = q; /* the last ": " of the line */
    double s = -1.0;
    if (colon && sscanf(colon + 2, "%lf s", &s) == 1) {
      *at = p;
      return s;
    }
  }
  *at = NULL;
  return -1.0;
}

/* --progress off a terminal: the set-up's phases of an open surface closed by fill_holes. */
static void setup_phases(const char *sim, const char *work, const char *path, const char *err,
                         const char *out)
{
  static char text[1 << 16];
  char cmd[8192], file[1024];
  /* [0.2, 0.8]^3 without its top face */
  snprintf(file, sizeof file, "%s/geo-open.obj", work);
  write_file(file, "v 0.2 0.2 0.2\nv 0.8 0.2 0.2\nv 0.8 0.8 0.2\nv 0.2 0.8 0.2\n"
                   "v 0.2 0.2 0.8\nv 0.8 0.2 0.8\nv 0.8 0.8 0.8\nv 0.2 0.8 0.8\n"
                   "f 1 3 2\nf 1 4 3\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
                   "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  scene(path, "{\"surface\": \"geo-open.obj\", \"fill_holes\": true}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check --progress 2> '%s' > '%s'", sim, path, err, out);
  TEST_TRUE(app_run(cmd) == 0);
  FILE *f = fopen(err, "r");
  size_t n = f ? fread(text + 1, 1, sizeof text - 2, f) : 0;
  if (f) fclose(f);
  text[0] = '\n'; /* every line starts after a newline */
  text[n + 1] = '\0';
  /* the phases in order, each with its time */
  static const char *const phases[] = {"building the background grid (2 x 2 x 2 cells): ",
                                       "reading the surface geo-open.obj: ",
                                       "filling the surface's holes: ",
                                       "checking the surface",
                                       "building the geometry of 12 surface triangles: ",
                                       "classifying 8 cells and building the cut cells' rules: ",
                                       "building the space",
                                       "setting up the integrator (factorization): ",
                                       "locating the output surface's 12 triangles"};
  const int np = (int)(sizeof phases / sizeof phases[0]);
  const char *prev = text, *at = NULL;
  double sum = 0.0;
  for (int k = 0; k < np; k++) {
    const double s = phase_seconds(prev, phases[k], &at);
    TEST_TRUE(at != NULL && s >= 0.0);
    if (!at) {
      fprintf(stderr, "phase line '%s' missing after:\n%s\n", phases[k], prev);
      break;
    }
    sum += s;
    prev = at;
  }
  /* the times printed (two decimals) add up to at most the set-up's */
  double setup = -1.0;
  const char *total = strstr(text, "\nfcm-sim: set-up: ");
  TEST_TRUE(total && sscanf(total, "\nfcm-sim: set-up: %lf s", &setup) == 1);
  TEST_TRUE(setup >= 0.0 && sum <= setup + 0.005 * np);
  TEST_TRUE(total && at && total > at);
  /* the warning, while the holes were filled */
  const char *warn = strstr(text, "\nfcm-sim: warning: scene geo: geometry.surface ");
  const char *read = strstr(text, "\nfcm-sim: reading the surface");
  const char *fill = strstr(text, "\nfcm-sim: filling the surface's holes: ");
  TEST_TRUE(warn &&
            strstr(warn, "fill_holes closed 1 of 1 hole(s) (edges: 4), adding 2 triangles"));
  TEST_TRUE(warn && read && fill && read < warn && warn < fill);
  /* the cell rules, long: a start line, then the progress, then the end */
  const char *start = strstr(text, "\nfcm-sim: classifying 8 cells and building the cut cells' "
                                   "rules: running\n");
  const char *bar = strstr(text, "\nfcm-sim: cell rules 8/8 cells");
  const char *end = strstr(text, "\nfcm-sim: classifying 8 cells and building the cut cells' "
                                 "rules: 0.");
  TEST_TRUE(start && bar && end && start < bar && bar < end);
  /* the summary splits the set-up's parts into phases */
  TEST_TRUE(file_has(out, "            [s] mesh and geometry: reading ") &&
            file_has(out, ", filling holes ") && file_has(out, "[s] cell rules: "));

  /* without --progress off a terminal: the warning, no phase line */
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 0);
  TEST_TRUE(file_has(err, "fcm-sim: warning: scene geo: geometry.surface "));
  TEST_TRUE(!file_has(err, "fcm-sim: reading the surface") && !file_has(err, "fcm-sim: set-up:"));
}

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  const char *sim = argv[1], *work = argv[2];
  char path[1024], err[1024], cmd[8192];
  snprintf(path, sizeof path, "%s/geo.json", work);
  snprintf(err, sizeof err, "%s/geo-stderr.txt", work);

  /* half outside beyond +x: [0.5, 1.5] x [0, 1] x [0, 1] */
  char out[1024];
  snprintf(out, sizeof out, "%s/geo-stdout.txt", work);
  scene(path, "{\"shape\": \"box\", \"min\": [0.5, 0, 0], \"max\": [1.5, 1, 1]}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > '%s'", sim, path, err, out);
  TEST_TRUE(app_run(cmd) == 0);
  TEST_TRUE(file_has(out, "outside the background 0.5,"));
  TEST_TRUE(file_has(out, "; beyond +x 0.5\n"));
  TEST_TRUE(file_has(err, "fcm-sim: warning: 0.5 m^3 of the body (50% of 1 m^3) lies outside"));
  TEST_TRUE(file_has(err, "(beyond +x: 0.5 m^3)"));

  /* wholly outside: exit 2, the section and both boxes, no traceback */
  scene(path, "{\"shape\": \"box\", \"min\": [2, 0, 0], \"max\": [3, 1, 1]}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "geometry: embed: the geometry (volume 1) lies wholly outside the "
                          "background mesh: geometry bounding box [2, 3] x [0, 1] x [0, 1], "
                          "background mesh bounding box [0, 1] x [0, 1] x [0, 1]"));
  TEST_TRUE(!file_has(err, "cell_rules.c"));
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check --debug 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "wholly outside") && file_has(err, "cell_rules.c"));

  /* a body too small for every cell: the message says so instead of "no active cell" */
  scene(path, "{\"shape\": \"box\", \"min\": [0.4, 0.4, 0.4], \"max\": [0.401, 0.401, 0.401]}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "geometry: every one of the 8 background cells holds less than "
                          "quadrature.min_fraction = 0.0001"));

  /* a voxel image with a bad header line */
  char img[1024];
  snprintf(img, sizeof img, "%s/geo-bad.nrrd", work);
  write_file(img, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 x\n");
  scene(path, "{\"voxels\": \"geo-bad.nrrd\"}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check 2> '%s' > /dev/null", sim, path, err);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(file_has(err, "geometry.voxels: ") && file_has(err, "geo-bad.nrrd:4: sizes: '2 2 x'"));

  /* --progress off a terminal: lines, the last one at all 8 cells */
  scene(path, "{\"level_set\": {\"sphere\": {\"center\": [0.5, 0.5, 0.5], \"radius\": 0.4}}}");
  snprintf(cmd, sizeof cmd, "'%s' '%s' --check --progress 2> '%s' > '%s'", sim, path, err, out);
  TEST_TRUE(app_run(cmd) == 0);
  TEST_TRUE(file_has(err, "fcm-sim: cell rules 8/8 cells"));
  /* 8 cut cells of 4^3 sub-cells, and 8^3 each in the error estimate */
  TEST_TRUE(file_has(err, "fcm-sim: level set 4608/4608 sub-cells"));
  TEST_TRUE(!app_has_warning(err));
  /* the summary: what the level set built, the cut-cell statistics and the volumes */
  TEST_TRUE(file_has(out, "geometry  level set: ") && file_has(out, "estimated error"));
  TEST_TRUE(file_has(out, "cells     8: 0 uncut, 8 cut, 0 dropped; cut-cell points stiffness"));
  TEST_TRUE(file_has(out, "(ratio 1.000000), outside the background 0"));

  guards(sim, work, path, err, out);
  setup_phases(sim, work, path, err, out);
  return TEST_RESULT();
}
