/* scene module internals: the simulation object shared by run.c (building, stepping,
 * output) and checkpoint.c (saving and restoring a run). */
#ifndef FCM_SCENE_RUN_IMPL_H
#define FCM_SCENE_RUN_IMPL_H

#include "fcm/embed.h"
#include "fcm/geom.h"
#include "fcm/io.h"
#include "fcm/mesh.h"
#include "fcm/simulation.h"

/* One row of the per-step log. */
typedef struct fcm__log_row {
  double time, residual, energy, wall;
  long long newton, linear;
} fcm__log_row;

struct fcm_simulation {
  fcm_ctx *ctx;
  const fcm_scene *scene;
  fcm_simulation_options opts;
  fcm_mesh *mesh;
  fcm_geometry *geom;
  fcm_cell_rules *rules;
  fcm_space *space;
  fcm_integrator *integ;
  fcm_simulation_counters c;
  long long num_steps;
  /* output scratch */
  fcm_index nn; /* background nodes */
  double *node_u, *node_v;
  int32_t *cell_active;
  double *cell_phi;
  fcm_index ns, nt; /* surface points and triangles (compacted) */
  fcm_index *surf_tri, *surf_cell;
  double *surf_X, *surf_xi, *surf_u, *surf_x;
  fcm_pvd *pvd_bg, *pvd_surf;
  /* times of the frames written (frame k at frame_time[k]); c.frames of them */
  double *frame_time;
  long long frame_cap;
  /* 1 after a checkpoint was restored and before the first frame: the PVD indexes are
   * rebuilt from frame_time when they are first written */
  int restored;
  /* a free body (dynamic, no constraint, gravity or surface load): its centre of mass at
   * t = 0, for the drift in the summary */
  int free_body;
  double com0[3];
  /* copies of the surface-load effects: the integrator's callbacks get these as their
   * (mutable) user pointer, so the scene's const effects are never cast */
  fcm_effect *loads;
  int num_loads;
  /* log */
  fcm__log_row *log;
  long long log_n, log_cap;
  /* what the voxel or level-set geometry reported ("" for the other kinds) */
  char geometry_note[256];
};

/* Grow an array of `size`-byte items to hold at least `need` (doubling). */
fcm_status fcm__sim_grow(fcm_ctx *ctx, void **array, long long *cap, long long need, size_t size);

#endif /* FCM_SCENE_RUN_IMPL_H */
