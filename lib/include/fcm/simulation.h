/* fcm — running a scene (lib/METHOD.md §1.2): build the background mesh, the embedded geometry, its
 * cell rules, the space and an integrator carrying exactly the scene's effects; step it;
 * write VTU/PVD frames of the background field and of the deformed embedded surface and a
 * CSV log per step. Counters say what was computed and what was skipped.
 *
 * Pipeline derived from the scene: no cell rules without a geometry; surface rules only with
 * a traction or pressure effect (or an explicit surface strength); one body-force pass per
 * gravity effect and none without; no inertia (static integrator) for a static scene; no
 * damping matrix without a damping effect; Schwarz blocks only for cut cells below the
 * threshold (with none, the Krylov solver falls back to Jacobi and no block is set up). */
#ifndef FCM_SIMULATION_H
#define FCM_SIMULATION_H

#include <stdio.h>

#include "fcm/core.h"
#include "fcm/scene.h"
#include "fcm/sim.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The phases of fcm_simulation_create()'s set-up, in the order they run with
 * background.fit_background (the grid is fitted around the geometry); otherwise the background
 * mesh comes first. A phase the scene does not need is skipped; none runs twice. */
typedef enum fcm_setup_phase {
  FCM_SETUP_READ,           /**< reading the geometry's file: a surface, a Gmsh or TetGen mesh, a
                                 voxel image */
  FCM_SETUP_FILL_HOLES,     /**< closing the surface's holes (geometry.fill_holes) */
  FCM_SETUP_SURFACE_CHECK,  /**< orienting and checking the surface (closed, manifold, no
                                 self-intersection) */
  FCM_SETUP_VOLUME_MESH,    /**< tetrahedralizing the surface with Gmsh (reports no progress) */
  FCM_SETUP_GEOMETRY,       /**< building the geometry: a shape, the voxels merged into boxes, a
                                 level set marched (progress: geometry_progress), the surface
                                 alone */
  FCM_SETUP_TRANSFORM,      /**< geometry.transform applied */
  FCM_SETUP_BACKGROUND,     /**< the background mesh: a grid (fitted around the geometry), or
                                 read from a Gmsh file */
  FCM_SETUP_CELL_RULES,     /**< classifying the cells and building the cut cells' rules,
                                 simplification included (progress: rules_progress) */
  FCM_SETUP_SPACE,          /**< the space: DOFs, element data */
  FCM_SETUP_INTEGRATOR,     /**< the integrator: effects, constraints, the mass matrix and body
                                 forces, the solver's set-up */
  FCM_SETUP_LOG,            /**< the element mass blocks of the log's mass and momentum */
  FCM_SETUP_CUTS,           /**< the cut effects at t = 0 */
  FCM_SETUP_OUTPUT_SURFACE, /**< the surface the frames write, located in the background cells */
  FCM_SETUP_PHASE_COUNT
} fcm_setup_phase;

/** The phase in a few words ("reading", "filling holes", "volume meshing (Gmsh)", ...; "?" out
 * of range): the names of the run summary. Static storage; thread safe. */
FCM_API const char *fcm_setup_phase_name(fcm_setup_phase phase);

/** What fcm_simulation_create() reports at the start and at the end of a set-up phase. */
typedef struct fcm_setup_phase_event {
  fcm_setup_phase phase;
  const char *what; /**< the phase and what it works on, in words for a user: "reading the
                         surface bunny.obj", "meshing the volume with Gmsh"; valid during the
                         call. The cell rules' end adds the share of the boundary area in
                         dropped cells when there is any */
  int finished;     /**< 0: the phase starts; 1: it ended (a phase that fails reports no end:
                         fcm_simulation_create() returns the error) */
  double seconds;   /**< 0 at the start; at the end the phase's wall time
                         (fcm_simulation_counters.time_setup_phase) */
  int progress;     /**< 1: the phase reports its progress meanwhile (rules_progress,
                         geometry_progress); 0: it reports none */
} fcm_setup_phase_event;

/** Called at the start and end of each set-up phase, on the calling thread, never from inside
 * a parallel region. */
typedef void (*fcm_setup_phase_fn)(const fcm_setup_phase_event *event, void *user);

