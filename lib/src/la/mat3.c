/* 3x3 decompositions for material hot loops: symmetric eigen-decomposition,
 * rotation-variant SVD and polar decomposition, all by Jacobi rotations.
 *
 * Eigen: cyclic two-sided Jacobi (Golub & Van Loan, Matrix Computations, 4th ed.,
 * §8.5.2). SVD: one-sided (Hestenes) Jacobi on the columns of F, which never forms
 * F^T F and so keeps small singular values accurate (Demmel & Veselić 1992); the
 * sign convention for inverted elements is the one of Irving, Teran & Fedkiw 2004
 * (U, V rotations, the smallest singular value takes the sign of det F). Inputs
 * are scaled by a power of two first, so no intermediate over- or underflows. */
#include "la/mat3.h"

#include <float.h>

#define MAT3_MAX_SWEEPS 60

/* The pairs (p, q) of a cyclic sweep. */
static const int pair_p[3] = {0, 0, 1}, pair_q[3] = {1, 2, 2};

static void set_identity(double M[9])
{
  for (int i = 0; i < 9; i++)
    M[i] = (i % 4 == 0) ? 1.0 : 0.0;
}

/* Rotation tangent t = tan(phi) that annihilates the off-diagonal entry of the
 * 2x2 symmetric [[x, z], [z, y]] (z != 0): the smaller root of t^2 + 2 zeta t - 1. */
static double jacobi_tangent(double x, double y, double z)
{
  double zeta = (y - x) / (2.0 * z);
  if (fabs(zeta) > 1e150) return 0.5 / zeta;
  return copysign(1.0, zeta) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
}

/* x * 2^e, by one multiplication when 2^e is a normal number (exact unless the
 * result is subnormal, like ldexp), else by ldexp. */
static double scale2(double x, double p2, int e)
{
  return (e > -1000 && e < 1000) ? x * p2 : ldexp(x, e);
}

static double dot3(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

int fcm__mat3_sym_eig(const double A[9], double lambda[3], double Q[9])
{
  double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, amax = 0.0;
  int finite = 1, e = 0, sweep;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      a[i][j] = 0.5 * (A[3 * i + j] + A[3 * j + i]);
      if (!isfinite(a[i][j])) finite = 0;
      amax = fmax(amax, fabs(a[i][j]));
    }
  set_identity(Q);
  if (!finite || amax == 0.0) {
    for (int k = 0; k < 3; k++)
      lambda[k] = finite ? 0.0 : NAN;
    return finite ? 0 : -1;
  }
  frexp(amax, &e);
  const double down = (e > -1000 && e < 1000) ? ldexp(1.0, -e) : 0.0;
  const double up = (e > -1000 && e < 1000) ? ldexp(1.0, e) : 0.0;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      a[i][j] = scale2(a[i][j], down, -e);

  for (sweep = 0; sweep < MAT3_MAX_SWEEPS; sweep++) {
    int rotated = 0;
    for (int r = 0; r < 3; r++) {
      int p = pair_p[r], q = pair_q[r], k = 3 - p - q;
      double apq = a[p][q], app = a[p][p], aqq = a[q][q];
      if (apq == 0.0) continue;
      /* Negligible against its diagonal pair (relative accuracy) or against the
       * scaled norm (~1): drop it. */
      if (fabs(apq) <= 0.5 * DBL_EPSILON * sqrt(fabs(app) * fabs(aqq)) ||
          fabs(apq) <= DBL_EPSILON * DBL_EPSILON) {
        a[p][q] = a[q][p] = 0.0;
        continue;
      }
      double t = jacobi_tangent(app, aqq, apq);
      double c = 1.0 / sqrt(1.0 + t * t), s = t * c;
      double akp = a[k][p], akq = a[k][q];
      a[p][p] = app - t * apq;
      a[q][q] = aqq + t * apq;
      a[p][q] = a[q][p] = 0.0;
      a[k][p] = a[p][k] = c * akp - s * akq;
      a[k][q] = a[q][k] = s * akp + c * akq;
      for (int i = 0; i < 3; i++) {
        double vip = v[i][p], viq = v[i][q];
        v[i][p] = c * vip - s * viq;
        v[i][q] = s * vip + c * viq;
      }
      rotated = 1;
    }
    if (!rotated) break;
  }

  /* Ascending order, eigenvectors along. */
  double d[3] = {a[0][0], a[1][1], a[2][2]};
  int idx[3] = {0, 1, 2};
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2 - i; j++)
      if (d[idx[j]] > d[idx[j + 1]]) {
        int tmp = idx[j];
        idx[j] = idx[j + 1];
        idx[j + 1] = tmp;
      }
  for (int k = 0; k < 3; k++) {
    lambda[k] = scale2(d[idx[k]], up, e);
    for (int i = 0; i < 3; i++)
      Q[3 * i + k] = v[i][idx[k]];
  }
  if (fcm__mat3_det(Q) < 0.0)
    for (int i = 0; i < 3; i++)
      Q[3 * i + 2] = -Q[3 * i + 2];
  return sweep;
}

