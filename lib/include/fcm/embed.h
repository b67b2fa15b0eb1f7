/* fcm — embedded (cut-cell) quadrature: per background cell, the embedded geometry is
 * clipped by the cell's planes, tetrahedralized and integrated with a tet rule mapped into
 * the cell's reference element (Longva et al. 2020 §4.5, lib/METHOD.md §5); cut-cell rules are
 * simplified (fcm/simplify.h) and stabilized; surface rules on the embedded boundary.
 *
 * Rules live in reference coordinates xi of the background cell K. A volume rule's weight
 * w already contains l_j |J_Q| / |det J_K(xi)|, so the physical integral over K ∩ Ω is
 * sum_j w_j det J_K(xi_j) f(X(xi_j)). Surface weights are physical area weights. */
#ifndef FCM_EMBED_H
#define FCM_EMBED_H

#include "fcm/core.h"
#include "fcm/element.h"
#include "fcm/geom.h"
#include "fcm/mesh.h"
#include "fcm/simplify.h"
#include "fcm/surface.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Class of a background cell by its volume fraction phi = |K ∩ Ω| / |K|. */
typedef enum fcm_cell_class {
  FCM_CELL_UNCUT = 0, /**< phi >= uncut_fraction: the catalogue rule of the cell's shape */
  FCM_CELL_CUT,       /**< min_fraction <= phi < uncut_fraction: an embedded rule */
  FCM_CELL_DROPPED    /**< phi < min_fraction: no points; the cell leaves the system */
} fcm_cell_class;

/** The two volume rules each cell carries (lib/METHOD.md §3: separate strengths). */
typedef enum fcm_rule_kind {
  FCM_RULE_STIFFNESS = 0, /**< stiffness, internal and body forces */
  FCM_RULE_MASS = 1,      /**< consistent mass */
  FCM_RULE_KIND_COUNT
} fcm_rule_kind;

/** Bits of fcm_cell_rules_options.kinds: which volume rules fcm_cell_rules_create() builds.
 * A kind that is not built costs nothing (no mapping, simplification, stabilization or
 * storage); asking for its rules afterwards (fcm_cell_rules_get(), assembling a mass matrix
 * from rules without mass rules, ...) is FCM_ERR_ARG naming the missing kind, never an
 * empty rule. Surface rules are requested separately by surface_strength >= 0. */
#define FCM_RULES_STIFFNESS (1u << FCM_RULE_STIFFNESS) /**< stiffness, internal and body forces */
#define FCM_RULES_MASS      (1u << FCM_RULE_MASS)      /**< consistent mass, momentum */
#define FCM_RULES_ALL       (FCM_RULES_STIFFNESS | FCM_RULES_MASS) /**< both volume kinds (default) */

/** Static name of a kind ("stiffness", "mass"; "invalid" outside the enum). */
FCM_API const char *fcm_rule_kind_name(fcm_rule_kind kind);

/** Whether fcm_cell_rules_create() simplifies the cut-cell rules (fcm_simplify()). */
typedef enum fcm_cell_simplify {
  FCM_CELL_SIMPLIFY_OFF = 0,  /**< keep every point of the mapped tet rules */
  FCM_CELL_SIMPLIFY_ON = 1,   /**< simplify the rules of every cut cell (default) */
  FCM_CELL_SIMPLIFY_AUTO = 2, /**< per rule kind, simplify when it pays for the expected number
                                   of assemblies: the simplification time of every cut cell
                                   (fcm_simplify_cost_estimate(), a deterministic model) against
                                   the assembly time it saves (fcm_simplify_pays()), so the
                                   same inputs always give the same rules; the choice and its
                                   inputs are in fcm_cell_rules_stats.decision */
  FCM_CELL_SIMPLIFY_COUNT
} fcm_cell_simplify;

/** Static name of a mode ("off", "on", "auto"; "invalid" outside the enum). */
FCM_API const char *fcm_cell_simplify_name(fcm_cell_simplify mode);

