/* sim: one integrator step (fcm_integrator_step()) — the substeps with halving on failure,
 * each a Newton solve (newton.c) from the constraints and loads at its end, then the accepted
 * step's energies and statistics, or the state restored after a failure. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <math.h>
#include <string.h>

static double dot(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

static int all_finite(fcm_index n, const double *a)
{
  for (fcm_index i = 0; i < n; i++)
    if (!isfinite(a[i])) return 0;
  return 1;
}

/* Step phase: the external load at the end t1 of a substep, the fraction s1 of the step
 * (static: interpolated from the last step's load; the last substep ends on exactly
 * f_ext(t0 + dt), what set_state() restores). Returns 0 when it is not finite. */
static int substep_load(fcm_integrator *I, int dyn, double t1, double s1, int last)
{
  fcm_index n = I->n;
  if (dyn)
    fcm__sim_eval_loads(I, t1, I->fext);
  else if (last)
    memcpy(I->fext, I->fend, sizeof(double) * (size_t)n);
  else
    for (fcm_index i = 0; i < n; i++)
      I->fext[i] = I->lp_bak[i] + s1 * (I->fend[i] - I->lp_bak[i]);
  return all_finite(n, I->fext);
}

/* Step phase: one substep of length h (0: static) ending at t1 from the current state:
 * constraints at t1, the damping matrix where it must be rebuilt, Newton. */
static fcm_status run_substep(fcm_integrator *I, int dyn, double h, double t1,
                              fcm_step_reason *reason, double *residual, double *tol, double *ref,
                              sim_stats *stats)
{
  fcm_status st = FCM_OK;
  /* f_int(u_n) of HHT and generalized-alpha, the boundary constraints at the substep's start */
  if (dyn && I->sch.af != 0.0) FCM_TRY(I->ctx, fcm__sim_scheme_force(I, reason, stats));
  if (*reason != FCM_STEP_NONE) return FCM_OK;
  fcm__sim_eval_constraints(I, t1);
  if (!dyn && I->rigid_ok != I->con_version + 1) {
    /* no mass: a body the constraints leave free makes every Newton matrix singular */
    FCM_TRY(I->ctx, fcm__sim_check_rigid_modes(I, t1));
    I->rigid_ok = I->con_version + 1;
  }
  memcpy(I->un, I->u, sizeof(double) * (size_t)I->n);
  if (dyn && I->D && (!I->linear || I->damp_version == 0))
    FCM_TRY(I->ctx, fcm__sim_update_damping(I, reason, stats));
  if (*reason == FCM_STEP_NONE && dyn && I->fstep) FCM_TRY(I->ctx, fcm__sim_scheme_begin(I));
  if (*reason == FCM_STEP_NONE)
    FCM_TRY(I->ctx, fcm__sim_newton(I, h, t1, reason, residual, tol, ref, stats));
  /* friction's fixed point: the normal forces and tangents at the converged state, and Newton
   * again from it, until they settle */
  for (int k = 0, nk = I->num_contacts > 0 ? fcm__sim_contact_updates(I) : 0;
       k < nk && (*reason == FCM_STEP_CONVERGED); k++) {
    double change = 0.0;
    FCM_TRY(I->ctx, fcm__sim_contact_relag(I, &change));
    if (change <= 1e-3) break;
    I->newton_resume = 1;
    st = fcm__sim_newton(I, h, t1, reason, residual, tol, ref, stats);
    I->newton_resume = 0;
    FCM_TRY(I->ctx, st);
  }
cleanup:
  return st;
}

/* Gather phase of a converged step: the inverted quadrature points of the accepted state (its
 * last energy assembly counted them) and where the first lies: the lowest element's first such
 * point. Each process of the backend (one in a serial run) offers its own first point in its
 * slot of w1 (1 + cell, X, J: 5 doubles per process, summed over the processes) and the lowest
 * cell wins; w1 holds num_dofs doubles, so a run with more than num_dofs / 5 processes reports
 * the count without the place. */
static fcm_status record_inversion(fcm_integrator *I, fcm_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_index elem = -1, cell = -1;
  double X[3] = {0, 0, 0}, det = 0.0;
  int rank = 0, nprocs = 1;
  info->inverted_points = (fcm_index)I->inverted;
  info->inverted_cell = -1;
  if (!(I->inverted > 0.0)) return FCM_OK;
  fcm__assembly_inverted(I->aws, &elem);
  if (elem >= 0 && fcm__assembly_inverted_point(I->aws, elem, I->u, X, &det))
    cell = fcm_space_element_cell(I->space, elem);
  fcm__integrator_processes(I, &rank, &nprocs);
  const fcm_index len = 5 * (fcm_index)nprocs;
  if (len > I->n) return FCM_OK;
  double *slot = I->w1 + 5 * (fcm_index)rank;
  memset(I->w1, 0, sizeof *I->w1 * (size_t)len);
  if (cell >= 0) {
    slot[0] = 1.0 + (double)cell;
    memcpy(slot + 1, X, sizeof X);
    slot[4] = det;
  }
  FCM_TRY(I->ctx, fcm__integrator_reduce(I, I->w1, len));
  cell = -1;
  for (int p = 0; p < nprocs; p++) {
    const double *q = I->w1 + 5 * (fcm_index)p;
    if (q[0] > 0.0 && (cell < 0 || q[0] - 1.0 < (double)cell)) {
      cell = (fcm_index)(q[0] - 1.0);
      memcpy(X, q + 1, sizeof X);
      det = q[4];
    }
  }
  if (cell >= 0) {
    info->inverted_cell = cell;
    memcpy(info->inverted_position, X, sizeof X);
    info->inverted_det = det;
  }
cleanup:
  return st;
}