/* One Jacobi rotation of the columns p, q of F V (b, v: columns), given their
 * squared norms d[p], d[q]; returns 1 if it rotated. The tangent t of
 * jacobi_tangent is written as num / den with one square root, and (c, s) as
 * (den, num) / |(den, num)|: three long operations on the critical path instead of
 * five (the one-sided Jacobi's cost is their latency). The rotated squared norms
 * follow from the 2x2 Gram matrix (d[p] - t gamma, d[q] + t gamma) without dot
 * products; each sweep starts from freshly computed ones, so the test of the last
 * sweep, which rotates nothing, is made on exact norms. */
static int svd_rotate(double b[3][3], double v[3][3], double d[3], int p, int q)
{
  double gamma = dot3(b[p], b[q]);
  /* |gamma| <= 4 eps sqrt(d[p] d[q]), squared (no square root; the inputs' range
   * keeps the squares normal at any relevant size). */
  if (gamma * gamma <= 16.0 * DBL_EPSILON * DBL_EPSILON * (d[p] * d[q])) return 0;
  double delta = d[q] - d[p], r2 = delta * delta + 4.0 * gamma * gamma;
  double c, s, tg;
  if (r2 > 0x1p-900) {
    double num = copysign(2.0, delta) * gamma, den = fabs(delta) + sqrt(r2);
    double h = 1.0 / sqrt(den * den + num * num);
    c = den * h, s = num * h, tg = num * gamma / den;
  } else { /* tiny columns: the quotient form never underflows */
    double t = jacobi_tangent(d[p], d[q], gamma);
    c = 1.0 / sqrt(1.0 + t * t), s = t * c, tg = t * gamma;
  }
  for (int i = 0; i < 3; i++) {
    double bp = b[p][i], bq = b[q][i], vp = v[p][i], vq = v[q][i];
    b[p][i] = c * bp - s * bq;
    b[q][i] = s * bp + c * bq;
    v[p][i] = c * vp - s * vq;
    v[q][i] = s * vp + c * vq;
  }
  d[p] -= tg;
  d[q] += tg;
  return 1;
}

