/* A linear scene on the PETSc backend's two paths (labels bench, mpi: not in the default run):
 * the linear driver (fcm_petsc_problem_create_from_scene(), its own steps) against the
 * integrator on PETSc (fcm_petsc_simulation_create(), fcm_simulation_step(): the path of
 * fcm-sim --backend petsc for every scene). Prints the set-up and the time per step of each,
 * best of `repeats` runs, with the Newton and KSP iterations; asserts that both end in the same
 * state to 1e-8 relative (both KSPs to rtol 1e-12). PETSc options after the arguments reach
 * both (the integrator path's solver is the scene's: MUMPS for solver.method direct, the
 * default; -ksp_type cg -pc_type gamg makes it the linear driver's). Arguments: scene file,
 * steps, repeats. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <petscsys.h>

typedef struct path_time {
  double setup, step;    /* seconds: the best run's set-up, the best run's time per step */
  long long newton, ksp; /* iterations over the steps */
} path_time;

/* One run of the linear driver: its time into *t (keeping the best), its state into u, v. */
static void run_driver(fcm_ctx *ctx, const fcm_scene *scene, int steps, path_time *t, double *u,
                       double *v)
{
  fcm_petsc_problem *P = NULL;
  MPI_Barrier(MPI_COMM_WORLD);
  const double t0 = fcm_wtime();
  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  const double t1 = fcm_wtime();
  long long ksp = 0;
  for (int k = 0; P && k < steps; k++) {
    fcm_petsc_step_info si;
    TEST_OK(ctx, fcm_petsc_problem_step(P, &si));
    ksp += si.iterations;
  }
  const double t2 = fcm_wtime();
  if (P) TEST_OK(ctx, fcm_petsc_problem_get_state(P, u, v));
  fcm_petsc_problem_destroy(&P);
  if (t->setup == 0.0 || t1 - t0 < t->setup) t->setup = t1 - t0;
  if (t->step == 0.0 || (t2 - t1) / steps < t->step) t->step = (t2 - t1) / steps;
  t->newton = steps, t->ksp = ksp;
}

/* One run of the integrator on PETSc, likewise. */
static void run_integrator(fcm_ctx *ctx, const fcm_scene *scene, int steps, path_time *t, double *u,
                           double *v, fcm_index n)
{
  fcm_simulation *S = NULL;
  MPI_Barrier(MPI_COMM_WORLD);
  const double t0 = fcm_wtime();
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           NULL, &S));
  const double t1 = fcm_wtime();
  long long newton = 0, ksp = 0;
  for (int k = 0; S && k < steps; k++) {
    fcm_step_info si;
    TEST_OK(ctx, fcm_simulation_step(S, &si));
    newton += si.newton_iterations, ksp += si.linear_iterations;
  }
  const double t2 = fcm_wtime();
  if (S) {
    const fcm_integrator *integ = fcm_simulation_integrator(S);
    TEST_TRUE(fcm_integrator_num_dofs(integ) == n);
    memcpy(u, fcm_integrator_displacement(integ), sizeof *u * (size_t)n);
    memcpy(v, fcm_integrator_velocity(integ), sizeof *v * (size_t)n);
  }
  fcm_simulation_destroy(&S);
  if (t->setup == 0.0 || t1 - t0 < t->setup) t->setup = t1 - t0;
  if (t->step == 0.0 || (t2 - t1) / steps < t->step) t->step = (t2 - t1) / steps;
  t->newton = newton, t->ksp = ksp;
}

static double rel_dist(fcm_index n, const double *a, const double *b)
{
  double s = 0.0, r = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    s += (a[i] - b[i]) * (a[i] - b[i]);
    r += b[i] * b[i];
  }
  return sqrt(s) / (r > 0.0 ? sqrt(r) : 1.0);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_petsc_problem *P = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 4) return 2;
  const int steps = atoi(argv[2]), repeats = atoi(argv[3]);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, argv[1], &scene));
  if (PetscOptionsSetValue(NULL, "-ksp_rtol", "1e-12")) TEST_TRUE(0);
  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  const fcm_index n = fcm_petsc_problem_num_dofs(P);
  fcm_petsc_problem_destroy(&P);
  double *ud = calloc((size_t)n + 1, sizeof *ud), *vd = calloc((size_t)n + 1, sizeof *vd);
  double *ui = calloc((size_t)n + 1, sizeof *ui), *vi = calloc((size_t)n + 1, sizeof *vi);
  TEST_TRUE(ud && vd && ui && vi);
  path_time d = {0}, in = {0};
  for (int r = 0; r < repeats; r++) {
    run_driver(ctx, scene, steps, &d, ud, vd);
    run_integrator(ctx, scene, steps, &in, ui, vi, n);
  }
  const double eu = rel_dist(n, ui, ud), ev = rel_dist(n, vi, vd);
  if (rank == 0) {
    printf("scene %s, %lld DOFs, %d process%s, %d steps, best of %d\n", fcm_scene_name(scene),
           (long long)n, size, size > 1 ? "es" : "", steps, repeats);
    printf("  linear driver  set-up %.3f s, step %.4f s (KSP %lld)\n", d.setup, d.step, d.ksp);
    printf("  integrator     set-up %.3f s, step %.4f s (Newton %lld, KSP %lld)\n", in.setup,
           in.step, in.newton, in.ksp);
    printf("  ratio          set-up %.2f, step %.2f; states differ by %.2g (u), %.2g (v)\n",
           in.setup / d.setup, in.step / d.step, eu, ev);
  }
  TEST_TRUE(eu < 1e-8 && ev < 1e-8);
  free(ud);
  free(vd);
  free(ui);
  free(vi);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
