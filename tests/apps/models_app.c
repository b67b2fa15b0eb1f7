/* fcm-models end to end on a small generated model (the bumpy sphere at 4,800 triangles, one
 * coarse cell size, 2 steps): the documented CSV header; a new row that ran (rules time > 0,
 * the set-up at least its phases, final points per cut cell <= M of each kind, no more than the
 * initial ones, a step at least its assembly, factorization and solves, a peak RSS); the old
 * row (Gmsh) with the same cells, cut cells and DOFs, moments equal to the new path's within
 * 1e-10 of the volume, and the ratio row old/new consistent with the two; without Gmsh the old
 * row is skipped with a note. An open surface fails to embed: exit 1, its rows "failed". The PNG is
 * a PNG (when gnuplot is installed). Bad options exit 2 and write no CSV. Mode ball (label bench):
 * the full ball study exits 0 (its claim, exponent <= 1.1, holds) and writes its rows (cut cells
 * growing with n, rules time > 0, points per cut cell <= M of both kinds). Usage: app_models
 * small|ball PATH_TO_fcm-models WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HEADER                                                                                     \
  "model,cell_size,element,path,status,dofs,cells,cut_cells,setup_geometry_s,setup_rules_s,"       \
  "setup_space_s,setup_integrator_s,setup_s,initial_points_stiffness,initial_points_mass,"         \
  "final_points_stiffness,final_points_mass,strength_stiffness,strength_mass,peak_rss_mb,"         \
  "steps,step_s,step_assembly_s,step_factor_s,step_solve_s,log_s,moment_diff,note\n"
#define NCOL 28

typedef struct mrow {
  char path[16], status[16];
  double v[NCOL]; /* numeric columns; -1 when empty */
} mrow;

/* Columns by index. */
enum {
  C_DOFS = 5,
  C_CELLS,
  C_CUT,
  C_GEOM,
  C_RULES,
  C_SPACE,
  C_INTEG,
  C_SETUP,
  C_INIT_K,
  C_INIT_M,
  C_FIN_K,
  C_FIN_M,
  C_STR_K,
  C_STR_M,
  C_PEAK,
  C_STEPS,
  C_STEP,
  C_ASM,
  C_FACT,
  C_SOLVE,
  C_LOG,
  C_MDIFF
};

static int read_rows(const char *path, const char *header, mrow *rows, int cap)
{
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  char line[4096], b[256];
  int n = 0;
  if (!fgets(line, sizeof line, f) || strcmp(line, header) != 0) {
    fclose(f);
    return -2;
  }
  while (n < cap && fgets(line, sizeof line, f)) {
    mrow *r = &rows[n++];
    field(line, 3, r->path, sizeof r->path);
    field(line, 4, r->status, sizeof r->status);
    for (int k = 0; k < NCOL; k++) {
      field(line, k, b, sizeof b);
      r->v[k] = b[0] ? atof(b) : -1.0;
    }
  }
  fclose(f);
  return n;
}

static double moments(double s)
{
  return (s + 1) * (s + 2) * (s + 3) / 6;
}

/* The checks of one row that ran. */
static void check_run(const mrow *r)
{
  TEST_TRUE(!strcmp(r->status, "ok"));
  TEST_TRUE(r->v[C_RULES] > 0.0 && r->v[C_GEOM] >= 0.0 && r->v[C_SPACE] >= 0.0);
  TEST_TRUE(r->v[C_SETUP] >=
            (r->v[C_GEOM] + r->v[C_RULES] + r->v[C_SPACE] + r->v[C_INTEG]) * (1.0 - 1e-3) - 2e-6);
  TEST_TRUE(r->v[C_CUT] > 0.0 && r->v[C_CELLS] > r->v[C_CUT] && r->v[C_DOFS] > 0.0);
  TEST_TRUE(r->v[C_STR_K] >= 1.0 && r->v[C_STR_M] >= 1.0);
  TEST_TRUE(r->v[C_FIN_K] > 0.0 && r->v[C_FIN_K] <= moments(r->v[C_STR_K]) + 1e-9);
  TEST_TRUE(r->v[C_FIN_K] <= r->v[C_INIT_K] + 1e-9 && r->v[C_FIN_M] <= r->v[C_INIT_M] + 1e-9);
  TEST_TRUE(r->v[C_PEAK] > 0.0 && r->v[C_STEPS] == 2.0);
  TEST_TRUE(r->v[C_STEP] > 0.0 && r->v[C_LOG] >= 0.0);
  TEST_TRUE(r->v[C_STEP] >= (r->v[C_ASM] + r->v[C_FACT] + r->v[C_SOLVE]) * (1.0 - 1e-3) - 2e-6);
}

static void check_png(const char *png)
{
  if (app_run("gnuplot --version > /dev/null 2>&1") != 0) return;
  TEST_TRUE(app_is_png(png));
}

