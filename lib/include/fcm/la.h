/* fcm — linear algebra: compressed sparse row (CSR) matrices and sparse direct
 * solvers (CHOLMOD for SPD, UMFPACK for general square matrices). */
#ifndef FCM_LA_H
#define FCM_LA_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------ CSR matrices
 * Layout: row i holds the entries row_ptr[i] .. row_ptr[i+1]-1 of col_idx and
 * values; column indices of a row are strictly increasing (sorted, no
 * duplicates), 0-based. Row pointers are 64-bit (fcm_index), so the number of
 * non-zeros may exceed 2^31; column indices are `int`, so ncols <= INT_MAX:
 * 12 instead of 16 bytes per non-zero, which is what a memory-bound sparse
 * matrix-vector product pays, and the layout of most host codes (PETSc,
 * Eigen, MKL) with 32-bit indices. A symmetric matrix stores BOTH triangles:
 * the product stays race-free and bitwise independent of the thread count,
 * and the same matrix goes to CHOLMOD (which reads one triangle) and, when
 * that fails, to UMFPACK (which needs all of it). */

/** What a CSR matrix promises. */
typedef enum fcm_csr_kind {
  FCM_CSR_GENERAL = 0,  /**< any m x n matrix */
  FCM_CSR_SYMMETRIC = 1 /**< square, a_ij = a_ji, both triangles stored (pattern symmetric) */
} fcm_csr_kind;

/** A sparse matrix in CSR form. Opaque; read it with fcm_csr_get_size(), fcm_csr_get_kind(),
 * fcm_csr_row_ptr(), fcm_csr_col_idx() and fcm_csr_values(). */
typedef struct fcm_csr fcm_csr;

/** Create a matrix with the given pattern (copied) and zero values.
 * @param[in]  ctx     context (allocator, errors); must outlive the matrix
 * @param[in]  nrows   number of rows >= 0
 * @param[in]  ncols   number of columns, 0 <= ncols <= INT_MAX
 * @param[in]  row_ptr nrows+1 offsets, row_ptr[0] = 0, non-decreasing; copied
 * @param[in]  col_idx row_ptr[nrows] column indices, sorted and unique per row; copied
 * @param[in]  kind    FCM_CSR_SYMMETRIC also requires nrows == ncols and a symmetric pattern
 * @param[out] A       the new matrix, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (invalid pattern: the message names the row and the
 * bad value), FCM_ERR_UNSUPPORTED (ncols > INT_MAX), FCM_ERR_ALLOC.
 * Allocates three arrays. Thread safe. */
FCM_API fcm_status fcm_csr_create(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                  const fcm_index *row_ptr, const int *col_idx, fcm_csr_kind kind,
                                  fcm_csr **A);

/** Create a matrix from (row, col, value) triplets; duplicates are summed.
 * @param[in]  rows, cols ntrip indices in [0, nrows) and [0, ncols)
 * @param[in]  vals       ntrip values, or NULL for a pattern with zero values
 * Other parameters and status codes as fcm_csr_create(). Allocates O(ntrip)
 * temporary memory; sorts each row (O(ntrip log ntrip)). Thread safe. */
FCM_API fcm_status fcm_csr_create_triplets(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                           fcm_index ntrip, const fcm_index *rows,
                                           const fcm_index *cols, const double *vals,
                                           fcm_csr_kind kind, fcm_csr **A);

/** Wrap caller arrays without copying (borrow: the caller keeps ownership and the
 * arrays must outlive the matrix). fcm never writes the pattern; `values`
 * (row_ptr[nrows] entries) is written only through fcm_csr_values() and
 * fcm_csr_set_zero(). The pattern is validated as in fcm_csr_create().
 * @return as fcm_csr_create(). Allocates only the small handle. Thread safe. */
FCM_API fcm_status fcm_csr_wrap(fcm_ctx *ctx, fcm_index nrows, fcm_index ncols,
                                const fcm_index *row_ptr, const int *col_idx, double *values,
                                fcm_csr_kind kind, fcm_csr **A);

/** Destroy a matrix (borrowed arrays are left alone); accepts NULL and
 * `*A == NULL`, sets `*A = NULL`. */
