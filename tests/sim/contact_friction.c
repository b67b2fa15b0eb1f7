/* Lagged, smoothed Coulomb friction on contact obstacles, by mode:
 *   fd         a ball resting near a moving plane and near a translating and rotating box
 *              (friction 0.4, eps_v = 1 m/s so the smoothing band is wide against the
 *              differences): with the lagged normal forces and tangents fixed (taken at a random
 *              start state), central differences of the energy match the force and those of the
 *              force the Newton matrix (relative error <= 1e-6), at slips both inside and beyond
 *              the smoothing band; the friction's energy is positive and the matrix exactly
 *              symmetric
 *   incline <mu>  a block (0.6 x 0.6 x 0.2 m, E = 1e6 Pa) resting on a floor under gravity
 *              tilted by theta = 20 degrees (tan theta = 0.364), backward Euler dt 0.01 s:
 *              with mu = 0.6 > tan theta it stays: its centre of mass moves along the slope by at
 *              most eps_v per second once settled (the smoothed static friction's creep bound);
 *              with mu = 0.2 it slides with the acceleration g (sin theta - mu cos theta)
 *              within 3 %; no point ever below the floor
 *   incline <mu> <updates>  the same with the normal forces and tangents taken anew at each
 *              converged state up to <updates> times per substep (fixed-point iterations):
 *              the same bounds hold, and updates are counted */
#include "sim_util.h"
#include "fcm/fcm.h"
#include "sim/sim_impl.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double rnd(void)
{
  return (double)rand() / RAND_MAX - 0.5;
}

/* The friction-only check on obstacle setup `kind` (0 moving plane, 1 moving box). */
static int fd_one(fcm_ctx *ctx, int kind)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  fcm_csr *T = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, r = 0.3;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 0.01;
  co.distance = 0.05;
  co.friction = 0.4;
  co.friction_velocity = 1.0;
  TEST_OK(ctx, ball_problem(&p, c, r, 4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  if (kind == 0) {
    const double pt[3] = {0.5, 0.5, c[2] - r - 0.02}, n[3] = {0.1, 0.05, 1.0},
                 v[3] = {0.3, -0.2, 0.01};
    TEST_OK(ctx, fcm_integrator_add_contact_plane(I, pt, n, v, &co, NULL));
  } else {
    const double lo[3] = {-1, -1, -1}, hi[3] = {2, 2, c[2] - r - 0.02};
    fcm_motion m = fcm_motion_default();
    m.velocity[0] = 0.4;
    m.velocity[1] = -0.1;
    m.center[0] = m.center[1] = 0.5;
    m.angular_speed = 0.5; /* about z: the top face stays level */
    TEST_OK(ctx, fcm_integrator_add_contact_box(I, lo, hi, &m, &co, NULL));
  }
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *u = calloc((size_t)n, sizeof *u), *d = calloc((size_t)n, sizeof *d);
  double *f0 = calloc((size_t)n, sizeof *f0), *fb = calloc((size_t)n, sizeof *fb);
  srand(5 + kind);
  /* the start state u_n (lagged forces and tangents there) and the substep [t - h, t] */
  const double t = 0.2, h = 0.01;
  for (fcm_index i = 0; i < n; i++)
    I->un[i] = 0.002 * rnd();
  I->bc_time = t;
  TEST_OK(ctx, fcm__sim_contact_lag(I, h));
  /* slips of about 0.5 eps = 0.005 m on average: some inside, some beyond the band */
  for (fcm_index i = 0; i < n; i++) {
    u[i] = I->un[i] + 0.01 * rnd();
    d[i] = rnd();
  }
  TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
  double e0 = 0.0, eb = 0.0, asym = 1.0;
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &e0, f0, T));
  /* the same without friction: the friction's own energy is positive */
  {
    double *lag = I->cp.lag;
    I->cp.lag = NULL;
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &eb, fb, NULL));
    I->cp.lag = lag;
  }
  if (!(e0 - eb > 0.0)) TEST_FAIL_("fd %d: friction energy %.3g", kind, e0 - eb);
  TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
  if (!(asym == 0.0)) TEST_FAIL_("fd %d: asymmetry %.3g", kind, asym);
  double err_e = 1.0, err_t = 1.0, fric = 0.0;
  contact_fd(ctx, I, n, u, d, t, 1e-7, f0, T, &err_e, &err_t);
  for (fcm_index i = 0; i < n; i++)
    fric += (f0[i] - fb[i]) * (f0[i] - fb[i]);
  printf("fd %d: friction energy %.4g J, |friction force| %.4g N, force error %.3g, tangent "
         "error %.3g\n",
         kind, e0 - eb, sqrt(fric), err_e, err_t);
  if (!(err_e <= 1e-6)) TEST_FAIL_("fd %d: force relative error %.3g", kind, err_e);
  if (!(err_t <= 1e-6)) TEST_FAIL_("fd %d: tangent relative error %.3g", kind, err_t);
  free(u), free(d), free(f0), free(fb);
  fcm_csr_destroy(&T);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* The centre of mass's velocity and displacement along x (mass-weighted). */
