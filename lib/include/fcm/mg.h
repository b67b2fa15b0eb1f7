/* fcm — cut-aware geometric multigrid for Hex8 and Hex20 box grids (Dick, Georgii,
 * Westermann 2011): on Hex20 a first p-level Hex20 -> Hex8 on the same grid, then
 * 2x2x2 blocks of cells are merged, one coarse cell per connected component of the block's
 * elements, so material that the fine space separates (disjoint bodies, cuts) is never merged;
 * coarse DOFs are duplicated per component. Trilinear prolongation per component, restriction
 * its transpose, Galerkin coarse matrices P^T A P, a CHOLMOD solve on the coarsest level,
 * symmetric Gauss-Seidel or damped Jacobi smoothing, V- or W-cycles. Use it as a solver
 * (fcm_mg_solve()) or as the preconditioner of fcm_krylov_cg() (fcm_mg_operator()). On an octree
 * background with hanging nodes the hierarchy first coarsens the octree level by level (Dick et
 * al. Sec. 5), then the uniform grid it reaches. */
#ifndef FCM_MG_H
#define FCM_MG_H

#include "fcm/core.h"
#include "fcm/fem.h"
#include "fcm/la.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The smoother of every level but the coarsest. */
typedef enum fcm_mg_smoother {
  /** Symmetric Gauss-Seidel (SSOR with omega): a forward then a backward sweep in a fixed
   * order of the rows: each level's rows in two ranges and the thin range between them that
   * keeps them apart (rows couple only within a range or with a neighbouring one); a forward
   * sweep runs the thin range, then the two others in parallel (each in row order), the
   * backward sweep the reverse. The order depends on the matrix pattern only, so the result
   * is bitwise independent of the thread count. Rows that couple far apart in row order
   * (Hex20's finest level numbers its corner nodes first) form one range, swept
   * sequentially. */
  FCM_MG_SMOOTHER_SGS = 0,
  /** Damped Jacobi x += omega D^{-1} (b - A x); rows in parallel, deterministic. */
  FCM_MG_SMOOTHER_JACOBI = 1,
  /** Symmetric Gauss-Seidel in multicolour order: the rows of each level are coloured
   * greedily (in row order, no two coupled rows share a colour); a forward sweep runs the
   * colours in ascending order, the rows of one colour in parallel (they do not read each
   * other), the backward sweep in descending order. Bitwise independent of the thread
   * count. */
  FCM_MG_SMOOTHER_SGS_COLORED = 2,
  FCM_MG_SMOOTHER_COUNT
} fcm_mg_smoother;

/** The finest level's blocks of the block smoother (fcm_mg_options.block_smoothing); the
 * coarser levels' blocks are the same for all. */
typedef enum fcm_mg_blocks {
  /** The vertex blocks of the cut cells' grid vertices, then the element blocks of the cut
   * cells (default). */
  FCM_MG_BLOCKS_ALL = 0,
  /** The vertex blocks only (on Hex8 3 DOFs a copy of the vertex: the cheapest set). */
  FCM_MG_BLOCKS_VERTEX = 1,
  /** The cut cells' element blocks only. */
  FCM_MG_BLOCKS_ELEMENT = 2,
  FCM_MG_BLOCKS_COUNT
} fcm_mg_blocks;

