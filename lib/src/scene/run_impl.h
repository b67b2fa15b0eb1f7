/* scene module internals: the simulation object shared by the runner's files (run.c building,
 * run_mesh.c, run_effects.c, run_step.c, run_output.c, run_summary.c, run_petsc.c) and checkpoint.c
 * (saving and restoring a run). */
#ifndef FCM_SCENE_RUN_IMPL_H
#define FCM_SCENE_RUN_IMPL_H

#include "core/core_impl.h"
#include "fcm/embed.h"
#include "fcm/fem.h"
#include "fcm/geom.h"
#include "fcm/io.h"
#include "fcm/mesh.h"
#include "fcm/simulation.h"
#include "fem/fem_backend.h"

/* One row of the per-step log: the step (its Newton residual and the stopping rule's
 * tolerance, fcm_step_info), and the body after it (separate bodies, mass and
 * linear momentum over the body's own quadrature points, fcm_space_momentum(); its inverted
 * quadrature points and the cell of the first, fcm_step_info; the NaN or infinite von Mises
 * values of the frame written after the step). -1: not known (inverted and inverted_cell of a
 * row restored from an older checkpoint; nonfinite of a step without a frame); NaN: tolerance
 * of a row restored from a checkpoint older than version 5, the energies (kinetic, elastic and
 * the load work, fcm_step_info) of one older than version 6. */
typedef struct fcm__log_row {
  double time, residual, tolerance, energy, wall;
  double kinetic, elastic, work;
  long long newton, linear;
  long long pieces;
  double mass, momentum[3];
  long long inverted, inverted_cell, nonfinite;
  /* contact scenes (fcm_integrator_contact_stats() after the step; not kept by checkpoints:
   * -1 and NaN in rows restored from one) */
  long long contact_points;
  double contact_dmin, contact_energy, friction;
} fcm__log_row;

/* The passes over each kind's points that quadrature.simplify = "auto" was told to expect, by
 * source (their sums are fcm_cell_rules_options.expected_assemblies; run.c), for the summary.
 * The set-up's space and integrator, and each cut's new ones, integrate every cell again. */
typedef struct fcm__auto_uses {
  double steps;    /* stiffness: force and tangent, RUN_ASSEMBLIES_PER_STEP per time or load step */
  double loads;    /* stiffness: the body-force assemblies of the set-up and of every cut */
  double frames;   /* stiffness: the stresses of every frame written */
  double matrix;   /* mass: the mass matrix of the set-up and of every cut */
  double momentum; /* mass: the log's element mass blocks (fcm_space_momentum()), likewise */
} fcm__auto_uses;

/* How fcm__simulation_create() makes a simulation: the public options and the backend that
 * distributes it. */
