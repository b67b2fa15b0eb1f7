/* Orthonormal polynomial bases on the reference shapes, with gradients, so that
 * moment equations of high degree stay well conditioned (never monomials).
 *
 * Line, quadrilateral, hexahedron: products of normalized Legendre polynomials.
 * Triangle and tetrahedron: the Proriol–Koornwinder–Dubiner basis. On the biunit
 * tetrahedron with collapsed coordinates a, b, c it is
 *   P_p(a) ((1-b)/2)^p P_q^(2p+1,0)(b) ((1-c)/2)^(p+q) P_r^(2p+2q+2,0)(c),
 * with squared L2 norm 8 / ((2p+1)(2p+2q+2)(2p+2q+2r+3)). Each factor times its
 * power of the collapse is a polynomial in Cartesian coordinates; the three-term
 * recurrences are run in that "homogenized" form (P_n(t/u) u^n with t, u affine),
 * which has no singularity at the collapsed edges and gives exact gradients. */
#include "quad/rulegen_impl.h"

#include <math.h>

#define NMAX (FCM__ORTHOBASIS_MAX_DEGREE + 1)

int fcm__orthobasis_size(fcm_shape shape, int m)
{
  if (m < 0 || m > FCM__ORTHOBASIS_MAX_DEGREE) return 0;
  switch (shape) {
  case FCM_SHAPE_LINE:
    return m + 1;
  case FCM_SHAPE_TRI:
  case FCM_SHAPE_QUAD:
    return (m + 1) * (m + 2) / 2;
  case FCM_SHAPE_TET:
  case FCM_SHAPE_HEX:
    return (m + 1) * (m + 2) * (m + 3) / 6;
  default:
    return 0;
  }
}

/* Q[n] = P_n^(alpha,0)(t/u) u^n for n = 0..N, where t and u are affine functions
 * with constant gradients dt, du (3 components); dQ[3n + k] = dQ[n]/dx_k. */
static void jacobi_h(int N, double alpha, double t, const double dt[3], double u,
                     const double du[3], double *Q, double *dQ)
{
  Q[0] = 1.0;
  for (int k = 0; k < 3; k++)
    dQ[k] = 0.0;
  if (N < 1) return;
  Q[1] = 0.5 * ((alpha + 2.0) * t + alpha * u);
  for (int k = 0; k < 3; k++)
    dQ[3 + k] = 0.5 * ((alpha + 2.0) * dt[k] + alpha * du[k]);
  for (int n = 1; n < N; n++) {
    double s = 2.0 * n + alpha;
    double den = 2.0 * (n + 1) * (n + alpha + 1.0) * s;
    double a = (s + 1.0) * (s + 2.0) * s / den;
    double b = (s + 1.0) * alpha * alpha / den;
    double c = 2.0 * (n + alpha) * n * (s + 2.0) / den;
    double lin = a * t + b * u;
    Q[n + 1] = lin * Q[n] - c * u * u * Q[n - 1];
    for (int k = 0; k < 3; k++)
      dQ[3 * (n + 1) + k] = (a * dt[k] + b * du[k]) * Q[n] + lin * dQ[3 * n + k] -
                            c * (2.0 * u * du[k] * Q[n - 1] + u * u * dQ[3 * (n - 1) + k]);
  }
}

/* Normalized Legendre sqrt(2n+1) P_n(x) and derivatives, n = 0..N. */
static void legendre(int N, double x, double *L, double *dL)
{
  static const double e0[3] = {1.0, 0.0, 0.0}, zero[3] = {0.0, 0.0, 0.0};
  double dQ[3 * NMAX];
  jacobi_h(N, 0.0, x, e0, 1.0, zero, L, dQ);
  for (int n = 0; n <= N; n++) {
    double c = sqrt(2.0 * n + 1.0);
    L[n] *= c;
    dL[n] = c * dQ[3 * n];
  }
}

static void eval_tensor(int dim, int m, const double *x, double *phi, double *grad, int ldg)
{
  double L[3][NMAX], dL[3][NMAX];
  for (int k = 0; k < dim; k++)
    legendre(m, x[k], L[k], dL[k]);
  int j = 0;
  if (dim == 1) {
    for (int p = 0; p <= m; p++, j++) {
      phi[j] = L[0][p];
      if (grad) grad[j] = dL[0][p];
    }
  } else if (dim == 2) {
    for (int p = 0; p <= m; p++)
      for (int q = 0; p + q <= m; q++, j++) {
        phi[j] = L[0][p] * L[1][q];
        if (grad) {
          grad[j] = dL[0][p] * L[1][q];
          grad[ldg + j] = L[0][p] * dL[1][q];
        }
      }
  } else {
    for (int p = 0; p <= m; p++)
      for (int q = 0; p + q <= m; q++)
        for (int r = 0; p + q + r <= m; r++, j++) {
          phi[j] = L[0][p] * L[1][q] * L[2][r];
          if (grad) {
            grad[j] = dL[0][p] * L[1][q] * L[2][r];
            grad[ldg + j] = L[0][p] * dL[1][q] * L[2][r];
            grad[2 * ldg + j] = L[0][p] * L[1][q] * dL[2][r];
          }
        }
  }
}

