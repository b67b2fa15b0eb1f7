/* sim: the linear solves of the Newton steps — CHOLMOD with UMFPACK as the fallback when
 * the matrix is not positive definite (a dynamic step's exact tangent: the Newton loop takes
 * the projected one instead; symbolic analyses kept for the whole run), CG /
 * MINRES with Jacobi, block Jacobi, additive Schwarz or multigrid preconditioning
 * (lib/METHOD.md §7), the preconditioner built from a PSD tangent by default
 * (preconditioner_tangent), or multigrid cycles as the solver (SPD Newton matrices). One
 * function per method: factor_direct, setup_preconditioner, mg_factor (set-up) and
 * solve_direct, solve_krylov, mg_solve (solves), gathered with a distributed backend's
 * factor and solve into the solver tables (sim_solver) the integrator calls. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"
#include "mg/mg_impl.h"

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

/* Remember that the current linear solve stagnated or broke down, with the solver's message. */
static void stalled(fcm_integrator *I, const char *msg)
{
  I->solve_stalled = 1;
  snprintf(I->stall_msg, sizeof I->stall_msg, "%s", msg);
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

/* A numerically singular system (the direct path refuses it instead of returning garbage) is
 * a hard error, not a step to retry with a shorter time step: re-raise it with
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
    if ((I->key_h > 0.0 || I->corot_exact) && !I->h_psd && !I->linear) {
      /* An exact tangent of a dynamic step, or the corotated linear model's exact Hessian,
       * that is not positive definite: its Newton direction need not descend, and an LU
       * factorization costs several Cholesky ones. The PSD-projected tangent is SPD there
       * (M/h^2 > 0; the corotated model's warped tangent is SPD on the constrained DOFs of a
       * static step, as the linear stiffness is): the Newton loop takes it. */
      I->h_indefinite = 1;
      fcm_ctx_error_clear(ctx);
      *reason = FCM_STEP_LINEAR_SOLVER_FAILED;
      return FCM_OK;
    }
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

