/* fcm material, internal part: the constitutive kernels as static inline
 * functions, so the assembly hot loop can inline fcm__material_eval(). */
#ifndef FCM_MATERIAL_IMPL_H
#define FCM_MATERIAL_IMPL_H

#include "core/core_impl.h"
#include "fcm/material.h"
#include "la/mat3.h"

#include <math.h>
#include <string.h>

/* Floor of s_i + s_j (signed singular values) in the corotated twist eigenvalue
 * (psi_i + psi_j)/(s_i + s_j): R = U V^T is not differentiable where it vanishes. */
#define FCM__COROTATED_TWIST_FLOOR 1e-8

/* SVD-based evaluation for the rotation-invariant models (material_svd.c): with
 * F = U diag(s) V^T (rotation variant, s signed) the tangent is assembled from its
 * analytic eigensystem (Smith et al. 2019), clamped to >= 0 when p->project_psd.
 * psi and P (either may be NULL) are computed from s as well. Used for every output
 * of the corotated model and for projected tangents. F must be finite. */
void fcm__material_eval_svd(const fcm_material_params *p, const double F[9], double *psi,
                            double P[9], double dPdF[81]);

/* Write NaN to every requested output. */
static inline void fcm__material_nan(double *psi, double P[9], double dPdF[81])
{
  if (psi) *psi = NAN;
  if (P)
    for (int i = 0; i < 9; i++)
      P[i] = NAN;
  if (dPdF)
    for (int i = 0; i < 81; i++)
      dPdF[i] = NAN;
}

/* Linear elasticity: eps = sym(F - I), P = 2 mu eps + lambda tr(eps) I. */
static inline void fcm__material_linear(double mu, double lambda, const double F[9], double *psi,
                                        double P[9], double dPdF[81])
{
  double eps[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      eps[3 * i + j] = 0.5 * (F[3 * i + j] + F[3 * j + i]) - (i == j ? 1.0 : 0.0);
  const double tr = eps[0] + eps[4] + eps[8];
  if (psi) {
    double ee = 0.0;
    for (int i = 0; i < 9; i++)
      ee += eps[i] * eps[i];
    *psi = mu * ee + 0.5 * lambda * tr * tr;
  }
  if (P)
    for (int i = 0; i < 9; i++)
      P[i] = 2.0 * mu * eps[i] + (i % 4 == 0 ? lambda * tr : 0.0);
  if (dPdF) {
    /* mu (d_ik d_jl + d_il d_jk) + lambda d_ij d_kl */
    memset(dPdF, 0, 81 * sizeof(double));
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++) {
        dPdF[9 * (3 * i + j) + 3 * i + j] += mu;
        dPdF[9 * (3 * i + j) + 3 * j + i] += mu;
      }
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++)
        dPdF[9 * (4 * i) + 4 * k] += lambda;
  }
}

/* St. Venant-Kirchhoff: E = (F^T F - I)/2, S = 2 mu E + lambda tr(E) I, P = F S;
 * dP_ij/dF_kl = d_ik S_lj + mu (F_il F_kj + (F F^T)_ik d_jl) + lambda F_ij F_kl. */
static inline void fcm__material_stvk(double mu, double lambda, const double F[9], double *psi,
                                      double P[9], double dPdF[81])
{
  double E[9], S[9];
  for (int i = 0; i < 3; i++)
    for (int j = i; j < 3; j++) {
      double c = F[i] * F[j] + F[3 + i] * F[3 + j] + F[6 + i] * F[6 + j];
      E[3 * i + j] = E[3 * j + i] = 0.5 * (c - (i == j ? 1.0 : 0.0));
    }
  const double tr = E[0] + E[4] + E[8];
  for (int i = 0; i < 9; i++)
    S[i] = 2.0 * mu * E[i] + (i % 4 == 0 ? lambda * tr : 0.0);
  if (psi) {
    double ee = 0.0;
    for (int i = 0; i < 9; i++)
      ee += E[i] * E[i];
    *psi = mu * ee + 0.5 * lambda * tr * tr;
  }
  if (P) fcm__mat3_mul(F, S, P);
  if (dPdF) {
    double B[9]; /* F F^T */
    for (int i = 0; i < 3; i++)
      for (int k = i; k < 3; k++)
        B[3 * i + k] = B[3 * k + i] =
            F[3 * i] * F[3 * k] + F[3 * i + 1] * F[3 * k + 1] + F[3 * i + 2] * F[3 * k + 2];
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++)
          for (int l = 0; l < 3; l++) {
            double v = mu * F[3 * i + l] * F[3 * k + j] + lambda * F[3 * i + j] * F[3 * k + l];
            if (i == k) v += S[3 * l + j];
            if (j == l) v += mu * B[3 * i + k];
            dPdF[9 * (3 * i + j) + 3 * k + l] = v;
          }
  }
}