/** Where fcm_cell_rules_create() takes the rules of a cut cell from. */
typedef enum fcm_cell_moments {
  FCM_CELL_MOMENTS_AUTO = 0,    /**< from the body's boundary surface where that applies (default):
                                     the exact moments of the cell's material in closed form from
                                     the boundary triangles that meet the cell, then a positive
                                     rule of at most M points fitted on candidate points inside
                                     the material; a cost that follows the surface, not the
                                     geometry's volume mesh. It applies to affine background
                                     cells of a whole geometry (not a crop) that no cut reaches,
                                     when simplify is not OFF; elsewhere, and for a cell whose fit
                                     fails, the VOLUME path (counted in the statistics), which
                                     for a geometry without a volume mesh starts from the cell
                                     split by the boundary triangles into parts inside and
                                     outside the body */
  FCM_CELL_MOMENTS_VOLUME = 1,  /**< clip the geometry's cells into tets, map a tet rule onto
                                    each, simplify (the path of every cell before the surface one) */
  FCM_CELL_MOMENTS_SURFACE = 2, /**< as AUTO, but a cell whose fit fails is an error
                                   (FCM_ERR_NUMERIC naming the cell) instead of a fallback */
  FCM_CELL_MOMENTS_COUNT
} fcm_cell_moments;

/** Static name of a path ("auto", "volume", "surface"; "invalid" outside the enum). */
FCM_API const char *fcm_cell_moments_name(fcm_cell_moments path);

/** The cost model of FCM_CELL_SIMPLIFY_AUTO: 1 when simplifying pays, i.e. when
 * (points_before - points_after) * point_cost * assemblies > simplify_time, else 0 (also for
 * non-finite or negative arguments). point_cost: core-seconds one quadrature point costs in
 * one assembly; simplify_time: core-seconds of simplifying the rules. No allocation. */
FCM_API int fcm_simplify_pays(double assemblies, double point_cost, double points_before,
                              double points_after, double simplify_time);

/** Core-seconds one cut-cell quadrature point of `kind` costs in one assembly of a cell of
 * element `type`, measured with `fcm-converge payoff` (stiffness: stable Neo-Hookean force +
 * tangent; mass: the consistent mass) on one core of the development machine; the default
 * point_cost of FCM_CELL_SIMPLIFY_AUTO. 0 for an invalid type or kind. */
FCM_API double fcm_cell_rules_point_cost(fcm_element_type type, fcm_rule_kind kind);

/** Progress of fcm_cell_rules_create(): `done` of `total` background cells processed (the
 * intersection, simplification and stabilization of each; with FCM_CELL_SIMPLIFY_AUTO the
 * simplification runs after this loop and is not reported). It must not call back into
 * the library on the rules being built. */
typedef void (*fcm_cell_rules_progress_fn)(fcm_index done, fcm_index total, void *user);

