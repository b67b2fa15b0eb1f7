/* fcm-quadrature end to end: `accuracy` writes the documented CSV with errors
 * <= 1e-12 and simplified counts <= M for every strength; `embed --dump` writes
 * one line per point whose physical weights add up to the embedded volume, for a
 * procedural ball and for an open cube surface (OFF) tetrahedralized with --fill-holes;
 * bad options and an open surface without --fill-holes exit with status 2 and write nothing.
 * Usage: app_quadrature PATH_TO_fcm-quadrature WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "test.h"

#include "app_run.h"

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  char cmd[16384], csv[4096], dump[4096];
  snprintf(csv, sizeof csv, "%s/accuracy.csv", argv[2]);
  snprintf(dump, sizeof dump, "%s/points.txt", argv[2]);
  remove(csv);
  remove(dump);

  /* accuracy: the paper's Fig. 4 experiment up to strength 6 */
  snprintf(cmd, sizeof cmd, "'%s' accuracy --max-strength 6 --csv '%s' > /dev/null", argv[1], csv);
  TEST_TRUE(app_run(cmd) == 0);
  FILE *f = fopen(csv, "r");
  TEST_TRUE(f != NULL);
  if (f) {
    char line[512];
    TEST_TRUE(fgets(line, sizeof line, f) &&
              !strcmp(line, "strength,rule,points,max_rel_error,median_rel_error\n"));
    int rows = 0, m, points;
    char rule[32];
    double mx, med;
    while (fscanf(f, "%d,%31[a-z],%d,%lf,%lf\n", &m, rule, &points, &mx, &med) == 5) {
      int M = (m + 1) * (m + 2) * (m + 3) / 6;
      TEST_TRUE(mx <= 1e-12 && med <= mx);
      if (!strcmp(rule, "simplified"))
        TEST_TRUE(points <= M);
      else
        TEST_TRUE(!strcmp(rule, "initial") && points > M);
      rows++;
    }
    TEST_TRUE(rows == 12);
    fclose(f);
  }

  /* embed: a ball in a Hex20 grid, no stabilization, nothing dropped */
  snprintf(cmd, sizeof cmd,
           "'%s' embed --element hex20 --box -1 -1 -1 1 1 1 --cells 3 3 3 --geometry "
           "ball:0.05,0,-0.1,0.8,2 --strength 4 --stabilization 0 --min-fraction 0 --dump '%s' "
           "> /dev/null 2>&1",
           argv[1], dump);
  TEST_TRUE(app_run(cmd) == 0);
  fcm_ctx *ctx = NULL;
  fcm_geometry *ball = NULL;
  const double c[3] = {0.05, 0, -0.1};
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.8, 2, &ball));
  f = fopen(dump, "r");
  TEST_TRUE(f != NULL);
  if (f) {
    char line[1024];
    double sum = 0.0;
    long n = 0;
    while (fgets(line, sizeof line, f)) {
      if (line[0] == '#') continue;
      long cell;
      double xi[3], X[3], wr, wp;
      int flag;
      if (sscanf(line, "%ld %lf %lf %lf %lf %lf %lf %lf %lf %d", &cell, xi, xi + 1, xi + 2, X,
                 X + 1, X + 2, &wr, &wp, &flag) != 10) {
        TEST_TRUE(!"malformed dump line");
        break;
      }
      TEST_TRUE(flag == 0 && cell >= 0 && cell < 27 && wp > 0.0);
      sum += wp;
      n++;
    }
    fclose(f);
    TEST_TRUE(n > 0);
    TEST_NEAR(sum, fcm_geometry_volume(ball), 1e-12, 0.0);
  }
  fcm_geometry_destroy(&ball);
  fcm_ctx_destroy(&ctx);

  /* embed a triangle surface by extension: the cube [-0.5, 0.5]^3 without its top face as
   * OFF; refused open (exit 2, no dump), embedded with --fill-holes (weights add up to 1) */
  {
    char off[4096];
    snprintf(off, sizeof off, "%s/open_cube.off", argv[2]);
    FILE *o = fopen(off, "w");
    TEST_TRUE(o != NULL);
    if (o) {
      fputs("OFF\n8 10 0\n-0.5 -0.5 -0.5\n0.5 -0.5 -0.5\n0.5 0.5 -0.5\n-0.5 0.5 -0.5\n"
            "-0.5 -0.5 0.5\n0.5 -0.5 0.5\n0.5 0.5 0.5\n-0.5 0.5 0.5\n"
            "3 0 2 1\n3 0 3 2\n3 0 1 5\n3 0 5 4\n3 3 7 6\n3 3 6 2\n3 0 4 7\n3 0 7 3\n"
            "3 1 2 6\n3 1 6 5\n",
            o);
      fclose(o);
    }
    remove(dump);
    snprintf(cmd, sizeof cmd,
             "'%s' embed --element hex8 --box -1 -1 -1 1 1 1 --cells 3 3 3 --geometry '%s' "
             "--strength 2 --stabilization 0 --min-fraction 0 --dump '%s' > /dev/null 2>&1",
             argv[1], off, dump);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(fopen(dump, "r") == NULL);
    if (fcm_surface_meshing_available()) {
      snprintf(cmd, sizeof cmd,
               "'%s' embed --element hex8 --box -1 -1 -1 1 1 1 --cells 3 3 3 --geometry '%s' "
               "--fill-holes --strength 2 --stabilization 0 --min-fraction 0 --dump '%s' "
               "> /dev/null 2>&1",
               argv[1], off, dump);
      TEST_TRUE(app_run(cmd) == 0);
      f = fopen(dump, "r");
      TEST_TRUE(f != NULL);
      double sum = 0.0;
      char line[1024];
      while (f && fgets(line, sizeof line, f)) {
        long cell;
        double xi[3], X[3], wr, wp;
        int flag;
        if (line[0] != '#' && sscanf(line, "%ld %lf %lf %lf %lf %lf %lf %lf %lf %d", &cell, xi,
                                     xi + 1, xi + 2, X, X + 1, X + 2, &wr, &wp, &flag) == 10)
          sum += wp;
      }
      if (f) fclose(f);
      TEST_NEAR(sum, 1.0, 1e-12, 0.0);
    }
    remove(off);
    remove(dump);
  }

  /* embed a voxel image by extension: 7 of 2 x 2 x 2 voxels of 0.5 m (weights add up to
   * 7 x 0.125 exactly) */
  {
    char img[4096];
    snprintf(img, sizeof img, "%s/block.nrrd", argv[2]);
    FILE *o = fopen(img, "w");
    TEST_TRUE(o != NULL);
    if (o) {
      fputs("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 0.5 0.5 0.5\n"
            "space origin: (-0.25,-0.25,-0.25)\nencoding: ascii\n\n1 1 1 0 1 1 1 1\n",
            o);
      fclose(o);
    }
    remove(dump);
    snprintf(cmd, sizeof cmd,
             "'%s' embed --element hex8 --box -1 -1 -1 1 1 1 --cells 3 3 3 --geometry '%s' "
             "--strength 2 --stabilization 0 --min-fraction 0 --dump '%s' > /dev/null 2>&1",
             argv[1], img, dump);
    TEST_TRUE(app_run(cmd) == 0);
    f = fopen(dump, "r");
    TEST_TRUE(f != NULL);
    double sum = 0.0;
    char line[1024];
    while (f && fgets(line, sizeof line, f)) {
      long cell;
      double xi[3], X[3], wr, wp;
      int flag;
      if (line[0] != '#' && sscanf(line, "%ld %lf %lf %lf %lf %lf %lf %lf %lf %d", &cell, xi,
                                   xi + 1, xi + 2, X, X + 1, X + 2, &wr, &wp, &flag) == 10)
        sum += wp;
    }
    if (f) fclose(f);
    TEST_NEAR(sum, 7 * 0.125, 1e-12, 0.0);
    remove(img);
    remove(dump);
  }

  /* bad input: exit 2, no output file */
  remove(csv);
  snprintf(cmd, sizeof cmd, "'%s' accuracy --max-strength 0 --csv '%s' 2> /dev/null", argv[1], csv);
  TEST_TRUE(app_run(cmd) == 2);
  snprintf(cmd, sizeof cmd, "'%s' embed --element hex27 2> /dev/null", argv[1]);
  TEST_TRUE(app_run(cmd) == 2);
  remove(dump); /* --box takes six values: five and then an option are refused */
  snprintf(cmd, sizeof cmd,
           "'%s' embed --element hex8 --box -1 -1 -1 1 1 --cells 2 2 2 --geometry "
           "ball:0,0,0,0.5,2 --strength 2 --dump '%s' 2> /dev/null",
           argv[1], dump);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(fopen(dump, "r") == NULL);
  snprintf(cmd, sizeof cmd, "'%s' tables --check=1 2> /dev/null", argv[1]);
  TEST_TRUE(app_run(cmd) == 2);
  TEST_TRUE(fopen(csv, "r") == NULL);
  return TEST_RESULT();
}
