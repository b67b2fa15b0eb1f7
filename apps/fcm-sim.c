/* fcm-sim: the main program. `fcm-sim scene.json` runs a scene file through fcm_simulation;
 * without a file, the built-in default scene (a twisting hollow cylinder). The steel
 * cantilever that used to be a second program here is the example scene
 * apps/scenes/cantilever.json (its Timoshenko comparison: tests/fem/cantilever.c). */
#define _POSIX_C_SOURCE 200809L
#include "app_env.h"
#include <fcm/fcm.h>
#include <fcm/simulation.h>

#include "cli.h"
#include "fcm-sim-petsc.h" /* sim_print_output(); sim_petsc_run() is built with PETSc only */
#include "fcm-sim-plot.h"

#include <errno.h>
#include <omp.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---------------------------------------------------------------- scene runs */

typedef struct scene_options {
  const char *path; /* NULL: the built-in scene */
  const char *outdir;
  const char *resume; /* checkpoint to continue from, or NULL */
  long long steps;
  int checkpoint_every; /* -1: the scene's */
  int check, quiet, print_scene;
  int preview;  /* write the preview files and stop before the set-up */
  int plot;     /* --plot: <name>_log.png (and .gp) beside the log at the end */
  int debug;    /* print the library's traceback with errors */
  int progress; /* the set-up's phases and progress also when stderr is not a terminal */
  int backend;  /* 0 serial, 1 petsc */
} scene_options;

static const char *const backend_names[] = {"serial", "petsc", NULL};

/* The option table, writing into `o`. */
#define SIM_NUM_OPTIONS 13
static void scene_option_table(scene_options *o, cli_option opts[SIM_NUM_OPTIONS])
{
  const cli_option t[SIM_NUM_OPTIONS] = {
      {"--output", "-o", CLI_STRING, &o->outdir, "DIR", "output directory (overrides the scene's)",
       0, 0, 0, NULL, NULL, NULL},
      {"--steps", NULL, CLI_LLONG, &o->steps, "N", "stop once N steps in all are taken", 1, 1e12, 0,
       NULL, NULL, NULL},
      {"--check", NULL, CLI_FLAG, &o->check, NULL,
       "run at most 3 steps without output, check the state is\n"
       "finite and print the run summary",
       0, 0, 0, NULL, NULL, NULL},
      {"--checkpoint-every", NULL, CLI_INT, &o->checkpoint_every, "K",
       "write <name>_checkpoint_NNNNNN.fcmck every K steps\n"
       "(overrides the scene's output.checkpoint_interval)",
       1, 1e9, 0, NULL, NULL, NULL},
      {"--resume", NULL, CLI_STRING, &o->resume, "FILE",
       "continue from a checkpoint of the same scene, bit for bit\n"
       "as the uninterrupted run with the same checkpoint\n"
       "interval; frames and log go on in the output directory",
       0, 0, 0, NULL, NULL, NULL},
      {"--preview", NULL, CLI_FLAG, &o->preview, NULL,
       "build only the background and the geometry, write\n"
       "<name>_preview.pvd into the output directory (the grid\n"
       "with inside/cut/outside cells, the surface, the nodes\n"
       "and boundary points of each effect's region, the cut\n"
       "surfaces), print the counts per region and exit",
       0, 0, 0, NULL, NULL, NULL},
      {"--print-scene", NULL, CLI_FLAG, &o->print_scene, NULL,
       "print the scene as JSON with every default filled in and exit", 0, 0, 0, NULL, NULL, NULL},
      {"--plot", NULL, CLI_FLAG, &o->plot, NULL,
       "at the end, draw the log against time into <name>_log.png\n"
       "(energy, momentum, Newton iterations, reactions; gnuplot,\n"
       "through the script <name>_log.gp written beside it)",
       0, 0, 0, NULL, NULL, NULL},
      {"--quiet", "-q", CLI_FLAG, &o->quiet, NULL, "print only errors and warnings", 0, 0, 0, NULL,
       NULL, NULL},
      {"--progress", NULL, CLI_FLAG, &o->progress, NULL,
       "report the set-up also when stderr is not a terminal: a\n"
       "line when a long phase starts (the cell rules, the level\n"
       "set, Gmsh's meshing), one with each phase's time as it\n"
       "ends, and the level-set and cell-rule builds every 2 s\n"
       "(on a terminal always: what runs now, bars, the times)",
       0, 0, 0, NULL, NULL, NULL},
      {"--debug", NULL, CLI_FLAG, &o->debug, NULL,
       "print the library's traceback with errors, and every\n"
       "warning (else the first 10)",
       0, 0, 0, NULL, NULL, NULL},
      {"--backend", NULL, CLI_CHOICE, &o->backend, "NAME",
       "serial (default) or petsc: distributed over the MPI\n"
       "processes (mpirun -n 2 fcm-sim scene.json --backend petsc;\n"
       "a build with PETSc). PETSc options (-ksp_type cg ...) may\n"
       "follow. Every scene runs, through\n"
       "the integrator on PETSc: the serial run's loop, log, frames\n"
       "and checkpoints (--resume also reads older .fcmpk files)",
       0, 0, 0, backend_names, NULL, NULL},
      {NULL, NULL, CLI_FLAG, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL}};
  memcpy(opts, t, sizeof t);
}

