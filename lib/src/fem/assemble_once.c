/* The one-shot assembly forms: each through an assembly workspace that lives for the call. */
#include "fem/fem_impl.h"

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
