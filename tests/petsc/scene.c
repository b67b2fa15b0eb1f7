/* Example scenes on the PETSc backend (label mpi; 1 and 2 processes): the scene's first steps
 * through fcm_petsc_problem_create_from_scene() give the displacement (and velocity) of the
 * serial fcm_simulation to 1e-8 relative — cantilever.json (static, Hex20, conforming) and
 * tests/petsc/scenes/vibrating_beam_euler.json (backward Euler, Hex8, embedded). The KSP runs to
 * rtol 1e-12 (set in the options database, as a user would with -ksp_rtol). Then a parallel VTU
 * frame: the .pvtu names one piece per process and the pieces hold every active cell once.
 * Arguments: scenes directory, scene file, steps. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <petscsys.h>
#include <unistd.h>

static double dist(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += (a[i] - b[i]) * (a[i] - b[i]);
  return sqrt(s);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  fcm_petsc_problem *P = NULL;
  char path[4096];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 4) return 2;
  const int steps = atoi(argv[3]);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  snprintf(path, sizeof path, "%s/%s", argv[1], argv[2]);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (PetscOptionsSetValue(NULL, "-ksp_rtol", "1e-12")) TEST_TRUE(0);

  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = steps;
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &sim));
  const fcm_index n = fcm_petsc_problem_num_dofs(P);
  fcm_integrator *integ = fcm_simulation_integrator(sim);
  TEST_TRUE(fcm_integrator_num_dofs(integ) == n);
  double *u = calloc((size_t)n, sizeof *u), *v = calloc((size_t)n, sizeof *v);
  for (int s = 0; s < steps; s++) {
    fcm_step_info si;
    fcm_petsc_step_info pi;
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
    TEST_OK(ctx, fcm_petsc_problem_step(P, &pi));
    TEST_NEAR(pi.time, fcm_integrator_time(integ), 1e-12, 0.0);
  }
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, u, v));
  const double *us = fcm_integrator_displacement(integ), *vs = fcm_integrator_velocity(integ);
  double un = 0.0, vn = 0.0;
  for (fcm_index i = 0; i < n; i++)
    un += us[i] * us[i], vn += vs[i] * vs[i];
  un = sqrt(un), vn = sqrt(vn);
  TEST_TRUE(un > 0.0);
  const double du = dist(n, u, us) / un;
  if (!(du <= 1e-8)) fprintf(stderr, "rank %d: |u - u_serial| / |u_serial| = %g\n", rank, du);
  TEST_TRUE(du <= 1e-8);
  if (vn > 0.0) TEST_TRUE(dist(n, v, vs) <= 1e-8 * vn);

  /* the parallel VTU: one piece per process with its own cells, all active cells in all */
  char dir[256] = "";
  if (rank == 0) {
    snprintf(dir, sizeof dir, "/tmp/fcm-petsc-frame-XXXXXX");
    if (!mkdtemp(dir)) dir[0] = '\0';
  }
  MPI_Bcast(dir, (int)sizeof dir, MPI_CHAR, 0, MPI_COMM_WORLD);
  TEST_TRUE(dir[0] != '\0');
  TEST_OK(ctx, fcm_petsc_problem_write_frame(P, dir, "frame"));
  if (rank == 0) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    char file[512], buf[4096];
    snprintf(file, sizeof file, "%s/frame.pvtu", dir);
    FILE *f = fopen(file, "r");
    size_t len = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    buf[len] = '\0';
    if (f) fclose(f);
    long long cells = 0;
    for (int r = 0; r < size; r++) {
      char piece[64];
      snprintf(piece, sizeof piece, "Source=\"frame_%d.vtu\"", r);
      TEST_TRUE(strstr(buf, piece) != NULL);
      snprintf(file, sizeof file, "%s/frame_%d.vtu", dir, r);
      FILE *g = fopen(file, "rb");
      char head[2048] = "";
      size_t hl = g ? fread(head, 1, sizeof head - 1, g) : 0;
      head[hl] = '\0';
      if (g) fclose(g);
      const char *nc = strstr(head, "NumberOfCells=\"");
      TEST_TRUE(nc != NULL);
      if (nc) cells += atoll(nc + strlen("NumberOfCells=\""));
      remove(file);
    }
    const fcm_space *sp = fcm_petsc_problem_space(P);
    long long active = 0;
    for (fcm_index c = 0; c < fcm_mesh_num_cells(fcm_space_mesh(sp)); c++)
      active += fcm_space_cell_active(sp, c);
    TEST_TRUE(cells == active);
    snprintf(file, sizeof file, "%s/frame.pvtu", dir);
    remove(file);
    rmdir(dir);
  }

  free(u), free(v);
  fcm_simulation_destroy(&sim);
  fcm_petsc_problem_destroy(&P);
  fcm_scene_destroy(&scene);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