static void usage(FILE *f, const cli_option *opts)
{
  fprintf(f,
          "usage: fcm-sim [SCENE.json] [options]\n"
          "\n"
          "Runs a scene file (schema: apps/scenes/README.md) with only the effects it names;\n"
          "without a file, the built-in default scene: a hollow cylinder, one end pushed in and\n"
          "the other twisted (Longva et al. 2020, 6.2; Hex20 FCM, about 20 s on 2 cores).\n"
          "Frames go to the scene's output directory: <name>_background_NNNN.vtu,\n"
          "<name>_surface_NNNN.vtu, <name>_background.pvd, <name>_surface.pvd (open the .pvd\n"
          "files in ParaView) and the per-step log <name>_log.csv. Example scenes, among them\n"
          "a steel cantilever under its own weight: apps/scenes/. A first scene from your own\n"
          "model, step by step: apps/docs/tutorial.md.\n"
          "\n"
          "options:\n");
  cli_print_options(f, opts);
  fprintf(f, "\n"
             "Exit 0 on success, 1 when the run fails, 2 on a usage error, an invalid scene (also\n"
             "one whose files or geometry fail to build: the message names the scene section,\n"
             "e.g. geometry.voxels) or a refused checkpoint. A warning is printed when part of\n"
             "the body lies outside the background mesh (it is cut off), when a traction,\n"
             "pressure or boundary constraint loses more than 0.1%% of its boundary to cells\n"
             "below quadrature.min_fraction (dropped), on the first step that\n"
             "ends with inverted quadrature points (J = det F <= 0; the log's inverted_points\n"
             "column and the summary count them), on the first frame holding NaN stresses and\n"
             "for what the library reports as a warning (NaN voxels, filled holes, solver\n"
             "fallbacks); with \"solver\": {\"on_inversion\": \"stop\"} an inverted step ends the\n"
             "run (exit 1). Errors print the library's message; --debug adds where in the\n"
             "library it failed.\n");
}

/* -1 when the arguments are parsed into `o`, else the exit code (0 after --help, 2). */
static int parse_scene_args(int argc, char **argv, scene_options *o)
{
  cli_option opts[SIM_NUM_OPTIONS];
  const char *pos[1] = {NULL};
  int npos = 0;
  scene_option_table(o, opts);
  const int rc = cli_parse_args("fcm-sim", opts, argc, argv, pos, 1, &npos, usage);
  if (rc >= 0) return rc;
  o->path = npos ? pos[0] : NULL;
  if (o->check && (o->resume || o->checkpoint_every > 0 || o->plot)) {
    fprintf(stderr, "fcm-sim: --check writes nothing: no --resume, --checkpoint-every or --plot\n");
    return 2;
  }
  if (o->preview && (o->check || o->resume || o->checkpoint_every > 0 || o->steps > 0 || o->plot)) {
    fprintf(stderr, "fcm-sim: --preview takes no steps: no --check, --resume, --steps, "
                    "--checkpoint-every or --plot\n");
    return 2;
  }
  return -1;
}

