/* mg module (internal): the hierarchy's prolongations without a matrix, for other solvers'
 * multigrid (lib/src/petsc/pcmg.c). */
#ifndef FCM_MG_IMPL_H
#define FCM_MG_IMPL_H

#include "core/core_impl.h"
#include "fcm/mg.h"

/* The prolongations of the hierarchy fcm_mg_create() builds, without a matrix. Level 0 is the
 * space (its DOF numbering); level l + 1 is coarser; P[l] is n[l] x n[l + 1], rows sorted by
 * column, the weights fcm_mg_create() prolongates with. inactive[l] (n[l] bytes) marks the
 * Dirichlet DOFs of each level: level 0 the constrained ones given, coarser ones as
 * fcm_mg_create() derives them (every coinciding finer DOF inactive, or no finer DOF
 * interpolating from it); P keeps their rows and columns (it is injective). */
typedef struct fcm__mg_transfers {
  int num_levels;    /* >= 1 */
  fcm_index *n;      /* num_levels: DOFs (rows) of each level */
  fcm_index **P_ptr; /* num_levels - 1 CSR prolongations */
  int **P_col;
  double **P_val;
  unsigned char **inactive; /* num_levels */
  /* the blocks of fcm_mg_options.block_smoothing on levels 0 .. num_levels - 2, in the level's
   * numbering (level 0: vertex blocks and the DOFs of each cut element; coarser: the corner
   * DOFs of each coarse cell that is not all material); CSR over blocks, they may overlap */
  fcm_index *num_blocks;
  fcm_index **block_ptr;
  fcm_index **block_dofs;
} fcm__mg_transfers;

/* The transfers of `space` (a Hex8 or Hex20 box grid, as fcm_mg_create() needs) with the
 * constrained DOFs `constrained` (fcm_space_num_dofs() bytes, nonzero: constrained; NULL:
 * none); max_levels and coarse_dofs as in fcm_mg_options (validated). The levels, copies and
 * prolongations are those fcm_mg_create() builds (the same code) for a matrix whose eliminated
 * rows are the constrained ones. @return FCM_OK, FCM_ERR_ARG, FCM_ERR_UNSUPPORTED (not a box
 * grid: named), FCM_ERR_ALLOC. */
FCM_COMPONENT_API fcm_status fcm__mg_transfers_create(fcm_ctx *ctx, const fcm_space *space,
                                                      const unsigned char *constrained,
                                                      int max_levels, fcm_index coarse_dofs,
                                                      fcm__mg_transfers **out);

/* Destroy; accepts NULL and *t == NULL, sets *t = NULL. */
FCM_COMPONENT_API void fcm__mg_transfers_destroy(fcm_ctx *ctx, fcm__mg_transfers **t);

/* The slab orders of the smoothers of `mg` (FCM_MG_SMOOTHER_SGS's rows, the block smoother's
 * blocks; fcm/mg.h) on `level` (< the number of levels - 1): the number of slabs (0 where the
 * level has none) and whether the order is sound: every item once, and no two slabs of the
 * same colour holding adjacent items (rows coupled in the level matrix's pattern; blocks one of
 * which has a DOF coupled with, or equal to, a DOF of the other), so that their sweeps may run
 * at once. @return FCM_OK, FCM_ERR_ARG (NULL, level out of range), FCM_ERR_INTERNAL (the order
 * is not sound: names the level, the items and the slabs), FCM_ERR_ALLOC. */
fcm_status fcm__mg_slabs_check(const fcm_mg *mg, int level, fcm_index *row_slabs,
                               fcm_index *block_slabs);

/* Test hook: on `level` (< the number of levels - 1, SGS smoother, after a setup), one SGS step
 * and then, where the level has blocks, one forward block sweep from x in one thread, by the
 * sweeps the cycle runs (x_fast: a copy's three rows of one pattern summed together, S_K's
 * lower triangle, or X^T X r where the block holds its factor's inverse X) and by the
 * reference (x_plain: one row at a time, the full S_K, formed from X where it holds X);
 * *triples: the copies whose three rows are summed together; *factor_blocks: the blocks
 * holding X (fcm__schwarz_block_factor()). The two agree to rounding.
 * @return FCM_OK, FCM_ERR_ARG (NULL, level out of range, another smoother). */
