/* Friction between bodies (fcm_contact_options.friction with fcm_integrator_add_contact_bodies())
 * and static contact between bodies:
 * a block (0.4 x 0.4 x 0.145 m, E = 1e6 Pa) falls 0.06 m onto a plate clamped at its bottom,
 * settles under gravity, and from t = 0.25 s is pulled sideways by a body force of density
 * rho a_x, a_x = 0.5 g (backward Euler dt 0.01 s, eps_v = 0.01 m/s); by mode:
 *   stick    mu = 0.8 > a_x / g: the block's centre of mass moves sideways by at most
 *            eps_v per second over the pull's last 0.2 s (the smoothed static friction's creep)
 *   slide    mu = 0.2: it slides with the acceleration a_x - mu g within 3 %; the friction's
 *            force against central differences of its energy (relative error <= 1e-6, the lag
 *            of the last substep), the Newton matrix positive semidefinite along them, and
 *            friction work reported
 * In both no sample lies inside the other body (depth <= 1e-6 m).
 *   static   the same plate and block in a static solve (gravity, 4 load steps), the block held
 *            in x and y at its nodes but not along z: with d^ = 0.1 m (the block starts 0.065 m
 *            above the plate) the plate holds it through the barrier, the solve converges and
 *            the plate's clamp carries the weight of both (1 %); with d^ = 0.03 m nothing holds
 *            the block's vertical translation and the step is refused (FCM_ERR_SINGULAR, naming
 *            it) */
#include "sim_util.h"
#include "fcm/fcm.h"
#include "sim/sim_impl.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define G0         9.81
#define PULL_START 0.25

/* The plate [0.05, 0.95]^2 x [0.05, 0.24] and the block [0.3, 0.7]^2 x [0.305, 0.45] (one
 * geometry) on 8 x 8 x 12 Hex8 cells over [0, 1]^2 x [0, 0.6]: the cell layer
 * 0.25 < z < 0.3 is empty, so they share no DOF. */
static fcm_status plate_block(problem *p)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0.6};
  const double alo[3] = {0.05, 0.05, 0.05}, ahi[3] = {0.95, 0.95, 0.24};
  const double blo[3] = {0.3, 0.3, 0.305}, bhi[3] = {0.7, 0.7, 0.45};
  const fcm_index cells[3] = {8, 8, 12}, n[3] = {2, 2, 1};
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  fcm_status st = merged_boxes(p->ctx, alo, ahi, blo, bhi, n, &p->geom);
  if (st == FCM_OK) st = fcm_mesh_create_box(p->ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p->mesh);
  ro.surface_strength = 2;
  ro.min_fraction = 1e-4;
  if (st == FCM_OK) st = fcm_cell_rules_create(p->ctx, p->mesh, p->geom, &ro, &p->rules);
  if (st == FCM_OK) st = fcm_space_create_embedded(p->ctx, p->mesh, p->rules, &p->space);
  return st;
}

static void pull(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)user, (void)normal;
  value[0] = x[2] > 0.27 ? 1000.0 * 0.5 * G0 : 0.0;
  value[1] = value[2] = 0.0;
}

static double pull_on(void *user, double t)
{
  (void)user;
  return t > PULL_START + 1e-9 ? 1.0 : 0.0;
}

/* The block's centre-of-mass velocity and displacement along x (the DOFs of the elements whose
 * cells lie above z = 0.27, weighted by the lumped mass). */
static void block_x(const problem *p, fcm_integrator *I, double *v, double *u)
{
  const fcm_index n = fcm_integrator_num_dofs(I);
  const fcm_csr *M = fcm_integrator_mass(I);
  double *e = calloc((size_t)n, sizeof *e), *w = calloc((size_t)n, sizeof *w), m = 0.0;
  for (fcm_index el = 0; el < fcm_space_num_elements(p->space); el++) {
    double X[3 * 8], zc = 0.0;
    fcm_mesh_cell_coords(p->mesh, fcm_space_element_cell(p->space, el), X);
    for (int a = 0; a < 8; a++)
      zc += X[3 * a + 2] / 8.0;
    if (zc < 0.27) continue;
    const fcm_index *ed = fcm_space_element_dofs(p->space, el);
    for (int a = 0; a < 8; a++)
      e[ed[a]] = 1.0;
  }
  TEST_OK(p->ctx, fcm_csr_apply(M, 1.0, e, 0.0, w));
  *v = *u = 0.0;
  for (fcm_index i = 0; i < n; i++) {
    m += e[i] * w[i];
    *v += fcm_integrator_velocity(I)[i] * e[i] * w[i];
    *u += fcm_integrator_displacement(I)[i] * e[i] * w[i];
  }
  *v /= m, *u /= m;
  free(e), free(w);
}

