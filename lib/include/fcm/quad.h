/* fcm — standard quadrature rules: Gauss–Legendre and Gauss–Jacobi on the line,
 * tensor rules on the quadrilateral and hexahedron, collapsed (conical) rules on
 * the triangle and tetrahedron, and the rule catalogue. "Strength m" means exact
 * for every polynomial of total degree <= m on the reference shape. */
#ifndef FCM_QUAD_H
#define FCM_QUAD_H

#include "fcm/core.h"
#include "fcm/element.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest strength the computed rules support. */
#define FCM_RULE_MAX_STRENGTH 40

/** A quadrature rule on a reference shape: points (num_points x dim, row-major,
 * dim = fcm_shape_dim(shape)) and weights. Immutable once created. */
typedef struct fcm_rule fcm_rule;

/** How the points and weights of a rule were obtained. */
typedef enum fcm_rule_origin {
  FCM_RULE_COMPUTED = 0, /**< Gauss tensor or collapsed conical product, computed at run time */
  FCM_RULE_TABLE,        /**< stored table from quadrature_tables/ (compiled in) */
  FCM_RULE_USER          /**< supplied by the caller */
} fcm_rule_origin;

/** The catalogue rule of strength m on `shape`: the stored table when one exists,
 * otherwise the computed rule (fcm_rule_create_computed).
 * @return FCM_OK, FCM_ERR_ARG (shape invalid or m outside [0, FCM_RULE_MAX_STRENGTH]),
 *         FCM_ERR_ALLOC. Allocates *rule; release with fcm_rule_destroy(). Thread safe. */
FCM_API fcm_status fcm_rule_create(fcm_ctx *ctx, fcm_shape shape, int strength, fcm_rule **rule);

/** The computed rule of strength m: Gauss–Legendre tensor with ceil((m+1)/2)
 * points per direction on line/quad/hex; collapsed Gauss–Jacobi product with the
 * same count per direction on tri/tet. Positive weights, interior points.
 * Errors and allocation as fcm_rule_create(). */
FCM_API fcm_status fcm_rule_create_computed(fcm_ctx *ctx, fcm_shape shape, int strength,
                                            fcm_rule **rule);

/** n-point Gauss–Jacobi rule on [-1, 1] for the weight (1-x)^alpha (1+x)^beta
 * (alpha, beta > -1), exact for degree 2n-1; alpha = beta = 0 is Gauss–Legendre.
 * Nodes ascending. @return FCM_OK, FCM_ERR_ARG (n < 1 or n > 200, alpha or beta <= -1
 * or not finite, weight mass not representable), FCM_ERR_LAPACK, FCM_ERR_NUMERIC (a node or
 * weight came out non-finite, non-positive or outside the interval), FCM_ERR_ALLOC.
 * The rule's shape is FCM_SHAPE_LINE and its strength 2n-1 (degree, against the weight). */
FCM_API fcm_status fcm_rule_create_gauss_jacobi(fcm_ctx *ctx, int n, double alpha, double beta,
                                                fcm_rule **rule);

/** Copy caller arrays into a new rule (origin FCM_RULE_USER).
 * @param[in] points  n x dim coordinates; @param[in] weights n weights.
 * n = 0 (NULL arrays allowed) gives an empty rule.
 * @return FCM_OK, FCM_ERR_ARG (shape invalid, strength outside [0, FCM_RULE_MAX_STRENGTH],
 *         n < 0, NULL arrays with n > 0, non-finite values), FCM_ERR_ALLOC. */
FCM_API fcm_status fcm_rule_create_from_arrays(fcm_ctx *ctx, fcm_shape shape, int strength, int n,
                                               const double *points, const double *weights,
                                               fcm_rule **rule);

/** Destroy a rule; accepts NULL and sets *rule = NULL. */
FCM_API void fcm_rule_destroy(fcm_rule **rule);

/** Accessors; pointers stay valid for the life of the rule. */
FCM_API fcm_shape fcm_rule_shape(const fcm_rule *rule);
FCM_API int fcm_rule_strength(const fcm_rule *rule);
FCM_API int fcm_rule_num_points(const fcm_rule *rule);
FCM_API const double *fcm_rule_points(const fcm_rule *rule);
FCM_API const double *fcm_rule_weights(const fcm_rule *rule);
FCM_API fcm_rule_origin fcm_rule_get_origin(const fcm_rule *rule);
/** One-line description of how the rule was made ("Gauss-Legendre 3^3", a table header line, ...).
 */
FCM_API const char *fcm_rule_description(const fcm_rule *rule);

/** Print shape, strength, count, origin and (with `full`) every point and weight. */
FCM_API void fcm_rule_view(const fcm_rule *rule, int full, FILE *stream);

#ifdef __cplusplus
}
#endif
#endif /* FCM_QUAD_H */
