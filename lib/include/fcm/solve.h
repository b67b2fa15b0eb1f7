/* fcm — iterative solvers: matrix-free preconditioned CG and MINRES (operator and
 * preconditioner given as callbacks), Jacobi and additive Schwarz preconditioners. */
#ifndef FCM_SOLVE_H
#define FCM_SOLVE_H

#include "fcm/core.h"
#include "fcm/la.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ operators */

/** A linear operator y = A x (or a preconditioner z = S r) of size n, SUNDIALS
 * style: `user` is the caller's state, x and y never overlap. Return FCM_OK or an
 * error status (recorded in the caller's ctx); the solver stops and propagates it. */
typedef fcm_status (*fcm_operator_fn)(void *user, const double *x, double *y);

/** Operator adapter for a square CSR matrix: y = A x with `user` an `fcm_csr *`
 * (fcm_csr_apply with alpha 1, beta 0). No allocation; result independent of the
 * thread count. @return as fcm_csr_apply(). */
FCM_API fcm_status fcm_csr_operator(void *user, const double *x, double *y);

/* ------------------------------------------------------------- Krylov solvers */

/** Why a Krylov solve stopped. */
typedef enum fcm_krylov_reason {
  FCM_KRYLOV_NONE = 0,                  /**< no solve has finished */
  FCM_KRYLOV_CONVERGED_RTOL,            /**< ||r|| <= rtol ||b|| (monitored norm) */
  FCM_KRYLOV_CONVERGED_ATOL,            /**< ||r|| <= atol (b = 0 included: x = 0) */
  FCM_KRYLOV_MAX_ITERATIONS,            /**< max_iterations reached */
  FCM_KRYLOV_BREAKDOWN,                 /**< CG: p^T A p <= 0 (A not positive definite); MINRES:
                                             singular Lanczos tridiagonal (gamma = 0) */
  FCM_KRYLOV_INDEFINITE_PRECONDITIONER, /**< r^T S r < 0, or = 0 for r != 0 */
  FCM_KRYLOV_NAN,                       /**< NaN or Inf in b, x0 or an iteration scalar */
  FCM_KRYLOV_CALLBACK_ERROR,            /**< the operator or preconditioner returned an error */
  FCM_KRYLOV_STAGNATED /**< the smallest monitored residual dropped by less than 0.1 % over
                            stagnation_window iterations: a singular (or nearly singular)
                            operator whose range b leaves, e.g. a semi-definite stiffness
                            with free rigid-body modes under a load they feel */
} fcm_krylov_reason;

/** Name of a reason ("converged-rtol", "max-iterations", "stagnated", ...), or "unknown". */
FCM_API const char *fcm_krylov_reason_name(fcm_krylov_reason reason);

/** Which residual norm the stopping test and the history use. */
typedef enum fcm_krylov_norm {
  FCM_KRYLOV_NORM_DEFAULT = 0,      /**< CG: unpreconditioned; MINRES: preconditioned */
  FCM_KRYLOV_NORM_UNPRECONDITIONED, /**< ||r||_2 (MINRES: only without preconditioner) */
  FCM_KRYLOV_NORM_PRECONDITIONED    /**< ||r||_S = sqrt(r^T S r) */
} fcm_krylov_norm;

/** Options of the Krylov solvers; initialize with fcm_krylov_options_default(). The
 * iteration stops when ||r_k|| <= max(rtol ||b||, atol), both in the monitored norm. */
typedef struct fcm_krylov_options {
  double rtol;             /**< relative tolerance >= 0 (default 1e-8) */
  double atol;             /**< absolute tolerance >= 0 (default 0) */
  int max_iterations;      /**< >= 0 (default 1000) */
  int stagnation_window;   /**< W >= 0 (default 0: off): every W iterations the smallest
                                monitored residual so far must have dropped by 0.1 % since
                                the previous such check, else the solve stops with
                                FCM_KRYLOV_STAGNATED (x is the last iterate) */
  fcm_krylov_norm norm;    /**< monitored norm (default FCM_KRYLOV_NORM_DEFAULT) */
  int check_true_residual; /**< nonzero: at exit compute ||b - A x||_2 / ||b||_2 into
                                info.true_residual (one more operator application) */
  int record_history;      /**< nonzero: record the relative monitored norm per iteration */
  double *history;         /**< caller buffer of history_capacity entries, or NULL: the
                                workspace's own buffer (grown to max_iterations) */
  int history_capacity;    /**< entries of `history`; recording stops when it is full */
} fcm_krylov_options;

/** Defaults: rtol 1e-8, atol 0, 1000 iterations, no stagnation test, default norm, no
 * true-residual check, no history. */
FCM_API fcm_krylov_options fcm_krylov_options_default(void);

