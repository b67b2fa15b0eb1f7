/* fcm simplify, internal part: the box-scaled Chebyshev basis, the GLPK adapter
 * interface and the state one simplification attempt (LP or recombination) fills. */
#ifndef FCM_SIMPLIFY_IMPL_H
#define FCM_SIMPLIFY_IMPL_H

#include "core/core_impl.h"
#include "fcm/simplify.h"

#include <string.h>

/* fcm_simplify() with a test hook that makes every LP and elimination fail: force_lp_failure
 * 0 off (what fcm_simplify() passes), 1 every LP stops at an iteration limit of 0, 2 every LP
 * triggers a GLPK fatal error (caught); with 1 and 2 every elimination finds its LU pivots
 * too small. Any other value: FCM_ERR_ARG. */
fcm_status fcm__simplify_hooked(fcm_ctx *ctx, int strength, fcm_index n, const double *points,
                                const double *weights, const fcm_simplify_options *opts,
                                int force_lp_failure, fcm_simplify_result *out,
                                fcm_simplify_info *info);

/* ---- basis (basis.c) ---- */

/* Tensor Chebyshev basis T_a(x^)T_b(y^)T_c(z^), a+b+c <= m and a, b, c <= q, on the bounding
 * box of a point set: x^ = scale * x + shift per axis; a degenerate axis (extent at rounding
 * level) gets scale 0 and shift 1, so every polynomial is constant along it. q >= m: the total
 * degree space P_m; q = k, m = 3k: the tensor space Q_k. */
typedef struct fcm__cheb_box {
  int m;           /* strength: the largest total degree */
  int q;           /* the largest degree in each variable (<= m) */
  int num_basis;   /* M: (m+3 choose 3) for q = m, (q+1)^3 for m >= 3q */
  double scale[3]; /* per axis */
  double shift[3];
} fcm__cheb_box;

/* (m+3 choose 3) for m >= 0. */
int fcm__simplify_num_basis(int m);

/* Number of (a, b, c) with a+b+c <= m and a, b, c <= q (q >= m or q < 0: (m+3 choose 3)). */
int fcm__simplify_space_size(int m, int q);

/* Box of the n points (n x 3, row-major) for strength m, every degree (q = m). */
void fcm__simplify_box(int m, int n, const double *points, fcm__cheb_box *box);

/* Cap box's basis at degree q in each variable (q < 0 or q >= m: none). */
void fcm__simplify_box_cap(fcm__cheb_box *box, int q);

/* The rows of sub's basis in top's (rows[0..sub->num_basis), ascending): sub's space must lie
 * in top's (sub->m <= top->m, sub->q <= top->q); both ordered as fcm__simplify_basis_eval. */
void fcm__simplify_basis_rows(const fcm__cheb_box *top, const fcm__cheb_box *sub, int *rows);

/* phi[0..M) at the point x[3]; ordered by total degree, then a descending, then b, skipping
 * the functions of degree above q in a variable. */
void fcm__simplify_basis_eval(const fcm__cheb_box *box, const double *x, double *phi);

/* Points per block of fcm__simplify_moments, and the fewest for which a block goes through
 * BLAS (measured by tests/simplify/bench_simplify.c). */
#define FCM__MOMENT_BLOCK    256
#define FCM__MOMENT_GEMM_MIN 64

/* Doubles of scratch fcm__simplify_moments needs at strength m. */
size_t fcm__simplify_moments_scratch(int m);

/* phi (M x n, column j = phi(points[j]), the order of fcm__simplify_basis_eval) by the same
 * blocked tensor products; work: fcm__simplify_moments_scratch(m) doubles. */
void fcm__simplify_basis_points(const fcm__cheb_box *box, int n, const double *points, double *phi,
                                double *work);

/* mom[0..M) = sum_i w[i] phi(points[idx[i]]) over i < n (idx NULL: points[i]). Uses the
 * tensor structure of the basis: per block of points, the products T_a(x) T_b(y) and
 * w T_c(z) and one matrix product (BLAS dgemm) for all (a, b, c). work: scratch of
 * fcm__simplify_moments_scratch(m) doubles. */
