/* Checkpoints of the PETSc linear driver (fcm_petsc_problem_write_checkpoint(): the checkpoint
 * container of the scene runs with the "no scene" source) and of its older format (.fcmpk, which
 * the library no longer writes: old_writer() below writes it) load into a scene's simulation
 * through fcm_simulation_read_checkpoint(), the one reader of the serial and the PETSc runs, and
 * into the driver through fcm_petsc_problem_read_checkpoint() (label mpi; 1 and 2 processes).
 * vibrating_beam_euler.json (tests/petsc/scenes: backward Euler): the linear driver takes K steps
 * and writes its checkpoint; then
 *  - the integrator on PETSc (fcm_petsc_simulation_create()) and the serial fcm_simulation read
 *    either file: the state bit for bit the driver's, the time and step count its own, the log
 *    rows of the K steps (time k dt, the other columns NaN) and the frames the driver's run wrote
 *    (steps 0, frame_interval, ... <= K);
 *  - both simulations' next step agrees with the linear driver's next step to 1e-8 (KSP rtol
 *    1e-12), and the serial and distributed states to 1e-10;
 *  - a new driver reads either file: the state bit for bit, the step count K;
 *  - files of another problem (dt changed; the container resealed with a valid checksum) are
 *    refused naming it; truncated and corrupted ones are format errors; the driver refuses a
 *    scene run's checkpoint.
 * Arguments: scenes directory, scene file, K, work file prefix <p> (the checkpoints are
 * <p>_np<processes>.fcmck and, of the older format, <p>_np<processes>.fcmpk), and "keep" to leave
 * both for a later run (fcm-sim --resume). */
#define _POSIX_C_SOURCE 200809L
#include "fcm/fcm.h"
#include "fcm/scene_petsc.h"
#include "fcm/simulation.h"
#include "test_mpi.h"

#include <petscsys.h>
#include <stdint.h>
#include <stdlib.h>
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

/* The whole file `path` (malloc'd; *size its length), NULL if unreadable. */
static unsigned char *slurp(const char *path, long *size)
{
  FILE *f = fopen(path, "rb");
  unsigned char *b = NULL;
  *size = -1;
  if (f && fseek(f, 0, SEEK_END) == 0 && (*size = ftell(f)) > 0 && fseek(f, 0, SEEK_SET) == 0) {
    b = malloc((size_t)*size);
    if (b && fread(b, 1, (size_t)*size, f) != (size_t)*size) free(b), b = NULL;
  }
  if (f) fclose(f);
  return b;
}

/* FNV-1a 64 (the container's checksum), written out here as the format defines it. */
static uint64_t fnv1a(const unsigned char *p, size_t n)
{
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t k = 0; k < n; k++)
    h = (h ^ p[k]) * 0x100000001b3ull;
  return h;
}

/* Process 0 copies the first `keep` bytes of src to dst, changing the 8 bytes at `patch` (if
 * >= 0) into the double x and, if `reseal`, the last 8 bytes into the checksum of those before
 * them, once every process has done with dst; every process waits for it. */