/* The matrix the preconditioner is built from: the eliminated Newton matrix H
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
  const fcm_preconditioner_tangent tm = I->opts.preconditioner_tangent;
  fcm_csr *K0 = NULL;
  *P = I->H;
  /* hanging nodes (hanging.c): H is the constrained matrix, Hpc would need reducing as well;
   * the preconditioner is built from H */
  if (tm == FCM_PC_TANGENT_EXACT || I->h_psd || I->opts.preconditioner == FCM_PRECOND_NONE || I->hP)
    return FCM_OK;
  if (!I->Hpc) FCM_TRY(ctx, fcm_space_matrix_create(I->space, &I->Hpc));
  fcm_index nnz = 0;
  fcm_csr_get_size(I->Hpc, NULL, NULL, &nnz);
  double *pv = fcm_csr_values(I->Hpc);
  const double h = I->key_h;
  fcm__sim_set_base(I, h, I->Hpc);
  if (tm == FCM_PC_TANGENT_LINEAR) {
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

/* ------------------------------------------------------------------ multigrid (fcm/mg.h) */

fcm_status fcm__sim_multigrid_validate(fcm_ctx *ctx, const fcm_integrator_options *o)
{
  fcm_status st = FCM_OK;
  const int as_solver = o->linear_solver == FCM_LINEAR_MULTIGRID;
  const int as_pc = (o->linear_solver == FCM_LINEAR_CG || o->linear_solver == FCM_LINEAR_MINRES) &&
                    o->preconditioner == FCM_PRECOND_MULTIGRID;
  const fcm_mg_options *m = &o->multigrid;
  FCM_CHECK(o->multigrid_fixed_cycles >= 0 && o->multigrid_fixed_cycles <= 1000, ctx, FCM_ERR_ARG,
            "integrator: multigrid_fixed_cycles = %d outside [0, 1000] (0: cycles until the "
            "tolerance)",
            o->multigrid_fixed_cycles);
  FCM_CHECK(o->multigrid_fixed_cycles == 0 || as_solver, ctx, FCM_ERR_ARG,
            "integrator: multigrid_fixed_cycles = %d needs the multigrid solver (linear_solver "
            "FCM_LINEAR_MULTIGRID), not linear_solver %d: a direct solve is exact, CG and MINRES "
            "stop at krylov_rtol (a multigrid preconditioner runs one cycle per iteration)",
            o->multigrid_fixed_cycles, (int)o->linear_solver);
  if (!as_solver && !as_pc) return FCM_OK;
  FCM_CHECK(m->smoother >= 0 && m->smoother < FCM_MG_SMOOTHER_COUNT, ctx, FCM_ERR_ARG,
            "integrator: multigrid.smoother = %d outside [0, %d] (sgs, jacobi, sgs colored)",
            (int)m->smoother, (int)FCM_MG_SMOOTHER_COUNT - 1);
  if (m->smoother == FCM_MG_SMOOTHER_JACOBI)
    FCM_CHECK(m->omega == 0.0 || (isfinite(m->omega) && m->omega > 0.0 && m->omega <= 1.0), ctx,
              FCM_ERR_ARG,
              "integrator: multigrid.omega = %g outside (0, 1] (the Jacobi smoother), or 0 (the "
              "smoother's own)",
              m->omega);
  else
    FCM_CHECK(m->omega == 0.0 || (isfinite(m->omega) && m->omega > 0.0 && m->omega < 2.0), ctx,
              FCM_ERR_ARG,
              "integrator: multigrid.omega = %g outside (0, 2) (the Gauss-Seidel smoothers), or 0 "
              "(the smoother's own)",
              m->omega);
  FCM_CHECK(m->pre_smooth >= 0 && m->post_smooth >= 0 && m->pre_smooth + m->post_smooth >= 1, ctx,
            FCM_ERR_ARG,
            "integrator: multigrid.pre_smooth = %d and post_smooth = %d must be >= 0 with at "
            "least one smoothing step",
            m->pre_smooth, m->post_smooth);
  FCM_CHECK(!as_pc || m->pre_smooth == m->post_smooth, ctx, FCM_ERR_ARG,
            "integrator: multigrid.pre_smooth = %d and post_smooth = %d must be equal when the "
            "multigrid preconditions %s (the cycle must be symmetric positive definite)",
            m->pre_smooth, m->post_smooth, o->linear_solver == FCM_LINEAR_CG ? "CG" : "MINRES");
  FCM_CHECK(m->cycle_index == 1 || m->cycle_index == 2, ctx, FCM_ERR_ARG,
            "integrator: multigrid.cycle_index = %d is neither 1 (V-cycle) nor 2 (W-cycle)",
            m->cycle_index);
  FCM_CHECK(isfinite(m->block_fraction) && m->block_fraction > 0.0 && m->block_fraction <= 1.0, ctx,
            FCM_ERR_ARG, "integrator: multigrid.block_fraction = %g outside (0, 1]",
            m->block_fraction);
  FCM_CHECK(m->max_levels >= 1 && m->max_levels <= 32, ctx, FCM_ERR_ARG,
            "integrator: multigrid.max_levels = %d outside [1, 32]", m->max_levels);
  FCM_CHECK(m->coarse_dofs >= 1, ctx, FCM_ERR_ARG,
            "integrator: multigrid.coarse_dofs = %lld must be >= 1", (long long)m->coarse_dofs);
cleanup:
  return st;
}

const fcm_mg *fcm_integrator_multigrid(const fcm_integrator *I)
{
  return I ? I->mg : NULL;
}

/* A failure of the multigrid: numerical ones (the coarsest Cholesky factorization or a
 * diagonal of a matrix that is not positive definite, cycles that do not converge) fail the
 * solve softly with a warning naming the cause; the others (not a Hex8 box grid, memory)
 * are hard errors, prefixed with the option. */
static fcm_status mg_soft(fcm_integrator *I, fcm_status s, fcm_step_reason *reason)
{
  fcm_ctx *ctx = I->ctx;
  if (s == FCM_ERR_NUMERIC || s == FCM_ERR_SINGULAR || s == FCM_ERR_NOT_CONVERGED) {
    fcm__log(ctx, FCM_LOG_WARNING, "integrator: t = %g: multigrid failed (%s); %s", I->t,
             fcm_ctx_error_message(ctx),
             I->opts.linear_solver == FCM_LINEAR_MULTIGRID
                 ? "the multigrid solver needs a symmetric positive definite Newton matrix "
                   "(static, or dynamic with a linear material or project_psd) and enough "
                   "cycles (krylov_max_iterations); retrying with a shorter step"
                 : "the multigrid preconditioner needs a symmetric positive definite matrix "
                   "(preconditioner_tangent projected or linear); retrying with a shorter step");
    fcm_ctx_error_clear(ctx);
    *reason = FCM_STEP_LINEAR_SOLVER_FAILED;
    return FCM_OK;
  }
  if (s != FCM_OK) {
    fcm__error_prefix(ctx, I->opts.linear_solver == FCM_LINEAR_MULTIGRID
                               ? "integrator: linear_solver multigrid"
                               : "integrator: preconditioner multigrid");
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
  }
  return s;
}

/* The hierarchy on A with A's current values: created at first use and when the matrix or
 * the active constraints changed (the eliminated rows are the multigrid's Dirichlet boundary),
 * else fcm_mg_setup() (new values on the same structure). A setup that
 * finds other eliminated rows (a row whose coupling vanished numerically) builds the hierarchy
 * again. A hierarchy built again takes what is unchanged from the earlier one
 * (fcm__mg_create_from(): the same bits as fcm_mg_create()), which forgets its matrix first
 * when that is another one (it may be gone). */
static fcm_status mg_prepare(fcm_integrator *I, const fcm_csr *A, fcm_step_reason *reason)
{
  fcm_status s = FCM_OK;
  fcm_mg *old = NULL;
  if (I->mg && (I->mg_A != A || I->mg_con != I->key_con)) old = I->mg, I->mg = NULL;
  if (I->mg) {
    s = fcm_mg_setup(I->mg);
    if (s == FCM_ERR_ARG) {
      fcm_ctx_error_clear(I->ctx);
      old = I->mg, I->mg = NULL;
    }
  }
  if (!I->mg) {
    if (I->mg_A != A) fcm__mg_detach(old);
    s = fcm__mg_create_from(I->ctx, &old, I->space, A, &I->opts.multigrid, &I->mg);
    I->mg_A = A;
    I->mg_con = I->key_con;
    I->mg_creations++;
  }
  return mg_soft(I, s, reason);
}

/* The rows H will have eliminated at the current active set (fcm__sim_eliminate()): the
 * constrained DOFs, and the free rows whose every off-diagonal entry of the pattern lies in a
 * constrained column. A coupling that vanishes numerically is not foreseen: the set-up then
 * finds other eliminated rows and builds the hierarchy again (mg_prepare()). */
static void predicted_eliminated(const fcm_integrator *I, const unsigned char *con,
                                 unsigned char *inactive)
{
  const fcm_index *rp = fcm_csr_row_ptr(I->H);
  const int *ci = fcm_csr_col_idx(I->H);
  for (fcm_index i = 0; i < I->n; i++) {
    int off = 0;
    for (fcm_index p = rp[i]; p < rp[i + 1] && !off && !con[i]; p++)
      off = ci[p] != i && !con[ci[p]];
    inactive[i] = (unsigned char)!off;
  }
}

/* Whether the solver has a structure to prepare: FCM_LINEAR_MULTIGRID on a serial space
 * without hanging nodes. */
static int mg_structure_wanted(const fcm_integrator *I)
{
  return I->opts.linear_solver == FCM_LINEAR_MULTIGRID && !I->backend.factor && !I->hP &&
         !I->space->is_local;
}

int fcm__sim_structure_wanted(const fcm_integrator *I)
{
  return mg_structure_wanted(I);
}

/* The solver's structure (mg_structure_wanted()): the hierarchy on H's pattern with the
 * constrained DOFs `con` (n entries) and its version `version` (mg_con), for the first set-up
 * (mg_prepare(): fcm_mg_setup() when that active set holds at the step). Reads of I only
 * what the setup's first stage wrote (options, backend, hanging DOFs, H's pattern) and its
 * hierarchy's fields, which it alone writes. */
static fcm_status mg_structure(fcm_integrator *I, const fcm_integrator *from,
                               const unsigned char *con, long long version, int beside)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  unsigned char *inactive = NULL;
  if (!mg_structure_wanted(I)) return FCM_OK;
  if (I->mg && I->mg_A == I->H && I->mg_con == version) return FCM_OK;
  fcm_mg *old = I->mg;
  I->mg = NULL;
  if (old && I->mg_A != I->H) fcm__mg_detach(old);
  FCM_ALLOC_RAW(ctx, (size_t)I->n + 1, inactive);
  predicted_eliminated(I, con, inactive);
  /* a cut's: old's hierarchy, made on its Newton matrix (the space's pattern), read */
  const fcm_mg *carry = from && from->mg && from->mg_A == from->H ? from->mg : NULL;
  if (carry && !old && beside)
    st = fcm__mg_create_pattern_cut_beside(ctx, carry, from->space, I->space, I->H, inactive,
                                           &I->opts.multigrid, &I->mg);
  else if (carry && !old)
    st = fcm__mg_create_pattern_cut(ctx, carry, from->space, I->space, I->H, inactive,
                                    &I->opts.multigrid, &I->mg);
  else
    st = fcm__mg_create_pattern(ctx, &old, I->space, I->H, inactive, &I->opts.multigrid, &I->mg);
  I->mg_A = I->mg ? I->H : NULL;
  I->mg_con = version;
  I->mg_creations += I->mg != NULL;
  if (st != FCM_OK) {
    fcm__error_prefix(ctx, "integrator: linear_solver multigrid");
    fcm__trace(ctx, __FILE__, __LINE__, __func__);
  }
cleanup:
  fcm__free(ctx, inactive);
  return st;
}