/* Gather phase of a converged step: time, the static load, the energies, the inverted
 * points. */
static fcm_status accept_step(fcm_integrator *I, int dyn, double t0, fcm_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_index n = I->n;
  double ekin = 0.0;
  I->t = t0 + I->opts.dt;
  I->steps++;
  fcm__sim_store_reactions(I);
  if (!dyn) memcpy(I->load_prev, I->fext, sizeof(double) * (size_t)n);
  if (dyn) {
    st = fcm__space_matrix_apply(I->space, I->M, I->v, I->w1);
    ekin = 0.5 * dot(n, I->v, I->w1);
    /* with a backend: this process's part (M is partial), summed */
    st = fcm__sim_reduce(I, st, &ekin, 1, NULL);
  }
  info->kinetic_energy = ekin;
  info->elastic_energy = I->psi;
  info->external_work = dot(n, I->fext, I->u);
  info->total_energy = ekin + I->psi - info->external_work;
  info->load_work = I->load_work;
  if (st == FCM_OK) st = record_inversion(I, info);
  return st;
}

/* Gather phase of a failed step: back to the state at its start; a soft failure
 * becomes the error that says why (st is a hard error already recorded, or FCM_OK). */
static fcm_status reject_step(fcm_integrator *I, fcm_status st, fcm_step_reason reason, double t0,
                              const fcm_step_info *info)
{
  fcm_index n = I->n;
  memcpy(I->u, I->u_bak, sizeof(double) * (size_t)n);
  memcpy(I->v, I->v_bak, sizeof(double) * (size_t)n);
  memcpy(I->load_prev, I->lp_bak, sizeof(double) * (size_t)n);
  if (I->a_bak) memcpy(I->a, I->a_bak, sizeof(double) * (size_t)n);
  fcm__sim_eval_constraints(I, I->t);
  if (!I->linear) I->h_state = SIM_H_INVALID;
  I->kept = 0;
  I->mg_warm = 0;
  if (st == FCM_OK && reason == FCM_STEP_LINEAR_SOLVER_STAGNATED)
    st = fcm__error(I->ctx, FCM_ERR_NOT_CONVERGED, __FILE__, __LINE__, __func__,
                    "integrator: step %lld from t = %g failed after %d halving(s) (last dt = "
                    "%g): %s, residual %g vs tolerance %g; state left at t = %g. The linear "
                    "solver stalled or broke down (%s): the Newton matrix is singular or nearly "
                    "so (rigid-body modes no constraint holds, a body held at too few points) "
                    "or, for CG, not positive definite",
                    I->steps + 1, t0, info->halvings, info->dt, fcm_step_reason_name(reason),
                    info->residual, info->tolerance, I->t, I->stall_msg);
  if (st == FCM_OK)
    st = fcm__error(I->ctx, reason == FCM_STEP_NONFINITE ? FCM_ERR_NUMERIC : FCM_ERR_NOT_CONVERGED,
                    __FILE__, __LINE__, __func__,
                    "integrator: step %lld from t = %g failed after %d halving(s) (last dt = "
                    "%g): %s, residual %g vs tolerance %g; state left at t = %g",
                    I->steps + 1, t0, info->halvings, info->dt, fcm_step_reason_name(reason),
                    info->residual, info->tolerance, I->t);
  return st;
}

/* Statistics phase: the step's counters and times, the cumulative ones. */
static void record_step_statistics(const fcm_integrator *I, const sim_stats *stats, double t_begin,
                                   fcm_step_info *info)
{
  info->time = I->t;
  info->newton_iterations = stats->newton_iterations;
  info->line_search_backtracks = stats->backtracks;
  info->linear_iterations = stats->linear_iterations;
  info->multigrid_cycles = stats->mg_cycles;
  info->tangent_assemblies = stats->tangent_assemblies;
  info->factorizations = stats->factorizations;
  info->direct_fallbacks = stats->direct_fallbacks;
  info->projection_fallbacks = stats->projection_fallbacks;
  info->reused_factorizations = stats->reused_factorizations;
  info->inexact_solves = stats->inexact_solves;
  info->total_analyses = fcm__sim_analyses(I);
  info->total_multigrid_creations = fcm__sim_mg_creations(I);
  info->total_factorizations = I->total_factorizations;
  info->total_direct_fallbacks = I->total_fallbacks;
  info->time_assembly = stats->time_assembly;
  info->time_factor = stats->time_factor;
  info->time_solve = stats->time_solve;
  info->time_total = fcm_wtime() - t_begin;
}