/** Options of fcm_simulation_create(); initialize with fcm_simulation_options_default(). */
typedef struct fcm_simulation_options {
  fcm_index max_steps;     /**< >= 1: stop after this many steps (fcm_simulation_done());
                                FCM_DEFAULT (default): the scene's step count */
  int checkpoint_interval; /**< >= 0: fcm_simulation_checkpoint_due() every n-th step (0:
                                never); FCM_DEFAULT (default): the scene's
                                output.checkpoint_interval */
  fcm_cell_rules_progress_fn rules_progress;   /**< progress of the cell rules build
                                  (fcm_cell_rules_options.progress); NULL (default): none */
  void *rules_progress_user;                   /**< its argument; default NULL */
  double rules_progress_interval;              /**< seconds between calls, >= 0; default 0.1
                                                    (also of geometry_progress) */
  fcm_level_set_progress_fn geometry_progress; /**< progress of building a level-set geometry
                                (fcm_level_set_options.progress: sub-cells marched); NULL
                                (default): none */
  void *geometry_progress_user;                /**< its argument; default NULL */
  fcm_setup_phase_fn setup_phase;              /**< called when each set-up phase starts and ends
                                                    (fcm_setup_phase_event); NULL (default): none */
  void *setup_phase_user;                      /**< its argument; default NULL */
  int host_cuts; /**< 1: the host will cut the body with fcm_simulation_cut(): the integrator
                      keeps what a cut reuses, as for a scene with cut effects (each element's
                      mass block and load vectors, nn (nn + 1) / 2 + 3 nn doubles per load), so
                      that a cut integrates only the elements it changes; 0 (default): only for
                      a scene with cut effects (a host's cut then integrates every element) */
} fcm_simulation_options;

/** Defaults as documented on each member. */
FCM_API fcm_simulation_options fcm_simulation_options_default(void);