long long fcm__sim_mg_creations(const fcm_integrator *I)
{
  return I->mg_creations;
}

static fcm_status prepare_solver(fcm_integrator *I, const fcm_integrator *from)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator prepare_solver: NULL integrator");
  FCM_CHECK(I->is_setup, I->ctx, FCM_ERR_ARG,
            "integrator prepare_solver: the integrator must be set up (fcm_integrator_setup())");
  const double t0 = fcm_wtime();
  st = mg_structure(I, from, I->is_con, I->con_version, 0);
  I->setup_info.solver_seconds += fcm_wtime() - t0;
cleanup:
  return st;
}

fcm_status fcm_integrator_prepare_solver(fcm_integrator *I)
{
  return prepare_solver(I, NULL);
}

fcm_status fcm__sim_prepare_solver_cut(fcm_integrator *I, const fcm_integrator *old, int beside,
                                       unsigned char **con)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  *con = NULL;
  if (!mg_structure_wanted(I)) return FCM_OK;
  /* the constrained DOFs at old's time: a constraint's DOFs are marked exactly while it is
   * active (fcm__sim_eval_constraints()), whatever the evaluations before */
  FCM_ALLOC(ctx, (size_t)I->n + 1, *con);
  for (fcm_index i = 0; i < I->ncon; i++)
    (*con)[I->con_dof[i]] = (unsigned char)fcm_motion_active(&I->cons[I->con_id[i]].motion, old->t);
  FCM_TRY(ctx, mg_structure(I, old, *con, -1, beside));
