/* sim: the linear solves of the Newton steps — CHOLMOD with UMFPACK as the fallback when
 * the matrix is not positive definite (symbolic analyses kept for the whole run), or CG /
 * MINRES with Jacobi, block Jacobi or additive Schwarz preconditioning (lib/METHOD.md §7), the
 * preconditioner built from a PSD tangent by default (preconditioner_tangent). */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

long long fcm__sim_analyses(const fcm_integrator *I)
{
  fcm_direct_info a, b;
  fcm_direct_get_info(I->chol, &a);
  fcm_direct_get_info(I->umf, &b);
  return a.analyses + b.analyses;
}

/* Map a soft failure of a solver call to a step reason; pass hard errors on. */
static fcm_status soft(fcm_integrator *I, fcm_status s, fcm_step_reason *reason)
{
  if (s == FCM_ERR_NUMERIC || s == FCM_ERR_SINGULAR || s == FCM_ERR_NOT_CONVERGED) {
    *reason = s == FCM_ERR_NUMERIC ? FCM_STEP_NONFINITE : FCM_STEP_LINEAR_SOLVER_FAILED;
    fcm_ctx_error_clear(I->ctx);
    return FCM_OK;
  }
  if (s != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return s;
}

/* A numerically singular system (issue 19: the direct path refuses it instead of returning
 * garbage) is a hard error, not a step to retry with a shorter time step: re-raise it with
 * the cause this integrator can name (no active constraint in a static step) before the
 * direct solver's message. */
static fcm_status singular(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  char msg[1024];
  snprintf(msg, sizeof msg, "%s", fcm_ctx_error_message(ctx));
  fcm_ctx_error_clear(ctx);
  const int free_static = I->nact == 0 && I->bcon_active == 0 && I->key_h == 0.0;
  FCM_CHECK(0, ctx, FCM_ERR_SINGULAR, "integrator: the Newton matrix is singular%s: %s%s%s",
            free_static ? " (static step without any active Dirichlet constraint: the body's "
                          "rigid-body modes are unconstrained)"
                        : "",
            msg, strstr(msg, "likely causes") ? "" : "; ",
            strstr(msg, "likely causes") ? "" : FCM__SINGULAR_HINT);
cleanup:
  return st;
}

/* singular() unless boundary constraints are active on a nonlinear material: far from rest
 * their energy (penalty estimated at rest) can make the Newton matrix singular, a soft failure
 * that the Newton loop retries with their PSD penalty part and the step with halving. */
static fcm_status singular_or_retry(fcm_integrator *I, fcm_step_reason *reason)
{
  if (I->bcon_active > 0 && !I->linear) {
    fcm__log(I->ctx, FCM_LOG_WARNING,
             "integrator: t = %g: the Newton matrix with boundary constraints is singular (%s); "
             "retrying (should it persist at large strains: raise nitsche_safety, or use the "
             "penalty method)",
             I->t, fcm_ctx_error_message(I->ctx));
    fcm_ctx_error_clear(I->ctx);
    *reason = FCM_STEP_LINEAR_SOLVER_FAILED;
    return FCM_OK;
  }
  return singular(I);
}

static fcm_status factor_direct(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  fcm_status st = FCM_OK, s;
  fcm_ctx *ctx = I->ctx;
  const double *vals = fcm_csr_values(I->H);
  I->direct = NULL;
  if (I->chol) {
    s = fcm_direct_factor(I->chol, vals);
    stats->factorizations++;
    I->total_factorizations++;
    if (s == FCM_OK) {
      I->direct = I->chol;
      return FCM_OK;
    }
    if (s != FCM_ERR_SINGULAR) return soft(I, s, reason);
    fcm_direct_info di;
    fcm_direct_get_info(I->chol, &di);
    if (di.failed_column < 0) return singular_or_retry(I, reason); /* rank deficient */
    /* Not positive definite: LU with partial pivoting on the same matrix. */
    stats->direct_fallbacks++;
    I->total_fallbacks++;
    fcm__log(ctx, FCM_LOG_WARNING,
             "integrator: t = %g: CHOLMOD failed (%s); factorizing with UMFPACK instead "
             "(direct fallback %lld)",
             I->t, fcm_ctx_error_message(ctx), (long long)I->total_fallbacks);
    fcm_ctx_error_clear(ctx);
  }
  if (!I->umf) {
    FCM_TRY(ctx, fcm_direct_create(ctx, FCM_DIRECT_UMFPACK, I->H, &I->umf));
    FCM_TRY(ctx, fcm_direct_analyze(I->umf));
  }
  s = fcm_direct_factor(I->umf, vals);
  stats->factorizations++;
  I->total_factorizations++;
  if (s == FCM_OK) {
    I->direct = I->umf;
    return FCM_OK;
  }
  /* LU with partial pivoting met a zero or rounding-level pivot: no shorter step changes
   * the rank (mass and constraints stay), so stop with the reason. */
  if (s == FCM_ERR_SINGULAR) return singular_or_retry(I, reason);
  return soft(I, s, reason);
cleanup:
  return st;
}

/* The matrix the preconditioner is built from (issue 19): the eliminated Newton matrix H
 * when its tangent is PSD already or preconditioner_tangent is EXACT; otherwise
 * Hpc = base(h) + K_pc with the PSD-projected tangent at u (PROJECTED) or the linear-elastic
 * stiffness at rest (LINEAR, assembled once into K0), eliminated like H. The exact tangent of
 * the physical points makes the small cut-cell blocks of H indefinite or nearly singular,
 * and their inverses poor; the PSD blocks of Hpc are positive definite (mass) and the
 * preconditioner SPD, while MINRES still solves with H. */
static fcm_status pc_matrix(fcm_integrator *I, fcm_csr **P, fcm_step_reason *reason,
                            sim_stats *stats)
{
  fcm_status st = FCM_OK, s;
  fcm_ctx *ctx = I->ctx;
  const fcm_fictitious_model tm = I->opts.preconditioner_tangent;
  fcm_csr *K0 = NULL;
  *P = I->H;
  if (tm == FCM_FICTITIOUS_EXACT || I->h_psd || I->opts.preconditioner == FCM_PRECOND_NONE)
    return FCM_OK;
  if (!I->Hpc) FCM_TRY(ctx, fcm_space_matrix_create(I->space, &I->Hpc));
  fcm_index nnz = 0;
  fcm_csr_get_size(I->Hpc, NULL, NULL, &nnz);
  double *pv = fcm_csr_values(I->Hpc);
  const double h = I->key_h;
  fcm__sim_set_base(I, h, I->Hpc);
  if (tm == FCM_FICTITIOUS_LINEAR) {
    if (!I->K0) { /* kept only when complete */
      fcm_linear_form form = fcm_linear_form_default();
      form.term = FCM_LINEAR_STIFFNESS;
      form.material = &I->mat;
      FCM_TRY(ctx, fcm_space_matrix_create(I->space, &K0));
      FCM_TRY(ctx, fcm_assembly_workspace_linear(I->aws, &form, K0, NULL));
      I->K0 = K0;
      K0 = NULL;
    }
    const double *kv = fcm_csr_values(I->K0);
    for (fcm_index e = 0; e < nnz; e++)
      pv[e] += kv[e];
  } else {
    s = fcm_assembly_workspace_hyperelastic(I->aws, &I->params_psd, I->u, NULL, NULL, I->Hpc);
    stats->tangent_assemblies++;
    if (s != FCM_OK) return soft(I, s, reason);
  }
  if (I->bcon_active > 0) { /* boundary constraints: their PSD penalty part */
    int finite = 1;
    FCM_TRY(ctx, fcm__sim_boundary_assemble(I, I->u, 1, NULL, NULL, I->Hpc, &finite));
    if (!finite) {
      *reason = FCM_STEP_NONFINITE;
      return FCM_OK;
    }
  }
  /* Eliminate the active constraints as H was (only the matrix matters; nothing allocated). */
  fcm__eliminate_marked(I->Hpc, NULL, I->is_con, NULL);
  *P = I->Hpc;
cleanup:
  fcm_csr_destroy(&K0);
  return st;
}

/* Schwarz with one block per flagged cell (cut cells with volume fraction below theta). */
static fcm_status schwarz_create(fcm_integrator *I, const fcm_csr *P)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_index nb = 0, nd = 0, *ptr = NULL, *dofs = NULL;
  FCM_TRY(ctx, fcm_space_cell_blocks(I->space, I->schwarz_flag, &nb, &nd, NULL, NULL));
  FCM_ALLOC(ctx, nb + 1, ptr);
  FCM_ALLOC(ctx, FCM_MAX(nd, 1), dofs);
  FCM_TRY(ctx, fcm_space_cell_blocks(I->space, I->schwarz_flag, &nb, &nd, ptr, dofs));
  FCM_TRY(ctx, fcm_schwarz_create(ctx, P, nb, ptr, dofs, &I->opts.schwarz, &I->schwarz));
cleanup:
  fcm__free(ctx, ptr);
  fcm__free(ctx, dofs);
  return st;
}

