/* fcm — scene files: a JSON description of a simulation (background mesh, embedded
 * geometry, material, quadrature, solver, time stepping, output and a list of effects)
 * parsed, validated and held as plain read-only data. The schema, with every key, type,
 * default, range and unit, is documented in apps/scenes/README.md.
 *
 * An fcm_scene is an opaque object; its sections come back as pointers to plain structs
 * (enums, doubles, fixed arrays, strings and arrays owned by the scene). They are
 * read-only and stay valid until fcm_scene_destroy(). Units are SI throughout (m, s, kg,
 * Pa, rad). Parsing never creates, opens for writing or touches any output file. */
#ifndef FCM_SCENE_H
#define FCM_SCENE_H

#include "fcm/core.h"
#include "fcm/element.h"
#include "fcm/embed.h"
#include "fcm/la.h"
#include "fcm/levelset.h"
#include "fcm/material.h"
#include "fcm/sim.h"
#include "fcm/simplify.h"
#include "fcm/solve.h"
#include "fcm/surface.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ sections */

/** Where the background mesh comes from. */
typedef enum fcm_scene_background_kind {
  FCM_SCENE_BACKGROUND_GRID = 0, /**< a structured grid over a box (fcm_mesh_create_box) */
  FCM_SCENE_BACKGROUND_MESH      /**< a Gmsh file (fcm_mesh_create_from_gmsh) */
} fcm_scene_background_kind;

/** The background mesh ("background"). */
typedef struct fcm_scene_background {
  fcm_scene_background_kind kind;
  fcm_element_type element; /**< GRID: the element type; MESH: FCM_ELEMENT_COUNT (file's) */
  double min[3], max[3];    /**< GRID: box corners, min[d] < max[d] */
  fcm_index cells[3];       /**< GRID: cells per axis, >= 1 */
  const char *mesh;         /**< MESH: the file, resolved against the scene file's directory;
                                 GRID: NULL */
  int fit;                  /**< GRID with "fit_background": 1, min, max and cells are then
                                 set when the simulation is built, from the geometry's box */
  double fit_cell_size;     /**< fit: edge of the (cubic) cells, > 0 */
  double fit_margin;        /**< fit: gap between the body's box and the grid's, >= 0 (default:
                                 one cell) */
  /** GRID with "octree": the grid refined as an octree (fcm_mesh_create_octree()), 2:1
   * balanced; each level 0 = off, at most FCM_OCTREE_MAX_LEVEL. */
  int octree;             /**< 1 when "octree" is given */
  int octree_boundary;    /**< "boundary": {"level"}: cells the embedded boundary meets */
  int octree_region;      /**< "region": {"level"}: cells meeting the box below */
  int octree_cuts;        /**< "cuts": {"level"}: cells the cut effects' surfaces meet (before the
                               cuts apply) */
  int octree_cuts_at_cut; /**< "cuts": {"when"}: 0 "setup" (default): the grid is built refined
                               along the cuts; 1 "cut": the run starts on the grid without
                               that refinement and refines along every cut's surface when the
                               first cut applies, just before it (the state carried by
                               fcm_integrator_create_refined()) */
  double octree_region_min[3], octree_region_max[3]; /**< "region": {"min", "max"} */
} fcm_scene_background;