cleanup:
  return st;
}

fcm_status fcm__sim_join_solver(fcm_integrator *I, double *seconds)
{
  const fcm_status st = fcm__mg_join(I->mg, seconds);
  if (st != FCM_OK) {
    fcm__error_prefix(I->ctx, "integrator: linear_solver multigrid");
    fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  }
  return st;
}

/* Preconditioner set-up: the hierarchy on the preconditioner's matrix P. Once built on Hpc
 * it stays there: when P is the Newton matrix itself (a PSD tangent: the projection
 * fallback), its values are copied into Hpc instead of building the hierarchy again. */
static fcm_status mg_precond_setup(fcm_integrator *I, fcm_csr *P, fcm_step_reason *reason)
{
  if (I->mg && I->mg_A == I->Hpc && P == I->H && I->Hpc && I->mg_con == I->key_con) {
    fcm_index nnz = 0;
    fcm_csr_get_size(I->H, NULL, NULL, &nnz);
    memcpy(fcm_csr_values(I->Hpc), fcm_csr_values_read(I->H), sizeof(double) * (size_t)nnz);
    P = I->Hpc;
  }
  return mg_prepare(I, P, reason);
}

/* fcm_operator_fn: one cycle from z = 0, counted. */
static fcm_status mg_precond_apply(void *user, const double *r, double *z)
{
  fcm_integrator *I = user;
  I->mg_applies++;
  return fcm_mg_operator(I->mg, r, z);
}

