/* Allocation failures: failing the k-th allocation (k = 0, 1, ...) anywhere in create,
 * configure, setup and two steps (direct with Rayleigh damping, and MINRES with a Jacobi
 * preconditioner created on first use; MINRES with the multigrid preconditioner and the multigrid
 * solver with PSD tangents, the hierarchy built on first use) gives FCM_ERR_ALLOC, leaks nothing,
 * and a failing step leaves the state where it was; eventually the whole sequence succeeds. */
#include "sim_util.h"
#include "test_alloc.h"

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

int main(void)
{
  failing f = {0, -1};
  fcm_ctx_options co = fcm_ctx_options_default();
  co.allocator.alloc = failing_alloc;
  co.allocator.release = failing_release;
  co.allocator.user = &f;
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  TEST_OK(ctx, fcm_ctx_create(&co, &ctx));
  TEST_OK(ctx, beam_mesh(ctx, FCM_ELEMENT_HEX8, 2, 2.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  long long base = fcm_ctx_live_allocations(ctx);
  for (int krylov = 0; krylov < 4; krylov++) {
    int done = 0;
    for (long long k = 0; k < 20000 && !done; k++) {
      f.count = 0;
      f.fail_at = k;
      int state_ok = 1;
      fcm_status st = run(ctx, space, nfix, fix, krylov, &state_ok);
      TEST_TRUE(st == FCM_OK || st == FCM_ERR_ALLOC);
      TEST_TRUE(state_ok);
      TEST_TRUE(fcm_ctx_live_allocations(ctx) == base);
      if (st == FCM_OK) done = 1;
      if (st != FCM_OK && st != FCM_ERR_ALLOC) break;
    }
    TEST_TRUE(done);
  }
  f.fail_at = -1;
  free(fix);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
