/* Errors of the integrator on PETSc (fcm_petsc_simulation_create()) end every process together
 * with the message (label mpi, 1 and 2 processes, under a timeout: a process left waiting in a
 * collective call would hang the test until the timeout fails it):
 * - the cut-cell rules fail on ONE process only (the last one's scene caps the rule memory at
 *   a few bytes): create fails on every process, the others' message names the failing
 *   process and carries its message;
 * - a boundary constraint that selects no embedded-boundary point (known only after the
 *   processes' point counts are summed, inside the integrator's setup): FCM_ERR_ARG
 *   everywhere;
 * - a KSP that cannot converge (CG without preconditioner, 2 iterations): the integrator
 *   halves the step, then fails with FCM_ERR_NOT_CONVERGED (linear-solver-failed) on every
 *   process;
 * - a cut between steps that fails on one process only (its cut surface file broken after the
 *   create): the step of the cut fails on every process, the others naming the failing one;
 * - resuming a run with cuts from checkpoints that differ in their cuts between the processes
 *   (on 3 processes 0, 1 and 2 cuts), and from a checkpoint the last process cannot read
 *   (truncated): every process fails before the cut replay (collective), no hang. */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static const char *scene_text(char *buf, size_t size, const char *extra_quadrature,
                              const char *effects, const char *solver)
{
  snprintf(buf, size,
           "{\"version\": 1, \"name\": \"fail\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [-0.6, -0.6, -0.6],"
           " \"max\": [0.6, 0.6, 0.6]}, \"cells\": [4, 4, 4]},"
           " \"geometry\": {\"shape\": \"ball\", \"center\": [0, 0, 0], \"radius\": 0.5,"
           " \"resolution\": 3},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e5, \"poisson\": 0.3,"
           " \"density\": 1000},"
           " \"quadrature\": {%s}, \"solver\": {%s},"
           " \"time\": {\"dt\": 0.01, \"duration\": 0.05},"
           " \"effects\": [{\"gravity\": {}}%s]}",
           extra_quadrature, solver, effects);
  return buf;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  char text[4096];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const char *fix = ", {\"fixed\": {\"region\": {\"half_space\": {\"point\": [0, 0, 0.3],"
                    " \"normal\": [0, 0, 1]}}}}";

  /* 1. the rules fail on the last process only */
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx,
                   scene_text(text, sizeof text,
                              rank == size - 1 ? "\"max_rule_memory_gib\": 1e-9" : "", fix, ""),
                   NULL, &scene));
  fcm_status s =
      fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO, NULL, &sim);
  TEST_TRUE(s != FCM_OK && sim == NULL);
  if (size > 1 && rank != size - 1) {
    char want[64];
    snprintf(want, sizeof want, "process %d of %d failed", size - 1, size);
    TEST_TRUE(strstr(fcm_ctx_error_message(ctx), want) != NULL);
  }
  if (getenv("FCM_TEST_VERBOSE"))
    fprintf(stderr, "rank %d: case 1: %s\n", rank, fcm_ctx_error_message(ctx));
  fcm_ctx_error_clear(ctx);
  fcm_scene_destroy(&scene);

  /* 2. a boundary constraint without points (summed over the processes) */
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx,
                   scene_text(text, sizeof text, "",
                              ", {\"fixed\": {\"boundary\": {\"half_space\": {\"point\": [0, 0, "
                              "0.9], \"normal\": [0, 0, 1]}}}}",
                              ""),
                   NULL, &scene));
  TEST_ERR(
      ctx,
      fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO, NULL, &sim),
      FCM_ERR_ARG, "selects no embedded-boundary point");
  fcm_scene_destroy(&scene);

  /* 3. a KSP that cannot converge: the step fails everywhere after its halvings */
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx,
                   scene_text(text, sizeof text, "", fix,
                              "\"method\": \"cg\", \"petsc_options\": \"-ksp_type cg -pc_type "
                              "none -ksp_max_it 2\""),
                   NULL, &scene));
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           NULL, &sim));
  fcm_step_info si;
  TEST_ERR(ctx, fcm_simulation_step(sim, &si), FCM_ERR_NOT_CONVERGED, "linear-solver-failed");
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  /* 4. a cut between steps that fails on the last process only (its cut surface file is
   * read at the create, then broken before the cut): every process returns the error at the
   * step of the cut, the others naming the failing process; no hang */
  char obj[128];
  snprintf(obj, sizeof obj, "/tmp/fcm-petsc-newton-failure-%ld-%d.obj", (long)getpid(), rank);
  FILE *f = fopen(obj, "w");
  TEST_TRUE(f != NULL);
  if (f) {
    fputs("v 0.05 -1 -1\nv 0.05 1 -1\nv 0.05 1 1\nv 0.05 -1 1\nf 1 2 3\nf 1 3 4\n", f);
    fclose(f);
  }
  char cut[256];
  snprintf(cut, sizeof cut, ", {\"cut\": {\"time\": 0.01, \"surface\": {\"mesh\": \"%s\"}}}", obj);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_text(text, sizeof text, "", cut, ""), NULL,
                                            &scene));
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           NULL, &sim));
  if (rank == size - 1 && (f = fopen(obj, "w")) != NULL) {
    fputs("this is not a surface\n", f);
    fclose(f);
  }
  if (sim) {
    TEST_OK(ctx, fcm_simulation_step(sim, &si)); /* to t = 0.01: no cut yet */
    s = fcm_simulation_step(sim, &si);           /* the cut at t = 0.01 first */
    TEST_TRUE(s != FCM_OK);
    if (size > 1 && rank != size - 1) {
      char want[64];
      snprintf(want, sizeof want, "process %d of %d failed", size - 1, size);
      TEST_TRUE(strstr(fcm_ctx_error_message(ctx), want) != NULL);
    }
    if (getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "rank %d: case 4: %s\n", rank, fcm_ctx_error_message(ctx));
    fcm_ctx_error_clear(ctx);
  }
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);

  /* 5. resume a run with two cuts (t = 0.01, 0.02): checkpoints ck[k] with k cuts (steps 1 to
   * 3) */
  char ck[3][128], obj2[128], cuts2[512];
  for (int k = 0; k < 3; k++)
    snprintf(ck[k], sizeof ck[k], "/tmp/fcm-petsc-newton-failure-%ld-%d-%d.fcmck", (long)getpid(),
             rank, k);
  snprintf(obj2, sizeof obj2, "/tmp/fcm-petsc-newton-failure-%ld-%d-b.obj", (long)getpid(), rank);
  if ((f = fopen(obj, "w")) != NULL) { /* case 4 broke it on the last process */
    fputs("v 0.05 -1 -1\nv 0.05 1 -1\nv 0.05 1 1\nv 0.05 -1 1\nf 1 2 3\nf 1 3 4\n", f);
    fclose(f);
  }
  if ((f = fopen(obj2, "w")) != NULL) {
    fputs("v -0.25 -1 -1\nv -0.25 1 -1\nv -0.25 1 1\nv -0.25 -1 1\nf 1 2 3\nf 1 3 4\n", f);
    fclose(f);
  }
  snprintf(cuts2, sizeof cuts2, "%s, {\"cut\": {\"time\": 0.02, \"surface\": {\"mesh\": \"%s\"}}}",
           cut, obj2);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, scene_text(text, sizeof text, "", cuts2, ""), NULL,
                                            &scene));
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           NULL, &sim));
  for (int k = 0; k < 3 && sim; k++) { /* steps 2 and 3 apply a cut first */
    TEST_OK(ctx, fcm_simulation_step(sim, &si));
    TEST_OK(ctx, fcm_simulation_write_checkpoint(sim, ck[k]));
  }
  fcm_simulation_destroy(&sim);
  /* 5a. the whole file resumes on every process (both cuts replayed) */
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           NULL, &sim));
  TEST_OK(ctx, fcm_simulation_read_checkpoint(sim, ck[2]));
  TEST_OK(ctx, fcm_simulation_step(sim, &si));
  fcm_simulation_destroy(&sim);
  /* 5b. process r reads ck[r mod 3] (0, 1 and 2 cuts on 3 processes: the mean equals one
   * process's count); 5c. the last process's ck[2] is truncated, every process reads ck[2] */
  for (int c = 0; c < 2; c++) {
    if (c == 1 && rank == size - 1 && truncate(ck[2], 64) != 0) TEST_TRUE(0);
    MPI_Barrier(MPI_COMM_WORLD);
    TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                             NULL, &sim));
    s = fcm_simulation_read_checkpoint(sim, c == 0 ? ck[rank % 3] : ck[2]);
    if (c == 0) {
      TEST_TRUE(s != FCM_OK || size == 1);
      if (size > 1)
        TEST_TRUE(strstr(fcm_ctx_error_message(ctx), "different numbers of cuts") != NULL);
    } else {
      TEST_TRUE(s != FCM_OK);
      if (size == 1) TEST_TRUE(s == FCM_ERR_FORMAT);
      if (size > 1 && rank != size - 1) {
        char want[64];
        snprintf(want, sizeof want, "process %d of %d failed", size - 1, size);
        TEST_TRUE(strstr(fcm_ctx_error_message(ctx), want) != NULL);
      }
    }
    if (getenv("FCM_TEST_VERBOSE"))
      fprintf(stderr, "rank %d: case 5%c: %s\n", rank, 'b' + c, fcm_ctx_error_message(ctx));
    fcm_ctx_error_clear(ctx);
    fcm_simulation_destroy(&sim);
  }
  fcm_scene_destroy(&scene);
  for (int k = 0; k < 3; k++)
    remove(ck[k]);
  remove(obj);
  remove(obj2);

  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