static double norm2(fcm_index n, const double *v)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += v[i] * v[i];
  return sqrt(s);
}

/* The initial guess of the cycles: the warm start of multigrid_fixed_cycles (the first Newton
 * iteration of a (sub)step of the warm start's length: the last accepted Newton solve's
 * correction, its constrained entries the eliminated rows' solutions b / diagonal), else 0. */
static void mg_initial_guess(fcm_integrator *I, const double *b, double *d)
{
  const fcm_index n = I->n;
  if (I->opts.multigrid_fixed_cycles > 0 && I->mg_warm && I->mg_iteration == 0 &&
      I->mg_warm_h == I->key_h) {
    memcpy(d, I->mg_guess, sizeof *d * (size_t)n);
    for (fcm_index j = 0; j < I->nact; j++)
      d[I->act_dof[j]] = b[I->act_dof[j]] / I->act_diag[j];
  } else {
    memset(d, 0, sizeof *d * (size_t)n);
  }
}

/* FCM_LINEAR_MULTIGRID: cycles on H d = b from the initial guess (mg_initial_guess()) until
 * ||b - H d|| <= max(krylov_rtol ||b||, krylov_atol), or exactly multigrid_fixed_cycles
 * cycles when that is set. Stops early (soft failure) when the residual grows past 1e3 ||b||
 * or is not finite (diverging: H is not positive definite) or when 20 cycles reduce it by
 * less than 5 % (stalled). With fixed cycles the residual is computed after the last cycle
 * only, for that test. */