/** What the pipeline computed (counts) and which stages it used (flags 0/1). */
typedef struct fcm_simulation_counters {
  int cell_rules;                /**< 1: embedded cell rules were built (scene has a geometry) */
  int surface_rules;             /**< 1: the cell rules carry surface rules */
  unsigned rule_kinds;           /**< volume rule kinds built (FCM_RULES_* bits of fcm/embed.h):
                                      stiffness always, mass only for a dynamic scene; 0 without
                                      cell rules */
  int inertia;                   /**< 1: dynamic integrator (inertia term); 0: static */
  int mass_assemblies;           /**< consistent-mass assemblies: 1 for dynamic scenes, 0 static */
  int body_force_assemblies;     /**< body-force assemblies the integrator's setup made (one per
                                      gravity effect) */
  int scale_assemblies;          /**< 1: a static scene without gravity assembled the body force of
                                      rho a_rep once for the Newton force scale (see sim.h) */
  int traction_assemblies;       /**< surface load assemblies the setup made (one per traction or
                                      pressure effect) */
  int damping;                   /**< 1: a Rayleigh damping matrix is used */
  int initial_velocity;          /**< initial-velocity effects applied */
  int constraints;               /**< constraint sets (fixed and motion effects) */
  int contacts;                  /**< contact obstacles (contact effects) */
  long long contact_evaluations; /**< evaluations of the contact terms (0 without contact) */
  long long contact_points_max;  /**< the most point-obstacle pairs within d^ after a step */
  double contact_min_distance;   /**< the smallest signed distance to an obstacle over every
                                      accepted state (each substep's end; HUGE_VAL: no contact
                                      effect or no step) */
  double contact_energy_max;     /**< the largest barrier energy after a step (J) */
  double friction_dissipation;   /**< the friction's work summed over the steps (J) */
  fcm_index constrained_nodes;   /**< background nodes named by them (with or without DOFs) */
  fcm_index constrained_dofs;    /**< constrained DOFs after setup */
  fcm_index boundary_points;     /**< embedded-boundary points held by `boundary` constraints */
  fcm_index schwarz_blocks;      /**< cut cells given a Schwarz block (0: no Schwarz set up) */
  int krylov;                    /**< 1: Krylov solves (CG, MINRES); 0: direct or multigrid */
  int multigrid;                 /**< 1: multigrid, as the Krylov preconditioner or the solver */
  long long steps;               /**< accepted steps */
  long long newton_iterations, linear_iterations, tangent_assemblies;
  long long multigrid_cycles;      /**< multigrid cycles (fcm_step_info.multigrid_cycles, summed;
                                        not in checkpoints: counted from the restore on) */
  long long factorizations;        /**< numeric factorizations / preconditioner setups (total) */
  long long reused_factorizations; /**< Newton iterations solved with a kept factorization
                                        (fcm_step_info.reused_factorizations, summed; not in
                                        checkpoints: counted from the restore on) */
  long long analyses;              /**< symbolic analyses (total) */
  long long direct_fallbacks;
  long long frames;    /**< frames written */
  fcm_index num_dofs;  /**< DOFs now (cuts add copies) */
  int cuts;            /**< cuts applied so far: cut effects and fcm_simulation_cut() */
  int cuts_missed;     /**< of them, cuts that missed the body (no cell got a new piece) */
  fcm_index cut_cells; /**< cells integrated again because a cut reached them (summed) */
  fcm_index pieces;    /**< separate bodies now (fcm_space_num_bodies()) */
  fcm_index surface_points, surface_triangles; /**< the embedded boundary written per frame
                                                    (without the cut faces) */
  /* Inversion: quadrature points of the body with J = det F <= 0 after a step
   * (fcm_step_info.inverted_points). After a restored checkpoint these and the frame counts
   * below are recounted from the log's rows. */
  long long inverted_steps;      /**< steps that ended with inverted points */
  long long inverted_first_step; /**< the first of them (0: none) */
  double inverted_first_time;    /**< its time (0: none) */
  fcm_index inverted_first_cell; /**< the background cell of its first inverted point (-1: none,
                                      or not known: a row of an older checkpoint) */
  fcm_index inverted_max;        /**< the most inverted points after one step (0: none) */
  long long inverted_max_step;   /**< the first step with that many (0: none) */
  /* Frames whose von Mises stresses (background cell averages, surface points) hold NaN or
   * infinite values: the stresses of points with J <= 0 (fcm_space_element_stress()). */
  long long nonfinite_frames;     /**< frames written with such values */
  fcm_index nonfinite_last;       /**< such values in the last frame written */
  fcm_index nonfinite_max;        /**< the most in one frame (0: none) */
  long long nonfinite_first_step; /**< the step of the first such frame (-1: none; 0: the
                                       initial state) */
  double time_setup, time_steps, time_output; /**< seconds; time_steps: the integrator's steps
                                                    and the cuts */
  double time_cuts; /**< seconds of the cuts applied after the set-up (rules, space, integrator;
                         part of time_steps) */
  double time_cut_rules; /**< of time_cuts: the cut cells' rules (fcm_cell_rules_create_cut()) */
  double time_cut_space; /**< of time_cuts: the new space (DOFs, element data) */
  double time_cut_integrator; /**< of time_cuts: the new integrator (set-up, the mass matrix, state
                                   transfer), its linear solver's structure apart */
  double time_cut_solver;     /**< of time_cuts: the new integrator's linear solver structure,
                                   which needs no matrix value (fcm_integrator_setup_info.
                                   solver_seconds): the direct solver's symbolic analysis, or
                                   the multigrid hierarchy without values; the next step sets
                                   up the values only (its time_step_factor: the numeric
                                   factorization, Galerkin values, smoothers, coarsest factor) */
  double time_cut_other;      /**< of time_cuts: the rest, the embedded surface split again and
                                   the log's mass blocks. On one thread the phases add up to
                                   time_cuts; with 2+ threads the integrator's values, the solver
                                   structure and the surface are made side by side (those two
                                   phases each its own wall time), and this is what the cut
                                   took beyond the sum of the others (0 when they overlap) */
  double time_log; /**< seconds of the per-step log rows (mass, momentum, reactions; not part
                        of time_steps) */
  double time_setup_geometry;   /**< seconds of the set-up's background mesh and geometry (reading
                                     files, hole filling, surface checks, meshing) */
  double time_setup_rules;      /**< seconds of its cut-cell rules (fcm_cell_rules_create()) */
  double time_setup_space;      /**< seconds of its space (DOFs, element data) */
  double time_setup_integrator; /**< seconds of its integrator: effects, constraints, the mass
                                     matrix, the solver's set-up */
  double time_setup_phase[FCM_SETUP_PHASE_COUNT]; /**< seconds of each set-up phase
                                     (fcm_setup_phase; 0: skipped). time_setup_geometry holds
                                     those up to the background mesh, time_setup_rules,
                                     time_setup_space and time_setup_integrator the next three;
                                     together they are at most time_setup */
  double time_step_assembly; /**< seconds of the steps' energy, force, tangent and damping
                                  assemblies (fcm_step_info.time_assembly, summed) */
  double time_step_factor;   /**< seconds of their factorizations or preconditioner set-ups */
  double time_step_solve;    /**< seconds of their triangular or Krylov solves */
  /* The embedded boundary in cells the set-up's rules dropped (volume fraction below
   * quadrature.min_fraction): no surface rule carries it, so loads and boundary constraints
   * there are lost. 0 without surface rules. */
  double boundary_area;           /**< the boundary's area: the rules' embedded_area plus
                                       dropped_area (fcm_cell_rules_stats) */
  double dropped_area;            /**< of it, the area in dropped cells */
  double effect_dropped_fraction; /**< the largest share, over the traction and pressure effects
                                       and the fixed and motion effects on the "boundary", of
                                       the boundary area an effect's region selects that lies
                                       in dropped cells (0: none) */
  int effect_dropped_index;       /**< that effect's index in the scene (meaningful when
                                       effect_dropped_fraction > 0) */
} fcm_simulation_counters;