/** What the embedded geometry is. */
typedef enum fcm_scene_geometry_kind {
  FCM_SCENE_GEOMETRY_NONE = 0,    /**< none: plain FEM, the background mesh is the body */
  FCM_SCENE_GEOMETRY_BOX,         /**< fcm_geometry_create_box() */
  FCM_SCENE_GEOMETRY_BALL,        /**< fcm_geometry_create_ball() */
  FCM_SCENE_GEOMETRY_HEMISPHERE,  /**< fcm_geometry_create_hemisphere() */
  FCM_SCENE_GEOMETRY_HOLLOW_BALL, /**< fcm_geometry_create_hollow_ball() */
  FCM_SCENE_GEOMETRY_TUBE,        /**< fcm_geometry_create_tube() */
  FCM_SCENE_GEOMETRY_GMSH,        /**< fcm_geometry_create_from_gmsh() */
  FCM_SCENE_GEOMETRY_TETGEN,      /**< fcm_geometry_create_from_tetgen() */
  FCM_SCENE_GEOMETRY_SURFACE,   /**< a triangle surface file, fcm_geometry_create_from_surface() */
  FCM_SCENE_GEOMETRY_VOXELS,    /**< fcm_geometry_create_from_voxels() of an image file */
  FCM_SCENE_GEOMETRY_LEVEL_SET, /**< fcm_geometry_create_from_level_set() of built-in
                                     implicits (fcm/levelset.h) */
  FCM_SCENE_GEOMETRY_KIND_COUNT
} fcm_scene_geometry_kind;

/** The embedded geometry ("geometry"); members not used by `kind` are zero. */
typedef struct fcm_scene_geometry {
  fcm_scene_geometry_kind kind;
  double min[3], max[3]; /**< BOX corners, min[d] < max[d]; LEVEL_SET: sampling box */
  fcm_index cells[3];    /**< BOX: cubes per axis (6 tets each); LEVEL_SET: sampling cells */
  double center[3];      /**< BALL, HEMISPHERE, HOLLOW_BALL, TUBE */
  double radius;         /**< BALL, HEMISPHERE */
  double inner_radius, outer_radius; /**< HOLLOW_BALL, TUBE */
  double hole_radius;                /**< HOLLOW_BALL (0: no holes) */
  double length;                     /**< TUBE */
  int axis;                          /**< TUBE: 0 (x), 1 (y), 2 (z) */
  int resolution; /**< BALL, HEMISPHERE: cubes per radius; HOLLOW_BALL: quads per patch edge */
  int layers;     /**< HOLLOW_BALL: radial layers */
  int radial_cells, angular_cells, axial_cells; /**< TUBE */
  const char *mesh;    /**< GMSH: the .msh file; TETGEN: the .node file; SURFACE: the .obj,
                            .off, .stl or .ply file (resolved paths) */
  const char *ele;     /**< TETGEN: the .ele file */
  int has_transform;   /**< 1: map the created geometry by x -> A x + b */
  double transform[9]; /**< A, row-major: rotation times scale (identity when none) */
  double offset[3];    /**< b */
  fcm_surface_mesh_options surface; /**< SURFACE: tetrahedralization options; volume_mesh -1
                                         ("auto"): a volume mesh only on the distributed
                                         backend or for cuts with moments = volume */
  int fill_holes;                   /**< SURFACE: 1: close holes first */
  fcm_surface_fill_options fill;    /**< SURFACE: which holes fill_holes closes */
  const char *image;    /**< VOXELS: the image file (.nrrd, .nhdr, .mhd, .mha; resolved path) */
  double threshold;     /**< VOXELS: voxels with value >= threshold are the body (default 0.5) */
  const double *labels; /**< VOXELS: label set replacing the threshold (NULL: none) */
  int num_labels;       /**< VOXELS: length of labels, [0, 256] */
  int merge;            /**< VOXELS: 1 (default): merge voxels into boxes */
  const fcm_implicit *implicit; /**< LEVEL_SET: the implicit tree, root last */
  int num_implicit;             /**< LEVEL_SET: nodes, [1, FCM_IMPLICIT_MAX_NODES] */
  int refinement;               /**< LEVEL_SET: sub-cells per cut cell edge (default 4) */
  int has_box;            /**< LEVEL_SET: 1: sampled on min/max/cells; 0: on the background grid */
  fcm_index max_subcells; /**< LEVEL_SET: fcm_level_set_options.max_subcells (default
                               FCM_LEVEL_SET_MAX_SUBCELLS; 0: no limit) */
} fcm_scene_geometry;

