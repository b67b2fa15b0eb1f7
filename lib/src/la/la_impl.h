/* Dense linear algebra adapter over BLAS/LAPACK (internal). All matrices are
 * column-major with an explicit leading dimension; sizes are int as in LAPACK.
 * Every LAPACK `info` is mapped to a status with a message naming the routine. */
#ifndef FCM_LA_IMPL_H
#define FCM_LA_IMPL_H

#include "core/core_impl.h"
#include "fcm/la.h"

/* The kernel set the BLAS runs on, as it names it (OpenBLAS's openblas_get_corename(),
 * "Prescott"), and its build description (openblas_get_config()); "" from a BLAS that has
 * no such query. Static strings; fcm__blas_config() is not thread safe with itself. */
const char *fcm__blas_core_name(void);
const char *fcm__blas_config(void);

/* Log once per context, at FCM_LOG_WARNING, that the BLAS runs on kernels below the CPU's
 * instruction set (fcm_blas_info_get()), with the fix. Thread safe. */
void fcm__blas_check(fcm_ctx *ctx);

/* C = alpha op(A) op(B) + beta C, op = 'N' or 'T'. Sizes are not checked: the
 * caller passes valid leading dimensions (cblas would print on bad ones). */
void fcm__gemm(char transa, char transb, int m, int n, int k, double alpha, const double *a,
               int lda, const double *b, int ldb, double beta, double *c, int ldc);

/* y = alpha op(A) x + beta y, A is m x n. */
void fcm__gemv(char trans, int m, int n, double alpha, const double *a, int lda, const double *x,
               double beta, double *y);

/* The same in single precision (BLAS sgemv). */
void fcm__sgemv(char trans, int m, int n, float alpha, const float *a, int lda, const float *x,
                float beta, float *y);

/* A += alpha x y^T, A m x n (lda), x stride 1, y stride incy (BLAS dger). */
void fcm__ger(int m, int n, double alpha, const double *x, const double *y, int incy, double *a,
              int lda);

/* x = inv(A) x with A n x n upper triangular (lda), its diagonal nonzero: BLAS dtrsv. */
void fcm__trsv_upper(int n, const double *a, int lda, double *x);

/* B = alpha B inv(A) with A n x n unit lower triangular (B m x n, ldb): BLAS dtrsm
 * side right, lower, no transpose, unit diagonal. */
void fcm__trsm_right_unit_lower(int m, int n, double alpha, const double *a, int lda, double *b,
                                int ldb);

/* Symmetric eigen-decomposition of the n x n matrix A (lower triangle read).
 * w receives the eigenvalues in ascending order; with want_vectors the columns of
 * A are overwritten by orthonormal eigenvectors. FCM_ERR_LAPACK if it fails to
 * converge, FCM_ERR_NUMERIC on NaN/Inf input. */
fcm_status fcm__syev(fcm_ctx *ctx, int want_vectors, int n, double *a, int lda, double *w);

/* Workspace of fcm__syev_work() for order n: *lwork doubles and *liwork ints (dsyevd's
 * query, plus one). */
fcm_status fcm__syev_workspace(fcm_ctx *ctx, int want_vectors, int n, size_t *lwork,
                               size_t *liwork);

/* fcm__syev() with caller workspace of at least the sizes fcm__syev_workspace() gives for n:
 * allocates nothing, same result (FCM_ERR_INTERNAL when the workspace is too small). */
fcm_status fcm__syev_work(fcm_ctx *ctx, int want_vectors, int n, double *a, int lda, double *w,
                          double *work, size_t lwork, int *iwork, size_t liwork);

/* Eigenvalues (ascending, into w) of the generalized symmetric-definite problem
 * A x = lambda B x (LAPACK dsygv, itype 1, no vectors; lower triangles read, A and B
 * destroyed). FCM_ERR_SINGULAR when B is not positive definite, FCM_ERR_NUMERIC on NaN/Inf,
 * FCM_ERR_LAPACK when the iteration fails. Allocates a workspace of 3n doubles. */
fcm_status fcm__sygv(fcm_ctx *ctx, int n, double *a, int lda, double *b, int ldb, double *w);

/* Eigenvalues (ascending, into d) and optionally eigenvectors (z, n x n, ldz) of
 * the symmetric tridiagonal matrix with diagonal d[0..n) and off-diagonal
 * e[0..n-1) (e is destroyed). z == NULL: eigenvalues only. */
