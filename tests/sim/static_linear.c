/* Static Newton with the linear material reproduces the linear solve K u = f (stiffness
 * assembly, symmetric elimination, CHOLMOD) to 1e-10: a cantilever under gravity, then with
 * its free end pushed down by a prescribed translation (non-zero Dirichlet values, first
 * through fcm_space_apply_dirichlet, then through the reused factor). Newton takes one
 * update per solve, the factor is computed once over load steps and steps, and a
 * body-force field equal to rho g gives the same answer as gravity. */
#include "sim_util.h"

static const double grav[3] = {0.0, 0.0, -9.81};
static const double rho = 1000.0;

static void rho_g(void *user, const double x[3], const double n[3], double b[3])
{
  (void)user, (void)x, (void)n;
  for (int i = 0; i < 3; i++)
    b[i] = rho * grav[i];
}

/* Reference: K u = f_g with u = 0 on x = 0 and u_z = -w on x = L. */
static void reference(fcm_ctx *ctx, fcm_space *space, const fcm_material *m, fcm_index nfix,
                      const fcm_index *fix, fcm_index nend, const fcm_index *end, double w,
                      double *u)
{
  fcm_index n = fcm_space_num_dofs(space), nc = 0;
  fcm_csr *K = NULL;
  fcm_direct *chol = NULL;
  fcm_material el = {FCM_MATERIAL_LINEAR, m->young, m->poisson, m->density};
  double *f = calloc((size_t)n, sizeof *f), *vals = calloc((size_t)n, sizeof *vals);
  fcm_index *dofs = calloc((size_t)n, sizeof *dofs);
  TEST_OK(ctx, fcm_space_matrix_create(space, &K));
  TEST_OK(ctx, fcm_assemble_stiffness(space, &el, NULL, K));
  TEST_OK(ctx, fcm_assemble_body_force(space, &el, grav, NULL, f));
  for (fcm_index k = 0; k < nfix; k++)
    for (int i = 0; i < 3; i++)
      dofs[nc] = fcm_space_node_dof(space, fix[k]) + i, vals[nc++] = 0.0;
  if (w != 0.0)
    for (fcm_index k = 0; k < nend; k++)
      dofs[nc] = fcm_space_node_dof(space, end[k]) + 2, vals[nc++] = -w;
  TEST_OK(ctx, fcm_space_apply_dirichlet(space, nc, dofs, vals, K, f));
  TEST_OK(ctx, fcm_direct_create(ctx, FCM_DIRECT_CHOLMOD, K, &chol));
  TEST_OK(ctx, fcm_direct_analyze(chol));
  TEST_OK(ctx, fcm_direct_factor(chol, fcm_csr_values(K)));
  TEST_OK(ctx, fcm_direct_solve(chol, f, u));
  fcm_direct_destroy(&chol);
  fcm_csr_destroy(&K);
  free(f), free(vals), free(dofs);
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  fcm_element_type type;
  if (argc != 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, beam_mesh(ctx, type, 4, 4.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index n = fcm_space_num_dofs(space), nfix = 0, nend = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix),
            *end = plane_nodes(ctx, mesh, 0, 4.0, &nend);
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1.0e6, 0.3, rho};
  double *uref = calloc((size_t)n, sizeof *uref), *u = calloc((size_t)n, sizeof *u);

  /* 1. Gravity, 3 load steps: one Newton update each, one factorization in all. */
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.dt = 1.0;
  o.load_steps = 3;
  o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  o.newton_tolerance = 1e-12;
  fcm_motion fixed = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  TEST_TRUE(fcm_integrator_num_constrained(integ) == 3 * nfix);
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  reference(ctx, space, &mat, nfix, fix, nend, end, 0.0, uref);
  double scale = vec_norm(n, uref);
  TEST_TRUE(scale > 0.0);
  TEST_TRUE(vec_dist(n, fcm_integrator_displacement(integ), uref) <= 1e-10 * scale);
  TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  TEST_TRUE(info.substeps == 3);
  TEST_TRUE(info.newton_iterations == 3);
  TEST_TRUE(info.total_factorizations == 1);
  TEST_TRUE(info.total_analyses == 1);
  TEST_TRUE(info.line_search_backtracks == 0);
  TEST_NEAR(fcm_integrator_time(integ), 1.0, 0, 0);
  /* Same load again: already in equilibrium, no update. */
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  TEST_TRUE(info.newton_iterations == 0);
  TEST_TRUE(info.total_factorizations == 1);
  fcm_integrator_destroy(&integ);

  /* 2. A body-force field equal to rho g gives the same displacement. */
  o.load_steps = 1;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_body_force(integ, rho_g, NULL, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  TEST_TRUE(vec_dist(n, fcm_integrator_displacement(integ), uref) <= 1e-10 * scale);
  fcm_integrator_destroy(&integ);

  /* 3. The free end translated down at 0.05 per unit (pseudo-)time: u_z = -0.05 t there. */
  fcm_motion push = fcm_motion_default();
  push.velocity[2] = -0.05;
  push.components[0] = push.components[1] = 0;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nend, end, &push, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  for (int s = 1; s <= 3; s++) {
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    reference(ctx, space, &mat, nfix, fix, nend, end, 0.05 * s, uref);
    fcm_integrator_get_state(integ, u, NULL, NULL, NULL);
    TEST_TRUE(vec_dist(n, u, uref) <= 1e-10 * vec_norm(n, uref));
    for (fcm_index k = 0; k < nend; k++)
      TEST_TRUE(u[fcm_space_node_dof(space, end[k]) + 2] == -0.05 * s);
    TEST_TRUE(info.newton_iterations == 1);
    TEST_TRUE(info.total_factorizations == 1);
  }
  fcm_integrator_destroy(&integ);

  free(fix), free(end), free(uref), free(u);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