static fcm_status mg_solve(fcm_integrator *I, const double *b, double *d, fcm_step_reason *reason,
                           int *iterations, sim_stats *stats)
{
  fcm_status st = FCM_OK, s = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_index n = I->n;
  const int fixed = I->opts.multigrid_fixed_cycles;
  const int max_cycles = fixed > 0 ? fixed : I->opts.krylov_max_iterations;
  FCM_CHECK(I->mg, ctx, FCM_ERR_INTERNAL, "integrator: no multigrid hierarchy to solve with");
  mg_initial_guess(I, b, d);
  const double bn = norm2(n, b);
  const double target = fixed > 0 ? -1.0 : fmax(I->opts.krylov_rtol * bn, I->opts.krylov_atol);
  double rk = bn, r1 = bn, r_back = bn;
  int k = 0;
  const char *why = NULL, *const stall = "stalled (less than 5 % reduction in 20 cycles)";
  while (!(rk <= target)) {
    if (k >= max_cycles) {
      if (fixed == 0) why = "cycle limit (krylov_max_iterations) reached";
      break;
    }
    s = fcm_mg_cycle(I->mg, b, d);
    if (s != FCM_OK) break;
    k++;
    if (fixed > 0 && k < fixed) continue; /* no test between the fixed cycles */
    if (I->mg_A == I->H) {                /* the same bits, three rows at a time */
      fcm__mg_residual(I->mg, b, d, I->mg_r);
    } else {
      FCM_TRY(ctx, fcm_csr_apply(I->H, -1.0, d, 0.0, I->mg_r));
      for (fcm_index i = 0; i < n; i++)
        I->mg_r[i] += b[i];
    }
    rk = norm2(n, I->mg_r);
    if (k == 1) r1 = rk;
    if (!isfinite(rk) || rk > 1e3 * bn) {
      why = "diverging";
      break;
    }
    if (fixed == 0 && k % 20 == 0) {
      if (rk > 0.95 * r_back) {
        why = stall;
        break;
      }
      r_back = rk;
    }
  }
  *iterations = k;
  stats->linear_iterations += k;
  stats->mg_cycles += k;
  if (s == FCM_OK && why) {
    const double factor = k >= 2 && r1 > 0.0 ? pow(rk / r1, 1.0 / (k - 1)) : 0.0;
    s = fcm__error(ctx, FCM_ERR_NOT_CONVERGED, __FILE__, __LINE__, __func__,
                   "multigrid solve %s: relative residual %g after %d cycles (rtol %g, atol %g), "
                   "mean factor per cycle %.3g",
                   why, bn > 0.0 ? rk / bn : 0.0, k, I->opts.krylov_rtol, I->opts.krylov_atol,
                   factor);
    if (why == stall) stalled(I, fcm_ctx_error_message(ctx));
  }
  st = mg_soft(I, s, reason);
  if (st == FCM_OK && *reason == FCM_STEP_LINEAR_SOLVER_FAILED && I->solve_stalled)
    *reason = FCM_STEP_LINEAR_SOLVER_STAGNATED;
cleanup:
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
  case FCM_PRECOND_MULTIGRID:
    stats->factorizations++;
    I->total_factorizations++;
    return mg_precond_setup(I, P, reason);
  }
  stats->factorizations++;
  I->total_factorizations++;
  return soft(I, s, reason);
}

/* FCM_LINEAR_MULTIGRID: the hierarchy on the Newton matrix itself. */
static fcm_status mg_factor(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  stats->factorizations++;
  I->total_factorizations++;
  return mg_prepare(I, I->H, reason);
}

static fcm_status solve_direct(fcm_integrator *I, const double *b, double *d,
                               fcm_step_reason *reason, int *iterations, sim_stats *stats)
{
  (void)iterations;
  (void)stats;
  fcm_status st = FCM_OK, s;
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(I->direct, ctx, FCM_ERR_INTERNAL, "integrator: no valid factorization to solve with");
  s = fcm_direct_solve(I->direct, b, d);
  if (s == FCM_ERR_SINGULAR) return singular_or_retry(I, reason);
  FCM_TRY(ctx, s);
cleanup:
  return st;
}