/** A running scene (opaque). */
typedef struct fcm_simulation fcm_simulation;

/** Build everything a scene needs and set the integrator up at t = 0 (initial velocities
 * applied). No file is created. A failure while building from a scene section has that
 * section's JSON path before the message ("background.mesh: ...", "geometry.voxels: ...",
 * "geometry: embed: the geometry lies wholly outside ..."). Each phase of the set-up is
 * reported to opts->setup_phase as it starts and ends (fcm_setup_phase) and timed in the
 * counters; the library's warnings on the way (holes filled, NaN voxels, simplification
 * fallbacks) go to the context's log callback.
 * @param[in]  ctx   context; must outlive the simulation
 * @param[in]  scene borrowed; must outlive the simulation
 * @param[in]  opts  NULL for defaults
 * @param[out] sim   the new simulation, NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (a fixed or motion region naming a node out of range, catching
 *         no node, or only nodes no cell with material uses: "effects[i]: ...", refused right
 *         after the geometry, before the cell rules); errors of the mesh, geometry, cell rules,
 * space and integrator creation and setup; FCM_ERR_ALLOC. Allocates; not thread safe. */
FCM_API fcm_status fcm_simulation_create(fcm_ctx *ctx, const fcm_scene *scene,
                                         const fcm_simulation_options *opts, fcm_simulation **sim);

/** What an effect selects, in fcm_preview_effect.selects. */
typedef enum fcm_preview_selects {
  FCM_PREVIEW_NOTHING = 0, /**< no region: gravity, damping, cut */
  FCM_PREVIEW_NODES,       /**< background nodes: fixed and motion with "region",
                                initial_velocity */
  FCM_PREVIEW_BOUNDARY     /**< embedded-boundary points: traction, pressure, fixed and motion
                                with "boundary" */
} fcm_preview_selects;

/** What fcm_simulation_write_preview() found for one effect of the scene. */
typedef struct fcm_preview_effect {
  fcm_preview_selects selects;
  fcm_index nodes;           /**< NODES: background nodes the region selects */
  fcm_index active_nodes;    /**< NODES: of them, the active ones (the coarse classification) */
  fcm_index boundary_points; /**< BOUNDARY: the surface's sample points in the region */
  fcm_index cut_triangles;   /**< a cut: triangles of its surface (0: a plane missing the body) */
} fcm_preview_effect;

/** What fcm_simulation_write_preview() found and wrote. The cell classes are coarse: a cell is
 * cut when a triangle of the embedded surface meets its bounding box (so it may hold no
 * material, and the run may still drop it below quadrature.min_fraction), else wholly inside or
 * outside the body; a node is active when a cell inside or cut uses it. */
typedef struct fcm_simulation_preview_info {
  fcm_element_type element; /**< of the background mesh */
  fcm_index num_cells, num_nodes;
  fcm_index cells[3];          /**< cells per fcm_cell_class: [FCM_CELL_UNCUT] inside,
                                    [FCM_CELL_CUT] cut, [FCM_CELL_DROPPED] outside; without a
                                    geometry every cell is inside */
  fcm_index active_nodes;      /**< nodes a cell inside or cut uses */
  fcm_index surface_triangles; /**< of the embedded surface (0: no geometry) */
  fcm_index surface_samples;   /**< points on the surface the boundary regions are tested at:
                                    per triangle a grid of n x n sub-triangles' centroids, n the
                                    longest edge over sample_spacing rounded up (at most 16) */
  double sample_spacing;       /**< the background cells' size, (box volume / cells)^(1/3), m */
  int files;                   /**< files written, the .pvd included */
} fcm_simulation_preview_info;

