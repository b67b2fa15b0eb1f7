/* sim: the time schemes of the dynamic integrator — backward Euler, Newmark's average
 * acceleration rule, HHT-alpha and generalized-alpha — as the parts of the incremental potential
 * they change (fcm/sim.h, top): the mass and damping coefficients, the predictor, the step's
 * constant force, the state update and the initial acceleration.
 *
 * Chung and Hulbert (1993), "A time integration algorithm for structural dynamics with improved
 * numerical dissipation: the generalized-alpha method", J. Appl. Mech. 60: eqs. (8)-(10) for the
 * update, (17), (20), (25) for alpha_m, alpha_f, gamma and beta from rho_inf; Hilber, Hughes and
 * Taylor (1977) for HHT (alpha_m = 0). The internal and damping forces are interpolated between
 * t_n and t_{n+1} (the HHT form of the balance), so that each step minimizes an energy with the
 * material's Psi itself and the same Newton iteration, line search and solvers serve every
 * scheme. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <string.h>

const char *fcm_time_scheme_name(fcm_time_scheme scheme)
{
  switch (scheme) {
  case FCM_SCHEME_BACKWARD_EULER:
    return "backward_euler";
  case FCM_SCHEME_NEWMARK:
    return "newmark";
  case FCM_SCHEME_HHT:
    return "hht";
  case FCM_SCHEME_GENERALIZED_ALPHA:
    return "generalized_alpha";
  case FCM_SCHEME_COUNT:
    break;
  }
  return "invalid";
}

fcm_status fcm__sim_scheme_validate(fcm_ctx *ctx, const fcm_integrator_options *o)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->scheme >= FCM_SCHEME_BACKWARD_EULER && o->scheme < FCM_SCHEME_COUNT, ctx,
            FCM_ERR_ARG,
            "integrator: scheme = %d outside [0, 3] (backward_euler, newmark, hht, "
            "generalized_alpha)",
            (int)o->scheme);
  FCM_CHECK(o->scheme != FCM_SCHEME_HHT || (o->hht_alpha >= -1.0 / 3.0 && o->hht_alpha <= 0.0), ctx,
            FCM_ERR_ARG,
            "integrator: hht_alpha = %g outside [-1/3, 0] (HHT is unconditionally stable and "
            "second order there)",
            o->hht_alpha);
  FCM_CHECK(o->scheme != FCM_SCHEME_GENERALIZED_ALPHA || (o->rho_inf >= 0.0 && o->rho_inf <= 1.0),
            ctx, FCM_ERR_ARG,
            "integrator: rho_inf = %g outside [0, 1] (the generalized-alpha spectral radius at "
            "infinite frequency)",
            o->rho_inf);
cleanup:
  return st;
}

sim_scheme fcm__sim_scheme_constants(const fcm_integrator_options *o)
{
  sim_scheme s;
  memset(&s, 0, sizeof s);
  s.kind = o->kind == FCM_INTEGRATOR_STATIC ? FCM_SCHEME_BACKWARD_EULER : o->scheme;
  s.beta = 0.25;
  s.gamma = 0.5;
  switch (s.kind) {
  case FCM_SCHEME_HHT:
    s.af = -o->hht_alpha;
    s.beta = 0.25 * (1.0 - o->hht_alpha) * (1.0 - o->hht_alpha);
    s.gamma = 0.5 - o->hht_alpha;
    break;
  case FCM_SCHEME_GENERALIZED_ALPHA: {
    const double r = o->rho_inf;
    s.am = (2.0 * r - 1.0) / (r + 1.0);
    s.af = r / (r + 1.0);
    s.gamma = 0.5 - s.am + s.af;
    s.beta = 0.25 * (1.0 - s.am + s.af) * (1.0 - s.am + s.af);
    break;
  }
  default:
    break;
  }
  s.cmass = s.kind == FCM_SCHEME_BACKWARD_EULER ? 1.0 : (1.0 - s.am) / ((1.0 - s.af) * s.beta);
  return s;
}

fcm_status fcm__sim_scheme_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  I->sch = fcm__sim_scheme_constants(&I->opts);
  if (I->opts.kind == FCM_INTEGRATOR_STATIC || I->sch.kind == FCM_SCHEME_BACKWARD_EULER)
    return FCM_OK;
  FCM_ALLOC(I->ctx, I->n, I->a_bak);
  FCM_ALLOC(I->ctx, I->n, I->ud);
  FCM_ALLOC(I->ctx, I->n, I->fstep);
cleanup:
  return st;
}

double fcm__sim_mass_coeff(const fcm_integrator *I, double h)
{
  return I->sch.cmass / (h * h);
}

double fcm__sim_damp_length(const fcm_integrator *I, double h)
{
  return I->sch.kind == FCM_SCHEME_BACKWARD_EULER ? h : I->sch.beta * h / I->sch.gamma;
}

void fcm__sim_set_base(const fcm_integrator *I, double h, fcm_csr *A)
{
  fcm_index nnz = 0;
  fcm_csr_get_size(A, NULL, NULL, &nnz);
  double *v = fcm_csr_values(A);
  const int nt = fcm_ctx_num_threads(I->ctx);
  if (h > 0.0) {
    /* entry by entry, the same values with any thread count; tens of megabytes every step */
    const double *mv = fcm_csr_values_read(I->M), a = fcm__sim_mass_coeff(I, h);
