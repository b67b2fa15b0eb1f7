/* The scene runner, output: the frames (background and surface VTU files, their PVD indexes;
 * a distributed run's background as one piece per process) and the per-step log (CSV). */
#include "scene/run_impl.h"
#include "scene/scene_impl.h"

#include "core/core_impl.h"
#include "embed/embed_impl.h"
#include "fem/fem_impl.h"
#include "sim/sim_backend.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/io.h"
#include "fcm/levelset.h"
#include "fcm/voxels.h"
#include "fcm/mesh.h"
#include "io/io_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* Create the PVD index <dir>/<name>_<kind>.pvd; after a restored checkpoint it first lists
 * the frames of the earlier run found in `dir` (<name>_<kind>_NNNN.vtu, NNNN = 0, 1, ...; .pvtu
 * for a distributed run's background). */
static fcm_status open_pvd(fcm_simulation *S, const char *dir, const char *kind, fcm_pvd **pvd)
{
  fcm_status st = FCM_OK;
  char path[4096];
  const char *name = fcm_scene_name(S->scene);
  snprintf(path, sizeof path, "%s/%s_%s.pvd", dir, name, kind);
  FCM_TRY(S->ctx, fcm_pvd_create(S->ctx, path, pvd));
  if (S->restored)
    for (long long k = 0; k < S->c.frames; k++) {
      struct stat sb;
      snprintf(path, sizeof path, "%s/%s_%s_%04lld.%s", dir, name, kind, k,
               /* a distributed run's background frames are .pvtu */
               fcm__integrator_distributed(S->integ, NULL) && strcmp(kind, "background") == 0
                   ? "pvtu"
                   : "vtu");
      if (stat(path, &sb) == 0) FCM_TRY(S->ctx, fcm_pvd_add(*pvd, S->frame_time[k], path));
    }
cleanup:
  return st;
}

/* A distributed run: this process's piece <name>_background_NNNN_<rank>.vtu of the background
 * frame (its own cells: the rules' cell mask, all cells on the root without rules; the node
 * fields from the replicated state, the stresses of its own cells computed here, *nonfinite
 * of them NaN or infinite), then the root's <name>_background_NNNN.pvtu naming the pieces
 * (path). Collective. */
static fcm_status write_background_pieces(fcm_simulation *S, const char *dir, int index,
                                          const double *u, const double *v, int root, char *path,
                                          size_t path_size, fcm_index *nonfinite)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = S->ctx;
  const fcm_cell_rules *R = fcm_space_cell_rules(S->space);
  const fcm_index nc = fcm_mesh_num_cells(S->mesh);
  const char *name = fcm_scene_name(S->scene);
  char stem[1024];
  int rank = 0, nprocs = 1;
  fcm__integrator_processes(S->integ, &rank, &nprocs);
  const int ns = snprintf(stem, sizeof stem, "%s_background_%04d", name, index);
  FCM_CHECK(ns > 0 && (size_t)ns < sizeof stem && strlen(dir) + (size_t)ns + 32 < path_size, ctx,
            FCM_ERR_ARG,
            "simulation: write_frame: the output directory or scene name is too long "
            "(%zu + %d characters)",
            strlen(dir), ns);
  unsigned char *keep = fcm__calloc(ctx, (size_t)nc + 1, 1);
  st = keep ? FCM_OK
            : fcm__error(ctx, FCM_ERR_ALLOC, __FILE__, __LINE__, __func__,
                         "simulation: out of memory (cell mask of %lld cells)", (long long)nc);
  for (fcm_index c = 0; keep && c < nc; c++)
    keep[c] = fcm__cell_rules_owns(R, c) && (R || root);
  snprintf(path, path_size, "%s/%.1023s_%d.vtu", dir, stem, rank);
  if (st == FCM_OK)
    st = fcm__space_write_vtu_piece(S->space, fcm_scene_get_material(S->scene), u, v, keep, rank,
                                    path, nonfinite);
  fcm__free(ctx, keep);
  FCM_TRY(ctx, fcm__integrator_reduce_status(S->integ, st, NULL, 0)); /* agree on st */
  snprintf(path, path_size, "%s/%.1023s.pvtu", dir, stem);
  if (root) FCM_TRY(ctx, fcm__write_pvtu(ctx, path, stem, nprocs, 1, 1));
cleanup:
  return st;
}

