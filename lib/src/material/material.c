/* Materials: model names, validation, the parameter setup (Lame parameters and
 * the Stable Neo-Hookean reparametrization) and the public evaluation entry point.
 *
 * Stable Neo-Hookean constants (Smith, Goes & Kim, "Stable Neo-Hookean flesh
 * simulation", ACM TOG 2018, §3.4; lib/METHOD.md §8): mu' = 4 mu/3, lambda' = lambda + 5 mu/6
 * make the linearization at F = I equal linear elasticity with (mu, lambda), and
 * alpha = 1 + 3 mu'/(4 lambda') makes the rest state stress free. */
#include "material/material_impl.h"

static const char *const model_names[FCM_MATERIAL_COUNT] = {"linear", "stvk", "corotated", "snh",
                                                            "corotated_linear"};

const char *fcm_material_model_name(fcm_material_model model)
{
  return ((int)model >= 0 && model < FCM_MATERIAL_COUNT) ? model_names[model] : NULL;
}

fcm_status fcm_material_model_parse(fcm_ctx *ctx, const char *name, fcm_material_model *model)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(name && model, ctx, FCM_ERR_ARG, "material: model name or output is NULL");
  if (strcmp(name, "stable_neo_hookean") == 0) {
    *model = FCM_MATERIAL_STABLE_NEO_HOOKEAN;
    goto cleanup;
  }
  for (int m = 0; m < FCM_MATERIAL_COUNT; m++)
    if (strcmp(name, model_names[m]) == 0) {
      *model = (fcm_material_model)m;
      goto cleanup;
    }
  FCM_CHECK(0, ctx, FCM_ERR_ARG,
            "material: unknown model \"%s\" (valid: linear, stvk, corotated, snh, "
            "stable_neo_hookean, corotated_linear)",
            name);
cleanup:
  return st;
}

/* The one Lame conversion of the library; it validates the model, E, nu and the density. */
fcm_status fcm_material_lame(fcm_ctx *ctx, const fcm_material *mat, double *lambda, double *mu)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(mat, ctx, FCM_ERR_ARG, "material: material is NULL");
  FCM_CHECK((int)mat->model >= 0 && mat->model < FCM_MATERIAL_COUNT, ctx, FCM_ERR_ARG,
            "material: model = %d out of range [0, %d)", (int)mat->model, FCM_MATERIAL_COUNT);
  FCM_CHECK(isfinite(mat->young) && mat->young > 0.0, ctx, FCM_ERR_ARG,
            "material: Young's modulus E = %g must be positive and finite", mat->young);
  FCM_CHECK(isfinite(mat->poisson) && mat->poisson > -1.0 && mat->poisson < 0.5, ctx, FCM_ERR_ARG,
            "material: Poisson's ratio nu = %g must lie in (-1, 0.5)", mat->poisson);
  FCM_CHECK(isfinite(mat->density) && mat->density >= 0.0, ctx, FCM_ERR_ARG,
            "material: density = %g must be non-negative and finite", mat->density);
  if (lambda)
    *lambda = mat->young * mat->poisson / ((1.0 + mat->poisson) * (1.0 - 2.0 * mat->poisson));
  if (mu) *mu = mat->young / (2.0 * (1.0 + mat->poisson));
cleanup:
  return st;
}

fcm_status fcm_material_validate(fcm_ctx *ctx, const fcm_material *mat)
{
  fcm_status st = FCM_OK;
  FCM_TRY(ctx, fcm_material_lame(ctx, mat, NULL, NULL));
cleanup:
  return st;
}

fcm_status fcm_material_setup(fcm_ctx *ctx, const fcm_material *mat, fcm_material_params *params)
{
  fcm_status st = FCM_OK;
  fcm_material_params p;
  memset(&p, 0, sizeof p);
  FCM_CHECK(params, ctx, FCM_ERR_ARG, "material: params is NULL");
  FCM_TRY(ctx, fcm_material_lame(ctx, mat, &p.lambda, &p.mu));
  p.model = mat->model;
  p.density = mat->density;
  p.project_psd = 0;
  if (p.model == FCM_MATERIAL_STABLE_NEO_HOOKEAN) {
    /* lambda' = lambda + 5 mu/6 > 0 for every nu > -1 (lambda/mu = 2 nu/(1 - 2 nu) > -5/6). */
    p.snh_mu = 4.0 * p.mu / 3.0;
    p.snh_lambda = p.lambda + 5.0 * p.mu / 6.0;
    p.snh_alpha = 1.0 + 0.75 * p.snh_mu / p.snh_lambda;
  }
  *params = p;
cleanup:
  return st;
}

void fcm_material_eval(const fcm_material_params *params, const double F[9], double *psi,
                       double P[9], double dPdF[81])
{
  fcm__material_eval(params, F, psi, P, dPdF);
}
