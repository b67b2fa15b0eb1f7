/* Contact with rigid half-spaces (log barrier on the embedded surface's points), by mode:
 *   gradient   on an embedded ball near a tilted moving plane, with a random displacement:
 *              central differences of the barrier energy match its force, and of the force
 *              its Newton matrix (relative error <= 1e-6); the matrix is exactly symmetric
 *   push       a floor moving up at constant velocity V hits a ball at rest (no gravity):
 *              never crossed, the ball leaves it at a speed in [V, 2 V]
 *   errors     a ball starting across the plane is refused naming the point and its
 *              distance; bad normals and negative options (threshold, stiffness, friction,
 *              friction velocity) are named
 *   drop <scheme>  a Hex8 ball dropped under gravity onto a floor: no surface point ever at
 *              or below the floor; backward Euler: it comes to rest (centre-of-mass velocity
 *              small) and the floor's reaction is m g within 3 %; Newmark: it bounces (the
 *              centre of mass moves up after the impact); after every step the Newton
 *              matrix (mass, Stable Neo-Hookean tangent, barrier, eliminated rows) is exactly
 *              symmetric
 *   iterates   a ball dropped onto a floor with Newmark (it bounces), Newton limited to 6
 *              iterations so that the impact's steps are halved into substeps: every Newton
 *              iterate (seen by the monitor) keeps every point in front of the floor, and each
 *              step's step_min_distance lies between the smallest distance over its iterates
 *              (every accepted state is an iterate) and the distance after the step
 *   static     a block (0.6 x 0.6 x 0.2 m) held in a cup of five planes within d^ of its faces
 *              (floor and four walls: the walls' barrier fixes the horizontal rigid motions a
 *              static solve cannot), pressed onto the floor by gravity and a downward traction
 *              on its top face, in load steps of the static kind: every step converges, no
 *              point reaches a plane, the floor's reaction equals the load within 1 % and the
 *              walls' net force vanishes; the same block 0.02 m (beyond d^) above the floor
 *              is refused as a free body (FCM_ERR_SINGULAR), the message naming the contact,
 *              and so is the block on the floor alone (2 translations and 1 rotation free) */
#include "sim_util.h"
#include "fcm/fcm.h"
#include "sim/sim_impl.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dotn(fcm_index n, const double *a, const double *b)
{
  double s = 0.0;
  for (fcm_index i = 0; i < n; i++)
    s += a[i] * b[i];
  return s;
}

