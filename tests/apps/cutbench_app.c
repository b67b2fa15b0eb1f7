/* fcm-cutbench end to end. Mode quick (label app): --quick on small sizes (0.15 x the papers',
 * a generated body of 2,000 triangles) with a looser Newton tolerance as the interactive option
 * set: exit 0; the documented CSV header; a defaults and an interactive row for each of the
 * three quick rows, every figure finite; each row's cut events as its scene has them; the cuts
 * add DOFs; a cut's phases fit inside its latency, the largest cut is at least the mean, so is
 * the largest step; at least one Newton iteration per step; the ratios are fcm's figure over
 * the paper's and the verdicts follow from them; both runs of a row end on the same DOFs and
 * differ in displacement by less than a tenth of the largest displacement. The PNG is a PNG
 * (with gnuplot). --write-scenes writes scenes that parse. Bad options (--repeat outside [1, 99]
 * and --dick-events outside [1, 16] among them) exit 2 and write no CSV.
 * Every run's count of runs is 1 and its ranges its figures. Mode rows (label app): the rows
 * left out of --quick — the accordion runs at 0.1 of its size, three times (--repeat 3: both
 * option sets ok, every figure finite and inside its range over the three runs, which all
 * ended alike; its five cut events add DOFs, at least one Newton iteration a step, the same
 * DOFs in both sets); the plate's, accordion's and octopus's scenes
 * written with --write-scenes parse with their cut events; Dick's Bunny 3 with its blades
 * pushed in one event and in three (--dick-events) ends on the same DOFs, and its scene with
 * eight events has eight cut effects.
 * Mode full (label bench): every row at the papers' sizes runs, the defaults ok, the program's
 * interactive sets ok or skipped (a build without their keys).
 * Usage: app_cutbench quick|rows|full PATH_TO_fcm-cutbench WORK_DIR */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "fcm/fcm.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HEADER                                                                                     \
  "row,paper,model,paper_size,element,material,solver,status,cell_size,cells,dofs_before,"         \
  "dofs_after,cut_events,cut_s_mean,cut_s_max,cut_rules_s,cut_space_s,cut_integrator_s,"           \
  "cut_solver_s,cut_other_s,cut_factor_s,setup_s,steps,step_s_mean,step_s_max,newton_per_step,"    \
  "linear_per_step,paper_cut_s,paper_step_s,paper_step_max_s,paper_machine,cut_ratio,step_ratio,"  \
  "step_target_s,cut_ok,step_ok,disp_diff_m,disp_max_m,runs,cut_s_max_lo,cut_s_max_hi,"            \
  "step_s_mean_lo,step_s_mean_hi,options,note\n"
#define NCOL 45

enum {
  C_ROW = 0,
  C_SOLVER = 6,
  C_STATUS,
  C_H,
  C_CELLS,
  C_DOFS0,
  C_DOFS1,
  C_EVENTS,
  C_CUT,
  C_CUTMAX,
  C_RULES,
  C_SPACE,
  C_INTEG,
  C_SOLV,
  C_OTHER,
  C_FACT,
  C_SETUP,
  C_STEPS,
  C_STEP,
  C_STEPMAX,
  C_NEWTON,
  C_LINEAR,
  C_PCUT,
  C_PSTEP,
  C_PSTEPMAX,
  C_MACHINE,
  C_CRATIO,
  C_SRATIO,
  C_TARGET,
  C_CUTOK,
  C_STEPOK,
  C_DIFF,
  C_DMAX,
  C_RUNS,
  C_CUTMAX_LO,
  C_CUTMAX_HI,
  C_STEP_LO,
  C_STEP_HI
};

typedef struct crow {
  char f[NCOL][128];
  double v[NCOL]; /* NAN when empty */
} crow;

static int read_rows(const char *path, crow *rows, int cap)
{
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  char line[8192];
  int n = 0;
  if (!fgets(line, sizeof line, f) || strcmp(line, HEADER) != 0) {
    fclose(f);
    return -2;
  }
  while (n < cap && fgets(line, sizeof line, f)) {
    crow *r = &rows[n++];
    for (int k = 0; k < NCOL; k++) {
      field(line, k, r->f[k], sizeof r->f[k]);
      r->v[k] = r->f[k][0] ? atof(r->f[k]) : NAN;
    }
  }
  fclose(f);
  return n;
}

