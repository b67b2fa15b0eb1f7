/* Shared by the tests that run a scene through the integrator on PETSc against the serial
 * fcm_simulation (newton.c, newton_cut.c): the comparison of two CSV logs
 * written by fcm_simulation_write_log(), and of two runs after their steps (compare_runs()). */
#ifndef FCM_TESTS_PETSC_LOG_COMPARE_H
#define FCM_TESTS_PETSC_LOG_COMPARE_H

#include "fcm/fcm.h"
#include "fcm/simulation.h"
#include "test.h"
#include "../sim/sim_util.h" /* vec_norm(), vec_dist() */

#include <mpi.h>
#include <unistd.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAXCOL 128
#define MAXROW 4096

/* A CSV log: header names and numeric rows. */
typedef struct table {
  int ncol, nrow;
  char name[MAXCOL][48];
  double *v; /* nrow x ncol */
} table;

static inline int read_table(const char *path, table *t)
{
  FILE *f = fopen(path, "r");
  char line[16384];
  memset(t, 0, sizeof *t);
  if (!f || !fgets(line, sizeof line, f)) {
    if (f) fclose(f);
    return 0;
  }
  for (char *tok = strtok(line, ",\n"); tok && t->ncol < MAXCOL; tok = strtok(NULL, ",\n"))
    snprintf(t->name[t->ncol++], sizeof t->name[0], "%s", tok);
  t->v = calloc((size_t)MAXROW * (size_t)t->ncol, sizeof *t->v);
  while (t->v && t->nrow < MAXROW && fgets(line, sizeof line, f)) {
    int c = 0;
    for (char *tok = strtok(line, ",\n"); tok && c < t->ncol; tok = strtok(NULL, ",\n"))
      t->v[(size_t)t->nrow * t->ncol + c++] = strtod(tok, NULL);
    t->nrow++;
  }
  fclose(f);
  return t->v != NULL;
}

static inline int starts(const char *s, const char *p)
{
  return strncmp(s, p, strlen(p)) == 0;
}

/* Compare the logs (process 0); the number of mismatches. */
static inline int compare_logs(const table *a, const table *b, double tol, double pscale)
{
  int bad = 0;
  if (a->ncol != b->ncol || a->nrow != b->nrow) {
    fprintf(stderr, "logs differ in shape: %d x %d vs %d x %d\n", a->nrow, a->ncol, b->nrow,
            b->ncol);
    return 1;
  }
  double rmax = 0.0, mmax = 0.0, pmax = pscale;
  for (int c = 0; c < a->ncol; c++)
    for (int r = 0; r < a->nrow; r++) {
      const double x = fmax(fabs(a->v[r * a->ncol + c]), fabs(b->v[r * b->ncol + c]));
      if (starts(a->name[c], "reaction_")) rmax = fmax(rmax, x);
      if (starts(a->name[c], "moment_")) mmax = fmax(mmax, x);
      if (starts(a->name[c], "momentum_")) pmax = fmax(pmax, x);
    }
  for (int c = 0; c < a->ncol; c++) {
    const char *nm = a->name[c];
    if (strcmp(nm, b->name[c]) != 0) {
      fprintf(stderr, "log column %d: %s vs %s\n", c, nm, b->name[c]);
      bad++;
      continue;
    }
    /* iteration counts, the final residual (round-off level) and wall times: not compared */
    if (starts(nm, "newton") || starts(nm, "linear") || starts(nm, "residual") ||
        starts(nm, "wall"))
      continue;
    const int exact = starts(nm, "step") || starts(nm, "pieces") || starts(nm, "inverted");
    double scale = 0.0;
    for (int r = 0; r < a->nrow; r++)
      scale = fmax(scale, fmax(fabs(a->v[r * a->ncol + c]), fabs(b->v[r * b->ncol + c])));
    if (starts(nm, "reaction_")) scale = rmax;
    if (starts(nm, "moment_")) scale = mmax;
    if (starts(nm, "momentum_")) scale = pmax;
    if (starts(nm, "time")) scale = fmax(scale, 1.0) * 1e-4; /* to 1e-12 absolute */
    for (int r = 0; r < a->nrow; r++) {
      const double x = a->v[r * a->ncol + c], y = b->v[r * b->ncol + c];
      if (isnan(x) && isnan(y)) continue; /* not known in either (a step without a frame) */
      if (exact ? x != y : !(fabs(x - y) <= tol * scale)) {
        fprintf(stderr, "log row %d column %s: serial %.17g, petsc %.17g (scale %g)\n", r + 1, nm,
                x, y, scale);
        bad++;
      }
    }
  }
  return bad;
}