/** Quadrature settings ("quadrature"): the library's cell-rules options with the library's
 * defaults (fcm_cell_rules_options_default(), documented in fcm/embed.h). The keys set:
 * "stiffness_strength" and "mass_strength" rules.strength[FCM_RULE_STIFFNESS / MASS] (0 gives
 * the cut cells a strength-0 rule and keeps the element's rule on full cells);
 * "surface_strength" rules.surface_strength, whose FCM_DEFAULT means automatic here (the
 * stiffness strength when a traction or pressure effect, or a fixed or motion effect on the
 * "boundary", is present, else no surface rules); "simplify" rules.simplify (true, false or
 * "auto"); "simplify_method" rules.simplify_options.method; "stabilization" rules.stabilization;
 * "min_fraction" rules.min_fraction; "max_rule_memory_gib" rules.max_rule_memory (in bytes
 * here: GiB x 2^30). The members the runner sets (kinds, expected_assemblies, progress,
 * cell_mask) keep their defaults. */
typedef struct fcm_scene_quadrature {
  fcm_cell_rules_options rules;
} fcm_scene_quadrature;

/** Solver settings ("solver"): the library's integrator options with the library's defaults
 * (fcm_integrator_options_default(), documented in fcm/sim.h, where each member names its key),
 * and the scene's own keys. The members set by other sections keep their defaults here and are
 * set by the runner: kind, dt and load_steps ("time"), rayleigh_mass and rayleigh_stiffness
 * (the "damping" effect), assembly ("quadrature"). "multigrid" needs a hex8 or hex20 "grid"
 * background; its "jacobi" smoother defaults to omega 0.6. */
typedef struct fcm_scene_solver {
  fcm_integrator_options integrator; /**< the solver keys (fcm/sim.h) */
  int threads;               /**< "threads": OpenMP threads >= 1, or FCM_DEFAULT ("threads": 0, the
                                  default): the context's own count. When given, fcm_simulation_create() makes
                                  it the context's thread count (fcm_ctx_set_num_threads()) */
  const char *petsc_options; /**< "petsc_options": PETSc options for the PETSc backend
                                  (fcm/petsc.h, `fcm-sim --backend petsc`), e.g. "-ksp_type
                                  minres -pc_type jacobi"; the command line wins for a key both
                                  give. NULL (default): none. The serial backend ignores it */
  int stop_on_inversion;     /**< "on_inversion": what a step that ends with inverted
                                  quadrature points (J = det F <= 0,
                                  fcm_step_info.inverted_points) does: "warn" (0, default): the
                                  run goes on, the log and the summary count them;
                                  "stop" (1): fcm_simulation_step() returns an error naming the
                                  step, the time, the count and the first point */
} fcm_scene_solver;

/** Time stepping ("time"). */
typedef struct fcm_scene_time {
  fcm_integrator_kind integrator; /**< FCM_INTEGRATOR_STATIC ("static": true: quasi-static
                                       equilibrium at each step, no inertia) or
                                       FCM_INTEGRATOR_DYNAMIC (the default) */
  fcm_time_scheme scheme;         /**< dynamic: "integrator": "backward_euler" (the default),
                                       "newmark", "hht" or "generalized_alpha" */
  double hht_alpha;               /**< "hht": "alpha" in [-1/3, 0], default -0.05 */
  double rho_inf;                 /**< "generalized_alpha": "rho_inf" in [0, 1], default 0.8 */
  double dt;                      /**< step in s, > 0, default 1/60 */
  fcm_index num_steps;            /**< steps to take (>= 1), from "steps" or "duration" */
  double duration;                /**< num_steps * dt: the simulated time in s */
  int load_steps;                 /**< static: load increments per step, >= 1, default 1 */
} fcm_scene_time;

/** Output settings ("output"). */
typedef struct fcm_scene_output {
  const char *directory;   /**< default "fcm-output"; relative to the working directory */
  int frame_interval;      /**< write every frame_interval-th step (>= 1, default 1) */
  int checkpoint_interval; /**< write a checkpoint every n-th step (>= 0; default 0: never) */
  int write_background;    /**< 1 (default): write the background mesh */
  int write_surface;       /**< 1 (default): write the embedded surface */
} fcm_scene_output;

