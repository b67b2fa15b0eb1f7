/* fcm-rulegen end to end: `--shape tri --shape line --strength 2:3 --out DIR` (a repeated
 * --shape adds to the list) writes DIR/<shape>/<shape>_<mm>.txt for both shapes and both
 * strengths, each a positive rule whose weights add up to the reference measure (triangle
 * 1/2, line 2) with the declared number of points; --dry-run writes nothing; bad options
 * (empty strength range, unknown shape, NaN, --starts 0 without --from-next, an unknown
 * option) exit 2 and write nothing.
 * Usage: app_rulegen PATH_TO_fcm-rulegen WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Check one table: `dim` coordinates and a weight per row, `points` rows as declared. */
static void check_table(const char *path, int dim, double measure)
{
  FILE *f = fopen(path, "r");
  TEST_TRUE(f != NULL);
  if (!f) return;
  char line[1024];
  int declared = -1, rows = 0, positive = 1;
  double sum = 0.0;
  while (fgets(line, sizeof line, f)) {
    if (line[0] == '#') {
      sscanf(line, "# points: %d", &declared);
      continue;
    }
    double v[3];
    int n =
        dim == 1 ? sscanf(line, "%lf %lf", v, v + 1) : sscanf(line, "%lf %lf %lf", v, v + 1, v + 2);
    TEST_TRUE(n == dim + 1);
    if (n != dim + 1) break;
    positive = positive && v[dim] > 0.0;
    sum += v[dim];
    rows++;
  }
  fclose(f);
  TEST_TRUE(declared > 0 && rows == declared && positive);
  TEST_NEAR(sum, measure, 1e-13, 0.0);
}

int main(int argc, char **argv)
{
  if (argc != 3) return 2;
  const char *prog = argv[1];
  char dir[4096], cmd[12288], path[8192];
  snprintf(dir, sizeof dir, "%s/rulegen", argv[2]);
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  TEST_TRUE(app_run(cmd) == 0);

  snprintf(cmd, sizeof cmd,
           "'%s' --shape tri --shape line --strength 2:3 --out '%s' > /dev/null 2>&1", prog, dir);
  TEST_TRUE(app_run(cmd) == 0);
  static const char *const shapes[2] = {"tri", "line"};
  for (int s = 0; s < 2; s++)
    for (int m = 2; m <= 3; m++) {
      snprintf(path, sizeof path, "%s/%s/%s_%02d.txt", dir, shapes[s], shapes[s], m);
      check_table(path, s == 0 ? 2 : 1, s == 0 ? 0.5 : 2.0);
    }
  snprintf(path, sizeof path, "%s/tri/tri_01.txt", dir); /* only the range asked for */
  TEST_TRUE(!app_exists(path));

  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  TEST_TRUE(app_run(cmd) == 0);
  snprintf(cmd, sizeof cmd, "'%s' --shape quad --strength 2 --dry-run --out '%s' > /dev/null 2>&1",
           prog, dir);
  TEST_TRUE(app_run(cmd) == 0);
  TEST_TRUE(!app_exists(dir));

  static const char *const bad[] = {"--strength 3:2", "--strength 0", "--strength 41",
                                    "--shape cube",   "--shape tri,", "--batch nan",
                                    "--starts 0",     "--tol 2",      "--bogus",
                                    "--dry-run=1",    "tri"};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    snprintf(cmd, sizeof cmd, "'%s' --shape line --strength 1 --out '%s' %s > /dev/null 2>&1", prog,
             dir, bad[k]);
    const int rc = app_run(cmd);
    if (rc != 2) fprintf(stderr, "'%s' exited with %d\n", bad[k], rc);
    TEST_TRUE(rc == 2);
    TEST_TRUE(!app_exists(dir));
  }
  return TEST_RESULT();
}