static fcm_status solve_krylov(fcm_integrator *I, const double *b, double *d,
                               fcm_step_reason *reason, int *iterations, sim_stats *stats)
{
  fcm_status st = FCM_OK, s;
  fcm_ctx *ctx = I->ctx;
  fcm_krylov_options ko = fcm_krylov_options_default();
  fcm_krylov_info ki;
  fcm_operator_fn S = NULL;
  void *S_user = NULL;
  ko.rtol = I->opts.krylov_rtol;
  ko.atol = I->opts.krylov_atol;
  ko.max_iterations = I->opts.krylov_max_iterations;
  ko.stagnation_window = I->opts.krylov_stagnation_window;
  if (I->jacobi && (I->opts.preconditioner == FCM_PRECOND_JACOBI ||
                    I->opts.preconditioner == FCM_PRECOND_BLOCK_JACOBI)) {
    S = fcm_jacobi_operator;
    S_user = I->jacobi;
  } else if (I->schwarz && I->opts.preconditioner == FCM_PRECOND_SCHWARZ) {
    S = fcm_schwarz_operator;
    S_user = I->schwarz;
  } else if (I->mg && I->opts.preconditioner == FCM_PRECOND_MULTIGRID) {
    S = mg_precond_apply;
    S_user = I;
  }
  const long long applies0 = I->mg_applies;
  memset(d, 0, sizeof *d * (size_t)I->n);
  memset(&ki, 0, sizeof ki);
  if (I->opts.linear_solver == FCM_LINEAR_CG)
    s = fcm_krylov_cg(I->krylov, fcm_csr_operator, I->H, S, S_user, b, d, &ko, &ki);
  else
    s = fcm_krylov_minres(I->krylov, fcm_csr_operator, I->H, S, S_user, b, d, &ko, &ki);
  *iterations = ki.iterations;
  stats->linear_iterations += ki.iterations;
  stats->mg_cycles += I->mg_applies - applies0;
  if (s == FCM_ERR_NOT_CONVERGED) {
    /* Stopped early (iteration limit, stagnation, CG breakdown on an indefinite matrix):
     * the iterate is still usable when it is a finite, non-zero vector; the Newton loop
     * checks that it descends. A stagnation or breakdown is remembered: it names the
     * failure should Newton not get on with it. */
    int usable = 1, nonzero = 0;
    if (ki.reason == FCM_KRYLOV_STAGNATED || ki.reason == FCM_KRYLOV_BREAKDOWN)
      stalled(I, fcm_ctx_error_message(ctx));
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
  if (*reason == FCM_STEP_LINEAR_SOLVER_FAILED && I->solve_stalled)
    *reason = FCM_STEP_LINEAR_SOLVER_STAGNATED;
cleanup:
  return st;
}

/* A distributed backend's factor (fem/fem_backend.h): its soft failure is a failed linear
 * solve (the step is retried). */
static fcm_status backend_factor(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  int failed = 0;
  fcm_status st = I->backend.factor(I->backend.user, I->H, I->is_con, I->h_psd, &failed);
  stats->factorizations++;
  I->total_factorizations++;
  if (st == FCM_OK && failed) *reason = FCM_STEP_LINEAR_SOLVER_FAILED;
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

static fcm_status backend_solve(fcm_integrator *I, const double *b, double *d,
                                fcm_step_reason *reason, int *iterations, sim_stats *stats)
{
  int failed = 0;
  fcm_status st = I->backend.solve(I->backend.user, b, d, iterations, &failed);
  stats->linear_iterations += *iterations;
  if (st == FCM_OK && failed) *reason = FCM_STEP_LINEAR_SOLVER_FAILED;
  return st;
}

/* Set-up of the direct solver: analyzed once here (the UMFPACK fallback on demand). */
static fcm_status direct_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const double t0 = fcm_wtime();
  if (I->opts.direct_method == FCM_DIRECT_CHOLMOD) {
    FCM_TRY(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, I->H, &I->chol));
    if (I->cut_ordering) FCM_TRY(ctx, fcm__direct_set_ordering(I->chol, I->cut_ordering));
    FCM_TRY(ctx, fcm_direct_analyze(I->chol));
  } else {
    FCM_TRY(ctx, fcm_direct_create(ctx, FCM_DIRECT_UMFPACK, I->H, &I->umf));
    FCM_TRY(ctx, fcm_direct_analyze(I->umf));
  }
cleanup:
  I->setup_info.solver_seconds += fcm_wtime() - t0;
  return st;
}

/* Set-up of multigrid as the solver: its residual and, for fixed cycles, the warm start's
 * vectors; the hierarchy itself at the first factor. */