/* One progress report per step on stderr: a bar with ETA on a terminal, else a line. */
/* k of n steps of this process done; step `step` of `total` in all. */
static void progress(int tty, long long k, long long n, long long step, long long total,
                     const fcm_step_info *si, double elapsed)
{
  if (tty) {
    int width = 30, fill = (int)(width * step / (total > 0 ? total : 1));
    double eta = k > 0 ? elapsed / (double)k * (double)(n - k) : 0.0;
    char bar[64];
    for (int i = 0; i < width; i++)
      bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    /* an interactive step (fixed Newton iterations) shows how far from the tolerance it is */
    if (si->reason == FCM_STEP_FIXED_ITERATIONS)
      fprintf(stderr, "\r[%s] %lld/%lld t=%.4g s newton %d residual %.2e > tol %.2e  ETA %.0f s   ",
              bar, step, total, si->time, si->newton_iterations, si->residual, si->tolerance, eta);
    else
      fprintf(stderr, "\r[%s] %lld/%lld t=%.4g s newton %d  ETA %.0f s   ", bar, step, total,
              si->time, si->newton_iterations, eta);
    if (k == n) fputc('\n', stderr);
  } else {
    char mg[48] = "";
    if (si->multigrid_cycles > 0)
      snprintf(mg, sizeof mg, " multigrid cycles %lld", si->multigrid_cycles);
    fprintf(stderr,
            "fcm-sim: step %lld/%lld t=%.6g s newton %d linear %lld%s residual %.3e tolerance "
            "%.3e%s (%.3f s)\n",
            step, total, si->time, si->newton_iterations, si->linear_iterations, mg, si->residual,
            si->tolerance,
            si->reason == FCM_STEP_FIXED_ITERATIONS ? " (fixed iterations: not converged)" : "",
            si->time_total);
  }
}

/* Progress of the set-up on stderr: its phases, and the cell rules and level set as a bar on
 * a terminal, else a line per call. open: the characters of a line left open on the terminal
 * (a phase's start, a bar), which a warning or the phase's end finishes first; atomic: the
 * library's warnings come from its OpenMP threads too. */
typedef struct rules_progress_state {
  int tty;
  double t0;
  atomic_int open;
} rules_progress_state;

/* One progress report of `what` (done of total `unit`): a bar with the elapsed time and the
 * estimate on a terminal (the unit named when bar_unit is set), else a line. */
static void progress_report(rules_progress_state *ps, fcm_index done, fcm_index total,
                            const char *what, const char *unit, int bar_unit)
{
  const double el = fcm_wtime() - ps->t0;
  if (ps->tty) {
    const int width = 30, fill = (int)(width * done / (total > 0 ? total : 1));
    char bar[64];
    for (int i = 0; i < width; i++)
      bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    const double eta = done > 0 ? el / (double)done * (double)(total - done) : 0.0;
    int n = fprintf(stderr, "\r[%s] %s %lld/%lld%s%s  %.0f s  ETA %.0f s   ", bar, what,
                    (long long)done, (long long)total, bar_unit ? " " : "", bar_unit ? unit : "",
                    el, eta);
    if (done == total) fputc('\n', stderr), n = 0;
    atomic_store(&ps->open, n);
  } else {
    fprintf(stderr, "fcm-sim: %s %lld/%lld %s (%.1f s)\n", what, (long long)done, (long long)total,
            unit, el);
  }
}

static void rules_progress(fcm_index done, fcm_index total, void *user)
{
  progress_report(user, done, total, "cell rules", "cells", 0);
}

/* Progress of a level-set geometry build. */
static void geometry_progress(fcm_index done, fcm_index total, void *user)
{
  progress_report(user, done, total, "level set", "sub-cells", 1);
}

/* Finish the line left open on the terminal, if any. */
static void close_line(rules_progress_state *ps)
{
  if (atomic_exchange(&ps->open, 0) > 0) fputc('\n', stderr);
}

/* A set-up phase (fcm_setup_phase_fn). Its end: a line with its time. Its start: a line when it
 * is long (it reports progress, or it is Gmsh's meshing, which cannot: say it runs); on a
 * terminal the other phases' starts show what runs now on a line that the end replaces. */
static void setup_phase(const fcm_setup_phase_event *ev, void *user)
{
  rules_progress_state *ps = user;
  const int is_long = ev->progress || ev->phase == FCM_SETUP_VOLUME_MESH;
  if (!ev->finished) {
    close_line(ps);
    ps->t0 = fcm_wtime(); /* the bars' elapsed time and estimate are the phase's */
    if (is_long) {
      fprintf(stderr, "fcm-sim: %s: running%s\n", ev->what,
              ev->progress ? "" : " (Gmsh reports no progress)");
    } else if (ps->tty) {
      const int n = fprintf(stderr, "fcm-sim: %s ...", ev->what);
      atomic_store(&ps->open, n);
    }
    fflush(stderr);
    return;
  }
  char line[512];
  snprintf(line, sizeof line, "fcm-sim: %s: %.2f s", ev->what, ev->seconds);
  const int n = atomic_exchange(&ps->open, 0);
  if (ps->tty && n > 0 && !is_long) /* replace the start line */
    fprintf(stderr, "\r%-*s\n", n, line);
  else
    fprintf(stderr, "%s%s\n", n > 0 ? "\n" : "", line);
  fflush(stderr);
}

