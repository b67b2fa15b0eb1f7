/* Checkpoints of the PETSc backend (label mpi; 1 and 2 processes): a dynamic embedded problem
 * (Hex8) saved after 2 of 4 steps and resumed on the same processes gives the uninterrupted run's
 * state to 1e-12 relative with the default solver (CG + GAMG; not asserted bit for bit: in some
 * runs GAMG's set-up on the resumed problem preconditions differently at round-off, with the
 * process's address layout — never with address randomization off) and with MUMPS, bit for bit
 * with MUMPS on one process (on several, MUMPS adds the contribution blocks of fronts in the
 * order their messages arrive, so two factorizations of the same matrix differ at round-off);
 * resumed on
 * process 0 alone (another process count) the same to 1e-10; a missing file is FCM_ERR_IO and a
 * checkpoint of another problem FCM_ERR_ARG, on every process. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "test_mpi.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const double grav[3] = {0.0, -9.81, 0.0};

static fcm_petsc_problem *make(fcm_ctx *ctx, MPI_Comm comm, const fcm_mesh *mesh,
                               const fcm_geometry *geom, fcm_integrator_kind kind,
                               const char *solver)
{
  fcm_petsc_problem *P = NULL;
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, 1000.0};
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = kind;
  po.dt = 0.01;
  po.solver.petsc_options = solver;
  po.solver.rtol = 1e-12;
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, comm, mesh, geom, &mat, &po, &P));
  const double *X = fcm_mesh_coords(mesh);
  fcm_index nn = fcm_mesh_num_nodes(mesh), *fix = calloc((size_t)nn, sizeof *fix), nfix = 0;
  for (fcm_index k = 0; k < nn; k++)
    if (X[3 * k] == 0.0) fix[nfix++] = k;
  const fcm_motion clamp = fcm_motion_default();
  TEST_OK(ctx, fcm_petsc_problem_add_gravity(P, grav));
  TEST_OK(ctx, fcm_petsc_problem_add_constraint(P, nfix, fix, &clamp));
  TEST_OK(ctx, fcm_petsc_problem_setup(P));
  free(fix);
  return P;
}

/* Run 4 steps saving after 2, resume on the same processes and on process 0 alone; bitwise:
 * the same-count resume must equal the uninterrupted run bit for bit. */