static int run(fcm_ctx *ctx, double mu)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  const double g[3] = {0, 0, -G0};
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 0.01;
  co.friction = mu;
  co.friction_velocity = 0.01;
  co.distance = 0.01;
  TEST_OK(ctx, plate_block(&p));
  if (!p.space) return 0;
  TEST_TRUE(fcm_space_num_bodies(p.space) == 2);
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  if (!I) return 0;
  {
    const fcm_index nn = fcm_mesh_num_nodes(p.mesh);
    const double *X = fcm_mesh_coords(p.mesh);
    fcm_index *nodes = malloc(sizeof(fcm_index) * (size_t)nn), m = 0;
    fcm_motion held = fcm_motion_default();
    for (fcm_index v = 0; v < nn; v++)
      if (X[3 * v + 2] < 0.11) nodes[m++] = v;
    TEST_OK(ctx, fcm_integrator_add_constraint(I, m, nodes, &held, NULL));
    free(nodes);
  }
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_body_force(I, pull, NULL, pull_on, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p.geom, &co, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  const int steps = 55, mark = 35;
  double v1 = 0.0, u1 = 0.0, v2 = 0.0, u2 = 0.0, depth = 0.0, work = 0.0;
  const double t0 = fcm_wtime();
  for (int s = 0; s < steps; s++) {
    fcm_step_info info;
    fcm_contact_stats cs;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    if (fcm_ctx_error_status(ctx) != FCM_OK) break;
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    depth = fmax(depth, cs.body_depth);
    work += cs.friction_dissipation;
    if (getenv("FCM_TEST_VERBOSE")) {
      double v, u;
      block_x(&p, I, &v, &u);
      printf("step %d: %d Newton, %lld pairs, smallest distance %.3g m, vx %.4g m/s, ux %.4g m, "
             "friction work %.3g J\n",
             s, info.newton_iterations, cs.body_pairs, cs.min_distance, v, u,
             cs.friction_dissipation);
    }
    if (s + 1 == mark) block_x(&p, I, &v1, &u1);
  }
  block_x(&p, I, &v2, &u2);
  const double T = (steps - mark) * o.dt;
  printf("mu = %g: %d steps %.3g s; over the last %g s: displacement %.4g m, velocity %.4g -> "
         "%.4g m/s; friction work %.4g J; largest depth %.3g m\n",
         mu, steps, fcm_wtime() - t0, T, u2 - u1, v1, v2, work, depth);
  if (!(depth <= 1e-6)) TEST_FAIL_("a sample got %.3g m inside the other body", depth);
  if (mu > 0.5) {
    if (!(fabs(u2 - u1) <= co.friction_velocity * T))
      TEST_FAIL_("the block crept %.3g m (bound %.3g)", u2 - u1, co.friction_velocity * T);
  } else {
    const double a = (v2 - v1) / T, a_ref = 0.5 * G0 - mu * G0;
    printf("slide: acceleration %.5g m/s^2 against a_x - mu g = %.5g\n", a, a_ref);
    TEST_NEAR(a, a_ref, 0.03, 0.0);
    TEST_TRUE(work > 0.0);
    /* the friction's force and Newton matrix at the end, with the last substep's lag */
    const fcm_index n = fcm_integrator_num_dofs(I);
    double *u = malloc(sizeof(double) * (size_t)n), *f = calloc((size_t)n, sizeof *f);
    double *d = malloc(sizeof(double) * (size_t)n), *Td = calloc((size_t)n, sizeof *Td);
    double e = 0.0;
    fcm_csr *H = NULL;
    const double t = fcm_integrator_time(I);
    TEST_OK(ctx, fcm_space_matrix_create(p.space, &H));
    fcm_integrator_get_state(I, u, NULL, NULL, NULL);
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &e, f, H));
    srand(13);
    for (int dir = 0; dir < 3; dir++) {
      double ee = 0.0, et = 0.0, dTd = 0.0;
      for (fcm_index i = 0; i < n; i++)
        d[i] = I->is_con[i] ? 0.0 : (double)rand() / RAND_MAX - 0.5;
      contact_fd(ctx, I, n, u, d, t, 1e-8, f, NULL, &ee, &et);
      TEST_OK(ctx, fcm_csr_apply(H, 1.0, d, 0.0, Td));
      for (fcm_index i = 0; i < n; i++)
        dTd += d[i] * Td[i];
      printf("slide: contact energy %.6g J; force against differences %.3g; d^T H d %.4g\n", e, ee,
             dTd);
      if (!(ee <= 1e-6)) TEST_FAIL_("force against differences: relative error %.3g", ee);
      if (!(dTd >= 0.0)) TEST_FAIL_("Newton matrix not positive semidefinite: %.3g", dTd);
    }
    fcm_csr_destroy(&H);
    free(u), free(f), free(d), free(Td);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

