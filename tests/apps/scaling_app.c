/* fcm-scaling end to end on small sizes (n = 4, 8 of the embedded ball and the cut ball, Hex8,
 * coarsest multigrid level <= 100 DOFs so both sizes have 2+ levels): the documented CSV
 * header; one row per (body, n, solver), every one status ok; every solver reaches the
 * relative residual 1e-8 (MINRES stops on its preconditioned norm: 1e-6 accepted for the
 * 2-norm) and agrees with CHOLMOD to 1e-5 (relative 2-norm), CHOLMOD's residual below 1e-12;
 * the DOFs grow with n and are the same for every solver of one size; the cg-mg iterations
 * at n = 8 are within 1.5x of n = 4 and below cg-jacobi's; the mg convergence factor (ball,
 * cut) is in (0, 1) with 2+ cycles and 2+ levels, and equals the reported (relative
 * residual)^(1/cycles) bound: factor^(cycles-1) >= final residual within a factor; the PNG is a
 * PNG (when gnuplot is installed); bad options exit 2 and write no CSV.
 * Mode quick / full (labels bench, slow): `--quick --check` / `--check` (the full study),
 * which must exit 0: the claims hold (see fcm-scaling --help), and write a CSV.
 * Mode petsc (label mpi, a build with PETSc): `MPIEXEC -n NP fcm-scaling --backend petsc` on
 * n = 4, 8 of the ball (Hex8) with --check exits 0 and writes the rows cholmod, cg-mg,
 * petsc-gamg, petsc-mumps, petsc-mg per size; the PETSc rows have status ok, processes NP, the
 * serial rows' DOFs, iterations >= 1, a relative residual (computed with the serial matrix) of at
 * most 2e-8 (GAMG, PCMG: CG on the true residual to rtol 1e-8) / 1e-12 (MUMPS), and agree with
 * CHOLMOD's solution to 1e-5 (GAMG, PCMG) / 1e-10 (MUMPS); options the PETSc backend refuses exit 2
 * on every process, with no CSV.
 * Usage: app_scaling small|quick|full PATH_TO_fcm-scaling WORK_DIR [MPIEXEC NP] */
#define _POSIX_C_SOURCE 200809L
#include "app_run.h"
#include "fcm/version.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HEADER                                                                                     \
  "element,cells,dofs,solver,iterations,convergence_factor,setup_s,solve_s,peak_rss_mb,body,"      \
  "status,relative_residual,diff_cholmod,setup_cpu_s,solve_cpu_s,base_rss_mb,levels,processes,"    \
  "note\n"

typedef struct srow {
  char element[16], solver[32], body[16], status[16];
  long long n, dofs;
  int iterations, levels, processes;
  double factor, setup, solve, peak, relres, diff;
} srow;

static double num(const char *line, int k)
{
  char b[64];
  field(line, k, b, sizeof b);
  return b[0] ? atof(b) : -1.0;
}

static int read_rows(const char *path, srow *rows, int cap)
{
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  char line[2048];
  int n = 0;
  if (!fgets(line, sizeof line, f) || strcmp(line, HEADER) != 0) {
    fclose(f);
    return -2;
  }
  while (n < cap && fgets(line, sizeof line, f)) {
    srow *r = &rows[n++];
    field(line, 0, r->element, sizeof r->element);
    r->n = (long long)num(line, 1);
    r->dofs = (long long)num(line, 2);
    field(line, 3, r->solver, sizeof r->solver);
    r->iterations = (int)num(line, 4);
    r->factor = num(line, 5);
    r->setup = num(line, 6);
    r->solve = num(line, 7);
    r->peak = num(line, 8);
    field(line, 9, r->body, sizeof r->body);
    field(line, 10, r->status, sizeof r->status);
    r->relres = num(line, 11);
    r->diff = num(line, 12);
    r->levels = (int)num(line, 16);
    r->processes = (int)num(line, 17);
  }
  fclose(f);
  return n;
}

static const srow *find(const srow *rows, int n, const char *body, long long cells,
                        const char *solver)
{
  for (int i = 0; i < n; i++)
    if (!strcmp(rows[i].body, body) && rows[i].n == cells && !strcmp(rows[i].solver, solver))
      return &rows[i];
  return NULL;
}