void fcm__simplify_moments(const fcm__cheb_box *box, int n, const double *points, const int *idx,
                           const double *w, double *mom, double *work);

/* ---- GLPK adapter (glpk_adapter.c, the only file that sees glpk.h) ---- */

typedef struct fcm__lp_params {
  int it_lim;        /* simplex iteration limit (> 0, or 0 with force_failure 1) */
  double tm_lim;     /* seconds; 0: none */
  int force_failure; /* 0, 1 (iteration limit 0), 2 (provoke a GLPK fatal error) */
} fcm__lp_params;

typedef struct fcm__lp_report {
  int ok;                     /* 1: x is a vertex reported (primal) feasible */
  fcm_simplify_reason reason; /* on failure: FCM_SIMPLIFY_REASON_LP or _LP_ERROR */
  int iterations;             /* simplex iterations */
  char message[160];          /* on failure: what GLPK said */
} fcm__lp_report;

/* Find a basic feasible solution of A x = b, x >= 0 (A rows x cols, column-major with
 * leading dimension lda, rows expected orthonormal) by GLPK's dual simplex with a zero
 * objective, presolver and scaling off, terminal output swallowed and the error hook
 * installed. An LP failure is not an error: it returns FCM_OK with rep->ok = 0.
 * Errors: FCM_ERR_ALLOC (our workspace). x has cols entries. Thread safe (GLPK 5.0
 * keeps its environment in thread-local storage). */
fcm_status fcm__simplify_lp_solve(fcm_ctx *ctx, int rows, int cols, const double *a, int lda,
                                  const double *b, const fcm__lp_params *prm, double *x,
                                  fcm__lp_report *rep);

/* ---- one attempt (simplify.c drives; lp.c and recombine.c implement) ---- */

typedef struct fcm__attempt {
  /* input, set by the driver */
  fcm_ctx *ctx;
  int n;                /* points */
  const double *points; /* n x 3 */
  const double *w0;     /* n weights normalized to mean 1 */
  double *moments;      /* M moments of w0 in the box basis, valid once have_moments: the
                           path that first evaluates the basis on all points sets them */
  int have_moments;
  fcm__cheb_box box;
  double rank_tol;
  fcm__lp_params lp;
  double pivot_tol; /* elimination: an LU pivot <= pivot_tol * max pivot means rank-deficient */
  int eliminate;    /* recombination: 1 rounds by Carathéodory elimination, 0 by SVD + GLPK */
  int elim_block;   /* null-space directions per blocked tableau update (1: rank-1 updates) */
  double *ws;       /* elimination scratch, grown on demand, released by the driver */
  int *iws;
  size_t ws_cap, iws_cap;
  /* output: a support of at most `capacity` points with positive weights (normalized
   * scale), or reason != NONE with a message; counters and times accumulate */
  int capacity; /* of support and w */
  int count;
  int *support; /* ascending input indices */
  double *w;
  int rank;
  fcm_simplify_reason reason;
  char message[200];
  long long lp_iterations;
  int num_lps, num_eliminations, rounds;
  double time_basis, time_svd, time_lp;
  double flops; /* of the eliminations: LU, triangular solve, tableau updates */
} fcm__attempt;

/* Set a->moments (once) to the sum of the ncols columns of g (M rows, ld M) times lam
 * (NULL: ones). */
void fcm__simplify_set_moments(fcm__attempt *a, int ncols, const double *g, const double *lam);

/* The attempt's support from the positive entries of x (n): point idx[j] (idx NULL: j) with
 * weight x[j] * scale[j] (scale NULL: x[j]), ascending when idx is; a soft COUNT failure
 * past a->capacity points, NOT_POSITIVE when none is positive (`what` names the step). */
void fcm__simplify_take_support(fcm__attempt *a, int n, const int *idx, const double *scale,
                                const double *x, const char *what);

/* Record a soft failure of an attempt (the driver retries or falls back). */
void fcm__simplify_fail(fcm__attempt *a, fcm_simplify_reason reason, const char *fmt, ...)
    FCM__PRINTF(3, 4);

/* Map a failing status of a dense solver inside an attempt: FCM_ERR_ALLOC stays a hard
 * error (returned); anything else becomes a soft NUMERIC failure and FCM_OK. */