/** What a Krylov solve did. Norms are in the monitored norm unless stated. */
typedef struct fcm_krylov_info {
  fcm_krylov_reason reason;
  int iterations;           /**< iterations performed (operator applications in the loop) */
  double rhs_norm;          /**< ||b|| */
  double residual_norm;     /**< final ||r|| (recurrence, not recomputed) */
  double relative_residual; /**< residual_norm / rhs_norm (0 when b = 0) */
  double initial_residual;  /**< ||b - A x0|| / ||b|| */
  double true_residual;  /**< ||b - A x||_2 / ||b||_2 at exit with check_true_residual, else -1 */
  const double *history; /**< history[k] = relative norm after iteration k+1, or NULL;
                              owned by the caller's buffer or the workspace (valid until
                              its next solve or destruction) */
  int history_length;    /**< entries in history: min(iterations, capacity) */
  long long operator_applications;       /**< calls of the operator */
  long long preconditioner_applications; /**< calls of the preconditioner */
  double time;                           /**< wall-clock seconds of the solve */
} fcm_krylov_info;

/** Workspace of the Krylov solvers for systems of one size: the vectors of CG and
 * MINRES and the history buffer. Create once, solve many times. */
typedef struct fcm_krylov fcm_krylov;

/** Create a workspace for systems of size n.
 * @param[in]  ctx context; must outlive the workspace
 * @param[in]  n   system size >= 0
 * @param[out] ws  the new workspace, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (n < 0, NULL), FCM_ERR_ALLOC. Allocates 7 n doubles. */
FCM_API fcm_status fcm_krylov_create(fcm_ctx *ctx, fcm_index n, fcm_krylov **ws);

/** Destroy a workspace (and its history); accepts NULL and `*ws == NULL`, sets `*ws = NULL`. */
FCM_API void fcm_krylov_destroy(fcm_krylov **ws);

/** Preconditioned conjugate gradients for A x = b, A and S symmetric positive definite.
 * @param[in]     ws     workspace of size n (not thread safe: one solve at a time)
 * @param[in]     A, A_user operator y = A x
 * @param[in]     S, S_user preconditioner z = S r, or S == NULL for the identity
 * @param[in]     b      right-hand side (n)
 * @param[in,out] x      initial guess in (an all-zero x saves one operator application),
 *                       last iterate out (also on failure)
 * @param[in]     opts   options, NULL for defaults
 * @param[out]    info   what happened, may be NULL
 * @return FCM_OK (converged), FCM_ERR_NOT_CONVERGED (max iterations, breakdown, indefinite
 * preconditioner, stagnation: see info->reason; on a positive semi-definite A with b outside
 * its range CG's residual stalls and then grows while x grows without bound, ending in a
 * breakdown unless the stagnation test stops it first), FCM_ERR_NUMERIC (NaN/Inf),
 * FCM_ERR_ARG, FCM_ERR_ALLOC
 * (growing the workspace history only), or the status a callback returned.
 * Vector operations use OpenMP; dot products are summed in a fixed order, so the result
 * is bitwise independent of the thread count for deterministic callbacks. */
FCM_API fcm_status fcm_krylov_cg(fcm_krylov *ws, fcm_operator_fn A, void *A_user, fcm_operator_fn S,
                                 void *S_user, const double *b, double *x,
                                 const fcm_krylov_options *opts, fcm_krylov_info *info);

/** MINRES (Paige and Saunders 1975) for symmetric, possibly indefinite A with a symmetric
 * positive definite preconditioner S: minimizes ||b - A x||_S over the Krylov space, and
 * monitors that preconditioned norm (its history is non-increasing). Parameters, status
 * codes and threading as fcm_krylov_cg(); FCM_KRYLOV_NORM_UNPRECONDITIONED is accepted
 * only with S == NULL. An indefinite S is detected (r^T S r < 0) and reported. */
FCM_API fcm_status fcm_krylov_minres(fcm_krylov *ws, fcm_operator_fn A, void *A_user,
                                     fcm_operator_fn S, void *S_user, const double *b, double *x,
                                     const fcm_krylov_options *opts, fcm_krylov_info *info);

/** One-shot CG: creates a workspace of size n, solves, destroys it. History only into a
 * caller buffer (opts->history; FCM_ERR_ARG otherwise); info->history points into it.
 * Otherwise as fcm_krylov_cg(). Allocates 7 n doubles. */
FCM_API fcm_status fcm_cg_solve(fcm_ctx *ctx, fcm_index n, fcm_operator_fn A, void *A_user,
                                fcm_operator_fn S, void *S_user, const double *b, double *x,
                                const fcm_krylov_options *opts, fcm_krylov_info *info);

/** One-shot MINRES; as fcm_cg_solve() for fcm_krylov_minres(). */
FCM_API fcm_status fcm_minres_solve(fcm_ctx *ctx, fcm_index n, fcm_operator_fn A, void *A_user,
                                    fcm_operator_fn S, void *S_user, const double *b, double *x,
                                    const fcm_krylov_options *opts, fcm_krylov_info *info);

