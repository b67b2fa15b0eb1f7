/* fcm — bodies given by a level-set function phi (phi < 0 inside) as embedded geometries:
 * marching tetrahedra on a refinement of each cut cell of a background grid, and a few
 * built-in implicit functions (sphere, torus, box, gyroid lattice) combined by CSG.
 *
 * The body is the region where the piecewise-linear interpolant of phi on the refined Kuhn
 * lattice (every sub-cube split into 6 tets around its lo -> hi diagonal) is negative: each
 * such tet is cut by the plane phi = 0 into at most 3 tets. The geometric error is O(h^2)
 * in the sub-cell size h for a smooth boundary. */
#ifndef FCM_LEVELSET_H
#define FCM_LEVELSET_H

#include "fcm/core.h"
#include "fcm/geom.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A level-set function: phi(x) < 0 inside the body, >= 0 outside. Called from one thread
 * at a time (the caller's); must return a finite value. */
typedef double (*fcm_level_set_fn)(const double x[3], void *user);

/** Peak bytes fcm_geometry_create_from_level_set() takes per sub-cell it triangulates
 * (fcm_level_set_info.subcells), everything it builds included: measured 5.5-12.7 kB on
 * spheres and gyroids at refinements 1-32 (about 12 tets per sub-cell the surface crosses;
 * the benchmark bench_level_set_memory prints the figures). */
#define FCM_LEVEL_SET_SUBCELL_BYTES 13000

/** Default of fcm_level_set_options.max_subcells: about 3.9 GB at FCM_LEVEL_SET_SUBCELL_BYTES. */
#define FCM_LEVEL_SET_MAX_SUBCELLS 300000

/** Progress of fcm_geometry_create_from_level_set(): `done` of `total` sub-cells marched (a
 * cut cell counts r^3 in the build and (2r)^3 in the error estimate; with refine_inside an
 * inside cell counts r^3 too). Called from the calling thread; must not call back into the
 * library on the geometry being built. */
typedef void (*fcm_level_set_progress_fn)(fcm_index done, fcm_index total, void *user);

/** Options of fcm_geometry_create_from_level_set(). */
typedef struct fcm_level_set_options {
  int refinement;         /**< sub-cells per background-cell edge where phi changes sign,
                               [1, 64]; default 4 */
  int estimate_error;     /**< 1 (default): also compute the volume at refinement 2r (volume
                               only, nothing stored) for fcm_level_set_info.error_estimate */
  int refine_inside;      /**< 0 (default): cells where every sample is inside become 6 tets of
                               the whole cell, and in cut cells the sub-cubes with every corner
                               inside are merged into boxes of 6 tets (fewer tets, which do not
                               conform to the refined ones next to them; the boundary triangles
                               are the same); 1: every sub-cube is split on its own */
  fcm_index max_subcells; /**< >= 0: refuse a build (FCM_ERR_UNSUPPORTED, after the cells are
                           classified and before any tet is stored) that would triangulate
                           more sub-cells (fcm_level_set_info.subcells) than this; 0: no
                           limit; default FCM_LEVEL_SET_MAX_SUBCELLS */
  fcm_level_set_progress_fn progress; /**< NULL (default): none; else called with the sub-cells
                           marched so far, at most every progress_interval seconds, and once
                           with done == total at the end */
  void *progress_user;                /**< passed to progress; default NULL */
  double progress_interval;           /**< seconds between progress calls, >= 0; default 0.1 */
} fcm_level_set_options;

/** Defaults as documented on each member. */
FCM_API fcm_level_set_options fcm_level_set_options_default(void);

/** What fcm_geometry_create_from_level_set() built. */
typedef struct fcm_level_set_info {
  fcm_index cells_inside;  /**< background cells with every sample inside */
  fcm_index cells_cut;     /**< cells where phi changes sign at the samples (refined) */
  fcm_index cells_outside; /**< cells with every sample outside */
  fcm_index num_tets;      /**< tets of the geometry */
  fcm_index subcells;      /**< the sub-cells the build triangulates, the estimate checked
                                against max_subcells: those of the cut cells where phi
                                changes sign at the corners (the surface crosses them), plus
                                one per cell wholly inside (6 tets); with refine_inside r^3
                                per cut or inside cell */
  double h;                /**< largest sub-cell edge: max_d (hi - lo)_d / (n_d r) */
  double volume;           /**< volume of the geometry */
  double volume_fine;      /**< the volume with the cells cut at refinement r sampled at 2r
                                (the others as at r); 0 unless estimate_error */
  double error_estimate;   /**< 4/3 |volume - volume_fine|: the Richardson estimate of the
                                volume error for an O(h^2) method (0 unless estimate_error) */
} fcm_level_set_info;

/** The body {phi < 0} inside the box [lo, hi] (sampled on n[0] x n[1] x n[2] cells, the
 * lattice of the background grid when it is one) as a Tet4 geometry. phi is sampled at the
 * (r + 1)^3 lattice points of every cell; cells with mixed signs are cut by marching
 * tetrahedra on the r^3 sub-cubes; cells entirely inside are 6 tets (unless
 * refine_inside). The parts of the body outside [lo, hi] are cut off. Tets share nodes
 * (lattice points and edge crossings). The boundary triangles are the surface: the
 * iso-surface pieces of the marched tets (facing along the gradient of the interpolant)
 * and the tet faces on the faces of [lo, hi], each owned by its tet; closed and outward
 * (fcm_geometry_create_transformed() keeps them). The cells are classified first (phi
 * sampled, nothing stored), so a build above max_subcells is refused before it allocates.
 * When phi is fcm_implicit_eval, its tree (user) is checked first by
 * fcm_implicit_check_spacing() with the spacing h of fcm_level_set_info.
 * @param[in] phi, user the function and its argument; @param[in] opts NULL for defaults
 * @param[out] geom the geometry; @param[out] info may be NULL
 * @return FCM_OK; FCM_ERR_ARG (NULL, lo >= hi, n outside [1, 10^4], refinement outside
 *         [1, 64], more than 2^31 sub-cells, max_subcells < 0, progress_interval < 0; an
 *         implicit tree that is invalid or not resolved by the sampling, naming the node,
 *         member, value and h); FCM_ERR_UNSUPPORTED (more sub-cells than max_subcells, with
 *         the estimate, the limit and their memory); FCM_ERR_GEOMETRY (phi not finite at a
 *         point, naming it; the body has no volume in the box); FCM_ERR_ALLOC. Allocates. */
FCM_API fcm_status fcm_geometry_create_from_level_set(fcm_ctx *ctx, fcm_level_set_fn phi,
                                                      void *user, const double lo[3],
                                                      const double hi[3], const fcm_index n[3],
                                                      const fcm_level_set_options *opts,
                                                      fcm_geometry **geom,
                                                      fcm_level_set_info *info);

/** Built-in implicit functions and CSG operations (fcm_implicit.kind). */
typedef enum fcm_implicit_kind {
  FCM_IMPLICIT_SPHERE = 0,   /**< |x - center| - radius */
  FCM_IMPLICIT_TORUS,        /**< torus around `axis` through center: major radius `radius`,
                                  tube radius `minor_radius` */
  FCM_IMPLICIT_BOX,          /**< the box [min, max]: max_d (|x_d - c_d| - half_d) */
  FCM_IMPLICIT_GYROID,       /**< gyroid lattice of cell size `period` inside [min, max]:
                                  g = sin kx cos ky + sin ky cos kz + sin kz cos kx, k = 2 pi /
                                  period, scaled by period / (2 pi); sheet: |g| - thickness,
                                  solid: g - thickness; intersected with the box */
  FCM_IMPLICIT_UNION,        /**< min(phi_a, phi_b) */
  FCM_IMPLICIT_INTERSECTION, /**< max(phi_a, phi_b) */
  FCM_IMPLICIT_DIFFERENCE,   /**< a minus b: max(phi_a, -phi_b) */
  FCM_IMPLICIT_KIND_COUNT
} fcm_implicit_kind;

/** One node of an implicit-function tree; members not used by `kind` are ignored. */
typedef struct fcm_implicit {
  fcm_implicit_kind kind;
  double center[3];      /**< SPHERE, TORUS */
  double radius;         /**< SPHERE; TORUS: major radius; > 0 */
  double minor_radius;   /**< TORUS: in (0, radius] */
  int axis;              /**< TORUS: symmetry axis 0 (x), 1 (y), 2 (z) */
  double min[3], max[3]; /**< BOX, GYROID: min[d] < max[d] */
  double period;         /**< GYROID: lattice cell size > 0 */
  double thickness;      /**< GYROID: sheet half-thickness (> 0) or solid level, in length
                              units (|thickness| < period / 4) */
  int sheet;             /**< GYROID: 1 a sheet (walls), 0 a solid network */
  int a, b;              /**< UNION, INTERSECTION, DIFFERENCE: operand nodes, indices < this
                              node's own */
} fcm_implicit;

/** Largest number of nodes of an implicit tree. */
#define FCM_IMPLICIT_MAX_NODES 64

/** A tree of implicit nodes: the root is the last node. Pass its address as the `user` of
 * fcm_implicit_eval(). */
typedef struct fcm_implicit_tree {
  int num_nodes;             /**< [1, FCM_IMPLICIT_MAX_NODES] */
  const fcm_implicit *nodes; /**< borrowed */
} fcm_implicit_tree;

/** Validate a tree (counts, kinds, parameters in the ranges documented on fcm_implicit,
 * operands earlier than their node). @return FCM_OK or FCM_ERR_ARG naming the node, member
 * and valid range. No allocation. */
FCM_API fcm_status fcm_implicit_check(fcm_ctx *ctx, const fcm_implicit_tree *tree);

/** Check that the sampling spacing h (the largest sub-cell edge,
 * fcm_level_set_info.h) resolves the smallest feature of every node of a tree: a sphere's
 * radius, a torus's minor_radius and every side (max - min) of a box must be at least h; a
 * gyroid's period at least 2 h (its channels are half a period wide: a period under two
 * samples only samples noise) and, for a sheet, its wall 2 thickness at least h. The tree
 * is validated first (fcm_implicit_check()).
 * @return FCM_OK or FCM_ERR_ARG naming the node, the member, its value and h (also h not
 *         positive and finite). No allocation. */
FCM_API fcm_status fcm_implicit_check_spacing(fcm_ctx *ctx, const fcm_implicit_tree *tree,
                                              double h);

/** The value of a validated tree (`user`: a const fcm_implicit_tree *) at x: an
 * fcm_level_set_fn. Thread safe, no allocation. */
FCM_API double fcm_implicit_eval(const double x[3], void *user);

#ifdef __cplusplus
}
#endif
#endif /* FCM_LEVELSET_H */