fcm_status fcm__stev(fcm_ctx *ctx, int n, double *d, double *e, double *z, int ldz);

/* Thin SVD A = U diag(s) Vt of the m x n matrix A (destroyed), k = min(m, n):
 * s[k] descending, U m x k (ldu), Vt k x n (ldvt); U or Vt may be NULL. */
fcm_status fcm__gesvd(fcm_ctx *ctx, int m, int n, double *a, int lda, double *s, double *u, int ldu,
                      double *vt, int ldvt);

/* LU factorization with partial pivoting in place; FCM_ERR_SINGULAR names the
 * zero pivot. ipiv has n entries. */
fcm_status fcm__getrf(fcm_ctx *ctx, int n, double *a, int lda, int *ipiv);

/* LU factorization with partial pivoting P A = L U of the m x n matrix A (m >= n) in
 * place; ipiv has n entries. An exactly zero pivot is not an error here: the caller reads
 * the diagonal of U. FCM_ERR_NUMERIC on NaN/Inf input. */
fcm_status fcm__getrf_tall(fcm_ctx *ctx, int m, int n, double *a, int lda, int *ipiv);

/* Solve A X = B with the factors of fcm__getrf; B is n x nrhs (ldb). */
fcm_status fcm__getrs(fcm_ctx *ctx, int n, int nrhs, const double *lu, int lda, const int *ipiv,
                      double *b, int ldb);

/* Cholesky A = L L^T in place (lower triangle read and overwritten);
 * FCM_ERR_SINGULAR naming the leading minor if not positive definite. */
fcm_status fcm__potrf(fcm_ctx *ctx, int n, double *a, int lda);

/* Solve A X = B with the factor of fcm__potrf. */
fcm_status fcm__potrs(fcm_ctx *ctx, int n, int nrhs, const double *l, int lda, double *b, int ldb);

/* Minimum-norm least-squares solution of min ||A x - b|| for the m x n matrix A
 * (destroyed) through the SVD (LAPACK dgelsd). B is max(m,n) x nrhs (ldb) and
 * receives the n x nrhs solution. Singular values below rcond * s_max count as
 * zero (rcond < 0: machine precision); *rank receives the effective rank (may be NULL). */
fcm_status fcm__lstsq(fcm_ctx *ctx, int m, int n, int nrhs, double *a, int lda, double *b, int ldb,
                      double rcond, int *rank);

/* ---- sparse ---- */

/* The CSR matrix (public type fcm_csr, layout documented in fcm/la.h). */
struct fcm_csr {
  fcm_ctx *ctx;
  fcm_index nrows, ncols, nnz;
  const fcm_index *row_ptr; /* nrows + 1; never written after creation */
  const int *col_idx;       /* nnz, sorted and unique per row; never written */
  double *values;           /* nnz */
  fcm_csr_kind kind;
  /* Storage allocated through ctx (fcm_csr_create), NULL when borrowed (fcm_csr_wrap):
   * row_ptr and col_idx point here or at the caller's arrays; values is owned iff owned. */
  fcm_index *own_row_ptr;
  int *own_col_idx;
  int owned;
};

/* A matrix on a borrowed pattern with values of its own (zeroed): row_ptr / col_idx are the
 * caller's (they must outlive A and are not checked: an internal pattern known valid, e.g. a
 * space's), the values are allocated here and freed by fcm_csr_destroy(). Several matrices of
 * one space share its pattern this way (8 bytes per entry each instead of 12). (csr.c) */
fcm_status fcm__csr_share_pattern(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                  const fcm_index *row_ptr, const int *col_idx, fcm_csr_kind kind,
                                  fcm_csr **A);

/* fcm__csr_share_pattern() whose values take the storage of give's values where it is large
 * enough (fcm__calloc_large_from(): zero filled again); give (or NULL) is then left without
 * values (NULL: it can only be destroyed). Else new values, give untouched. (csr.c) */
fcm_status fcm__csr_share_pattern_from(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                       const fcm_index *row_ptr, const int *col_idx,
                                       fcm_csr_kind kind, fcm_csr *give, fcm_csr **A);

/* The room of A's values (when A owns them) mapped, its contents kept (fcm__large_map()): for
 * a matrix whose storage a successor will take (fcm__csr_share_pattern_from()). */
