/* Shape functions of the trilinear (Hex8) and 20-node serendipity (Hex20)
 * hexahedra on [-1,1]^3, VTK node ordering (see fcm/element.h). */
#include "element/element_impl.h"

/* The kernels below are static inline helpers called with literal node signs;
 * after inlining every node is straight-line arithmetic without branches.
 * Notation: xm = 1 - xi, xp = 1 + xi (same for eta, zeta). */

/* Hex8 corner with signs (s, t, u): N = (1 + s xi)(1 + t eta)(1 + u zeta) / 8. */
static inline void hex8_grad(double ax, double ay, double az, double s, double t, double u,
                             double *g)
{
  g[0] = 0.125 * s * ay * az;
  g[1] = 0.125 * t * ax * az;
  g[2] = 0.125 * u * ax * ay;
}

void fcm__element_shape_hex8(const double xi[3], double N[8])
{
  const double xm = 1.0 - xi[0], xp = 1.0 + xi[0];
  const double ym = 1.0 - xi[1], yp = 1.0 + xi[1];
  const double zm = 0.125 * (1.0 - xi[2]), zp = 0.125 * (1.0 + xi[2]);
  const double mm = xm * ym, pm = xp * ym, pp = xp * yp, mp = xm * yp;
  N[0] = mm * zm;
  N[1] = pm * zm;
  N[2] = pp * zm;
  N[3] = mp * zm;
  N[4] = mm * zp;
  N[5] = pm * zp;
  N[6] = pp * zp;
  N[7] = mp * zp;
}

void fcm__element_grad_hex8(const double xi[3], double dN[24])
{
  const double xm = 1.0 - xi[0], xp = 1.0 + xi[0];
  const double ym = 1.0 - xi[1], yp = 1.0 + xi[1];
  const double zm = 1.0 - xi[2], zp = 1.0 + xi[2];
  hex8_grad(xm, ym, zm, -1.0, -1.0, -1.0, dN + 0);
  hex8_grad(xp, ym, zm, +1.0, -1.0, -1.0, dN + 3);
  hex8_grad(xp, yp, zm, +1.0, +1.0, -1.0, dN + 6);
  hex8_grad(xm, yp, zm, -1.0, +1.0, -1.0, dN + 9);
  hex8_grad(xm, ym, zp, -1.0, -1.0, +1.0, dN + 12);
  hex8_grad(xp, ym, zp, +1.0, -1.0, +1.0, dN + 15);
  hex8_grad(xp, yp, zp, +1.0, +1.0, +1.0, dN + 18);
  hex8_grad(xm, yp, zp, -1.0, +1.0, +1.0, dN + 21);
}

/* Hex20 corner (s, t, u): N = (1+s xi)(1+t eta)(1+u zeta)(s xi + t eta + u zeta - 2) / 8,
 * where ax = 1 + s xi etc.; dN/dxi = s (1+t eta)(1+u zeta)(2 s xi + t eta + u zeta - 1) / 8. */
static inline double hex20_corner(const double xi[3], double ax, double ay, double az, double s,
                                  double t, double u)
{
  return 0.125 * ax * ay * az * (s * xi[0] + t * xi[1] + u * xi[2] - 2.0);
}

static inline void hex20_corner_grad(const double xi[3], double ax, double ay, double az, double s,
                                     double t, double u, double *g)
{
  const double q = s * xi[0] + t * xi[1] + u * xi[2] - 1.0;
  g[0] = 0.125 * s * ay * az * (q + s * xi[0]);
  g[1] = 0.125 * t * ax * az * (q + t * xi[1]);
  g[2] = 0.125 * u * ax * ay * (q + u * xi[2]);
}

/* Mid-edge nodes: (1 - xi^2)(1 + t eta)(1 + u zeta) / 4 on edges along xi, and
 * the same with the roles of the coordinates permuted. */

