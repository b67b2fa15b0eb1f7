/* fcm — quadrature rule simplification (at most M positive points that keep every
 * moment of total degree <= m; Longva et al. 2020 §4.4) and cut-cell stabilization. */
#ifndef FCM_SIMPLIFY_H
#define FCM_SIMPLIFY_H

#include "fcm/core.h"
#include "fcm/quad.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest strength fcm_simplify() accepts (M = 1771 basis functions). */
#define FCM_SIMPLIFY_MAX_STRENGTH 20

/** Which algorithm selects the kept points. */
typedef enum fcm_simplify_method {
  FCM_SIMPLIFY_AUTO = 0,  /**< the measured default: FCM_SIMPLIFY_ELIMINATE */
  FCM_SIMPLIFY_LP,        /**< thin SVD of P, one LP on all N points */
  FCM_SIMPLIFY_RECOMBINE, /**< hierarchical recombination: small LPs on cluster moments */
  FCM_SIMPLIFY_ELIMINATE, /**< Carathéodory elimination along null vectors of an LU tableau,
                               on all points or inside recombination rounds (default) */
  FCM_SIMPLIFY_METHOD_COUNT
} fcm_simplify_method;

/** Why an attempt failed (the first failure is kept in fcm_simplify_info.reason). */
typedef enum fcm_simplify_reason {
  FCM_SIMPLIFY_REASON_NONE = 0,     /**< no attempt failed */
  FCM_SIMPLIFY_REASON_LP,           /**< GLPK returned an error code or a non-feasible status */
  FCM_SIMPLIFY_REASON_LP_ERROR,     /**< GLPK hit a fatal error (caught by its error hook) */
  FCM_SIMPLIFY_REASON_NUMERIC,      /**< SVD or least squares failed, or a non-finite value */
  FCM_SIMPLIFY_REASON_NOT_POSITIVE, /**< no positive weights on the support */
  FCM_SIMPLIFY_REASON_RESIDUAL,     /**< moment residual above the tolerance */
  FCM_SIMPLIFY_REASON_COUNT,        /**< more than M points (a broken vertex) */
  FCM_SIMPLIFY_REASON_NO_PROGRESS   /**< a recombination round removed nothing */
} fcm_simplify_reason;

/** Options of fcm_simplify(); initialize with fcm_simplify_options_default(). */
typedef struct fcm_simplify_options {
  fcm_simplify_method method; /**< default FCM_SIMPLIFY_AUTO */
  double rank_tol;        /**< singular values <= rank_tol * s_max count as zero; default 1e-13 */
  double residual_tol;    /**< accepted relative moment residual; default 1e-12 */
  int lp_iteration_limit; /**< simplex iterations per LP, >= 1; FCM_DEFAULT (default):
                               20 M + 1000 */
  double lp_time_limit;   /**< seconds per LP; 0: none; default 60 */
  int elimination_block;  /**< ELIMINATE: null-space directions taken per blocked tableau update
                               (their rank-1 updates applied together as one matrix product),
                               1 ... 256; 1: one at a time, a rank-1 update per pivot (the
                               unblocked elimination, kept to measure against); FCM_DEFAULT
                               (default): 32 (measured: lib/docs/performance.md) */
  int axis_degree;        /**< the moments kept: those of the polynomials of total degree <=
                               strength whose degree in each variable is <= axis_degree, so
                               M = #{(a, b, c): a + b + c <= strength, a, b, c <= axis_degree}
                               (axis_degree = k, strength >= 3k: the tensor space Q_k, (k+1)^3
                               functions; a Hex8 cell's consistent mass N_i N_j lies in Q_2);
                               0 ... 20; FCM_DEFAULT (default) or a value >= strength: every
                               polynomial of total degree <= strength */
} fcm_simplify_options;

/** The simplified rule: a subset of the input points with new weights. */
typedef struct fcm_simplify_result {
  fcm_ctx *ctx;       /**< the arrays were allocated through this context */
  fcm_index count;    /**< number of kept points */
  fcm_index *indices; /**< count indices into the input, ascending */
  double *weights;    /**< count new weights, all > 0 */
} fcm_simplify_result;

/** What fcm_simplify() did. Times in seconds. */
typedef struct fcm_simplify_info {
  fcm_index n;                     /**< input points N */
  int num_basis;                   /**< M = (m+3 choose 3), fewer with axis_degree < m */
  int rank;                        /**< numerical rank of the moment matrix used last */
  fcm_index kept;                  /**< points returned */
  double residual;                 /**< max |P w - P w0| / max |P w0| of the returned rule
                                        (box-scaled Chebyshev basis); 0 when returned unchanged */
  long long lp_iterations;         /**< simplex iterations over all LPs */
  int num_lps;                     /**< LPs solved */
  int num_eliminations;            /**< Carathéodory eliminations (one per round or solve) */
  int rounds;                      /**< recombination rounds (not counting the final LP) */
  int attempts;                    /**< attempts made; 1 when the first succeeded */
  fcm_simplify_method method_used; /**< path of the last attempt (AUTO when none ran) */
  int skipped;                     /**< 1: N <= M, input returned unchanged, or at most M points
                                        of positive weight, returned without the others */
  int fallback;                    /**< 1: every attempt failed, input returned unchanged */
  fcm_simplify_reason reason;      /**< first failure; NONE if none */
  char message[320];               /**< account of the failed attempts ("" if none) */
  /** Seconds in: the basis and moments; SVDs and LU factorizations; LPs and eliminations;
   * the least-squares re-fit and verification; the whole call. */
  double time_basis, time_svd, time_lp, time_refit, time_total;
  /** Floating-point operations of the eliminations' LU factorizations, triangular solves and
   * tableau updates (0 on the GLPK paths): the arithmetic of the algorithm, not of the basis
   * evaluation or the verification. */
  double flops;
} fcm_simplify_info;