void fcm__csr_map_room(fcm_csr *A);

/* A (owning its values, not yet written: a Galerkin product's before its first set-up) takes
 * the storage of give's values (a matrix about to be destroyed) when it holds A's: A's own,
 * never touched, is freed, A's values are then give's bits until written, and give is left
 * without values (destroy only). Returns 1 when taken, else 0 (nothing changed). (csr.c) */
int fcm__csr_take_values(fcm_csr *A, fcm_csr *give);

/* The values storage `to` gave to `from` (fcm__csr_share_pattern_from()) back to `to`: 1 when
 * given back (to's values then as from's left them, from without values: destroy only); 0 when
 * there is nothing to give back (to has values, or from none of its own). (csr.c) */
int fcm__csr_give_back(fcm_csr *from, fcm_csr *to);

/* y = A x (fcm_csr_apply() with alpha 1, beta 0: the same bits) at the rows i whose
 * rows3[i / 3] is set; the other entries of y are left as they are. Serial. (csr.c) */
void fcm__csr_apply_rows(const fcm_csr *A, const double *x, double *y, const unsigned char *rows3);

/* fcm__csr_share_pattern_from() that leaves taken values as give held them (*taken 1: the
 * caller writes every entry); new values are zero filled (*taken 0). (csr.c) */
fcm_status fcm__csr_share_pattern_keep(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                       const fcm_index *row_ptr, const int *col_idx,
                                       fcm_csr_kind kind, fcm_csr *give, fcm_csr **A, int *taken);

/* A matrix that takes over *row_ptr and *col_idx (arrays from fcm__calloc or fcm__malloc;
 * set to NULL, also on failure, when they are freed), its values not set: the caller writes
 * every one before any is read (no zero fill of a large array). For patterns built inside
 * the library that are already known to be valid (rows strictly increasing, in range, both
 * triangles of an FCM_CSR_SYMMETRIC pattern): unlike fcm_csr_create() it neither copies nor
 * checks them. (csr.c) */
fcm_status fcm__csr_adopt_pattern(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                  fcm_index **row_ptr, int **col_idx, fcm_csr_kind kind,
                                  fcm_csr **A);

/* The sparse triple product C = P^T A P of a square matrix A (n x n, either kind) and a
 * prolongation P (n x nc, CSR arrays: P_ptr n + 1 offsets, P_col sorted per row in [0, nc),
 * P_val), like PETSc's MatPtAP, in two phases: fcm__ptap_create() finds the patterns of A P and
 * of C once and creates C (nc x nc, A's kind, values not yet set); fcm__ptap_apply() computes C's
 * values from A's current ones, as often as they change (same pattern). C = R (A P) with
 * R = P^T stored: each entry is summed by one thread in a fixed order (the rows of A, then of
 * P), so C does not depend on the thread count, but rounding may leave c_ij != c_ji for a
 * symmetric A: a caller that needs exact symmetry averages the pair. Internal rather than in
 * fcm/la.h: its only user, the multigrid, borrows P as bare arrays and reads R for its
 * restriction; a public call would take fcm_csr operands. (ptap.c) */
typedef struct fcm__ptap fcm__ptap;

/* The plan and C. P is borrowed (it must outlive the plan and not change); with_diagonal:
 * C stores every diagonal entry (zero where P^T A P has none structurally: rows of empty
 * columns of P). nt >= 1: the most threads fcm__ptap_apply() may use, and those that find the
 * patterns (nt = 1: serial). @return FCM_OK, FCM_ERR_ARG (NULL, A not square, a column of P
 * out of range), FCM_ERR_ALLOC; on failure *plan and *C are NULL. Allocates R, A P and nt
 * accumulators of nc doubles. */
fcm_status fcm__ptap_create(fcm_ctx *ctx, const fcm_csr *A, fcm_index nc, const fcm_index *P_ptr,
                            const int *P_col, const double *P_val, int with_diagonal, int nt,
                            fcm__ptap **plan, fcm_csr **C);

/* What fcm__ptap_create_from() takes over: the plan and product of an earlier A and P (a
 * hierarchy's level before a cut) and the maps between the old and new numberings. A row of
 * A P whose row of A and the rows of P it reaches are the old ones with every index mapped
 * (the same positions) is the old row mapped; a row of C whose row of R is the old one mapped,
 * reaching only such rows of A P, is the old row mapped (sorted). The maps must be injective,
 * each the other's inverse where >= 0. */