/* ------------------------------------------------------------------- regions */

/** Kinds of region. */
typedef enum fcm_region_kind {
  FCM_REGION_ALL = 0,    /**< everything (an effect without "region", where allowed) */
  FCM_REGION_BOX,        /**< min - tol <= x <= max + tol, componentwise */
  FCM_REGION_HALF_SPACE, /**< (x - point) . normal >= -tol, normal a unit vector */
  FCM_REGION_NODES       /**< an explicit list of background-mesh node ids */
} fcm_region_kind;

/** A region of space or a node set. */
typedef struct fcm_region {
  fcm_region_kind kind;
  double min[3], max[3];      /**< BOX: corners, min[d] <= max[d] (equal: a plane) */
  double point[3], normal[3]; /**< HALF_SPACE: a point on the plane, unit normal into it */
  double tolerance;           /**< BOX, HALF_SPACE: absolute, >= 0, default 1e-9 m */
  fcm_index num_nodes;        /**< NODES: count >= 1 */
  const fcm_index *nodes;     /**< NODES: 0-based ids, ascending, distinct (owned by the scene;
                                   their range is checked against the mesh by the caller) */
} fcm_region;

/** Whether the point x lies in the region: 1 or 0. ALL contains every point; NODES none
 * (membership is by node id). No allocation; thread safe. */
FCM_API int fcm_region_contains(const fcm_region *region, const double x[3]);

/** fcm_region_contains() as an fcm_boundary_select_fn (fcm/sim.h): `region` is a
 * const fcm_region *; the normal is ignored. For fcm_integrator_add_boundary_constraint(). */
FCM_API int fcm_region_select(void *region, const double X[3], const double normal[3]);

/* ------------------------------------------------------------------- effects */

/** Effect types, in the order of the one effect table (see fcm_effect_type_name()). */
typedef enum fcm_effect_type {
  FCM_EFFECT_GRAVITY = 0,      /**< "gravity": body force rho g */
  FCM_EFFECT_FIXED,            /**< "fixed": zero displacement on a region */
  FCM_EFFECT_MOTION,           /**< "motion": prescribed translation and rotation */
  FCM_EFFECT_INITIAL_VELOCITY, /**< "initial_velocity": v0 + omega x (X - c) */
  FCM_EFFECT_DAMPING,          /**< "damping": Rayleigh D = mass M + stiffness K */
  FCM_EFFECT_TRACTION,         /**< "traction": force per area on the embedded boundary */
  FCM_EFFECT_PRESSURE,         /**< "pressure": p along the inward normal of the boundary */
  FCM_EFFECT_CUT,              /**< "cut": a cut surface inserted at a time (XFEM) */
  FCM_EFFECT_CONTACT,          /**< "contact": a rigid plane obstacle (log barrier) */
  FCM_EFFECT_TYPE_COUNT
} fcm_effect_type;

/** Name of an effect type as written in scene files ("gravity", ...), or NULL. */
FCM_API const char *fcm_effect_type_name(fcm_effect_type type);

typedef struct fcm_effect_gravity {
  double acceleration[3]; /**< m/s^2, default (0, 0, -9.81) */
} fcm_effect_gravity;

/** Where a fixed or motion effect acts: on background nodes ("region") or, weakly, on the
 * embedded-boundary points in the region ("boundary": fcm_integrator_add_boundary_constraint(),
 * Nitsche's method by default). */
typedef struct fcm_effect_fixed {
  fcm_region region;
  int components[3]; /**< 1: that displacement component is held (default all) */
  int boundary;      /**< 1: "boundary" (BOX, HALF_SPACE or ALL: "boundary": "all"); 0: nodes */
  fcm_boundary_options boundary_options; /**< "method" ("nitsche", "penalty"), "penalty",
                                              "nitsche_safety"; boundary only */
} fcm_effect_fixed;