/* ------------------------------------------------------------------- Jacobi */

/** Jacobi variants. */
typedef enum fcm_jacobi_kind {
  FCM_JACOBI_SCALAR = 0, /**< z_i = r_i / |a_ii| */
  FCM_JACOBI_BLOCK3 = 1  /**< inverse of each nodal 3x3 diagonal block (rows 3k..3k+2) */
} fcm_jacobi_kind;

/** Diagonal (or 3x3 block-diagonal) preconditioner, symmetric positive definite by
 * construction: a negative diagonal entry is used with its absolute value, and a 3x3
 * block that is not positive definite (Cholesky pivot <= 1e-12 of its largest diagonal)
 * falls back to the inverse of its |diagonal|; both count as fallbacks. */
typedef struct fcm_jacobi fcm_jacobi;

/** Create and set up from the diagonal (blocks) of the square matrix A.
 * @param[in]  ctx  context; must outlive P
 * @param[in]  A    square matrix, read during the call only; FCM_JACOBI_BLOCK3 needs
 *                  nrows divisible by 3
 * @param[in]  kind FCM_JACOBI_SCALAR or FCM_JACOBI_BLOCK3
 * @param[out] P    the new preconditioner, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG, FCM_ERR_SINGULAR (zero diagonal entry: the message names
 * the row), FCM_ERR_NUMERIC (NaN/Inf on the diagonal), FCM_ERR_ALLOC. Allocates O(n). */
FCM_API fcm_status fcm_jacobi_create(fcm_ctx *ctx, const fcm_csr *A, fcm_jacobi_kind kind,
                                     fcm_jacobi **P);

/** Recompute from new values of a matrix of the same size (no allocation).
 * @return as fcm_jacobi_create(); on failure P keeps no valid data until the next setup. */
FCM_API fcm_status fcm_jacobi_setup(fcm_jacobi *P, const fcm_csr *A);

/** z = S r (r and z of n entries, must not overlap). No allocation; parallel over rows,
 * bitwise independent of the thread count. @return FCM_OK, FCM_ERR_ARG (NULL, not set up). */
FCM_API fcm_status fcm_jacobi_apply(const fcm_jacobi *P, const double *r, double *z);

/** fcm_jacobi_apply() as an fcm_operator_fn; `user` is an `fcm_jacobi *`. */
FCM_API fcm_status fcm_jacobi_operator(void *user, const double *r, double *z);

/** Number of fallbacks of the last setup (negative diagonals, or non-SPD 3x3 blocks). */
FCM_API fcm_index fcm_jacobi_num_fallbacks(const fcm_jacobi *P);

/** Destroy; accepts NULL and `*P == NULL`, sets `*P = NULL`. */
FCM_API void fcm_jacobi_destroy(fcm_jacobi **P);

/* --------------------------------------------------------- additive Schwarz */

/** How eigenvalues below eps * lambda_max of a block are inverted (Longva et al. 2020, §5.2,
 * eq. 14; lambda_max = max_k |lambda_k| of the block). In both, |lambda_k| >= eps lambda_max
 * becomes 1/|lambda_k| (negative eigenvalues are reflected, so S_K is SPD). */
typedef enum fcm_schwarz_clamp {
  FCM_SCHWARZ_CLAMP = 0, /**< 1/(eps lambda_max): |lambda| clamped from below, then inverted
                              (the authors' code; default) */
  FCM_SCHWARZ_PAPER = 1  /**< eps/lambda_max, as eq. 14 is printed */
} fcm_schwarz_clamp;

/** Options of the Schwarz preconditioner; initialize with fcm_schwarz_options_default(). */
typedef struct fcm_schwarz_options {
  double epsilon;          /**< relative eigenvalue threshold in (0, 1) (default 1e-13) */
  fcm_schwarz_clamp clamp; /**< default FCM_SCHWARZ_CLAMP */
} fcm_schwarz_options;

/** Defaults: epsilon 1e-13, FCM_SCHWARZ_CLAMP. */
FCM_API fcm_schwarz_options fcm_schwarz_options_default(void);

/** Statistics of the last setup. */
typedef struct fcm_schwarz_info {
  fcm_index num_blocks;           /**< blocks K */
  fcm_index block_dofs;           /**< sum of the block sizes */
  int max_block_size;             /**< largest block */
  int num_colors;                 /**< colours of a greedy colouring of the block graph (blocks of a
                                       colour share no DOF; a statistic, the apply does not use it) */
  fcm_index outside_dofs;         /**< DOFs in no block (Jacobi) */
  fcm_index negative_eigenvalues; /**< reflected eigenvalues lambda < 0 (over all blocks) */
  fcm_index clamped_eigenvalues;  /**< eigenvalues with |lambda| < eps lambda_max */
  fcm_index jacobi_fallbacks;     /**< outside DOFs with a negative diagonal (|a_ii| used) */
  double setup_time;              /**< seconds of the last setup */
} fcm_schwarz_info;