static void run_case(fcm_ctx *ctx, const fcm_mesh *mesh, const fcm_geometry *geom, int rank,
                     const char *dir, const char *solver, int bitwise)
{
  char path[512];
  snprintf(path, sizeof path, "%s/run.ck", dir);
  /* the uninterrupted run, saved after 2 steps */
  fcm_petsc_problem *P =
      make(ctx, MPI_COMM_WORLD, mesh, geom, FCM_INTEGRATOR_BACKWARD_EULER, solver);
  const fcm_index n = fcm_petsc_problem_num_dofs(P);
  double *u = calloc((size_t)n, sizeof *u), *v = calloc((size_t)n, sizeof *v);
  double *u2 = calloc((size_t)n, sizeof *u2), *v2 = calloc((size_t)n, sizeof *v2);
  for (int s = 0; s < 4; s++) {
    TEST_OK(ctx, fcm_petsc_problem_step(P, NULL));
    if (s == 1) TEST_OK(ctx, fcm_petsc_problem_write_checkpoint(P, path));
  }
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, u, v));
  fcm_petsc_problem_destroy(&P);

  /* resumed on the same processes: bit for bit where the solver is reproducible */
  P = make(ctx, MPI_COMM_WORLD, mesh, geom, FCM_INTEGRATOR_BACKWARD_EULER, solver);
  TEST_OK(ctx, fcm_petsc_problem_read_checkpoint(P, path));
  TEST_TRUE(fcm_petsc_problem_step_count(P) == 2);
  fcm_petsc_step_info si;
  memset(&si, 0, sizeof si);
  for (int s = 0; s < 2; s++)
    TEST_OK(ctx, fcm_petsc_problem_step(P, &si));
  TEST_NEAR(si.time, 0.04, 1e-14, 0.0);
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, u2, v2));
  double du = 0.0, nu = 0.0, dv = 0.0, nv = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    du = fmax(du, fabs(u[i] - u2[i])), nu = fmax(nu, fabs(u[i]));
    dv = fmax(dv, fabs(v[i] - v2[i])), nv = fmax(nv, fabs(v[i]));
  }
  const int same =
      !memcmp(u, u2, sizeof(double) * (size_t)n) && !memcmp(v, v2, sizeof(double) * (size_t)n);
  if (bitwise) TEST_TRUE(same);
  TEST_TRUE(du <= 1e-12 * nu && dv <= 1e-12 * nv);
  if (getenv("FCM_TEST_VERBOSE") && rank == 0)
    printf("%s: resume %s (max |du| %.3g, |dv| %.3g)\n", solver ? solver : "default",
           same ? "bit for bit" : "differs at round-off", du, dv);
  /* errors, on every process */
  snprintf(path + strlen(path), sizeof path - strlen(path), ".missing");
  TEST_ERR(ctx, fcm_petsc_problem_read_checkpoint(P, path), FCM_ERR_IO, "cannot open");
  path[strlen(path) - strlen(".missing")] = '\0';
  fcm_petsc_problem_destroy(&P);
  P = make(ctx, MPI_COMM_WORLD, mesh, geom, FCM_INTEGRATOR_STATIC, solver);
  TEST_ERR(ctx, fcm_petsc_problem_read_checkpoint(P, path), FCM_ERR_ARG, "another problem");
  fcm_petsc_problem_destroy(&P);

  /* resumed on process 0 alone (another process count when run on 2) */
  MPI_Comm solo;
  MPI_Comm_split(MPI_COMM_WORLD, rank == 0 ? 0 : MPI_UNDEFINED, 0, &solo);
  if (rank == 0) {
    P = make(ctx, solo, mesh, geom, FCM_INTEGRATOR_BACKWARD_EULER, solver);
    TEST_OK(ctx, fcm_petsc_problem_read_checkpoint(P, path));
    for (int s = 0; s < 2; s++)
      TEST_OK(ctx, fcm_petsc_problem_step(P, NULL));
    TEST_OK(ctx, fcm_petsc_problem_get_state(P, u2, v2));
    double d = 0.0, m = 0.0;
    for (fcm_index i = 0; i < n; i++)
      d += (u[i] - u2[i]) * (u[i] - u2[i]), m += u[i] * u[i];
    TEST_TRUE(m > 0.0 && sqrt(d) <= 1e-10 * sqrt(m));
    fcm_petsc_problem_destroy(&P);
    MPI_Comm_free(&solo);
    remove(path);
  }

  free(u), free(v), free(u2), free(v2);
  MPI_Barrier(MPI_COMM_WORLD);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 1};
  const double glo[3] = {0.0, 0.07, 0.11}, ghi[3] = {1.83, 0.91, 0.94};
  const fcm_index cells[3] = {6, 3, 3}, gn[3] = {3, 2, 2};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_box(ctx, glo, ghi, gn, &geom));
  char dir[256] = "";
  if (rank == 0) {
    snprintf(dir, sizeof dir, "/tmp/fcm-petsc-ckpt-XXXXXX");
    if (!mkdtemp(dir)) dir[0] = '\0';
  }
  MPI_Bcast(dir, (int)sizeof dir, MPI_CHAR, 0, MPI_COMM_WORLD);
  TEST_TRUE(dir[0] != '\0');
  /* the default solver (CG + GAMG, rigid-body near-null space): to round-off (see the top) */
  run_case(ctx, mesh, geom, rank, dir, NULL, 0);
  /* MUMPS: bit for bit on one process only (see the top) */
  run_case(ctx, mesh, geom, rank, dir,
           "-ksp_type preonly -pc_type cholesky -pc_factor_mat_solver_type mumps", size == 1);
  if (rank == 0) rmdir(dir);

  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