fcm_status fcm_simulation_write_frame(fcm_simulation *S, const char *dir, int index)
{
  fcm_status st = FCM_OK;
  char path[4096];
  fcm_ctx *ctx = S ? S->ctx : NULL;
  int root = 1, dist = 0;
  double t0 = fcm_wtime(), time = 0.0;
  fcm_index bad_cells = 0, bad_points = 0; /* NaN or infinite von Mises values written */
  FCM_CHECK(S && dir && index >= 0, ctx, FCM_ERR_ARG,
            "simulation: write_frame needs a directory and index >= 0 (got %d)", index);
  const char *name = fcm_scene_name(S->scene);
  const fcm_scene_output *out = fcm_scene_get_output(S->scene);
  const fcm_material *mat = fcm_scene_get_material(S->scene);
  time = fcm_integrator_time(S->integ);
  const double *u = fcm_integrator_displacement(S->integ), *v = fcm_integrator_velocity(S->integ);
  dist = fcm__integrator_distributed(S->integ, &root);
  /* room for the frame time first: a frame that is written is also counted */
  FCM_TRY(ctx, fcm__sim_grow(ctx, (void **)&S->frame_time, &S->frame_cap, S->c.frames + 1,
                             sizeof *S->frame_time));
  /* distributed: every process writes its piece, the root the .pvtu and the PVD */
  if (dist && out->write_background)
    FCM_TRY(ctx, write_background_pieces(S, dir, index, u, v, root, path, sizeof path, &bad_cells));
  else if (out->write_background) {
    snprintf(path, sizeof path, "%s/%s_background_%04d.vtu", dir, name, index);
    FCM_TRY(ctx, fcm__space_write_vtu_counted(S->space, mat, u, v, path, &bad_cells));
  }
  if (out->write_background && root) {
    if (!S->pvd_bg) FCM_TRY(ctx, open_pvd(S, dir, "background", &S->pvd_bg));
    FCM_TRY(ctx, fcm_pvd_add(S->pvd_bg, time, path));
  }
  if (S->surf && root) { /* the surface's fields come from u alone: whole on every process */
    snprintf(path, sizeof path, "%s/%s_surface_%04d.vtu", dir, name, index);
    FCM_TRY(ctx, fcm__embedded_surface_write_vtu_counted(S->surf, mat, u, path, &bad_points));
    if (!S->pvd_surf) FCM_TRY(ctx, open_pvd(S, dir, "surface", &S->pvd_surf));
    FCM_TRY(ctx, fcm_pvd_add(S->pvd_surf, time, path));
  }
cleanup:
  /* distributed: a failure on any process (the root's files included) is returned on every
   * process, and no process counts the frame then */
  if (dist) st = fcm__integrator_finish(S->integ, st);
  if (dist && st == FCM_OK) { /* every process: the pieces' cells and the root's points */
    double q[2] = {(double)bad_cells, (double)bad_points};
    st = fcm__integrator_reduce(S->integ, q, 2);
    bad_cells = (fcm_index)q[0], bad_points = (fcm_index)q[1];
  }
  if (st == FCM_OK) {
    S->frame_time[S->c.frames++] = time;
    S->c.time_output += fcm_wtime() - t0;
    fcm__sim_count_frame(&S->c, S->c.steps, bad_cells + bad_points);
    /* the log row of the step this frame shows (none for the initial state) */
    if (S->c.steps > 0 && S->log_n == S->c.steps)
      S->log[S->log_n - 1].nonfinite = bad_cells + bad_points;
  }
  return st;
}

fcm_status fcm_simulation_write_log(fcm_simulation *S, const char *path)
{
  fcm_status st = FCM_OK;
  fcm__atomic_file af;
  memset(&af, 0, sizeof af);
  FCM_CHECK(S && path, S ? S->ctx : NULL, FCM_ERR_ARG, "simulation: write_log needs a path");
  FCM_TRY(S->ctx, fcm__io_atomic_open(S->ctx, path, 0, NULL, &af));
  FCM_TRY(S->ctx, fcm__io_atomic_printf(
                      S->ctx, &af,
                      "step,time,newton_iterations,linear_iterations,residual,energy,pieces,mass,"
                      "momentum_x,momentum_y,momentum_z"));
  for (int k = 0; k < S->num_react; k++) {
    const int i = S->react_effect[k];
    FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af,
                                          ",reaction_%d_x,reaction_%d_y,reaction_%d_z,moment_%d_x,"
                                          "moment_%d_y,moment_%d_z",
                                          i, i, i, i, i, i));
  }
  FCM_TRY(S->ctx,
          fcm__io_atomic_printf(S->ctx, &af,
                                ",inverted_points,nonfinite_stresses,tolerance,kinetic_energy,"
                                "elastic_energy,load_work,wall_time%s\n",
                                S->c.contacts > 0 ? ",contact_points,contact_min_distance,"
                                                    "contact_energy,friction_dissipation"
                                                  : ""));
  for (long long k = 0; k < S->log_n; k++) {
    const fcm__log_row *r = &S->log[k];
    FCM_TRY(S->ctx,
            fcm__io_atomic_printf(
                S->ctx, &af, "%lld,%.17g,%lld,%lld,%.17g,%.17g,%lld,%.17g,%.17g,%.17g,%.17g", k + 1,
                r->time, r->newton, r->linear, r->residual, r->energy, r->pieces, r->mass,
                r->momentum[0], r->momentum[1], r->momentum[2]));
    for (int j = 0; j < 6 * S->num_react; j++)
      FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af, ",%.17g",
                                            S->react_log[(size_t)k * 6 * S->num_react + j]));
    /* counts: nan where not known (no frame after the step; a row of an older checkpoint),
     * as the reactions such a row lacks */
    const long long counts[2] = {r->inverted, r->nonfinite};
    for (int j = 0; j < 2; j++)
      FCM_TRY(S->ctx, counts[j] >= 0 ? fcm__io_atomic_printf(S->ctx, &af, ",%lld", counts[j])
                                     : fcm__io_atomic_printf(S->ctx, &af, ",nan"));
    /* the stopping rule's tolerance beside the residual: an interactive step
     * (newton_fixed_iterations) may end above it */
    FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af, ",%.17g,%.17g,%.17g,%.17g,%.6g",
                                          r->tolerance, r->kinetic, r->elastic, r->work, r->wall));
    if (S->c.contacts > 0)
      FCM_TRY(S->ctx,
              r->contact_points >= 0
                  ? fcm__io_atomic_printf(S->ctx, &af, ",%lld,%.17g,%.17g,%.17g", r->contact_points,
                                          r->contact_dmin, r->contact_energy, r->friction)
                  : fcm__io_atomic_printf(S->ctx, &af, ",nan,nan,nan,nan"));
    FCM_TRY(S->ctx, fcm__io_atomic_printf(S->ctx, &af, "\n"));
  }
  FCM_TRY(S->ctx, fcm__io_atomic_commit(S->ctx, &af));
cleanup:
  if (st != FCM_OK && S) fcm__io_atomic_abort(S->ctx, &af);
  return st;
}