void fcm__element_shape_hex20(const double xi[3], double N[20])
{
  const double x = xi[0], y = xi[1], z = xi[2];
  const double xm = 1.0 - x, xp = 1.0 + x, ym = 1.0 - y, yp = 1.0 + y, zm = 1.0 - z, zp = 1.0 + z;
  const double x2 = 0.25 * (1.0 - x * x), y2 = 0.25 * (1.0 - y * y), z2 = 0.25 * (1.0 - z * z);
  N[0] = hex20_corner(xi, xm, ym, zm, -1.0, -1.0, -1.0);
  N[1] = hex20_corner(xi, xp, ym, zm, +1.0, -1.0, -1.0);
  N[2] = hex20_corner(xi, xp, yp, zm, +1.0, +1.0, -1.0);
  N[3] = hex20_corner(xi, xm, yp, zm, -1.0, +1.0, -1.0);
  N[4] = hex20_corner(xi, xm, ym, zp, -1.0, -1.0, +1.0);
  N[5] = hex20_corner(xi, xp, ym, zp, +1.0, -1.0, +1.0);
  N[6] = hex20_corner(xi, xp, yp, zp, +1.0, +1.0, +1.0);
  N[7] = hex20_corner(xi, xm, yp, zp, -1.0, +1.0, +1.0);
  /* bottom edges 8 (0,1), 9 (1,2), 10 (2,3), 11 (3,0) */
  N[8] = x2 * ym * zm;
  N[9] = y2 * xp * zm;
  N[10] = x2 * yp * zm;
  N[11] = y2 * xm * zm;
  /* top edges 12 (4,5), 13 (5,6), 14 (6,7), 15 (7,4) */
  N[12] = x2 * ym * zp;
  N[13] = y2 * xp * zp;
  N[14] = x2 * yp * zp;
  N[15] = y2 * xm * zp;
  /* vertical edges 16 (0,4), 17 (1,5), 18 (2,6), 19 (3,7) */
  N[16] = z2 * xm * ym;
  N[17] = z2 * xp * ym;
  N[18] = z2 * xp * yp;
  N[19] = z2 * xm * yp;
}

void fcm__element_grad_hex20(const double xi[3], double dN[60])
{
  const double x = xi[0], y = xi[1], z = xi[2];
  const double xm = 1.0 - x, xp = 1.0 + x, ym = 1.0 - y, yp = 1.0 + y, zm = 1.0 - z, zp = 1.0 + z;
  const double x2 = 0.25 * (1.0 - x * x), y2 = 0.25 * (1.0 - y * y), z2 = 0.25 * (1.0 - z * z);
  const double dx2 = -0.5 * x, dy2 = -0.5 * y, dz2 = -0.5 * z; /* derivatives of x2, y2, z2 */
  hex20_corner_grad(xi, xm, ym, zm, -1.0, -1.0, -1.0, dN + 0);
  hex20_corner_grad(xi, xp, ym, zm, +1.0, -1.0, -1.0, dN + 3);
  hex20_corner_grad(xi, xp, yp, zm, +1.0, +1.0, -1.0, dN + 6);
  hex20_corner_grad(xi, xm, yp, zm, -1.0, +1.0, -1.0, dN + 9);
  hex20_corner_grad(xi, xm, ym, zp, -1.0, -1.0, +1.0, dN + 12);
  hex20_corner_grad(xi, xp, ym, zp, +1.0, -1.0, +1.0, dN + 15);
  hex20_corner_grad(xi, xp, yp, zp, +1.0, +1.0, +1.0, dN + 18);
  hex20_corner_grad(xi, xm, yp, zp, -1.0, +1.0, +1.0, dN + 21);
  /* 8: x2 ym zm */
  dN[24] = dx2 * ym * zm, dN[25] = -x2 * zm, dN[26] = -x2 * ym;
  /* 9: y2 xp zm */
  dN[27] = y2 * zm, dN[28] = dy2 * xp * zm, dN[29] = -y2 * xp;
  /* 10: x2 yp zm */
  dN[30] = dx2 * yp * zm, dN[31] = x2 * zm, dN[32] = -x2 * yp;
  /* 11: y2 xm zm */
  dN[33] = -y2 * zm, dN[34] = dy2 * xm * zm, dN[35] = -y2 * xm;
  /* 12: x2 ym zp */
  dN[36] = dx2 * ym * zp, dN[37] = -x2 * zp, dN[38] = x2 * ym;
  /* 13: y2 xp zp */
  dN[39] = y2 * zp, dN[40] = dy2 * xp * zp, dN[41] = y2 * xp;
  /* 14: x2 yp zp */
  dN[42] = dx2 * yp * zp, dN[43] = x2 * zp, dN[44] = x2 * yp;
  /* 15: y2 xm zp */
  dN[45] = -y2 * zp, dN[46] = dy2 * xm * zp, dN[47] = y2 * xm;
  /* 16: z2 xm ym */
  dN[48] = -z2 * ym, dN[49] = -z2 * xm, dN[50] = dz2 * xm * ym;
  /* 17: z2 xp ym */
  dN[51] = z2 * ym, dN[52] = -z2 * xp, dN[53] = dz2 * xp * ym;
  /* 18: z2 xp yp */
  dN[54] = z2 * yp, dN[55] = z2 * xp, dN[56] = dz2 * xp * yp;
  /* 19: z2 xm yp */
  dN[57] = -z2 * yp, dN[58] = z2 * xm, dN[59] = dz2 * xm * yp;
}
