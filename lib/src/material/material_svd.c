/* Rotation-invariant materials through the singular values of F: the corotated
 * model, and the positive semi-definite projection of every tangent.
 *
 * With the rotation-variant SVD F = U diag(s) V^T (U, V proper rotations, s signed,
 * s0 >= s1 >= |s2|) an isotropic energy is Psi = Psi^(s) and P = U diag(dPsi^/ds) V^T.
 * Its Hessian has the analytic eigensystem of Smith, De Goes & Kim, "Analytic
 * eigensystems for isotropic distortion energies" (ACM TOG 2019), §4-5: with the
 * orthonormal basis U X V^T of 3x3 matrices,
 *  - scaling modes X = diag(q), q an eigenvector of the 3x3 Hessian d2Psi^/ds2;
 *  - for each pair i < j, flip X = (e_i e_j^T + e_j e_i^T)/sqrt 2 with eigenvalue
 *    (psi_i - psi_j)/(s_i - s_j) and twist X = (e_i e_j^T - e_j e_i^T)/sqrt 2 with
 *    (psi_i + psi_j)/(s_i + s_j) (psi_i = dPsi^/ds_i).
 * Both quotients are simplified per model to division-free forms, so repeated
 * singular values need no guard; only the corotated twist keeps the true
 * 1/(s_i + s_j) of dR/dF (floored at FCM__COROTATED_TWIST_FLOOR). The tangent is
 * K C K^T with K = U (x) V (K[(ij),(ab)] = U_ia V_jb) and C the tangent in the
 * singular frame; the projection clamps the eigenvalues of C's blocks at 0. */
#include "material/material_impl.h"

/* Spectral data of one model at singular values s. Pair m couples the two indices
 * other than m: m = 0 -> (1, 2), m = 1 -> (0, 2), m = 2 -> (0, 1). */
typedef struct spectral {
  double psi;
  double g[3];  /* dPsi^/ds */
  double H[9];  /* d2Psi^/ds2 */
  double lf[3]; /* flip eigenvalue of pair m */
  double lt[3]; /* twist eigenvalue of pair m */
} spectral;

static const int pair_i[3] = {1, 0, 0}, pair_j[3] = {2, 2, 1};

static void corotated(double mu, double lambda, const double s[3], spectral *d)
{
  const double tr3 = s[0] + s[1] + s[2] - 3.0;
  d->psi = 0.5 * lambda * tr3 * tr3;
  for (int a = 0; a < 3; a++) {
    d->psi += mu * (s[a] - 1.0) * (s[a] - 1.0);
    d->g[a] = 2.0 * mu * (s[a] - 1.0) + lambda * tr3;
    for (int b = 0; b < 3; b++)
      d->H[3 * a + b] = lambda + (a == b ? 2.0 * mu : 0.0);
  }
  for (int m = 0; m < 3; m++) {
    /* s_i + s_j >= 0 by the sign convention of the SVD. */
    double sum = FCM_MAX(s[pair_i[m]] + s[pair_j[m]], FCM__COROTATED_TWIST_FLOOR);
    d->lf[m] = 2.0 * mu;
    d->lt[m] = 2.0 * mu + (2.0 * lambda * tr3 - 4.0 * mu) / sum;
  }
}

static void stvk(double mu, double lambda, const double s[3], spectral *d)
{
  const double ic3 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2] - 3.0, t = 0.5 * lambda * ic3;
  d->psi = 0.125 * lambda * ic3 * ic3;
  for (int a = 0; a < 3; a++) {
    const double e = s[a] * s[a] - 1.0;
    d->psi += 0.25 * mu * e * e;
    d->g[a] = (mu * e + t) * s[a];
    for (int b = 0; b < 3; b++)
      d->H[3 * a + b] = lambda * s[a] * s[b] + (a == b ? mu * (3.0 * s[a] * s[a] - 1.0) + t : 0.0);
  }
  for (int m = 0; m < 3; m++) {
    const double si = s[pair_i[m]], sj = s[pair_j[m]], q = si * si + sj * sj - 1.0;
    d->lf[m] = mu * (q + si * sj) + t;
    d->lt[m] = mu * (q - si * sj) + t;
  }
}

static void snh(double mu_s, double lambda_s, const double s[3], spectral *d)
{
  const double ic = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
  const double J = s[0] * s[1] * s[2], Js[3] = {s[1] * s[2], s[0] * s[2], s[0] * s[1]};
  const double a = mu_s * (1.0 - 1.0 / (ic + 1.0)), b = 2.0 * mu_s / ((ic + 1.0) * (ic + 1.0));
  const double c = lambda_s * (J - 1.0) - 0.75 * mu_s; /* lambda'(J - alpha) */
  d->psi = 0.5 * mu_s * (ic - 3.0) - 0.5 * mu_s * log(ic + 1.0) + 0.5 * c * c / lambda_s;
  for (int x = 0; x < 3; x++) {
    d->g[x] = a * s[x] + c * Js[x];
    for (int y = 0; y < 3; y++)
      d->H[3 * x + y] =
          b * s[x] * s[y] + lambda_s * Js[x] * Js[y] + (x == y ? a : c * s[3 - x - y]);
  }
  for (int m = 0; m < 3; m++) {
    d->lf[m] = a - c * s[m];
    d->lt[m] = a + c * s[m];
  }
}

