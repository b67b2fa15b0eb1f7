/* Inverse geometric map xi(x) of an element: closed form for affine cells,
 * Newton's method with a backtracking line search otherwise. */
#include "element/element_impl.h"
#include "core/core_impl.h"
#include "la/mat3.h"
#include "la/vec3.h"

#include <math.h>

#define INV_MAX_ITER     50    /* Newton iterations */
#define INV_RTOL         1e-13 /* residual tolerance relative to the cell size */
#define INV_AFFINE_RTOL  1e-13 /* nodes this close to an affine map: closed form */
#define INV_SINGULAR     1e-12 /* |det J| <= this * |J|_F^3 counts as singular */
#define INV_MAX_HALVINGS 30    /* backtracking steps per Newton iteration */
#define INV_ARMIJO       1e-4  /* sufficient decrease of |r| */

/* r = x(xi) - b in coordinates relative to node 0 (Xl), so that round-off is
 * relative to the cell size and not to the distance from the origin. */
static double residual(fcm_element_type type, const double *Xl, const double b[3],
                       const double xi[3], double r[3])
{
  double y[3];
  fcm_element_map(type, Xl, xi, y);
  r[0] = y[0] - b[0], r[1] = y[1] - b[1], r[2] = y[2] - b[2];
  return fcm__vec3_norm(r);
}

static int singular(double det, const double J[9])
{
  const double s = fcm__mat3_norm(J);
  return !isfinite(det) || !(fabs(det) > INV_SINGULAR * s * s * s);
}

fcm_status fcm_element_inverse_map(fcm_ctx *ctx, fcm_element_type type, const double *X,
                                   const double x[3], double xi[3])
{
  fcm_status st = FCM_OK;
  const fcm_element_info *info = fcm_element_get_info(type);
  double Xl[3 * FCM_ELEMENT_MAX_NODES], b[3], J[9], Jinv[9], r[3], dxi[3], xt[3], rt[3];
  double h = 0.0, tol = 0.0, rn = 0.0, det = 0.0;
  const char *name = "element";
  int n = 0, it = 0, stalled = 0;

  FCM_CHECK(info, ctx, FCM_ERR_ARG, "element inverse map: type %d out of range [0,%d)", (int)type,
            (int)FCM_ELEMENT_COUNT);
  name = info->name;
  n = info->num_nodes;
  FCM_CHECK(X && x && xi, ctx, FCM_ERR_ARG,
            "%s inverse map: NULL argument (X, x and xi are required)", name);
  FCM_CHECK(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]), ctx, FCM_ERR_ARG,
            "%s inverse map: point x = (%g, %g, %g) is not finite", name, x[0], x[1], x[2]);
  for (int a = 0; a < n; a++)
    for (int d = 0; d < 3; d++)
      Xl[3 * a + d] = X[3 * a + d] - X[d];
  for (int d = 0; d < 3; d++)
    b[d] = x[d] - X[d];
  h = fcm__element_cell_size(n, X);
  FCM_CHECK(isfinite(h) && h > 0.0, ctx, FCM_ERR_GEOMETRY,
            "%s inverse map: cell size %g (bounding-box diagonal) must be positive and finite",
            name, h);
  tol = INV_RTOL * h;

  if (fcm_element_is_affine(type, Xl, INV_AFFINE_RTOL)) {
    double xi0[3];
    fcm__element_corner_affine(type, Xl, J, xi0);
    det = fcm__mat3_inv(J, Jinv);
    FCM_CHECK(!singular(det, J), ctx, FCM_ERR_GEOMETRY,
              "%s inverse map: degenerate affine cell (det J = %g, |J|^3 = %g, cell size %g) "
              "at x = (%g, %g, %g)",
              name, det, pow(fcm__mat3_norm(J), 3.0), h, x[0], x[1], x[2]);
    fcm__mat3_mulv(Jinv, b, xi);
    for (int d = 0; d < 3; d++)
      xi[d] += xi0[d];
    goto cleanup; /* exact up to round-off, also far outside the cell */
  }

  xi[0] = xi[1] = xi[2] = info->shape == FCM_SHAPE_TET ? 0.25 : 0.0;

  rn = residual(type, Xl, b, xi, r);
  for (it = 0; it < INV_MAX_ITER && !(rn <= tol); it++) {
    det = fcm_element_jacobian(type, Xl, xi, J);
    FCM_CHECK(!singular(det, J), ctx, FCM_ERR_GEOMETRY,
              "%s inverse map: singular Jacobian (det J = %g, cell size %g) at xi = (%g, %g, %g) "
              "in Newton iteration %d for x = (%g, %g, %g), residual %.3g",
              name, det, h, xi[0], xi[1], xi[2], it, x[0], x[1], x[2], rn);
    fcm__mat3_inv(J, Jinv);
    fcm__mat3_mulv(Jinv, r, dxi);
    double alpha = 1.0, rtn = 0.0;
    int k = 0;
    for (k = 0; k < INV_MAX_HALVINGS; k++, alpha *= 0.5) {
      for (int d = 0; d < 3; d++)
        xt[d] = xi[d] - alpha * dxi[d];
      rtn = residual(type, Xl, b, xt, rt);
      if (rtn <= (1.0 - INV_ARMIJO * alpha) * rn) break;
    }
    if (k == INV_MAX_HALVINGS) {
      stalled = 1; /* no decrease along the Newton direction: a local minimum of |r| */
      break;
    }
    for (int d = 0; d < 3; d++)
      xi[d] = xt[d], r[d] = rt[d];
    rn = rtn;
  }
  FCM_CHECK(rn <= tol, ctx, FCM_ERR_NOT_CONVERGED,
            "%s inverse map: no convergence for x = (%g, %g, %g) after %d Newton iterations "
            "(%s): residual %.3g > tolerance %.3g (1e-13 x cell size), last xi = (%g, %g, %g)",
            name, x[0], x[1], x[2], it, stalled ? "line search stalled" : "iteration limit", rn,
            tol, xi[0], xi[1], xi[2]);
cleanup:
  return st;
}