static void com_x(const fcm_integrator *I, fcm_index n, double *v, double *u)
{
  const fcm_csr *M = fcm_integrator_mass(I);
  double *ex = calloc((size_t)n, sizeof *ex), *w = calloc((size_t)n, sizeof *w), m = 0.0;
  for (fcm_index i = 0; i < n; i++)
    ex[i] = i % 3 == 0 ? 1.0 : 0.0;
  fcm_csr_apply(M, 1.0, ex, 0.0, w);
  *v = *u = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    m += ex[i] * w[i];
    *v += fcm_integrator_velocity(I)[i] * w[i];
    *u += fcm_integrator_displacement(I)[i] * w[i];
  }
  *v /= m;
  *u /= m;
  free(ex), free(w);
}

static int incline(fcm_ctx *ctx, double mu, int updates)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  const double blo[3] = {0.2, 0.2, 0.1}, bhi[3] = {0.8, 0.8, 0.3}, lo[3] = {0, 0, 0},
               hi[3] = {1, 1, 0.5};
  const fcm_index gcells[3] = {2, 2, 1}, cells[3] = {5, 5, 3};
  const double theta = atan(1.0) * 80.0 / 180.0, g0 = 9.81; /* 20 degrees */
  const double g[3] = {g0 * sin(theta), 0.0, -g0 * cos(theta)}, up[3] = {0, 0, 1};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 0.01;
  co.friction = mu;
  co.distance = 0.01;
  co.friction_updates = updates;
  ro.surface_strength = 2;
  ro.min_fraction = 1e-4;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, bhi, gcells, &p.geom));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p.mesh));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, p.mesh, p.geom, &ro, &p.rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p.mesh, p.rules, &p.space));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  /* the floor 0.3 d^ below the block: the barrier carries it from the first steps */
  const double fp[3] = {0.5, 0.5, blo[2] - 0.003};
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, fp, up, NULL, &co, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_space_num_dofs(p.space);
  const int settle = 20, steps = 80;
  double v1 = 0.0, u1 = 0.0, v2 = 0.0, u2 = 0.0, dmin_all = HUGE_VAL;
  for (int s = 0; s < steps; s++) {
    fcm_step_info info;
    double dmin = 0.0;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, NULL, &dmin, NULL, NULL));
    dmin_all = fmin(dmin_all, dmin);
    if (s + 1 == settle) com_x(I, n, &v1, &u1);
  }
  com_x(I, n, &v2, &u2);
  {
    fcm_contact_stats cs;
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    printf("incline: %lld friction updates over %d steps\n", cs.friction_updates, steps);
    /* updates happen where the normal forces moved over the substep: at least at the start */
    if (updates > 0 ? cs.friction_updates == 0 : cs.friction_updates != 0)
      TEST_FAIL_("%lld friction updates with friction_updates = %d", cs.friction_updates, updates);
  }
  const double T = (steps - settle) * o.dt;
  printf("incline mu = %g: min distance %.3g m; after settling: slope displacement %.4g m, "
         "velocity %.4g -> %.4g m/s over %g s\n",
         mu, dmin_all, u2 - u1, v1, v2, T);
  if (!(dmin_all > 0.0)) TEST_FAIL_("a point reached distance %.3g", dmin_all);
  if (mu > tan(theta)) {
    const double bound = co.friction_velocity > 0.0 ? co.friction_velocity * T : 1e-3 * T;
    if (!(fabs(u2 - u1) <= bound))
      TEST_FAIL_("stick: moved %.3g m along the slope, more than eps_v T = %.3g m", u2 - u1, bound);
  } else {
    const double a = (v2 - v1) / T, a_ref = g0 * (sin(theta) - mu * cos(theta));
    printf("incline: acceleration %.5g m/s^2 against g (sin - mu cos) = %.5g\n", a, a_ref);
    TEST_NEAR(a, a_ref, 0.03, 0.0);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const char *mode = argc > 1 ? argv[1] : "fd";
  if (!strcmp(mode, "fd")) {
    fd_one(ctx, 0);
    fd_one(ctx, 1);
  } else if (!strcmp(mode, "incline") && argc > 2) {
    incline(ctx, atof(argv[2]), argc > 3 ? atoi(argv[3]) : 0);
  } else {
    return 2;
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