/** Options of fcm_cell_rules_create(); initialize with fcm_cell_rules_options_default(). */
typedef struct fcm_cell_rules_options {
  unsigned kinds; /**< the volume rules to build, a non-empty set of FCM_RULES_* bits;
                       default FCM_RULES_ALL (what every caller got before the kinds
                       could be chosen). A static problem needs FCM_RULES_STIFFNESS
                       only; mass rules serve the mass matrix (dynamics, Rayleigh
                       damping) and fcm_space_momentum(). The scene runner derives the
                       set from the scene (fcm/simulation.h). */
  int strength[FCM_RULE_KIND_COUNT];    /**< per kind; FCM_DEFAULT (default): the element's */
  int axis_degree[FCM_RULE_KIND_COUNT]; /**< per kind, the cut-cell rules' moment space: the
                              polynomials of total degree <= strength whose degree in each
                              reference variable is <= axis_degree (axis_degree = k <= strength / 3:
                              the tensor space Q_k); a value >= strength: every polynomial of
                              total degree <= strength (P_strength), 0 ... 20; FCM_DEFAULT
                              (default): with the element's strength the element's
                              (fcm_element_info.mass_axis_degree for mass: Hex8 2, so Hex8's
                              cut-cell mass rules are exact on Q_2, 27 moments instead of P_6's
                              84; stiffness: the strength), with an explicit strength the
                              strength (P_strength). Uncut cells keep the catalogue rule. */
  int stiffness_on_mass_space; /**< 1: the cut cells' stiffness rules are fitted on the mass
                              rules' moment space (strength and axis_degree of the mass kind,
                              built or not), which holds the stiffness integrand of every
                              element (Hex8: Q_2, 27 moments, where the Hex8 stiffness of an
                              affine cell lies: its cut pieces' stiffness becomes exact), and
                              one fit serves both kinds, on candidates sized for that space;
                              more stiffness points per piece (Hex8: up to 27 instead of 10),
                              which pays where the stiffness is integrated once (corotated
                              linear). 0 (default): each kind on its own space. */
  int surface_strength;        /**< FCM_DEFAULT (default): no surface rules; else the triangle rule
                                    strength (the explicit request for surface rules) */
  double min_fraction;   /**< phi below this: dropped; default 1e-4 (0: drop only empty cells) */
  double uncut_fraction; /**< phi at or above this: uncut; default 1 - 1e-12 */
  double clip_rtol;      /**< vertex-on-plane tolerance / the smaller of the cell diameter and the
                             embedded cell's thickness 6|E|/diam(E)^2; default 1e-12 */
  double sliver_rtol;    /**< tets with volume <= this * min(|K|, |E|) are dropped (|E|: the
                             embedded cell clipped), so thin geometry keeps its volume; counted
                             with their volume in the statistics; default 1e-14 */
  double convex_rtol;    /**< tolerance of fcm_mesh_cell_is_convex(); default 1e-10 */
  fcm_cell_simplify simplify; /**< FCM_CELL_SIMPLIFY_ON (default), OFF or AUTO */
  fcm_cell_moments moments;   /**< FCM_CELL_MOMENTS_AUTO (default), VOLUME or SURFACE */
  double expected_assemblies[FCM_RULE_KIND_COUNT]; /**< AUTO: how many passes over the points
                              of each kind the rules will see (>= 0), every use counted: a
                              static single solve about 1 stiffness per Newton iteration, 0
                              mass; a dynamic run steps x Newton iterations stiffness (plus
                              body forces and output stresses), mass 2 per space built on the
                              rules (the mass matrix, and the element blocks of
                              fcm_space_momentum()); default 1 */
  double point_cost[FCM_RULE_KIND_COUNT]; /**< AUTO: core-seconds per point per assembly, > 0;
                              FCM_DEFAULT (default): fcm_cell_rules_point_cost() */
  fcm_simplify_options simplify_options;  /**< default fcm_simplify_options_default() */
  double max_rule_memory; /**< bytes the rules of one cut cell may take to build (an estimate
                               checked before allocating: points of both kinds plus the
                               simplification's moment matrix and LP); a cell above it fails
                               with FCM_ERR_UNSUPPORTED naming the cell, the estimate and the
                               limit; default 4 GiB; 0: no limit */
  fcm_stabilization_options stabilization; /**< default mass + stiffness, alpha 1e-6 */
  fcm_cell_rules_progress_fn progress;     /**< NULL (default): none; else called with the cells
                                  done so far, at most every progress_interval seconds and once
                                  with done == total at the end of the cell loop, always from the
                                  thread that called fcm_cell_rules_create() */
  void *progress_user;                     /**< passed to progress; default NULL */
  double progress_interval;                /**< seconds between progress calls, >= 0; default 0.1 */
  /** NULL (default): every cell's rules; else num_cells flags (read during the call only):
   * cells flagged 0 are classified as usual (class, volume fraction, pieces and their volumes,
   * so a space built on the rules has the same elements and DOFs) but get no quadrature points
   * (no volume or surface rules, no simplification, no stabilization). For distributed runs,
   * where each process integrates its own cells only (fcm/petsc.h); the rules must then not be
   * assembled on unflagged cells. Not with FCM_CELL_SIMPLIFY_AUTO (its choice would depend on
   * the mask; the PETSc backend sums the choice's inputs over its processes internally).
   * fcm_cell_rules_create_cut() of rules built with a mask keeps the mask: the same cells
   * get points, every cell is split and gets its cut faces. */
  const unsigned char *cell_mask;
} fcm_cell_rules_options;

/** Defaults as documented on each member. */
FCM_API fcm_cell_rules_options fcm_cell_rules_options_default(void);

/** What FCM_CELL_SIMPLIFY_AUTO decided for one rule kind, and why (times in core-seconds).
 * With OFF / ON only `simplified` and `time_simplify` are set (the rest 0). */
typedef struct fcm_simplify_decision {
  int simplified;             /**< 1: the cut-cell rules of this kind were simplified */
  double expected_assemblies; /**< input of the model */
  double point_cost;          /**< input: core-seconds per point per assembly */
  double estimated_time;      /**< simplification time of all cut cells: the sum of
                                   fcm_simplify_cost_estimate() over them */
  double estimated_kept;      /**< points all cut cells keep: min(N, M) per cell */
  double cost_plain;          /**< assembly time of the unsimplified cut-cell points over the
                                   expected assemblies: points x point_cost x assemblies */
  double cost_simplified;     /**< estimated_time + estimated_kept x point_cost x assemblies */
  double time_simplify;       /**< simplification time actually spent on this kind */
} fcm_simplify_decision;

/** Statistics of fcm_cell_rules_create(). Point counts cover cut cells unless "total"; after
 * fcm_cell_rules_create_cut() they cover the cells that call integrated.
 * Times in seconds: wall clock, except intersect and simplify, which are summed over
 * threads (seconds of one core). */