fcm_status fcm__mg_smooth_paths(fcm_mg *mg, int level, const double *b, const double *x,
                                double *x_fast, double *x_plain, fcm_index *triples,
                                fcm_index *factor_blocks);
/* Test hook: dx = S r for one block's slot (S: m (m + 1) / 2 doubles, a lower triangle packed
 * by rows; factor: S holds X with S_K = X^T X, else S_K's triangle) by the block sweeps'
 * product (dx_fast; r is overwritten) and by the reference (dx_plain, each entry formed). */
void fcm__mg_block_apply_paths(const double *S, int m, int factor, double *r, double *dx_fast,
                               double *dx_plain);

/* r = b - A x with level 0's matrix A, the threads of the hierarchy's team: each row's sum
 * in fcm_csr_apply()'s order, so r equals b + fcm_csr_apply(A, -1, x, 0, .) bit for bit. */
FCM_COMPONENT_API void fcm__mg_residual(const fcm_mg *m, const double *b, const double *x,
                                        double *r);

/* What fcm__mg_create_from() took from the earlier hierarchy (zero for fcm_mg_create()). */
typedef struct fcm__mg_kept {
  int plans;           /* levels whose Galerkin plan, coarse pattern and positions were kept */
  int row_orders;      /* levels whose SGS row slabs were kept */
  int block_smoothers; /* levels whose block smoother and block slabs were kept */
  int analysis;        /* 1: the coarsest level's symbolic analysis was kept */
  /* fcm__mg_create_pattern_cut(): the levels whose Galerkin plan took rows from the hierarchy
   * before the cut, and the rows of A P and of the coarse patterns taken, all levels */
  int carried_plans;
  fcm_index carried_ap_rows, carried_coarse_rows;
  fcm_index carried_blocks; /* blocks whose positions were copied, all levels */
  int carried_ordering;     /* 1: the coarsest analysis took the old one's ordering (the
                               coarsest pattern the old one's) */
} fcm__mg_kept;

/* fcm_mg_create(ctx, space, A, opts, mg), taking from *old (NULL or *old == NULL: nothing)
 * the parts whose inputs are unchanged: the result, and every level's data, are those of
 * fcm_mg_create() bit for bit (lib/src/mg/update.c lists the parts and what each is compared
 * on). Reads only the arrays *old owns, and its level-0 matrix unless detached
 * (fcm__mg_detach()): that matrix must then still be alive, its pattern unchanged. *old is
 * destroyed (*old = NULL) whatever the result; a level of *old found not to be taken is freed
 * as soon as that is known, before the new level's arrays are allocated. Octree hierarchies, and
 * options or thread counts other than old's, keep nothing. @return as fcm_mg_create(). */
FCM_COMPONENT_API fcm_status fcm__mg_create_from(fcm_ctx *ctx, fcm_mg **old, const fcm_space *space,
                                                 const fcm_csr *A, const fcm_mg_options *opts,
                                                 fcm_mg **mg);

/* fcm__mg_create_from() on A's pattern alone, before its values exist: every structure of the
 * creation (cells, copies, prolongations, Galerkin plans and coarse patterns, row orders, block
 * smoothers' blocks and slabs, the coarsest symbolic analysis) with `inactive` (one entry per
 * row: 1 for a row the matrix will have eliminated, no off-diagonal value) as level 0's
 * Dirichlet rows; no value of A is read. fcm_mg_setup() with A's values must follow before
 * anything else: it sets up the block smoothers (their first set-up), the Galerkin values and
 * the coarsest factor, and the hierarchy is then fcm_mg_create()'s on A bit for bit; when A's
 * eliminated rows are not `inactive` it returns FCM_ERR_ARG (create it again). *old as
 * fcm__mg_create_from(). @return as fcm_mg_create(); FCM_ERR_UNSUPPORTED on an octree mesh. */
FCM_COMPONENT_API fcm_status fcm__mg_create_pattern(fcm_ctx *ctx, fcm_mg **old,
                                                    const fcm_space *space, const fcm_csr *A,
                                                    const unsigned char *inactive,
                                                    const fcm_mg_options *opts, fcm_mg **mg);