/* A step of dt in 2^max_halvings units (static: load_steps x 2^max_halvings): substeps
 * of the current size; a failed substep is retried at half the size, down to one unit. */
fcm_status fcm_integrator_step(fcm_integrator *I, fcm_step_info *info)
{
  fcm_status st = FCM_OK;
  fcm_step_info dummy;
  sim_stats stats;
  if (!info) info = &dummy;
  memset(info, 0, sizeof *info);
  info->inverted_cell = -1;
  memset(&stats, 0, sizeof stats);
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(I->is_setup, I->ctx, FCM_ERR_ARG, "integrator: call fcm_integrator_setup() first");
  if (I->num_contacts > 0) FCM_TRY(I->ctx, fcm__sim_contact_check(I, I->u, I->t));
  I->contact_inner_states = 0;
  {
    const fcm_integrator_options *o = &I->opts;
    fcm_index n = I->n;
    int dyn = o->kind == FCM_INTEGRATOR_BACKWARD_EULER;
    double t_begin = fcm_wtime(), t0 = I->t, residual = 0.0, tol = 0.0, ref = 0.0, work = 0.0;
    int H = o->max_halvings, level = 0;
    long long units = (long long)(dyn ? 1 : o->load_steps) << H, done = 0;
    fcm_step_reason reason = FCM_STEP_NONE;
    memcpy(I->u_bak, I->u, sizeof(double) * (size_t)n);
    memcpy(I->v_bak, I->v, sizeof(double) * (size_t)n);
    memcpy(I->lp_bak, I->load_prev, sizeof(double) * (size_t)n);
    if (!dyn) fcm__sim_eval_loads(I, t0 + o->dt, I->fend);
    /* the load at the start (the load work's trapezoid; f_ext(t_n) of HHT, generalized-alpha) */
    if (dyn)
      fcm__sim_eval_loads(I, t0, I->fprev);
    else
      memcpy(I->fprev, I->lp_bak, sizeof(double) * (size_t)n);
    if (dyn && I->a_bak && !I->a_valid) {
      st = fcm__sim_initial_acceleration(I, &stats);
      if (st != FCM_OK) {
        fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
        goto finish;
      }
    }
    if (I->a_bak) memcpy(I->a_bak, I->a, sizeof(double) * (size_t)n);

    while (done < units) {
      long long size = 1LL << (H - level);
      int last = done + size == units;
      double s1 = (double)(done + size) / (double)units;
      double t1 = last ? t0 + o->dt : t0 + s1 * o->dt;
      double h = dyn ? ldexp(o->dt, -level) : 0.0;
      if (!substep_load(I, dyn, t1, s1, last)) {
        reason = FCM_STEP_NONFINITE;
        st = fcm__error(I->ctx, FCM_ERR_NUMERIC, __FILE__, __LINE__, __func__,
                        "integrator: the external load is not finite at t = %g (a load's "
                        "time scale or field returned NaN or infinity)",
                        t1);
        break;
      }
      st = run_substep(I, dyn, h, t1, &reason, &residual, &tol, &ref, &stats);
      if (st != FCM_OK) {
        fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
        break;
      }
      info->dt = dyn ? h : o->dt * (double)size / (double)units;
      if (reason == FCM_STEP_CONVERGED || reason == FCM_STEP_FIXED_ITERATIONS) {
        double dw = 0.0;
        for (fcm_index i = 0; i < n; i++)
          dw += (I->fprev[i] + I->fext[i]) * (I->u[i] - I->un[i]);
        work += 0.5 * dw;
        memcpy(I->fprev, I->fext, sizeof(double) * (size_t)n);
        if (dyn) fcm__sim_scheme_update(I, h);
        done += size;
        info->substeps++;
        /* the contact's smallest distance over every accepted state of the step */
        if (I->num_contacts > 0 && done < units) {
          st = fcm__sim_contact_track(I);
          if (st != FCM_OK) break;
        }
        reason = done < units ? FCM_STEP_NONE : reason;
        continue;
      }
      info->failed_attempts++; /* retry the substep at half the size */
      memcpy(I->u, I->un, sizeof(double) * (size_t)n);
      if (!I->linear) I->h_state = SIM_H_INVALID;
      I->kept = 0;
      I->mg_warm = 0;
      if (level >= H) break;
      level++;
      reason = FCM_STEP_NONE;
    }
  finish:
    info->reason = reason;
    info->halvings = level;
    info->residual = residual;
    info->tolerance = tol;
    info->residual_reference = ref;
    if (st == FCM_OK && (reason == FCM_STEP_CONVERGED || reason == FCM_STEP_FIXED_ITERATIONS)) {
      I->load_work += work;
      st = accept_step(I, dyn, t0, info);
    } else
      st = reject_step(I, st, reason, t0, info);
    record_step_statistics(I, &stats, t_begin, info);
  }
cleanup:
  return st;
}
