/* Allocation failures: failing the k-th allocation (k = 0, 1, ...) anywhere in create,
 * configure, setup and two steps (direct with Rayleigh damping, and MINRES with a Jacobi
 * preconditioner created on first use; MINRES with the multigrid preconditioner and the multigrid
 * solver with PSD tangents, the hierarchy built on first use) gives FCM_ERR_ALLOC, leaks nothing,
 * and a failing step leaves the state where it was; eventually the whole sequence succeeds. */
#include "sim_util.h"
#include "alloc_loop.h"

#include <stdio.h>

static fcm_status run(fcm_ctx *ctx, fcm_space *space, fcm_index nfix, const fcm_index *fix,
                      int krylov, int *state_ok)
{
  fcm_status st;
  fcm_integrator *integ = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  const double g[3] = {0, 0, -9.81};
  fcm_motion fixed = fcm_motion_default();
  o.dt = 0.01;
  o.rayleigh_mass = 0.1;
  o.rayleigh_stiffness = 1e-3;
  if (krylov == 1) o.linear_solver = FCM_LINEAR_MINRES, o.preconditioner = FCM_PRECOND_JACOBI;
  if (krylov == 2) o.linear_solver = FCM_LINEAR_MINRES, o.preconditioner = FCM_PRECOND_MULTIGRID;
  if (krylov == 3) o.linear_solver = FCM_LINEAR_MULTIGRID, o.project_psd = 1;
  o.multigrid.coarse_dofs = 12; /* two levels on the 2-cell beam */
  *state_ok = 1;
  if ((st = fcm_integrator_create(ctx, space, &mat, &o, &integ))) goto done;
  if ((st = fcm_integrator_add_gravity(integ, g, NULL, NULL))) goto done;
  if ((st = fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL))) goto done;
  if ((st = fcm_integrator_setup(integ))) goto done;
  for (int s = 0; s < 2; s++) {
    double t = fcm_integrator_time(integ);
    long long k = fcm_integrator_step_count(integ);
    if ((st = fcm_integrator_step(integ, NULL))) {
      *state_ok = fcm_integrator_time(integ) == t && fcm_integrator_step_count(integ) == k;
      goto done;
    }
  }
done:
  fcm_integrator_destroy(&integ);
  return st;
}

typedef struct sim_case {
  fcm_ctx *ctx;
  fcm_space *space;
  fcm_index nfix;
  const fcm_index *fix;
  int krylov;
} sim_case;

/* One round of the whole sequence; a failing step must leave the state where it was. */
static fcm_status sim_round(void *user)
{
  sim_case *c = user;
  int state_ok = 1;
  fcm_status st = run(c->ctx, c->space, c->nfix, c->fix, c->krylov, &state_ok);
  TEST_TRUE(state_ok);
  return st;
}

int main(void)
{
  failing f;
  fcm_ctx *ctx = failing_ctx(&f);
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_TRUE(ctx != NULL);
  TEST_OK(ctx, beam_mesh(ctx, FCM_ELEMENT_HEX8, 2, 2.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  sim_case c = {ctx, space, nfix, fix, 0};
  for (c.krylov = 0; c.krylov < 4; c.krylov++) {
    char name[32];
    snprintf(name, sizeof name, "solver %d", c.krylov);
    alloc_loop(ctx, &f, name, sim_round, NULL, &c, 1, 20000);
  }
  free(fix);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
