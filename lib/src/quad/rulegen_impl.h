/* fcm quad, internal part of rule generation: orthonormal polynomial bases on the
 * reference shapes (values and gradients) used by node elimination and its tests. */
#ifndef FCM_RULEGEN_IMPL_H
#define FCM_RULEGEN_IMPL_H

#include "core/core_impl.h"
#include "fcm/element.h"
#include "fcm/rulegen.h"

/* Largest degree of fcm__orthobasis_eval (the recurrences use fixed buffers). */
#define FCM__ORTHOBASIS_MAX_DEGREE 40

/* Number of polynomials of total degree <= m on `shape` (binom(m + d, d));
 * 0 for an invalid shape or m outside [0, FCM__ORTHOBASIS_MAX_DEGREE]. */
int fcm__orthobasis_size(fcm_shape shape, int m);

/* Evaluate at one point x (reference coordinates of `shape`, length dim) the
 * basis of total degree <= m that is orthonormal for the uniform probability
 * measure on the shape (so phi[0] = 1 and the exact moments are e_0):
 * Legendre products on line/quad/hex, Proriol–Koornwinder–Dubiner on tri/tet.
 * phi receives fcm__orthobasis_size(shape, m) values; grad (may be NULL) receives
 * the gradients, component k of function j at grad[k * ldg + j] (ldg >= size).
 * No allocation; thread safe. Arguments are not validated. */
void fcm__orthobasis_eval(fcm_shape shape, int m, const double *x, double *phi, double *grad,
                          int ldg);

/* Node elimination on raw arrays (the engine of fcm_rule_eliminate_nodes):
 * start with n0 points x0 (n0 x dim, reference coordinates) and weights w0
 * (summing to the measure of the shape), already checked to be positive,
 * interior and exact. On success *n, *x and *w (allocated through ctx, caller
 * frees) hold the result, weights again summing to the measure. opts and info
 * must not be NULL. FCM_ERR_NOT_CONVERGED when the start cannot be polished. */
fcm_status fcm__rulegen_eliminate(fcm_ctx *ctx, fcm_shape shape, int m, int n0, const double *x0,
                                  const double *w0, const fcm_rulegen_options *opts,
                                  fcm_rulegen_info *info, int *n, double **x, double **w);

/* Max relative moment residual (orthonormal basis, exact moments e_0) of the n
 * points x with weights w summing to the measure; -1 on allocation failure. */
double fcm__rulegen_residual(fcm_ctx *ctx, fcm_shape shape, int m, int n, const double *x,
                             const double *w);

/* Smallest Euclidean distance of the n points x to the boundary of the reference
 * shape (negative when a point lies outside). */
double fcm__rulegen_min_distance(fcm_shape shape, int n, const double *x);

#endif /* FCM_RULEGEN_IMPL_H */
