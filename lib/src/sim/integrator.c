/* sim: the integrator object — options, loads, prescribed motions, setup (mass and load
 * assembly, constrained DOF lists, solver creation) and the integrators that continue a run
 * across a cut; the state and its queries are in state.c. */
#include "sim/sim_impl.h"
#include "fem/fem_impl.h"
#include "la/la_impl.h"
#include "mg/mg_impl.h"

#include <math.h>
#include <string.h>

fcm_integrator_options fcm_integrator_options_default(void)
{
  fcm_integrator_options o;
  memset(&o, 0, sizeof o);
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.scheme = FCM_SCHEME_BACKWARD_EULER;
  o.hht_alpha = -0.05;
  o.rho_inf = 0.8;
  o.dt = 1.0 / 60.0;
  o.load_steps = 1;
  o.max_halvings = 4;
  o.newton_max_iterations = 100;
  o.tolerance_mode = FCM_NEWTON_TOL_AUTO;
  o.newton_tolerance = 1e-5;
  o.newton_atol = 0.0;
  o.rep_acceleration = 9.81;
  o.line_search = 1;
  o.armijo = 1e-4;
  o.backtrack = 0.5;
  o.max_backtracks = 20;
  o.project_psd = 0;
  o.reuse_factorization = 1;
  o.reuse_contraction = 0.25;
  o.newton_fixed_iterations = 0;
  o.linear_solver = FCM_LINEAR_DIRECT;
  o.direct_method = FCM_DIRECT_CHOLMOD;
  o.preconditioner = FCM_PRECOND_SCHWARZ;
  o.preconditioner_tangent = FCM_PC_TANGENT_PROJECTED;
  o.krylov_rtol = 1e-8;
  o.krylov_atol = 0.0;
  o.krylov_max_iterations = 1000;
  o.multigrid_fixed_cycles = 0;
  o.krylov_stagnation_window = 50;
  o.schwarz_theta = 0.5;
  o.schwarz = fcm_schwarz_options_default();
  o.multigrid = fcm_mg_options_default();
  o.assembly = fcm_assembly_options_default();
  return o;
}

const char *fcm_step_reason_name(fcm_step_reason reason)
{
  switch (reason) {
  case FCM_STEP_NONE:
    return "none";
  case FCM_STEP_CONVERGED:
    return "converged";
  case FCM_STEP_MAX_NEWTON:
    return "max-newton";
  case FCM_STEP_LINE_SEARCH_FAILED:
    return "line-search-failed";
  case FCM_STEP_LINEAR_SOLVER_FAILED:
    return "linear-solver-failed";
  case FCM_STEP_NONFINITE:
    return "nonfinite";
  case FCM_STEP_LINEAR_SOLVER_STAGNATED:
    return "linear-solver-stagnated";
  case FCM_STEP_FIXED_ITERATIONS:
    return "fixed-iterations";
  }
  return "unknown";
}

fcm_status fcm_integrator_create(fcm_ctx *ctx, const fcm_space *space, const fcm_material *mat,
                                 const fcm_integrator_options *opts, fcm_integrator **integ)
{
  fcm_status st = FCM_OK;
  fcm_integrator *I = NULL;
  FCM_CHECK(integ, ctx, FCM_ERR_ARG, "integrator: output pointer is NULL");
  *integ = NULL;
  FCM_CHECK(space && mat, ctx, FCM_ERR_ARG, "integrator: NULL space or material");
  FCM_ALLOC(ctx, 1, I);
  I->ctx = ctx;
  I->space = space;
  I->mat = *mat;
  I->opts = opts ? *opts : fcm_integrator_options_default();
  FCM_TRY(ctx, fcm_material_setup(ctx, mat, &I->params));
  I->params_psd = I->params;
  I->params_psd.project_psd = 1;
  I->params.project_psd = I->opts.project_psd ? 1 : 0;
  I->linear = mat->model == FCM_MATERIAL_LINEAR;
  I->n = fcm_space_num_dofs(space);
  FCM_ALLOC(ctx, I->n, I->u);
  FCM_ALLOC(ctx, I->n, I->v);
  FCM_ALLOC(ctx, I->n, I->a);
  FCM_ALLOC(ctx, I->n, I->load_prev);
  FCM_TRY(ctx, fcm__sim_serial_backend(I));
  *integ = I;
  I = NULL;
cleanup:
  fcm_integrator_destroy(&I);
  return st;
}