typedef struct fcm_cell_rules_stats {
  fcm_index num_cells, num_uncut, num_cut, num_dropped;
  fcm_index num_candidates;      /**< (background cell, embedded cell) pairs from the tree */
  fcm_index num_parts;           /**< non-empty clipped polyhedra (convex parts) */
  fcm_index num_material_pieces; /**< material pieces (fcm_cell_rules_num_pieces()) */
  fcm_index num_split;           /**< cells that cuts split into two or more pieces */
  fcm_index num_links;           /**< fcm_cell_rules_num_links() */
  fcm_index num_integrated;      /**< cells whose rules this call built: every cell for
                                      fcm_cell_rules_create(), the cells the new cut reaches and
                                      changes for fcm_cell_rules_create_cut() (the others are
                                      copied) */
  fcm_index num_kept;            /**< fcm_cell_rules_create_cut(): cells the new cut reaches
                                      without changing their material pieces (it divides none
                                      of their parts and separates none from another: material
                                      on one side only, an empty cell, a cut along a face); their
                                      class, fraction, pieces and rules are copied bit for bit,
                                      their cut faces made again */
  fcm_index num_degenerate;      /**< cells whose splitting by the new cut changed their
                                      parts' volume by more than 1e-12 of the cell's (after a
                                      successful fcm_cell_rules_create_cut() 0, unless no shift
                                      resolved them and each change is within the tolerance's
                                      layer, 1e-9: split_change) */
  double cut_shift[3];           /**< the translation fcm_cell_rules_create_cut() applied to the
                                      new cut to resolve degenerate cells; 0 when none was needed */
  int cut_attempts;              /**< times it applied the cut (1: no shift) */
  fcm_index num_tets;            /**< tets of the pieces kept (slivers excluded) */
  fcm_index num_slivers;         /**< tets dropped as slivers */
  double sliver_volume;          /**< their summed volume (not in embedded_volume) */
  double moved_volume;           /**< volume the rules of parts that the tolerances left slightly
                                      non-convex move: their fan tets of negative volume get no
                                      points and the others are scaled to keep the part's volume,
                                      so a function g is integrated over the cells this call built
                                      with an error of at most 2 moved_volume max |g| beyond the
                                      rules' own (0 when every part is convex to rounding) */
  unsigned kinds;                /**< the volume kinds built (FCM_RULES_* bits); a kind not
                                      built has 0 points everywhere below */
  fcm_index points_initial[FCM_RULE_KIND_COUNT];    /**< before simplification */
  fcm_index points_simplified[FCM_RULE_KIND_COUNT]; /**< after (= initial when off) */
  fcm_index points_stabilization[FCM_RULE_KIND_COUNT];
  fcm_index points_total[FCM_RULE_KIND_COUNT];       /**< all stored points, uncut cells included */
  fcm_index simplify_skipped[FCM_RULE_KIND_COUNT];   /**< cut cells with N <= M */
  fcm_index simplify_fallbacks[FCM_RULE_KIND_COUNT]; /**< kept unsimplified after failure */
  double max_residual[FCM_RULE_KIND_COUNT]; /**< largest relative moment residual reported */
  fcm_index num_surface_cells;     /**< cut cells whose rules were fitted on surface moments
                                      (FCM_CELL_MOMENTS_AUTO / SURFACE) */
  fcm_index num_surface_fallbacks; /**< cells where that fit failed and the volume path built
                                      the rules (AUTO) */
  fcm_index surface_triangles; /**< clipped boundary triangles kept (per piece in cells that cuts
                                  split) */
  fcm_index surface_points;
  double embedded_volume;        /**< sum over all cells of |K ∩ Ω| (dropped cells included) */
  double dropped_volume;         /**< the part of it in dropped cells */
  double embedded_area;          /**< sum of the surface weights (non-dropped cells) */
  double geometry_volume;        /**< fcm_geometry_volume() */
  double outside_volume;         /**< the body outside the background mesh: geometry_volume -
                                      embedded_volume - sliver_volume, 0 when that is below 1e-12
                                      geometry_volume (rounding) */
  double outside_side_volume[6]; /**< the body beyond each face plane of the mesh's bounding
                               box, in the order -x, +x, -y, +y, -z, +z (a part beyond an edge
                               or a corner counts for each side it is beyond) */
  double volume_ratio;           /**< embedded_volume / geometry_volume (0 for an empty geometry) */
  double mesh_lo[3], mesh_hi[3]; /**< bounding box of the background mesh */
  double geometry_lo[3], geometry_hi[3]; /**< bounding box of the embedded geometry */
  double time_setup, time_intersect, time_simplify, time_gather, time_total;
  int num_threads;
  fcm_simplify_decision decision[FCM_RULE_KIND_COUNT]; /**< per kind (see the mode) */
  double dropped_area; /**< the embedded surface's area in dropped cells: boundary that no
                            surface rule carries (their traction or Nitsche terms are lost);
                            embedded_area + dropped_area is the surface's area. Computed only
                            when surface rules are built (surface_strength >= 0), else 0 */
  double split_change; /**< the largest change of a cell's parts' volume by the new cut's
                            splitting, relative to the cell's volume (rounding, about 1e-15;
                            above 1e-12 in the cells num_degenerate counts; at most 1e-9 after
                            a successful fcm_cell_rules_create_cut(); each cut's adds to the
                            earlier ones') */
} fcm_cell_rules_stats;