/* fcm__mg_create_pattern() (no old hierarchy to consume) for the space `space` made by a cut
 * of `old_space`, taking rows of the Galerkin plans from `old`, the hierarchy of old_space
 * (NULL: none), which is only read and stays usable. Rows are taken only when old's level-0
 * matrix had old_space's pattern at old's creation and A has space's (row_ptr and col_idx
 * those of the space: fcm_space_matrix_create()), both grid hierarchies, and space is a
 * cut of old_space (full spaces); otherwise nothing is taken and the result is the plain
 * creation, without an error. old's level-0 matrix may be gone, old_space must live. The
 * result is fcm__mg_create_pattern()'s bit for bit (lib/src/mg/carry.c: what is taken and
 * how it is checked); fcm__mg_get_kept() counts what was taken. @return as
 * fcm__mg_create_pattern(). */
FCM_COMPONENT_API fcm_status fcm__mg_create_pattern_cut(fcm_ctx *ctx, const fcm_mg *old,
                                                        const fcm_space *old_space,
                                                        const fcm_space *space, const fcm_csr *A,
                                                        const unsigned char *inactive,
                                                        const fcm_mg_options *opts, fcm_mg **mg);

/* fcm__mg_create_pattern_cut() inside a parallel region whose barrier comes before m is used
 * (scene/run.c cut_parts()): level 0's smoothing order and block smoother are made by a task
 * that any thread of the team may run, and may still be pending when this returns FCM_OK, so
 * that the calling thread goes on with other work. Until fcm__mg_join(), after the team's
 * barrier, m must not be used (fcm_mg_destroy() only by the thread that created m, whose
 * taskwait waits for the task, or after the barrier), and old, old_space, space and A's
 * pattern must live. Outside an active parallel region the task runs at once. The
 * result after fcm__mg_join() is fcm__mg_create_pattern_cut()'s bit for bit. */
FCM_COMPONENT_API fcm_status fcm__mg_create_pattern_cut_beside(
    fcm_ctx *ctx, const fcm_mg *old, const fcm_space *old_space, const fcm_space *space,
    const fcm_csr *A, const unsigned char *inactive, const fcm_mg_options *opts, fcm_mg **mg);

/* Complete the creation of m (fcm__mg_create_pattern_cut_beside()) once the task making level
 * 0's smoothers has run (after the team's barrier): its error (FCM_ERR_ALLOC, FCM_ERR_INTERNAL,
 * with its message), or FCM_OK with m ready for fcm_mg_setup(); after an error m must be
 * destroyed. *seconds (may be NULL): the task's wall time (0 when nothing was pending).
 * Accepts NULL and a complete m (FCM_OK, nothing done). */
FCM_COMPONENT_API fcm_status fcm__mg_join(fcm_mg *m, double *seconds);

/* Forget the level-0 matrix and the space of m (they may be destroyed now): m stays usable
 * only as the `old` of fcm__mg_create_from(), which then keeps nothing of level 0 itself
 * (its plan needs level 0's pattern). Accepts NULL. */
FCM_COMPONENT_API void fcm__mg_detach(fcm_mg *m);

/* m, created on a pattern and not yet set up (fcm__mg_create_pattern_cut() and the like),
 * takes the storage of old's Galerkin products where it holds m's, level by level: the
 * products' scratch (A P) and the coarse matrices' values (fcm__ptap_take_scratch(),
 * fcm__csr_take_values()). m's first set-up then writes into pages already mapped instead of
 * faulting fresh ones in; its results are the same. old (a hierarchy that nothing shares with
 * m, about to be destroyed) can only be destroyed afterwards. Returns the arrays taken (0 for
 * NULL arguments, or when m is set up already). */
FCM_COMPONENT_API int fcm__mg_take_scratch(fcm_mg *m, fcm_mg *old);

/* What m's creation kept (all zero for NULL). */
FCM_COMPONENT_API void fcm__mg_get_kept(const fcm_mg *m, fcm__mg_kept *kept);

#endif /* FCM_MG_IMPL_H */