FCM_API void fcm_csr_destroy(fcm_csr **A);

/** Sizes: any output pointer may be NULL. */
FCM_API void fcm_csr_get_size(const fcm_csr *A, fcm_index *nrows, fcm_index *ncols, fcm_index *nnz);
/** The kind given at creation. */
FCM_API fcm_csr_kind fcm_csr_get_kind(const fcm_csr *A);
/** Row pointers (nrows+1 entries), owned by A or the wrapping caller. */
FCM_API const fcm_index *fcm_csr_row_ptr(const fcm_csr *A);
/** Column indices (nnz entries). */
FCM_API const int *fcm_csr_col_idx(const fcm_csr *A);
/** Values (nnz entries), writable: assembly adds into them. NULL for a NULL matrix. */
FCM_API double *fcm_csr_values(fcm_csr *A);
/** Values (nnz entries), read only: what code that holds a `const fcm_csr *` reads
 * (libCEED's GetArrayRead next to GetArray). NULL for a NULL matrix. Thread safe. */
FCM_API const double *fcm_csr_values_read(const fcm_csr *A);

/** Position of entry (row, col) in the value array (binary search within the
 * row), or -1 when it is not in the pattern or out of range. Thread safe. */
FCM_API fcm_index fcm_csr_position(const fcm_csr *A, fcm_index row, fcm_index col);

/** Set every stored value to zero (keeps the pattern). */
FCM_API void fcm_csr_set_zero(fcm_csr *A);

/** y = alpha A x + beta y (beta == 0: y is overwritten, its old content unused).
 * Rows are distributed over OpenMP threads; each row is summed serially, so the
 * result does not depend on the number of threads. No allocation.
 * @param[in]  x ncols entries, must not overlap y
 * @param[out] y nrows entries
 * @return FCM_OK, FCM_ERR_ARG (NULL pointer, x == y). Thread safe for distinct y. */
FCM_API fcm_status fcm_csr_apply(const fcm_csr *A, double alpha, const double *x, double beta,
                                 double *y);

/** The triple product C = P^T A P of a square A (n x n) and P (n x m): C is m x m, of A's
 * kind (a symmetric C has its mirrored entries averaged, so it is exactly symmetric), with
 * every diagonal entry stored. For a constrained system: P the constraint matrix of
 * fcm_space_hanging_matrix_create().
 * @param[out] C the new matrix, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL, A not square, P's rows not A's), FCM_ERR_ALLOC.
 * Allocates C and O(nnz(A P)) scratch. Thread safe. */
FCM_API fcm_status fcm_csr_create_ptap(fcm_ctx *ctx, const fcm_csr *A, const fcm_csr *P,
                                       fcm_csr **C);

/** Largest |a_ij - a_ji| over stored entries (an entry whose mirror is not
 * stored counts against 0), divided by max |a_ij| (0 for a zero matrix).
 * @return FCM_OK, FCM_ERR_ARG (A not square). No allocation. Thread safe. */
FCM_API fcm_status fcm_csr_asymmetry(const fcm_csr *A, double *rel_asymmetry);

/* ------------------------------------------------------------ direct solvers
 * Phases: create (pattern, copied) -> analyze (symbolic: ordering, elimination
 * tree, once per pattern) -> factor (numeric, repeat with new values of the
 * same pattern) -> solve (repeat) -> destroy. SuiteSparse allocates its own
 * factor memory through the C library (its allocator hooks are global state we
 * leave alone); our handle, pattern copy and workspaces go through the ctx.
 * SuiteSparse never prints: its status is mapped to fcm codes and messages. */

/** Which library factors the matrix. */
typedef enum fcm_direct_method {
  FCM_DIRECT_CHOLMOD = 0, /**< supernodal Cholesky L L^T; FCM_CSR_SYMMETRIC positive definite */
  FCM_DIRECT_UMFPACK = 1  /**< LU with partial pivoting; any square matrix */
} fcm_direct_method;