void fcm_integrator_destroy(fcm_integrator **integ)
{
  if (!integ || !*integ) return;
  fcm_integrator *I = *integ;
  fcm_ctx *ctx = I->ctx;
  for (int k = 0; k < I->num_loads; k++) {
    fcm__free(ctx, I->loads[k].f);
    fcm__free_large(ctx, I->loads[k].blk);
  }
  fcm__free(ctx, I->loads);
  for (int k = 0; k < I->num_cons; k++)
    fcm__free(ctx, I->cons[k].nodes);
  fcm__free(ctx, I->cons);
  fcm__sim_boundary_free(I);
  fcm__sim_contact_free(I);
  double **vecs[] = {&I->u,        &I->v,      &I->load_prev, &I->act_val, &I->act_inc, &I->Ma,
                     &I->act_diag, &I->u_bak,  &I->v_bak,     &I->lp_bak,  &I->un,      &I->uhat,
                     &I->fext,     &I->fend,   &I->fint,      &I->g,       &I->d,       &I->b,
                     &I->ut,       &I->fint_t, &I->g_t,       &I->w1,      &I->w2,      &I->mg_r,
                     &I->mg_guess, &I->mg_acc, &I->a,         &I->a_bak,   &I->ud,      &I->fstep,
                     &I->fprev};
  for (size_t k = 0; k < sizeof vecs / sizeof vecs[0]; k++)
    FCM_FREE(ctx, *vecs[k]);
  fcm__free(ctx, I->con_dof);
  fcm__free(ctx, I->con_node);
  fcm__free(ctx, I->con_comp);
  fcm__free(ctx, I->con_id);
  fcm__free(ctx, I->is_con);
  fcm__free(ctx, I->con_on);
  fcm__free(ctx, I->reaction);
  fcm__free(ctx, I->act_dof);
  fcm__free(ctx, I->schwarz_flag);
  fcm__free(ctx, I->owned);
  fcm__free(ctx, I->cut_ordering);
  fcm__free_large(ctx, I->blk_mass);
  fcm__free(ctx, I->cut_same);
  fcm__free(ctx, I->cut_rows);
  fcm__free(ctx, I->cut_dirty);
  fcm__free(ctx, I->cut_self);
  fcm_csr_destroy(&I->M);
  fcm_csr_destroy(&I->H);
  fcm_csr_destroy(&I->D);
  fcm_csr_destroy(&I->H0);
  fcm_csr_destroy(&I->Hpc);
  fcm_csr_destroy(&I->K0);
  fcm__sim_hanging_destroy(I);
  fcm_direct_destroy(&I->chol);
  fcm_direct_destroy(&I->umf);
  fcm_krylov_destroy(&I->krylov);
  fcm_jacobi_destroy(&I->jacobi);
  fcm_schwarz_destroy(&I->schwarz);
  fcm_mg_destroy(&I->mg);
  fcm_assembly_workspace_destroy(&I->aws);
  if (I->backend.destroy) I->backend.destroy(I->backend.user);
  fcm__free(ctx, I);
  *integ = NULL;
}

static fcm_status add_load(fcm_integrator *I, const sim_load *load)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(!I->is_setup, I->ctx, FCM_ERR_ARG,
            "integrator: loads must be added before fcm_integrator_setup()");
  FCM_TRY(I->ctx, fcm__resize(I->ctx, (void **)&I->loads, (size_t)I->num_loads,
                              (size_t)I->num_loads + 1, sizeof *I->loads));
  I->loads[I->num_loads++] = *load;
cleanup:
  return st;
}

fcm_status fcm_integrator_add_gravity(fcm_integrator *I, const double accel[3], fcm_time_fn scale,
                                      void *scale_user)
{
  fcm_status st = FCM_OK;
  sim_load l;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(accel, I->ctx, FCM_ERR_ARG, "integrator: gravity is NULL");
  FCM_CHECK(isfinite(accel[0]) && isfinite(accel[1]) && isfinite(accel[2]), I->ctx, FCM_ERR_ARG,
            "integrator: gravity (%g, %g, %g) is not finite", accel[0], accel[1], accel[2]);
  memset(&l, 0, sizeof l);
  l.kind = SIM_LOAD_GRAVITY;
  memcpy(l.accel, accel, sizeof l.accel);
  l.scale = scale;
  l.scale_user = scale_user;
  FCM_TRY(I->ctx, add_load(I, &l));
cleanup:
  return st;
}

static fcm_status add_field_load(fcm_integrator *I, sim_load_kind kind, fcm_field_fn field,
                                 void *user, fcm_time_fn scale, void *scale_user)
{
  fcm_status st = FCM_OK;
  sim_load l;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  FCM_CHECK(field, I->ctx, FCM_ERR_ARG, "integrator: %s field is NULL",
            kind == SIM_LOAD_BODY ? "body force" : "traction");
  memset(&l, 0, sizeof l);
  l.kind = kind;
  l.field = field;
  l.field_user = user;
  l.scale = scale;
  l.scale_user = scale_user;
  FCM_TRY(I->ctx, add_load(I, &l));
cleanup:
  return st;
}

fcm_status fcm_integrator_add_body_force(fcm_integrator *I, fcm_field_fn field, void *user,
                                         fcm_time_fn scale, void *scale_user)
{
  return add_field_load(I, SIM_LOAD_BODY, field, user, scale, scale_user);
}

fcm_status fcm_integrator_add_traction(fcm_integrator *I, fcm_field_fn traction, void *user,
                                       fcm_time_fn scale, void *scale_user)
{
  return add_field_load(I, SIM_LOAD_TRACTION, traction, user, scale, scale_user);
}