/* The library's warnings (FCM_LOG_WARNING: NaN voxels, holes filled, solver fallbacks) on
 * stderr, the first SIM_MAX_WARNINGS of them (all with --debug); errors are printed where
 * they end the run. Called from the library's OpenMP threads too (a simplification
 * fallback inside the cell loop): the count is atomic. */
#define SIM_MAX_WARNINGS 10
typedef struct warn_state {
  int all;                     /* --debug: print every warning */
  long long n;                 /* warnings so far */
  rules_progress_state *setup; /* a line it left open on the terminal is finished first */
} warn_state;

static void print_warning(void *user, fcm_log_level level, const char *msg)
{
  warn_state *ws = user;
  if (level != FCM_LOG_WARNING) return;
  long long k;
#pragma omp atomic capture
  k = ++ws->n;
  if ((ws->all || k <= SIM_MAX_WARNINGS + 1) && ws->setup) close_line(ws->setup);
  if (ws->all || k <= SIM_MAX_WARNINGS)
    fprintf(stderr, "fcm-sim: warning: %s\n", msg);
  else if (k == SIM_MAX_WARNINGS + 1)
    fprintf(stderr, "fcm-sim: warning: further warnings are not printed (--debug prints all)\n");
}

/* An error of the run: the library's message, which names the cause and what to change; the
 * traceback of the library's frames only with --debug. */
static void report_error(fcm_ctx *ctx, int debug, const char *what)
{
  if (debug) {
    fprintf(stderr, "fcm-sim: %s:\n", what);
    fcm_ctx_error_view(ctx, stderr);
    return;
  }
  fprintf(stderr, "fcm-sim: %s: %s (%s)\n", what, fcm_ctx_error_message(ctx),
          fcm_status_name(fcm_ctx_error_status(ctx)));
  fprintf(stderr, "fcm-sim: --debug shows where in the library it failed\n");
}

/* Exit code of a failed build: 2 for errors of the input (files, geometry, arguments), 1 for
 * the rest (memory, numerical failures). */
static int build_exit_code(fcm_status st)
{
  return st == FCM_ERR_ARG || st == FCM_ERR_IO || st == FCM_ERR_FORMAT || st == FCM_ERR_GEOMETRY ||
                 st == FCM_ERR_UNSUPPORTED
             ? 2
             : 1;
}