/** Counters and statistics of a direct solver (cumulative unless noted). */
typedef struct fcm_direct_info {
  long long analyses;       /**< symbolic analyses the library performed (1 per solver) */
  long long factorizations; /**< numeric factorizations attempted */
  long long solves;         /**< solves performed */
  double factor_nnz;        /**< non-zeros of the factors (L, or L + U), last analysis/factor */
  double factor_flops;      /**< flops of the last numeric factorization (estimate for CHOLMOD) */
  double rcond;             /**< crude reciprocal condition estimate from the factor's diagonal
                                 (CHOLMOD: (min/max diag L)^2, UMFPACK: min/max |diag U|) */
  fcm_index failed_column;  /**< column (original numbering) where the last factor failed
                                 (not positive definite), or -1 */
  double min_pivot_ratio;   /**< CHOLMOD: min over columns of pivot / diagonal (L_jj^2 / A_jj, in
                                 (0, 1]) of the last completed factor; below 1e-10 the factor
                                 is refused as numerically singular. 0 before any, and for
                                 UMFPACK. */
  double backward_error;    /**< ||b - A x|| / (||A|| ||x|| + ||b||) (infinity norms) of the
                                 last solve; above 1e-8 the solve is refused as singular */
  double time_analyze;      /**< seconds in analyze */
  double time_factor;       /**< seconds in factor */
  double time_solve;        /**< seconds in solve */
} fcm_direct_info;

/** A sparse direct solver object. */
typedef struct fcm_direct fcm_direct;

/** Name of a method ("cholmod", "umfpack"), or "unknown". */
FCM_API const char *fcm_direct_method_name(fcm_direct_method method);

/** Create a solver for matrices with the pattern of `pattern` (copied; its values
 * are ignored; the matrix may be destroyed afterwards).
 * @param[in]  method  FCM_DIRECT_CHOLMOD needs an FCM_CSR_SYMMETRIC pattern
 * @param[out] solver  the new solver, NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (not square, wrong kind, NULL), FCM_ERR_ALLOC,
 * FCM_ERR_UNSUPPORTED (unknown method). Allocates O(nnz). Thread safe. */
FCM_API fcm_status fcm_direct_create(fcm_ctx *ctx, fcm_direct_method method, const fcm_csr *pattern,
                                     fcm_direct **solver);

/** Symbolic analysis (fill-reducing ordering and factor structure), once per
 * solver; a second call is a no-op. @return FCM_OK, FCM_ERR_ARG (NULL),
 * FCM_ERR_ALLOC, FCM_ERR_UNSUPPORTED (integer overflow in the library),
 * FCM_ERR_INTERNAL (other library failure; the message gives its status).
 * SuiteSparse allocates the symbolic factor. Not thread safe on one solver. */
FCM_API fcm_status fcm_direct_analyze(fcm_direct *solver);

/** Numeric factorization of the matrix with the created pattern and `values`
 * (nnz entries in pattern order, e.g. fcm_csr_values(); read during the call
 * only). Reuses the symbolic analysis; call fcm_direct_analyze() first.
 * @return FCM_OK, FCM_ERR_ARG (not analyzed), FCM_ERR_NUMERIC (NaN/Inf value),
 * FCM_ERR_SINGULAR (CHOLMOD: not positive definite, UMFPACK: zero pivot; the
 * message and info.failed_column name the column; CHOLMOD also refuses a completed factor
 * whose smallest pivot is below 1e-10 of its diagonal, numerically singular: the message
 * names the column and the likely causes, info.failed_column stays -1; UMFPACK likewise a
 * factor with rcond = min/max |diag U| below 1e-13; no factor is kept),
 * FCM_ERR_ALLOC. SuiteSparse allocates the numeric factor. Not thread safe on one solver. */
FCM_API fcm_status fcm_direct_factor(fcm_direct *solver, const double *values);

/** Solve A x = b (n entries each) with the last successful factorization; `x`
 * may equal `b`. No allocation (CHOLMOD allocates its solve workspace once, on
 * the first solve). The residual of x is checked: a normwise backward error above 1e-8
 * (singular system, b outside the range) gives FCM_ERR_SINGULAR with the likely causes and
 * x is still written. @return FCM_OK, FCM_ERR_ARG (no valid factorization, NULL),
 * FCM_ERR_ALLOC (CHOLMOD's first solve), FCM_ERR_SINGULAR. Not thread safe on one solver. */