/** Look at a scene before its expensive set-up: build only the background mesh and the embedded
 * geometry (the first phases of fcm_simulation_create(), reported to opts->setup_phase the same
 * way), classify the cells coarsely (fcm_simulation_preview_info), and write into the existing
 * directory `dir`, atomically: <name>_preview_grid.vtu (the background cells with a cell array
 * `class`, 0 inside, 1 cut, 2 outside, and a point array `active`), <name>_preview_surface.vtu
 * (the embedded surface's triangles), <name>_preview_nodes.vtu (one vertex per node an effect
 * selects, with point arrays `effect`, the effect's index, and `active`),
 * <name>_preview_boundary_points.vtu (the surface's sample points each boundary effect selects,
 * with `effect`), <name>_preview_cuts.vtu (the triangles of every cut surface, with cell arrays
 * `effect` and `time`), each only when it has something, and <name>_preview.pvd naming them as
 * the parts of one data set. Then the checks of fcm_simulation_create() on the regions run: the
 * files show the region that fails.
 * @param[in]  opts    NULL for defaults (only the progress callbacks are used)
 * @param[out] info    may be NULL; filled once the files are written, also when a region fails
 * @param[out] effects NULL, or fcm_scene_num_effects(scene) entries (caller's), effect i's counts
 * @return FCM_OK; FCM_ERR_ARG (a region naming a node out of range, selecting no background node
 *         or only inactive ones: "effects[i]: ..."); the errors of the mesh and geometry
 *         creation; FCM_ERR_IO (naming the path); FCM_ERR_ALLOC. Allocates; not thread safe. */
FCM_API fcm_status fcm_simulation_write_preview(fcm_ctx *ctx, const fcm_scene *scene,
                                                const fcm_simulation_options *opts, const char *dir,
                                                fcm_simulation_preview_info *info,
                                                fcm_preview_effect *effects);

/** Print what fcm_simulation_write_preview() found to `stream`: the background's cells by class
 * and its active nodes, the surface, and per effect with a region the nodes (active ones) or
 * boundary points it selects, per cut its triangles. effects may be NULL. */
FCM_API void fcm_simulation_preview_view(const fcm_scene *scene,
                                         const fcm_simulation_preview_info *info,
                                         const fcm_preview_effect *effects, FILE *stream);

/** Destroy; accepts NULL and `*sim == NULL`, sets `*sim = NULL`. */
FCM_API void fcm_simulation_destroy(fcm_simulation **sim);

/** The cell rules of the embedded geometry (statistics: fcm_cell_rules_get_stats()), NULL
 * for a scene without geometry. Valid until the next cut (a step that applies a cut effect,
 * or fcm_simulation_cut()), which replaces them, as it does the space and the integrator. */
FCM_API const fcm_cell_rules *fcm_simulation_cell_rules(const fcm_simulation *sim);

/** Advance one step (fcm_integrator_step()) and record it for the log and the counters (the
 * inverted quadrature points among them). A step that ends with inverted points when the
 * scene's solver.on_inversion is "stop" (fcm_scene_solver.stop_on_inversion) is taken and
 * logged, and then reported as FCM_ERR_GEOMETRY: "simulation <name>: step <k> (t = <t> s)
 * ended with <n> inverted quadrature points (J = det F <= 0), the first in cell <c> at X =
 * (x, y, z) with J = <J> ...". The state is that step's; a host stops there (frames written
 * before stay valid).
 * @param[out] info may be NULL
 * @return as fcm_integrator_step(); FCM_ERR_GEOMETRY (inverted points, "stop");
 * FCM_ERR_ARG when the run is done. */
FCM_API fcm_status fcm_simulation_step(fcm_simulation *sim, fcm_step_info *info);

/** The coordinates a blade given to fcm_simulation_cut() is in. */
typedef enum fcm_cut_frame {
  FCM_CUT_FRAME_REFERENCE = 0, /**< the body at rest (material coordinates), as the scene's
                                    "cut" effects */
  FCM_CUT_FRAME_DEFORMED = 1   /**< the body as it is now, x = X + u: each blade vertex is
                                    carried back to the rest position of the material point it
                                    lies on (fcm_simulation_rest_positions()); the triangles
                                    stay flat at rest. Bent back, a blade is no longer flat: one
                                    triangulated finer than the cells costs more and may be
                                    refused (lib/docs/cutting.md). For a tool swept through a
                                    moving body, cut strips in the reference frame instead */
} fcm_cut_frame;

/** What one fcm_simulation_cut() did. Seconds are wall clock; the phases are those of the
 * counters' time_cut_* (on two threads the integrator and the solver's structure overlap);
 * seconds_rules includes the blade's check and, in the deformed frame, its pull-back. */
