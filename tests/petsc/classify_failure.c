/* Failures around the distributed classification end every process together with the message
 * (label mpi, 1 and 2 processes, under a timeout: a process left waiting in the classification
 * exchange would hang the test until the timeout fails it):
 * - phase 2 (fcm_petsc_simulation_create()): the last process fails before its rules build
 *   (its simulation options are invalid), the others wait in the exchange inside theirs;
 * - phase 1 (fcm_petsc_problem_create()): the last process's rules options are refused inside
 *   the rules build, before its per-cell loop (the exchange is still called, with the error);
 * in both, every process fails, and the others' message names the failing process and carries
 * its message. Then a valid problem on the same communicator is built (the processes are still
 * in step) and nothing is left allocated. */
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <stdio.h>
#include <stdlib.h>

static const char *scene =
    "{\"version\": 1, \"name\": \"classify_failure\","
    " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.6, -0.6, -0.6],"
    " \"max\": [0.6, 0.6, 0.6]}, \"cells\": [4, 4, 4]},"
    " \"geometry\": {\"shape\": \"ball\", \"center\": [0, 0, 0], \"radius\": 0.5,"
    " \"resolution\": 3},"
    " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3, \"density\": 1000},"
    " \"time\": {\"dt\": 0.01, \"duration\": 0.05},"
    " \"effects\": [{\"gravity\": {}}, {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0,"
    " 0.3], \"normal\": [0, 0, 1]}}}}]}";

/* The failure everywhere; on the other processes the message names the last one and contains
 * `what`, on the last one it contains `what` itself. */
static void check_failure(fcm_ctx *ctx, fcm_status s, int rank, int size, const char *what)
{
  TEST_TRUE(s != FCM_OK);
  const char *msg = fcm_ctx_error_message(ctx);
  TEST_TRUE(strstr(msg, what) != NULL);
  if (size > 1 && rank != size - 1) {
    char want[64];
    snprintf(want, sizeof want, "process %d of %d failed", size - 1, size);
    TEST_TRUE(strstr(msg, want) != NULL);
  }
  if (getenv("FCM_TEST_VERBOSE")) fprintf(stderr, "rank %d: %s\n", rank, msg);
  fcm_ctx_error_clear(ctx);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *sc = NULL;
  fcm_simulation *sim = NULL;
  fcm_mesh *mesh = NULL;
  fcm_geometry *geom = NULL;
  fcm_petsc_problem *P = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);

  /* 1. phase 2: the last process fails before its rules build */
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene, NULL, &sc));
  fcm_simulation_options so = fcm_simulation_options_default();
  if (rank == size - 1) so.max_steps = -5;
  fcm_status s =
      fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, sc, FCM_PETSC_PARTITION_AUTO, &so, &sim);
  TEST_TRUE(sim == NULL);
  check_failure(ctx, s, rank, size, "max_steps = -5");
  fcm_scene_destroy(&sc);

  /* 2. phase 1: the last process's rules options are refused inside the rules build */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, c[3] = {0.5, 0.5, 0.5};
  const fcm_index cells[3] = {4, 4, 4};
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &mesh));
  TEST_OK(ctx, fcm_geometry_create_ball(ctx, c, 0.4, 2, &geom));
  const fcm_material mat = {FCM_MATERIAL_LINEAR, 1e6, 0.3, 1000.0};
  fcm_petsc_options po = fcm_petsc_options_default();
  po.kind = FCM_INTEGRATOR_STATIC;
  if (rank == size - 1) po.rules.clip_rtol = 0.5;
  s = fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P);
  TEST_TRUE(P == NULL);
  check_failure(ctx, s, rank, size, "clip_rtol = 0.5");

  /* 3. still in step: a valid problem */
  po.rules.clip_rtol = fcm_cell_rules_options_default().clip_rtol;
  TEST_OK(ctx, fcm_petsc_problem_create(ctx, MPI_COMM_WORLD, mesh, geom, &mat, &po, &P));
  TEST_TRUE(P != NULL && fcm_petsc_problem_num_dofs(P) > 0);
  fcm_petsc_problem_destroy(&P);
  fcm_geometry_destroy(&geom);
  fcm_mesh_destroy(&mesh);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