typedef struct fcm__ptap_prior {
  const fcm__ptap *plan; /* made with the same with_diagonal */
  const fcm_csr *C;      /* its product (the pattern is read) */
  /* the old A's pattern: CSR rows (A_ptr, A_col), or with A_col NULL a copy graph (A_ptr,
   * A_adj): row i holds 3 j, 3 j + 1, 3 j + 2 for each j of graph row i / 3; then the new A's
   * pattern must be the copy graph (G_ptr, G_adj) alike (copy_same compares it a copy at a time)
   * and the maps of A's rows must map a copy's three rows together (3 k + c to 3 k' + c) */
  const fcm_index *A_ptr;
  const int *A_col;
  const fcm_index *A_adj;
  const fcm_index *G_ptr, *G_adj;
  /* copy-graph mode: per copy k of the new A, 1 exactly where rows 3 k .. 3 k + 2 map to an
   * old copy's three in order and G's row k is that copy's old graph row mapped entry by
   * entry (row_new): the caller compares the graph rows (the block smoothers' carry reads
   * the same comparison) */
  const unsigned char *copy_same;
  const fcm_index *row_old, *row_new;   /* A's rows: new -> old, old -> new (-1: none) */
  const fcm_index *crow_old, *crow_new; /* C's rows (P's columns) alike */
} fcm__ptap_prior;

/* fcm__ptap_create() with the rows of A P and C that `prior` shows unchanged (the inputs
 * compared entry by entry through the maps) taken over mapped instead of computed: the same
 * plan and C bit for bit. taken (may be NULL): the rows of A P and of C taken over. c_same
 * (NULL: not wanted): per row of C (nc + 1 bytes, allocated here, the caller's), 1 where it is
 * the old row mapped column for column in the same order (taken, its mapped columns
 * ascending). @return as fcm__ptap_create(). */
fcm_status fcm__ptap_create_from(fcm_ctx *ctx, const fcm__ptap_prior *prior, const fcm_csr *A,
                                 fcm_index nc, const fcm_index *P_ptr, const int *P_col,
                                 const double *P_val, int with_diagonal, int nt, fcm__ptap **plan,
                                 fcm_csr **C, fcm_index taken[2], unsigned char **c_same);

/* C's values = P^T A P for A's current values, on `nt` threads (clamped to [1, the plan's]).
 * A has the pattern given to fcm__ptap_create(), C is the matrix it created. Allocates
 * nothing; one call at a time per plan. */
void fcm__ptap_apply(fcm__ptap *plan, const fcm_csr *A, fcm_csr *C, int nt);

/* The plan t takes the storage of give's A P values (a plan of a hierarchy before a cut, about
 * to be destroyed) when it holds t's: t's own, never touched, is freed, and its products then
 * write into pages already mapped instead of faulting fresh ones in. give is left without it:
 * it can only be destroyed. Returns 1 when taken, else 0 (nothing changed). */
int fcm__ptap_take_scratch(fcm__ptap *t, fcm__ptap *give);

/* The storage of the plan's A P values (NULL for NULL, or once taken). */
const double *fcm__ptap_scratch(const fcm__ptap *t);

/* R = P^T (nc x n) as the plan holds it: row J lists the rows of P with a column J,
 * ascending. Valid while the plan lives. */
void fcm__ptap_transpose(const fcm__ptap *plan, const fcm_index **R_ptr, const int **R_col,
                         const double **R_val);

/* Destroy; accepts NULL and *plan == NULL, sets *plan = NULL. */
void fcm__ptap_destroy(fcm__ptap **plan);

/* One table per sparse direct-solver adapter (cholmod_adapter.c,
 * umfpack_adapter.c); fcm_direct (direct.c) checks arguments and phases, counts
 * and times, and calls these. `impl` is the adapter's state. The adapter sets
 * info->factor_nnz, factor_flops, rcond and failed_column; the caller the
 * counters and timings, except `analyses`, which the adapter increments each
 * time the library really computes a symbolic analysis. */