/** Per-cell quadrature of an embedded geometry in a background mesh (opaque). */
typedef struct fcm_cell_rules fcm_cell_rules;

/** Build the rules of every background cell (lib/METHOD.md §5): AABB-tree candidates, convex
 * clipping by the cell's face planes, fan tetrahedralization, tet rules mapped into the
 * reference cell (closed-form inverse for affine cells, Newton otherwise), classification;
 * then per cut cell simplification (if enabled) followed by stabilization points (flag 1).
 * Parallel over cells (OpenMP, fcm_ctx_num_threads(ctx) threads); the output does not depend on
 * the thread count. With
 * FCM_CELL_SIMPLIFY_AUTO the choice per kind depends on measured times; the rules are then
 * exactly those of OFF or of ON for that kind.
 * @param[in] mesh background mesh; every cell must be convex (straight edges, planar faces)
 * @param[in] geom embedded geometry; mesh and geom are only read during the call
 * @param[in] opts NULL for defaults; @param[out] rules NULL on failure
 * @return FCM_OK; FCM_ERR_ARG (NULL, kinds empty or with bits outside FCM_RULES_ALL,
 *         strengths outside [0, 20] with simplification or
 *         [0, FCM_RULE_MAX_STRENGTH] without, simplify not a mode, AUTO with expected_assemblies
 *         < 0, point_cost <= 0 (not FCM_DEFAULT), thresholds outside 0 <=
 *         min_fraction < uncut_fraction <= 1, tolerances out of range, bad stabilization,
 *         progress_interval < 0); FCM_ERR_GEOMETRY (a non-convex background cell, naming it;
 *         a degenerate cell; a geometry of positive volume with no part inside any background
 *         cell, printing both bounding boxes); FCM_ERR_NOT_CONVERGED
 *         (inverse map); FCM_ERR_UNSUPPORTED (a cell whose rules would exceed
 *         max_rule_memory or 2^30 points); FCM_ERR_ALLOC; errors of fcm_simplify(). When
 *         several cells fail, the error is that of the lowest-numbered one. Volume fractions
 *         are clamped to [0, 1]. Allocates. */
FCM_API fcm_status fcm_cell_rules_create(fcm_ctx *ctx, const fcm_mesh *mesh,
                                         const fcm_geometry *geom,
                                         const fcm_cell_rules_options *opts,
                                         fcm_cell_rules **rules);

/** Destroy; accepts NULL and sets `*rules = NULL`. */
FCM_API void fcm_cell_rules_destroy(fcm_cell_rules **rules);

/** Number of background cells; the element type; the strength of a kind (-1 for a kind
 * that was not built) or of the surface rules (-1 when none). */
FCM_API fcm_index fcm_cell_rules_num_cells(const fcm_cell_rules *rules);
FCM_API fcm_element_type fcm_cell_rules_element_type(const fcm_cell_rules *rules);
FCM_API int fcm_cell_rules_strength(const fcm_cell_rules *rules, fcm_rule_kind kind);
FCM_API int fcm_cell_rules_surface_strength(const fcm_cell_rules *rules);

/** The largest degree in each reference variable of the polynomials on which the cut-cell rules
 * of `kind` are exact (they are exact on those of total degree <= fcm_cell_rules_strength()
 * with this degree in each variable): the strength when the space is all of P_strength, less
 * for a tensor space (Hex8 mass by default: 2 with strength 6, Q_2); -1 for a kind that was not
 * built. */
FCM_API int fcm_cell_rules_axis_degree(const fcm_cell_rules *rules, fcm_rule_kind kind);

