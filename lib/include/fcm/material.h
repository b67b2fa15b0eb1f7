/* fcm — hyperelastic materials for the mechanics (lib/METHOD.md §8): energy density
 * Psi(F), first Piola stress P(F) = dPsi/dF and tangent dP/dF of linear
 * elasticity, St. Venant-Kirchhoff, corotated linear and Stable Neo-Hookean,
 * with optional projection of the tangent to positive semi-definite.
 *
 * Layout: F and P are row-major 3x3 (F[3*i + j] = F_ij); the tangent is 9x9
 * with dPdF[9*(3*i + j) + 3*k + l] = dP_ij / dF_kl (symmetric: a Hessian). */
#ifndef FCM_MATERIAL_H
#define FCM_MATERIAL_H

#include "fcm/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Constitutive models (mu, lambda: Lame parameters of E, nu; I_C = tr(F^T F), J = det F):
 * - LINEAR: Psi = mu eps:eps + lambda/2 tr(eps)^2, eps = sym(F - I),
 *   P = 2 mu eps + lambda tr(eps) I
 * - STVK: Psi = mu E:E + lambda/2 tr(E)^2, E = (F^T F - I)/2, P = F (2 mu E + lambda tr(E) I)
 * - COROTATED: Psi = mu |F - R|^2 + lambda/2 tr(R^T F - I)^2, F = R S polar with R a proper
 *   rotation (also for J <= 0), P = 2 mu (F - R) + lambda tr(R^T F - I) R
 * - STABLE_NEO_HOOKEAN (Smith et al. 2018): Psi = mu'/2 (I_C - 3) - mu'/2 log(I_C + 1)
 *   + lambda'/2 (J - alpha)^2, mu' = 4 mu/3, lambda' = lambda + 5 mu/6,
 *   alpha = 1 + 3 mu'/(4 lambda'); P = mu' (1 - 1/(I_C + 1)) F + lambda' (J - alpha) cof F.
 *   Psi(I) = lambda'/2 (1 - alpha)^2 - mu'/2 log 4 is a constant, not zero.
 * - COROTATED_LINEAR (element-corotated linear elasticity, stiffness warping; Dick et al.
 *   2011 §5): the assembly gives each element its linear stiffness K_e (kept across steps)
 *   and one rotation R_e, the polar rotation of F averaged over the element's material (on
 *   an affine element F at the centroid): element energy
 *   1/2 d^T K_e d, d = [R_e]^T x_e - X_e, its exact gradient as the force and its exact
 *   Hessian as the tangent (symmetric, possibly indefinite), or with project_psd the warped
 *   [R_e] K_e [R_e]^T, positive semi-definite (lib/docs/time_integration.md; the integrator
 *   starts each Newton substep on the warped one). At a single point
 *   (fcm_material_eval(), stress output) it is the COROTATED model: the same energy with R
 *   taken per point. */
typedef enum fcm_material_model {
  FCM_MATERIAL_LINEAR = 0,
  FCM_MATERIAL_STVK,
  FCM_MATERIAL_COROTATED,
  FCM_MATERIAL_STABLE_NEO_HOOKEAN,
  FCM_MATERIAL_COROTATED_LINEAR,
  FCM_MATERIAL_COUNT
} fcm_material_model;

/** A material as a user or a scene file states it (plain value type). */
typedef struct fcm_material {
  fcm_material_model model;
  double young;   /**< Young's modulus E > 0 */
  double poisson; /**< Poisson's ratio, -1 < nu < 0.5 */
  double density; /**< mass density rho >= 0 */
} fcm_material;

/** Evaluation parameters derived by fcm_material_setup() (plain value type; copy freely).
 * All members but project_psd are read-only results of the setup. */
typedef struct fcm_material_params {
  fcm_material_model model;
  double mu, lambda; /**< Lame parameters (the conversion of fcm_material_lame()) */
  double snh_mu;     /**< mu' = 4 mu/3 (Stable Neo-Hookean; 0 for the other models) */
  double snh_lambda; /**< lambda' = lambda + 5 mu/6 (Stable Neo-Hookean; else 0) */
  double snh_alpha;  /**< alpha = 1 + 3 mu'/(4 lambda') (Stable Neo-Hookean; else 0) */
  double density;    /**< rho */
  int project_psd;   /**< 1: fcm_material_eval() returns the tangent with its negative
                          eigenvalues clamped to 0. Set to 0 by the setup; the caller may
                          change it at any time. */
} fcm_material_params;

/** Canonical name of a model ("linear", "stvk", "corotated", "snh", "corotated_linear"), or NULL
 * for an invalid value. Static string; thread safe. */
FCM_API const char *fcm_material_model_name(fcm_material_model model);

/** Model of a name (case-sensitive): "linear", "stvk", "corotated", "snh",
 * "stable_neo_hookean" or "corotated_linear".
 * @param[in]  ctx   context for the error message (may be NULL)
 * @param[in]  name  the name
 * @param[out] model the model; unchanged on failure
 * @return FCM_OK, FCM_ERR_ARG (NULL argument, unknown name: the message quotes it and
 * lists the valid names). No allocation; thread safe. */
FCM_API fcm_status fcm_material_model_parse(fcm_ctx *ctx, const char *name,
                                            fcm_material_model *model);

/** Check a material: model in [0, FCM_MATERIAL_COUNT), E positive and finite,
 * nu in (-1, 0.5), density non-negative and finite.
 * @return FCM_OK or FCM_ERR_ARG; the message names the bad value and the valid range.
 * No allocation; thread safe (errors are recorded in ctx, which may be NULL). */
FCM_API fcm_status fcm_material_validate(fcm_ctx *ctx, const fcm_material *mat);

/** Validate `mat` (fcm_material_validate()) and return its Lame parameters
 * lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)); either output may be NULL.
 * @return FCM_OK or FCM_ERR_ARG (as fcm_material_validate()). No allocation; thread safe. */
FCM_API fcm_status fcm_material_lame(fcm_ctx *ctx, const fcm_material *mat, double *lambda,
                                     double *mu);

/** Validate `mat` and derive its evaluation parameters (project_psd = 0).
 * @param[in]  ctx    context for the error message (may be NULL)
 * @param[in]  mat    the material
 * @param[out] params the parameters; unchanged on failure
 * @return FCM_OK, FCM_ERR_ARG (as fcm_material_validate(), or params NULL). No allocation. */
FCM_API fcm_status fcm_material_setup(fcm_ctx *ctx, const fcm_material *mat,
                                      fcm_material_params *params);

/** Energy density, first Piola stress and tangent at the deformation gradient F.
 * @param[in]  params from fcm_material_setup()
 * @param[in]  F      deformation gradient (row-major); any F, also singular or inverted
 * @param[out] psi    Psi(F), or NULL
 * @param[out] P      P(F) (9 entries, row-major), or NULL
 * @param[out] dPdF   dP/dF (81 entries, layout above; projected to positive semi-definite
 *                    when params->project_psd is set), or NULL
 * A NaN or infinite entry in F (or an invalid params->model) makes every requested output
 * NaN; the caller detects it. Corotated: where two signed singular values of F nearly cancel
 * (s_i + s_j < 1e-8; R is not differentiable there, e.g. F = -I) the tangent is evaluated
 * with s_i + s_j = 1e-8. No allocation, no error state; thread safe (pure function). */
FCM_API void fcm_material_eval(const fcm_material_params *params, const double F[9], double *psi,
                               double P[9], double dPdF[81]);

#ifdef __cplusplus
}
#endif
#endif /* FCM_MATERIAL_H */
