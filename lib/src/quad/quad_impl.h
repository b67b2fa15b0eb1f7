/* fcm quad, internal part: the rule object layout and the helpers other files
 * and modules use to build rules (1-D Gauss–Jacobi, the compiled-in table hook). */
#ifndef FCM_QUAD_IMPL_H
#define FCM_QUAD_IMPL_H

#include "core/core_impl.h"
#include "fcm/quad.h"

/* Capacity of a rule's description, including the terminating NUL. */
#define FCM__RULE_DESC_LEN 128

/* Largest number of points of fcm_rule_create_gauss_jacobi(). */
#define FCM__GAUSS_JACOBI_MAX_POINTS 200

struct fcm_rule {
  fcm_ctx *ctx;           /* allocated through this context; destroy releases there */
  fcm_shape shape;        /* reference shape */
  int dim;                /* fcm_shape_dim(shape) */
  int strength;           /* exact for total degree <= strength (Gauss–Jacobi: 2n-1) */
  int n;                  /* number of points */
  fcm_rule_origin origin; /* computed, table or user */
  double *points;         /* n x dim, row-major */
  double *weights;        /* n */
  char description[FCM__RULE_DESC_LEN];
};

/* Allocate a rule with zeroed arrays for n points on `shape` (n >= 0) and an empty
 * description; the caller fills points, weights and description. Arguments are
 * not validated beyond the shape. On failure *rule = NULL and nothing leaks. */
fcm_status fcm__quad_rule_alloc(fcm_ctx *ctx, fcm_shape shape, int strength, int n,
                                fcm_rule_origin origin, fcm_rule **rule);

/* Argument checks shared by the rule constructors: rule != NULL (then *rule = NULL),
 * ctx != NULL, shape valid, strength in [0, FCM_RULE_MAX_STRENGTH]. `who` names
 * the caller in messages. */
fcm_status fcm__quad_check_args(fcm_ctx *ctx, const char *who, fcm_shape shape, int strength,
                                fcm_rule **rule);

/* n-point Gauss–Jacobi nodes x[n] (ascending) and weights w[n] on [-1, 1] for the
 * weight (1-x)^alpha (1+x)^beta: Golub–Welsch (LAPACK dstev) followed by Newton
 * polishing of each node and Christoffel-function weights. Validates
 * 1 <= n <= FCM__GAUSS_JACOBI_MAX_POINTS and alpha, beta > -1 (FCM_ERR_ARG).
 * Allocates O(n^2) workspace; thread safe. */
fcm_status fcm__quad_gauss_jacobi(fcm_ctx *ctx, int n, double alpha, double beta, double *x,
                                  double *w);

/* Compiled-in rule table for (shape, strength) from quadrature_tables/: on success
 * returns 1 and sets *n, *points (n x dim, row-major), *weights and *description
 * to static data; returns 0 when no table exists (outputs untouched). No
 * allocation; thread safe. Implemented in tables.c. */
int fcm__quad_table_lookup(fcm_shape shape, int strength, int *n, const double **points,
                           const double **weights, const char **description);

#endif /* FCM_QUAD_IMPL_H */
