/* fcm-sim --backend petsc (see fcm-sim-petsc.h): every process reads the scene; every scene
 * runs its own simulation with the integrator on PETSc (fcm_petsc_simulation_create():
 * the backend partitions the cells, each process integrates its own, the integrator sums the
 * partial assemblies and solves through PETSc) in the one time loop, fcm_simulation_run(), with
 * a monitor (on_step()) as the serial fcm-sim. Process 0 prints and writes the log
 * <name>_log.csv, the surface frames and the checkpoints (.fcmck, the serial format); the
 * background frames are parallel VTUs (<name>_background_NNNN.pvtu + one piece per process,
 * indexed by <name>_background.pvd). */
#define _POSIX_C_SOURCE 200809L
#include "fcm-sim-petsc.h"
#include "cli.h"
#include "fcm-sim-plot.h"

#include <fcm/fcm.h>
#include <fcm/scene_petsc.h>
#include <fcm/simulation.h>

#include <stdio.h>

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
static int write_frame(fcm_ctx *ctx, fcm_simulation *sim, const char *dir, int index, int rank)
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

/* What the monitor of the integrator path's run (on_step()) needs and keeps. */
typedef struct scene_run {
  fcm_ctx *ctx;
  const char *dir, *name, *logpath;
  int write, talk, rank;
  int frame;           /* the next frame's index */
  int warned_inverted; /* a resumed run may have warned already */
  long long attempted; /* the step being taken */
  int stopped;         /* 1: the monitor ended the run (and reported why) */
} scene_run;

/* fcm_simulation_monitor_fn of the integrator path (collective): the state's check, the
 * warning on the first step that ends inverted (as the serial fcm-sim; the counts are the same
 * on every process), the progress line, the frame and log when due, and the checkpoint when
 * due (after the frame, as the serial fcm-sim: the checkpoint counts it). */
static fcm_status on_step(void *user, fcm_simulation *sim, const fcm_simulation_step_event *ev)
{
  scene_run *r = user;
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
    if (!write_frame(r->ctx, sim, r->dir, r->frame++, r->rank)) return FCM_ERR_IO;
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

/* A scene's own simulation with the integrator on PETSc (fcm_petsc_simulation_create()), every
 * scene alike (a linear material too: its Newton step is one solve, and the kept factorization
 * serves the following steps). Every process holds the same state and log; each process writes
 * its background piece, process 0 the rest of the frames (<name>_background.pvd naming the .pvtu
 * frames, the surface VTUs and PVD), the log <name>_log.csv and the checkpoints
 * (<name>_checkpoint_NNNNNN.fcmck, --checkpoint-every or the scene's
 * output.checkpoint_interval) with the serial writers; --resume: every process reads the
 * checkpoint (fcm_simulation_read_checkpoint(): also the linear driver's .fcmpk files of
 * earlier versions). Returns the exit code (the same on every process). */
static int run_scene(fcm_ctx *ctx, const fcm_scene *scene, const char *outdir, long long steps,
                     int check, int quiet, int plot, int checkpoint_every, const char *resume,
                     int rank, int size)
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
    if (rank == 0) cli_report_scene_error("fcm-sim", name, fcm_ctx_error_message(ctx));
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
    if (!resume && !write_frame(ctx, sim, dir, frame++, rank)) goto done;
    if (rank == 0) {
      ok = fcm_simulation_write_log(sim, logpath) == FCM_OK;
      if (!ok) fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (!ok) goto done;
  }
  const double t0 = fcm_wtime();
  fcm_simulation_get_counters(sim, &c); /* a resumed run may have warned already */
  scene_run rn = {ctx,
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
  st = fcm_simulation_run(sim, on_step, &rn); /* collective; the same status everywhere */
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
    if (ok && plot) ok = sim_plot_log("fcm-sim", logpath);
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
    if (write) sim_print_output(dir, name, logpath, 0, plot);
  }
  rc = 0;
done:
  fcm_simulation_destroy(&sim);
  return rc;
}

int sim_petsc_run(const char *path, const char *outdir, long long steps, int check, int quiet,
                  int plot, int checkpoint_every, const char *resume, int petsc_argc,
                  char **petsc_argv)
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
  /* the inputs before the set-up: the output directory (the root writes it) and the
   * checkpoint (every process reads it) */
  if (!check && rank == 0 &&
      !cli_check_output_dir("fcm-sim", outdir ? outdir : fcm_scene_get_output(scene)->directory))
    rc = 2;
  if (rc != 2 && resume && fcm_simulation_check_checkpoint(ctx, resume) != FCM_OK) {
    if (rank == 0) fprintf(stderr, "fcm-sim: --resume: %s\n", fcm_ctx_error_message(ctx));
    rc = 2;
  }
  {
    int bad = rc == 2, any = bad;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
      rc = 2;
      goto done;
    }
  }
  const char *name = fcm_scene_name(scene);
  if (talk)
    fprintf(stderr, "fcm-sim: scene %s (%s): building on %d process%s (backend petsc)\n", name,
            fcm_scene_source(scene), size, size > 1 ? "es" : "");
  rc = run_scene(ctx, scene, outdir, steps, check, quiet, plot, checkpoint_every, resume, rank,
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