/** Options of fcm_mg_create(); initialize with fcm_mg_options_default(). */
typedef struct fcm_mg_options {
  fcm_mg_smoother smoother; /**< default FCM_MG_SMOOTHER_SGS */
  double omega;             /**< relaxation: SGS (both orders) in (0, 2), Jacobi in (0, 1];
                                 0 (default): the smoother's own,
                                 fcm_mg_smoother_omega() (1.0 SGS, 0.6 Jacobi), resolved by
                                 fcm_mg_create(), so choosing another smoother alone gives
                                 it its relaxation */
  int pre_smooth;           /**< smoothing steps before the coarse correction, >= 0 (default 1;
                                 one SGS step is a forward and a backward sweep) */
  int post_smooth;          /**< after it, >= 0 (default 1); pre = post keeps the cycle
                                 symmetric (needed as a CG preconditioner) */
  int cycle_index;          /**< coarse-level corrections per level: 1 V-cycle, 2 W-cycle
                                 (default); in [1, 2]. In 3D a W-cycle costs about 4/3 of
                                 the finest level's work against 8/7 for a V-cycle, and it
                                 keeps the iteration counts flat where the V-cycle's factor
                                 grows with n (hollow ball with holes: V 0.28, 0.35, 0.43,
                                 W 0.23, 0.22, 0.17 for n = 8, 16, 32) */
  int max_levels;           /**< levels including the finest, >= 1 (default 20) */
  fcm_index coarse_dofs;    /**< stop coarsening once a level has at most this many DOFs,
                                 >= 1 (default 2000); that level is solved by CHOLMOD */
  int block_smoothing;      /**< 1 (default): smooth blocks of DOFs where cells hold little
                                 material, after the pre-smoothing and before the
                                 post-smoothing (a symmetric block Gauss-Seidel sweep in a
                                 fixed order: the blocks by their first DOF, cut into up to
                                 16 runs whose even and odd runs each share the threads, as
                                 the SGS smoother's ranges; each block inverted by the
                                 clamped eigen-inverse of the Schwarz preconditioner,
                                 fcm/solve.h). Finest level: the
                                 DOFs around each grid vertex of a cut cell (the copies whose
                                 support lies in the vertex's 8 cells: its own and, on Hex20,
                                 the mid-edge nodes' at it; de Prenter et al. 2020), then all
                                 DOFs of each cut element (on an octree a block's hanging
                                 DOFs replaced by their masters); coarser levels: the corner
                                 DOFs of each coarse cell that is not all material, on the
                                 octree levels of a cut space the coarse DOFs each finer
                                 block's rows of the prolongation read. Small cut
                                 fractions and thin walls make such basis functions nearly
                                 linearly dependent, which pointwise smoothing cannot resolve
                                 (the Hex20 V-cycle stalls near 0.95 without it, the hollow
                                 ball's grows with n); 0: pointwise smoothing only */
  fcm_mg_blocks blocks;     /**< the finest level's blocks (default FCM_MG_BLOCKS_ALL) */
  double block_fraction;    /**< the finest level's blocks only at the cut cells one of whose
                                 pieces holds less than this fraction of the cell (the cells
                                 whose basis functions a small support makes nearly dependent;
                                 a piece filling much of its cell is smoothed pointwise well
                                 enough); in (0, 1], default 1: every cut cell */
  int block_sweep;          /**< 0 (default): each block smoothing is a symmetric block
                                 Gauss-Seidel sweep (forward, then backward); 1: one way,
                                 forward before the coarse correction and backward after it
                                 (the cycle stays symmetric, half the block work, a weaker
                                 smoothing) */
  int point_sweep;          /**< 0 (default): each pointwise smoothing step of the "sgs"
                                 smoother is a forward and a backward sweep; 1: one way, a
                                 forward sweep before the coarse correction and a backward
                                 one after it (the cycle stays symmetric with equal pre- and
                                 post-smoothing steps; half the pointwise work) */
  int coarse_interval;      /**< 1 (default): fcm_mg_setup() computes every level's values;
                                 k > 1: the coarser levels' (Galerkin products, their block
                                 smoothers, the coarsest factorization) at every k-th set-up
                                 of a hierarchy only (its first included: fcm_mg_create()
                                 with values counts as the first, so with k = 2 the next
                                 fcm_mg_setup() keeps the coarser levels), the finest level's
                                 diagonal and block smoother at each: the coarse correction
                                 then uses operators of up to k - 1 set-ups before (a
                                 corotated matrix's rotations of a few steps), for the
                                 products' cost */
} fcm_mg_options;

/** Defaults as documented on each member. */
FCM_API fcm_mg_options fcm_mg_options_default(void);

/** The default relaxation omega of a smoother: 1.0 for symmetric Gauss-Seidel (both orders),
 * 0.6 for damped Jacobi, which over-corrects the high-frequency modes of elasticity near 1
 * (the V-cycle diverges from omega = 0.7 on a box grid: lib/docs/multigrid.md): what
 * fcm_mg_options.omega = 0 (the default) stands for; 1.0 for a value outside fcm_mg_smoother. */