static int gradient(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  fcm_csr *T = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, r = 0.35;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  /* a tilted plane moving towards the ball: at t = 1 it lies 0.3 d^ below the lowest point */
  const double nrm[3] = {0.2, -0.1, 1.0}, vel[3] = {0.0, 0.0, 0.01};
  double nu[3], pt[3], dh = 0.0, kappa = 0.0, dmin = 0.0;
  const double nl = sqrt(dotn(3, nrm, nrm));
  for (int i = 0; i < 3; i++)
    nu[i] = nrm[i] / nl;
  co.distance = 0.05;
  for (int i = 0; i < 3; i++)
    pt[i] = c[i] - (r + 0.3 * co.distance) * nu[i] - vel[i];
  TEST_OK(ctx, ball_problem(&p, c, r, 4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, pt, nrm, vel, &co, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  TEST_OK(ctx, fcm_integrator_contact_info(I, 0, NULL, &dmin, &dh, &kappa));
  TEST_NEAR(dh, co.distance, 1e-15, 0.0);
  TEST_NEAR(kappa, mat.young * 4.0, 1e-12, 0.0); /* default E / h, h = 1/4 */
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *u = calloc((size_t)n, sizeof *u), *d = calloc((size_t)n, sizeof *d);
  double *f0 = calloc((size_t)n, sizeof *f0);
  srand(7);
  for (fcm_index i = 0; i < n; i++) {
    u[i] = 0.002 * ((double)rand() / RAND_MAX - 0.5);
    d[i] = (double)rand() / RAND_MAX - 0.5;
  }
  TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
  const double t = 1.0;
  double e0 = 0.0, asym = 1.0, err_e = 1.0, err_t = 1.0;
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &e0, f0, T));
  TEST_TRUE(e0 > 0.0);
  TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
  if (!(asym == 0.0)) TEST_FAIL_("tangent: relative asymmetry %.3g", asym);
  contact_fd(ctx, I, n, u, d, t, 1e-7, f0, T, &err_e, &err_t);
  if (!(err_e <= 1e-6)) TEST_FAIL_("force: relative error %.3g against the energy's", err_e);
  if (!(err_t <= 1e-6))
    TEST_FAIL_("tangent: relative error %.3g against the force's differences", err_t);
  contact_eval_cost(ctx, I, &p, u, t, f0, T, "plane");
  free(u), free(d), free(f0);
  fcm_csr_destroy(&T);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

static int errors(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, up[3] = {0, 0, 1}, zero[3] = {0, 0, 0};
  fcm_material mat = {FCM_MATERIAL_LINEAR, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  TEST_OK(ctx, ball_problem(&p, c, 0.35, 4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, c, zero, NULL, NULL, NULL), FCM_ERR_ARG,
           "no direction");
  co.distance = -1.0;
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, c, up, NULL, &co, NULL), FCM_ERR_ARG,
           "distance = -1");
  co.distance = 0.0;
  co.stiffness = -2.0;
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, c, up, NULL, &co, NULL), FCM_ERR_ARG,
           "stiffness = -2");
  co.stiffness = 0.0;
  co.friction = -0.5;
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, c, up, NULL, &co, NULL), FCM_ERR_ARG,
           "contact plane 0: friction = -0.5 must be finite and >= 0");
  co.friction = 0.5;
  co.friction_velocity = -1.0;
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, c, up, NULL, &co, NULL), FCM_ERR_ARG,
           "contact plane 0: friction_velocity = -1 must be finite and >= 0");
  co.friction_velocity = 0.0;
  co.friction_updates = -1;
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, c, up, NULL, &co, NULL), FCM_ERR_ARG,
           "contact plane 0: friction_updates = -1 must be in [0, 20]");
  /* the plane through the centre: half of the surface lies behind it */
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, c, up, NULL, NULL, NULL));
  TEST_ERR(ctx, fcm_integrator_setup(I), FCM_ERR_ARG, "lies at distance");
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* The centre-of-mass velocity's z component: ez^T M v / ez^T M ez; *mass the total mass. */
static double com_velocity(const fcm_integrator *I, fcm_index n, double *ez, double *w,
                           double *mass)
{
  const fcm_csr *M = fcm_integrator_mass(I);
  for (fcm_index i = 0; i < n; i++)
    ez[i] = i % 3 == 2 ? 1.0 : 0.0;
  fcm_csr_apply(M, 1.0, ez, 0.0, w);
  *mass = dotn(n, ez, w);
  return dotn(n, fcm_integrator_velocity(I), w) / *mass;
}