static int finite3(const double a[3])
{
  return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

fcm_status fcm_integrator_add_constraint(fcm_integrator *I, fcm_index num_nodes,
                                         const fcm_index *nodes, const fcm_motion *motion, int *id)
{
  fcm_status st = FCM_OK;
  fcm_index *copy = NULL;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(!I->is_setup, ctx, FCM_ERR_ARG,
            "integrator: constraints must be added before fcm_integrator_setup()");
  FCM_CHECK(motion && num_nodes >= 0 && (num_nodes == 0 || nodes), ctx, FCM_ERR_ARG,
            "constraint %d: NULL motion or node list, or num_nodes = %lld < 0", I->num_cons,
            (long long)num_nodes);
  FCM_CHECK(finite3(motion->velocity) && finite3(motion->center) && finite3(motion->axis) &&
                isfinite(motion->angular_speed),
            ctx, FCM_ERR_ARG, "constraint %d: velocity, center, axis or angular_speed not finite",
            I->num_cons);
  FCM_CHECK(isfinite(motion->start) && !isnan(motion->end) && motion->end >= motion->start, ctx,
            FCM_ERR_ARG, "constraint %d: end = %g must be >= start = %g (start finite)",
            I->num_cons, motion->end, motion->start);
  FCM_CHECK(motion->angular_speed == 0.0 ||
                (motion->axis[0] != 0.0 || motion->axis[1] != 0.0 || motion->axis[2] != 0.0),
            ctx, FCM_ERR_ARG, "constraint %d: rotation with a zero axis", I->num_cons);
  {
    fcm_index nn = fcm_mesh_num_nodes(fcm_space_mesh(I->space));
    for (fcm_index k = 0; k < num_nodes; k++)
      FCM_CHECK(nodes[k] >= 0 && nodes[k] < nn, ctx, FCM_ERR_ARG,
                "constraint %d: nodes[%lld] = %lld out of range [0, %lld)", I->num_cons,
                (long long)k, (long long)nodes[k], (long long)nn);
  }
  FCM_ALLOC(ctx, num_nodes, copy);
  if (num_nodes > 0) memcpy(copy, nodes, sizeof *copy * (size_t)num_nodes);
  FCM_TRY(ctx, fcm__resize(ctx, (void **)&I->cons, (size_t)I->num_cons, (size_t)I->num_cons + 1,
                           sizeof *I->cons));
  {
    sim_constraint *c = &I->cons[I->num_cons];
    c->motion = *motion;
    double an = sqrt(motion->axis[0] * motion->axis[0] + motion->axis[1] * motion->axis[1] +
                     motion->axis[2] * motion->axis[2]);
    if (an > 0.0)
      for (int i = 0; i < 3; i++)
        c->motion.axis[i] = motion->axis[i] / an;
    for (int i = 0; i < 3; i++)
      c->motion.components[i] = motion->components[i] != 0;
    c->num_nodes = num_nodes;
    c->nodes = copy;
    copy = NULL;
  }
  if (id) *id = I->num_cons;
  I->num_cons++;
cleanup:
  if (copy) fcm__free(I->ctx, copy);
  return st;
}

void fcm__sim_eval_loads(const fcm_integrator *I, double t, double *f)
{
  memset(f, 0, sizeof *f * (size_t)I->n);
  for (int k = 0; k < I->num_loads; k++) {
    const sim_load *l = &I->loads[k];
    double s = l->scale ? l->scale(l->scale_user, t) : 1.0;
    if (s == 0.0) continue; /* an absent load costs nothing; NaN still propagates below */
    for (fcm_index i = 0; i < I->n; i++)
      f[i] += s * l->f[i];
  }
}

void fcm__sim_eval_constraints(fcm_integrator *I, double t)
{
  const double *X = fcm_mesh_coords(fcm_space_mesh(I->space));
  int changed = 0;
  for (int k = 0; k < I->num_cons; k++) {
    const fcm_motion *m = &I->cons[k].motion;
    unsigned char on = (unsigned char)fcm_motion_active(m, t);
    if (on != I->con_on[k]) changed = 1;
    I->con_on[k] = on;
  }
  if (fcm__sim_boundary_time(I, t)) changed = 1;
  fcm_index j = 0;
  for (fcm_index i = 0; i < I->ncon; i++) {
    if (changed) I->is_con[I->con_dof[i]] = I->con_on[I->con_id[i]];
    if (!I->con_on[I->con_id[i]]) continue;
    double u[3];
    fcm_motion_eval(&I->cons[I->con_id[i]].motion, X + 3 * I->con_node[i], t, u, NULL);
    I->act_dof[j] = I->con_dof[i];
    I->act_val[j] = u[I->con_comp[i]];
    j++;
  }
  I->nact = j;
  if (changed) I->con_version++;
}

/* Representative acceleration vector (uniform): magnitude and direction per the options. */
static void rep_acceleration(const fcm_integrator *I, double a[3])
{
  const double *grav = NULL;
  for (int k = 0; k < I->num_loads && !grav; k++)
    if (I->loads[k].kind == SIM_LOAD_GRAVITY) {
      const double *g = I->loads[k].accel;
      if (g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0) grav = g;
    }
  double dir[3] = {1.0 / sqrt(3.0), 1.0 / sqrt(3.0), 1.0 / sqrt(3.0)}, mag = 9.81;
  if (grav) {
    double gn = sqrt(grav[0] * grav[0] + grav[1] * grav[1] + grav[2] * grav[2]);
    for (int i = 0; i < 3; i++)
      dir[i] = grav[i] / gn;
    mag = gn;
  }
  if (I->opts.rep_acceleration > 0.0) mag = I->opts.rep_acceleration;
  for (int i = 0; i < 3; i++)
    a[i] = mag * dir[i];
}

static fcm_status validate_options(fcm_ctx *ctx, const fcm_integrator_options *o)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(o->kind == FCM_INTEGRATOR_STATIC || o->kind == FCM_INTEGRATOR_BACKWARD_EULER, ctx,
            FCM_ERR_ARG, "integrator: kind = %d must be STATIC (0) or DYNAMIC (1)", (int)o->kind);
  FCM_TRY(ctx, fcm__sim_scheme_validate(ctx, o));
  FCM_CHECK(isfinite(o->dt) && o->dt > 0.0, ctx, FCM_ERR_ARG,
            "integrator: dt = %g must be positive and finite", o->dt);
  FCM_CHECK(o->load_steps >= 1, ctx, FCM_ERR_ARG, "integrator: load_steps = %d must be >= 1",
            o->load_steps);
  FCM_CHECK(o->load_steps <= (1 << 20), ctx, FCM_ERR_ARG,
            "integrator: load_steps = %d must be <= 2^20", o->load_steps);
  FCM_CHECK(o->max_halvings >= 0 && o->max_halvings <= 20, ctx, FCM_ERR_ARG,
            "integrator: max_halvings = %d outside [0, 20]", o->max_halvings);
  FCM_CHECK(o->newton_max_iterations >= 1, ctx, FCM_ERR_ARG,
            "integrator: newton_max_iterations = %d must be >= 1", o->newton_max_iterations);
  FCM_CHECK(o->tolerance_mode == FCM_NEWTON_TOL_REPRESENTATIVE ||
                o->tolerance_mode == FCM_NEWTON_TOL_RELATIVE ||
                o->tolerance_mode == FCM_NEWTON_TOL_AUTO,
            ctx, FCM_ERR_ARG,
            "integrator: tolerance_mode = %d must be 0 (representative), 1 (relative) or 2 (auto)",
            (int)o->tolerance_mode);
  FCM_CHECK(o->newton_tolerance > 0.0 && o->newton_tolerance < 1.0, ctx, FCM_ERR_ARG,
            "integrator: newton_tolerance = %g outside (0, 1)", o->newton_tolerance);
  FCM_CHECK(o->newton_atol >= 0.0 && isfinite(o->newton_atol), ctx, FCM_ERR_ARG,
            "integrator: newton_atol = %g must be finite and >= 0", o->newton_atol);
  FCM_CHECK((o->rep_acceleration > 0.0 && isfinite(o->rep_acceleration)) ||
                o->rep_acceleration == FCM_DEFAULT,
            ctx, FCM_ERR_ARG,
            "integrator: rep_acceleration = %g must be positive and finite, or FCM_DEFAULT (-1)",
            o->rep_acceleration);
  FCM_CHECK(o->armijo > 0.0 && o->armijo < 0.5, ctx, FCM_ERR_ARG,
            "integrator: armijo = %g outside (0, 0.5)", o->armijo);
  FCM_CHECK(o->backtrack > 0.0 && o->backtrack < 1.0, ctx, FCM_ERR_ARG,
            "integrator: backtrack = %g outside (0, 1)", o->backtrack);
  FCM_CHECK(o->max_backtracks >= 0, ctx, FCM_ERR_ARG,
            "integrator: max_backtracks = %d must be >= 0", o->max_backtracks);
  FCM_CHECK(o->reuse_factorization == 0 || o->reuse_factorization == 1, ctx, FCM_ERR_ARG,
            "integrator: reuse_factorization = %d must be 0 or 1", o->reuse_factorization);
  FCM_CHECK(o->reuse_contraction > 0.0 && o->reuse_contraction < 1.0, ctx, FCM_ERR_ARG,
            "integrator: reuse_contraction = %g outside (0, 1)", o->reuse_contraction);
  FCM_CHECK(o->newton_fixed_iterations >= 0 && o->newton_fixed_iterations <= 1000000, ctx,
            FCM_ERR_ARG,
            "integrator: newton_fixed_iterations = %d outside [0, 10^6] (0: the stopping rule "
            "alone)",
            o->newton_fixed_iterations);
  FCM_CHECK(o->linear_solver >= FCM_LINEAR_DIRECT && o->linear_solver <= FCM_LINEAR_MULTIGRID, ctx,
            FCM_ERR_ARG,
            "integrator: linear_solver = %d outside [0, 3] (direct, cg, minres, multigrid)",
            (int)o->linear_solver);
  FCM_CHECK(o->direct_method == FCM_DIRECT_CHOLMOD || o->direct_method == FCM_DIRECT_UMFPACK, ctx,
            FCM_ERR_ARG, "integrator: direct_method = %d must be CHOLMOD (0) or UMFPACK (1)",
            (int)o->direct_method);
  FCM_CHECK(o->preconditioner >= FCM_PRECOND_NONE && o->preconditioner <= FCM_PRECOND_MULTIGRID,
            ctx, FCM_ERR_ARG,
            "integrator: preconditioner = %d outside [0, 4] (none, jacobi, block jacobi, "
            "schwarz, multigrid)",
            (int)o->preconditioner);
  FCM_TRY(ctx, fcm__sim_multigrid_validate(ctx, o));
  FCM_CHECK(o->preconditioner_tangent >= 0 && o->preconditioner_tangent < FCM_PC_TANGENT_COUNT, ctx,
            FCM_ERR_ARG,
            "integrator: preconditioner_tangent = %d outside [0, 2] (projected, linear, exact)",
            (int)o->preconditioner_tangent);
  FCM_CHECK(o->krylov_rtol >= 0.0 && o->krylov_rtol < 1.0, ctx, FCM_ERR_ARG,
            "integrator: krylov_rtol = %g outside [0, 1)", o->krylov_rtol);
  FCM_CHECK(o->krylov_atol >= 0.0 && isfinite(o->krylov_atol), ctx, FCM_ERR_ARG,
            "integrator: krylov_atol = %g must be finite and >= 0", o->krylov_atol);
  FCM_CHECK(o->krylov_max_iterations >= 1, ctx, FCM_ERR_ARG,
            "integrator: krylov_max_iterations = %d must be >= 1", o->krylov_max_iterations);
  FCM_CHECK(o->krylov_stagnation_window >= 0, ctx, FCM_ERR_ARG,
            "integrator: krylov_stagnation_window = %d must be >= 0 (0: off)",
            o->krylov_stagnation_window);
  FCM_CHECK(o->schwarz_theta > 0.0 && o->schwarz_theta <= 1.0, ctx, FCM_ERR_ARG,
            "integrator: schwarz_theta = %g outside (0, 1]", o->schwarz_theta);
  FCM_CHECK(o->cut_reuse >= 0 && o->cut_reuse <= (FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING |
                                                  FCM_CUT_REUSE_STORAGE),
            ctx, FCM_ERR_ARG,
            "integrator: cut_reuse = %d is not a sum of fcm_cut_reuse flags (0 .. %d)",
            o->cut_reuse, FCM_CUT_REUSE_BLOCKS | FCM_CUT_REUSE_ORDERING | FCM_CUT_REUSE_STORAGE);
  FCM_CHECK(o->rayleigh_mass >= 0.0 && isfinite(o->rayleigh_mass), ctx, FCM_ERR_ARG,
            "integrator: rayleigh_mass = %g must be finite and >= 0", o->rayleigh_mass);
  FCM_CHECK(o->rayleigh_stiffness >= 0.0 && isfinite(o->rayleigh_stiffness), ctx, FCM_ERR_ARG,
            "integrator: rayleigh_stiffness = %g must be finite and >= 0", o->rayleigh_stiffness);
cleanup:
  return st;
}