static int static_rest(fcm_ctx *ctx, double dhat)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  const double g[3] = {0, 0, -G0};
  int clamp = -1;
  o.kind = FCM_INTEGRATOR_STATIC;
  o.load_steps = 4;
  co.distance = dhat;
  TEST_OK(ctx, plate_block(&p));
  if (!p.space) return 0;
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  if (!I) return 0;
  {
    const fcm_index nn = fcm_mesh_num_nodes(p.mesh);
    const double *X = fcm_mesh_coords(p.mesh);
    fcm_index *low = malloc(sizeof(fcm_index) * (size_t)nn),
              *high = malloc(sizeof(fcm_index) * (size_t)nn);
    fcm_index nl = 0, nh = 0;
    fcm_motion held = fcm_motion_default(), side = fcm_motion_default();
    for (fcm_index v = 0; v < nn; v++) {
      if (X[3 * v + 2] < 0.11) low[nl++] = v;
      if (X[3 * v + 2] > 0.27) high[nh++] = v;
    }
    side.components[2] = 0;
    TEST_OK(ctx, fcm_integrator_add_constraint(I, nl, low, &held, &clamp));
    TEST_OK(ctx, fcm_integrator_add_constraint(I, nh, high, &side, NULL));
    free(low), free(high);
  }
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p.geom, &co, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  fcm_step_info info;
  if (dhat < 0.065) {
    TEST_TRUE(fcm_integrator_step(I, &info) == FCM_ERR_SINGULAR);
    const char *msg = fcm_ctx_error_message(ctx);
    printf("static, d^ = %g m: %s\n", dhat, msg);
    TEST_TRUE(strstr(msg, "1 rigid-body translation free") != NULL);
    fcm_ctx_error_clear(ctx);
  } else {
    fcm_contact_stats cs;
    double R[3] = {0, 0, 0};
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    TEST_TRUE(info.reason == FCM_STEP_CONVERGED);
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    TEST_OK(ctx, fcm_integrator_reaction(I, clamp, R, NULL));
    const double w = 1000.0 * G0 * (0.9 * 0.9 * 0.19 + 0.4 * 0.4 * 0.145);
    printf("static, d^ = %g m: %d Newton iterations; %lld pairs, smallest distance %.4g m, "
           "depth %.3g m; the clamp's reaction %.6g N against the weight of both %.6g N\n",
           dhat, info.newton_iterations, cs.body_pairs, cs.min_distance, cs.body_depth, R[2], w);
    TEST_TRUE(cs.body_pairs > 0 && cs.min_distance > 0.0 && cs.body_depth <= 1e-6);
    TEST_NEAR(R[2], w, 0.01, 0.0);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(argc > 1);
  if (argc < 2) return TEST_RESULT();
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  if (!strcmp(argv[1], "stick"))
    run(ctx, 0.8);
  else if (!strcmp(argv[1], "slide"))
    run(ctx, 0.2);
  else if (!strcmp(argv[1], "static")) {
    static_rest(ctx, 0.1);
    static_rest(ctx, 0.03);
  } else
    TEST_FAIL_("unknown mode %s", argv[1]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