FCM_API double fcm_mg_smoother_omega(fcm_mg_smoother smoother);

/** A multigrid hierarchy and its operators for one matrix pattern. */
typedef struct fcm_mg fcm_mg;

/** Build the hierarchy of `space` and the operators of `A`. The space must live on a structured
 * Hex8 or Hex20 box grid (fcm_mesh_create_box(): every cell an axis-aligned box of one size at an
 * integer grid position) or an octree over one (below); any cell counts, dropped cells and cut
 * (XFEM) pieces are allowed. Level 0 is the space itself: its elements (pieces) and DOF copies. On
 * Hex20, level 1 is the Hex8 space of the same elements with the copies they use at their corners:
 * those copies are injected, a mid-edge copy takes the mean of the corner copies at the ends of its
 * edge (exact for trilinear fields); the 2x2x2 coarsening below starts from level 1. Two elements
 * of face-neighbouring cells are connected when they use the same copy at a node of the common face
 * and, where cuts reach either cell, the cell rules link their pieces (fcm_cell_rules_links());
 * coarse cells are the connected components of the elements (cells) of each 2x2x2 block, and coarse
 * cells are connected when some of their fine cells are. A coarse cell has its own copy at each of
 * its 8 corners; two coarse cells share a corner's copy when a fine copy that interpolates from
 * that corner is used by fine elements of both, so the coarse space separates exactly what the fine
 * one separates (two bodies never share a coarse DOF) and the prolongation is single valued. Rows
 * of A whose off-diagonal entries are all zero (DOFs eliminated by fcm_space_apply_dirichlet())
 * mark the Dirichlet boundary: a coarse DOF whose coinciding fine DOFs are all eliminated (or,
 * coarser, constrained) is constrained (decoupled in the coarse matrix, no correction from it), so
 * coarse corrections vanish there. The prolongation stays injective, so every coarse matrix is
 * positive definite.
 *
 * Octree backgrounds (fcm_mesh_create_octree(), Hex8 or Hex20, with hanging nodes; one DOF copy
 * per node: no cuts): A must be the constrained operator the integrators solve, P^T K P + I_h
 * (P the square hanging-node matrix of fcm_space_hanging_matrix_create() written on all DOFs,
 * I_h the identity on the hanging DOFs, lib/docs/octree.md), its hanging rows decoupled
 * identity rows. Level 1 is the octree without its deepest level (every family of 8 finest
 * leaves replaced by its parent), its cells active where an active cell of level 0 lies, its
 * hanging nodes constrained alike, and so on until the octree is a uniform grid, whose
 * hierarchy then continues as above. Between octree levels the prolongation is the exact
 * nested interpolation: each fine free DOF takes the coarse conforming field at its node; fine
 * hanging DOFs get no correction, coarse hanging DOFs are inactive. Separate bodies are kept
 * apart on the grid levels only: an octree level has one DOF per node, so bodies closer than its
 * cells share its DOFs (converges, more slowly: lib/docs/octree.md).
 * @param[in]  ctx   context; must outlive the object
 * @param[in]  space borrowed: must outlive the object
 * @param[in]  A     symmetric positive definite, the space's pattern (fcm_space_matrix_create();
 *                   on an octree that of fcm_csr_create_ptap());
 *                   borrowed: must outlive the object, values read by this call and by
 *                   fcm_mg_setup(), applied in every cycle
 * @param[in]  opts  copied (omega 0: fcm_mg_smoother_omega() of the smoother); NULL for
 *                   defaults
 * @param[out] mg    the new object, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL, option out of range, A not the space's size; on an octree:
 * a hanging DOF's row coupled, i.e. A is not the constrained operator),
 * FCM_ERR_UNSUPPORTED (not a Hex8 or Hex20 box grid or octree: the message names the cell; an
 * octree space with several DOF copies at a node),
 * FCM_ERR_SINGULAR or FCM_ERR_NUMERIC (the coarsest factorization, a zero diagonal),
 * FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_mg_create(fcm_ctx *ctx, const fcm_space *space, const fcm_csr *A,
                                 const fcm_mg_options *opts, fcm_mg **mg);

/** New values of the same A (same pattern, same eliminated rows): recompute the finest
 * level's smoothers and, at the set-ups fcm_mg_options.coarse_interval selects (every one by
 * default; always when the hierarchy has a single level), the Galerkin matrices, the coarser
 * smoothers and the coarsest factorization. After a failed set-up the levels may hold old and
 * new values mixed: fcm_mg_cycle() and fcm_mg_solve() refuse (FCM_ERR_ARG) until a set-up
 * succeeds, and that one recomputes every level. @return FCM_OK, FCM_ERR_ARG (NULL, other
 * size, a different set of eliminated rows), FCM_ERR_NUMERIC (a diagonal entry not positive
 * and finite), the smoothers' and the factorization's errors. No allocation but CHOLMOD's. */
