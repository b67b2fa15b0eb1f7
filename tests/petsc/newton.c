/* Example scenes through the integrator on PETSc (fcm_petsc_simulation_create(); label mpi, 1
 * and 2 processes) against the serial fcm_simulation of the same scene, step by step:
 * - the displacement and velocity after the steps equal the serial ones to `tol` relative
 *   (norm of the difference over the norm of the serial state), and are bit for bit the same
 *   on every process;
 * - each step's energies (kinetic, elastic, external work, total) equal the serial ones to
 *   tol relative to the step's energy scale;
 * - the log (fcm_simulation_write_log(), written by process 0 for both runs): the time and
 *   the pieces exactly, energy, mass, momentum and the reactions of every constraint to tol
 *   relative to the largest value of the column (reactions, moments, momentum: of all
 *   columns of the kind; momentum at least the mass times the largest speed);
 * - the distributed run's linear solves went through PETSc (iterations counted) while the
 *   serial one's matrices were never factored by PETSc (nothing more to check there).
 * Arguments: scenes directory, scene file, steps, [tol (default 1e-8)], then PETSc options.
 * The KSP runs to rtol 1e-12 (-ksp_rtol, as a user would set it). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/petsc.h"
#include "fcm/simulation.h"
#include "log_compare.h"
#include "test.h"

#include <petscsys.h>
#include <unistd.h>

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *ser = NULL, *par = NULL;
  char path[4096];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 4) return 2;
  int steps = atoi(argv[3]);
  const double tol = argc > 4 ? atof(argv[4]) : 1e-8;
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  snprintf(path, sizeof path, "%s/%s", argv[1], argv[2]);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (PetscOptionsSetValue(NULL, "-ksp_rtol", "1e-12")) TEST_TRUE(0);

  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = steps;
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, &so, &ser));
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           &so, &par));
  if (!ser || !par) {
    fcm_simulation_destroy(&ser);
    fcm_scene_destroy(&scene);
    fcm_ctx_destroy(&ctx);
    fcm_petsc_finalize();
    return 1;
  }
  if (fcm_simulation_num_steps(ser) < steps) steps = (int)fcm_simulation_num_steps(ser);
  fcm_integrator *is = fcm_simulation_integrator(ser), *ip = fcm_simulation_integrator(par);
  const fcm_index n = fcm_integrator_num_dofs(is);
  TEST_TRUE(fcm_integrator_num_dofs(ip) == n);
  long long linear = 0;
  for (int s = 0; s < steps && !test_failures_; s++) {
    fcm_step_info a, b;
    TEST_OK(ctx, fcm_simulation_step(ser, &a));
    TEST_OK(ctx, fcm_simulation_step(par, &b));
    TEST_NEAR(b.time, a.time, 1e-12, 0.0);
    const double scale =
        fabs(a.kinetic_energy) + fabs(a.elastic_energy) + fabs(a.external_work) + 1e-300;
    TEST_TRUE(fabs(a.kinetic_energy - b.kinetic_energy) <= tol * scale);
    TEST_TRUE(fabs(a.elastic_energy - b.elastic_energy) <= tol * scale);
    TEST_TRUE(fabs(a.external_work - b.external_work) <= tol * scale);
    TEST_TRUE(fabs(a.total_energy - b.total_energy) <= tol * scale);
    if (rank == 0 && getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "step %d: newton %d / %d, linear %lld, E %.12g / %.12g\n", s + 1,
              a.newton_iterations, b.newton_iterations, b.linear_iterations, a.total_energy,
              b.total_energy);
    linear += b.linear_iterations;
  }
  TEST_TRUE(linear > 0); /* the solves went through the KSP */
  compare_runs(ctx, ser, par, steps, tol, rank);

  fcm_simulation_destroy(&ser);
  fcm_simulation_destroy(&par);
  fcm_scene_destroy(&scene);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  int mine = test_failures_, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  fcm_petsc_finalize();
  return all ? TEST_RESULT() + 1 : 0;
}
