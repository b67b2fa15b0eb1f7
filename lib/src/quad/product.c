/* Computed rules of strength m: Gauss–Legendre tensor products on the line,
 * quadrilateral and hexahedron; collapsed (conical) Gauss–Jacobi products on the
 * triangle and tetrahedron.
 *
 * Stroud's conical product (Stroud 1971, §2.7; Karniadakis & Sherwin §4.1): the unit
 * tet is the image of [0,1]^3 under x = a, y = b(1-a), z = c(1-a)(1-b), with
 * Jacobian (1-a)^2 (1-b). The Jacobian factors are absorbed into the weights by
 * Gauss–Jacobi rules in a (weight (1-a)^2) and b (weight (1-b)); c is
 * Gauss–Legendre. A monomial of total degree m becomes a polynomial of degree <= m
 * in each of a, b, c, so k = ceil((m+1)/2) points per direction suffice. The
 * triangle is the same with x = a, y = b(1-a) and weight (1-a) in a. */
#include "quad_impl.h"

#include <stdio.h>

/* k-point Gauss–Jacobi rule for the weight (1-u)^alpha on [0, 1]: nodes u[k],
 * 1 - u in om[k] (kept separately for accuracy), weights w[k]. From the rule on
 * [-1, 1] with t = 2u - 1: (1-t)^alpha dt = 2^(alpha+1) (1-u)^alpha du. */
static fcm_status unit_jacobi(fcm_ctx *ctx, int k, int alpha, double *u, double *om, double *w)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm__quad_gauss_jacobi(ctx, k, (double)alpha, 0.0, u, w));
  double scale = 1.0 / (double)(2 << alpha); /* 2^-(alpha+1) */
  for (int i = 0; i < k; i++) {
    om[i] = 0.5 * (1.0 - u[i]);
    u[i] = 0.5 * (1.0 + u[i]);
    w[i] *= scale;
  }
cleanup:
  return st;
}

fcm_status fcm_rule_create_computed(fcm_ctx *ctx, fcm_shape shape, int strength, fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  fcm_rule *r = NULL;
  double *work = NULL;
  int k, dim, n;
  FCM_TRY(ctx, fcm__quad_check_args(ctx, "computed rule", shape, strength, rule));
  k = (strength + 2) / 2; /* ceil((m+1)/2) */
  dim = fcm_shape_dim(shape);
  n = dim == 1 ? k : dim == 2 ? k * k : k * k * k;
  FCM_TRY(ctx, fcm__quad_rule_alloc(ctx, shape, strength, n, FCM_RULE_COMPUTED, &r));
  /* work: per direction d nodes, 1 - node, weights (9 k) */
  FCM_ALLOC(ctx, 9 * (size_t)k, work);
  double *x[3], *om[3], *w[3];
  for (int d = 0; d < 3; d++) {
    x[d] = work + 3 * d * k;
    om[d] = x[d] + k;
    w[d] = om[d] + k;
  }
  double *p = r->points, *wt = r->weights;
  switch (shape) {
  case FCM_SHAPE_LINE:
  case FCM_SHAPE_QUAD:
  case FCM_SHAPE_HEX:
    FCM_TRY(ctx, fcm__quad_gauss_jacobi(ctx, k, 0.0, 0.0, x[0], w[0]));
    for (int i = 0; i < n; i++) {
      int idx = i;
      wt[i] = 1.0;
      for (int d = dim - 1; d >= 0; d--) { /* last coordinate varies fastest */
        int j = idx % k;
        idx /= k;
        p[i * dim + d] = x[0][j];
        wt[i] *= w[0][j];
      }
    }
    snprintf(r->description, sizeof r->description,
             dim == 1 ? "Gauss-Legendre %d" : "Gauss-Legendre %d^%d", k, dim);
    break;
  case FCM_SHAPE_TRI:
    FCM_TRY(ctx, unit_jacobi(ctx, k, 1, x[0], om[0], w[0]));
    FCM_TRY(ctx, unit_jacobi(ctx, k, 0, x[1], om[1], w[1]));
    for (int i = 0; i < k; i++)
      for (int j = 0; j < k; j++) {
        int q = i * k + j;
        p[2 * q + 0] = x[0][i];
        p[2 * q + 1] = x[1][j] * om[0][i];
        wt[q] = w[0][i] * w[1][j];
      }
    snprintf(r->description, sizeof r->description, "collapsed Gauss-Jacobi %d^2", k);
    break;
  case FCM_SHAPE_TET:
    FCM_TRY(ctx, unit_jacobi(ctx, k, 2, x[0], om[0], w[0]));
    FCM_TRY(ctx, unit_jacobi(ctx, k, 1, x[1], om[1], w[1]));
    FCM_TRY(ctx, unit_jacobi(ctx, k, 0, x[2], om[2], w[2]));
    for (int i = 0; i < k; i++)
      for (int j = 0; j < k; j++)
        for (int l = 0; l < k; l++) {
          int q = (i * k + j) * k + l;
          p[3 * q + 0] = x[0][i];
          p[3 * q + 1] = x[1][j] * om[0][i];
          p[3 * q + 2] = x[2][l] * om[0][i] * om[1][j];
          wt[q] = w[0][i] * w[1][j] * w[2][l];
        }
    snprintf(r->description, sizeof r->description, "collapsed Gauss-Jacobi %d^3", k);
    break;
  default:
    FCM_CHECK(0, ctx, FCM_ERR_INTERNAL, "computed rule: shape %d not handled", (int)shape);
  }
  *rule = r;
  r = NULL;
cleanup:
  fcm__free(ctx, work);
  fcm_rule_destroy(&r);
  return st;
}