/* Whether the symmetric 3x3 A is positive definite: the pivots of its LDL^T are positive
 * (false for NaN). The clamp of the eigenvalues leaves such a block as it is, so its
 * eigen-decomposition is skipped. */
static int positive_definite3(const double A[9])
{
  const double d0 = A[0];
  if (!(d0 > 0.0)) return 0;
  const double l1 = A[3] / d0, l2 = A[6] / d0;
  const double d1 = A[4] - l1 * A[3];
  if (!(d1 > 0.0)) return 0;
  const double e = A[7] - l2 * A[3];
  return A[8] - l2 * A[6] - e * e / d1 > 0.0;
}

/* Clamp at 0, keeping NaN. */
static double clamp0(double v)
{
  return v < 0.0 ? 0.0 : v;
}

void fcm__material_eval_svd(const fcm_material_params *p, const double F[9], double *psi,
                            double P[9], double dPdF[81])
{
  double U[9], V[9], s[3];
  spectral d;
  fcm__mat3_svd(F, U, s, V);
  switch (p->model) {
  case FCM_MATERIAL_COROTATED:
  case FCM_MATERIAL_COROTATED_LINEAR: /* at a point: the corotated model */
    corotated(p->mu, p->lambda, s, &d);
    break;
  case FCM_MATERIAL_STVK:
    stvk(p->mu, p->lambda, s, &d);
    break;
  case FCM_MATERIAL_STABLE_NEO_HOOKEAN:
    snh(p->snh_mu, p->snh_lambda, s, &d);
    break;
  default: /* linear elasticity is not rotation invariant; never called for it */
    fcm__material_nan(psi, P, dPdF);
    return;
  }
  if (psi) *psi = d.psi;
  if (P)
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        P[3 * i + j] = U[3 * i] * d.g[0] * V[3 * j] + U[3 * i + 1] * d.g[1] * V[3 * j + 1] +
                       U[3 * i + 2] * d.g[2] * V[3 * j + 2];
  if (!dPdF) return;

  double H[9], dg[3], off[3];
  memcpy(H, d.H, sizeof H);
  if (p->project_psd) {
    if (!positive_definite3(d.H)) {
      double h[3], Q[9];
      fcm__mat3_sym_eig(d.H, h, Q);
      for (int k = 0; k < 3; k++)
        h[k] = clamp0(h[k]);
      for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
          H[3 * a + b] = Q[3 * a] * h[0] * Q[3 * b] + Q[3 * a + 1] * h[1] * Q[3 * b + 1] +
                         Q[3 * a + 2] * h[2] * Q[3 * b + 2];
    }
    for (int m = 0; m < 3; m++) {
      d.lf[m] = clamp0(d.lf[m]);
      d.lt[m] = clamp0(d.lt[m]);
    }
  }
  for (int m = 0; m < 3; m++) {
    dg[m] = 0.5 * (d.lf[m] + d.lt[m]);  /* C[ab][ab] */
    off[m] = 0.5 * (d.lf[m] - d.lt[m]); /* C[ab][ba] */
  }

  /* K = U (x) V, then T = K C column by column (C is sparse), then K C K^T. */
  double K[81], T[81];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
          K[9 * (3 * i + j) + 3 * a + b] = U[3 * i + a] * V[3 * j + b];
  for (int x = 0; x < 9; x++) {
    const double *kx = K + 9 * x;
    double *tx = T + 9 * x;
    for (int a = 0; a < 3; a++)
      tx[4 * a] = kx[0] * H[a] + kx[4] * H[3 + a] + kx[8] * H[6 + a];
    for (int m = 0; m < 3; m++) {
      const int ab = 3 * pair_i[m] + pair_j[m], ba = 3 * pair_j[m] + pair_i[m];
      tx[ab] = kx[ab] * dg[m] + kx[ba] * off[m];
      tx[ba] = kx[ba] * dg[m] + kx[ab] * off[m];
    }
  }
  for (int x = 0; x < 9; x++)
    for (int y = x; y < 9; y++) {
      const double *tx = T + 9 * x, *ky = K + 9 * y;
      double v = 0.0;
      for (int z = 0; z < 9; z++)
        v += tx[z] * ky[z];
      dPdF[9 * x + y] = dPdF[9 * y + x] = v;
    }
}