/** 1 when the rules of `kind` were built (fcm_cell_rules_options.kinds), else 0 (also for
 * NULL rules or a kind out of range). */
FCM_API int fcm_cell_rules_has_kind(const fcm_cell_rules *rules, fcm_rule_kind kind);

/** Class and volume fraction of `cell` (in [0, num_cells); out of range: DROPPED, 0). */
FCM_API fcm_cell_class fcm_cell_rules_class(const fcm_cell_rules *rules, fcm_index cell);
FCM_API double fcm_cell_rules_volume_fraction(const fcm_cell_rules *rules, fcm_index cell);

/** The volume rule of `kind` for `cell`: for a cell that cuts split into several material
 * pieces, the concatenation of its pieces' rules (each with its own stabilization points;
 * fcm_cell_rules_get_piece() gives them one by one). num_points, reference points (n x 3), weights
 * (n, including |J_Q|/|J_K|; stabilization points have alpha times the standard weight) and flags
 * (n; 0 authentic, 1 fictitious stabilization point). Uncut cells share one catalogue rule; dropped
 * cells have 0 points (pointers then NULL). Any output may be NULL. Pointers stay valid for the
 * life of `rules`. @return FCM_OK or FCM_ERR_ARG (cell or kind out of range, or a kind that
 * was not built: fcm_cell_rules_options.kinds). No allocation; thread safe. */
FCM_API fcm_status fcm_cell_rules_get(const fcm_cell_rules *rules, fcm_index cell,
                                      fcm_rule_kind kind, int *num_points, const double **points,
                                      const double **weights, const unsigned char **flags);

/** The surface rule of `cell` on the embedded boundary: reference points (n x 3), physical
 * area weights (the integral of g over the boundary part in K is sum w_j g(X(xi_j))), unit
 * outward normals (n x 3) and the boundary triangle of each point (index into
 * fcm_geometry_boundary_triangles()). Dropped cells and rules built without surface
 * strength have 0 points. Any output may be NULL. @return FCM_OK or FCM_ERR_ARG. */
FCM_API fcm_status fcm_cell_rules_get_surface(const fcm_cell_rules *rules, fcm_index cell,
                                              int *num_points, const double **points,
                                              const double **weights, const double **normals,
                                              const fcm_index **triangles);

/* ---------------------------------------------------------------- cutting (XFEM) */

/** Extend `prev` by a cut (XFEM; Koschier et al. 2017, Ton-That et al. 2024): a triangle surface in
 * the reference (material) coordinates of the geometry. Inside every background cell the cuts
 * reach, the convex parts of the embedded geometry are split by the plane of each cut triangle that
 * reaches them and by its three edge planes (perpendicular to the triangle through its edges), so
 * every new face lies wholly on or wholly off a triangle; two parts sharing a face of positive area
 * are connected unless that face lies on a cut triangle; the connected components are the cell's
 * material pieces. Each piece's rules come from the same path as a cut cell (tetrahedralize, map,
 * simplify with prev's options, stabilize). A cut that ends inside a cell does not separate it.
 * Only the cells the new cut reaches are integrated again (stats.num_integrated); the rules of
 * every other cell are copied, so adding cuts one at a time costs what the cut touches. Triangles
 * without area are ignored (a cut with no triangle of positive area is refused: it would separate
 * nothing); a cut that misses the body changes nothing but still counts in
 * fcm_cell_rules_num_cuts(). The links between pieces of neighbouring cells
 * (fcm_cell_rules_links()) are recomputed around every cut. `prev` is not changed (it may be
 * destroyed afterwards).
 * Degenerate cuts: every part vertex is classified once per plane, with the tolerance of the
 * link test (1e-9 of the cell size): a cut that close to a node, an edge or a face goes
 * through it (a cut in cell faces separates the cells without splitting them). Where that
 * cannot resolve a cell (near-coincident vertices classified differently: splitting would
 * change the cell's volume, stats.num_degenerate), the whole cut is shifted by a small
 * deterministic translation (1e-7, then 1e-6, 1e-5 of the mean cell size; stats.cut_shift,
 * stats.cut_attempts) and applied again. If no shift resolves it, the attempt of least change
 * is taken when every cell's change is at most 1e-9 of its volume (the layer the tolerance
 * leaves: a vertex taken as on a plane lies up to 1e-9 of the cell size off it; the pieces are
 * as the tolerance places them, stats.num_degenerate > 0), else the cut fails.
 * @param[in] mesh, geom the mesh and geometry `prev` was built on; @param[in] cut copied
 * On an octree mesh pieces are also linked across faces between cells of different levels,
 * where a piece's part of the finer face overlaps a coarser piece's part of the coarser face.
 * @return FCM_OK; FCM_ERR_ARG (NULL, another mesh); FCM_ERR_GEOMETRY
 *         (every cut triangle without area, giving the first; degenerate cells left after
 *         the largest shift);
 *         FCM_ERR_INTERNAL (a split exceeding the polyhedron
 *         capacity); the errors of fcm_cell_rules_create(). Allocates. */