static fcm_status setup_preconditioner(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  fcm_status s = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_csr *P = NULL;
  s = pc_matrix(I, &P, reason, stats);
  if (s != FCM_OK || *reason != FCM_STEP_NONE) return s;
  switch (I->opts.preconditioner) {
  case FCM_PRECOND_NONE:
    return FCM_OK;
  case FCM_PRECOND_JACOBI:
  case FCM_PRECOND_BLOCK_JACOBI:
    if (I->jacobi)
      s = fcm_jacobi_setup(I->jacobi, P);
    else
      s = fcm_jacobi_create(ctx, P,
                            I->opts.preconditioner == FCM_PRECOND_JACOBI ? FCM_JACOBI_SCALAR
                                                                         : FCM_JACOBI_BLOCK3,
                            &I->jacobi);
    break;
  case FCM_PRECOND_SCHWARZ:
    if (I->schwarz)
      s = fcm_schwarz_setup(I->schwarz, P);
    else
      s = schwarz_create(I, P);
    break;
  }
  stats->factorizations++;
  I->total_factorizations++;
  return soft(I, s, reason);
}

fcm_status fcm__sim_factor(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  double t0 = fcm_wtime();
  fcm_status st = I->opts.linear_solver == FCM_LINEAR_DIRECT
                      ? factor_direct(I, reason, stats)
                      : setup_preconditioner(I, reason, stats);
  stats->time_factor += fcm_wtime() - t0;
  return st;
}