/* The constrained DOF list: every (node with DOFs, constrained component) of every
 * constraint; a DOF in two constraints is an error. */
static fcm_status build_constraints(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  int *owner = NULL;
  fcm_index count = 0;
  FCM_ALLOC(ctx, I->n, owner);
  for (int k = 0; k < I->num_cons; k++) {
    const sim_constraint *c = &I->cons[k];
    for (fcm_index a = 0; a < c->num_nodes; a++) {
      const fcm_index d0 = fcm_space_node_dof(I->space, c->nodes[a]);
      const fcm_index ncp = fcm_space_node_copies(I->space, c->nodes[a]);
      for (fcm_index d = d0; d0 >= 0 && d < d0 + 3 * ncp; d += 3) /* every copy */
        for (int i = 0; i < 3; i++) {
          if (!c->motion.components[i]) continue;
          FCM_CHECK(owner[d + i] == 0 || owner[d + i] == k + 1, ctx, FCM_ERR_ARG,
                    "constraint %d: node %lld component %c is already constrained by constraint %d",
                    k, (long long)c->nodes[a], "xyz"[i], owner[d + i] - 1);
          if (owner[d + i] == 0) count++;
          owner[d + i] = k + 1;
        }
    }
  }
  FCM_TRY(ctx, fcm__sim_hanging_constraints(I, owner));
  I->ncon = count;
  FCM_ALLOC(ctx, count, I->con_dof);
  FCM_ALLOC(ctx, count, I->con_node);
  FCM_ALLOC(ctx, count, I->con_comp);
  FCM_ALLOC(ctx, count, I->con_id);
  FCM_ALLOC(ctx, count, I->act_dof);
  FCM_ALLOC(ctx, count, I->act_val);
  FCM_ALLOC(ctx, count, I->act_inc);
  FCM_ALLOC(ctx, count, I->act_diag);
  FCM_ALLOC(ctx, I->n, I->is_con);
  FCM_ALLOC(ctx, I->num_cons, I->con_on);
  FCM_ALLOC(ctx, 6 * (size_t)I->num_cons + 1, I->reaction);
  count = 0;
  for (int k = 0; k < I->num_cons; k++) {
    const sim_constraint *c = &I->cons[k];
    for (fcm_index a = 0; a < c->num_nodes; a++) {
      const fcm_index d0 = fcm_space_node_dof(I->space, c->nodes[a]);
      const fcm_index ncp = fcm_space_node_copies(I->space, c->nodes[a]);
      for (fcm_index d = d0; d0 >= 0 && d < d0 + 3 * ncp; d += 3) /* every copy */
        for (int i = 0; i < 3; i++) {
          if (!c->motion.components[i] || owner[d + i] != k + 1) continue;
          owner[d + i] = -1; /* a node listed twice in one constraint counts once */
          I->con_dof[count] = d + i;
          I->con_node[count] = c->nodes[a];
          I->con_comp[count] = i;
          I->con_id[count] = k;
          count++;
        }
    }
  }
  I->ncon = count;
  /* Start with every constraint "off" so the first evaluation builds is_con. */
  I->con_version = 0;
cleanup:
  fcm__free(ctx, owner);
  return st;
}