static void copy_file(const char *src, const char *dst, long keep, long patch, double x, int reseal,
                      int rank)
{
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    long size = 0;
    unsigned char *b = slurp(src, &size);
    FILE *g = fopen(dst, "wb");
    TEST_TRUE(b && g && keep <= size && keep >= 8);
    if (b && g && keep <= size && keep >= 8) {
      if (patch >= 0) memcpy(b + patch, &x, sizeof x);
      if (reseal) {
        const uint64_t sum = fnv1a(b, (size_t)keep - 8);
        memcpy(b + keep - 8, &sum, sizeof sum);
      }
      TEST_TRUE(fwrite(b, 1, (size_t)keep, g) == (size_t)keep);
    }
    free(b);
    if (g) fclose(g);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

/* The linear driver's older checkpoint format, which the library no longer writes (process 0):
 * the 16 bytes "fcm-petsc-ck-1\n\0"; int64 n, elements, steps, integrator kind; double t, dt;
 * n doubles u, n doubles v (host byte order, the space's DOF numbering). */
static void old_writer(const char *path, const int64_t head[4], const double times[2],
                       const double *u, const double *v, int rank)
{
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) {
    static const char magic[16] = "fcm-petsc-ck-1\n";
    const size_t n = (size_t)head[0];
    FILE *f = fopen(path, "wb");
    TEST_TRUE(f && fwrite(magic, 1, sizeof magic, f) == sizeof magic &&
              fwrite(head, sizeof *head, 4, f) == 4 && fwrite(times, sizeof *times, 2, f) == 2 &&
              fwrite(u, sizeof *u, n, f) == n && fwrite(v, sizeof *v, n, f) == n);
    if (f) fclose(f);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

/* A new driver reads `path`: the state bit for bit u, v, the step count k. */
static void check_driver(fcm_ctx *ctx, fcm_scene *scene, const char *path, fcm_index n,
                         const double *u, const double *v, long long k)
{
  fcm_petsc_problem *P = NULL;
  double *a = calloc((size_t)n + 1, sizeof *a), *b = calloc((size_t)n + 1, sizeof *b);
  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  TEST_OK(ctx, fcm_petsc_problem_read_checkpoint(P, path));
  TEST_TRUE(fcm_petsc_problem_step_count(P) == k);
  TEST_OK(ctx, fcm_petsc_problem_get_state(P, a, b));
  TEST_TRUE(a && b && !memcmp(a, u, sizeof *u * (size_t)n) && !memcmp(b, v, sizeof *v * (size_t)n));
  fcm_petsc_problem_destroy(&P);
  free(a);
  free(b);
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

/* A restored simulation's next step against the driver's (u1, v1 at time t1) and against
 * the serial one's. */
static void check_next(fcm_ctx *ctx, fcm_simulation *dist, fcm_simulation *serial, fcm_index n,
                       const double *u1, const double *v1, double t1, long long K, int rank)
{
  fcm_step_info si;
  TEST_OK(ctx, fcm_simulation_step(dist, &si));
  TEST_OK(ctx, fcm_simulation_step(serial, &si));
  const fcm_integrator *id = fcm_simulation_integrator(dist);
  const fcm_integrator *is = fcm_simulation_integrator(serial);
  TEST_NEAR(fcm_integrator_time(id), t1, 1e-14, 0.0);
  const double eu = rel_dist(n, fcm_integrator_displacement(id), u1);
  const double ev = rel_dist(n, fcm_integrator_velocity(id), v1);
  const double es = rel_dist(n, fcm_integrator_displacement(id), fcm_integrator_displacement(is));
  if (rank == 0)
    printf("step %lld after the restore: |u - u_driver| %.3g, |v - v_driver| %.3g, "
           "|u - u_serial| %.3g (relative)\n",
           K + 1, eu, ev, es);
  TEST_TRUE(eu < 1e-8 && ev < 1e-8 && es < 1e-10);
}

/* `path` (a copy of a checkpoint made by copy_file()) refused by the simulation and the driver
 * with `code` and a message naming `what`. */
static void check_refused(fcm_ctx *ctx, fcm_scene *scene, const char *path, fcm_status code,
                          const char *what)
{
  fcm_simulation *sim = NULL;
  fcm_petsc_problem *P = NULL;
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  TEST_ERR(ctx, fcm_simulation_read_checkpoint(sim, path), code, what);
  fcm_simulation_destroy(&sim);
  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  TEST_ERR(ctx, fcm_petsc_problem_read_checkpoint(P, path), code, what);
  TEST_TRUE(fcm_petsc_problem_step_count(P) == 0);
  fcm_petsc_problem_destroy(&P);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *dist = NULL, *serial = NULL;
  fcm_petsc_problem *P = NULL;
  char path[4096], ck[4200], old[4200], bad[4200], scene_ck[4200];
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, fcm_petsc_initialize(ctx, &argc, &argv));
  if (argc < 5) return 2;
  const long long K = atoll(argv[3]);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  snprintf(path, sizeof path, "%s/%s", argv[1], argv[2]);
  snprintf(ck, sizeof ck, "%s_np%d.fcmck", argv[4], size);
  snprintf(old, sizeof old, "%s_np%d.fcmpk", argv[4], size);
  snprintf(bad, sizeof bad, "%s_np%d_bad.fcmck", argv[4], size);
  snprintf(scene_ck, sizeof scene_ck, "%s_np%d_scene.fcmck", argv[4], size);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &scene));
  if (PetscOptionsSetValue(NULL, "-ksp_rtol", "1e-12")) TEST_TRUE(0);
  const fcm_scene_time *tm = fcm_scene_get_time(scene);
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
  fcm_petsc_problem_destroy(&P);

  /* the container's layout (io/checkpoint_file.c): "FCMCKPT\0", version, byte-order mark, the
   * source word 0, int64 n, elements, steps, kind, double t, dt at byte 32, the state, the
   * checksum; the same values make the older format */
  long fsize = 0;
  unsigned char *b = slurp(ck, &fsize);
  int64_t head[4] = {0, 0, 0, 0};
  double times[2] = {0.0, 0.0};
  uint64_t source = 1;
  TEST_TRUE(b && fsize == 88 + 16 * (long)n && !memcmp(b, "FCMCKPT", 8));
  if (b && fsize == 88 + 16 * (long)n) {
    memcpy(&source, b + 24, sizeof source);
    memcpy(head, b + 32, sizeof head);
    memcpy(times, b + 64, sizeof times);
    TEST_TRUE(!memcmp(b + 80, u, sizeof *u * (size_t)n));
    TEST_TRUE(fnv1a(b, (size_t)fsize - 8) == *(const uint64_t *)(const void *)(b + fsize - 8));
  }
  free(b);
  TEST_TRUE(source == 0 && head[0] == n && head[1] > 0 && head[2] == K &&
            head[3] == (int64_t)tm->integrator && times[0] == t && times[1] == tm->dt);
  old_writer(old, head, times, u, v, rank);

  /* the integrator on PETSc and the serial simulation read either file; their next steps */
  const char *files[2] = {ck, old};
  for (int f = 0; f < 2; f++) {
    TEST_OK(ctx, fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO,
                                             NULL, &dist));
    TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &serial));
    check_restored(ctx, dist, files[f], n, u, v, t, K, every);
    check_restored(ctx, serial, files[f], n, u, v, t, K, every);
    check_next(ctx, dist, serial, n, u1, v1, pi.time, K, rank);
    if (f == 0) TEST_OK(ctx, fcm_simulation_write_checkpoint(serial, scene_ck));
    fcm_simulation_destroy(&serial);
    fcm_simulation_destroy(&dist);
    /* and the driver */
    check_driver(ctx, scene, files[f], n, u, v, K);
  }

  /* another problem's file: dt changed, the container resealed */
  copy_file(ck, bad, 88 + 16 * (long)n, 72, 0.5, 1, rank);
  check_refused(ctx, scene, bad, FCM_ERR_ARG, "another problem");
  copy_file(old, bad, 64 + 16 * (long)n, 56, 0.5, 0, rank);
  check_refused(ctx, scene, bad, FCM_ERR_ARG, "another problem");
  /* corrupted: dt changed without the checksum */
  copy_file(ck, bad, 88 + 16 * (long)n, 72, 0.5, 0, rank);
  check_refused(ctx, scene, bad, FCM_ERR_FORMAT, "checksum mismatch");
  /* truncated: the last value missing (resealed: the count still tells) */
  copy_file(ck, bad, 88 + 16 * (long)n - 8, -1, 0.0, 1, rank);
  check_refused(ctx, scene, bad, FCM_ERR_FORMAT, "truncated");
  copy_file(old, bad, 64 + 16 * (long)n - 8, -1, 0.0, 0, rank);
  check_refused(ctx, scene, bad, FCM_ERR_FORMAT, "truncated");
  /* the driver reads no scene run's checkpoint (the serial simulation's, written above) */
  TEST_OK(ctx, fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                   FCM_PETSC_PARTITION_AUTO, &P));
  TEST_ERR(ctx, fcm_petsc_problem_read_checkpoint(P, scene_ck), FCM_ERR_ARG, "scene run");
  fcm_petsc_problem_destroy(&P);

  MPI_Barrier(MPI_COMM_WORLD); /* every process has read the files */
  if (rank == 0) {
    if (!(argc > 5 && strcmp(argv[5], "keep") == 0)) remove(ck), remove(old);
    remove(bad);
    remove(scene_ck);
  }
  free(u);
  free(v);
  free(u1);
  free(v1);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return test_mpi_result();
}
