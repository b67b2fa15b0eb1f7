/* Checkpoints of the PETSc linear driver's older format (.fcmpk, fcm_petsc_problem_write_
 * checkpoint()) load into a scene's simulation through fcm_simulation_read_checkpoint(), the one
 * reader of the serial and the PETSc runs (label mpi; 1 and 2 processes). vibrating_beam.json:
 * the linear driver takes K steps and writes its checkpoint; then
 *  - the integrator on PETSc (fcm_petsc_simulation_create()) and the serial fcm_simulation read
 *    it: the state bit for bit the driver's, the time and step count its own, the log rows of the
 *    K steps (time k dt, the other columns NaN) and the frames the driver's run wrote (steps 0,
 *    frame_interval, ... <= K);
 *  - both simulations' next step agrees with the linear driver's next step to 1e-8 (KSP rtol
 *    1e-12), and the serial and distributed states to 1e-10;
 *  - a file of another problem (dt changed) is refused naming it; a truncated one is a format
 *    error.
 * Arguments: scenes directory, scene file, K, work file prefix <p> (the checkpoint is
 * <p>_np<processes>.fcmpk), and "keep" to leave that file for a later run (fcm-sim --resume). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <petscsys.h>
#include <string.h>

static double rel_dist(fcm_index n, const double *a, const double *b)
{
  double s = 0.0, r = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    s += (a[i] - b[i]) * (a[i] - b[i]);
    r += b[i] * b[i];
  }
  return sqrt(s) / (sqrt(r) > 0.0 ? sqrt(r) : 1.0);
}

/* Process 0 copies the first `keep` bytes of src to dst, changing the 8 bytes at `patch` (if
 * >= 0) into the double x, once every process has done with dst; every process waits for it. */
static void copy_file(const char *src, const char *dst, long keep, long patch, double x, int rank)
{
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    FILE *f = fopen(src, "rb"), *g = fopen(dst, "wb");
    TEST_TRUE(f && g);
    for (long k = 0; f && g && k < keep; k++) {
      int c = fgetc(f);
      if (patch >= 0 && k >= patch && k < patch + 8) c = ((unsigned char *)&x)[k - patch];
      fputc(c, g);
    }
    if (f) fclose(f);
    if (g) fclose(g);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

/* Restore `path` into sim and check it against the driver's state (u, v, t after k steps). */
static void check_restored(fcm_ctx *ctx, fcm_simulation *sim, const char *path, fcm_index n,
                           const double *u, const double *v, double t, long long k, int every)
{
  TEST_OK(ctx, fcm_simulation_read_checkpoint(sim, path));
  fcm_integrator *integ = fcm_simulation_integrator(sim);
  TEST_TRUE(fcm_integrator_num_dofs(integ) == n);
  TEST_TRUE(memcmp(fcm_integrator_displacement(integ), u, sizeof *u * (size_t)n) == 0);
  TEST_TRUE(memcmp(fcm_integrator_velocity(integ), v, sizeof *v * (size_t)n) == 0);
  TEST_TRUE(fcm_integrator_time(integ) == t);
  TEST_TRUE(fcm_simulation_step_count(sim) == k);
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  TEST_TRUE(c.steps == k && c.frames == k / every + 1);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *dist = NULL, *serial = NULL, *other = NULL;
  fcm_petsc_problem *P = NULL;
  char path[4096], ck[4200], bad[4200];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 5) return 2;
  const long long K = atoll(argv[3]);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  snprintf(path, sizeof path, "%s/%s", argv[1], argv[2]);
  snprintf(ck, sizeof ck, "%s_np%d.fcmpk", argv[4], size);
  snprintf(bad, sizeof bad, "%s_np%d_bad.fcmpk", argv[4], size);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (PetscOptionsSetValue(NULL, "-ksp_rtol", "1e-12")) TEST_TRUE(0);
  const int every = fcm_scene_get_output(scene)->frame_interval > 0
                        ? fcm_scene_get_output(scene)->frame_interval
                        : 1;

  /* the linear driver: K steps, its checkpoint, its state, one step more */
  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  const fcm_index n = fcm_petsc_problem_num_dofs(P);
  double *u = calloc((size_t)n + 1, sizeof *u), *v = calloc((size_t)n + 1, sizeof *v);
  double *u1 = calloc((size_t)n + 1, sizeof *u1), *v1 = calloc((size_t)n + 1, sizeof *v1);
  TEST_TRUE(u && v && u1 && v1);
  fcm_petsc_step_info pi;
  for (long long k = 0; k < K; k++)
    TEST_OK(ctx, fcm_petsc_problem_step(P, &pi));
  const double t = pi.time;
  TEST_OK(ctx, fcm_petsc_problem_write_checkpoint(P, ck));
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, u, v));
  TEST_OK(ctx, fcm_petsc_problem_step(P, &pi));
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, u1, v1));

  /* the integrator on PETSc and the serial simulation read it */
  TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                           NULL, &dist));
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &serial));
  check_restored(ctx, dist, ck, n, u, v, t, K, every);
  check_restored(ctx, serial, ck, n, u, v, t, K, every);
  fcm_step_info si;
  TEST_OK(ctx, fcm_simulation_step(dist, &si));
  TEST_OK(ctx, fcm_simulation_step(serial, &si));
  const fcm_integrator *id = fcm_simulation_integrator(dist);
  const fcm_integrator *is = fcm_simulation_integrator(serial);
  TEST_NEAR(fcm_integrator_time(id), pi.time, 1e-14, 0.0);
  const double eu = rel_dist(n, fcm_integrator_displacement(id), u1);
  const double ev = rel_dist(n, fcm_integrator_velocity(id), v1);
  const double es = rel_dist(n, fcm_integrator_displacement(id), fcm_integrator_displacement(is));
  if (rank == 0)
    printf("step %lld after the restore: |u - u_driver| %.3g, |v - v_driver| %.3g, "
           "|u - u_serial| %.3g (relative)\n",
           K + 1, eu, ev, es);
  TEST_TRUE(eu < 1e-8 && ev < 1e-8 && es < 1e-10);

  /* another problem's file: dt (the second double after the 48 bytes of magic and integers) */
  copy_file(ck, bad, 64 + 16 * (long)n, 16 + 32 + 8, 0.5, rank);
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &other));
  TEST_ERR(ctx, fcm_simulation_read_checkpoint(other, bad), FCM_ERR_ARG, "another problem");
  fcm_simulation_destroy(&other);
  /* truncated: the last velocity value missing */
  copy_file(ck, bad, 64 + 16 * (long)n - 8, -1, 0.0, rank);
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &other));
  TEST_ERR(ctx, fcm_simulation_read_checkpoint(other, bad), FCM_ERR_FORMAT, "truncated");

  MPI_Barrier(MPI_COMM_WORLD); /* every process has read the files */
  if (rank == 0) {
    if (!(argc > 5 && strcmp(argv[5], "keep") == 0)) remove(ck);
    remove(bad);
  }
  free(u);
  free(v);
  free(u1);
  free(v1);
  fcm_simulation_destroy(&other);
  fcm_simulation_destroy(&serial);
  fcm_simulation_destroy(&dist);
  fcm_petsc_problem_destroy(&P);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