/* Add s * d^2 det(F)/dF^2 to the tangent: d cof(F)_ij / dF_kl = e_ikn e_jlq F_nq
 * (e the Levi-Civita symbol), non-zero only for i != k and j != l. */
static inline void fcm__material_add_det_hessian(double s, const double F[9], double dPdF[81])
{
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) {
      if (k == i) continue;
      const int n = 3 - i - k;
      const double si = ((k - i + 3) % 3 == 1) ? s : -s; /* s e_ikn */
      for (int j = 0; j < 3; j++)
        for (int l = 0; l < 3; l++) {
          if (l == j) continue;
          const int q = 3 - j - l;
          const double v = ((l - j + 3) % 3 == 1) ? F[3 * n + q] : -F[3 * n + q];
          dPdF[9 * (3 * i + j) + 3 * k + l] += si * v;
        }
    }
}

/* Stable Neo-Hookean with the cofactor (no division by J):
 * P = mu'(1 - 1/(I_C + 1)) F + lambda'(J - alpha) cof F, and
 * dP/dF = mu'(1 - 1/(I_C+1)) I + 2 mu'/(I_C+1)^2 f f^T + lambda' g g^T + lambda'(J - alpha) H_J,
 * f = vec F, g = vec cof F, H_J = d^2 J/dF^2. lambda'(J - alpha) is formed as
 * lambda'(J - 1) - 3 mu'/4 (= lambda'(J - alpha) exactly), which keeps P(R) = 0 to
 * rounding also when lambda' >> mu'. */
static inline void fcm__material_snh(double mu_s, double lambda_s, const double F[9], double *psi,
                                     double P[9], double dPdF[81])
{
  double C[9];
  fcm__mat3_cofactor(F, C);
  const double J = F[0] * C[0] + F[1] * C[1] + F[2] * C[2];
  double ic = 0.0;
  for (int i = 0; i < 9; i++)
    ic += F[i] * F[i];
  const double a = mu_s * (1.0 - 1.0 / (ic + 1.0));
  const double c = lambda_s * (J - 1.0) - 0.75 * mu_s; /* lambda'(J - alpha) */
  if (psi) *psi = 0.5 * mu_s * (ic - 3.0) - 0.5 * mu_s * log(ic + 1.0) + 0.5 * c * c / lambda_s;
  if (P)
    for (int i = 0; i < 9; i++)
      P[i] = a * F[i] + c * C[i];
  if (dPdF) {
    const double b = 2.0 * mu_s / ((ic + 1.0) * (ic + 1.0));
    for (int x = 0; x < 9; x++)
      for (int y = 0; y < 9; y++)
        dPdF[9 * x + y] = b * F[x] * F[y] + lambda_s * C[x] * C[y] + (x == y ? a : 0.0);
    fcm__material_add_det_hessian(c, F, dPdF);
  }
}

/* The evaluation behind fcm_material_eval() (contract documented there). */
static inline void fcm__material_eval(const fcm_material_params *p, const double F[9], double *psi,
                                      double P[9], double dPdF[81])
{
  /* NaN/Inf anywhere in F makes z NaN (x * 0 is NaN exactly for non-finite x). */
  double z = 0.0;
  for (int i = 0; i < 9; i++)
    z += F[i] * 0.0;
  if (isnan(z)) {
    fcm__material_nan(psi, P, dPdF);
    return;
  }
  const int project = dPdF && p->project_psd;
  switch (p->model) {
  case FCM_MATERIAL_LINEAR:
    /* Tangent eigenvalues 0 (rotations), 2 mu, 2 mu + 3 lambda = E/(1 - 2 nu): already
     * positive semi-definite for every valid (E, nu), so projection changes nothing. */
    fcm__material_linear(p->mu, p->lambda, F, psi, P, dPdF);
    return;
  case FCM_MATERIAL_STVK:
    fcm__material_stvk(p->mu, p->lambda, F, psi, P, project ? NULL : dPdF);
    break;
  case FCM_MATERIAL_STABLE_NEO_HOOKEAN:
    fcm__material_snh(p->snh_mu, p->snh_lambda, F, psi, P, project ? NULL : dPdF);
    break;
  case FCM_MATERIAL_COROTATED:
  case FCM_MATERIAL_COROTATED_LINEAR: /* at a point: the corotated model */
    fcm__material_eval_svd(p, F, psi, P, dPdF);
    return;
  default:
    fcm__material_nan(psi, P, dPdF);
    return;
  }
  if (project) fcm__material_eval_svd(p, F, NULL, NULL, dPdF);
}

#endif /* FCM_MATERIAL_IMPL_H */