/* After the steps (every process): the distributed run's displacement and velocity equal the
 * serial run's to tol relative and are bit for bit the same on every process; process 0
 * compares the two logs (steps rows; time and pieces exactly, the rest to tol of the column's
 * scale). */
static inline void compare_runs(fcm_ctx *ctx, fcm_simulation *ser, fcm_simulation *par, int steps,
                                double tol, int rank)
{
  fcm_integrator *is = fcm_simulation_integrator(ser), *ip = fcm_simulation_integrator(par);
  const fcm_index n = fcm_integrator_num_dofs(is);
  const double *us = fcm_integrator_displacement(is), *vs = fcm_integrator_velocity(is);
  const double *up = fcm_integrator_displacement(ip), *vp = fcm_integrator_velocity(ip);
  const double un = vec_norm(n, us), vn = vec_norm(n, vs);
  if (rank == 0 && getenv("FCM_TEST_VERBOSE"))
    fprintf(stderr, "|u| serial %.17g, petsc %.17g\n", un, vec_norm(n, up));
  TEST_TRUE(un > 0.0);
  const double du = vec_dist(n, up, us) / un;
  if (!(du <= tol)) fprintf(stderr, "rank %d: |u - u_serial| / |u_serial| = %g\n", rank, du);
  TEST_TRUE(du <= tol);
  if (vn > 0.0) TEST_TRUE(vec_dist(n, vp, vs) <= tol * vn);
  /* the same state, bit for bit, on every process */
  double *u0 = malloc(sizeof *u0 * (size_t)(2 * n));
  TEST_TRUE(u0 != NULL);
  if (u0) {
    memcpy(u0, up, sizeof *u0 * (size_t)n);
    memcpy(u0 + n, vp, sizeof *u0 * (size_t)n);
    MPI_Bcast(u0, (int)(2 * n), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    TEST_TRUE(memcmp(u0, up, sizeof *u0 * (size_t)n) == 0);
    TEST_TRUE(memcmp(u0 + n, vp, sizeof *u0 * (size_t)n) == 0);
    free(u0);
  }
  /* the logs */
  if (rank == 0) {
    char dir[] = "/tmp/fcm-petsc-logs-XXXXXX", la[128], lb[128];
    TEST_TRUE(mkdtemp(dir) != NULL);
    snprintf(la, sizeof la, "%s/serial.csv", dir);
    snprintf(lb, sizeof lb, "%s/petsc.csv", dir);
    TEST_OK(ctx, fcm_simulation_write_log(ser, la));
    TEST_OK(ctx, fcm_simulation_write_log(par, lb));
    table ta, tb;
    TEST_TRUE(read_table(la, &ta) && read_table(lb, &tb));
    TEST_TRUE(ta.nrow == steps);
    double vmax = 0.0, mass = 0.0;
    for (fcm_index i = 0; i < n; i++)
      vmax = fmax(vmax, fabs(vs[i]));
    for (int r = 0; r < ta.nrow; r++)
      for (int c = 0; c < ta.ncol; c++)
        if (strcmp(ta.name[c], "mass") == 0) mass = fmax(mass, ta.v[r * ta.ncol + c]);
    TEST_TRUE(compare_logs(&ta, &tb, tol, mass * vmax) == 0);
    free(ta.v), free(tb.v);
    remove(la), remove(lb), rmdir(dir);
  }
}

#endif /* FCM_TESTS_PETSC_LOG_COMPARE_H */