/* mode petsc: argv = PATH_TO_fcm-scaling WORK_DIR MPIEXEC NP (after the mode) */
static int petsc_mode(char **argv)
{
  char cmd[8192], csv[1024];
  static srow rows[64];
  const int np = atoi(argv[4]);
  snprintf(csv, sizeof csv, "%s/scaling-petsc-np%d.csv", argv[2], np);
  remove(csv);
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' -n %d '%s' --backend petsc --sizes 4,8 "
           "--elements hex8 --bodies ball --coarse-dofs 100 --check --csv '%s' > /dev/null 2>&1",
           argv[3], np, argv[1], csv);
  TEST_TRUE(app_run(cmd) == 0);
  const int n = read_rows(csv, rows, 64);
  TEST_TRUE(n == 2 * 5);
  static const char *const solvers[5] = {"cholmod", "cg-mg", "petsc-gamg", "petsc-mumps",
                                         "petsc-mg"};
  for (long long c = 4; c <= 8; c *= 2) {
    const srow *ch = find(rows, n, "ball", c, "cholmod");
    TEST_TRUE(ch != NULL && ch->processes == 1 && !strcmp(ch->status, "ok"));
    for (int s = 1; s < 5 && ch; s++) {
      const srow *r = find(rows, n, "ball", c, solvers[s]);
      TEST_TRUE(r != NULL);
      if (!r) continue;
      TEST_TRUE(!strcmp(r->status, "ok") && r->dofs == ch->dofs && r->iterations >= 1);
      TEST_TRUE(r->setup >= 0.0 && r->solve >= 0.0 && r->peak > 0.0);
      if (s == 1) continue;
      TEST_TRUE(r->processes == np);
      const int mumps = s == 3;
      if (!(r->relres >= 0.0 && r->relres <= (mumps ? 1e-12 : 2e-8) && r->diff >= 0.0 &&
            r->diff <= (mumps ? 1e-10 : 1e-5)))
        fprintf(stderr, "n=%lld %s: relres %g diff %g\n", c, solvers[s], r->relres, r->diff);
      TEST_TRUE(r->relres >= 0.0 && r->relres <= (mumps ? 1e-12 : 2e-8));
      TEST_TRUE(r->diff >= 0.0 && r->diff <= (mumps ? 1e-10 : 1e-5));
    }
  }
  /* refused: exit non-zero (2 on every process), no CSV */
  static const char *const bad[] = {"--constrain-ratio 0.1", "--solvers petsc-cg", "--backend mpi"};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    remove(csv);
    snprintf(cmd, sizeof cmd, "'%s' -n %d '%s' --backend petsc %s --csv '%s' > /dev/null 2>&1",
             argv[3], np, argv[1], bad[k], csv);
    TEST_TRUE(app_run(cmd) != 0);
    TEST_TRUE(!app_exists(csv));
  }
  return TEST_RESULT();
}

