/* fcm-sim --backend petsc (see fcm-sim-petsc.h): every process reads the scene and builds the
 * mesh and the geometry. A scene the linear driver runs (fcm_petsc_problem_supports_scene():
 * linear material, gravity, fixed and motion on node regions) goes through it
 * (fcm_petsc_problem_create_from_scene() distributes the cells, the cut-cell rules, the
 * assembly and the solves); every other scene (cuts and simplify auto included) goes through
 * the integrator on PETSc (run_newton(), fcm_petsc_simulation_create()). Process 0 prints and
 * writes the log <name>_log.csv; on the linear driver each frame is a parallel VTU
 * (<name>_NNNN.pvtu by process 0 naming one piece <name>_NNNN_<rank>.vtu per process: its own
 * cells), indexed by <name>.pvd, and checkpoints are <name>_checkpoint_NNNNNN.fcmpk; on the
 * integrator the background frames are parallel VTUs too (<name>_background_NNNN.pvtu + one
 * piece per process, indexed by <name>_background.pvd), the surface frames and checkpoints
 * (.fcmck) are written by process 0 (run_newton()). */
#define _POSIX_C_SOURCE 200809L
#include "fcm-sim-petsc.h"
#include "cli.h"

#include <fcm/fcm.h>
#include <fcm/scene_petsc.h>
#include <fcm/simulation.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct run_log {
  long long step;
  double time, residual, kinetic, elastic, work, wall;
  int iterations;
} run_log;

static fcm_status write_log(fcm_ctx *ctx, const char *path, const run_log *rows, long long n)
{
  fcm_atomic_file *f = NULL;
  fcm_status st = fcm_atomic_file_open(ctx, path, &f);
  if (st != FCM_OK) return st;
  FILE *s = fcm_atomic_file_stream(f);
  fprintf(s, "step,time,ksp_iterations,ksp_residual,kinetic_energy,elastic_energy,external_work,"
             "wall_seconds\n");
  for (long long k = 0; k < n; k++)
    fprintf(s, "%lld,%.17g,%d,%.17g,%.17g,%.17g,%.17g,%.6g\n", rows[k].step, rows[k].time,
            rows[k].iterations, rows[k].residual, rows[k].kinetic, rows[k].elastic, rows[k].work,
            rows[k].wall);
  return fcm_atomic_file_commit(&f);
}

/* A frame (collective): the pieces and the .pvtu, indexed in the PVD by process 0. */
static int write_frame(fcm_ctx *ctx, fcm_petsc_problem *P, const char *dir, const char *name,
                       int index, double time, fcm_pvd *pvd, int rank)
{
  char stem[512], file[600];
  snprintf(stem, sizeof stem, "%s_%04d", name, index);
  snprintf(file, sizeof file, "%s.pvtu", stem);
  int ok = fcm_petsc_problem_write_frame(P, dir, stem) == FCM_OK;
  if (ok && rank == 0) ok = fcm_pvd_add(pvd, time, file) == FCM_OK;
  if (!ok && rank == 0) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return ok;
}

/* Process 0, resuming: the rows of steps <= first of an existing log (missing ones stay 0). */
static void read_old_log(const char *path, run_log *rows, long long first)
{
  FILE *f = fopen(path, "r");
  char line[1024];
  if (!f) return;
  while (fgets(line, sizeof line, f)) {
    run_log r;
    if (sscanf(line, "%lld,%lg,%d,%lg,%lg,%lg,%lg,%lg", &r.step, &r.time, &r.iterations,
               &r.residual, &r.kinetic, &r.elastic, &r.work, &r.wall) == 8 &&
        r.step >= 1 && r.step <= first)
      rows[r.step - 1] = r;
  }
  fclose(f);
}

/* Process 0 writes the checkpoint <dir>/<name>_checkpoint_NNNNNN.fcmck of the current step
 * (the serial format, fcm_simulation_write_checkpoint(): the state is the same on every
 * process, so any process count, and the serial fcm-sim, can resume from it). Collective:
 * returns whether it was written, on every process. */