/** Additive Schwarz preconditioner S = sum_K R_K^T S_K R_K + D^{-1} (Longva et al. 2020,
 * §5.2): S_K is the reflected, clamped pseudo-inverse of the dense block C_K = R_K C R_K^T
 * of the system matrix C on the DOFs of block K; D^{-1} the inverse |diagonal| on the DOFs
 * outside all blocks. Stored as dense S_K, applied matrix-free. C need not be the matrix
 * the Krylov method solves with: for an indefinite system A (the exact tangent of a large
 * deformation), building S from a positive definite C close to A (the PSD-projected tangent:
 * fcm_integrator_options.preconditioner_tangent in fcm/sim.h) gives well-conditioned blocks
 * where the blocks of A itself are indefinite or nearly singular. */
typedef struct fcm_schwarz fcm_schwarz;

/** Create from the square matrix C and a list of blocks, and set up (fcm_schwarz_setup()).
 * Block k holds the DOFs block_dofs[block_ptr[k] .. block_ptr[k+1]) (distinct, in [0, n),
 * any order); blocks may overlap.
 * @param[in]  ctx        context; must outlive P
 * @param[in]  C          square matrix (values read during the call only)
 * @param[in]  num_blocks >= 0; @param[in] block_ptr num_blocks+1 offsets; @param[in]
 *                        block_dofs the DOF lists (both copied)
 * @param[in]  opts       options, NULL for defaults
 * @param[out] P          the new preconditioner, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (bad block: the message names it and the DOF), and the
 * codes of fcm_schwarz_setup(). Allocates the blocks (sum of squared sizes), O(n), and the
 * setup scratch of omp_get_max_threads() threads (a largest block, its eigenvalues and
 * dsyevd workspace, n ints of the gather each), so that fcm_schwarz_setup() allocates nothing.
 * Blocks of cells of a finite element space: fcm_space_cell_blocks() (fcm/fem.h). Thread
 * safe. */
FCM_API fcm_status fcm_schwarz_create(fcm_ctx *ctx, const fcm_csr *C, fcm_index num_blocks,
                                      const fcm_index *block_ptr, const fcm_index *block_dofs,
                                      const fcm_schwarz_options *opts, fcm_schwarz **P);

/** Recompute the blocks and the diagonal from new values of C (same size): dense block
 * gather, symmetric eigendecomposition (LAPACK dsyevd, lower triangle), eigenvalue
 * reflection and clamping, S_K = V diag(s) V^T; a block that is positive definite with
 * eps ||C_K||_F ||C_K^{-1}||_F <= 1e-3 (no eigenvalue near the clamp) is C_K^{-1} through its
 * Cholesky factor instead, the same matrix to rounding of order cond(C_K) times the unit
 * round-off. Parallel over blocks (OpenMP, at most the thread count of the creation); each
 * block is computed by one thread, so the result does not depend on the thread count.
 * @return FCM_OK, FCM_ERR_ARG (size mismatch), FCM_ERR_SINGULAR (a zero block or a zero
 * diagonal outside the blocks: named), FCM_ERR_NUMERIC (NaN/Inf in a block's lower triangle,
 * the part either inverse reads, or on the diagonal: named), FCM_ERR_LAPACK. No allocation
 * (scratch from fcm_schwarz_create()). */
FCM_API fcm_status fcm_schwarz_setup(fcm_schwarz *P, const fcm_csr *C);

/** z = S r (n entries each, must not overlap). No allocation. One parallel loop over the
 * DOFs (no barrier inside): each z_i is summed by one thread from its diagonal term and
 * the rows of the blocks holding DOF i in ascending block order, so z is bitwise
 * independent of the thread count.
 * @return FCM_OK, FCM_ERR_ARG (NULL, not set up). Thread safe for distinct z. */
FCM_API fcm_status fcm_schwarz_apply(const fcm_schwarz *P, const double *r, double *z);

/** fcm_schwarz_apply() as an fcm_operator_fn; `user` is an `fcm_schwarz *`. */
FCM_API fcm_status fcm_schwarz_operator(void *user, const double *r, double *z);

/** Statistics of the last setup. */
FCM_API void fcm_schwarz_get_info(const fcm_schwarz *P, fcm_schwarz_info *info);

/** Destroy; accepts NULL and `*P == NULL`, sets `*P = NULL`. */
FCM_API void fcm_schwarz_destroy(fcm_schwarz **P);

#ifdef __cplusplus
}
#endif
#endif /* FCM_SOLVE_H */
