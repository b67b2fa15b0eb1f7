/* fcm-sim with the geometry diagnostics: a body half outside the background runs (exit 0)
 * and prints a warning with the lost volume (half the body) and the side (+x); a body
 * wholly outside exits 2 naming the scene section and both bounding boxes, without a
 * traceback unless --debug; a malformed voxel image exits 2 naming geometry.voxels and the
 * file:line of the bad header field; a body smaller than min_fraction of every cell exits 2
 * saying so; --progress prints the cell-rule progress off a
 * terminal and ends at all cells. Usage: sim_geometry_app FCM_SIM WORKDIR */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "test.h"

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

/* A 1 x 1 x 1 Hex8 grid of 2^3 cells and a geometry section. */
static void scene(const char *path, const char *geometry)
{
  char text[4096];
  snprintf(text, sizeof text,
           "{\"version\": 1, \"name\": \"geo\", \"output\": {\"directory\": \"geo-out\"},"
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           " \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"geometry\": %s,"
           " \"material\": {\"model\": \"linear\", \"young\": 1e6, \"poisson\": 0.3},"
           " \"time\": {\"static\": true, \"steps\": 1},"
           " \"effects\": [{\"gravity\": {\"acceleration\": [0, 0, -9.81]}},"
           " {\"fixed\": {\"region\": {\"box\": {\"min\": [-1, -1, -1], \"max\": [2, 2, 0]}}}}]}",
           geometry);
  write_file(path, text);
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
  TEST_TRUE(!file_has(err, "warning"));
  /* the summary: what the level set built, the cut-cell statistics and the volumes */
  TEST_TRUE(file_has(out, "geometry  level set: ") && file_has(out, "estimated error"));
  TEST_TRUE(file_has(out, "cells     8: 0 uncut, 8 cut, 0 dropped; cut-cell points stiffness"));
  TEST_TRUE(file_has(out, "(ratio 1.000000), outside the background 0"));
  return TEST_RESULT();
}