/* 1 when a cut will take I's storage (FCM_CUT_REUSE_STORAGE): the room of its large arrays
 * (H's and M's values, the corotated store) is mapped as they are made, so that the cut
 * growing into it pays no first touch of fresh pages; a quarter more resident memory for
 * those arrays. */
static int maps_room(const fcm_integrator *I)
{
  return (I->opts.cut_reuse & FCM_CUT_REUSE_STORAGE) != 0;
}

/* Set-up phase: the work vectors, the Newton matrix H and the assembly workspace. */
static fcm_status setup_storage(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  double **vecs[] = {&I->Ma,   &I->u_bak,  &I->v_bak, &I->lp_bak, &I->un, &I->uhat,
                     &I->fext, &I->fend,   &I->fint,  &I->g,      &I->d,  &I->b,
                     &I->ut,   &I->fint_t, &I->g_t,   &I->w1,     &I->w2, &I->fprev};
  for (size_t k = 0; k < sizeof vecs / sizeof vecs[0]; k++)
    FCM_ALLOC(ctx, I->n, *vecs[k]);
  /* H's values are written whole (fcm__sim_set_base()) before any read: the values taken
   * from the old integrator's H need no zeroing */
  if (I->hP)
    FCM_TRY(ctx, fcm__sim_hanging_storage(I, &I->H));
  else
    FCM_TRY(ctx, fcm__space_matrix_create_rows_unzeroed(
                     I->space, I->cut_give ? I->cut_give->H : NULL, &I->H));
  if (maps_room(I)) fcm__csr_map_room(I->H);
  FCM_TRY(ctx, fcm_assembly_workspace_create(I->space, &I->opts.assembly, &I->aws));
  /* after a cut: the corotated linear model's element matrices the cut leaves valid (in the
   * old integrator's store, each kept element at its slot, when it gives its storage; else
   * copied) */
  if (I->cut_old && I->cut_same)
    FCM_TRY(ctx, I->cut_give ? fcm__assembly_corot_take(I->aws, I->cut_give->aws, I->cut_same)
                             : fcm__assembly_corot_inherit(I->aws, I->cut_old->aws, I->cut_same));
cleanup:
  return st;
}