FCM_API fcm_status fcm_direct_solve(fcm_direct *solver, const double *b, double *x);

/** Copy the counters and statistics into *info. */
FCM_API void fcm_direct_get_info(const fcm_direct *solver, fcm_direct_info *info);

/** Destroy the solver and its factors; accepts NULL and `*solver == NULL`, sets `*solver = NULL`.
 */
FCM_API void fcm_direct_destroy(fcm_direct **solver);

/** Threads OpenBLAS may use inside one BLAS/LAPACK call (process-wide OpenBLAS state).
 * fcm parallelizes over cells with OpenMP (cut-cell rules, Schwarz blocks, assembly) and
 * calls LAPACK inside those loops; with the pthreads build of OpenBLAS each such call may
 * start its own threads and oversubscribe the cores, so programs that use those loops should
 * set 1 here (the fcm programs do). The cut-cell rule builds (fcm_cell_rules_create*()) set 1
 * for the duration of their cell loops themselves and restore the count after them. n < 1
 * only queries. @return the previous count. Not thread safe. */
FCM_API int fcm_blas_set_num_threads(int n);

/** Instruction-set levels of x86-64 BLAS kernels and CPUs, lowest first. */
typedef enum fcm_isa {
  FCM_ISA_UNKNOWN = 0, /**< not an x86-64 CPU, or a kernel set the table does not know */
  FCM_ISA_SSE2,        /**< baseline x86-64 */
  FCM_ISA_SSE3,        /**< SSE3 (OpenBLAS Prescott, Core2, Nehalem, Barcelona, ...) */
  FCM_ISA_AVX,         /**< AVX (Sandybridge, Bulldozer ... Excavator) */
  FCM_ISA_AVX2,        /**< AVX2 + FMA (Haswell, Zen) */
  FCM_ISA_AVX512       /**< AVX-512 F/DQ/BW/VL (SkylakeX, Cooperlake, SapphireRapids) */
} fcm_isa;

/** Which kernels the BLAS runs on, against what the CPU supports (fcm_blas_info_get()). */
typedef struct fcm_blas_info {
  const char *name;     /**< "OpenBLAS", or "unknown" (a BLAS that does not say) */
  const char *config;   /**< the BLAS's build description (openblas_get_config()), or "" */
  const char *core;     /**< kernel set in use, as the BLAS names it ("Prescott"), or "" */
  const char *cpu_core; /**< the kernel set for this CPU, as OPENBLAS_CORETYPE takes it
                             ("SkylakeX", "Zen", "Haswell", "Sandybridge"), or "" */
  fcm_isa core_isa;     /**< level of `core` */
  fcm_isa cpu_isa;      /**< level of the CPU (what it and the OS support) */
  int fallback;         /**< 1: the kernels are below the CPU (core_isa < cpu_isa, both known
                             and cpu_core set): setting OPENBLAS_CORETYPE=cpu_core before the
                             program starts selects the right ones */
} fcm_blas_info;

/** Find the BLAS's kernel set (OpenBLAS's openblas_get_corename() and openblas_get_config(),
 * looked up at run time, so any BLAS links) and the CPU's instruction set (cpuid). The
 * strings are static. A fallback is also logged once per context at FCM_LOG_WARNING with the
 * fix, here and at the first fcm_direct_analyze() (CHOLMOD and UMFPACK spend most of their
 * time in DGEMM). OpenBLAS reads OPENBLAS_CORETYPE only when it loads: the fcm programs set it
 * and re-execute themselves (FCM_BLAS_CORETYPE=keep turns that off); a host program sets it
 * in its environment. @param[in] ctx for the warning (may be NULL)
 * @param[out] info the result. @return FCM_OK, FCM_ERR_ARG (info NULL). No allocation.
 * Not thread safe with itself (OpenBLAS writes its config string to a static buffer). */
FCM_API fcm_status fcm_blas_info_get(fcm_ctx *ctx, fcm_blas_info *info);

/** The name of an instruction-set level ("AVX-512", ...; "unknown" out of range). */
FCM_API const char *fcm_isa_name(fcm_isa isa);

#ifdef __cplusplus
}
#endif
#endif /* FCM_LA_H */
