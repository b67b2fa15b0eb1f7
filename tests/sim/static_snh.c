/* Static Newton for a Stable Neo-Hookean cantilever under gravity (large deflection): it
 * converges, full steps are taken at the end, and the last residuals drop quadratically,
 * r_{k+1} / r_k <= 100 r_k / r_0 once r_k <= 1e-3 r_0 (above round-off). The result
 * is an equilibrium: repeating the step changes nothing, and splitting the load into 4
 * steps reaches the same configuration. Optional argument "-v" prints the history. */
#include "sim_util.h"

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  fcm_mesh *mesh = NULL;
  fcm_space *space = NULL;
  fcm_integrator *integ = NULL;
  fcm_element_type type;
  if (argc < 2 || fcm_element_type_from_name(argv[1], &type) != FCM_OK) return 2;
  int verbose = argc > 2 && !strcmp(argv[2], "-v");
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  TEST_OK(ctx, beam_mesh(ctx, type, 4, 4.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index n = fcm_space_num_dofs(space), nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2.0e6, 0.4, 1000.0};
  const double grav[3] = {0.0, 0.0, -9.81};
  double *u1 = calloc((size_t)n, sizeof *u1);
  newton_log log;
  memset(&log, 0, sizeof log);

  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.dt = 1.0;
  o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
  o.newton_tolerance = 1e-11;
  o.monitor = newton_log_fn;
  o.monitor_user = &log;
  fcm_motion fixed = fcm_motion_default();
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  fcm_step_info info;
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  fcm_integrator_get_state(integ, u1, NULL, NULL, NULL);
  if (verbose) {
    for (int k = 0; k < log.count; k++)
      printf("it %2d  residual %.3e  alpha %.4g  tol %.3e\n", log.iteration[k], log.residual[k],
             log.alpha[k], log.tolerance[k]);
    printf("newton %d, backtracks %d, tangents %d, factorizations %d, assembly %.3f s, factor "
           "%.3f s, solve %.3f s, total %.3f s\n",
           info.newton_iterations, info.line_search_backtracks, info.tangent_assemblies,
           info.factorizations, info.time_assembly, info.time_factor, info.time_solve,
           info.time_total);
  }
  /* Large deflection: the tip goes down by more than 10% of the length. */
  double tipz = 0.0;
  {
    fcm_index nend = 0;
    fcm_index *end = plane_nodes(ctx, mesh, 0, 4.0, &nend);
    for (fcm_index k = 0; k < nend; k++)
      tipz += u1[fcm_space_node_dof(space, end[k]) + 2] / (double)nend;
    free(end);
  }
  if (verbose) printf("mean tip deflection %.6f\n", tipz);
  TEST_TRUE(tipz < -0.4);
  TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  TEST_TRUE(info.newton_iterations >= 3 && info.newton_iterations <= 25);
  TEST_TRUE(log.count == info.newton_iterations + 1);
  TEST_TRUE(info.residual <= info.tolerance);
  /* Quadratic convergence at the end: once r_k <= 1e-3 r_0 and while r_{k+1} is above
   * round-off (1e-12 of the force scale R = tolerance / 1e-11), full steps are taken and
   * r_{k+1} / r_k <= 100 r_k / r_0 (linear convergence, e.g. a constant factor 0.1, fails
   * this); the last update gains at least three digits. */
  double r0 = log.residual[0], R = info.tolerance / o.newton_tolerance;
  int checked = 0;
  for (int k = 1; k + 1 < log.count; k++) {
    double rk = log.residual[k], rk1 = log.residual[k + 1];
    if (rk > 1e-3 * r0 || rk1 < 1e-12 * R) continue;
    TEST_TRUE(log.alpha[k + 1] == 1.0);
    TEST_TRUE(rk1 / rk <= 100.0 * rk / r0);
    checked++;
  }
  TEST_TRUE(log.residual[log.count - 1] <= 1e-3 * log.residual[log.count - 2]);
  TEST_TRUE(checked >= 1);

  /* Repeating the step: already converged at the initial guess. */
  log.count = 0;
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  TEST_TRUE(info.newton_iterations == 0);
  TEST_TRUE(info.total_analyses == 1);
  fcm_integrator_destroy(&integ);

  /* Four load steps reach the same equilibrium (it is unique near the reference here). */
  o.load_steps = 4;
  o.monitor = NULL;
  TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
  TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
  TEST_OK(ctx, fcm_integrator_setup(integ));
  TEST_OK(ctx, fcm_integrator_step(integ, &info));
  TEST_TRUE(info.substeps == 4);
  TEST_TRUE(vec_dist(n, fcm_integrator_displacement(integ), u1) <= 1e-8 * vec_norm(n, u1));
  fcm_integrator_destroy(&integ);

  free(fix), free(u1);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