static int write_checkpoint(fcm_ctx *ctx, fcm_simulation *sim, const char *dir, const char *name,
                            int talk, int rank)
{
  char path[4300];
  int ok = 1;
  snprintf(path, sizeof path, "%s/%s_checkpoint_%06lld.fcmck", dir, name,
           fcm_simulation_step_count(sim));
  if (rank == 0) {
    ok = fcm_simulation_write_checkpoint(sim, path) == FCM_OK;
    if (!ok)
      fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    else if (talk)
      fprintf(stderr, "fcm-sim: checkpoint %s\n", path);
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return ok;
}

/* A frame of the integrator path (collective: every process writes the background piece of its
 * own cells, process 0 the .pvtu, the surface VTU and the PVDs); whether it was written, on
 * every process. */
static int write_frame_newton(fcm_ctx *ctx, fcm_simulation *sim, const char *dir, int index,
                              int rank)
{
  int ok = fcm_simulation_write_frame(sim, dir, index) == FCM_OK;
  if (!ok && rank == 0) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD); /* a failure of a piece is everywhere */
  return ok;
}

/* Every process restores the checkpoint `path` into its new simulation (the same bytes give
 * the same state and the same errors everywhere; a file that one process cannot read is
 * reported by the lowest such process). Collective: 1 when every process restored it. */