/* The full ball study: exit status (the claim holds), rows. */
static void ball(const char *prog, const char *work)
{
  char cmd[8192], csv[1024];
  snprintf(csv, sizeof csv, "%s/models-ball.csv", work);
  remove(csv);
  snprintf(cmd, sizeof cmd, "'%s' --ball-study --csv '%s'", prog, csv);
  TEST_TRUE(app_run(cmd) == 0);
  FILE *f = fopen(csv, "r");
  char line[1024], b[64];
  TEST_TRUE(f && fgets(line, sizeof line, f) &&
            !strcmp(line, "n,triangles,cells,cut_cells,rules_s,us_per_cut_cell,"
                          "points_per_cut_cell,strength_stiffness,strength_mass,status,note\n"));
  double prev = 0.0;
  int n = 0;
  while (f && fgets(line, sizeof line, f)) {
    n++;
    field(line, 9, b, sizeof b);
    TEST_TRUE(!strcmp(b, "ok"));
    field(line, 3, b, sizeof b);
    const double cut = atof(b);
    TEST_TRUE(cut > prev);
    prev = cut;
    field(line, 4, b, sizeof b);
    TEST_TRUE(atof(b) > 0.0);
    field(line, 7, b, sizeof b);
    const double mk = moments(atof(b));
    field(line, 8, b, sizeof b);
    const double mm = moments(atof(b));
    field(line, 6, b, sizeof b); /* at most M of each kind */
    TEST_TRUE(atof(b) > 0.0 && atof(b) <= mk + mm + 1e-9);
  }
  TEST_TRUE(n == 4);
  if (f) fclose(f);
}

int main(int argc, char **argv)
{
  if (argc != 4) return 2;
  const char *mode = argv[1], *prog = argv[2], *work = argv[3];
  if (!strcmp(mode, "ball")) {
    ball(prog, work);
    return TEST_RESULT();
  }
  char cmd[8192], csv[1024], png[1024];
  static mrow rows[16];
  snprintf(csv, sizeof csv, "%s/models-small.csv", work);
  snprintf(png, sizeof png, "%s/models-small.png", work);
  remove(csv);
  remove(png);
  snprintf(cmd, sizeof cmd,
           "'%s' --model bumpy --bumpy-triangles 5000 --cell-sizes 0.25 --steps 2 --csv '%s' "
           "--png '%s' > /dev/null 2>&1",
           prog, csv, png);
  TEST_TRUE(app_run(cmd) == 0);
  const int gmsh = fcm_surface_meshing_available();
  const int n = read_rows(csv, HEADER, rows, 16);
  TEST_TRUE(n == (gmsh ? 3 : 2));
  if (n >= 2) {
    const mrow *nw = &rows[0], *old = &rows[1];
    TEST_TRUE(!strcmp(nw->path, "new") && !strcmp(old->path, "old"));
    check_run(nw);
    TEST_TRUE(nw->v[C_FIN_M] <= moments(nw->v[C_STR_M]) + 1e-9);
    if (!gmsh) {
      printf("fcm-models: no Gmsh in this build: the volume path (old) is skipped\n");
      TEST_TRUE(!strcmp(old->status, "skipped") && nw->v[C_MDIFF] < 0.0);
    } else {
      check_run(old);
      TEST_TRUE(old->v[C_CUT] == nw->v[C_CUT] && old->v[C_CELLS] == nw->v[C_CELLS]);
      TEST_TRUE(old->v[C_DOFS] == nw->v[C_DOFS]);
      TEST_TRUE(nw->v[C_MDIFF] >= 0.0 && nw->v[C_MDIFF] <= 1e-10);
      TEST_TRUE(old->v[C_MDIFF] == nw->v[C_MDIFF]);
      const mrow *q = &rows[2];
      TEST_TRUE(!strcmp(q->path, "old/new") && !strcmp(q->status, "ratio"));
      TEST_NEAR(q->v[C_RULES], old->v[C_RULES] / nw->v[C_RULES], 1e-4, 0.0);
      TEST_NEAR(q->v[C_PEAK], old->v[C_PEAK] / nw->v[C_PEAK], 1e-4, 0.0);
      TEST_NEAR(q->v[C_INIT_M], old->v[C_INIT_M] / nw->v[C_INIT_M], 1e-4, 0.0);
    }
  }
  check_png(png);
  /* a model that fails to embed (an open surface without --fill-holes): exit 1, its rows
   * failed with the library's message */
  char obj[1024];
  snprintf(obj, sizeof obj, "%s/models-open.obj", work);
  FILE *f = fopen(obj, "w");
  TEST_TRUE(f != NULL);
  if (f) {
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n", f);
    fclose(f);
  }
  remove(csv);
  snprintf(cmd, sizeof cmd,
           "'%s' --model '%s' --cell-sizes 0.5 --steps 1 --csv '%s' > /dev/null 2>&1", prog, obj,
           csv);
  TEST_TRUE(app_run(cmd) == 1);
  const int nf = read_rows(csv, HEADER, rows, 16);
  TEST_TRUE(nf == 2 && !strcmp(rows[0].status, "failed"));
  TEST_TRUE(nf == 2 && !strcmp(rows[1].status, gmsh ? "failed" : "skipped"));
  /* bad options: exit 2, nothing written */
  static const char *const bad[] = {
      "--cell-sizes 0",
      "--cell-sizes 0.1,0.1",
      "--cell-sizes 0.1,x",
      "--element tet4",
      "--element hex9",
      "--model /nonexistent/x.obj",
      "--quick",
      "--ball-study --model bumpy",
      "--steps 0",
      "--bumpy-triangles 10",
      "--scale -1",
      "--frobnicate",
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    remove(csv);
    snprintf(cmd, sizeof cmd, "'%s' %s --csv '%s' > /dev/null 2>&1", prog, bad[k], csv);
    const int rc = app_run(cmd);
    if (rc != 2) fprintf(stderr, "'%s': exit %d, expected 2\n", bad[k], rc);
    TEST_TRUE(rc == 2);
    TEST_TRUE(!app_exists(csv));
  }
  return TEST_RESULT();
}