/* The runs' count and the ranges of the largest cut and the mean step: `runs` runs, each
 * figure inside its range (a single run's range is the figure itself). */
static void check_runs(const crow *r, double runs)
{
  TEST_TRUE(r->v[C_RUNS] == runs);
  TEST_TRUE(r->v[C_CUTMAX_LO] <= r->v[C_CUTMAX] && r->v[C_CUTMAX] <= r->v[C_CUTMAX_HI]);
  TEST_TRUE(r->v[C_STEP_LO] <= r->v[C_STEP] && r->v[C_STEP] <= r->v[C_STEP_HI]);
  if (runs == 1.0)
    TEST_TRUE(r->v[C_CUTMAX_LO] == r->v[C_CUTMAX_HI] && r->v[C_STEP_LO] == r->v[C_STEP_HI]);
}

/* Every measured figure of a run that went well. */
static void check_run(const crow *r, double events)
{
  TEST_TRUE(!strcmp(r->f[C_STATUS], "ok"));
  for (int k = C_H; k <= C_LINEAR; k++)
    TEST_TRUE(isfinite(r->v[k]) && r->v[k] >= 0.0);
  TEST_TRUE(r->v[C_EVENTS] == events);
  TEST_TRUE(r->v[C_CELLS] > 0.0 && r->v[C_DOFS1] > r->v[C_DOFS0] && r->v[C_DOFS0] > 0.0);
  TEST_TRUE(r->v[C_CUT] > 0.0 && r->v[C_CUTMAX] >= r->v[C_CUT] * (1.0 - 1e-5));
  TEST_TRUE(r->v[C_RULES] > 0.0);
  /* the five phases add up to the latency (to the CSV's rounding) */
  TEST_NEAR(r->v[C_RULES] + r->v[C_SPACE] + r->v[C_INTEG] + r->v[C_SOLV] + r->v[C_OTHER],
            r->v[C_CUT], 1e-4, 4e-6);
  TEST_TRUE(r->v[C_STEP] > 0.0 && r->v[C_STEPMAX] >= r->v[C_STEP] * (1.0 - 1e-5));
  TEST_TRUE(r->v[C_NEWTON] >= 1.0);
  TEST_TRUE(isfinite(r->v[C_PSTEP]) && r->v[C_PSTEP] > 0.0);
  TEST_NEAR(r->v[C_SRATIO], r->v[C_STEP] / r->v[C_PSTEP], 1e-4, 0.0);
  TEST_TRUE(!strcmp(r->f[C_STEPOK], r->v[C_STEP] <= r->v[C_TARGET] ? "yes" : "no"));
  if (isfinite(r->v[C_PCUT])) {
    TEST_NEAR(r->v[C_CRATIO], r->v[C_CUTMAX] / r->v[C_PCUT], 1e-4, 0.0);
    TEST_TRUE(!strcmp(r->f[C_CUTOK], r->v[C_CUTMAX] <= r->v[C_PCUT] ? "yes" : "no"));
  } else {
    TEST_TRUE(!r->f[C_CUTOK][0] && !isfinite(r->v[C_CRATIO]));
  }
}

static void check_png(const char *png)
{
  if (app_run("gnuplot --version > /dev/null 2>&1") != 0) return;
  TEST_TRUE(app_is_png(png));
}