static int resume_checkpoint(fcm_ctx *ctx, fcm_simulation *sim, const char *path, int rank)
{
  const int mine = fcm_simulation_read_checkpoint(sim, path) == FCM_OK ? -1 : rank;
  int bad = -1, first = mine < 0 ? 1 << 30 : mine;
  MPI_Allreduce(&mine, &bad, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (bad < 0) return 1;
  int lowest = first;
  MPI_Allreduce(&first, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (rank == lowest) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
  return 0;
}

/* What the monitor of the integrator path's run (on_step_newton()) needs and keeps. */
typedef struct newton_run {
  fcm_ctx *ctx;
  const char *dir, *name, *logpath;
  int write, talk, rank;
  int frame;           /* the next frame's index */
  int warned_inverted; /* a resumed run may have warned already */
  long long attempted; /* the step being taken */
  int stopped;         /* 1: the monitor ended the run (and reported why) */
} newton_run;

/* fcm_simulation_monitor_fn of the integrator path (collective): the state's check, the
 * warning on the first step that ends inverted (as the serial fcm-sim; the counts are the same
 * on every process), the progress line, the frame and log when due, and the checkpoint when
 * due (after the frame, as the serial fcm-sim: the checkpoint counts it). */
static fcm_status on_step_newton(void *user, fcm_simulation *sim,
                                 const fcm_simulation_step_event *ev)
{
  newton_run *r = user;
  const fcm_step_info *si = ev->info;
  const long long k = ev->step;
  int ok = 1;
  r->stopped = 1;
  if (!fcm_simulation_state_finite(sim)) {
    if (r->rank == 0) fprintf(stderr, "fcm-sim: non-finite state after step %lld\n", k);
    return FCM_ERR_NUMERIC;
  }
  if (r->rank == 0 && si->inverted_points > 0 && !r->warned_inverted)
    fprintf(stderr,
            "fcm-sim: warning: step %lld (t = %.6g s) ended with %lld inverted quadrature "
            "point%s (J = det F <= 0; the first in cell %lld, -1: not located); the stresses "
            "there are NaN\n",
            k, si->time, (long long)si->inverted_points, si->inverted_points == 1 ? "" : "s",
            (long long)si->inverted_cell);
  r->warned_inverted |= si->inverted_points > 0;
  if (r->talk)
    fprintf(stderr,
            "fcm-sim: step %lld/%lld t = %.6g s: Newton %d, KSP %lld iterations, residual "
            "%.3g\n",
            k, ev->num_steps, si->time, si->newton_iterations, si->linear_iterations, si->residual);
  if (r->write && fcm_simulation_frame_due(sim)) {
    if (!write_frame_newton(r->ctx, sim, r->dir, r->frame++, r->rank)) return FCM_ERR_IO;
    if (r->rank == 0) {
      ok = fcm_simulation_write_log(sim, r->logpath) == FCM_OK;
      if (!ok) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(r->ctx));
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) return FCM_ERR_IO;
  }
  if (r->write && fcm_simulation_checkpoint_due(sim) &&
      !write_checkpoint(r->ctx, sim, r->dir, r->name, r->talk, r->rank))
    return FCM_ERR_IO;
  r->attempted = k + 1;
  r->stopped = 0;
  return FCM_OK;
}

/* A scene the linear driver does not run (non-linear material, boundary constraints, loads on
 * the boundary, damping, initial velocities, release): the scene's own simulation with the
 * integrator on PETSc (fcm_petsc_simulation_create()). Every process holds the same state and
 * log; each process writes its background piece, process 0 the rest of the frames
 * (<name>_background.pvd naming the .pvtu frames, the surface VTUs and PVD), the log
 * <name>_log.csv and the checkpoints (<name>_checkpoint_NNNNNN.fcmck, --checkpoint-every or
 * the scene's output.checkpoint_interval) with the serial writers; --resume: every process
 * reads the checkpoint. Returns the exit code (the same on every process). */
static int run_newton(fcm_ctx *ctx, const fcm_scene *scene, const char *outdir, long long steps,
                      int check, int quiet, int checkpoint_every, const char *resume, int rank,
                      int size)
{
  const char *name = fcm_scene_name(scene);
  const int talk = rank == 0 && !quiet;
  fcm_simulation *sim = NULL;
  int rc = 1, ok = 1;
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = check ? (steps > 0 && steps < 3 ? steps : 3) : (steps > 0 ? steps : FCM_DEFAULT);
  so.checkpoint_interval = check ? 0 : checkpoint_every; /* -1: the scene's */
  if (talk) fprintf(stderr, "fcm-sim: scene %s: through the integrator (Newton) on PETSc\n", name);
  fcm_status st =
      fcm_petsc_simulation_create(ctx, MPI_COMM_WORLD, scene, FCM_PETSC_PARTITION_AUTO, &so, &sim);
  if (st != FCM_OK) { /* every process has the error; process 0 prints it */
    if (rank == 0) fprintf(stderr, "fcm-sim: scene %s: %s\n", name, fcm_ctx_error_message(ctx));
    return st == FCM_ERR_ARG || st == FCM_ERR_IO || st == FCM_ERR_FORMAT ||
                   st == FCM_ERR_GEOMETRY || st == FCM_ERR_UNSUPPORTED
               ? 2
               : 1;
  }
  if (resume) {
    if (!resume_checkpoint(ctx, sim, resume, rank)) {
      rc = 2;
      goto done;
    }
    if (talk)
      fprintf(stderr, "fcm-sim: resumed from %s at step %lld (t = %.9g s)\n", resume,
              fcm_simulation_step_count(sim), fcm_integrator_time(fcm_simulation_integrator(sim)));
  }
  const char *dir = outdir ? outdir : fcm_scene_get_output(scene)->directory;
  const int write = !check;
  char logpath[4200];
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  int frame = (int)c.frames; /* resumed: the frames the checkpoint had */
  snprintf(logpath, sizeof logpath, "%s/%s_log.csv", dir, name);
  if (write) {
    if (rank == 0) ok = cli_make_dirs("fcm-sim", dir);
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) goto done;
    if (!resume && !write_frame_newton(ctx, sim, dir, frame++, rank)) goto done;
    if (rank == 0) {
      ok = fcm_simulation_write_log(sim, logpath) == FCM_OK;
      if (!ok) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) goto done;
  }
  const double t0 = fcm_wtime();
  fcm_simulation_get_counters(sim, &c); /* a resumed run may have warned already */
  newton_run rn = {ctx,
                   dir,
                   name,
                   logpath,
                   write,
                   talk,
                   rank,
                   frame,
                   c.inverted_steps > 0,
                   fcm_simulation_step_count(sim) + 1,
                   0};
  st = fcm_simulation_run(sim, on_step_newton, &rn); /* collective; the same status everywhere */
  if (st != FCM_OK) {
    if (rn.stopped) goto done;
    /* the step failed, or was taken and refused (solver.on_inversion) */
    if (rank == 0) {
      fprintf(stderr, "fcm-sim: step %lld: %s\n", rn.attempted, fcm_ctx_error_message(ctx));
      if (write) fcm_simulation_write_log(sim, logpath);
    }
    goto done;
  }
  if (write && rank == 0) {
    ok = fcm_simulation_write_log(sim, logpath) == FCM_OK;
    if (!ok) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!ok) goto done;
  if (fcm_petsc_simulation_summary_view(sim, talk ? stdout : NULL) != FCM_OK) {
    if (rank == 0) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    goto done;
  }
  if (talk) {
    printf("  backend   petsc, %d process%s (Newton on PETSc), steps %.3g s\n", size,
           size > 1 ? "es" : "", fcm_wtime() - t0);
    if (write) printf("  output    %s/%s_background.pvd, %s\n", dir, name, logpath);
  }
  rc = 0;
done:
  fcm_simulation_destroy(&sim);
  return rc;
}

