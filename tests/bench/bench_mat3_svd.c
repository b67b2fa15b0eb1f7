/* Micro-benchmark of fcm__mat3_svd (the corotated model's SVD): nanoseconds per call
 * against the reference one-sided Jacobi that tests every pair with three dot products
 * and ends with a full verification sweep, paired (alternating runs on the same
 * matrices, the minimum of the repetitions), on three sets of F: near-identity
 * (|F - I| ~ 0.05, a simulation's common case), uniform random entries in [-1, 1],
 * and random rotations times diag(1, 1, 1e-6) (near-singular). Prints the mean
 * sweeps, ns per call and the largest difference of the singular values. */
#include "la/mat3.h"
#include "test.h"

#include <float.h>
#include <stdio.h>
#include <time.h>

#define MAT3_MAX_SWEEPS 60
#define NMAT            4096
#define REPS            41

static const int pair_p[3] = {0, 0, 1}, pair_q[3] = {1, 2, 2};

static void set_identity(double M[9])
{
  for (int i = 0; i < 9; i++)
    M[i] = (i % 4 == 0) ? 1.0 : 0.0;
}

static double jacobi_tangent(double x, double y, double z)
{
  double zeta = (y - x) / (2.0 * z);
  if (fabs(zeta) > 1e150) return 0.5 / zeta;
  return copysign(1.0, zeta) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
}

static double scale2(double x, double p2, int e)
{
  return (e > -1000 && e < 1000) ? x * p2 : ldexp(x, e);
}

static double dot3(const double a[3], const double b[3])
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The reference: the same algorithm, each pair's norms by dot products, scaling always. */
static int ref_svd(const double F[9], double U[9], double sigma[3], double V[9])
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
  frexp(amax, &e);
  const double down = (e > -1000 && e < 1000) ? ldexp(1.0, -e) : 0.0;
  const double up = (e > -1000 && e < 1000) ? ldexp(1.0, e) : 0.0;
  for (int k = 0; k < 3; k++)
    for (int i = 0; i < 3; i++) {
      b[k][i] = scale2(F[3 * i + k], down, -e);
      v[k][i] = (i == k) ? 1.0 : 0.0;
    }

  /* Rotate pairs of columns of F V until all are orthogonal to working precision. */
  for (sweep = 0; sweep < MAT3_MAX_SWEEPS; sweep++) {
    int rotated = 0;
    for (int r = 0; r < 3; r++) {
      int p = pair_p[r], q = pair_q[r];
      double alpha = dot3(b[p], b[p]), beta = dot3(b[q], b[q]), gamma = dot3(b[p], b[q]);
      if (fabs(gamma) <= 4.0 * DBL_EPSILON * sqrt(alpha * beta)) continue;
      double t = jacobi_tangent(alpha, beta, gamma);
      double c = 1.0 / sqrt(1.0 + t * t), s = t * c;
      for (int i = 0; i < 3; i++) {
        double bp = b[p][i], bq = b[q][i], vp = v[p][i], vq = v[q][i];
        b[p][i] = c * bp - s * bq;
        b[q][i] = s * bp + c * bq;
        v[p][i] = c * vp - s * vq;
        v[q][i] = s * vp + c * vq;
      }
      rotated = 1;
    }
    if (!rotated) break;
  }

  /* Descending column norms; a swap negates one column of both B and V, so
   * F V = B still holds and det V stays +1. */
  for (int k = 0; k < 3; k++)
    nrm[k] = sqrt(dot3(b[k], b[k]));
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

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static unsigned long long state = 88172645463325252ULL;
static double uniform(void) /* xorshift64, in [-1, 1) */
{
  state ^= state << 13, state ^= state >> 7, state ^= state << 17;
  return 2.0 * ((state >> 11) * 0x1p-53) - 1.0;
}

typedef int (*svd_fn)(const double *, double *, double *, double *);

/* Seconds for one pass over the set; the sweeps and a checksum through sink. */
static double run(svd_fn f, double (*F)[9], double *sweeps, double (*sig)[3])
{
  double U[9], V[9];
  long total = 0;
  double t0 = now();
  for (int m = 0; m < NMAT; m++)
    total += f(F[m], U, sig[m], V);
  double t = now() - t0;
  *sweeps = (double)total / NMAT;
  return t;
}

static double F[NMAT][9], s_new[NMAT][3], s_ref[NMAT][3];

int main(void)
{
  const char *sets[3] = {"near-identity", "uniform", "near-singular"};
  printf("%-14s %10s %10s %12s %12s %8s %10s\n", "set", "sweeps ref", "sweeps new", "ns/call ref",
         "ns/call new", "ratio", "max dsigma");
  for (int set = 0; set < 3; set++) {
    for (int m = 0; m < NMAT; m++) {
      if (set == 0)
        for (int i = 0; i < 9; i++)
          F[m][i] = (i % 4 == 0) + 0.05 * uniform();
      else if (set == 1)
        for (int i = 0; i < 9; i++)
          F[m][i] = uniform();
      else {
        double A[9], R[9], S[9], Q[2][9];
        for (int r = 0; r < 2; r++) {
          for (int i = 0; i < 9; i++)
            A[i] = uniform();
          fcm__mat3_polar(A, Q[r], S);
        }
        for (int i = 0; i < 3; i++)
          for (int k = 0; k < 3; k++)
            R[3 * i + k] = Q[0][3 * i + k] * (k == 2 ? 1e-6 : 1.0);
        fcm__mat3_mul(R, Q[1], F[m]);
      }
    }
    double best_ref = 1e30, best_new = 1e30, sw_ref = 0, sw_new = 0;
    for (int r = 0; r < REPS; r++) {
      double t = run(ref_svd, F, &sw_ref, s_ref);
      if (t < best_ref) best_ref = t;
      t = run(fcm__mat3_svd, F, &sw_new, s_new);
      if (t < best_new) best_new = t;
    }
    double dmax = 0.0;
    for (int m = 0; m < NMAT; m++)
      for (int k = 0; k < 3; k++)
        dmax = fmax(dmax, fabs(s_new[m][k] - s_ref[m][k]));
    printf("%-14s %10.2f %10.2f %12.1f %12.1f %8.3f %10.2e\n", sets[set], sw_ref, sw_new,
           1e9 * best_ref / NMAT, 1e9 * best_new / NMAT, best_new / best_ref, dmax);
    TEST_TRUE(dmax <= 1e-14 * 3.0);
  }
  return TEST_RESULT();
}