/** Prescribed motion of the background nodes in a region: the library's fcm_motion (its
 * formula, evaluated by fcm_motion_eval() and fcm_motion_active() in fcm/sim.h, is what the
 * runner constrains). Scene defaults: velocity 0, axis (0, 0, 1) (normalized by the parser),
 * center 0, angular_speed 0, start 0 (>= 0), end HUGE_VAL (> start), release 0, all three
 * components constrained. */
typedef struct fcm_effect_motion {
  fcm_region region;
  fcm_motion motion;
  int boundary;                          /**< as fcm_effect_fixed */
  fcm_boundary_options boundary_options; /**< as fcm_effect_fixed */
} fcm_effect_motion;

/** Initial velocity v(X) = velocity + angular_velocity x (X - c) on the region (default
 * ALL); c = center, or the embedded body's centre of mass when center_of_mass is 1. */
typedef struct fcm_effect_initial_velocity {
  fcm_region region;
  double velocity[3];         /**< m/s, default 0 */
  double angular_velocity[3]; /**< rad/s, default 0 */
  double center[3];           /**< used when center_of_mass is 0 */
  int center_of_mass;         /**< 1 (default, no "center" key): c = centre of mass */
} fcm_effect_initial_velocity;

/** Rayleigh damping D = mass M + stiffness K. */
typedef struct fcm_effect_damping {
  double mass;      /**< 1/s, >= 0, default 0 */
  double stiffness; /**< s, >= 0, default 0 */
} fcm_effect_damping;

/** Traction (force per reference area) on the part of the embedded boundary in the
 * region, during start <= t <= end. */
typedef struct fcm_effect_traction {
  fcm_region region;  /**< BOX or HALF_SPACE */
  double traction[3]; /**< Pa */
  double start, end;  /**< s; default 0 and HUGE_VAL */
} fcm_effect_traction;

/** Pressure on the part of the embedded boundary in the region (force -p n per area, n the
 * outward normal: positive pressure pushes inward), during start <= t <= end. */
typedef struct fcm_effect_pressure {
  fcm_region region; /**< BOX or HALF_SPACE */
  double pressure;   /**< Pa, any sign */
  double start, end; /**< s; default 0 and HUGE_VAL */
} fcm_effect_pressure;

/** The forms of a cut surface (in the reference coordinates of the geometry). */
typedef enum fcm_cut_kind {
  FCM_CUT_PLANE = 0, /**< "plane": {"point", "normal"}: clipped to the body's bounding box
                          enlarged by 10 % (fcm_surface_create_plane()) */
  FCM_CUT_RECTANGLE, /**< "rectangle": {"center", "normal", "axis", "size": [a, b]} */
  FCM_CUT_DISC,      /**< "disc": {"center", "normal", "radius", "segments" (default 64)} */
  FCM_CUT_MESH       /**< "mesh": "FILE" (OBJ, OFF, STL, PLY; fcm_surface_create_from_file()) */
} fcm_cut_kind;

/** A cut at `time`: before the first step that starts at or after it (time 0: before the
 * run), the surface is added to the cell rules (fcm_cell_rules_create_cut()) and the run
 * continues on the enriched space (fcm_integrator_create_cut()). Every form takes an
 * optional "transform" (scale, rotation, translation) as the geometry does. */
typedef struct fcm_effect_cut {
  double time; /**< s, in [0, duration] (default 0) */
  fcm_cut_kind kind;
  double point[3];  /**< PLANE: a point; RECTANGLE, DISC: the centre */
  double normal[3]; /**< unit (normalized by the parser) */
  double axis[3];   /**< RECTANGLE: the direction of the first side */
  double size[2];   /**< RECTANGLE: side lengths, > 0 */
  double radius;    /**< DISC, > 0 */
  int segments;     /**< DISC: triangles, [3, 256], default 64 */
  const char *mesh; /**< MESH: resolved path */
  int has_transform;
  double transform[9], offset[3]; /**< x -> transform x + offset (identity when none) */
} fcm_effect_cut;