static fcm_status mg_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  FCM_ALLOC(I->ctx, I->n, I->mg_r);
  if (I->opts.multigrid_fixed_cycles > 0) {
    FCM_ALLOC(I->ctx, I->n, I->mg_guess);
    FCM_ALLOC(I->ctx, I->n, I->mg_acc);
  }
  I->mg_warm = 0;
cleanup:
  return st;
}

/* Set-up of a Krylov solver; Schwarz flags the small cut cells. */
static fcm_status krylov_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  FCM_TRY(ctx, fcm_krylov_create(ctx, I->n, &I->krylov));
  if (I->opts.preconditioner == FCM_PRECOND_SCHWARZ) {
    const fcm_mesh *mesh = fcm_space_mesh(I->space);
    const fcm_cell_rules *rules = fcm_space_cell_rules(I->space);
    fcm_index nc = fcm_mesh_num_cells(mesh);
    FCM_ALLOC(ctx, nc, I->schwarz_flag);
    if (rules)
      for (fcm_index c = 0; c < nc; c++)
        I->schwarz_flag[c] = fcm_space_cell_active(I->space, c) &&
                             fcm_cell_rules_class(rules, c) == FCM_CELL_CUT &&
                             fcm_cell_rules_volume_fraction(rules, c) < I->opts.schwarz_theta;
  }
cleanup:
  return st;
}

/* A distributed backend solves with its own solvers: nothing to set up here. */
static fcm_status backend_setup(fcm_integrator *I)
{
  (void)I;
  return FCM_OK;
}

/* The linear solvers of the Newton systems: set up once (fcm_integrator_setup()), then factor
 * (or set up the preconditioner) for each new eliminated matrix H and solve with it. Soft
 * failures set *reason and return FCM_OK. */
struct sim_solver {
  fcm_status (*setup)(fcm_integrator *I);
  fcm_status (*factor)(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats);
  fcm_status (*solve)(fcm_integrator *I, const double *b, double *d, fcm_step_reason *reason,
                      int *iterations, sim_stats *stats);
};

static const sim_solver solver_direct = {direct_setup, factor_direct, solve_direct};
static const sim_solver solver_krylov = {krylov_setup, setup_preconditioner, solve_krylov};
static const sim_solver solver_multigrid = {mg_setup, mg_factor, mg_solve};
static const sim_solver solver_backend = {backend_setup, backend_factor, backend_solve};

fcm_status fcm__sim_solver_setup(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  /* a backend with a factor of its own (a distributed one) takes every solve whatever
   * linear_solver says; the serial backend leaves them to the options */
  if (I->backend.factor) {
    FCM_CHECK(I->opts.multigrid_fixed_cycles == 0, I->ctx, FCM_ERR_ARG,
              "integrator: multigrid_fixed_cycles = %d needs the serial multigrid solver; the "
              "distributed backend solves with its own solver (set it to 0)",
              I->opts.multigrid_fixed_cycles);
    I->solver = &solver_backend;
  } else if (I->opts.linear_solver == FCM_LINEAR_DIRECT) {
    I->solver = &solver_direct;
  } else if (I->opts.linear_solver == FCM_LINEAR_MULTIGRID) {
    I->solver = &solver_multigrid;
  } else {
    I->solver = &solver_krylov;
  }
  st = I->solver->setup(I);
cleanup:
  return st;
}

fcm_status fcm__sim_factor(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  double t0 = fcm_wtime();
  fcm_status st = I->solver->factor(I, reason, stats);
  stats->time_factor += fcm_wtime() - t0;
  return st;
}

fcm_status fcm__sim_solve(fcm_integrator *I, const double *b, double *d, fcm_step_reason *reason,
                          int *iterations, sim_stats *stats)
{
  double t0 = fcm_wtime();
  *iterations = 0;
  I->solve_stalled = 0;
  fcm_status st = I->solver->solve(I, b, d, reason, iterations, stats);
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  stats->time_solve += fcm_wtime() - t0;
  return st;
}
