/* Scenes with cuts and with quadrature.simplify = "auto" through the integrator on PETSc
 * (fcm_petsc_simulation_create(); label mpi, 1 and 2 processes) against the serial
 * fcm_simulation of the same scene, step by step:
 * - each step's time and energies equal the serial ones (energies to `tol` of the step's
 *   energy scale);
 * - after each step the cut bookkeeping equals the serial run's exactly: cuts applied and
 *   missed, cells integrated again, separate bodies, DOFs, constrained DOFs, and the current
 *   rules' classification (uncut / cut cells, material pieces, split cells, links);
 * - the rules' simplification choice per kind equals the serial one; with "auto" and before
 *   any cut, its inputs too (points kept exactly, the modelled time to 1e-12 relative: the
 *   distributed run sums every process's cut cells);
 * - the displacement and velocity after the steps equal the serial ones to tol relative, and
 *   are bit for bit the same on every process, as is the DOF count;
 * - the logs (time and pieces exactly; energy, mass, momentum, reactions to tol of their
 *   column's scale), as tests/petsc/newton.c compares them.
 * Arguments: scenes directory, scene file, steps, [tol (default 1e-8)], then PETSc options.
 * The KSP runs to rtol 1e-12. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "log_compare.h"
#include "test_mpi.h"

#include <petscsys.h>
#include <unistd.h>

/* The cut bookkeeping of the two runs after a step: the number of differences (printed). */
static int compare_counters(fcm_simulation *ser, fcm_simulation *par, int step, int rank)
{
  fcm_simulation_counters a, b;
  fcm_simulation_get_counters(ser, &a);
  fcm_simulation_get_counters(par, &b);
  int bad = 0;
#define SAME(field)                                                                                \
  do {                                                                                             \
    if ((long long)a.field != (long long)b.field) {                                                \
      fprintf(stderr, "rank %d step %d: counter " #field ": serial %lld, petsc %lld\n", rank,      \
              step, (long long)a.field, (long long)b.field);                                       \
      bad++;                                                                                       \
    }                                                                                              \
  } while (0)
  SAME(cuts);
  SAME(cuts_missed);
  SAME(cut_cells);
  SAME(pieces);
  SAME(num_dofs);
  SAME(constrained_dofs);
#undef SAME
  const fcm_cell_rules *ra = fcm_simulation_cell_rules(ser), *rb = fcm_simulation_cell_rules(par);
  if (!ra || !rb) return bad + (ra != rb);
  const fcm_cell_rules_stats *sa = fcm_cell_rules_get_stats(ra), *sb = fcm_cell_rules_get_stats(rb);
#define SAME_STAT(field)                                                                           \
  do {                                                                                             \
    if ((long long)sa->field != (long long)sb->field) {                                            \
      fprintf(stderr, "rank %d step %d: rules " #field ": serial %lld, petsc %lld\n", rank, step,  \
              (long long)sa->field, (long long)sb->field);                                         \
      bad++;                                                                                       \
    }                                                                                              \
  } while (0)
  SAME_STAT(num_uncut);
  SAME_STAT(num_cut);
  SAME_STAT(num_dropped);
  SAME_STAT(num_material_pieces);
  SAME_STAT(num_split);
  SAME_STAT(num_links);
  for (int k = 0; k < FCM_RULE_KIND_COUNT; k++) {
    SAME_STAT(decision[k].simplified);
    if (a.cuts > 0) continue; /* a cut decides as the rules it extends: inputs are its own */
    const fcm_simplify_decision *da = &sa->decision[k], *db = &sb->decision[k];
    if (da->estimated_kept != db->estimated_kept ||
        !(fabs(da->estimated_time - db->estimated_time) <= 1e-12 * fabs(da->estimated_time)) ||
        da->expected_assemblies != db->expected_assemblies) {
      fprintf(stderr,
              "rank %d: kind %d: the choice's inputs differ: kept %.17g / %.17g, time %.17g / "
              "%.17g, assemblies %g / %g\n",
              rank, k, da->estimated_kept, db->estimated_kept, da->estimated_time,
              db->estimated_time, da->expected_assemblies, db->expected_assemblies);
      bad++;
    }
  }
#undef SAME_STAT
  return bad;
}

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
    fcm_simulation_destroy(&par);
    fcm_scene_destroy(&scene);
    fcm_ctx_destroy(&ctx);
    fcm_petsc_finalize();
    return 1;
  }
  if (fcm_simulation_num_steps(ser) < steps) steps = (int)fcm_simulation_num_steps(ser);
  TEST_TRUE(compare_counters(ser, par, 0, rank) == 0);
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
    TEST_TRUE(compare_counters(ser, par, s + 1, rank) == 0);
    if (rank == 0 && getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "step %d: newton %d / %d, linear %lld, DOFs %lld, E %.12g / %.12g\n", s + 1,
              a.newton_iterations, b.newton_iterations, b.linear_iterations,
              (long long)fcm_integrator_num_dofs(fcm_simulation_integrator(par)), a.total_energy,
              b.total_energy);
    linear += b.linear_iterations;
  }
  TEST_TRUE(linear > 0); /* the solves went through the KSP */
  fcm_integrator *is = fcm_simulation_integrator(ser), *ip = fcm_simulation_integrator(par);
  const fcm_index n = fcm_integrator_num_dofs(is);
  TEST_TRUE(fcm_integrator_num_dofs(ip) == n);
  {
    long long mine[2] = {(long long)n, -(long long)n}, all[2];
    MPI_Allreduce(mine, all, 2, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
    TEST_TRUE(all[0] == -all[1]); /* the same DOF count on every process */
  }
  compare_runs(ctx, ser, par, steps, tol, rank);

  fcm_simulation_destroy(&ser);
  fcm_simulation_destroy(&par);
  fcm_scene_destroy(&scene);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