fcm_status fcm__simplify_soften(fcm__attempt *a, fcm_status st, const char *what);

/* Rows of the numerical row space: thin SVD of the rows x cols matrix g (destroyed,
 * column-major, ld rows); q (k x cols, ld k, k = min(rows, cols)) receives V^T, whose
 * first *r rows (s_i > rank_tol s_0) span the row space; time goes to time_svd. */
fcm_status fcm__simplify_row_space(fcm__attempt *a, int rows, int cols, double *g, double *q,
                                   int *r);

/* One full LP on all n points (lib/METHOD.md §6): P (M x n), thin SVD, V_r^T w = V_r^T w0. */
fcm_status fcm__simplify_run_lp(fcm__attempt *a);

/* Hierarchical recombination (Litterer & Lyons 2012): about log2(n/M) rounds on cluster moments and
 * a final step on single points, each an LP (or, with a->eliminate, a Carathéodory elimination). */
fcm_status fcm__simplify_run_recombine(fcm__attempt *a);

/* Largest and default elimination_block (fcm_simplify_options): the default measured by
 * tests/bench/bench_roofline.c. */
#define FCM__ELIM_BLOCK_MAX 256
#define FCM__ELIM_BLOCK     32

/* Carathéodory elimination (caratheodory.c) on the rows x ncols matrix g (ld ldg): lam
 * (ncols, >= 0, entries <= 0 are set to 0) is replaced by weights with the same g lam and at
 * most `rows` positive entries. *deficient = 1 (lam unchanged) when the LU pivots say the
 * active columns do not have full row rank. Times go to time_svd (LU) and time_lp.
 * Errors: FCM_ERR_ALLOC; a failed LU becomes a soft NUMERIC failure. */
fcm_status fcm__simplify_caratheodory(fcm__attempt *a, int rows, int ncols, const double *g,
                                      int ldg, double *lam, int *deficient);

/* Elimination with the rank handled: on g (rows x ncols, ld rows, destroyed) directly, or,
 * when its rows are dependent, on the orthonormal rows of its row space (thin SVD; q is
 * min(rows, ncols) x ncols scratch). Sets a->rank. */
fcm_status fcm__simplify_reduce(fcm__attempt *a, int rows, int ncols, double *g, double *q,
                                double *lam);

/* Elimination on all n points when n <= 4 M, else recombination with elimination rounds. */
fcm_status fcm__simplify_run_eliminate(fcm__attempt *a);

/* ---- moment fitting (fit.c) ---- */

/* Interior candidates per moment that a fit's first candidate set of strength m aims at. NNLS
 * costs more the more candidates it prices, but a set whose cone misses the moments costs an
 * NNLS run to prove it and then a set four times larger: on real cut cells (ball, cut
 * fractions 0.25..0.75; tests/bench/bench_roofline.c) 2 per moment fails on half the cells at
 * m = 7 and on all at m = 9, 2.5 at m = 7 and (m - 1) / 2 at m = 9 on none; on a scanned model
 * at m = 7 2.5 and 3 fail on the same 6 % of the cells (the smaller set the faster), and below
 * 2.5 the four sets of a small piece can all fail (lib/docs/performance.md). */
static inline double fcm__fit_candidates_per_moment(int m)
{
  return m > 7 ? 0.5 * (m - 1) : m > 5 ? 2.5 : 2.0;
}

/* A fitted rule: count <= M candidates idx[] (ascending) with positive weights w[] (both
 * arrays of M entries, the caller's), their relative moment residual and the NNLS fit's
 * floating-point operations (not those of the LP that follows when NNLS stops short); ok = 0
 * with a message when the candidates cannot carry the moments. */
typedef struct fcm__fit {
  int ok, count;
  int *idx;
  double *w;
  double residual;
  double flops; /* of the NNLS fit on all candidates (fcm__nnls_report.flops) */
  char message[200];
} fcm__fit;

/* What fcm__simplify_nnls() found: ok when the residual reached the caller's level, optimal
 * when it stopped short of it because no column lowers the residual (x is then the least-squares
 * minimizer over x >= 0 up to rounding), infeasible when it stopped on a proof that no x >= 0
 * reaches the caller's `reach` (x is then the last iterate), the residual max_i |(b - A x)_i|,
 * the passive set's size (the positive entries of x), the outer iterations and the
 * floating-point operations. */