static void quick(const char *prog, const char *work)
{
  char cmd[8192], csv[1024], png[1024];
  static crow rows[16];
  snprintf(csv, sizeof csv, "%s/cutbench-quick.csv", work);
  snprintf(png, sizeof png, "%s/cutbench-quick.png", work);
  remove(csv);
  remove(png);
  snprintf(cmd, sizeof cmd,
           "'%s' --quick --scale 0.15 --surface-triangles 2000 --interactive '\"newton\": "
           "{\"rtol\": 1e-2}' --csv '%s' --png '%s' > /dev/null 2>&1",
           prog, csv, png);
  TEST_TRUE(app_run(cmd) == 0);
  const int n = read_rows(csv, rows, 16);
  TEST_TRUE(n == 6);
  static const char *const names[3] = {"dick-bunny3", "koschier-bunny", "tonthat-slab"};
  static const double events[3] = {4, 5, 4};
  for (int i = 0; i < 3 && n == 6; i++) {
    const crow *d = &rows[2 * i], *q = &rows[2 * i + 1];
    TEST_TRUE(!strcmp(d->f[C_ROW], names[i]) && !strcmp(q->f[C_ROW], names[i]));
    TEST_TRUE(!strcmp(d->f[C_SOLVER], "defaults") && !strcmp(q->f[C_SOLVER], "interactive"));
    check_run(d, events[i]);
    check_run(q, events[i]);
    check_runs(d, 1.0);
    check_runs(q, 1.0);
    TEST_TRUE(q->v[C_DOFS1] == d->v[C_DOFS1] && q->v[C_DOFS0] == d->v[C_DOFS0]);
    TEST_TRUE(d->v[C_DMAX] > 0.0 && isfinite(q->v[C_DIFF]) && q->v[C_DIFF] >= 0.0);
    TEST_TRUE(q->v[C_DIFF] <= 0.1 * d->v[C_DMAX]);
  }
  check_png(png);
  /* the scenes written for the examples parse */
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/cutbench-scenes", work);
  snprintf(cmd, sizeof cmd,
           "rm -rf '%s' && '%s' --write-scenes '%s' --quick --scale 0.15 "
           "--surface-triangles 2000 > /dev/null",
           dir, prog, dir);
  TEST_TRUE(app_run(cmd) == 0);
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  for (int i = 0; i < 3; i++) {
    char path[2048];
    snprintf(path, sizeof path, "%s/cutbench_%s.json", dir, names[i]);
    for (char *c = path + strlen(dir); *c; c++)
      if (*c == '-') *c = '_';
    fcm_scene *scene = NULL;
    TEST_TRUE(fcm_scene_create_from_file(ctx, path, &scene) == FCM_OK);
    TEST_TRUE(scene && fcm_scene_count_effects(scene, FCM_EFFECT_CUT) == (int)events[i]);
    fcm_scene_destroy(&scene);
  }
  fcm_ctx_destroy(&ctx);
  /* usage errors: exit 2, no CSV */
  static const char *const bad[] = {"--rows nope",
                                    "--quick --rows dick-bunny3",
                                    "--scale 0",
                                    "--fill-holes",
                                    "--interactive '{\"rtol\": 1}'",
                                    "--model x.obj --surface-triangles 100",
                                    "--repeat 0",
                                    "--repeat 100",
                                    "--dick-events 0",
                                    "--dick-events 17"};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    remove(csv);
    snprintf(cmd, sizeof cmd, "'%s' %s --csv '%s' 2> /dev/null", prog, bad[k], csv);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(!app_exists(csv));
  }
}

/* The scenes of `rows` (names as the files spell them) written to <work>/<sub> parse, each
 * with its cut events. */
static void check_scenes(const char *prog, const char *work, const char *sub, const char *opts,
                         const char *const *names, const double *events, int n)
{
  char cmd[8192], dir[1024];
  snprintf(dir, sizeof dir, "%s/%s", work, sub);
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && '%s' --write-scenes '%s' %s > /dev/null", dir, prog,
           dir, opts);
  TEST_TRUE(app_run(cmd) == 0);
  fcm_ctx *ctx = NULL;
  TEST_TRUE(fcm_ctx_create(NULL, &ctx) == FCM_OK);
  for (int i = 0; i < n; i++) {
    char path[2048];
    snprintf(path, sizeof path, "%s/cutbench_%s.json", dir, names[i]);
    fcm_scene *scene = NULL;
    TEST_TRUE(fcm_scene_create_from_file(ctx, path, &scene) == FCM_OK);
    TEST_TRUE(scene && fcm_scene_count_effects(scene, FCM_EFFECT_CUT) == (int)events[i]);
    fcm_scene_destroy(&scene);
  }
  fcm_ctx_destroy(&ctx);
}

/* Dick's blades pushed in one event and in three: the bands share their edges, so both cut
 * the same surface and end with the same DOFs (a band that left a gap or an overlap would
 * change the pieces), each event is one cut effect, and a step follows every other one. The
 * interactive set is quick's (no multigrid structure made beside the integrator, so the
 * phases add up to the latency as check_run() asks). */
