/* Prescribed motion: the free end of a clamped beam rotates about the beam axis (through
 * (4, 0.5, 0.5), 2 rad/s until t = 0.25, then held). After every backward Euler step the
 * constrained nodes sit on the rotated positions (independent formula, 1e-14) and exactly
 * on fcm_motion_eval(); their velocities are the step's chord velocities and, at setup,
 * the analytic omega x r. A static run of the same motion places them too. A translating
 * set released at t = 0.1 is held at its final position until then and falls under gravity
 * afterwards. Motion evaluation itself: translation, rotation, start/end clamping. */
#include "sim_util.h"

static const double PI = 3.14159265358979323846;

static const double C[3] = {4.0, 0.5, 0.5};

/* Rotation by theta about the x axis through C. */
static void rotated(const double X[3], double theta, double x[3])
{
  double y = X[1] - C[1], z = X[2] - C[2];
  x[0] = X[0];
  x[1] = C[1] + cos(theta) * y - sin(theta) * z;
  x[2] = C[2] + sin(theta) * y + cos(theta) * z;
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

  /* fcm_motion_eval on its own. */
  {
    fcm_motion m = fcm_motion_default();
    double X[3] = {1, 2, 3}, u[3], v[3];
    fcm_motion_eval(&m, X, 5.0, u, v);
    for (int i = 0; i < 3; i++)
      TEST_TRUE(u[i] == 0.0 && v[i] == 0.0);
    m.velocity[0] = 2.0, m.start = 1.0, m.end = 3.0;
    fcm_motion_eval(&m, X, 0.5, u, v);
    TEST_TRUE(u[0] == 0.0 && v[0] == 0.0);
    fcm_motion_eval(&m, X, 2.0, u, v);
    TEST_TRUE(u[0] == 2.0 && v[0] == 2.0 && u[1] == 0.0);
    fcm_motion_eval(&m, X, 7.0, u, v);
    TEST_TRUE(u[0] == 4.0 && v[0] == 0.0);
    fcm_motion r = fcm_motion_default();
    r.axis[0] = 0, r.axis[1] = 0, r.axis[2] = 2.0; /* any length */
    r.angular_speed = 0.5 * PI;
    fcm_motion_eval(&r, X, 1.0, u, v); /* quarter turn about z: (1, 2) -> (-2, 1) */
    TEST_NEAR(X[0] + u[0], -2.0, 0, 1e-15);
    TEST_NEAR(X[1] + u[1], 1.0, 0, 1e-15);
    TEST_TRUE(u[2] == 0.0);
    TEST_NEAR(v[0], -0.5 * PI * 1.0, 0, 1e-15); /* omega x x = w (-y, x, 0) at (-2, 1) */
    TEST_NEAR(v[1], -0.5 * PI * 2.0, 0, 1e-15);
  }

  TEST_OK(ctx, beam_mesh(ctx, type, 4, 4.0, &mesh));
  TEST_OK(ctx, fcm_space_create(ctx, mesh, NULL, &space));
  fcm_index n = fcm_space_num_dofs(space), nfix = 0, nend = 0;
  fcm_index *fix = plane_nodes(ctx, mesh, 0, 0.0, &nfix),
            *end = plane_nodes(ctx, mesh, 0, 4.0, &nend);
  const double *X = fcm_mesh_coords(mesh);
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1.0e6, 0.35, 1000.0};
  double *uprev = calloc((size_t)n, sizeof *uprev);
  fcm_motion fixed = fcm_motion_default(), twist = fcm_motion_default();
  memcpy(twist.center, C, sizeof C);
  twist.axis[0] = 1.0, twist.axis[1] = 0.0, twist.axis[2] = 0.0;
  twist.angular_speed = 2.0;
  twist.end = 0.25;

  for (int kind = 0; kind < 2; kind++) {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.kind = kind == 0 ? FCM_INTEGRATOR_BACKWARD_EULER : FCM_INTEGRATOR_STATIC;
    o.dt = kind == 0 ? 0.05 : 0.125;
    o.load_steps = 2;
    o.tolerance_mode = kind == 0 ? FCM_NEWTON_TOL_REPRESENTATIVE : FCM_NEWTON_TOL_RELATIVE;
    o.newton_tolerance = kind == 0 ? 1e-5 : 1e-9;
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nend, end, &twist, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    TEST_TRUE(fcm_integrator_num_constrained(integ) == 3 * (nfix + nend));
    if (kind == 0) /* setup gives the constrained DOFs their prescribed velocity */
      for (fcm_index k = 0; k < nend; k++) {
        const double *x = X + 3 * end[k];
        fcm_index d = fcm_space_node_dof(space, end[k]);
        TEST_NEAR(fcm_integrator_velocity(integ)[d + 1], -2.0 * (x[2] - C[2]), 0, 1e-15);
        TEST_NEAR(fcm_integrator_velocity(integ)[d + 2], 2.0 * (x[1] - C[1]), 0, 1e-15);
      }
    memset(uprev, 0, sizeof *uprev * (size_t)n);
    int steps = kind == 0 ? 8 : 3;
    for (int s = 1; s <= steps; s++) {
      fcm_step_info info;
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
      double t = fcm_integrator_time(integ), theta = 2.0 * fmin(t, 0.25);
      const double *u = fcm_integrator_displacement(integ), *v = fcm_integrator_velocity(integ);
      for (fcm_index k = 0; k < nend; k++) {
        const double *Xa = X + 3 * end[k];
        fcm_index d = fcm_space_node_dof(space, end[k]);
        double x[3], um[3];
        rotated(Xa, theta, x);
        fcm_motion_eval(&twist, Xa, t, um, NULL);
        for (int i = 0; i < 3; i++) {
          TEST_NEAR(Xa[i] + u[d + i], x[i], 0, 1e-14);
          TEST_TRUE(u[d + i] == um[i]);
          if (kind == 0) TEST_NEAR(v[d + i], (u[d + i] - uprev[d + i]) / o.dt, 1e-12, 1e-12);
        }
      }
      for (fcm_index k = 0; k < nfix; k++)
        for (int i = 0; i < 3; i++)
          TEST_TRUE(u[fcm_space_node_dof(space, fix[k]) + i] == 0.0);
      memcpy(uprev, u, sizeof *uprev * (size_t)n);
    }
    /* The middle of the beam twisted along (rotation transmitted, not just the end). */
    double mid = 0.0;
    for (fcm_index a = 0; a < fcm_mesh_num_nodes(mesh); a++)
      if (fabs(X[3 * a] - 2.0) < 1e-12 && X[3 * a + 1] > 0.5 && X[3 * a + 2] > 0.5)
        mid = uprev[fcm_space_node_dof(space, a) + 1];
    TEST_TRUE(mid < -0.05);
    fcm_integrator_destroy(&integ);
  }

  /* A translating, released set: held (u_z = -0.2 * 0.1) until t = 0.1, then it falls. */
  {
    fcm_integrator_options o = fcm_integrator_options_default();
    o.dt = 0.05;
    fcm_motion lift = fcm_motion_default();
    lift.velocity[2] = -0.2;
    lift.end = 0.1;
    lift.release = 1;
    const double g[3] = {0, 0, -9.81};
    TEST_OK(ctx, fcm_integrator_create(ctx, space, &mat, &o, &integ));
    TEST_OK(ctx, fcm_integrator_add_gravity(integ, g, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nfix, fix, &fixed, NULL));
    TEST_OK(ctx, fcm_integrator_add_constraint(integ, nend, end, &lift, NULL));
    TEST_OK(ctx, fcm_integrator_setup(integ));
    fcm_step_info info;
    for (int s = 1; s <= 2; s++)
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
    fcm_index d = fcm_space_node_dof(space, end[0]);
    TEST_NEAR(fcm_integrator_displacement(integ)[d + 2], -0.02, 1e-15, 0);
    long long f0 = info.total_factorizations;
    for (int s = 3; s <= 6; s++)
      TEST_OK(ctx, fcm_integrator_step(integ, &info));
    TEST_TRUE(fcm_integrator_displacement(integ)[d + 2] < -0.02 - 1e-3);
    TEST_TRUE(info.total_factorizations > f0);
    TEST_TRUE(info.total_analyses == 1);
    fcm_integrator_destroy(&integ);
  }

  free(fix), free(end), free(uprev);
  fcm_space_destroy(&space);
  fcm_mesh_destroy(&mesh);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