static int drop(fcm_ctx *ctx, fcm_time_scheme scheme, int argc_steps)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, r = 0.35, up[3] = {0, 0, 1}, g[3] = {0, 0, -9.81};
  const double floor_pt[3] = {0.5, 0.5, c[2] - r - 0.03};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.scheme = scheme;
  o.dt = scheme == FCM_SCHEME_BACKWARD_EULER ? 0.02 : 0.01;
  TEST_OK(ctx, ball_problem(&p, c, r, 6));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, floor_pt, up, NULL, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *ez = calloc((size_t)n, sizeof *ez), *w = calloc((size_t)n, sizeof *w);
  double dmin_all = HUGE_VAL, vmax_up = 0.0, vcom = 0.0, mass = 0.0, F[3] = {0, 0, 0};
  int touched = 0;
  const int steps = argc_steps;
  for (int s = 0; s < steps; s++) {
    fcm_step_info info;
    double dmin = 0.0;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    double asym = 1.0;
    TEST_TRUE(I->H != NULL);
    TEST_OK(ctx, fcm_csr_asymmetry(I->H, &asym));
    if (!(asym == 0.0)) TEST_FAIL_("drop: step %d: Newton matrix asymmetry %.3g", s, asym);
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, F, &dmin, NULL, NULL));
    dmin_all = fmin(dmin_all, dmin);
    vcom = com_velocity(I, n, ez, w, &mass);
    if (getenv("CONTACT_TRACE")) printf("%d %g %g %g\n", s, vcom, dmin, F[2]);
    touched |= F[2] > 0.0;
    if (touched) vmax_up = fmax(vmax_up, vcom);
  }
  if (!(dmin_all > 0.0)) TEST_FAIL_("drop: a surface point reached distance %.3g", dmin_all);
  TEST_TRUE(touched);
  {
    /* the filter shortened Newton steps that would have crossed the floor */
    long long filtered = 0, pullbacks = 0;
    TEST_OK(ctx, fcm_integrator_contact_counters(I, &filtered, &pullbacks));
    printf("drop: %lld Newton steps shortened, %lld guesses pulled back\n", filtered, pullbacks);
    TEST_TRUE(filtered + pullbacks > 0);
  }
  const double mg = mass * 9.81;
  printf("drop %s: min distance %.4g, final vz %.4g m/s, max upward vz after contact %.4g m/s, "
         "reaction %.6g N, m g %.6g N\n",
         fcm_time_scheme_name(scheme), dmin_all, vcom, vmax_up, F[2], mg);
  if (scheme == FCM_SCHEME_BACKWARD_EULER) {
    /* at rest: the impact speed is sqrt(2 g 0.03) = 0.77 m/s */
    if (!(fabs(vcom) <= 0.005)) TEST_FAIL_("drop: centre-of-mass velocity %.3g m/s", vcom);
    TEST_NEAR(F[2], mg, 0.02, 0.0);
  } else {
    if (!(vmax_up >= 0.1)) TEST_FAIL_("drop: no bounce (largest upward velocity %.3g)", vmax_up);
  }
  free(ez), free(w);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* A floor moving up at V = 0.2 m/s hits a ball at rest (no gravity), backward Euler: no point
 * ever at or below the moving floor, and the ball leaves it with a centre-of-mass velocity in
 * [V, 2 V] (between a fully inelastic and an elastic collision with an infinitely heavy wall). */
static int push(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  const double c[3] = {0.5, 0.5, 0.5}, r = 0.35, up[3] = {0, 0, 1}, vel[3] = {0, 0, 0.2};
  const double floor_pt[3] = {0.5, 0.5, c[2] - r - 0.01};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 0.01;
  TEST_OK(ctx, ball_problem(&p, c, r, 6));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, floor_pt, up, vel, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *ez = calloc((size_t)n, sizeof *ez), *w = calloc((size_t)n, sizeof *w);
  double dmin_all = HUGE_VAL, vcom = 0.0, mass = 0.0;
  for (int s = 0; s < 100; s++) {
    fcm_step_info info;
    double dmin = 0.0;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, NULL, &dmin, NULL, NULL));
    dmin_all = fmin(dmin_all, dmin);
  }
  vcom = com_velocity(I, n, ez, w, &mass);
  printf("push: min distance %.4g m, final vz %.4g m/s\n", dmin_all, vcom);
  if (!(dmin_all > 0.0)) TEST_FAIL_("push: a surface point reached distance %.3g", dmin_all);
  /* a collision with an infinitely heavy wall moving at V leaves the body between V (fully
   * inelastic) and 2 V (elastic) */
  if (!(vcom >= 0.95 * vel[2] && vcom <= 2.05 * vel[2]))
    TEST_FAIL_("push: centre-of-mass velocity %.3g m/s outside [V, 2 V], V = %g", vcom, vel[2]);
  free(ez), free(w);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* The Newton monitor's view of the iterates: the smallest distance to obstacle 0 over the
 * iterates since the last reset. */
