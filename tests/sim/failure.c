/* Failure paths of the integrator. Non-convergence (one Newton update allowed, a tight
 * tolerance, 2 halvings) gives FCM_ERR_NOT_CONVERGED with reason MAX_NEWTON after 3
 * attempts, and the state (u, v, t, steps) is bitwise the last accepted one; the next
 * step with a looser setting then succeeds. A load whose time scale turns NaN gives
 * FCM_ERR_NUMERIC with reason NONFINITE, state unchanged. A too-short line search reports
 * LINE_SEARCH_FAILED. Argument errors name the bad value. */
#include "sim_util.h"

static double nan_after(void *user, double t)
{
  return t > *(const double *)user ? NAN : 1.0;
}

typedef struct snapshot {
  double *u, *v, t;
  long long steps;
} snapshot;

static void take(const fcm_integrator *integ, snapshot *s)
{
  fcm_integrator_get_state(integ, s->u, s->v, &s->t, &s->steps);
}

static int same(const fcm_integrator *integ, const snapshot *s)
{
  fcm_index n = fcm_integrator_num_dofs(integ);
  if (fcm_integrator_time(integ) != s->t || fcm_integrator_step_count(integ) != s->steps) return 0;
  return !memcmp(fcm_integrator_displacement(integ), s->u, sizeof(double) * (size_t)n) &&
         !memcmp(fcm_integrator_velocity(integ), s->v, sizeof(double) * (size_t)n);
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
  fcm_index n = fcm_space_num_dofs(space), nfix = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix);
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 2.0e6, 0.4, 1000.0};
  const double grav[3] = {0, 0, -9.81};
  fcm_motion fixed = fcm_motion_default();
  snapshot snap = {calloc((size_t)n, sizeof(double)), calloc((size_t)n, sizeof(double)), 0, 0};
  fcm_step_info info;

  /* 1. Non-convergence: a static step with one Newton update and a 1e-13 tolerance. */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = FCM_INTEGRATOR_STATIC;
    o.dt = 1.0;
    o.newton_max_iterations = 1;
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    o.newton_tolerance = 1e-13;
    o.max_halvings = 2;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    take(integ, &snap);
    TEST_ERR(ctx, fcm_integrator_step(integ, &info), FCM_ERR_NOT_CONVERGED, "max-newton");
    TEST_TRUE(info.reason == FCM_STEP_MAX_NEWTON);
    TEST_TRUE(info.halvings == 2);
    TEST_TRUE(info.failed_attempts == 3);
    TEST_TRUE(info.substeps == 0);
    TEST_TRUE(info.residual > info.tolerance);
    TEST_TRUE(same(integ, &snap));
    fcm_integrator_destroy(&integ);
  }

  /* 2. Dynamic: two good steps, then a NaN gravity scale; then halvings that succeed. */
  {
    double t_nan = 0.025;
    fcm_integrator_options o = fcm_integrator_options_default();
    o.dt = 0.01;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, nan_after, &t_nan));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
    take(integ, &snap);
    TEST_ERR(ctx, fcm_integrator_step(integ, &info), FCM_ERR_NUMERIC, "not finite");
    TEST_TRUE(info.reason == FCM_STEP_NONFINITE);
    TEST_TRUE(same(integ, &snap));
    for (fcm_index i = 0; i < n; i++)
      TEST_TRUE(isfinite(fcm_integrator_displacement(integ)[i]));
    fcm_integrator_destroy(&integ);
  }

  /* 3. Halving rescues a step: a load jump the first attempt cannot take in 2 updates. */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = FCM_INTEGRATOR_STATIC;
    o.dt = 1.0;
    o.newton_max_iterations = 4;
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    o.newton_tolerance = 1e-8;
    o.max_halvings = 6;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
    TEST_TRUE(info.halvings >= 1 && info.failed_attempts >= 1);
    TEST_TRUE(info.substeps >= 2);
    TEST_NEAR(fcm_integrator_time(integ), 1.0, 0, 0);
    TEST_TRUE(fcm_integrator_step_count(integ) == 1);
    fcm_integrator_destroy(&integ);
  }

  /* 4. A line search without backtracking fails on the first overshooting update. */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = FCM_INTEGRATOR_STATIC;
    o.tolerance_mode = FCM_NEWTON_TOL_REPRESENTATIVE;
    o.dt = 1.0;
    o.max_backtracks = 0;
    o.max_halvings = 0;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    take(integ, &snap);
    TEST_ERR(ctx, fcm_integrator_step(integ, &info), FCM_ERR_NOT_CONVERGED, "line-search-failed");
    TEST_TRUE(info.reason == FCM_STEP_LINE_SEARCH_FAILED);
    TEST_TRUE(same(integ, &snap));
    fcm_integrator_destroy(&integ);
  }

  /* 5. Argument errors. */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    TEST_ERR(ctx, fcm_integrator_create(ctx, NULL, &mat, &o, &integ), FCM_ERR_ARG, "NULL space");
    TEST_TRUE(integ == NULL);
    fcm_material bad = mat;
    bad.poisson = 0.5;
    TEST_ERR(ctx, fcm_integrator_create(ctx, space, &bad, &o, &integ), FCM_ERR_ARG, "0.5");
    o.dt = -1.0;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_ERR(ctx, fcm_integrator_step(integ, &info), FCM_ERR_ARG, "setup");
    TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "dt = -1");
    fcm_integrator_destroy(&integ);
    o = fcm_integrator_options_default();
    o.newton_tolerance = 2.0;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "newton_tolerance = 2");
    fcm_integrator_destroy(&integ);

    o = fcm_integrator_options_default();
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    fcm_index bad_node = 100000;
    TEST_ERR(ctx, fcm_integrator_add_constraint(integ, 1, &bad_node, &fixed, NULL), FCM_ERR_ARG,
             "out of range");
    fcm_motion m = fixed;
    m.end = -1.0;
    TEST_ERR(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &m, NULL), FCM_ERR_ARG,
             "end = -1");
    m = fixed;
    m.angular_speed = 1.0;
    m.axis[2] = 0.0;
    TEST_ERR(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &m, NULL), FCM_ERR_ARG,
             "zero axis");
    double nan3[3] = {0, NAN, 0};
    TEST_ERR(ctx, fcm_integrator_add_gravity(integ, nan3, NULL, NULL), FCM_ERR_ARG, "not finite");
    TEST_ERR(ctx, fcm_integrator_set_rigid_velocity(integ, nan3, NULL, NULL), FCM_ERR_ARG,
             "not finite");
    /* The same DOF in two constraints. */
    int id = -1;
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, &id));
    TEST_TRUE(id == 0);
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, 1, fix, &fixed, &id));
    TEST_TRUE(id == 1);
    TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "already constrained by constraint 0");
    fcm_integrator_destroy(&integ);

    /* Zero density: no representative force; fine with the relative rule. */
    fcm_material light = mat;
    light.density = 0.0;
    o.kind = FCM_INTEGRATOR_STATIC;
    o.tolerance_mode = FCM_NEWTON_TOL_REPRESENTATIVE;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &light, &o, &integ));
    TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "representative force");
    fcm_integrator_destroy(&integ);
    o.tolerance_mode = FCM_NEWTON_TOL_RELATIVE;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &light, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    TEST_ERR(ctx, fcm_integrator_setup(integ), FCM_ERR_ARG, "already set up");
    TEST_ERR(ctx, fcm_integrator_add_gravity(integ, grav, NULL, NULL), FCM_ERR_ARG,
             "before fcm_integrator_setup");
    TEST_ERR(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL), FCM_ERR_ARG,
             "before fcm_integrator_setup");
    snap.u[0] = NAN;
    TEST_ERR(ctx, fcm_integrator_set_state(integ, snap.u, NULL, 0.0, 0), FCM_ERR_ARG, "u[0]");
    fcm_integrator_destroy(&integ);
    TEST_TRUE(!strcmp(fcm_step_reason_name(FCM_STEP_LINEAR_SOLVER_FAILED), "linear-solver-failed"));
    TEST_TRUE(!strcmp(fcm_step_reason_name((fcm_step_reason)99), "unknown"));
  }

  free(fix), free(snap.u), free(snap.v);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