typedef struct fcm_cut_info {
  int missed; /**< 1: no cell got a new piece and no node a new copy: the blade missed the
                   body, or only extended a crack inside cells (which counts from the cut that
                   completes it) */
  fcm_index dofs_before;      /**< fcm_space_num_dofs() before the cut */
  fcm_index dofs_after;       /**< and after it */
  fcm_index cells_integrated; /**< cells whose rules the cut made again */
  double seconds;             /**< the whole cut, the blade's pull-back included */
  double seconds_rules, seconds_space, seconds_integrator, seconds_solver;
} fcm_cut_info;

/** Cut the body now along `blade`, an open or closed triangle surface (its triangles need no
 * orientation), as a scene's "cut" effect does at its time: the cell rules, the space, the
 * integrator and the linear solver's structure are updated from the last ones, the state
 * carries over, and the output surface and the log follow. In the reference frame the result
 * is the same, bit for bit, as the same blade given as a cut effect due before the next step.
 * A cut integrates only the elements it changes when the simulation was created with
 * fcm_simulation_options.host_cuts (or its scene has cut effects). A blade that misses the
 * body is no error (info->missed); one that meets no material at all (no cell integrated
 * again, no cut face) leaves a serial run's rules, space and integrator as they were (the
 * rules then do not count it: fcm_cell_rules_num_cuts()), and its next steps those it would
 * take without the cut. Call it between steps, as often as the tool
 * moves; every process of a distributed run calls it with the same blade. The pointers the
 * simulation gave before (fcm_simulation_integrator(), _space(), _cell_rules()) are replaced
 * (kept by a blade that meets no material).
 * The counters count the cut (cuts, time_cut_*), and fcm_simulation_summary_view() lists it.
 * A checkpoint cannot hold such cuts (their blades are not in the scene):
 * fcm_simulation_write_checkpoint() refuses after one, and fcm_simulation_checkpoint_due() is
 * 0 from then on.
 * @param[in]  blade  not kept: the caller may destroy it on return
 * @param[out] info   may be NULL
 * @return FCM_OK; FCM_ERR_ARG (NULL simulation or blade, a frame out of range, a scene without
 * an embedded geometry); FCM_ERR_GEOMETRY (a blade whose triangles all lack area, or the
 * errors of fcm_simulation_rest_positions()); FCM_ERR_UNSUPPORTED (a background refined along
 * the cuts when they are applied, "octree": {"cuts": {"when": "cut"}};
 * FCM_CUT_FRAME_DEFORMED in a distributed run); the errors of a scene's cut (FCM_ERR_ALLOC,
 * FCM_ERR_GEOMETRY, ...). A failure before the new space takes over leaves the simulation as
 * it was, its counters included; one after it (the log's blocks) leaves the body cut. */
FCM_API fcm_status fcm_simulation_cut(fcm_simulation *sim, const fcm_surface *blade,
                                      fcm_cut_frame frame, fcm_cut_info *info);

/** Carry points of the body as it is now (x = X + u) back to the rest positions of the
 * material points they lie on: X[3i..3i+3) for x[3i..3i+3), as FCM_CUT_FRAME_DEFORMED carries
 * a blade's vertices. A point goes by the first element (in the space's order) whose deformed
 * map reaches it inside the element's cell (in a cell that cuts split, inside its piece); a
 * point in no such element by the affine motion, at its centre, of the element whose deformed
 * node centroid is nearest. A tool that moves through a moving body sweeps a cut whose
 * consecutive strips meet in the material only if each shared edge keeps the rest position it
 * had when the tool was there: a host carries the tool's edge back at each step and cuts the
 * strip between the last and the new rest positions in the reference frame
 * (apps/examples/host_cut.c).
 * @return FCM_OK; FCM_ERR_ARG (NULL, n < 0, a non-finite point); FCM_ERR_UNSUPPORTED (a
 * distributed run); FCM_ERR_NUMERIC (a non-finite deformed node); FCM_ERR_GEOMETRY (a body
 * without elements, or the element nearest to a point outside the body inverted);
 * FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_simulation_rest_positions(fcm_simulation *sim, fcm_index n, const double *x,
                                                 double *X);

/** What fcm_simulation_run() reports to its monitor after each step it took. */
typedef struct fcm_simulation_step_event {
  long long step;            /**< steps taken so far (fcm_simulation_step_count()) */
  long long first;           /**< steps taken when the run started (a restored checkpoint's) */
  long long num_steps;       /**< steps to take (fcm_simulation_num_steps()) */
  double wall;               /**< seconds since fcm_simulation_run() started */
  const fcm_step_info *info; /**< what the step did (valid during the call) */
} fcm_simulation_step_event;