/* Set-up phase: the mass matrix (constant; dynamics only) and each load of scale 1. */
static fcm_status setup_mass_and_loads(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_linear_form form = fcm_linear_form_default();
  form.material = &I->mat; /* linear assembly: mass and body forces */
  if (I->opts.kind == FCM_INTEGRATOR_BACKWARD_EULER) {
    FCM_TRY(ctx, fcm__sim_cut_mass_matrix(I, &I->M)); /* after a cut: the kept rows taken */
    if (maps_room(I)) fcm__csr_map_room(I->M);
    form.term = FCM_LINEAR_MASS;
    st = fcm__sim_assemble_kept(I, &form, I->M, NULL, &I->blk_mass,
                                I->cut_old ? I->cut_old->blk_mass : NULL,
                                I->cut_give ? &I->cut_give->blk_mass : NULL);
    /* with a backend M stays this process's partial mass matrix (its cells' part; never
     * summed: every use sums a product, fem/fem_backend.h); agree on the status only */
    FCM_TRY(ctx, fcm__sim_reduce(I, st, NULL, 0, NULL));
    I->setup_info.mass_assemblies = 1;
  }
  for (int k = 0; k < I->num_loads; k++) {
    sim_load *l = &I->loads[k];
    FCM_ALLOC(ctx, I->n, l->f);
    if (I->cut_rows) fcm__sim_cut_load(I, k, l->f);
    form.accel = l->accel;
    form.field = l->field;
    form.user = l->field_user;
    form.term = l->kind == SIM_LOAD_GRAVITY ? FCM_LINEAR_BODY_FORCE
                : l->kind == SIM_LOAD_BODY  ? FCM_LINEAR_BODY_FORCE_FIELD
                                            : FCM_LINEAR_SURFACE_TRACTION;
    st = fcm__sim_assemble_kept(I, &form, NULL, l->f, &l->blk,
                                I->cut_old ? I->cut_old->loads[k].blk : NULL,
                                I->cut_give ? &I->cut_give->loads[k].blk : NULL);
    FCM_TRY(ctx, fcm__sim_reduce(I, st, NULL, 0, l->f));
    if (l->kind == SIM_LOAD_TRACTION)
      I->setup_info.traction_assemblies++;
    else
      I->setup_info.body_force_assemblies++;
  }
cleanup:
  return st;
}

/* Set-up phase: the representative force M a_rep of the representative tolerance and
 * its norm. Static runs have no M: by the partition of unity (sum_b N_b = 1),
 * (M a_rep)_a = int rho N_a a_rep, the body force of rho a_rep, which is the gravity
 * load itself when a_rep is that gravity (the default). */
static fcm_status setup_representative_force(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  fcm_index n = I->n;
  double a[3];
  rep_acceleration(I, a);
  if (I->M) {
    for (fcm_index i = 0; i < n; i++)
      I->w1[i] = a[i % 3];
    /* with a backend: the partial product, summed (n doubles); after a cut: the rows the
     * cut left, old's */
    if (!fcm__sim_cut_rep_force(I)) st = fcm__space_matrix_apply(I->space, I->M, I->w1, I->Ma);
    FCM_TRY(ctx, fcm__sim_reduce(I, st, NULL, 0, I->Ma));
  } else {
    const sim_load *same = NULL;
    for (int k = 0; k < I->num_loads && !same; k++)
      if (I->loads[k].kind == SIM_LOAD_GRAVITY && I->loads[k].accel[0] == a[0] &&
          I->loads[k].accel[1] == a[1] && I->loads[k].accel[2] == a[2])
        same = &I->loads[k];
    if (same) {
      memcpy(I->Ma, same->f, sizeof *I->Ma * (size_t)n);
    } else {
      fcm_linear_form form = fcm_linear_form_default();
      form.term = FCM_LINEAR_BODY_FORCE;
      form.material = &I->mat;
      form.accel = a;
      memset(I->Ma, 0, sizeof *I->Ma * (size_t)n);
      st = fcm_assembly_workspace_linear(I->aws, &form, NULL, I->Ma);
      FCM_TRY(ctx, fcm__sim_reduce(I, st, NULL, 0, I->Ma));
      I->setup_info.scale_assemblies = 1;
    }
  }
  fcm__sim_hanging_reduce(I, I->Ma); /* the constrained problem's force, as its residual */
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += I->Ma[i] * I->Ma[i];
  I->rep_norm_full = sqrt(s);
  FCM_CHECK(I->rep_norm_full > 0.0 && isfinite(I->rep_norm_full), ctx, FCM_ERR_ARG,
            "integrator: the representative force ||M a_rep|| is %g (density %g): set a "
            "positive density or use FCM_NEWTON_TOL_RELATIVE",
            I->rep_norm_full, I->mat.density);
cleanup:
  return st;
}

/* Set-up phase: the pristine copy (linear), the damping matrix, and the linear solver
 * (fcm__sim_solver_setup()). */
static fcm_status setup_solvers(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  const fcm_integrator_options *o = &I->opts;
  if (I->linear && I->hP)
    FCM_TRY(ctx, fcm__sim_hanging_storage(I, &I->H0));
  else if (I->linear)
    FCM_TRY(ctx, fcm__space_matrix_create_rows(I->space, &I->H0));
  if (o->kind == FCM_INTEGRATOR_BACKWARD_EULER &&
      (o->rayleigh_mass > 0.0 || o->rayleigh_stiffness > 0.0))
    FCM_TRY(ctx, fcm__space_matrix_create_rows(I->space, &I->D));
  FCM_TRY(ctx, fcm__sim_solver_setup(I));
cleanup:
  return st;
}

/* Set-up phase: the state at the current time — active constraints, the prescribed
 * velocities (dynamics) or the external load of the last step (a resumed static run). */
static void setup_initial_state(fcm_integrator *I)
{
  I->h_state = SIM_H_INVALID;
  I->kept = 0;
  I->damp_version = 0;
  for (int k = 0; k < I->num_cons; k++)
    I->con_on[k] = 0;
  I->is_setup = 1;
  fcm__sim_eval_constraints(I, I->t);
  if (I->opts.kind == FCM_INTEGRATOR_BACKWARD_EULER) {
    const double *X = fcm_mesh_coords(fcm_space_mesh(I->space));
    for (fcm_index i = 0; i < I->ncon; i++) {
      if (!I->con_on[I->con_id[i]]) continue;
      double uu[3], vv[3];
      fcm_motion_eval(&I->cons[I->con_id[i]].motion, X + 3 * I->con_node[i], I->t, uu, vv);
      I->v[I->con_dof[i]] = vv[I->con_comp[i]];
    }
  } else if (I->steps > 0) {
    fcm__sim_eval_loads(I, I->t, I->load_prev);
  }
}