/* The linear driver's summary (process 0): partition, DOFs and elements per process, steps and
 * iterations, times, and per DOF; pvdpath NULL: no output written. */
static void linear_summary(const char *name, int size, const fcm_petsc_info *info, double t_setup,
                           double tsteps, const char *pvdpath, const char *logpath)
{
  printf("scene %s (backend petsc, %d process%s, partition %s)\n", name, size, size > 1 ? "es" : "",
         fcm_petsc_partition_name(info->partition));
  printf("  dofs      %lld; elements per process %lld .. %lld\n", (long long)info->num_dofs,
         (long long)info->min_local_elements, (long long)info->max_local_elements);
  printf("  steps     %lld, KSP iterations %lld\n", info->steps, info->total_iterations);
  printf("  time      setup %.3g s (rules %.3g s, assembly %.3g s on process 0), steps %.3g s\n",
         t_setup, info->time_rules, info->time_assembly, tsteps);
  printf("  per dof   setup %.3g us, step %.3g us; memory %.0f bytes (all processes), "
         "matrix %.0f bytes\n",
         1e6 * t_setup / (double)info->num_dofs,
         1e6 * tsteps / (double)(info->num_dofs * (info->steps > 0 ? info->steps : 1)),
         info->memory_total / (double)info->num_dofs, info->matrix_memory / (double)info->num_dofs);
  if (pvdpath) printf("  output    %s, %s\n", pvdpath, logpath);
}

/* The linear driver's run: its problem, its output and its step log. */
typedef struct linear_run {
  fcm_ctx *ctx;
  fcm_petsc_problem *P;
  fcm_pvd *pvd;  /* process 0, when writing */
  run_log *rows; /* nsteps rows */
  const char *dir, *name;
  char logpath[4200], pvdpath[4200];
  int write, talk, rank;
  int interval, ck_every; /* frame and checkpoint intervals (steps) */
  long long nsteps;
  int frame; /* the next frame's index */
} linear_run;

/* Process 0, when writing: the output directory and the PVD; resuming from step first, the
 * earlier frames (0, interval, 2 interval, ... <= first) indexed again and the earlier log
 * rows kept. 0 after reporting a failure. */
static int linear_output_open(linear_run *L, double dt, int resume, long long first)
{
  int ok =
      cli_make_dirs("fcm-sim", L->dir) && fcm_pvd_create(L->ctx, L->pvdpath, &L->pvd) == FCM_OK;
  for (long long k = 0; ok && resume && k <= first && k <= L->nsteps; k += L->interval) {
    char file[600];
    snprintf(file, sizeof file, "%s_%04d.pvtu", L->name, L->frame++);
    ok = fcm_pvd_add(L->pvd, (double)k * dt, file) == FCM_OK;
  }
  if (resume && first <= L->nsteps) read_old_log(L->logpath, L->rows, first);
  if (!ok && fcm_ctx_error_status(L->ctx) != FCM_OK)
    fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(L->ctx));
  return ok;
}

/* After step k (collective): the frame and the log when due, the checkpoint when due; 0 after
 * reporting a failure. */