/** Called by fcm_simulation_run() after each step that succeeded: the host checks the state,
 * writes frames, the log and checkpoints (fcm_simulation_frame_due(),
 * fcm_simulation_checkpoint_due()) and reports progress here. FCM_OK goes on; any other
 * status ends the run, which returns it as it is (the monitor records a message in the
 * context if it wants one). */
typedef fcm_status (*fcm_simulation_monitor_fn)(void *user, fcm_simulation *sim,
                                                const fcm_simulation_step_event *event);

/** The time loop: take the steps left (fcm_simulation_step() until fcm_simulation_done()),
 * calling `monitor` (may be NULL) after each. The same loop serves a serial simulation and a
 * distributed one (fcm_petsc_simulation_create(), where it is collective and so must the
 * monitor be). A failed step ends the run with its status; fcm_simulation_step_count() is
 * then that of the last step that succeeded (or, for a step refused after it was taken,
 * solver.on_inversion = "stop", that step's).
 * @return FCM_OK when the run is done; the status of a failed step (its message in the
 * context); the monitor's status; FCM_ERR_ARG (NULL simulation). */
FCM_API fcm_status fcm_simulation_run(fcm_simulation *sim, fcm_simulation_monitor_fn monitor,
                                      void *user);

/** 1 when the steps to take (scene or max_steps) are taken, else 0. */
FCM_API int fcm_simulation_done(const fcm_simulation *sim);
/** Steps taken so far and steps to take. */
FCM_API long long fcm_simulation_step_count(const fcm_simulation *sim);
FCM_API long long fcm_simulation_num_steps(const fcm_simulation *sim);
/** Whether this step should be written (frame_interval of the scene; step 0 and the last
 * step always): 1 or 0. */
FCM_API int fcm_simulation_frame_due(const fcm_simulation *sim);

/** 1 when the displacement and velocity are finite everywhere, else 0. */
FCM_API int fcm_simulation_state_finite(const fcm_simulation *sim);

/** Write frame `index` of the current state into the existing directory `dir`, every point at
 * its reference position with a point array `displacement` (apps/docs/fcm-sim.md: ParaView recipe):
 * <dir>/<name>_background_NNNN.vtu (fcm_space_write_vtu(): displacement and velocity per node;
 * active flag, volume fraction and the cell averages of stress, von Mises stress and strain
 * energy density per cell) and, with a geometry, <dir>/<name>_surface_NNNN.vtu
 * (fcm_embedded_surface_write_vtu(): the boundary triangles of the embedded mesh and both
 * sides of every cut face with displacement, cut_face and the stresses at the points; u of a
 * vertex in a dropped cell is extrapolated from the nearest active cell), as the scene's
 * output section asks; <dir>/<name>_background.pvd and <dir>/<name>_surface.pvd are
 * rewritten. All writes are atomic. A simulation of fcm_petsc_simulation_create() (fcm/petsc.h):
 * collective — every process calls it and writes the piece of its own cells,
 * <dir>/<name>_background_NNNN_<rank>.vtu; process 0 writes <dir>/<name>_background_NNNN.pvtu
 * naming the pieces (the PVD indexes it) and the surface frame; every process counts the
 * frame. The von Mises values written that are NaN or infinite (points with J = det F <= 0)
 * are counted: fcm_simulation_counters.nonfinite_last and the log's nonfinite_stresses.
 * @return FCM_OK, FCM_ERR_IO (naming the path), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_simulation_write_frame(fcm_simulation *sim, const char *dir, int index);

/** Write the per-step log as CSV atomically to `path`: header
 * "step,time,newton_iterations,linear_iterations,residual,energy,pieces,mass,momentum_x,
 * momentum_y,momentum_z", then for every fixed or motion effect i (its index in the scene's
 * effects) "reaction_<i>_x,reaction_<i>_y,reaction_<i>_z,moment_<i>_x,moment_<i>_y,moment_<i>_z"
 * (fcm_integrator_reaction(): the force the region exerts on the body, inertia included, and
 * its moment about the origin), then "inverted_points,nonfinite_stresses,wall_time"; one row
 * per step taken (pieces: separate bodies, fcm_space_num_bodies(); mass and linear momentum
 * over the body's own quadrature points, fcm_space_momentum(); inverted_points: quadrature
 * points with J = det F <= 0 after the step, fcm_step_info.inverted_points; nonfinite_stresses:
 * NaN or infinite von Mises values in the frame written after the step, "nan" when none was;
 * both "nan" in rows restored from a checkpoint that did not record them, as the reactions).
 * @return FCM_OK, FCM_ERR_IO, FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_simulation_write_log(fcm_simulation *sim, const char *path);

/** Save the run: write a checkpoint to `path` atomically (a temporary beside it, synced, then
 * renamed). It holds the integrator state (displacement, velocity, time, step count) bit for
 * bit, the per-step log, the times of the frames written, the cumulative Newton, linear and
 * tangent counts, and a fingerprint of the scene and its discretization; a checksum closes
 * the file. Host byte order (the header records it). Format: lib/src/scene/checkpoint.c.
 * A resumed run starts without the integrator's kept factorization (fcm_integrator_options.
 * reuse_factorization), so this one drops it too: when it writes (one process) and after every
 * step at which a checkpoint is due (every process of a distributed run).
 * @return FCM_OK, FCM_ERR_ARG (NULL), FCM_ERR_IO (naming the path; nothing is left
 * behind), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_simulation_write_checkpoint(fcm_simulation *sim, const char *path);

/** Continue a run: restore a checkpoint into a simulation that was just created from the
 * same scene (only its time span and output section may differ, so a run can be extended)
 * and has neither stepped nor written a frame. Stepping on then reproduces the states of the
 * uninterrupted run bit for bit (same build, same thread counts). The frames of the earlier
 * run count as written: the next frame index is the `frames` counter, and the PVD indexes,
 * when next written into a directory, first list those earlier frames found in that
 * directory (<name>_background_NNNN.vtu, NNNN = 0 .. frames-1, as fcm-sim numbers them).
 * Solver counters (factorizations, analyses) count this process only.
 * @return FCM_OK; FCM_ERR_IO (cannot open or read, naming the path); FCM_ERR_FORMAT (not
 * a checkpoint, other byte order or version, truncated, checksum mismatch, a count out of
 * range: named); FCM_ERR_ARG (the simulation has stepped; a different scene or DOF count;
 * more steps than the simulation takes; a non-finite state); FCM_ERR_ALLOC. On failure the
 * simulation is unchanged. */