static void dick_events(const char *prog, const char *work)
{
  char cmd[8192], csv[1024];
  static crow rows[4];
  double dofs[2] = {-1.0, -2.0};
  static const int n_events[2] = {1, 3};
  for (int k = 0; k < 2; k++) {
    snprintf(csv, sizeof csv, "%s/cutbench-dick-events%d.csv", work, n_events[k]);
    remove(csv);
    snprintf(cmd, sizeof cmd,
             "'%s' --rows dick-bunny3 --scale 0.1 --surface-triangles 2000 --dick-events %d "
             "--interactive '\"newton\": {\"rtol\": 1e-2}' --csv '%s' > /dev/null 2>&1",
             prog, n_events[k], csv);
    TEST_TRUE(app_run(cmd) == 0);
    const int n = read_rows(csv, rows, 4);
    TEST_TRUE(n == 2);
    for (int i = 0; i < n && n == 2; i++) {
      check_run(&rows[i], n_events[k]);
      TEST_TRUE(rows[i].v[C_STEPS] == 2 * n_events[k] + 1);
    }
    if (n == 2) dofs[k] = rows[0].v[C_DOFS1];
  }
  TEST_TRUE(dofs[0] == dofs[1]);
  static const char *const names[1] = {"dick_bunny3"};
  static const double events[1] = {8};
  check_scenes(prog, work, "cutbench-dick-events-scenes",
               "--rows dick-bunny3 --dick-events 8 --scale 0.1 --surface-triangles 2000", names,
               events, 1);
}

static void rows_mode(const char *prog, const char *work)
{
  char cmd[8192], csv[1024];
  static crow rows[16];
  snprintf(csv, sizeof csv, "%s/cutbench-accordion.csv", work);
  remove(csv);
  snprintf(cmd, sizeof cmd,
           "'%s' --rows tonthat-accordion --scale 0.1 --repeat 3 --csv '%s' > /dev/null 2>&1", prog,
           csv);
  TEST_TRUE(app_run(cmd) == 0);
  const int n = read_rows(csv, rows, 16);
  TEST_TRUE(n == 2);
  if (n == 2) {
    const crow *d = &rows[0], *q = &rows[1];
    TEST_TRUE(!strcmp(d->f[C_ROW], "tonthat-accordion") && !strcmp(q->f[C_ROW], d->f[C_ROW]));
    TEST_TRUE(!strcmp(d->f[C_SOLVER], "defaults") && !strcmp(q->f[C_SOLVER], "interactive"));
    check_run(d, 5);
    check_run(q, 5);
    check_runs(d, 3.0);
    check_runs(q, 3.0);
    TEST_TRUE(q->v[C_DOFS1] == d->v[C_DOFS1] && q->v[C_DOFS0] == d->v[C_DOFS0]);
    TEST_TRUE(d->v[C_DMAX] > 0.0 && isfinite(q->v[C_DIFF]));
  }
  static const char *const names[3] = {"koschier_plate", "tonthat_accordion", "tonthat_octopus"};
  static const double events[3] = {5, 5, 3};
  check_scenes(prog, work, "cutbench-rows-scenes",
               "--rows koschier-plate,tonthat-accordion,tonthat-octopus --scale 0.1 "
               "--surface-triangles 2000",
               names, events, 3);
  dick_events(prog, work);
}

static void full(const char *prog, const char *work)
{
  char cmd[8192], csv[1024];
  static crow rows[32];
  snprintf(csv, sizeof csv, "%s/cutbench-full.csv", work);
  remove(csv);
  snprintf(cmd, sizeof cmd, "'%s' --csv '%s'", prog, csv);
  TEST_TRUE(app_run(cmd) == 0);
  const int n = read_rows(csv, rows, 32);
  int defaults = 0;
  for (int i = 0; i < n; i++) {
    const int d = !strcmp(rows[i].f[C_SOLVER], "defaults");
    defaults += d;
    /* the program's interactive sets run where the build has their keys */
    TEST_TRUE(!strcmp(rows[i].f[C_STATUS], "ok") ||
              (!d && !strcmp(rows[i].f[C_STATUS], "skipped")));
  }
  TEST_TRUE(defaults == 8 && n == 16);
}

int main(int argc, char **argv)
{
  if (argc != 4) return 2;
  if (!strcmp(argv[1], "full"))
    full(argv[2], argv[3]);
  else if (!strcmp(argv[1], "rows"))
    rows_mode(argv[2], argv[3]);
  else
    quick(argv[2], argv[3]);
  return TEST_RESULT();
}