#pragma omp parallel for num_threads(nt) schedule(static) if (nnz > 65536)
    for (fcm_index e = 0; e < nnz; e++)
      v[e] = a * mv[e];
    if (I->D) {
      const double *dv = fcm_csr_values_read(I->D), hd = fcm__sim_damp_length(I, h);
#pragma omp parallel for num_threads(nt) schedule(static) if (nnz > 65536)
      for (fcm_index e = 0; e < nnz; e++)
        v[e] += dv[e] / hd;
    }
  } else {
    memset(v, 0, sizeof *v * (size_t)nnz);
  }
}

void fcm__sim_scheme_predict(fcm_integrator *I, double h)
{
  const sim_scheme *s = &I->sch;
  if (s->kind == FCM_SCHEME_BACKWARD_EULER) {
    for (fcm_index i = 0; i < I->n; i++) {
      I->uhat[i] = I->un[i] + h * I->v[i];
      I->u[i] = I->is_con[i] ? I->un[i] : I->uhat[i];
    }
    return;
  }
  /* u~ = u_n + h v_n + h^2 (1/2 - beta) a_n; u_d = u~ - h_d (v_n + h (1 - gamma) a_n); the
   * guess u~ + beta h^2 a_n keeps the acceleration (exact in free fall) */
  const double c1 = h * h * (0.5 - s->beta), c2 = h * (1.0 - s->gamma), c3 = s->beta * h * h;
  const double hd = fcm__sim_damp_length(I, h);
  for (fcm_index i = 0; i < I->n; i++) {
    I->uhat[i] = I->un[i] + h * I->v[i] + c1 * I->a[i];
    I->ud[i] = I->uhat[i] - hd * (I->v[i] + c2 * I->a[i]);
    I->u[i] = I->is_con[i] ? I->un[i] : I->uhat[i] + c3 * I->a[i];
  }
}

fcm_status fcm__sim_scheme_force(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  int finite = 1;
  FCM_TRY(I->ctx, fcm__sim_internal_force(I, I->u, I->fstep, &finite, stats));
  if (!finite) *reason = FCM_STEP_NONFINITE;
cleanup:
  return st;
}

/* w2 = sum over the processes of A x (A a partial matrix with a backend). */
static fcm_status apply_summed(fcm_integrator *I, const fcm_csr *A, const double *x)
{
  fcm_status st = fcm__space_matrix_apply(I->space, A, x, I->w2);
  return fcm__integrator_reduce_status(I, st, I->w2, I->n);
}

fcm_status fcm__sim_scheme_begin(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  const sim_scheme *s = &I->sch;
  const fcm_index n = I->n;
  const double cf = s->af / (1.0 - s->af), cm = s->am / (1.0 - s->af);
  double *f = I->fstep;
  /* fstep holds f_int(u_n) when alpha_f != 0 (fcm__sim_scheme_force()) */
  if (s->af != 0.0) {
    for (fcm_index i = 0; i < n; i++)
      f[i] = cf * (I->fprev[i] - f[i]);
    if (I->D) {
      FCM_TRY(I->ctx, apply_summed(I, I->D, I->v));
      for (fcm_index i = 0; i < n; i++)
        f[i] -= cf * I->w2[i];
    }
  } else {
    memset(f, 0, sizeof *f * (size_t)n);
  }
  if (s->am != 0.0) {
    FCM_TRY(I->ctx, apply_summed(I, I->M, I->a));
    for (fcm_index i = 0; i < n; i++)
      f[i] -= cm * I->w2[i];
  }
cleanup:
  return st;
}

void fcm__sim_scheme_update(fcm_integrator *I, double h)
{
  const sim_scheme *s = &I->sch;
  if (s->kind == FCM_SCHEME_BACKWARD_EULER) {
    for (fcm_index i = 0; i < I->n; i++)
      I->v[i] = (I->u[i] - I->un[i]) / h;
    return;
  }
  const double ca = 1.0 / (s->beta * h * h), c1 = h * (1.0 - s->gamma), c2 = h * s->gamma;
  for (fcm_index i = 0; i < I->n; i++) {
    const double a1 = ca * (I->u[i] - I->uhat[i]);
    I->v[i] += c1 * I->a[i] + c2 * a1;
    I->a[i] = a1;
  }
  I->a_valid = 1;
}