/* The setup's first stage: the checks, the hanging DOFs, the constraints' DOFs and the
 * storage with the Newton matrix's pattern, all that the solver's structure needs
 * (fcm__sim_prepare_solver_cut()). */
static fcm_status setup_begin(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  FCM_CHECK(I, NULL, FCM_ERR_ARG, "integrator: NULL integrator");
  fcm_ctx *ctx = I->ctx;
  FCM_CHECK(!I->is_setup, ctx, FCM_ERR_ARG, "integrator: already set up");
  FCM_CHECK(!I->spent, ctx, FCM_ERR_ARG,
            "integrator: its storage went to the integrator of a cut (FCM_CUT_REUSE_STORAGE); "
            "it can only be destroyed");
  FCM_TRY(ctx, validate_options(ctx, &I->opts));
  if (I->opts.tolerance_mode == FCM_NEWTON_TOL_AUTO)
    I->opts.tolerance_mode = I->opts.kind == FCM_INTEGRATOR_STATIC ? FCM_NEWTON_TOL_RELATIVE
                                                                   : FCM_NEWTON_TOL_REPRESENTATIVE;
  FCM_CHECK(I->n > 0, ctx, FCM_ERR_ARG, "integrator: the space has no DOFs");
  /* a local space (a distributed run's own and ghost cells) gives partial sums only: the
   * backend sums them; without one the results would silently miss the other cells */
  FCM_CHECK(!I->space->is_local || fcm__integrator_distributed(I, NULL), ctx, FCM_ERR_ARG,
            "integrator: the space is a local space (a distributed run's cells only) but the "
            "integrator has no distributed backend; build the space with fcm_space_create() "
            "or fcm_space_create_embedded()");
  /* an octree mesh: the hanging DOFs follow their masters (hanging.c) */
  FCM_TRY(ctx, fcm__sim_hanging_setup(I));
  FCM_TRY(ctx, build_constraints(I));
  FCM_TRY(ctx, setup_storage(I));
cleanup:
  return st;
}

/* The setup's second stage, the values: the scheme, Nitsche's boundary, the mass matrix and
 * the loads, the representative force, the linear solver, the corotated element matrices
 * not built yet (in the store of the assembly workspace setup_begin() made), the state and
 * contact. It leaves the rest of what setup_begin() wrote and the hierarchy's fields (I->mg,
 * mg_A, mg_con, mg_creations) as they are; the solver's structure reads neither the
 * workspace nor its store. */
static fcm_status setup_values(fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = I->ctx;
  FCM_TRY(ctx, fcm__sim_scheme_setup(I));
  FCM_TRY(ctx, fcm__sim_boundary_setup(I));
  FCM_TRY(ctx, setup_mass_and_loads(I));
  if (I->opts.tolerance_mode == FCM_NEWTON_TOL_REPRESENTATIVE)
    FCM_TRY(ctx, setup_representative_force(I));
  FCM_TRY(ctx, setup_solvers(I));
  /* the corotated model's element stiffnesses (after a cut, those the cut made new): set-up
   * work, which the first step would do otherwise */
  if (I->params.model == FCM_MATERIAL_COROTATED_LINEAR) {
    FCM_TRY(ctx, fcm__assembly_corot_build(I->aws, &I->params));
    if (maps_room(I)) fcm__assembly_corot_map(I->aws);
  }
  setup_initial_state(I);
  FCM_TRY(ctx, fcm__sim_contact_setup(I));
cleanup:
  return st;
}

fcm_status fcm_integrator_setup(fcm_integrator *I)
{
  fcm_status st = setup_begin(I);
  if (st == FCM_OK) st = setup_values(I);
  return st;
}

fcm_status fcm__sim_copy_effects(const fcm_integrator *old, fcm_integrator *I)
{
  fcm_status st = FCM_OK;
  for (int k = 0; st == FCM_OK && k < old->num_loads; k++) {
    sim_load l = old->loads[k];
    l.f = l.blk = NULL;
    st = add_load(I, &l);
  }
  for (int k = 0; st == FCM_OK && k < old->num_bcons; k++)
    st = fcm_integrator_add_boundary_constraint(I, old->bcons[k].select, old->bcons[k].select_user,
                                                &old->bcons[k].motion, &old->bcons[k].opts, NULL);
  for (int k = 0; st == FCM_OK && k < old->num_contacts; k++)
    st = fcm__sim_contact_copy(I, &old->contacts[k]);
  return st;
}

fcm_status fcm__integrator_cut_begin(const fcm_integrator *old, const fcm_space *space,
                                     fcm__integrator_cut *cut)
{
  fcm_status st = FCM_OK;
  fcm_ctx *ctx = old ? old->ctx : NULL;
  fcm_integrator *I = NULL;
  const double t0 = fcm_wtime();
  memset(cut, 0, sizeof *cut);
  cut->old = old;
  FCM_CHECK(old && space, ctx, FCM_ERR_ARG, "integrator cut: NULL integrator or space");
  FCM_CHECK(old->is_setup, ctx, FCM_ERR_ARG,
            "integrator cut: the integrator must be set up (fcm_integrator_setup())");
  /* with a backend (fem/fem_backend.h) a local failure goes into its setup, which agrees */
  st = fcm_integrator_create(ctx, space, &old->mat, &old->opts, &cut->integ);
  I = cut->integ;
  if (st == FCM_OK) st = fcm__sim_copy_effects(old, I);
  for (int k = 0; st == FCM_OK && k < old->num_cons; k++)
    st = fcm_integrator_add_constraint(I, old->cons[k].num_nodes, old->cons[k].nodes,
                                       &old->cons[k].motion, NULL);
  {
    /* the old integrator's backend for the new space (the serial one stays serial) */
    fcm__backend b;
    memset(&b, 0, sizeof b);
    FCM_CHECK(old->backend.setup, ctx, FCM_ERR_UNSUPPORTED,
              "integrator cut: the integrator's distributed backend cannot be cut");
    FCM_TRY(ctx, old->backend.setup(old->backend.user, st, space, &b));
    FCM_TRY(ctx, fcm__integrator_set_backend(I, &b));
  }
  FCM_TRY(ctx, fcm__sim_cut_ordering(old, I));
  FCM_TRY(ctx, fcm__sim_cut_prepare_blocks(old, I));
  fcm__sim_cut_give_storage(old, I);
  cut->giver = I->cut_give;
  FCM_TRY(ctx, setup_begin(I));
cleanup:
  cut->seconds[0] += fcm_wtime() - t0;
  return st;
}