/** Defaults: AUTO, rank_tol 1e-13, residual_tol 1e-12, automatic iteration limit, 60 s,
 * the measured elimination block, every degree (axis_degree FCM_DEFAULT). */
FCM_API fcm_simplify_options fcm_simplify_options_default(void);

/** Reduce a positive rule to at most M = (m+3 choose 3) of its own points with positive
 * weights reproducing every moment of total degree <= strength (lib/METHOD.md §6); with
 * opts->axis_degree = q < strength only those of degree <= q in each variable, M of them.
 * Every returned rule is verified (weights > 0, count <= M, relative residual <=
 * residual_tol); if all attempts (the chosen path; a GLPK path: the other GLPK path for LP
 * or RECOMBINE, for ELIMINATE the LP up to N = 12 M and recombination above; the chosen
 * path with a looser rank threshold) fail, the input is returned unchanged with info->fallback = 1
 * and FCM_OK: the caller decides and counts; the fallback is also logged at FCM_LOG_WARNING through
 * the ctx's log callback (with the account of info->message). N <= M also returns the input
 * (info->skipped). Points of zero weight are never kept.
 * @param[in] points  n x 3 reference coordinates (row-major); @param[in] weights n, >= 0
 * @param[in] opts NULL for defaults; @param[out] out release with fcm_simplify_result_destroy()
 * @param[out] info may be NULL
 * @return FCM_OK, FCM_ERR_ARG (n < 1, NULL arrays, non-finite values, negative weights, zero
 *         total weight, strength outside [0, 20], bad options), FCM_ERR_ALLOC. On error *out
 *         is empty. Allocates through ctx (GLPK allocates its own). Thread safe: call
 *         concurrently on different cells (GLPK 5.0 state is per thread). GLPK's terminal
 *         and error hooks of the calling thread are reset; after a caught GLPK fatal error
 *         that thread's GLPK environment is freed (glp_free_env). */
FCM_API fcm_status fcm_simplify(fcm_ctx *ctx, int strength, fcm_index n, const double *points,
                                const double *weights, const fcm_simplify_options *opts,
                                fcm_simplify_result *out, fcm_simplify_info *info);

/** Model of the core-seconds fcm_simplify()'s default path takes for n points at this
 * strength: 2.5e-9 N M + 6.6e-10 M^3 for N > M (0 otherwise), M = (strength+3 choose 3),
 * fitted to simplify_bench on one core of the development machine (M = 20 ... 286,
 * N = 72 ... 110,592; within a factor 2 of each case). Deterministic, for cost decisions
 * (FCM_CELL_SIMPLIFY_AUTO); a strength outside [0, 20] or n < 0 gives 0. */
FCM_API double fcm_simplify_cost_estimate(int strength, fcm_index n);

/** Release the arrays of a result and zero it; accepts NULL and an empty result. */
FCM_API void fcm_simplify_result_destroy(fcm_simplify_result *res);

/** Static name of a method ("auto", "lp", "recombine") or reason ("none", "lp", ...). */
FCM_API const char *fcm_simplify_method_name(fcm_simplify_method method);
FCM_API const char *fcm_simplify_reason_name(fcm_simplify_reason reason);

/* ---- stabilization (lib/METHOD.md §7) ---- */

/** Which matrices receive the fictitious stabilization points of cut cells. */
typedef enum fcm_stabilization_mode {
  FCM_STABILIZATION_MASS_STIFFNESS = 0, /**< mass and stiffness (default) */
  FCM_STABILIZATION_MASS,               /**< mass only (enough with direct solvers) */
  FCM_STABILIZATION_OFF,                /**< none */
  FCM_STABILIZATION_MODE_COUNT
} fcm_stabilization_mode;

/** Stabilization settings; initialize with fcm_stabilization_options_default(). */
typedef struct fcm_stabilization_options {
  fcm_stabilization_mode mode; /**< default FCM_STABILIZATION_MASS_STIFFNESS */
  double alpha;                /**< weight factor, default 1e-6 (the authors' scenes: 1e-8) */
} fcm_stabilization_options;

/** Defaults: mass and stiffness, alpha = 1e-6. */
FCM_API fcm_stabilization_options fcm_stabilization_options_default(void);

/** Append the full cell's rule with weights x alpha after a cut cell's (simplified) points,
 * flagged fictitious, so the simplified part keeps all its points inside the geometry.
 * Mode OFF appends nothing. Entries [*n, *n + rule points) of points (x3), weights and
 * fictitious (1; may be NULL) are written and *n advanced.
 * @param[in] opts NULL for defaults; @param[in] full_rule a 3-D rule (tet or hex), e.g. from
 *        fcm_rule_create(); @param[in] capacity entries available in the arrays
 * @return FCM_OK, FCM_ERR_ARG (NULL arguments, rule not 3-D, mode invalid, alpha not finite or
 *         <= 0 (unless OFF), capacity too small: nothing written). No allocation; thread safe. */
FCM_API fcm_status fcm_stabilization_append(fcm_ctx *ctx, const fcm_stabilization_options *opts,
                                            const fcm_rule *full_rule, fcm_index capacity,
                                            fcm_index *n, double *points, double *weights,
                                            unsigned char *fictitious);

#ifdef __cplusplus
}
#endif
#endif /* FCM_SIMPLIFY_H */