fcm_status fcm__sim_initial_acceleration(fcm_integrator *I, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  const fcm_index n = I->n;
  fcm_step_reason reason = FCM_STEP_NONE;
  int finite = 1, its = 0;
  fcm_index nnz = 0;
  /* the damping matrix at u_0 (the first substep builds the same one again) */
  memcpy(I->un, I->u, sizeof *I->un * (size_t)n);
  if (I->D) FCM_TRY(I->ctx, fcm__sim_update_damping(I, &reason, stats));
  if (reason == FCM_STEP_NONE)
    FCM_TRY(I->ctx, fcm__sim_internal_force(I, I->u, I->fstep, &finite, stats));
  FCM_CHECK(reason == FCM_STEP_NONE && finite, I->ctx, FCM_ERR_NUMERIC,
            "integrator: initial acceleration at t = %g (scheme %s): the internal force or the "
            "damping matrix at the initial state is not finite",
            I->t, fcm_time_scheme_name(I->sch.kind));
  for (fcm_index i = 0; i < n; i++)
    I->b[i] = I->fprev[i] - I->fstep[i];
  if (I->D) {
    FCM_TRY(I->ctx, apply_summed(I, I->D, I->v));
    for (fcm_index i = 0; i < n; i++)
      I->b[i] -= I->w2[i];
  }
  /* H = M with the active constrained rows and columns eliminated (zero increments there: the
   * constrained DOFs start without acceleration), factored and solved as a Newton system; with
   * hanging nodes M and the right-hand side are reduced as the Newton system is (hanging.c) and
   * the hanging DOFs' accelerations follow their masters' */
  fcm_csr_get_size(I->M, NULL, NULL, &nnz);
  memcpy(fcm_csr_values(fcm__sim_tangent_target(I)), fcm_csr_values_read(I->M),
         sizeof(double) * (size_t)nnz);
  if (I->hP) {
    FCM_TRY(I->ctx, fcm__sim_hanging_matrix(I));
    fcm__sim_hanging_reduce(I, I->b);
  }
  memset(I->w1, 0, sizeof *I->w1 * (size_t)n);
  st = fcm__sim_eliminate(I, 0);
  /* a local failure there meets the others in the backend's factor (its agreement) */
  if (st != FCM_OK) FCM_TRY(I->ctx, fcm__integrator_finish(I, st));
  I->h_state = SIM_H_SYSTEM;
  I->h_psd = 1;
  I->key_h = -1.0; /* no Newton system: nothing reuses this factor */
  I->kept = 0;
  I->mg_warm = 0;
  I->mg_iteration = 0;
  st = fcm__sim_factor(I, &reason, stats);
  if (st == FCM_OK && reason == FCM_STEP_NONE)
    st = fcm__sim_solve(I, I->b, I->a, &reason, &its, stats);
  I->h_state = SIM_H_INVALID;
  I->kept = 0;
  FCM_TRY(I->ctx, st);
  for (fcm_index i = 0; reason == FCM_STEP_NONE && i < n; i++)
    if (!isfinite(I->a[i])) reason = FCM_STEP_NONFINITE;
  FCM_CHECK(reason == FCM_STEP_NONE, I->ctx, FCM_ERR_NUMERIC,
            "integrator: initial acceleration at t = %g (scheme %s): the mass matrix solve "
            "M a0 = f_ext - f_int(u0) - D v0 failed (%s; %d linear iterations): the mass "
            "matrix is singular (a DOF without mass: check the density and the stabilization) "
            "or the linear solver did not converge",
            I->t, fcm_time_scheme_name(I->sch.kind), fcm_step_reason_name(reason), its);
  for (fcm_index j = 0; j < I->nact; j++)
    I->a[I->act_dof[j]] = 0.0;
  fcm__sim_hanging_fill(I, I->a);
  I->a_valid = 1;
cleanup:
  if (st != FCM_OK) I->h_state = SIM_H_INVALID, I->kept = 0;
  return st;
}

int fcm_integrator_get_acceleration(const fcm_integrator *I, double *a)
{
  const int known = I && I->a_valid;
  if (a && I) {
    if (known)
      memcpy(a, I->a, sizeof *a * (size_t)I->n);
    else
      memset(a, 0, sizeof *a * (size_t)I->n);
  }
  return known;
}

fcm_status fcm_integrator_set_acceleration(fcm_integrator *I, const double *a)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  for (fcm_index i = 0; a && i < I->n; i++)
    FCM_CHECK(isfinite(a[i]), I->ctx, FCM_ERR_ARG, "integrator: a[%lld] = %g is not finite",
              (long long)i, a[i]);
  if (a) memcpy(I->a, a, sizeof *a * (size_t)I->n);
  I->a_valid = a != NULL;
cleanup:
  return st;
}

double fcm_integrator_load_work(const fcm_integrator *I)
{
  return I ? I->load_work : 0.0;
}

fcm_status fcm_integrator_set_load_work(fcm_integrator *I, double work)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(isfinite(work), I->ctx, FCM_ERR_ARG, "integrator: load work %g is not finite", work);
  I->load_work = work;
cleanup:
  return st;
}
