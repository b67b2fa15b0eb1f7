/* Moment basis of the simplification: tensor Chebyshev polynomials of total degree
 * <= m on the bounding box of the points (Longva et al. 2020 §4.4.3, eq. 9). */
#include "simplify/simplify_impl.h"

#include <float.h>
#include <math.h>

int fcm__simplify_num_basis(int m)
{
  return (m + 1) * (m + 2) * (m + 3) / 6;
}

void fcm__simplify_box(int m, int n, const double *points, fcm__cheb_box *box)
{
  box->m = m;
  box->num_basis = fcm__simplify_num_basis(m);
  for (int d = 0; d < 3; d++) {
    double lo = points[d], hi = points[d];
    for (int j = 1; j < n; j++) {
      const double v = points[3 * j + d];
      lo = v < lo ? v : lo;
      hi = v > hi ? v : hi;
    }
    const double c = 0.5 * (lo + hi), l = 0.5 * (hi - lo);
    /* An extent at rounding level carries no geometry: constant along that axis. */
    if (l <= 64.0 * DBL_EPSILON * fmax(1.0, fmax(fabs(lo), fabs(hi)))) {
      box->scale[d] = 0.0;
      box->shift[d] = 1.0;
    } else {
      box->scale[d] = 1.0 / l;
      box->shift[d] = -c / l;
    }
  }
}

void fcm__simplify_basis_eval(const fcm__cheb_box *box, const double *x, double *phi)
{
  double t[3][FCM_SIMPLIFY_MAX_STRENGTH + 1];
  const int m = box->m;
  for (int d = 0; d < 3; d++) {
    const double s = box->scale[d] * x[d] + box->shift[d];
    t[d][0] = 1.0;
    if (m >= 1) t[d][1] = s;
    for (int k = 2; k <= m; k++)
      t[d][k] = 2.0 * s * t[d][k - 1] - t[d][k - 2];
  }
  int i = 0;
  for (int deg = 0; deg <= m; deg++)
    for (int a = deg; a >= 0; a--)
      for (int b = deg - a; b >= 0; b--)
        phi[i++] = t[0][a] * t[1][b] * t[2][deg - a - b];
}
