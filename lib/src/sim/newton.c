/* sim: Newton's method of one substep with a backtracking (Armijo) line search on the
 * incremental potential (the step around it, its substeps and halving: step.c).
 *
 * lib/METHOD.md §8 and Longva et al. (2020) §3, §6: backward Euler minimizes
 * E(u) = 1/2 |u - u^|_M^2 / h^2 + Psi(u) - f^T u (+ 1/(2h) |u - u_n|_D^2); its gradient is
 * M v' - f_total, and the Newton loop stops when that is below 1e-5 |M a_rep| (the paper's
 * rule; a_rep = gravity) or below a relative threshold. Prescribed motion enters through
 * symmetric elimination: while a constrained DOF is off its prescribed value, the Newton
 * system carries the increment that reaches it (a "predictor" update, taken in full for the
 * constrained DOFs, snapped exactly); afterwards the constrained increments are zero and
 * the free DOFs descend the energy with the line search. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"

#include <float.h>
#include <math.h>
#include <string.h>

static double dot(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

static double norm_free(const fcm_integrator *I, const double *g)
{
  double s = 0.0;
  for (fcm_index i = 0; i < I->n; i++)
    if (!I->is_con[i]) s += g[i] * g[i];
  return sqrt(s);
}

static int all_finite(fcm_index n, const double *a)
{
  for (fcm_index i = 0; i < n; i++)
    if (!isfinite(a[i])) return 0;
  return 1;
}

/* Hyperelastic assembly that turns FCM_ERR_NUMERIC (material NaN/Inf) into *finite = 0. */
static fcm_status assemble(fcm_integrator *I, const fcm_material_params *p, const double *x,
                           double *psi, double *fint, fcm_csr *T, int *finite, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  double t0 = fcm_wtime();
  if (I->params.model == FCM_MATERIAL_COROTATED_LINEAR)
    fcm__assembly_corot_tangent(I->aws, I->corot_exact);
  st = fcm_assembly_workspace_hyperelastic(I->aws, p, x, psi, fint, T);
  stats->time_assembly += fcm_wtime() - t0;
  if (T) stats->tangent_assemblies++;
  if (st == FCM_ERR_NUMERIC) {
    fcm_ctx_error_clear(I->ctx);
    *finite = 0;
    return FCM_OK;
  }
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

/* The boundary constraints' terms (nitsche.c) and the contact barrier's (contact.c) at x:
 * energy, force, tangent (projected: the boundary constraints' PSD penalty part only), timed
 * with the assembly. */
static fcm_status assemble_boundary(fcm_integrator *I, const double *x, int projected,
                                    double *energy, double *fint, fcm_csr *T, int *finite,
                                    sim_stats *stats)
{
  if (I->bcon_active == 0 && I->num_contacts == 0) return FCM_OK;
  double t0 = fcm_wtime();
  fcm_status st = FCM_OK;
  if (I->bcon_active > 0)
    st = fcm__sim_boundary_assemble(
        I, x, projected || I->params.project_psd || (T && I->bc_psd_only), energy, fint, T, finite);
  /* the contact barrier (contact.c): its Hessian is positive semidefinite as it is */
  if (st == FCM_OK && *finite && I->num_contacts > 0)
    fcm__sim_contact_assemble(I, x, energy, fint, T, finite);
  stats->time_assembly += fcm_wtime() - t0;
  if (st != FCM_OK) fcm__trace(I->ctx, __FILE__, __LINE__, __func__);
  return st;
}

/* The base of the Newton matrix into H before the tangent is added. With a backend
 * (fem/fem_backend.h) H stays this process's partial matrix (the backend adds the processes'
 * matrices): M/h^2 + D/h of its partial M and D, the serial formula. */
static void tangent_base(fcm_integrator *I, double h)
{
  fcm__sim_set_base(I, h, fcm__sim_tangent_target(I));
}

/* Agree on st and on *finite, and sum the scalars and fint over the processes of the backend
 * (every process then holds the same global values; the serial backend's sums are the values
 * themselves); the matrices stay partial (fem/fem_backend.h). */
static fcm_status reduce_eval(fcm_integrator *I, fcm_status st, double *scalars, int ns,
                              double *fint, int *finite, sim_stats *stats)
{
  double s[4] = {0, 0, 0, 0}; /* up to 3 scalars, then the count of non-finite processes */
  for (int k = 0; k < ns; k++)
    s[k] = scalars[k];
  s[ns] = *finite ? 0.0 : 1.0;
  double t0 = fcm_wtime();
  st = fcm__sim_reduce(I, st, s, ns + 1, NULL);
  if (st == FCM_OK && s[ns] == 0.0 && fint) st = fcm__sim_reduce(I, FCM_OK, NULL, 0, fint);
  stats->time_assembly += fcm_wtime() - t0;
  if (st != FCM_OK) return st;
  *finite = s[ns] == 0.0;
  for (int k = 0; k < ns; k++)
    scalars[k] = s[k];
  return FCM_OK;
}

/* Tangent at x into H: H = base(h) + K(x), optionally with the PSD-projected material. */
static fcm_status assemble_tangent(fcm_integrator *I, double h, const double *x, int projected,
                                   int *finite, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  tangent_base(I, h);
  fcm_csr *A = fcm__sim_tangent_target(I);
  st = assemble(I, projected ? &I->params_psd : &I->params, x, NULL, NULL, A, finite, stats);
  if (st == FCM_OK && *finite)
    st = assemble_boundary(I, x, projected, NULL, NULL, A, finite, stats);
  FCM_TRY(I->ctx, reduce_eval(I, st, NULL, 0, NULL, finite, stats));
cleanup:
  return st;
}

fcm_status fcm__sim_internal_force(fcm_integrator *I, const double *x, double *fint, int *finite,
                                   sim_stats *stats)
{
  fcm_status st = FCM_OK;
  double psi = 0.0, bnd = 0.0;
  *finite = 1;
  memset(fint, 0, sizeof *fint * (size_t)I->n);
  st = assemble(I, &I->params, x, &psi, fint, NULL, finite, stats);
  if (st == FCM_OK && *finite) st = assemble_boundary(I, x, 0, &bnd, fint, NULL, finite, stats);
  FCM_TRY(I->ctx, reduce_eval(I, st, NULL, 0, fint, finite, stats));
  if (*finite) *finite = all_finite(I->n, fint);
cleanup:
  return st;
}

/* Energy parts at x: E, the internal force fint, the gradient g (n each), the elastic
 * energy, the magnitude scale of E (sum of the absolute parts) and the inverted quadrature
 * points the assembly met (fcm__assembly_inverted()). With `tangent`, H = base + K(x) in the
 * same pass. *finite = 0 when anything is NaN/Inf. */
typedef struct eval_out {
  double E, psi, scale, inverted;
  int finite;
} eval_out;

static fcm_status evaluate(fcm_integrator *I, double h, const double *x, int tangent, double *fint,
                           double *g, eval_out *out, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  fcm_index n = I->n;
  double psi = 0.0, inertia = 0.0, damp = 0.0, wext, bnd = 0.0;
  out->finite = 1;
  memset(fint, 0, sizeof *fint * (size_t)n);
  fcm_csr *A = tangent ? fcm__sim_tangent_target(I) : NULL;
  if (tangent) tangent_base(I, h);
  st = assemble(I, &I->params, x, &psi, fint, A, &out->finite, stats);
  if (st == FCM_OK && out->finite)
    st = assemble_boundary(I, x, 0, &bnd, fint, A, &out->finite, stats);
  {
    double parts[3] = {psi, bnd, (double)fcm__assembly_inverted(I->aws, NULL)};
    FCM_TRY(I->ctx, reduce_eval(I, st, parts, 3, fint, &out->finite, stats));
    psi = parts[0];
    bnd = parts[1];
    out->inverted = parts[2];
  }
  if (!out->finite) return FCM_OK;
  {
    double t0 = fcm_wtime();
    for (fcm_index i = 0; i < n; i++)
      g[i] = fint[i] - I->fext[i];
    if (h > 0.0) {
      for (fcm_index i = 0; i < n; i++)
        I->w1[i] = x[i] - I->uhat[i];
      /* with a backend M is this process's partial matrix: sum the product (n doubles); at the
       * initial guess itself (x = u^, the first evaluation of a step) M 0 = +0 (each row's sum
       * of signed zeros from +0), which the product is not needed for */
      int at_guess = 1;
      for (fcm_index i = 0; i < n && at_guess; i++)
        at_guess = I->w1[i] == 0.0;
      if (at_guess) {
        memset(I->w2, 0, sizeof *I->w2 * (size_t)n);
        st = FCM_OK;
      } else {
        st = fcm__space_matrix_apply(I->space, I->M, I->w1, I->w2);
      }
      FCM_TRY(I->ctx, fcm__integrator_reduce_status(I, st, I->w2, n));
      const double a = fcm__sim_mass_coeff(I, h);
      inertia = 0.5 * a * dot(n, I->w1, I->w2);
      for (fcm_index i = 0; i < n; i++)
        g[i] += a * I->w2[i];
      if (I->D) {
        /* the damping centre: u_n (backward Euler) or u_d (the other schemes, sim.h) */
        const double *c = I->ud ? I->ud : I->un, hd = fcm__sim_damp_length(I, h);
        for (fcm_index i = 0; i < n; i++)
          I->w1[i] = x[i] - c[i];
        /* with a backend D is this process's partial matrix: sum the product (n doubles) */
        st = fcm__space_matrix_apply(I->space, I->D, I->w1, I->w2);
        FCM_TRY(I->ctx, fcm__integrator_reduce_status(I, st, I->w2, n));
        damp = 0.5 / hd * dot(n, I->w1, I->w2);
        for (fcm_index i = 0; i < n; i++)
          g[i] += I->w2[i] / hd;
      }
    }
    wext = dot(n, I->fext, x);
    if (h > 0.0 && I->fstep) { /* the step's constant force f_a (schemes other than BE) */
      for (fcm_index i = 0; i < n; i++)
        g[i] -= I->fstep[i];
      wext += dot(n, I->fstep, x);
    }
    fcm__sim_hanging_reduce(I, g); /* the constrained problem's gradient (hanging.c) */
    out->psi = psi;
    out->E = inertia + damp + psi + bnd - wext;
    out->scale = fabs(inertia) + fabs(damp) + fabs(psi) + fabs(bnd) + fabs(wext);
    out->finite = isfinite(out->E) && all_finite(n, g);
    stats->time_assembly += fcm_wtime() - t0;
  }
cleanup:
  return st;
}

static int constraints_met(const fcm_integrator *I, const double *x)
{
  for (fcm_index j = 0; j < I->nact; j++)
    if (x[I->act_dof[j]] != I->act_val[j]) return 0;
  return 1;
}

/* Threshold of the stopping rule at the current iterate, and its reference (the force scale
 * the tolerance multiplies: ||M a_rep|| on the free DOFs, or R). */
static double tolerance(const fcm_integrator *I, double rep_free, double r_start, double *ref)
{
  const fcm_integrator_options *o = &I->opts;
  if (o->tolerance_mode == FCM_NEWTON_TOL_REPRESENTATIVE) {
    *ref = rep_free;
    return o->newton_tolerance * rep_free;
  }
  double R = FCM_MAX(r_start, sqrt(dot(I->n, I->fint, I->fint)));
  R = FCM_MAX(R, sqrt(dot(I->n, I->fext, I->fext)));
  *ref = R;
  return FCM_MAX(o->newton_tolerance * R, o->newton_atol);
}

static void swap(double **a, double **b)
{
  double *t = *a;
  *a = *b;
  *b = t;
}

/* fcm__eliminate_marked()'s symmetric elimination on H, with the increments w1 at the
 * constrained DOFs, written for a backend's partial H (fem/fem_backend.h; the serial
 * backend's H is the whole matrix and its sums are the values themselves). Every process
 * zeroes the constrained rows and columns of its matrix; the parts that need the summed
 * matrix — the lift H_fc inc_c of the free right-hand side (predictor) and the constrained
 * diagonal (the summed tangent's, 1 where that is not positive, as the serial rule) — are
 * summed over the processes as vectors: n doubles with a predictor, nact without (the lift is
 * zero then). The diagonal goes on the rows this process owns (act_diag keeps it for the reuse
 * path); b (the same on every process) gets the summed lift and diag * inc on the constrained
 * rows. Collective. */
fcm_status fcm__sim_eliminate(fcm_integrator *I, int predictor)
{
  fcm_status st = FCM_OK;
  const fcm_space *s = I->space;
  const fcm_index n = I->n, nact = I->nact, nrows = fcm__space_num_rows(s);
  const fcm_index *rp = fcm_csr_row_ptr(I->H);
  const int *ci = fcm_csr_col_idx(I->H);
  double *v = fcm_csr_values(I->H), *l = I->w2;
  const unsigned char *con = I->is_con;
  const double *inc = I->w1;
  fcm_index placed = 0, owned_con = 0;
  if (nact == 0) return FCM_OK;
  /* the matrix has the rows of the space's local copies (all of them on a full space): l is
   * zero on the DOFs without a row (no term of this process there) */
  memset(l, 0, sizeof *l * (size_t)n);
#pragma omp parallel for num_threads(fcm_ctx_num_threads(I->ctx)) schedule(static)
  for (fcm_index r = 0; r < nrows; r++) {
    const fcm_index i = fcm__space_row_dof(s, r);
    double acc = 0.0;
    if (con[i]) {
      for (fcm_index e = rp[r]; e < rp[r + 1]; e++) {
        if (ci[e] == i) acc = v[e];
        v[e] = 0.0;
      }
    } else {
      for (fcm_index e = rp[r]; e < rp[r + 1]; e++)
        if (con[ci[e]]) {
          acc += v[e] * inc[ci[e]];
          v[e] = 0.0;
        }
    }
    l[i] = acc;
  }
  if (predictor) {
    FCM_TRY(I->ctx, fcm__integrator_reduce(I, l, n));
    for (fcm_index j = 0; j < nact; j++)
      I->act_diag[j] = l[I->act_dof[j]];
  } else {
    for (fcm_index j = 0; j < nact; j++)
      I->act_diag[j] = l[I->act_dof[j]];
    FCM_TRY(I->ctx, fcm__integrator_reduce(I, I->act_diag, nact));
  }
  if (predictor)
    for (fcm_index i = 0; i < n; i++)
      if (!con[i]) I->b[i] -= l[i];
  /* l (done with) carries each constrained DOF's diagonal to its row below */
  for (fcm_index j = 0; j < nact; j++) {
    const fcm_index d = I->act_dof[j];
    if (!(I->act_diag[j] > 0.0)) I->act_diag[j] = 1.0;
    I->b[d] = I->act_diag[j] * inc[d];
    l[d] = I->act_diag[j];
    owned_con += I->owned[d] != 0;
  }
  for (fcm_index r = 0; r < nrows; r++) {
    const fcm_index d = fcm__space_row_dof(s, r);
    if (!con[d] || !I->owned[d]) continue;
    const fcm_index pos = fcm_csr_position(I->H, r, d);
    FCM_CHECK(pos >= 0, I->ctx, FCM_ERR_INTERNAL,
              "integrator: the Newton matrix's pattern has no diagonal entry at DOF %lld (a "
              "DOF this process owns)",
              (long long)d);
    v[pos] = l[d];
    placed++;
  }
  FCM_CHECK(placed == owned_con, I->ctx, FCM_ERR_INTERNAL,
            "integrator: %lld of the %lld constrained DOFs this process owns have a row in its "
            "Newton matrix (the space's local cells must cover every copy the process owns)",
            (long long)placed, (long long)owned_con);
cleanup:
  return st;
}

/* A corrector iteration of a dynamic step may solve with the kept factorization
 * (reuse_factorization): the direct solver (or the backend's, which then solves with the
 * operator it was last given) holds the factor of this h, active set and damping matrix, and
 * every iteration solved with it contracted enough. Not under the fixed-iteration rule: its
 * steps end where their iterations do, so an iteration on an older tangent leaves its larger
 * residual in the state, and these errors add up from step to step until the run diverges
 * (lib/docs/cutting.md, "Fixed iterations factor anew"). */
static int kept_usable(const fcm_integrator *I, double h)
{
  return I->opts.reuse_factorization && I->opts.newton_fixed_iterations == 0 && !I->linear &&
         h > 0.0 && I->opts.linear_solver == FCM_LINEAR_DIRECT && I->kept && I->kept_ok &&
         I->key_h == h && I->key_con == I->con_version && I->key_damp == I->damp_version;
}

/* Build the eliminated Newton system for the current iterate and factor it, or reuse the
 * factor of a constant (linear) system; b = -g with the constrained increments lifted. */
static fcm_status build_system(fcm_integrator *I, double h, int predictor, int projected,
                               fcm_step_reason *reason, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  fcm_index n = I->n;
  for (fcm_index i = 0; i < n; i++)
    I->b[i] = -I->g[i];
  int reuse = I->linear && !projected && I->h_state == SIM_H_SYSTEM && I->key_h == h &&
              I->key_con == I->con_version && I->key_damp == I->damp_version;
  if (reuse) {
    /* b_f -= H0_fc inc_c, b_c = H_cc inc_c (as fcm_space_apply_dirichlet would). */
    if (predictor) {
      memset(I->w1, 0, sizeof *I->w1 * (size_t)n);
      for (fcm_index j = 0; j < I->nact; j++)
        I->w1[I->act_dof[j]] = I->act_inc[j];
      /* with a backend H0 is this process's partial matrix: sum the product */
      st = fcm__space_matrix_apply(I->space, I->H0, I->w1, I->w2);
      FCM_TRY(I->ctx, fcm__integrator_reduce_status(I, st, I->w2, n));
      for (fcm_index i = 0; i < n; i++)
        if (!I->is_con[i]) I->b[i] -= I->w2[i];
    }
    for (fcm_index j = 0; j < I->nact; j++) {
      fcm_index d = I->act_dof[j];
      I->b[d] = predictor ? I->act_diag[j] * I->act_inc[j] : 0.0;
    }
    return FCM_OK;
  }
  if (I->h_state != SIM_H_TANGENT || projected) {
    int finite = 1;
    FCM_TRY(I->ctx, assemble_tangent(I, h, I->u, projected, &finite, stats));
    if (!finite) {
      I->h_state = SIM_H_INVALID;
      *reason = FCM_STEP_NONFINITE;
      return FCM_OK;
    }
  }
  if (I->hP) FCM_TRY(I->ctx, fcm__sim_hanging_matrix(I)); /* H = P^T Ha P + I_h */
  if (I->H0) {
    fcm_index nnz = 0;
    fcm_csr_get_size(I->H, NULL, NULL, &nnz);
    memcpy(fcm_csr_values(I->H0), fcm_csr_values(I->H), sizeof(double) * (size_t)nnz);
  }
  /* fcm_space_apply_dirichlet's elimination on the integrator's own marks (is_con is the
   * active set act_dof; w1 carries the increments there): nothing allocated per iteration. */
  for (fcm_index j = 0; j < I->nact; j++)
    I->w1[I->act_dof[j]] = predictor ? I->act_inc[j] : 0.0;
  /* a local failure there meets the others in the backend's factor (its agreement) */
  st = fcm__sim_eliminate(I, predictor);
  if (st != FCM_OK) FCM_TRY(I->ctx, fcm__integrator_finish(I, st));
  I->h_state = SIM_H_SYSTEM;
  I->h_psd = projected || I->opts.project_psd || I->linear;
  I->key_h = h;
  I->key_con = I->con_version;
  I->key_damp = I->damp_version;
  I->kept = 0;
  FCM_TRY(I->ctx, fcm__sim_factor(I, reason, stats));
  if (*reason != FCM_STEP_NONE || projected) I->h_state = SIM_H_INVALID;
  I->kept = I->kept_ok = *reason == FCM_STEP_NONE; /* for the keys above */
cleanup:
  if (st != FCM_OK) I->h_state = SIM_H_INVALID, I->kept = 0;
  return st;
}

/* Solve for the direction and pin its constrained entries (Krylov iterates and Schwarz
 * blocks may leave round-off there). */
static fcm_status direction(fcm_integrator *I, int predictor, fcm_step_reason *reason, int *its,
                            sim_stats *stats)
{
  fcm_status st = FCM_OK;
  FCM_TRY(I->ctx, fcm__sim_solve(I, I->b, I->d, reason, its, stats));
  if (*reason != FCM_STEP_NONE) return FCM_OK;
  /* contact between bodies: the pieces' coupling the space's pattern cannot hold */
  if (I->num_contacts > 0)
    FCM_TRY(I->ctx, fcm__sim_bodies_refine(I, I->b, I->d, reason, its, stats));
  if (*reason != FCM_STEP_NONE) return FCM_OK;
  if (!all_finite(I->n, I->d)) {
    *reason = FCM_STEP_NONFINITE;
    return FCM_OK;
  }
  for (fcm_index j = 0; j < I->nact; j++)
    I->d[I->act_dof[j]] = predictor ? I->act_inc[j] : 0.0;
  fcm__sim_hanging_fill(I, I->d); /* hanging DOFs follow their masters */
cleanup:
  return st;
}

static void monitor(const fcm_integrator *I, double t1, int it, double r, double tol, double E,
                    double alpha, int its, int met)
{
  if (!I->opts.monitor) return;
  fcm_newton_event ev;
  ev.time = t1;
  ev.iteration = it;
  ev.residual = r;
  ev.tolerance = tol;
  ev.energy = E;
  ev.step_length = alpha;
  ev.linear_iterations = its;
  ev.constraints_met = met;
  I->opts.monitor(I->opts.monitor_user, &ev);
}

/* Newton set-up phase: the initial guess u^ = u_n + h v_n on free DOFs (exact for
 * free flight), u_n elsewhere, and its evaluation; the tangent it assembled is kept (none
 * when the kept factorization will serve the first iteration). */
static fcm_status newton_start(fcm_integrator *I, double h, eval_out *cur, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  if (h > 0.0 && !I->newton_resume) fcm__sim_scheme_predict(I, h);
  fcm__sim_hanging_fill(I, I->u); /* continuous: hanging DOFs follow their masters */
  if (I->num_contacts > 0 && !I->newton_resume) {
    FCM_TRY(I->ctx, fcm__sim_contact_lag(I, h)); /* friction's normal forces and tangents */
    fcm__sim_contact_pull_back(I);
  }
  /* a predictor iteration (constraints off their values) cannot use the kept factorization */
  const int tangent = !I->linear && !(kept_usable(I, h) && constraints_met(I, I->u));
  FCM_TRY(I->ctx, evaluate(I, h, I->u, tangent, I->fint, I->g, cur, stats));
  I->h_state = I->linear ? (I->h_state == SIM_H_SYSTEM ? SIM_H_SYSTEM : SIM_H_INVALID)
                         : (cur->finite && tangent ? SIM_H_TANGENT : SIM_H_INVALID);
  I->psi = cur->psi;
  I->inverted = cur->inverted;
cleanup:
  return st;
}

/* Newton direction phase: solve for d; a corrector direction that is not a descent
 * direction (indefinite tangent or inexact solve) is retried once with the PSD-projected
 * tangent, which with M/h^2 (or the constraints) is SPD. *slope = g.d; *reason is set
 * when no usable direction exists. */
static fcm_status newton_direction(fcm_integrator *I, double h, int predictor, double *slope,
                                   int *its, int *used_kept, fcm_step_reason *reason,
                                   sim_stats *stats)
{
  fcm_status st = FCM_OK;
  int projected = 0;
  *used_kept = 0;
  if (!predictor && kept_usable(I, h)) {
    /* the kept factorization: b = -g, zero on the constrained DOFs (their increments are 0) */
    for (fcm_index i = 0; i < I->n; i++)
      I->b[i] = -I->g[i];
    for (fcm_index j = 0; j < I->nact; j++)
      I->b[I->act_dof[j]] = 0.0;
    FCM_TRY(I->ctx, direction(I, 0, reason, its, stats));
    if (*reason == FCM_STEP_NONE) {
      *slope = dot(I->n, I->g, I->d);
      if (*slope < 0.0) {
        *used_kept = 1;
        stats->reused_factorizations++;
        goto cleanup;
      }
    }
    /* not a descent direction, or the solve failed: factor anew at this iterate */
    *reason = FCM_STEP_NONE;
    I->kept = 0;
  }
  /* an exact tangent found not positive definite (linsolve.c) earlier in this substep: the
   * projected one from then on, without trying the exact one first */
  if (!I->h_indefinite) FCM_TRY(I->ctx, build_system(I, h, predictor, 0, reason, stats));
  if (I->h_indefinite && (*reason == FCM_STEP_NONE || *reason == FCM_STEP_LINEAR_SOLVER_FAILED)) {
    projected = 1;
    *reason = FCM_STEP_NONE;
    stats->projection_fallbacks++;
    FCM_TRY(I->ctx, build_system(I, h, predictor, 1, reason, stats));
  }
  if (*reason == FCM_STEP_NONE) FCM_TRY(I->ctx, direction(I, predictor, reason, its, stats));
  if (*reason == FCM_STEP_LINEAR_SOLVER_FAILED && I->bcon_active > 0 && !I->opts.project_psd) {
    /* Boundary constraints: far from rest the exact Hessian of the Nitsche terms (penalty
     * estimated at rest) may make the Newton matrix singular; retry with their PSD penalty
     * part only (the material's exact tangent kept, as with node constraints). */
    int its2 = 0;
    projected = 1;
    *reason = FCM_STEP_NONE;
    stats->projection_fallbacks++;
    I->bc_psd_only = 1;
    I->h_state = SIM_H_INVALID;
    st = build_system(I, h, predictor, 0, reason, stats);
    if (st == FCM_OK && *reason == FCM_STEP_NONE)
      st = direction(I, predictor, reason, &its2, stats);
    I->bc_psd_only = 0;
    I->h_state = SIM_H_INVALID;
    FCM_TRY(I->ctx, st);
    *its += its2;
  }
  if (*reason != FCM_STEP_NONE) goto cleanup;
  *slope = dot(I->n, I->g, I->d);
  if (predictor || *slope < 0.0) goto cleanup;
  if (!I->opts.project_psd && !projected) {
    int its2 = 0;
    stats->projection_fallbacks++;
    FCM_TRY(I->ctx, build_system(I, h, 0, 1, reason, stats));
    if (*reason != FCM_STEP_NONE) goto cleanup;
    FCM_TRY(I->ctx, direction(I, 0, reason, &its2, stats));
    *its += its2;
    if (*reason != FCM_STEP_NONE) goto cleanup;
    *slope = dot(I->n, I->g, I->d);
  }
  if (!(*slope < 0.0)) *reason = FCM_STEP_LINE_SEARCH_FAILED;
cleanup:
  return st;
}

/* What the line search found. */
typedef struct line_result {
  int accepted;     /* ut = u + alpha d (fint_t, g_t, trial) is the new iterate */
  int speculative;  /* the trial assembled its tangent (the full step) */
  double alpha, rt; /* step length; free residual norm at the trial */
} line_result;

/* Newton line-search phase: backtracking on E (predictor: constrained DOFs land exactly,
 * the free part backs off only if the energy is not finite there). The tangent of a full
 * step is assembled with it: usually it is accepted and the next iteration needs that
 * tangent (one pass instead of two); not in the `last` iteration of the fixed-iteration
 * rule, which has no next one. */
static fcm_status line_search(fcm_integrator *I, double h, int predictor, int last,
                              const eval_out *cur, double slope, double r, eval_out *trial,
                              line_result *lr, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  const fcm_integrator_options *o = &I->opts;
  lr->alpha = 1.0;
  if (I->num_contacts > 0) { /* never into penetration: 0.9 of the largest safe fraction */
    const double amax = fcm__sim_contact_step_bound(I, I->u, I->d);
    if (0.9 * amax < 1.0) {
      lr->alpha = 0.9 * amax;
      I->contact_filtered++;
    }
  }
  lr->accepted = lr->speculative = 0;
  lr->rt = NAN;
  for (int bt = 0;; bt++) {
    for (fcm_index i = 0; i < I->n; i++)
      I->ut[i] = I->u[i] + lr->alpha * I->d[i];
    if (predictor)
      for (fcm_index j = 0; j < I->nact; j++)
        I->ut[I->act_dof[j]] = I->act_val[j];
    /* not once the exact tangent was found indefinite: the next one is the projected one */
    lr->speculative = !I->linear && !last && bt == 0 && !kept_usable(I, h) && !I->h_indefinite;
    FCM_TRY(I->ctx, evaluate(I, h, I->ut, lr->speculative, I->fint_t, I->g_t, trial, stats));
    if (trial->finite) {
      lr->rt = norm_free(I, I->g_t);
      if (predictor || !o->line_search) {
        lr->accepted = 1;
      } else {
        int armijo = trial->E <= cur->E + o->armijo * lr->alpha * slope;
        /* Where E no longer resolves the decrease (round-off), ask the residual to drop. */
        int flat =
            fabs(trial->E - cur->E) <= 100.0 * DBL_EPSILON * FCM_MAX(cur->scale, trial->scale) &&
            lr->rt < r;
        lr->accepted = armijo || flat;
      }
    }
    if (lr->accepted || bt >= o->max_backtracks) break;
    lr->alpha *= o->backtrack;
    stats->backtracks++;
  }
cleanup:
  return st;
}

/* multigrid_fixed_cycles' warm start: the sum of the accepted updates of this Newton solve
 * (mg_acc; ut - u before the trial is accepted), made the next solve's guess when it ends
 * in success. */
static void warm_accumulate(fcm_integrator *I)
{
  if (!I->mg_acc) return;
  for (fcm_index i = 0; i < I->n; i++)
    I->mg_acc[i] += I->ut[i] - I->u[i];
}

static void warm_finish(fcm_integrator *I, double h, fcm_step_reason reason)
{
  if (!I->mg_acc) return;
  I->mg_warm = reason == FCM_STEP_CONVERGED || reason == FCM_STEP_FIXED_ITERATIONS;
  if (!I->mg_warm) return;
  swap(&I->mg_guess, &I->mg_acc);
  I->mg_warm_h = h;
}

/* Why the Newton loop stops before iteration `it` (FCM_STEP_NONE: it goes on): the stopping
 * rule with the constraints met, then the fixed-iteration rule (newton_fixed_iterations, an
 * accepted end), then the iteration limit. */
static fcm_step_reason newton_stop(const fcm_integrator *I, int it, int finite, int met, double r,
                                   double tol)
{
  const int fixed = I->opts.newton_fixed_iterations;
  if (!finite) return FCM_STEP_NONFINITE;
  if (met && r <= tol) return FCM_STEP_CONVERGED;
  if (fixed > 0 && it >= fixed) return met ? FCM_STEP_FIXED_ITERATIONS : FCM_STEP_MAX_NEWTON;
  if (fixed == 0 && it >= I->opts.newton_max_iterations) return FCM_STEP_MAX_NEWTON;
  return FCM_STEP_NONE;
}

fcm_status fcm__sim_newton(fcm_integrator *I, double h, double t1, fcm_step_reason *reason,
                           double *residual, double *tol_out, double *ref_out, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  const fcm_integrator_options *o = &I->opts;
  eval_out cur, trial;
  double rep_free = 0.0, r = NAN, r_start = NAN, tol = 0.0, ref = 0.0;
  int met = 0;
  *reason = FCM_STEP_NONE;
  I->solve_stalled = 0;
  I->h_indefinite = 0;
  I->corot_exact = 0;
  if (I->mg_acc) memset(I->mg_acc, 0, sizeof *I->mg_acc * (size_t)I->n);

  if (o->tolerance_mode == FCM_NEWTON_TOL_REPRESENTATIVE) rep_free = norm_free(I, I->Ma);
  FCM_TRY(I->ctx, newton_start(I, h, &cur, stats));
  r = cur.finite ? norm_free(I, I->g) : NAN;
  r_start = r;
  tol = tolerance(I, rep_free, r_start, &ref);
  met = constraints_met(I, I->u);
  monitor(I, t1, 0, r, tol, cur.E, 0.0, 0, met);

  for (int it = 0;; it++) {
    *reason = newton_stop(I, it, cur.finite, met, r, tol);
    if (*reason != FCM_STEP_NONE) break;
    /* A predictor step first moves the constrained DOFs onto their prescribed values. */
    int predictor = !met, its = 0, used_kept = 0;
    const int last = o->newton_fixed_iterations > 0 && it + 1 >= o->newton_fixed_iterations;
    double slope = 0.0;
    line_result lr;
    for (fcm_index j = 0; j < I->nact; j++)
      I->act_inc[j] = I->act_val[j] - I->u[I->act_dof[j]];
    I->mg_iteration = it;
    FCM_TRY(I->ctx, newton_direction(I, h, predictor, &slope, &its, &used_kept, reason, stats));
    if (*reason != FCM_STEP_NONE) break;
    FCM_TRY(I->ctx, line_search(I, h, predictor, last, &cur, slope, r, &trial, &lr, stats));
    if (!lr.accepted && used_kept) {
      /* the kept factorization's direction found no decrease: a fresh one at this iterate */
      I->kept = 0;
      its = 0;
      FCM_TRY(I->ctx, newton_direction(I, h, predictor, &slope, &its, &used_kept, reason, stats));
      if (*reason != FCM_STEP_NONE) break;
      FCM_TRY(I->ctx, line_search(I, h, predictor, last, &cur, slope, r, &trial, &lr, stats));
    }
    if (!lr.accepted) {
      I->h_state = SIM_H_INVALID;
      *reason = trial.finite ? FCM_STEP_LINE_SEARCH_FAILED : FCM_STEP_NONFINITE;
      break;
    }
    /* Accept the trial as the new iterate. */
    warm_accumulate(I);
    swap(&I->u, &I->ut);
    swap(&I->fint, &I->fint_t);
    swap(&I->g, &I->g_t);
    cur = trial;
    I->psi = cur.psi;
    I->inverted = cur.inverted;
    if (!I->linear)
      I->h_state = (lr.speculative && lr.alpha == 1.0) ? SIM_H_TANGENT : SIM_H_INVALID;
    stats->newton_iterations++;
    /* an iteration on the kept factorization that backtracked or contracted too little:
     * the next one factors anew */
    if (used_kept && !(lr.alpha == 1.0 && lr.rt <= o->reuse_contraction * r)) I->kept_ok = 0;
    const double r_prev = r;
    r = lr.rt;
    met = constraints_met(I, I->u);
    tol = tolerance(I, rep_free, r_start, &ref);
    /* the corotated linear model on the direct solver assembles the warped tangent at the
     * start of each substep: kept factorizations serve it well while the strains are small.
     * A corrector iteration on a fresh factorization of it that reduced the residual by less
     * than half, with iterations to follow (a large rotation under stress, where Newton on it
     * converges linearly and slowly), turns the exact Hessian on for the rest of the substep,
     * and the next iteration factors it */
    if (I->params.model == FCM_MATERIAL_COROTATED_LINEAR && !o->project_psd && !I->corot_exact &&
        o->linear_solver == FCM_LINEAR_DIRECT && !used_kept && !predictor && !last &&
        !(lr.rt <= 0.5 * r_prev) && !(met && r <= tol)) {
      I->corot_exact = 1;
      I->kept = 0;
      I->h_state = SIM_H_INVALID;
    }
    monitor(I, t1, it + 1, r, tol, cur.E, lr.alpha, its, met);
  }
  /* Newton could not go on with the result of a linear solve that stagnated or broke down:
   * that, not the line search, is why the substep failed */
  if (I->solve_stalled &&
      (*reason == FCM_STEP_LINE_SEARCH_FAILED || *reason == FCM_STEP_MAX_NEWTON))
    *reason = FCM_STEP_LINEAR_SOLVER_STAGNATED;
  warm_finish(I, h, *reason);
cleanup:
  *residual = r;
  *tol_out = tol;
  *ref_out = ref;
  return st;
}

/* D = alpha_M M + beta_K K+(u_n) (projected tangent at the start of the substep). With a
 * backend (fem/fem_backend.h) D is this process's PARTIAL damping matrix, not summed: its
 * cells' K+ and alpha_M M of its partial M; the processes' D sum to the serial one (evaluate() sums
 * its products, the Newton matrix's base adds it partially). */
fcm_status fcm__sim_update_damping(fcm_integrator *I, fcm_step_reason *reason, sim_stats *stats)
{
  fcm_status st = FCM_OK;
  const fcm_integrator_options *o = &I->opts;
  fcm_index nnz = 0;
  int finite = 1;
  fcm_csr_get_size(I->D, NULL, NULL, &nnz);
  double *dv = fcm_csr_values(I->D);
  const double *mv = fcm_csr_values(I->M);
  fcm_csr_set_zero(I->D);
  if (o->rayleigh_stiffness > 0.0) {
    st = assemble(I, &I->params_psd, I->un, NULL, NULL, I->D, &finite, stats);
    FCM_TRY(I->ctx, reduce_eval(I, st, NULL, 0, NULL, &finite, stats));
    if (!finite) {
      *reason = FCM_STEP_NONFINITE;
      return FCM_OK;
    }
  }
  for (fcm_index e = 0; e < nnz; e++)
    dv[e] = o->rayleigh_stiffness * dv[e] + o->rayleigh_mass * mv[e];
  I->damp_version++;
  if (!I->linear) I->h_state = SIM_H_INVALID;
cleanup:
  return st;
}