typedef struct fcm__simulation_config {
  fcm_simulation_options opts;
  /* the distributed backend (fem/fem_backend.h; NULL: serial), borrowed during the create:
   * its reduce sums the inputs of the rules' quadrature.simplify = "auto" choice over the
   * processes, and fcm__integrator_attach_backend() gives the integrator its own reference
   * (set up for the space) before the integrator's setup; the log's partial quantities (mass,
   * momentum) are summed through it, and cuts hand it on to each new integrator */
  const fcm__backend *backend;
  /* with a backend: the cells whose points this process integrates (every cell is still
   * classified, so the space and its DOF numbering are those of the serial run) */
  const unsigned char *cell_mask;
  /* NULL, or with a backend: each process intersects its share of the cells and the exchange
   * hands over the others' classes (fcm__cell_rules_create_distributed(), embed/embed_impl.h) */
  const struct fcm__rules_exchange *exchange;
} fcm__simulation_config;

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
  fcm_index nn;               /* background nodes */
  fcm_embedded_surface *surf; /* the surface frames write (NULL: none) */
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
  /* the scene's cuts ("cut" effects) in time order; the first cuts_applied of them have been
   * applied (the rules hold them, with the host's cuts: fcm_simulation_cut()) */
  int num_cuts, cuts_applied;
  const fcm_effect **cuts;
  /* The rule statistics of the set-up (a cut replaces the rules, whose statistics are then
   * the cut's) and of each cut applied, the scene's and the host's in the order they came
   * (cut_stats[k], k < c.cuts: the cells that cut integrated again; zero for a cut whose
   * surface missed the body's box), with its wall time (cut_time[k]: rules, space and
   * integrator), for the summary. */
  fcm_cell_rules_stats setup_stats;
  fcm__auto_uses auto_uses; /* with quadrature.simplify = "auto" */
  fcm_cell_rules_stats *cut_stats;
  long long cut_cap; /* entries of cut_stats, cut_time, cut_solver, cut_at */
  double *cut_at;    /* each cut's simulated time */
  int api_cuts;      /* of the cuts, those fcm_simulation_cut() applied */
  double *cut_time;
  double *cut_solver;  /* each cut's seconds of the linear solver's structure (of cut_time) */
  double cut_phase[4]; /* the last cut's rules, space, integrator and solver-structure seconds
                          (the step adds them to the counters' time_cut_*) */
  /* cuts whose integrator and output surface were made on two threads; 1 in cuts_in_turn: one
   * after the other on every thread (the sequence the tests compare with) */
  int cuts_side_by_side, cuts_in_turn;
  fcm_index pieces;     /* separate bodies of the current space (fcm_space_num_bodies()) */
  fcm_index cut_pieces; /* those of a cut's space, counted by its parts (cut_part()) */
  long long base_factorizations, base_analyses, base_fallbacks; /* of integrators before cuts */
  /* "octree": {"cuts": {"when": "cut"}}: the refinement along the cuts done when the first cut
   * applied: the time, the cells before and after, the wall time (refined 0: not yet) */
  int refined;
  double refined_at, refine_seconds;
  fcm_index refine_cells[2];
  fcm_index base_nodes, base_cells;      /* the background before a refinement during the run (the
                                            checkpoint fingerprint) */
  fcm_index base_dofs, base_constrained; /* DOFs and constrained DOFs before any cut (the
                                            checkpoint fingerprint) */
  /* log */
  fcm__log_row *log;
  long long log_n, log_cap;
  /* reactions in the log: the constraint effects (fixed, motion) in effect order, their effect
   * index and integrator constraint id; per log row 6 x num_react values (force x, y, z,
   * moment x, y, z; NaN where unknown, e.g. rows of a version-2 checkpoint) */
  int num_react;
  int *react_effect, *react_id;
  double *react_log;
  long long react_cap;
  /* the distributed backend of the create (fcm__simulation_config; NULL afterwards and in
   * serial runs) */
  const fcm__simulation_config *config;
  int distributed; /* 1: built for the distributed backend (a surface gets a volume mesh) */
  /* what the voxel or level-set geometry reported ("" for the other kinds) */
  char geometry_note[256];
  /* the set-up phase running (fcm_setup_phase_event; -1: none), its start and its words; bit p
   * of phases_run: phase p ran (the summary lists those) */
  int phase, phase_progress;
  double phase_t0;
  char phase_what[320];
  unsigned phases_run;
};

/* A set-up phase starts: `what` (printf format) in words for the user; progress: 1 when it
 * reports progress meanwhile. The options' setup_phase hears of it; the phase's clock starts
 * after the call, so the host's printing is not counted in it (run.c). */
void fcm__sim_phase_begin(fcm_simulation *S, fcm_setup_phase p, int progress, const char *what, ...)
    FCM__PRINTF(4, 5);

/* The running phase ended: its time into the counters, then the options' setup_phase (run.c). */
void fcm__sim_phase_end(fcm_simulation *S);

/* Put the scene section `path` before the recorded error's message, unless the message
 * names it already (run.c). */
void fcm__sim_name_section(fcm_ctx *ctx, const char *path);

/* Grow an array of `size`-byte items to hold at least `need` (doubling). */
fcm_status fcm__sim_grow(fcm_ctx *ctx, void **array, long long *cap, long long need, size_t size);

/* Recount the inversion and frame counters of S->c (inverted_*, nonfinite_*) from the log's
 * rows, as a restored checkpoint leaves them (run_step.c). */
void fcm__sim_count_log(fcm_simulation *S);

/* Centre of mass of the body at displacement u (NULL: the reference one), 1^T M x / 1^T M 1
 * per component; dynamic scenes only (the mass matrix). Collective in a distributed run
 * (run_effects.c). */