typedef struct fcm__nnls_report {
  int ok, optimal, infeasible, passive, iterations;
  double residual;
  double flops; /* of the algorithm: gradients, QR updates, solves, residuals */
} fcm__nnls_report;

/* x^T y over n entries in 8 partial sums (one per vector lane, added in a fixed tree at the
 * end): a single running sum is a chain of n dependent additions. */
static inline double fcm__fit_dot(int n, const double *x, const double *y)
{
#if defined(__GNUC__) || defined(__clang__)
  typedef double v8d __attribute__((vector_size(64)));
  v8d acc = {0}, a, b;
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    memcpy(&a, x + i, sizeof a), memcpy(&b, y + i, sizeof b);
    acc += a * b;
  }
  double t = ((acc[0] + acc[4]) + (acc[2] + acc[6])) + ((acc[1] + acc[5]) + (acc[3] + acc[7]));
#else
  double t = 0.0;
  int i = 0;
#endif
  for (; i < n; i++)
    t += x[i] * y[i];
  return t;
}

/* NNLS's largest cosine (fit.c): max2() of g_j inv_j over the columns j not passive in
 * iteration it (pas[j] != it), 0 if none is larger; in chains side by side, the value one
 * running maximum gives, NaNs left out. */
double fcm__nnls_top_cosine(int k, const double *g, const double *inv, const int *pas, int it);

/* y = A^T x for A m x n: NNLS's products (fit_kernels.c). fcm__fit_dgemv_t() takes A
 * column-major (leading dimension lda), fcm__fit_sgemv_rows() by rows (row i at A + i ldr),
 * each y_j then the sum over the rows in their order, as the plain loop gives it bit for bit. */
void fcm__fit_dgemv_t(int m, int n, const double *A, int lda, const double *x, double *y);
void fcm__fit_sgemv_rows(int m, int n, const float *A, int ldr, const float *x, float *y);

/* Non-negative least squares min ||A x - b||_2, x >= 0 (Lawson and Hanson's active set method
 * with the passive columns' QR factorization updated column by column): A is M x k (ld M), x
 * (k) receives the iterate at which max_i |(b - A x)_i| <= stop (rep->ok = 1) or, when no
 * column lowers the residual any more or after 3 k + M steps, the last one (rep->ok = 0). Its
 * positive entries are linearly independent columns (at most M). With reach > 0 and row 0 of A
 * positive (the moments of the constant function), it also stops (rep->infeasible = 1) once a
 * residual proves that no x >= 0 has max_i |(A x - b)_i| <= reach (a Farkas certificate:
 * y with A^T y <= 0 and b^T y > reach ||y||_1); reach 0: run to optimality. Errors:
 * FCM_ERR_ALLOC. */
fcm_status fcm__simplify_nnls(fcm_ctx *ctx, int M, int k, const double *A, const double *b,
                              double stop, double reach, double *x, fcm__nnls_report *rep);

/* At most M of the n candidate points (x 3) with positive weights whose moments in the basis of
 * box equal b (M entries) to max(tol max|b|, atol): relative, down to the absolute level atol
 * of the moments' own rounding. Not fitting is not an error (ok = 0); errors: FCM_ERR_ALLOC,
 * GLPK's. */
fcm_status fcm__simplify_fit(fcm_ctx *ctx, const fcm__cheb_box *box, int n, const double *pts,
                             const double *b, double tol, double atol, fcm__fit *f);

/* fcm__simplify_fit on the candidates' basis values P (M x n, ld M, column j the basis of
 * fcm__simplify_basis_points at point j): callers fitting several degrees on the same points
 * and box evaluate the basis once at the highest and take the leading rows (the basis is
 * ordered by degree, and its lower-degree values do not depend on the highest degree). */
fcm_status fcm__simplify_fit_basis(fcm_ctx *ctx, int M, int n, const double *P, const double *b,
                                   double tol, double atol, fcm__fit *f);

#endif /* FCM_SIMPLIFY_IMPL_H */