/** Contact obstacle kinds of the "contact" effect. */
typedef enum fcm_contact_obstacle {
  FCM_CONTACT_PLANE = 0, /**< "plane": fcm_integrator_add_contact_plane() */
  FCM_CONTACT_SPHERE,    /**< "sphere": fcm_integrator_add_contact_sphere() */
  FCM_CONTACT_BOX,       /**< "box": fcm_integrator_add_contact_box() */
  FCM_CONTACT_SURFACE,   /**< "surface": fcm_integrator_add_contact_surface() from a file */
  FCM_CONTACT_BODIES     /**< "bodies": true: fcm_integrator_add_contact_bodies() (the bodies and
                              cut pieces repel each other) */
} fcm_contact_obstacle;

/** A rigid obstacle: a half-space (the plane through point + velocity t with the unit normal
 * pointing to the body's side), a sphere, a box or the solid a closed triangle surface bounds,
 * the last three static or moved by a rigid motion; the barrier's threshold and stiffness (0:
 * the defaults of fcm_contact_options). */
typedef struct fcm_effect_contact {
  fcm_contact_obstacle obstacle; /**< which of the members below apply */
  double point[3];               /**< PLANE: m */
  double normal[3];              /**< PLANE: unit (normalized by the parser) */
  double velocity[3];            /**< PLANE: m/s (default 0: a static obstacle) */
  double center[3];              /**< SPHERE: m */
  double radius;                 /**< SPHERE: m, > 0 */
  double min[3], max[3];         /**< BOX: corners, min < max */
  const char *mesh;              /**< SURFACE: the .obj, .off, .stl or .ply file (resolved) */
  fcm_motion motion;             /**< SPHERE, BOX, SURFACE: "velocity", "rotation", "start",
                                      "end" as the motion effect (default: static) */
  fcm_contact_options options;   /**< "distance" (m), "stiffness" (Pa/m), "friction" (mu),
                                      "friction_velocity" (m/s), each >= 0;
                                      "friction_updates" in [0, 20] */
} fcm_effect_contact;

/** One effect of the scene: a tagged union. */
typedef struct fcm_effect {
  fcm_effect_type type; /**< selects the member */
  int index;            /**< position in the scene's "effects" array */
  union {
    fcm_effect_gravity gravity;
    fcm_effect_fixed fixed;
    fcm_effect_motion motion;
    fcm_effect_initial_velocity initial_velocity;
    fcm_effect_damping damping;
    fcm_effect_traction traction;
    fcm_effect_pressure pressure;
    fcm_effect_cut cut;
    fcm_effect_contact contact;
  };
} fcm_effect;

/** Initial velocity at X: velocity + angular_velocity x (X - c), with c = `com` (the
 * body's centre of mass, computed by the caller) when iv->center_of_mass, else iv->center.
 * `com` may be NULL when iv->center_of_mass is 0. No allocation; thread safe. */
FCM_API void fcm_effect_initial_velocity_eval(const fcm_effect_initial_velocity *iv,
                                              const double X[3], const double com[3], double v[3]);

/* --------------------------------------------------------------------- scene */

/** A parsed and validated scene (opaque; the sections are plain read-only data). */
typedef struct fcm_scene fcm_scene;

/** Read, parse and validate a scene file. Relative file names inside it are resolved
 * against the directory of `path`; referenced mesh files must exist and be readable. A scene
 * without "name" is named after the file's stem, characters outside [A-Za-z0-9_.-] replaced by
 * '_' (a warning through the context's log says so).
 * @param[in]  ctx   context (allocation, errors); must outlive the scene
 * @param[in]  path  the JSON file
 * @param[out] scene the new scene, NULL on failure
 * @return FCM_OK; FCM_ERR_IO (the file or a referenced mesh cannot be read: the message
 *         names the path and the system error); FCM_ERR_FORMAT (malformed JSON:
 *         "path:line:column: ..."); FCM_ERR_ARG (unknown key or effect, wrong type, value
 *         out of range, missing key: "path: effects[2].motion.end: expected ..., got ...",
 *         unknown keys list the allowed ones); FCM_ERR_ALLOC. Allocates through ctx (the
 *         JSON parser allocates its temporary tree with malloc). Thread safe. */
