/* fcm — generation of small positive interior quadrature rules by node
 * elimination (Xiao & Gimbutas 2010): an offline tool behind quadrature_tables/,
 * also usable at run time for low strengths. */
#ifndef FCM_RULEGEN_H
#define FCM_RULEGEN_H

#include "fcm/core.h"
#include "fcm/quad.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Progress of a running elimination, passed to the progress callback. */
typedef struct fcm_rulegen_info {
  int initial_points;   /**< points of the start rule */
  int num_points;       /**< points of the current (final, on return) rule */
  int removals;         /**< accepted removal steps (a step may remove several points) */
  int failed_attempts;  /**< removal attempts whose solve did not converge */
  long long iterations; /**< Levenberg–Marquardt iterations, all attempts */
  double residual;   /**< max_j |sum_i w_i phi_j(x_i) - int phi_j| / int phi_0 (orthonormal phi) */
  double min_weight; /**< smallest weight divided by the mean weight */
  double min_distance; /**< smallest distance of a point to the boundary of the shape */
  double seconds;      /**< wall time so far */
} fcm_rulegen_info;

/** Progress callback, called after every accepted removal (from the calling thread). */
typedef void (*fcm_rulegen_progress_fn)(void *user, const fcm_rulegen_info *info);

/** Options of fcm_rule_eliminate_nodes(); initialize with fcm_rulegen_options_default(). */
typedef struct fcm_rulegen_options {
  double tol;         /**< accept a removal when the relative moment residual <= tol (1e-14) */
  int max_iterations; /**< Levenberg–Marquardt iterations per attempt (60) */
  int max_candidates; /**< single points tried, least significant first, before stopping (12) */
  int target_points;  /**< stop at or below this many points (0: as few as possible) */
  double max_batch;   /**< while unknowns exceed 1.25 x moments, remove up to this fraction of
                           the points at once (0.05; 0 removes one point at a time) */
  double margin;      /**< points keep this distance from the boundary (1e-9) */
  fcm_rulegen_progress_fn progress; /**< NULL: none */
  void *progress_user;              /**< passed to `progress` */
} fcm_rulegen_options;

/** Default options (see the member comments). */
FCM_API fcm_rulegen_options fcm_rulegen_options_default(void);

/** Node elimination: starting from `start` (positive weights, interior points, exact
 * for `strength`), repeatedly remove the least significant point(s) (w_i sum_j
 * phi_j(x_i)^2) and restore exactness by damped Gauss–Newton (Levenberg–Marquardt)
 * on points and weights in an orthonormal basis, keeping weights positive and points
 * inside; a removal is kept only when the residual returns below opts->tol.
 * @param[in]  start    rule on FCM_SHAPE_LINE/TRI/QUAD/TET/HEX; not modified
 * @param[in]  strength 0 <= strength <= min(fcm_rule_strength(start), 40)
 * @param[in]  opts     NULL for defaults; @param[out] info may be NULL
 * @param[out] out      new rule (origin FCM_RULE_COMPUTED); NULL on failure
 * @return FCM_OK, FCM_ERR_ARG (bad shape/strength/options, start not positive, not
 *         interior or not exact), FCM_ERR_NOT_CONVERGED (start rule cannot be polished
 *         to tol), FCM_ERR_LAPACK, FCM_ERR_ALLOC. Allocates O(M n) memory for M moments
 *         and n points; uses OpenMP and BLAS threads. Thread safe for distinct outputs. */
FCM_API fcm_status fcm_rule_eliminate_nodes(fcm_ctx *ctx, const fcm_rule *start, int strength,
                                            const fcm_rulegen_options *opts, fcm_rulegen_info *info,
                                            fcm_rule **out);

/** Relative moment residual of `rule` for `strength` in the orthonormal basis used
 * by fcm_rule_eliminate_nodes() (the number it reports as `residual`).
 * @return FCM_OK, FCM_ERR_ARG (shape unsupported, strength outside [0, 40]),
 *         FCM_ERR_ALLOC. Allocates O(M) workspace; thread safe. */
FCM_API fcm_status fcm_rule_moment_residual(fcm_ctx *ctx, const fcm_rule *rule, int strength,
                                            double *residual);

#ifdef __cplusplus
}
#endif
#endif /* FCM_RULEGEN_H */