int fcm__mat3_svd(const double F[9], double U[9], double sigma[3], double V[9])
{
  double b[3][3], v[3][3], u[3][3], nrm[3], amax = 0.0; /* b[k], v[k], u[k]: columns */
  int finite = 1, e = 0, sweep;
  for (int i = 0; i < 9; i++) {
    if (!isfinite(F[i])) finite = 0;
    amax = fmax(amax, fabs(F[i]));
  }
  set_identity(U);
  set_identity(V);
  if (!finite || amax == 0.0) {
    for (int k = 0; k < 3; k++)
      sigma[k] = finite ? 0.0 : NAN;
    return finite ? 0 : -1;
  }
  /* Within 2^-126 <= amax <= 2^126 the squares and their products neither over- nor
   * underflow at a relevant size, and scaling by a power of two changes no result:
   * skip it there. */
  double down = 1.0, up = 1.0;
  if (amax < 0x1p-126 || amax > 0x1p126) {
    frexp(amax, &e);
    down = (e > -1000 && e < 1000) ? ldexp(1.0, -e) : 0.0;
    up = (e > -1000 && e < 1000) ? ldexp(1.0, e) : 0.0;
  }
  for (int k = 0; k < 3; k++)
    for (int i = 0; i < 3; i++) {
      b[k][i] = scale2(F[3 * i + k], down, -e);
      v[k][i] = (i == k) ? 1.0 : 0.0;
    }

  /* Rotate pairs of columns of F V until all are orthogonal to working precision. */
  for (sweep = 0; sweep < MAT3_MAX_SWEEPS; sweep++) {
    for (int k = 0; k < 3; k++)
      nrm[k] = dot3(b[k], b[k]);
    int rotated = svd_rotate(b, v, nrm, 0, 1);
    rotated |= svd_rotate(b, v, nrm, 0, 2);
    rotated |= svd_rotate(b, v, nrm, 1, 2);
    if (!rotated) break;
  }

  /* Descending column norms; a swap negates one column of both B and V, so
   * F V = B still holds and det V stays +1. */
  if (sweep == MAT3_MAX_SWEEPS)
    for (int k = 0; k < 3; k++)
      nrm[k] = dot3(b[k], b[k]);
  for (int k = 0; k < 3; k++)
    nrm[k] = sqrt(nrm[k]);
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2 - i; j++)
      if (nrm[j] < nrm[j + 1]) {
        for (int m = 0; m < 3; m++) {
          double tb = b[j][m], tv = v[j][m];
          b[j][m] = b[j + 1][m], v[j][m] = v[j + 1][m];
          b[j + 1][m] = -tb, v[j + 1][m] = -tv;
        }
        double tn = nrm[j];
        nrm[j] = nrm[j + 1], nrm[j + 1] = tn;
      }

  /* U: normalized columns, completed to a rotation; the last singular value is
   * the (signed) component of the last column along u2 = u0 x u1. */
  for (int i = 0; i < 3; i++)
    u[0][i] = b[0][i] / nrm[0];
  double w[3] = {0.0, 0.0, 0.0}, len = 0.0;
  if (nrm[1] > 0.0) {
    for (int i = 0; i < 3; i++)
      w[i] = b[1][i] / nrm[1];
    double proj = dot3(u[0], w);
    for (int i = 0; i < 3; i++)
      w[i] -= proj * u[0][i];
    len = sqrt(dot3(w, w));
  }
  if (len < 0.5) { /* rank 1: any unit vector orthogonal to u0 */
    int j = 0;
    for (int i = 1; i < 3; i++)
      if (fabs(u[0][i]) < fabs(u[0][j])) j = i;
    for (int i = 0; i < 3; i++)
      w[i] = (i == j ? 1.0 : 0.0) - u[0][j] * u[0][i];
    len = sqrt(dot3(w, w));
  }
  for (int i = 0; i < 3; i++)
    u[1][i] = w[i] / len;
  u[2][0] = u[0][1] * u[1][2] - u[0][2] * u[1][1];
  u[2][1] = u[0][2] * u[1][0] - u[0][0] * u[1][2];
  u[2][2] = u[0][0] * u[1][1] - u[0][1] * u[1][0];

  sigma[0] = scale2(nrm[0], up, e);
  sigma[1] = scale2(nrm[1], up, e);
  /* |u2 . b2| <= |b2| <= |b1| up to rounding; keep the order exact. */
  double s2 = dot3(u[2], b[2]);
  if (fabs(s2) > nrm[1]) s2 = copysign(nrm[1], s2);
  sigma[2] = scale2(s2, up, e);
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      U[3 * i + k] = u[k][i];
      V[3 * i + k] = v[k][i];
    }
  return sweep;
}

int fcm__mat3_polar(const double F[9], double R[9], double S[9])
{
  double U[9], V[9], sigma[3];
  int ret = fcm__mat3_svd(F, U, sigma, V);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      R[3 * i + j] =
          U[3 * i] * V[3 * j] + U[3 * i + 1] * V[3 * j + 1] + U[3 * i + 2] * V[3 * j + 2];
      if (j >= i) {
        double s = 0.0;
        for (int k = 0; k < 3; k++)
          s += V[3 * i + k] * sigma[k] * V[3 * j + k];
        S[3 * i + j] = S[3 * j + i] = s;
      }
    }
  return ret;
}