fcm_status fcm__sim_center_of_mass(const fcm_simulation *S, const double *u, double com[3]);

/* Run the initialize hooks of the scene's effects into one velocity, set once (run_effects.c). */
fcm_status fcm__sim_initialize_effects(fcm_simulation *S);

/* The frame counters after a frame of the state after step `step` with `nonfinite` NaN or
 * infinite von Mises values (run_step.c). */
void fcm__sim_count_frame(fcm_simulation_counters *c, long long step, fcm_index nonfinite);

/* Apply the next cut of the scene (S->cuts[S->cuts_applied]): rules, space, integrator and the
 * output's element map are replaced; the state carries over (run.c). */
fcm_status fcm__sim_apply_cut(fcm_simulation *S);

/* A cut along surf (reference coordinates; NULL: it missed the body's box) at simulated time
 * `at`, started at wall time t0: the work of fcm__sim_apply_cut() after its surface, entry
 * S->c.cuts of the per-cut statistics (run.c). */
fcm_status fcm__sim_cut_along(fcm_simulation *S, const fcm_surface *surf, double at, double t0);

/* Room for entry k of the per-cut statistics (run.c). */
fcm_status fcm__sim_cut_room(fcm_simulation *S, int k);

/* The counters' time of a cut that took `seconds` (its phases: S->cut_phase) (run.c). */
void fcm__sim_count_cut(fcm_simulation *S, double seconds);

/* The background mesh and the embedded geometry (S->mesh, S->nn, S->geom; no geometry for a
 * scene without one), the set-up's first phases; errors of the inputs name the scene section
 * they come from (run_mesh.c). */
fcm_status fcm__sim_build_mesh_geometry(fcm_simulation *S);

/* The surface of cut effect c: the plane is clipped to the body's bounding box enlarged by 10 %
 * of its diagonal (before the transform). *surf NULL: a plane that misses the box (run.c). */
fcm_status fcm__sim_cut_surface(fcm_simulation *S, const fcm_effect_cut *c, fcm_surface **surf);

/* The background nodes of region r (box, half-space, all: by position; nodes: by id) into nodes
 * (NULL: count only), ascending; their count. Ids of a nodes region outside [0, num nodes) are
 * left out, the first of them in *bad (-1: none; bad may be NULL). No allocation (preview.c). */
fcm_index fcm__sim_select_nodes(const fcm_mesh *mesh, const fcm_region *r, fcm_index *nodes,
                                fcm_index *bad);

/* Refuse, before the set-up's cell rules, a fixed or motion effect whose region names a node out
 * of range, selects no background node, or only nodes that no cell with material uses, by the
 * coarse classification of the cells against the geometry's surface
 * (fcm__embed_classify_coarse(): conservative, so the exact check after the rules stays):
 * FCM_ERR_ARG naming effects[i], the region and the counts; FCM_ERR_ALLOC (preview.c). */
fcm_status fcm__sim_check_regions(fcm_simulation *S);

/* The background mesh and the embedded geometry of a scene (NULL when it has none), built as
 * fcm_simulation_create() builds them, for a driver of its own (the PETSc backend, fcm/petsc.h);
 * the caller destroys both (run_mesh.c). */
FCM_COMPONENT_API fcm_status fcm__scene_mesh_geometry(fcm_ctx *ctx, const fcm_scene *scene,
                                                      fcm_mesh **mesh, fcm_geometry **geom);

/* fcm_simulation_create() with a configuration: cfg->opts, and the backend that distributes
 * the run (fcm__simulation_config; the PETSc one: run_petsc.c). Collective over the backend's
 * processes. (run.c) */
FCM_COMPONENT_API fcm_status fcm__simulation_create(fcm_ctx *ctx, const fcm_scene *scene,
                                                    const fcm__simulation_config *cfg,
                                                    fcm_simulation **out);

/* A distributed run's fcm_simulation_summary_view() (collective; f may be NULL on all but one
 * process): the rules' point counts and the body's largest |u| summed / maximized over the
 * processes' own cells first (each process's rules carry its own cells' points only). */
FCM_COMPONENT_API fcm_status fcm__simulation_summary_view_distributed(fcm_simulation *S, FILE *f);

#endif /* FCM_SCENE_RUN_IMPL_H */