static int linear_step_output(linear_run *L, long long k, double time)
{
  if (L->write && (k % L->interval == 0 || k == L->nsteps)) {
    if (!write_frame(L->ctx, L->P, L->dir, L->name, L->frame++, time, L->pvd, L->rank)) return 0;
    int ok = L->rank != 0 || write_log(L->ctx, L->logpath, L->rows, k) == FCM_OK;
    if (!ok) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(L->ctx));
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) return 0;
  }
  if (L->write && L->ck_every > 0 && k % L->ck_every == 0) {
    char ck[4300];
    snprintf(ck, sizeof ck, "%s/%s_checkpoint_%06lld.fcmpk", L->dir, L->name, k);
    if (fcm_petsc_problem_write_checkpoint(L->P, ck) != FCM_OK) {
      if (L->rank == 0) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(L->ctx));
      return 0;
    }
    if (L->talk) fprintf(stderr, "fcm-sim: checkpoint %s\n", ck);
  }
  return 1;
}

/* Steps first + 1 .. nsteps (collective), each logged into rows with its wall time since t1,
 * and its output; 0 after reporting a failure. */
static int linear_steps(linear_run *L, long long first, double t1)
{
  for (long long k = first + 1; k <= L->nsteps; k++) {
    fcm_petsc_step_info si;
    fcm_status st = fcm_petsc_problem_step(L->P, &si);
    if (st != FCM_OK) {
      if (L->rank == 0)
        fprintf(stderr, "fcm-sim: step %lld: %s\n", k, fcm_ctx_error_message(L->ctx));
      if (L->write && L->rank == 0) write_log(L->ctx, L->logpath, L->rows, k - 1);
      return 0;
    }
    L->rows[k - 1] = (run_log){k,
                               si.time,
                               si.residual,
                               si.kinetic_energy,
                               si.elastic_energy,
                               si.external_work,
                               fcm_wtime() - t1,
                               si.iterations};
    if (L->talk)
      fprintf(stderr, "fcm-sim: step %lld/%lld t = %.6g s: KSP %d iterations, residual %.3g\n", k,
              L->nsteps, si.time, si.iterations, si.residual);
    if (!linear_step_output(L, k, si.time)) return 0;
  }
  return 1;
}

/* Whether the state (u, v) of the n DOFs, read into u and v, is finite. */
static int linear_state_finite(fcm_petsc_problem *P, fcm_index n, double *u, double *v)
{
  int finite = fcm_petsc_problem_get_state(P, u, v) == FCM_OK;
  for (fcm_index i = 0; finite && i < n; i++)
    finite = isfinite(u[i]) && isfinite(v[i]);
  return finite;
}

/* A scene the linear driver runs (fcm_petsc_problem_create_from_scene()): its own steps, frames
 * (<name>.pvd naming the .pvtu frames), log and checkpoints (<name>_checkpoint_NNNNNN.fcmpk);
 * --resume: every process reads the checkpoint. Returns the exit code (this process's). */