FCM_API fcm_status fcm_scene_create_from_file(fcm_ctx *ctx, const char *path, fcm_scene **scene);

/** Parse and validate a scene from a NUL-terminated JSON text.
 * @param[in]  source_name name used in messages (NULL: "<string>"); relative file names in
 *             the scene are resolved against its directory part (none: the working directory)
 * Otherwise as fcm_scene_create_from_file(). */
FCM_API fcm_status fcm_scene_create_from_string(fcm_ctx *ctx, const char *json_text,
                                                const char *source_name, fcm_scene **scene);

/** The built-in default scene: the example apps/scenes/twisting_cylinder.json, a hollow
 * cylinder with one end pushed in and the other twisted (Longva et al. 2020 §6.2, on a
 * coarse Hex20 grid), embedded in the library when it is built. Static NUL-terminated JSON
 * text; never NULL. */
FCM_API const char *fcm_scene_default_json(void);

/** fcm_scene_create_from_string(ctx, fcm_scene_default_json(), "<default>", scene). */
FCM_API fcm_status fcm_scene_create_default(fcm_ctx *ctx, fcm_scene **scene);

/** Destroy a scene; accepts NULL and `*scene == NULL`, sets `*scene = NULL`. */
FCM_API void fcm_scene_destroy(fcm_scene **scene);

/** Accessors (scene must not be NULL). Pointers stay valid for the life of the scene;
 * the data are read-only. Thread safe. */
FCM_API const char *fcm_scene_name(const fcm_scene *scene);        /**< "name" or file stem */
FCM_API const char *fcm_scene_description(const fcm_scene *scene); /**< "" when none */
FCM_API const char *fcm_scene_source(const fcm_scene *scene);      /**< file or source name */
/** The scene as normalized JSON text: every key the parser read, with the value it took —
 * the defaults filled in, choices by their canonical name, file names absolute — indented.
 * Parsed again (saved anywhere) it gives the same scene (fcm_scene_view() prints the same).
 * Keys whose default is computed for the problem (FCM_DEFAULT) are left out. */
FCM_API const char *fcm_scene_json(const fcm_scene *scene);
FCM_API const fcm_scene_background *fcm_scene_get_background(const fcm_scene *scene);
FCM_API const fcm_scene_geometry *fcm_scene_get_geometry(const fcm_scene *scene);
FCM_API const fcm_material *fcm_scene_get_material(const fcm_scene *scene);
FCM_API const fcm_scene_quadrature *fcm_scene_get_quadrature(const fcm_scene *scene);
FCM_API const fcm_scene_solver *fcm_scene_get_solver(const fcm_scene *scene);
FCM_API const fcm_scene_time *fcm_scene_get_time(const fcm_scene *scene);
FCM_API const fcm_scene_output *fcm_scene_get_output(const fcm_scene *scene);

/** Number of effects, and effect i (in [0, num_effects); NULL out of range), in file order. */
FCM_API int fcm_scene_num_effects(const fcm_scene *scene);
FCM_API const fcm_effect *fcm_scene_get_effect(const fcm_scene *scene, int i);

/** Number of effects of `type` in the scene (0: that effect costs nothing). */
FCM_API int fcm_scene_count_effects(const fcm_scene *scene, fcm_effect_type type);

/** Print a normalized summary (every section with defaults filled in and units, then the
 * effects) to `stream`. */
FCM_API void fcm_scene_view(const fcm_scene *scene, FILE *stream);

#ifdef __cplusplus
}
#endif
#endif /* FCM_SCENE_H */
