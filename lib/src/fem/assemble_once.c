/* The one-shot assembly forms, each through an assembly workspace that lives for the call;
 * and what needs no workspace: the defaults of the options and forms, the standard rules,
 * the size of an element's kept block. */
#include "fem/fem_impl.h"

#include <string.h>

fcm_assembly_options fcm_assembly_options_default(void)
{
  fcm_assembly_options o = {FCM_DEFAULT, FCM_DEFAULT, FCM_FICTITIOUS_PROJECTED};
  return o;
}

fcm_status fcm_element_standard_rule(fcm_ctx *ctx, fcm_element_type type, fcm_rule_kind kind,
                                     int strength, fcm_rule **rule)
{
  fcm_status st = FCM_OK;
  const fcm_element_info *info = fcm_element_get_info(type);
  FCM_CHECK(info, ctx, FCM_ERR_ARG, "standard rule: invalid element type %d", (int)type);
  FCM_CHECK(kind == FCM_RULE_STIFFNESS || kind == FCM_RULE_MASS, ctx, FCM_ERR_ARG,
            "standard rule: invalid rule kind %d", (int)kind);
  FCM_CHECK(strength >= 0 || strength == FCM_DEFAULT, ctx, FCM_ERR_ARG,
            "standard rule: strength = %d must be >= 0, or FCM_DEFAULT (-1)", strength);
  if (strength >= 0)
    FCM_TRY(ctx, fcm_rule_create(ctx, info->shape, strength, rule));
  else if (info->shape == FCM_SHAPE_HEX) /* order+1 points per direction: strength 2*order+1 */
    FCM_TRY(ctx, fcm_rule_create_computed(ctx, info->shape, 2 * info->order + 1, rule));
  else
    FCM_TRY(ctx, fcm_rule_create(
                     ctx, info->shape,
                     kind == FCM_RULE_MASS ? info->mass_strength : info->stiffness_strength, rule));
cleanup:
  return st;
}

fcm_linear_form fcm_linear_form_default(void)
{
  fcm_linear_form f;
  memset(&f, 0, sizeof f);
  f.term = FCM_LINEAR_STIFFNESS;
  return f;
}

int fcm__assembly_block_size(const fcm_space *s, fcm_linear_term term)
{
  switch (term) {
  case FCM_LINEAR_MASS:
    return s->nn * (s->nn + 1) / 2;
  case FCM_LINEAR_BODY_FORCE:
  case FCM_LINEAR_BODY_FORCE_FIELD:
  case FCM_LINEAR_SURFACE_TRACTION:
    return 3 * s->nn;
  default:
    return 0;
  }
}

/* One linear term through a workspace that lives for this call only. */
static fcm_status linear_once(const fcm_space *s, const fcm_assembly_options *opts,
                              fcm_linear_term term, const fcm_material *material,
                              const double *accel, fcm_field_fn field, void *user, fcm_csr *A,
                              double *f)
{
  fcm_status st = FCM_OK;
  fcm_assembly_workspace *ws = NULL;
  fcm_linear_form form = {term, material, accel, field, user};
  FCM_TRY(s->ctx, fcm_assembly_workspace_create(s, opts, &ws));
  FCM_TRY(s->ctx, fcm_assembly_workspace_linear(ws, &form, A, f));
cleanup:
  fcm_assembly_workspace_destroy(&ws);
  return st;
}

fcm_status fcm_assemble_stiffness(const fcm_space *s, const fcm_material *mat,
                                  const fcm_assembly_options *opts, fcm_csr *A)
{
  return linear_once(s, opts, FCM_LINEAR_STIFFNESS, mat, NULL, NULL, NULL, A, NULL);
}

fcm_status fcm_assemble_mass(const fcm_space *s, const fcm_material *mat,
                             const fcm_assembly_options *opts, fcm_csr *A)
{
  return linear_once(s, opts, FCM_LINEAR_MASS, mat, NULL, NULL, NULL, A, NULL);
}

fcm_status fcm_assemble_body_force(const fcm_space *s, const fcm_material *mat,
                                   const double accel[3], const fcm_assembly_options *opts,
                                   double *f)
{
  return linear_once(s, opts, FCM_LINEAR_BODY_FORCE, mat, accel, NULL, NULL, NULL, f);
}

fcm_status fcm_assemble_body_force_field(const fcm_space *s, fcm_field_fn field, void *user,
                                         const fcm_assembly_options *opts, double *f)
{
  return linear_once(s, opts, FCM_LINEAR_BODY_FORCE_FIELD, NULL, NULL, field, user, NULL, f);
}

fcm_status fcm_assemble_surface_traction(const fcm_space *s, fcm_field_fn traction, void *user,
                                         double *f)
{
  return linear_once(s, NULL, FCM_LINEAR_SURFACE_TRACTION, NULL, NULL, traction, user, NULL, f);
}

fcm_status fcm_assemble_hyperelastic(const fcm_space *s, const fcm_material_params *mat,
                                     const double *u, const fcm_assembly_options *opts,
                                     double *energy, double *force, fcm_csr *tangent)
{
  fcm_status st = FCM_OK;
  fcm_assembly_workspace *ws = NULL;
  FCM_TRY(s->ctx, fcm_assembly_workspace_create(s, opts, &ws));
  FCM_TRY(s->ctx, fcm_assembly_workspace_hyperelastic(ws, mat, u, energy, force, tangent));
cleanup:
  fcm_assembly_workspace_destroy(&ws);
  return st;
}