FCM_API fcm_status fcm_cell_rules_create_cut(fcm_ctx *ctx, const fcm_mesh *mesh,
                                             const fcm_geometry *geom, const fcm_cell_rules *prev,
                                             const fcm_surface *cut, fcm_cell_rules **rules);

/** Number of cuts added so far (fcm_cell_rules_create_cut() calls). */
FCM_API int fcm_cell_rules_num_cuts(const fcm_cell_rules *rules);

/** Number of material pieces over all cells: one per uncut cell, none for a dropped cell,
 * one or (when cuts split it) more per cut cell. Pieces are numbered cell by cell. */
FCM_API fcm_index fcm_cell_rules_num_pieces(const fcm_cell_rules *rules);

/** Number of pieces of `cell` and, in *first (may be NULL), the first one's index (0 and 0
 * for a cell out of range). */
FCM_API fcm_index fcm_cell_rules_cell_pieces(const fcm_cell_rules *rules, fcm_index cell,
                                             fcm_index *first);

/** The cell of `piece` (-1 out of range) and its volume (|piece|, physical). */
FCM_API fcm_index fcm_cell_rules_piece_cell(const fcm_cell_rules *rules, fcm_index piece);
FCM_API double fcm_cell_rules_piece_volume(const fcm_cell_rules *rules, fcm_index piece);

/** The volume rule of `kind` for one piece, as fcm_cell_rules_get() (a piece of an uncut
 * cell has the catalogue rule). @return FCM_OK or FCM_ERR_ARG (piece or kind out of range, or
 * a kind that was not built). No allocation; thread safe. */
FCM_API fcm_status fcm_cell_rules_get_piece(const fcm_cell_rules *rules, fcm_index piece,
                                            fcm_rule_kind kind, int *num_points,
                                            const double **points, const double **weights,
                                            const unsigned char **flags);

/** The surface rule of one piece, as fcm_cell_rules_get_surface(). In a cell split into
 * pieces each surface quadrature point goes to the piece whose part contains it (the
 * boundary triangles themselves are not split by the cut planes, so a traction integral
 * over a triangle that a cut crosses is split point by point).
 * @return FCM_OK or FCM_ERR_ARG. */
FCM_API fcm_status fcm_cell_rules_get_piece_surface(const fcm_cell_rules *rules, fcm_index piece,
                                                    int *num_points, const double **points,
                                                    const double **weights, const double **normals,
                                                    const fcm_index **triangles);

/** The faces of `piece` that lie on the cuts (its side of them), as triangles for output:
 * returns their number and, in *xi (may be NULL; NULL when none), 9 reference coordinates
 * per triangle (3 vertices in the cell's reference element), oriented outward from the
 * piece. Both sides of a cut face appear, each with its own piece, so moving each with its
 * piece's DOFs shows the opening. 0 for a piece out of range or of a cell no cut reaches.
 * No allocation; thread safe. */
FCM_API fcm_index fcm_cell_rules_get_piece_cut_faces(const fcm_cell_rules *rules, fcm_index piece,
                                                     const double **xi);

/** The piece of the rules this object extended (the `prev` of fcm_cell_rules_create_cut())
 * that holds `piece` (pieces only ever split: every piece lies in one earlier piece of the
 * same cell); -1 for rules from fcm_cell_rules_create() or out of range. With
 * fcm_cell_rules_parent_num_pieces() (0 without a parent) this is what
 * fcm_space_transfer() maps fields through. */
FCM_API fcm_index fcm_cell_rules_piece_parent(const fcm_cell_rules *rules, fcm_index piece);
FCM_API fcm_index fcm_cell_rules_parent_num_pieces(const fcm_cell_rules *rules);

/** Links between pieces of face-neighbouring cells near the cuts: pairs (p, q), p < q, of
 * pieces that share a part of the cells' common face with positive area not lying on a
 * cut triangle; 2 x num_links entries, sorted. Computed for every pair of cells that share a
 * node with a cell the cuts reach (elsewhere every cell has one piece). A cut only separates:
 * two pieces are linked only if their parents (fcm_cell_rules_piece_parent()) were, so the
 * bodies after a cut are parts of the bodies before it. The generalized enrichment of
 * fcm_space_create_embedded() groups each node's pieces along these links. */