fcm_status fcm__integrator_cut_values(fcm__integrator_cut *cut)
{
  fcm_status st = FCM_OK;
  fcm_integrator *I = cut->integ;
  const fcm_integrator *old = cut->old;
  fcm_ctx *ctx = I->ctx;
  double *u = NULL, *v = NULL, *a = NULL;
  const double t0 = fcm_wtime();
  st = setup_values(I);
  I->cut_old = NULL; /* borrowed for the setup only */
  I->cut_give = NULL;
  FCM_FREE(ctx, I->cut_same);
  FCM_FREE(ctx, I->cut_rows);
  FCM_FREE(ctx, I->cut_dirty);
  FCM_FREE(ctx, I->cut_self);
  FCM_TRY(ctx, st);
  FCM_ALLOC_RAW(ctx, (size_t)I->n + 1, u);
  FCM_ALLOC_RAW(ctx, (size_t)I->n + 1, v);
  FCM_TRY(ctx, fcm_space_transfer(old->space, I->space, old->u, u));
  FCM_TRY(ctx, fcm_space_transfer(old->space, I->space, old->v, v));
  FCM_TRY(ctx, fcm_integrator_set_state(I, u, v, old->t, old->steps));
  if (old->a_valid) { /* the acceleration too (every new copy inherits its parent's) */
    FCM_ALLOC_RAW(ctx, (size_t)I->n + 1, a);
    FCM_TRY(ctx, fcm_space_transfer(old->space, I->space, old->a, a));
    FCM_TRY(ctx, fcm_integrator_set_acceleration(I, a));
  }
cleanup:
  fcm__free(ctx, u);
  fcm__free(ctx, v);
  fcm__free(ctx, a);
  cut->seconds[0] += fcm_wtime() - t0;
  return st;
}

fcm_status fcm__integrator_cut_structure(fcm__integrator_cut *cut)
{
  const double t0 = fcm_wtime();
  const fcm_status st = fcm__sim_prepare_solver_cut(cut->integ, cut->old, cut->beside, &cut->con);
  cut->seconds[1] += fcm_wtime() - t0;
  return st;
}

fcm_status fcm__integrator_cut_join(fcm__integrator_cut *cut)
{
  double task = 0.0;
  const fcm_status st = cut->integ ? fcm__sim_join_solver(cut->integ, &task) : FCM_OK;
  cut->seconds[1] += task;
  return st;
}

int fcm__integrator_cut_has_structure(const fcm__integrator_cut *cut)
{
  return cut->integ && fcm__sim_structure_wanted(cut->integ);
}

fcm_status fcm__integrator_cut_end(fcm__integrator_cut *cut, fcm_status st, fcm_integrator **integ)
{
  fcm_integrator *I = cut->integ;
  fcm_ctx *ctx = cut->old ? cut->old->ctx : NULL;
  const double t0 = fcm_wtime();
  *integ = NULL;
  if (I && st == FCM_OK) /* the structure's task that ran beside, if not joined yet (done: past
                            the barrier; after a failure the integrator's destruction drops it) */
    st = fcm__integrator_cut_join(cut);
  if (st == FCM_OK) {
    /* the structure's active set is I's when I's state holds it (always, by
     * fcm__sim_eval_constraints()); else the first factor builds the hierarchy again */
    if (I->mg)
      I->mg_con = cut->con && memcmp(cut->con, I->is_con, (size_t)I->n) == 0 ? I->con_version : -1;
    I->setup_info.solver_seconds += cut->seconds[1];
    I->load_work = cut->old->load_work;
    *integ = I;
    I = NULL;
    if (cut->giver) { /* its storage is the new integrator's, its hierarchy's products' too */
      cut->giver->spent = 1, cut->giver->is_setup = 0;
      fcm__mg_take_scratch((*integ)->mg, cut->giver->mg);
    }
  }
  if (I && cut->giver) fcm__sim_cut_give_back(I, cut->giver); /* failed: old goes on */
  fcm__free(ctx, cut->con);
  fcm_integrator_destroy(&I);
  cut->integ = NULL;
  cut->con = NULL;
  cut->seconds[0] += fcm_wtime() - t0;
  return st;
}

fcm_status fcm_integrator_create_cut(const fcm_integrator *old, const fcm_space *space,
                                     fcm_integrator **integ)
{
  fcm_status st = FCM_OK;
  fcm__integrator_cut cut;
  FCM_CHECK(integ, old ? old->ctx : NULL, FCM_ERR_ARG, "integrator cut: output pointer is NULL");
  *integ = NULL;
  st = fcm__integrator_cut_begin(old, space, &cut);
  if (st == FCM_OK) st = fcm__integrator_cut_values(&cut);
  /* the solver's structure, part of the cut: what the cut left of old's hierarchy taken */
  if (st == FCM_OK) st = fcm__integrator_cut_structure(&cut);
  st = fcm__integrator_cut_end(&cut, st, integ);
cleanup:
  return st;
}