typedef struct fcm__direct_ops {
  const char *name;
  /* Take the pattern of the square matrix A (its values are not read). */
  fcm_status (*create)(fcm_ctx *ctx, const fcm_csr *A, void **impl);
  fcm_status (*analyze)(fcm_ctx *ctx, void *impl, fcm_direct_info *info);
  /* A fill-reducing ordering to analyze with instead of computing one (a permutation of
   * 0..n-1, copied), and the ordering of the analysis; NULL where the method has none. */
  fcm_status (*set_ordering)(fcm_ctx *ctx, void *impl, const fcm_index *perm);
  void (*get_ordering)(const void *impl, fcm_index *perm);
  /* Values are finite (checked by the caller). On failure no factor is kept. */
  fcm_status (*factor)(fcm_ctx *ctx, void *impl, const double *values, fcm_direct_info *info);
  /* x may equal b. */
  fcm_status (*solve)(fcm_ctx *ctx, void *impl, const double *b, double *x);
  void (*destroy)(fcm_ctx *ctx, void *impl); /* accepts impl == NULL */
} fcm__direct_ops;

/* Numerical rank checks of the direct path (calibration in cholmod_adapter.c and direct.c): a
 * CHOLMOD pivot below this fraction of its column's diagonal, or a solve whose normwise backward
 * error ||b - A x|| / (||A|| ||x|| + ||b||) (infinity norms) exceeds the second value, or an
 * UMFPACK factor whose rcond (min/max |diag U|, row-scaled) is below the third, is refused with
 * FCM_ERR_SINGULAR and the hint below. */
#define FCM__SINGULAR_PIVOT_RATIO    1e-10
#define FCM__SINGULAR_BACKWARD_ERROR 1e-8
#define FCM__SINGULAR_UMFPACK_RCOND  1e-13
#define FCM__SINGULAR_HINT                                                                         \
  "likely causes: rigid-body modes left free (a static problem needs Dirichlet constraints "       \
  "that fix translations and rotations), a quadrature rule too weak for the element "              \
  "(hourglass modes; raise the quadrature strength), or cells with (nearly) no quadrature "        \
  "points (empty or dropped cut cells without stabilization)"

extern const fcm__direct_ops fcm__cholmod_ops;

/* The symbolic analysis of s (not yet analyzed) takes the fill-reducing ordering perm (a
 * permutation of 0..n-1: perm[k] is the row eliminated k-th; copied) instead of computing one
 * (AMD / METIS): fcm_direct_analyze() then computes only the elimination tree, the
 * postordering and the factor's structure. CHOLMOD only. After a cut the new system's
 * ordering is the old one with the new DOFs beside their parents (sim/cut_update.c).
 * @return FCM_OK, FCM_ERR_ARG (NULL, analyzed already, not a permutation of 0..n-1),
 * FCM_ERR_UNSUPPORTED (UMFPACK), FCM_ERR_ALLOC. (direct.c) */
fcm_status fcm__direct_set_ordering(fcm_direct *s, const fcm_index *perm);

/* The ordering of the analysis (n entries into perm: the row eliminated k-th, after CHOLMOD's
 * postordering). @return FCM_OK, FCM_ERR_ARG (NULL, not analyzed), FCM_ERR_UNSUPPORTED
 * (UMFPACK). (direct.c) */
fcm_status fcm__direct_get_ordering(const fcm_direct *s, fcm_index *perm);
extern const fcm__direct_ops fcm__umfpack_ops;

/* A fill-reducing ordering of the symmetric pattern A whose rows come in groups (group[i] in
 * [0, ngroup): row i's, e.g. its node): AMD on the graph of the groups (two neighbour when a
 * row of one has an entry in a column of the other), each group's rows then together in
 * ascending order; n entries into perm (perm[k]: the row eliminated k-th), for
 * fcm__direct_set_ordering(). On the DOFs of 3-D elasticity the graph has a ninth of A's
 * entries, so it is found faster than AMD on A, with a factor of about AMD's size
 * (lib/docs/cutting.md, "The coarsest ordering"). @return FCM_OK, FCM_ERR_ARG (NULL, ngroup
 * < 0, A not square, a group outside [0, ngroup)), FCM_ERR_ALLOC,
 * FCM_ERR_INTERNAL (AMD refused the graph). (ordering.c) */
fcm_status fcm__amd_group_ordering(fcm_ctx *ctx, const fcm_csr *A, fcm_index ngroup,
                                   const fcm_index *group, fcm_index *perm);

#endif /* FCM_LA_IMPL_H */