/* Unit triangle; biunit coordinates X = 2x - 1 inside. */
static void eval_tri(int m, const double *x, double *phi, double *grad, int ldg)
{
  double F[NMAX], dF[3 * NMAX], G[NMAX], dG[3 * NMAX];
  double X = 2.0 * x[0] - 1.0, Y = 2.0 * x[1] - 1.0;
  const double dtf[3] = {1.0, 0.5, 0.0}, duf[3] = {0.0, -0.5, 0.0};
  const double dtg[3] = {0.0, 1.0, 0.0}, dug[3] = {0.0, 0.0, 0.0};
  jacobi_h(m, 0.0, X + 0.5 * (1.0 + Y), dtf, 0.5 * (1.0 - Y), duf, F, dF);
  int j = 0;
  for (int p = 0; p <= m; p++) {
    jacobi_h(m - p, 2.0 * p + 1.0, Y, dtg, 1.0, dug, G, dG);
    for (int q = 0; p + q <= m; q++, j++) {
      double c = sqrt((2.0 * p + 1.0) * (2.0 * p + 2.0 * q + 2.0) / 2.0);
      phi[j] = c * F[p] * G[q];
      if (grad)
        for (int k = 0; k < 2; k++)
          grad[k * ldg + j] = 2.0 * c * (dF[3 * p + k] * G[q] + F[p] * dG[3 * q + k]);
    }
  }
}

/* Unit tetrahedron; biunit coordinates inside. */
static void eval_tet(int m, const double *x, double *phi, double *grad, int ldg)
{
  double F[NMAX], dF[3 * NMAX], G[NMAX], dG[3 * NMAX], H[NMAX], dH[3 * NMAX];
  double X = 2.0 * x[0] - 1.0, Y = 2.0 * x[1] - 1.0, Z = 2.0 * x[2] - 1.0;
  const double dtf[3] = {1.0, 0.5, 0.5}, duf[3] = {0.0, -0.5, -0.5};
  const double dtg[3] = {0.0, 1.0, 0.5}, dug[3] = {0.0, 0.0, -0.5};
  const double dth[3] = {0.0, 0.0, 1.0}, duh[3] = {0.0, 0.0, 0.0};
  jacobi_h(m, 0.0, 1.0 + X + 0.5 * (Y + Z), dtf, -0.5 * (Y + Z), duf, F, dF);
  int j = 0;
  for (int p = 0; p <= m; p++) {
    jacobi_h(m - p, 2.0 * p + 1.0, 0.5 * (1.0 + 2.0 * Y + Z), dtg, 0.5 * (1.0 - Z), dug, G, dG);
    for (int q = 0; p + q <= m; q++) {
      jacobi_h(m - p - q, 2.0 * p + 2.0 * q + 2.0, Z, dth, 1.0, duh, H, dH);
      for (int r = 0; p + q + r <= m; r++, j++) {
        double c = sqrt((2.0 * p + 1.0) * (2.0 * p + 2.0 * q + 2.0) *
                        (2.0 * p + 2.0 * q + 2.0 * r + 3.0) / 6.0);
        phi[j] = c * F[p] * G[q] * H[r];
        if (grad)
          for (int k = 0; k < 3; k++)
            grad[k * ldg + j] = 2.0 * c *
                                (dF[3 * p + k] * G[q] * H[r] + F[p] * dG[3 * q + k] * H[r] +
                                 F[p] * G[q] * dH[3 * r + k]);
      }
    }
  }
}

void fcm__orthobasis_eval(fcm_shape shape, int m, const double *x, double *phi, double *grad,
                          int ldg)
{
  switch (shape) {
  case FCM_SHAPE_LINE:
    eval_tensor(1, m, x, phi, grad, ldg);
    break;
  case FCM_SHAPE_QUAD:
    eval_tensor(2, m, x, phi, grad, ldg);
    break;
  case FCM_SHAPE_HEX:
    eval_tensor(3, m, x, phi, grad, ldg);
    break;
  case FCM_SHAPE_TRI:
    eval_tri(m, x, phi, grad, ldg);
    break;
  case FCM_SHAPE_TET:
    eval_tet(m, x, phi, grad, ldg);
    break;
  default:
    break;
  }
}