FCM_API fcm_index fcm_cell_rules_num_links(const fcm_cell_rules *rules);
FCM_API const fcm_index *fcm_cell_rules_links(const fcm_cell_rules *rules);

/** The statistics (a pointer into `rules`). */
FCM_API const fcm_cell_rules_stats *fcm_cell_rules_get_stats(const fcm_cell_rules *rules);

/** Print the statistics (classes, points before/after simplification, fallbacks, residual,
 * volumes with the embedded / geometry ratio and the volume outside the mesh by side, times)
 * to `stream`. */
FCM_API void fcm_cell_rules_view(const fcm_cell_rules *rules, FILE *stream);

/** Print every point of `kind` in cell order as "cell xi eta zeta X Y Z w_ref w_phys flag"
 * (X = map of xi, w_phys = w_ref det J_K(xi)), full precision, one per line, after a
 * '#' header line. `mesh` must be the mesh the rules were built on.
 * @return FCM_OK, FCM_ERR_ARG (NULL, kind invalid or not built, cell count differs), FCM_ERR_IO. */
FCM_API fcm_status fcm_cell_rules_view_points(const fcm_cell_rules *rules, const fcm_mesh *mesh,
                                              fcm_rule_kind kind, FILE *stream);

/** Map reference points of `cell` to physical coordinates: x_j = X(xi_j) and det_j = det
 * J_K(xi_j), so a volume weight w_j of the cell's rules integrates physically as w_j det_j
 * (fcm/embed.h, top). Works for the points of any of the cell's rules (volume, surface,
 * pieces). `mesh` must be the mesh the rules were built on.
 * @param[in]  xi  num_points x 3 reference coordinates
 * @param[out] x   num_points x 3 physical coordinates; may be NULL
 * @param[out] det num_points Jacobian determinants; may be NULL
 * @return FCM_OK, FCM_ERR_ARG (NULL rules, mesh or xi with points; num_points < 0; cell out
 * of range; a mesh of another cell count or element type). No allocation; thread safe. */
FCM_API fcm_status fcm_cell_rules_map_points(const fcm_cell_rules *rules, const fcm_mesh *mesh,
                                             fcm_index cell, int num_points, const double *xi,
                                             double *x, double *det);

/** Options of fcm_cell_rules_write(); initialize with fcm_cell_rules_write_options_default(). */
typedef struct fcm_cell_rules_write_options {
  int include_mesh;        /**< 1 (default): the mesh's node coordinates and cell connectivity
                                (arrays "mesh/nodes", "mesh/cells"), so a reader can match its
                                own cells to fcm's; 0: only counts and the bounding box */
  int include_physical;    /**< 1 (default): physical points and weights beside the reference
                                ones ("points_phys", "weights_phys"); 0: reference only */
  const char *description; /**< NULL (default) or text stored as the header's "description"
                                (the command line, the geometry's name, ...); copied */
} fcm_cell_rules_write_options;

/** Defaults as documented on each member. */
FCM_API fcm_cell_rules_write_options fcm_cell_rules_write_options_default(void);

/** Write every cell's rules to a file for other codes (format: lib/docs/rules_format.md):
 * a JSON header (version, element type, counts, mesh description, the table of arrays with
 * name, dtype, shape, byte offset and byte order) followed by raw little-endian arrays in CSR
 * layout: per cell its class, volume fraction and pieces; per piece its cell, volume and the
 * offsets of its points in each volume rule built and in the surface rule; per point the
 * reference (and physical) coordinates, weights and flags; surface normals and triangles.
 * The file is written atomically: a temporary beside `path` replaces it only when complete.
 * @param[in] mesh the mesh the rules were built on; @param[in] opts NULL for defaults
 * @return FCM_OK; FCM_ERR_ARG (NULL rules, mesh or path, another mesh, a description with
 * control characters); FCM_ERR_IO (cannot create, write or rename; the previous file is left
 * intact and no temporary remains); FCM_ERR_ALLOC. Allocates transiently; thread safe for
 * distinct paths. */
FCM_API fcm_status fcm_cell_rules_write(const fcm_cell_rules *rules, const fcm_mesh *mesh,
                                        const char *path, const fcm_cell_rules_write_options *opts);

#ifdef __cplusplus
}
#endif
#endif /* FCM_EMBED_H */