int main(int argc, char **argv)
{
  if (argc != 4 && !(argc == 6 && !strcmp(argv[1], "petsc"))) return 2;
  const char *mode = argv[1];
  argv++;
  if (!strcmp(mode, "petsc")) return petsc_mode(argv);
  char cmd[8192], csv[1024], png[1024];
  static srow rows[64];
  if (strcmp(mode, "small")) {
    snprintf(csv, sizeof csv, "%s/scaling-%s.csv", argv[2], mode);
    snprintf(png, sizeof png, "%s/scaling-%s.png", argv[2], mode);
    remove(csv);
    snprintf(cmd, sizeof cmd, "'%s' %s --check --csv '%s' --png '%s'", argv[1],
             strcmp(mode, "quick") ? "" : "--quick", csv, png);
    TEST_TRUE(app_run(cmd) == 0);
    TEST_TRUE(app_exists(csv));
    return TEST_RESULT();
  }
  snprintf(csv, sizeof csv, "%s/scaling-small.csv", argv[2]);
  snprintf(png, sizeof png, "%s/scaling-small.png", argv[2]);
  remove(csv);
  remove(png);
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 '%s' --sizes 4,8 --elements hex8 --bodies "
           "ball,cut --coarse-dofs 100 --csv '%s' --png '%s' > /dev/null 2>&1",
           argv[1], csv, png);
  TEST_TRUE(app_run(cmd) == 0);
  const int n = read_rows(csv, rows, 64);
  TEST_TRUE(n == 2 * 5 + 2); /* ball: 2 sizes x 5 solvers; cut: 2 sizes x mg */
  static const char *const solvers[5] = {"cholmod", "cg-jacobi", "minres-schwarz", "cg-mg", "mg"};
  for (int i = 0; i < n; i++) {
    const srow *r = &rows[i];
    TEST_TRUE(!strcmp(r->element, "hex8") && !strcmp(r->status, "ok"));
    TEST_TRUE(r->setup >= 0.0 && r->solve >= 0.0 && r->peak > 0.0);
    TEST_TRUE(r->iterations >= 1);
    if (!strcmp(r->solver, "cholmod")) {
      TEST_TRUE(r->relres >= 0.0 && r->relres < 1e-12);
      TEST_TRUE(r->factor < 0.0); /* empty */
    } else if (!strcmp(r->solver, "minres-schwarz")) {
      TEST_TRUE(r->relres >= 0.0 && r->relres <= 1e-6);
    } else {
      TEST_TRUE(r->relres >= 0.0 && r->relres <= 1e-8 * (1.0 + 1e-6));
    }
    if (!strcmp(r->body, "ball") && strcmp(r->solver, "cholmod"))
      TEST_TRUE(r->diff >= 0.0 && r->diff <= 1e-5);
    if (!strcmp(r->solver, "mg") || !strcmp(r->solver, "cg-mg")) TEST_TRUE(r->levels >= 2);
  }
  for (long long c = 4; c <= 8; c *= 2) {
    const srow *ch = find(rows, n, "ball", c, "cholmod");
    TEST_TRUE(ch != NULL);
    for (int s = 0; s < 5 && ch; s++) {
      const srow *r = find(rows, n, "ball", c, solvers[s]);
      TEST_TRUE(r && r->dofs == ch->dofs);
    }
    for (int b = 0; b < 2; b++) {
      const srow *m = find(rows, n, b ? "cut" : "ball", c, "mg");
      TEST_TRUE(m && m->iterations >= 2 && m->factor > 0.0 && m->factor < 1.0);
      /* the factor is the mean reduction after the first cycle: the final residual is at
       * most the first one (< 1) times factor^(cycles-1) */
      if (m) TEST_TRUE(m->relres <= pow(m->factor, m->iterations - 1) * (1.0 + 1e-9));
    }
  }
  const srow *a4 = find(rows, n, "ball", 4, "cholmod"), *a8 = find(rows, n, "ball", 8, "cholmod");
  TEST_TRUE(a4 && a8 && a8->dofs > 2 * a4->dofs);
  const srow *g4 = find(rows, n, "ball", 4, "cg-mg"), *g8 = find(rows, n, "ball", 8, "cg-mg");
  const srow *j8 = find(rows, n, "ball", 8, "cg-jacobi");
  TEST_TRUE(g4 && g8 && j8);
  if (g4 && g8 && j8) {
    TEST_TRUE(g8->iterations <= 1.5 * g4->iterations);
    TEST_TRUE(g8->iterations < j8->iterations);
  }
  if (app_run("gnuplot --version > /dev/null 2>&1") == 0) {
    FILE *f = fopen(png, "rb");
    unsigned char magic[8] = {0};
    TEST_TRUE(f && fread(magic, 1, 8, f) == 8 && magic[1] == 'P' && magic[2] == 'N' &&
              magic[3] == 'G');
    if (f) fclose(f);
  }
  /* bad options: exit 2, nothing written */
  static const char *const bad[] = {
    "--sizes 8,4",
    "--sizes 1",
    "--solvers cholmod,foo",
    "--elements tet4",
    "--bodies ball,ball",
    "--rtol 0",
    "--clock sun",
    "--solvers cholmod,petsc-gamg", /* the PETSc solvers need --backend petsc */
    "--backend mpi",
#if !FCM_HAVE_PETSC
    "--backend petsc", /* not in this build */
#endif
  };
  for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
    remove(csv);
    snprintf(cmd, sizeof cmd, "'%s' %s --csv '%s' > /dev/null 2>&1", argv[1], bad[k], csv);
    TEST_TRUE(app_run(cmd) == 2);
    TEST_TRUE(!app_exists(csv));
  }
  return TEST_RESULT();
}