FCM_API fcm_status fcm_simulation_read_checkpoint(fcm_simulation *sim, const char *path);

/** Check that `path` is a checkpoint this build reads (fcm_simulation_write_checkpoint()'s
 * container: its header, version, byte order and checksum, or an older `.fcmpk`), without a
 * simulation: a program checks its input before the set-up. Whether it belongs to a given
 * scene is decided by fcm_simulation_read_checkpoint().
 * @return FCM_OK; FCM_ERR_IO (cannot open or read, naming the path); FCM_ERR_FORMAT (not a
 * checkpoint, other byte order or version, truncated, checksum mismatch); FCM_ERR_ARG (NULL
 * path). */
FCM_API fcm_status fcm_simulation_check_checkpoint(fcm_ctx *ctx, const char *path);

/** 1 when a checkpoint is due after the step just taken (every checkpoint_interval-th step,
 * from the options or the scene), else 0. */
FCM_API int fcm_simulation_checkpoint_due(const fcm_simulation *sim);

/** Centre of mass of the deformed body, 1^T M x / 1^T M 1 per component with x = X + u at
 * the nodes (exact for the interpolated field and the mass quadrature, embedded or not).
 * Dynamic scenes only. fcm_simulation_summary_view() prints its drift for a free body (no
 * constraint, gravity or surface load), which momentum conservation keeps at zero. Collective
 * in a distributed run (fcm_petsc_simulation_create(): the partial mass matrix's sums).
 * @return FCM_OK, FCM_ERR_ARG (NULL; a static scene has no mass matrix), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_simulation_center_of_mass(const fcm_simulation *sim, double com[3]);

/** Copy the counters out. */
FCM_API void fcm_simulation_get_counters(const fcm_simulation *sim,
                                         fcm_simulation_counters *counters);

/** Borrowed views: the integrator (for energies, momentum, state), the space and the cell
 * rules (NULL without a geometry). */
FCM_API fcm_integrator *fcm_simulation_integrator(fcm_simulation *sim);
FCM_API const fcm_space *fcm_simulation_space(const fcm_simulation *sim);

/** Print what was computed and what was skipped, with the counters, to `stream`; also the
 * largest displacement of the body (over its quadrature points and the surface points the
 * frames write) beside the DOF vector's (fictitious nodes included), and the steps that ended
 * with inverted quadrature points and the frames with NaN or infinite stresses (the first and
 * the worst; zero when none). */
FCM_API void fcm_simulation_summary_view(const fcm_simulation *sim, FILE *stream);

#ifdef __cplusplus
}
#endif
#endif /* FCM_SIMULATION_H */