typedef struct iterate_watch {
  fcm_integrator *I;
  double dmin;
  long long seen;
} iterate_watch;

static void watch_iterate(void *user, const fcm_newton_event *ev)
{
  iterate_watch *w = user;
  double d = HUGE_VAL;
  (void)ev;
  if (!w->I || fcm_integrator_contact_info(w->I, 0, NULL, &d, NULL, NULL) != FCM_OK) d = NAN;
  w->dmin = isnan(d) ? NAN : fmin(w->dmin, d);
  w->seen++;
}

static int iterates(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  iterate_watch w = {NULL, HUGE_VAL, 0};
  const double c[3] = {0.5, 0.5, 0.5}, r = 0.35, up[3] = {0, 0, 1}, g[3] = {0, 0, -9.81};
  const double floor_pt[3] = {0.5, 0.5, c[2] - r - 0.03};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_DYNAMIC;
  o.scheme = FCM_SCHEME_NEWMARK;
  o.dt = 0.02;
  o.newton_max_iterations = 6;
  o.max_halvings = 6;
  o.monitor = watch_iterate;
  o.monitor_user = &w;
  TEST_OK(ctx, ball_problem(&p, c, r, 4));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, floor_pt, up, NULL, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  w.I = I;
  int split = 0, closer = 0;
  double dmin_all = HUGE_VAL;
  for (int s = 0; s < 30; s++) {
    fcm_step_info info;
    fcm_contact_stats cs;
    w.dmin = HUGE_VAL;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    dmin_all = fmin(dmin_all, w.dmin);
    split += info.substeps > 1;
    closer += cs.step_min_distance < cs.min_distance;
    if (!(w.dmin > 0.0)) TEST_FAIL_("step %d: a Newton iterate reached distance %.3g", s, w.dmin);
    if (!(w.dmin <= cs.step_min_distance && cs.step_min_distance <= cs.min_distance))
      TEST_FAIL_("step %d (%d substeps): iterates' minimum %.6g, step minimum %.6g, after the "
                 "step %.6g: not in order",
                 s, info.substeps, w.dmin, cs.step_min_distance, cs.min_distance);
    if (info.substeps > 1 && getenv("CONTACT_TRACE"))
      printf("step %d: %d substeps, iterates %.4g, step %.4g, after %.4g\n", s, info.substeps,
             w.dmin, cs.step_min_distance, cs.min_distance);
  }
  printf("iterates: %lld Newton iterates, smallest distance %.4g m; %d steps split into "
         "substeps, %d with an earlier substep closer than the step's end\n",
         w.seen, dmin_all, split, closer);
  TEST_TRUE(split > 0 && closer > 0);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* Static contact: see the header. The load is m g plus a traction q over the top face. */
static void top_traction(void *user, const double x[3], const double normal[3], double out[3])
{
  (void)user, (void)x;
  out[0] = out[1] = 0.0;
  out[2] = normal[2] > 0.5 ? -2000.0 : 0.0;
}

static int static_block(fcm_ctx *ctx, double gap, int walls)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  const double blo[3] = {0.2, 0.2, 0.1}, bhi[3] = {0.8, 0.8, 0.3}, lo[3] = {0, 0, 0},
               hi[3] = {1, 1, 0.5}, g[3] = {0, 0, -9.81};
  const fcm_index gcells[3] = {2, 2, 1}, cells[3] = {5, 5, 3};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  o.kind = FCM_INTEGRATOR_STATIC;
  o.load_steps = 4;
  co.distance = 0.01;
  ro.surface_strength = 2;
  ro.min_fraction = 1e-4;
  TEST_OK(ctx, fcm_geometry_create_box(ctx, blo, bhi, gcells, &p.geom));
  TEST_OK(ctx, fcm_mesh_create_box(ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p.mesh));
  TEST_OK(ctx, fcm_cell_rules_create(ctx, p.mesh, p.geom, &ro, &p.rules));
  TEST_OK(ctx, fcm_space_create_embedded(ctx, p.mesh, p.rules, &p.space));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_traction(I, top_traction, NULL, NULL, NULL));
  {
    const double fp[3] = {0.5, 0.5, blo[2] - gap}, up[3] = {0, 0, 1};
    TEST_OK(ctx, fcm_integrator_add_contact_plane(I, fp, up, NULL, &co, NULL));
    for (int a = 0; a < 2 * walls; a++)
      for (int side = 0; side < 2; side++) {
        double pt[3] = {0.5, 0.5, 0.2}, n[3] = {0, 0, 0};
        pt[a] = side ? bhi[a] + gap : blo[a] - gap;
        n[a] = side ? -1.0 : 1.0;
        TEST_OK(ctx, fcm_integrator_add_contact_plane(I, pt, n, NULL, &co, NULL));
      }
  }
  TEST_OK(ctx, fcm_integrator_setup(I));
  if (gap > co.distance || !walls) { /* nothing, or the floor alone, holds the block */
    fcm_step_info info;
    const char *msg;
    TEST_TRUE(fcm_integrator_step(I, &info) == FCM_ERR_SINGULAR);
    msg = fcm_ctx_error_message(ctx);
    printf("static, gap %g m, %s: %s\n", gap, walls ? "walls" : "no walls", msg);
    TEST_TRUE(strstr(msg, "contact obstacle") != NULL);
    TEST_TRUE(strstr(msg, walls ? "3 rigid-body translations and 3 rotations"
                                : "2 rigid-body translations and 1 rotation free") != NULL);
    fcm_ctx_error_clear(ctx);
    fcm_integrator_destroy(&I);
    problem_free(&p);
    return 0;
  }
  double dmin_all = HUGE_VAL, F[3] = {0, 0, 0}, W[3] = {0, 0, 0};
  {
    fcm_step_info info;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
  }
  for (int c = 0; c < 5; c++) {
    double f[3], dmin = 0.0;
    TEST_OK(ctx, fcm_integrator_contact_info(I, c, f, &dmin, NULL, NULL));
    dmin_all = fmin(dmin_all, dmin);
    for (int i = 0; i < 3; i++)
      (c == 0 ? F : W)[i] += f[i];
  }
  const double mg = 1000.0 * 0.6 * 0.6 * 0.2 * 9.81, load = mg + 2000.0 * 0.6 * 0.6;
  printf("static: min distance %.3g m; floor reaction %.6g N against the load %.6g N; walls' "
         "net force (%.3g, %.3g, %.3g) N\n",
         dmin_all, F[2], load, W[0], W[1], W[2]);
  if (!(dmin_all > 0.0)) TEST_FAIL_("static: a point reached distance %.3g", dmin_all);
  TEST_NEAR(F[2], load, 0.01, 0.0);
  TEST_NEAR(F[0], 0.0, 0.0, 1e-3 * load);
  TEST_NEAR(F[1], 0.0, 0.0, 1e-3 * load);
  for (int i = 0; i < 3; i++)
    TEST_NEAR(W[i], 0.0, 0.0, 1e-3 * load);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const char *mode = argc > 1 ? argv[1] : "gradient";
  if (!strcmp(mode, "gradient")) {
    gradient(ctx);
  } else if (!strcmp(mode, "push")) {
    push(ctx);
  } else if (!strcmp(mode, "iterates")) {
    iterates(ctx);
  } else if (!strcmp(mode, "static")) {
    static_block(ctx, 0.003, 1);
    static_block(ctx, 0.02, 1);
    static_block(ctx, 0.003, 0);
  } else if (!strcmp(mode, "errors")) {
    errors(ctx);
  } else if (!strcmp(mode, "drop")) {
    const char *sch = argc > 2 ? argv[2] : "backward_euler";
    drop(ctx, !strcmp(sch, "newmark") ? FCM_SCHEME_NEWMARK : FCM_SCHEME_BACKWARD_EULER,
         argc > 3 ? atoi(argv[3]) : (strcmp(sch, "newmark") ? 150 : 60));
  } else {
    return 2;
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