static int run_linear(fcm_ctx *ctx, const fcm_scene *scene, const char *outdir, long long steps,
                      int check, int quiet, int checkpoint_every, const char *resume, int rank,
                      int size)
{
  int rc = 1;
  linear_run L = {0};
  L.ctx = ctx;
  L.name = fcm_scene_name(scene);
  L.talk = rank == 0 && !quiet;
  L.rank = rank;
  double *u = NULL, *v = NULL;
  double t0 = fcm_wtime();
  fcm_status st = fcm_petsc_problem_create_from_scene(ctx, MPI_COMM_WORLD, scene,
                                                      FCM_PETSC_PARTITION_AUTO, &L.P);
  if (st != FCM_OK) { /* every process has the error; process 0 prints it */
    if (rank == 0) fprintf(stderr, "fcm-sim: scene %s: %s\n", L.name, fcm_ctx_error_message(ctx));
    rc = st == FCM_ERR_ARG || st == FCM_ERR_IO || st == FCM_ERR_FORMAT || st == FCM_ERR_GEOMETRY ||
                 st == FCM_ERR_UNSUPPORTED
             ? 2
             : 1;
    goto done;
  }
  const double t_setup = fcm_wtime() - t0;
  L.nsteps = (long long)fcm_scene_get_time(scene)->num_steps;
  if (steps > 0 && steps < L.nsteps) L.nsteps = steps;
  if (check && L.nsteps > 3) L.nsteps = 3;
  L.write = !check;
  L.dir = outdir ? outdir : fcm_scene_get_output(scene)->directory;
  L.interval = fcm_scene_get_output(scene)->frame_interval > 0
                   ? fcm_scene_get_output(scene)->frame_interval
                   : 1;
  const fcm_index n = fcm_petsc_problem_num_dofs(L.P);
  int ok = 1;
  long long first = 0;
  L.ck_every =
      checkpoint_every >= 0 ? checkpoint_every : fcm_scene_get_output(scene)->checkpoint_interval;
  if (resume) { /* every process reads the checkpoint */
    st = fcm_petsc_problem_read_checkpoint(L.P, resume);
    if (st != FCM_OK) {
      if (rank == 0) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
      rc = 2;
      goto done;
    }
    first = fcm_petsc_problem_step_count(L.P);
    if (L.talk) fprintf(stderr, "fcm-sim: resumed from %s at step %lld\n", resume, first);
  }
  u = calloc((size_t)n + 1, sizeof *u);
  v = calloc((size_t)n + 1, sizeof *v);
  L.rows = calloc((size_t)L.nsteps + 1, sizeof *L.rows);
  if (!u || !v || !L.rows) {
    fprintf(stderr, "fcm-sim: out of memory\n");
    MPI_Abort(MPI_COMM_WORLD, 1); /* a local failure the others cannot learn otherwise */
  }
  snprintf(L.logpath, sizeof L.logpath, "%s/%s_log.csv", L.dir, L.name);
  snprintf(L.pvdpath, sizeof L.pvdpath, "%s/%s.pvd", L.dir, L.name);
  if (L.write && rank == 0)
    ok = linear_output_open(&L, fcm_scene_get_time(scene)->dt, resume != NULL, first);
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Bcast(&L.frame, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!ok ||
      (L.write && !resume && !write_frame(ctx, L.P, L.dir, L.name, L.frame++, 0.0, L.pvd, rank)))
    goto done;
  double t1 = fcm_wtime();
  if (!linear_steps(&L, first, t1)) goto done;
  fcm_petsc_info info;
  if (fcm_petsc_problem_get_info(L.P, &info) != FCM_OK) goto done;
  if (check && !linear_state_finite(L.P, n, u, v)) {
    if (rank == 0) fprintf(stderr, "fcm-sim: non-finite state after %lld steps\n", L.nsteps);
    goto done;
  }
  if (L.talk)
    linear_summary(L.name, size, &info, t_setup, fcm_wtime() - t1, L.write ? L.pvdpath : NULL,
                   L.logpath);
  rc = 0;
done:
  fcm_pvd_destroy(&L.pvd);
  free(u);
  free(v);
  free(L.rows);
  fcm_petsc_problem_destroy(&L.P);
  return rc;
}

int sim_petsc_run(const char *path, const char *outdir, long long steps, int check, int quiet,
                  int checkpoint_every, const char *resume, int petsc_argc, char **petsc_argv)
{
  int rc = 1, rank = 0, size = 1;
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-sim: cannot create the fcm context\n");
    return 1;
  }
  if (fcm_petsc_initialize(ctx, &petsc_argc, &petsc_argv) != FCM_OK) {
    fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    fcm_ctx_destroy(&ctx);
    return 1;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int talk = rank == 0 && !quiet;
  /* every process parses the same file; a failure is the same everywhere */
  fcm_status st =
      path ? fcm_scene_create_from_file(ctx, path, &scene) : fcm_scene_create_default(ctx, &scene);
  if (st != FCM_OK) {
    if (rank == 0) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    rc = 2;
    goto done;
  }
  const char *name = fcm_scene_name(scene);
  if (talk)
    fprintf(stderr, "fcm-sim: scene %s (%s): building on %d process%s (backend petsc)\n", name,
            fcm_scene_source(scene), size, size > 1 ? "es" : "");
  rc = fcm_petsc_problem_supports_scene(ctx, scene)
           ? run_linear(ctx, scene, outdir, steps, check, quiet, checkpoint_every, resume, rank,
                        size)
           : run_newton(ctx, scene, outdir, steps, check, quiet, checkpoint_every, resume, rank,
                        size);
done:
  /* the exit code every process returns: the largest */
  {
    int all = rc;
    MPI_Allreduce(&rc, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    rc = all;
  }
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  fcm_petsc_finalize();
  return rc;
}