FCM_API fcm_status fcm_mg_setup(fcm_mg *mg);

/** Destroy; accepts NULL and `*mg == NULL`, sets `*mg = NULL`. */
FCM_API void fcm_mg_destroy(fcm_mg **mg);

/** One cycle for A x = b from the guess in x (updated in place); b and x have num_dofs
 * entries and must not overlap. @return FCM_OK, FCM_ERR_ARG, the coarsest solve's errors.
 * No allocation (CHOLMOD's first solve allocates its workspace). Not thread safe on one
 * object; bitwise independent of the thread count. */
FCM_API fcm_status fcm_mg_cycle(fcm_mg *mg, const double *b, double *x);

/** Preconditioner callback (fcm_operator_fn of fcm/solve.h): z = one cycle from z = 0 for
 * the right-hand side r; `user` is an fcm_mg. Symmetric positive definite when pre_smooth =
 * post_smooth, so fit for fcm_krylov_cg(). */
FCM_API fcm_status fcm_mg_operator(void *user, const double *r, double *z);

/** What fcm_mg_solve() did. */
typedef struct fcm_mg_solve_info {
  int cycles;                /**< cycles performed */
  int converged;             /**< 1 when ||b - A x|| <= rtol ||b|| */
  double relative_residual;  /**< ||b - A x||_2 / ||b||_2 at exit (0 when b = 0) */
  double convergence_factor; /**< (r_k / r_1)^(1/(k-1)): the mean residual reduction per cycle
                                  after the first (the first, from an arbitrary guess, is
                                  not typical); 0 with fewer than 2 cycles */
} fcm_mg_solve_info;

/** Cycles from the guess in x until ||b - A x||_2 <= rtol ||b||_2 or max_cycles.
 * @return FCM_OK (converged), FCM_ERR_NOT_CONVERGED, FCM_ERR_NUMERIC (NaN residual),
 * FCM_ERR_ARG (NULL, rtol < 0, max_cycles < 0). info may be NULL. */
FCM_API fcm_status fcm_mg_solve(fcm_mg *mg, const double *b, double *x, double rtol, int max_cycles,
                                fcm_mg_solve_info *info);

/** Number of levels (1: the finest is solved directly). */
FCM_API int fcm_mg_num_levels(const fcm_mg *mg);

/** Sizes of one level (0 finest). */
typedef struct fcm_mg_level_info {
  fcm_index cells;   /**< elements (level 0) or coarse cells */
  fcm_index copies;  /**< node copies (3 DOFs each before dropping) */
  fcm_index dofs;    /**< rows of the level matrix */
  fcm_index nnz;     /**< stored entries of the level matrix */
  fcm_index bodies;  /**< connected components of the cells, two cells being connected when
                          they share a copy */
  fcm_index grid[3]; /**< cells per axis of the level's grid */
  int colors;        /**< colours of the rows (FCM_MG_SMOOTHER_SGS_COLORED; 0 otherwise and
                          on the coarsest level) */
} fcm_mg_level_info;

/** Sizes of `level`. @return FCM_OK, FCM_ERR_ARG (NULL, level out of range), FCM_ERR_ALLOC
 * (scratch for the bodies). */
FCM_API fcm_status fcm_mg_get_level_info(const fcm_mg *mg, int level, fcm_mg_level_info *info);

#ifdef __cplusplus
}
#endif
#endif /* FCM_MG_H */