fcm_status fcm__sim_solve(fcm_integrator *I, const double *b, double *d, fcm_step_reason *reason,
                          int *iterations, sim_stats *stats)
{
  fcm_status st = FCM_OK, s;
  fcm_ctx *ctx = I->ctx;
  double t0 = fcm_wtime();
  *iterations = 0;
  if (I->opts.linear_solver == FCM_LINEAR_DIRECT) {
    FCM_CHECK(I->direct, ctx, FCM_ERR_INTERNAL, "integrator: no valid factorization to solve with");
    s = fcm_direct_solve(I->direct, b, d);
    if (s == FCM_ERR_SINGULAR) {
      st = singular_or_retry(I, reason);
      goto cleanup;
    }
    FCM_TRY(ctx, s);
  } else {
    fcm_krylov_options ko = fcm_krylov_options_default();
    fcm_krylov_info ki;
    fcm_operator_fn S = NULL;
    void *S_user = NULL;
    ko.rtol = I->opts.krylov_rtol;
    ko.atol = I->opts.krylov_atol;
    ko.max_iterations = I->opts.krylov_max_iterations;
    if (I->jacobi && (I->opts.preconditioner == FCM_PRECOND_JACOBI ||
                      I->opts.preconditioner == FCM_PRECOND_BLOCK_JACOBI)) {
      S = fcm_jacobi_operator;
      S_user = I->jacobi;
    } else if (I->schwarz && I->opts.preconditioner == FCM_PRECOND_SCHWARZ) {
      S = fcm_schwarz_operator;
      S_user = I->schwarz;
    }
    memset(d, 0, sizeof *d * (size_t)I->n);
    memset(&ki, 0, sizeof ki);
    if (I->opts.linear_solver == FCM_LINEAR_CG)
      s = fcm_krylov_cg(I->krylov, fcm_csr_operator, I->H, S, S_user, b, d, &ko, &ki);
    else
      s = fcm_krylov_minres(I->krylov, fcm_csr_operator, I->H, S, S_user, b, d, &ko, &ki);
    *iterations = ki.iterations;
    stats->linear_iterations += ki.iterations;
    if (s == FCM_ERR_NOT_CONVERGED) {
      /* Stopped early (iteration limit, CG breakdown on an indefinite matrix): the iterate
       * is still usable when it is a finite, non-zero vector; the Newton loop checks that
       * it descends. */
      int usable = 1, nonzero = 0;
      for (fcm_index i = 0; i < I->n; i++) {
        if (!isfinite(d[i])) usable = 0;
        if (d[i] != 0.0) nonzero = 1;
      }
      if (usable && nonzero) {
        fcm_ctx_error_clear(ctx);
        stats->inexact_solves++;
        s = FCM_OK;
      }
    }
    FCM_TRY(ctx, soft(I, s, reason));
  }
cleanup:
  stats->time_solve += fcm_wtime() - t0;
  return st;
}