/* The warning when part of the body lies outside the background mesh. */
#define SIM_OUTSIDE_RTOL 1e-6
static void warn_outside(const fcm_simulation *sim)
{
  const fcm_cell_rules *r = fcm_simulation_cell_rules(sim);
  if (!r) return;
  const fcm_cell_rules_stats *S = fcm_cell_rules_get_stats(r);
  if (!(S->outside_volume > SIM_OUTSIDE_RTOL * S->geometry_volume)) return;
  static const char *const sides[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  fprintf(stderr,
          "fcm-sim: warning: %.6g m^3 of the body (%.3g%% of %.6g m^3) lies outside the "
          "background mesh and is cut off",
          S->outside_volume, 100.0 * S->outside_volume / S->geometry_volume, S->geometry_volume);
  const char *sep = " (beyond";
  for (int k = 0; k < 6; k++)
    if (S->outside_side_volume[k] > 0.0) {
      fprintf(stderr, "%s %s: %.3g m^3", sep, sides[k], S->outside_side_volume[k]);
      sep = ",";
    }
  fprintf(stderr,
          "%s; body [%g, %g] x [%g, %g] x [%g, %g], background [%g, %g] x [%g, %g] x "
          "[%g, %g]\n",
          sep[0] == ',' ? ")" : "", S->geometry_lo[0], S->geometry_hi[0], S->geometry_lo[1],
          S->geometry_hi[1], S->geometry_lo[2], S->geometry_hi[2], S->mesh_lo[0], S->mesh_hi[0],
          S->mesh_lo[1], S->mesh_hi[1], S->mesh_lo[2], S->mesh_hi[2]);
}

/* The warning when a boundary effect (traction, pressure, a fixed or motion constraint on the
 * "boundary") loses more than this share of its boundary to dropped cells, where no surface
 * rule carries its load or constraint. */
#define SIM_DROPPED_BOUNDARY_SHARE 1e-3
static void warn_dropped_boundary(const fcm_simulation *sim, const fcm_scene *scene)
{
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  if (!(c.effect_dropped_fraction > SIM_DROPPED_BOUNDARY_SHARE)) return;
  const fcm_effect *e = fcm_scene_get_effect(scene, c.effect_dropped_index);
  fprintf(stderr,
          "fcm-sim: warning: effects[%d] (%s) loses %.3g%% of the boundary area its region "
          "selects: it lies in cells with a volume fraction below quadrature.min_fraction = %g, "
          "which are dropped with their surface rules (%.3g of %.6g m^2 of the whole boundary); "
          "lower quadrature.min_fraction in the scene (0 keeps every cell with material)\n",
          c.effect_dropped_index, e ? fcm_effect_type_name(e->type) : "?",
          100.0 * c.effect_dropped_fraction, fcm_scene_get_quadrature(scene)->rules.min_fraction,
          c.dropped_area, c.boundary_area);
}

/* The warning on the first step that ends with inverted quadrature points (the run summary
 * counts them all). */
static void warn_inverted(int tty, const fcm_step_info *si, long long step)
{
  if (tty) fputc('\n', stderr);
  fprintf(stderr,
          "fcm-sim: warning: step %lld (t = %.6g s) ended with %lld inverted quadrature point%s "
          "(J = det F <= 0)",
          step, si->time, (long long)si->inverted_points, si->inverted_points == 1 ? "" : "s");
  if (si->inverted_cell >= 0)
    fprintf(stderr, ", the first in cell %lld at X = (%.6g, %.6g, %.6g) with J = %.3g",
            (long long)si->inverted_cell, si->inverted_position[0], si->inverted_position[1],
            si->inverted_position[2], si->inverted_det);
  fprintf(stderr, "; the stresses there are NaN (\"solver\": {\"on_inversion\": \"stop\"} ends "
                  "the run at such a step)\n");
}

/* The warning on the first frame holding NaN or infinite stresses. */
static void warn_nonfinite(int tty, const fcm_simulation_counters *c, int frame)
{
  if (tty) fputc('\n', stderr);
  fprintf(stderr,
          "fcm-sim: warning: frame %d (after step %lld) holds %lld NaN or infinite von Mises "
          "value%s (points with J = det F <= 0)\n",
          frame, c->steps, (long long)c->nonfinite_last, c->nonfinite_last == 1 ? "" : "s");
}

/* Write a checkpoint <dir>/<name>_checkpoint_NNNNNN.fcmck of the current step. */
static int write_checkpoint(fcm_ctx *ctx, fcm_simulation *sim, const char *dir, const char *name,
                            int quiet, int debug)
{
  char path[4096];
  snprintf(path, sizeof path, "%s/%s_checkpoint_%06lld.fcmck", dir, name,
           fcm_simulation_step_count(sim));
  if (fcm_simulation_write_checkpoint(sim, path) != FCM_OK) {
    report_error(ctx, debug, "writing a checkpoint");
    return 0;
  }
  if (!quiet && !isatty(2)) fprintf(stderr, "fcm-sim: checkpoint %s\n", path);
  return 1;
}

/* What the monitor of the run (on_step()) needs and keeps. */
typedef struct run_state {
  fcm_ctx *ctx;
  const scene_options *o;
  const char *dir, *name, *logpath;
  int write, tty;
  int frame; /* the next frame's index */
  /* warn once of each: an earlier run (a resumed checkpoint) may have warned already */
  int warned_inverted, warned_nonfinite;
  int stopped; /* 1: the monitor ended the run (and reported why) */
} run_state;

/* fcm_simulation_monitor_fn: after each step, the state's check, the warnings, the progress
 * line, the frame and log when due, and the checkpoint when due (after the frame: it counts
 * it). */
static fcm_status on_step(void *user, fcm_simulation *sim, const fcm_simulation_step_event *ev)
{
  run_state *r = user;
  const scene_options *o = r->o;
  const fcm_step_info *si = ev->info;
  r->stopped = 1;
  if (!fcm_simulation_state_finite(sim)) {
    fprintf(stderr, "fcm-sim: non-finite state after step %lld\n", ev->step);
    return FCM_ERR_NUMERIC;
  }
  if (si->inverted_points > 0 && !r->warned_inverted) {
    warn_inverted(r->tty, si, ev->step);
    r->warned_inverted = 1;
  }
  if (!o->quiet)
    progress(r->tty, ev->step - ev->first, ev->num_steps - ev->first, ev->step, ev->num_steps, si,
             ev->wall);
  if (r->write && fcm_simulation_frame_due(sim)) {
    if (fcm_simulation_write_frame(sim, r->dir, r->frame++) != FCM_OK ||
        fcm_simulation_write_log(sim, r->logpath) != FCM_OK) {
      report_error(r->ctx, o->debug, "writing the output");
      return FCM_ERR_IO;
    }
    fcm_simulation_counters c;
    fcm_simulation_get_counters(sim, &c);
    if (c.nonfinite_last > 0 && !r->warned_nonfinite) {
      warn_nonfinite(r->tty, &c, r->frame - 1);
      r->warned_nonfinite = 1;
    }
  }
  if (r->write && fcm_simulation_checkpoint_due(sim) &&
      !write_checkpoint(r->ctx, sim, r->dir, r->name, o->quiet, o->debug))
    return FCM_ERR_IO;
  r->stopped = 0;
  return FCM_OK;
}

/* --backend petsc: the PETSc driver with the PETSc arguments pargv, or why it cannot run;
 * the exit code. */
static int run_petsc_backend(const scene_options *o, int pargc, char **pargv)
{
#if FCM_HAVE_PETSC
  return o->print_scene || o->preview
             ? (fprintf(stderr,
                        "fcm-sim: --backend petsc: %s is the serial backend's (drop "
                        "--backend: it builds no distributed state)\n",
                        o->print_scene ? "--print-scene" : "--preview"),
                2)
             : sim_petsc_run(o->path, o->outdir, o->steps, o->check, o->quiet, o->plot,
                             o->check ? 0 : o->checkpoint_every, o->resume, pargc, pargv);
#else
  (void)o;
  (void)pargc;
  (void)pargv;
  fprintf(stderr, "fcm-sim: --backend petsc: this fcm was built without PETSc (CMake option "
                  "FCM_WITH_PETSC; Debian: bash setup.sh deps --petsc, then rebuild)\n");
  return 2;
#endif
}

/* The simulation options of the command line: the step limit, the checkpoint interval and
 * the progress reports of the build (into rps). */
static fcm_simulation_options simulation_options(const scene_options *o, rules_progress_state *rps)
{
  fcm_simulation_options so = fcm_simulation_options_default();
  so.max_steps = o->check ? (o->steps > 0 && o->steps < 3 ? o->steps : 3)
                          : (o->steps > 0 ? o->steps : FCM_DEFAULT);
  so.checkpoint_interval = o->check ? 0 : o->checkpoint_every;
  if (rps->tty || (o->progress && !o->quiet)) {
    so.rules_progress = rules_progress;
    so.rules_progress_user = rps;
    so.rules_progress_interval = rps->tty ? 0.2 : 2.0;
    so.geometry_progress = geometry_progress;
    so.geometry_progress_user = rps;
    so.setup_phase = setup_phase;
    so.setup_phase_user = rps;
  }
  return so;
}

/* A failed build or preview: the library's message (the traceback with --debug), a pointer to
 * --preview when a region is refused; the exit code. */
static int report_build_error(fcm_ctx *ctx, fcm_status st, const char *name, int debug)
{
  const char *msg = fcm_ctx_error_message(ctx);
  if (debug)
    fcm_ctx_error_view(ctx, stderr);
  else
    cli_report_scene_error("fcm-sim", name, msg);
  if (st == FCM_ERR_ARG && strstr(msg, "effects[") && strstr(msg, "region"))
    fprintf(stderr, "fcm-sim: --preview writes each region's nodes for a look in ParaView\n");
  return build_exit_code(st);
}

/* Build the simulation of the scene (and resume it from the checkpoint of --resume); 0, or the
 * exit code after reporting why not. */
static int build_simulation(fcm_ctx *ctx, fcm_scene *scene, const scene_options *o,
                            rules_progress_state *rps, fcm_simulation **sim)
{
  const fcm_simulation_options so = simulation_options(o, rps);
  const char *name = fcm_scene_name(scene);
  if (!o->quiet)
    fprintf(stderr, "fcm-sim: scene %s (%s): building\n", name, fcm_scene_source(scene));
  fcm_status st = fcm_simulation_create(ctx, scene, &so, sim);
  if (so.setup_phase) close_line(rps);
  if (st == FCM_OK && so.setup_phase) {
    fcm_simulation_counters c;
    fcm_simulation_get_counters(*sim, &c);
    fprintf(stderr, "fcm-sim: set-up: %.2f s\n", c.time_setup);
  }
  if (st != FCM_OK) return report_build_error(ctx, st, name, o->debug);
  warn_outside(*sim);
  warn_dropped_boundary(*sim, scene);
  if (o->resume) {
    if (fcm_simulation_read_checkpoint(*sim, o->resume) != FCM_OK) {
      fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
      return 2;
    }
    if (!o->quiet)
      fprintf(stderr, "fcm-sim: resumed from %s at step %lld (t = %.9g s)\n", o->resume,
              fcm_simulation_step_count(*sim),
              fcm_integrator_time(fcm_simulation_integrator(*sim)));
  }
  return 0;
}

/* --preview: the background and the geometry only, the preview files in the output directory
 * and the counts per region (also when a region is refused: the files show it); the exit code. */
static int run_preview(fcm_ctx *ctx, fcm_scene *scene, const scene_options *o,
                       rules_progress_state *rps)
{
  const char *name = fcm_scene_name(scene);
  const char *dir = o->outdir ? o->outdir : fcm_scene_get_output(scene)->directory;
  const int ne = fcm_scene_num_effects(scene);
  fcm_simulation_preview_info info;
  fcm_preview_effect *eff = calloc((size_t)ne + 1, sizeof *eff);
  if (!eff || !cli_make_dirs("fcm-sim", dir)) {
    free(eff);
    return 1;
  }
  const fcm_simulation_options so = simulation_options(o, rps);
  if (!o->quiet)
    fprintf(stderr, "fcm-sim: scene %s (%s): preview\n", name, fcm_scene_source(scene));
  const fcm_status st = fcm_simulation_write_preview(ctx, scene, &so, dir, &info, eff);
  if (so.setup_phase) close_line(rps);
  if (info.files > 0 && !o->quiet) {
    fcm_simulation_preview_view(scene, &info, eff, stdout);
    printf("  output      %s/%s_preview.pvd (%d files)\n", dir, name, info.files);
    fflush(stdout);
  }
  free(eff);
  return st == FCM_OK ? 0 : report_build_error(ctx, st, name, o->debug);
}

/* The output directory, the log path <dir>/<name>_log.csv (logsize bytes) and, unless the run
 * resumes, frame *frame (counted); 0 after reporting a failure. */
static int start_output(fcm_ctx *ctx, fcm_simulation *sim, const scene_options *o, const char *dir,
                        const char *name, char *logpath, size_t logsize, int *frame)
{
  if (!cli_make_dirs("fcm-sim", dir)) return 0;
  snprintf(logpath, logsize, "%s/%s_log.csv", dir, name);
  if ((!o->resume && fcm_simulation_write_frame(sim, dir, (*frame)++) != FCM_OK) ||
      fcm_simulation_write_log(sim, logpath) != FCM_OK) {
    report_error(ctx, o->debug, "writing the output");
    return 0;
  }
  return 1;
}

/* After fcm_simulation_run() returned st: the failed step's error (unless the monitor said
 * why), the final log and the summary; the exit code. */
static int finish_run(fcm_simulation *sim, fcm_status st, const run_state *rs, int frames_at_start)
{
  const scene_options *o = rs->o;
  const char *dir = rs->dir, *name = rs->name;
  if (st != FCM_OK) {
    if (rs->stopped) return 1; /* the monitor said why */
    if (rs->tty) fputc('\n', stderr);
    char what[160];
    snprintf(what, sizeof what, "scene %s: step %lld (t = %.6g s)", name,
             fcm_simulation_step_count(sim) + 1,
             fcm_integrator_time(fcm_simulation_integrator(sim)));
    report_error(rs->ctx, o->debug, what);
    if (rs->write && fcm_simulation_write_log(sim, rs->logpath) != FCM_OK)
      report_error(rs->ctx, o->debug, "writing the log");
    else if (rs->write && o->plot)
      sim_plot_log("fcm-sim", rs->logpath); /* the steps up to the failure */
    return 1;
  }
  if (rs->write && fcm_simulation_write_log(sim, rs->logpath) != FCM_OK) {
    report_error(rs->ctx, o->debug, "writing the log");
    return 1;
  }
  if (rs->write && o->plot && !sim_plot_log("fcm-sim", rs->logpath)) return 1;
  if (!o->quiet) {
    fcm_simulation_summary_view(sim, stdout);
    if (rs->write) {
      fcm_simulation_counters c;
      fcm_simulation_get_counters(sim, &c);
      sim_print_output(dir, name, rs->logpath, !(c.frames > 0 && (int)c.frames > frames_at_start),
                       o->plot);
    }
  }
  return 0;
}

void sim_print_output(const char *dir, const char *name, const char *logpath, int no_frame,
                      int plot)
{
  static const char *const series[] = {"background", "surface"};
  char path[4096];
  printf("  output    ");
  for (int k = 0; k < 2 && !no_frame; k++) {
    snprintf(path, sizeof path, "%s/%s_%s.pvd", dir, name, series[k]);
    struct stat sb;
    if (stat(path, &sb) == 0) printf("%s, ", path);
  }
  printf("%s%s", logpath, no_frame ? " (no new frame)" : "");
  snprintf(path, sizeof path, "%s/%s_log.png", dir, name);
  struct stat sb;
  if (plot && stat(path, &sb) == 0) printf(", %s", path);
  printf("\n");
}

static int scene_main(int argc, char **argv)
{
  scene_options o = {NULL, NULL, NULL, 0, -1, 0, 0, 0, 0, 0, 0, 0, 0};
  int pargc = 1;
  char **pargv = calloc((size_t)argc + 1, sizeof *pargv);
  if (!pargv) return 1;
  cli_split_petsc_args(&argc, argv, &pargc, pargv);
  const int parsed = parse_scene_args(argc, argv, &o);
  if (parsed >= 0 || o.backend == 1) {
    const int rc = parsed >= 0 ? parsed : run_petsc_backend(&o, pargc, pargv);
    free(pargv);
    return rc;
  }
  free(pargv);
  int rc = 1;
  fcm_ctx *ctx = NULL;
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  char logpath[4096];
  rules_progress_state rps = {!o.quiet && isatty(2), fcm_wtime(), 0};
  warn_state ws = {o.debug, 0, &rps};
  fcm_ctx_options co = fcm_ctx_options_default();
  co.log = print_warning;
  co.log_user = &ws;
  if (fcm_ctx_create(&co, &ctx) != FCM_OK) {
    fprintf(stderr, "fcm-sim: cannot create the fcm context\n");
    return 1;
  }
  fcm_status st = o.path ? fcm_scene_create_from_file(ctx, o.path, &scene)
                         : fcm_scene_create_default(ctx, &scene);
  if (st != FCM_OK) { /* invalid scene: the parser's message, nothing written */
    fprintf(stderr, "fcm-sim: %s\n", fcm_ctx_error_message(ctx));
    rc = 2;
    goto done;
  }
  if (o.print_scene) {
    printf("%s\n", fcm_scene_json(scene));
    rc = 0;
    goto done;
  }
  /* every input is checked before the set-up, which may take minutes */
  if (!o.check && !cli_check_output_dir(
                      "fcm-sim", o.outdir ? o.outdir : fcm_scene_get_output(scene)->directory)) {
    rc = 2;
    goto done;
  }
  if (o.resume && fcm_simulation_check_checkpoint(ctx, o.resume) != FCM_OK) {
    fprintf(stderr, "fcm-sim: --resume: %s\n", fcm_ctx_error_message(ctx));
    rc = 2;
    goto done;
  }
  if (fcm_scene_get_solver(scene)->threads > 0) /* every OpenMP loop of the run */
    omp_set_num_threads(fcm_scene_get_solver(scene)->threads);
  rps.t0 = fcm_wtime();
  if (o.preview) {
    rc = run_preview(ctx, scene, &o, &rps);
    goto done;
  }
  rc = build_simulation(ctx, scene, &o, &rps, &sim);
  if (rc != 0) goto done;
  rc = 1;
  const char *name = fcm_scene_name(scene);
  const char *dir = o.outdir ? o.outdir : fcm_scene_get_output(scene)->directory;
  int write = !o.check;
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  int frame = (int)c.frames, frames_at_start = frame;
  /* warn once of each: an earlier run (a resumed checkpoint) may have warned already */
  int warned_inverted = c.inverted_steps > 0, warned_nonfinite = c.nonfinite_frames > 0;
  int tty = !o.quiet && isatty(2);
  if (write && !start_output(ctx, sim, &o, dir, name, logpath, sizeof logpath, &frame)) goto done;
  run_state rs = {ctx, &o, dir, name, logpath, write, tty, frame, warned_inverted, warned_nonfinite,
                  0};
  st = fcm_simulation_run(sim, on_step, &rs);
  rc = finish_run(sim, st, &rs, frames_at_start);
done:
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  fcm_ctx_destroy(&ctx);
  return rc;
}

int main(int argc, char **argv)
{
  app_env_init(argc, argv);    /* OpenMP waiting, the CPU's BLAS kernels, huge pages (app_env.h) */
  fcm_blas_set_num_threads(1); /* fcm's OpenMP cell loops call LAPACK: no nested BLAS threads */
  return scene_main(argc, argv);
}
