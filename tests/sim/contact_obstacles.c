/* Contact with spheres, boxes and closed triangle surfaces, by mode:
 *   triangle   the point-triangle distance in each of its seven regions (face, three edges,
 *              three vertices): the region found, the distance not above that of 20,000 points
 *              sampled on the triangle and within 2e-2 of their minimum, the gradient against
 *              central differences of the distance and the Hessian against those of the
 *              gradient (absolute error <= 1e-6)
 *   distance   spheres, boxes and a cube-shaped surface, each moving rigidly (translation and
 *              rotation): gradients and Hessians of fcm_integrator_contact_distance() against
 *              central differences at points near faces, edges and corners; the box and the
 *              surface of the same cube give the same signed distance inside and outside; the
 *              sphere's distance is |x - c(t)| - r with c(t) from fcm_motion_eval()
 *   force      an embedded ball near each kind (a random displacement): central differences
 *              of the barrier energy match its force (relative error <= 1e-6); the Newton
 *              matrix is exactly symmetric and positive semidefinite along random directions
 *   drop <kind>  a Hex8 ball dropped under gravity onto a sphere, a box or a tilted cube
 *              surface (backward Euler): touches it, never reaches distance 0 (signed: inside
 *              counts) at any step, and the filter acted
 *   push <kind>  the obstacle moves up at V = 0.2 m/s into a ball at rest (no gravity): never
 *              crossed, the ball leaves with a centre-of-mass velocity in [V, 2 V]
 *   errors     bad radius, corners, motion and options, an open surface, and a body starting
 *              inside each kind: refused, naming the field, the point and its depth */
#include "sim_util.h"
#include "fcm/fcm.h"
#include "sim/sim_impl.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The 8 corners and 12 outward triangles of the box [lo, hi]. */
static void cube_surface(const double lo[3], const double hi[3], double xyz[24], fcm_index tri[36])
{
  static const fcm_index t[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                  2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
  for (int v = 0; v < 8; v++) {
    const int bx = (v == 1 || v == 2 || v == 5 || v == 6),
              by = (v == 2 || v == 3 || v == 6 || v == 7);
    xyz[3 * v] = bx ? hi[0] : lo[0];
    xyz[3 * v + 1] = by ? hi[1] : lo[1];
    xyz[3 * v + 2] = v >= 4 ? hi[2] : lo[2];
  }
  memcpy(tri, t, sizeof t);
}

static double rnd(void)
{
  return (double)rand() / RAND_MAX - 0.5;
}

/* Central differences of the distance (gradient) and of the gradient (Hessian) at x against g
 * and H; the largest absolute error. fn(user, x, &d, g, H). */
typedef void (*dist_fn)(void *user, const double x[3], double *d, double g[3], double H[9]);

static double fd_error(dist_fn fn, void *user, const double x[3], const double g[3],
                       const double H[9])
{
  const double h = 1e-6;
  double err = 0.0;
  for (int j = 0; j < 3; j++) {
    double xp[3], xm[3], dp, dm, gp[3], gm[3], Hs[9];
    memcpy(xp, x, sizeof xp);
    memcpy(xm, x, sizeof xm);
    xp[j] += h;
    xm[j] -= h;
    fn(user, xp, &dp, gp, Hs);
    fn(user, xm, &dm, gm, Hs);
    err = fmax(err, fabs((dp - dm) / (2 * h) - g[j]));
    for (int i = 0; i < 3; i++)
      err = fmax(err, fabs((gp[i] - gm[i]) / (2 * h) - H[3 * i + j]));
  }
  return err;
}

typedef struct tri_user {
  const double *a, *b, *c;
} tri_user;

static void tri_fn(void *user, const double x[3], double *d, double g[3], double H[9])
{
  const tri_user *t = user;
  fcm__sim_point_triangle_distance(x, t->a, t->b, t->c, d, g, H, NULL);
}

static int triangle(void)
{
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0.2, 0.9, 0};
  /* one point per region: face, edges ab, bc, ca, vertices a, b, c */
  const double pts[7][3] = {{0.3, 0.3, 0.4},   {0.5, -0.3, 0.2}, {0.8, 0.6, 0.3}, {-0.2, 0.5, 0.1},
                            {-0.3, -0.3, 0.2}, {1.4, -0.2, 0.1}, {0.2, 1.4, 0.3}};
  tri_user u = {a, b, c};
  srand(3);
  for (int r = 0; r < 7; r++) {
    double d, g[3], H[9], smin = HUGE_VAL;
    int region = -1;
    fcm__sim_point_triangle_distance(pts[r], a, b, c, &d, g, H, &region);
    if (region != r) TEST_FAIL_("triangle: point %d in region %d, expected %d", r, region, r);
    for (int k = 0; k < 20000; k++) {
      double s = rnd() + 0.5, t = rnd() + 0.5, q[3], e = 0.0;
      if (s + t > 1.0) s = 1.0 - s, t = 1.0 - t;
      for (int i = 0; i < 3; i++) {
        q[i] = a[i] + s * (b[i] - a[i]) + t * (c[i] - a[i]) - pts[r][i];
        e += q[i] * q[i];
      }
      smin = fmin(smin, sqrt(e));
    }
    if (!(d <= smin + 1e-14 && smin - d <= 2e-2))
      TEST_FAIL_("triangle: region %d: distance %.6g against sampled minimum %.6g", r, d, smin);
    const double err = fd_error(tri_fn, &u, pts[r], g, H);
    if (!(err <= 1e-6)) TEST_FAIL_("triangle: region %d: derivative error %.3g", r, err);
  }
  return 0;
}

typedef struct obst_user {
  fcm_integrator *I;
  int id;
  double t;
} obst_user;

static void obst_fn(void *user, const double x[3], double *d, double g[3], double H[9])
{
  const obst_user *o = user;
  fcm_integrator_contact_distance(o->I, o->id, x, o->t, d, g, H);
}

/* An integrator on a small embedded ball (the obstacles need one to live in). */
static fcm_integrator *make_integrator(fcm_ctx *ctx, problem *p, fcm_index nc)
{
  fcm_integrator *I = NULL;
  const double c[3] = {0.5, 0.5, 0.5};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 0.02;
  TEST_OK(ctx, ball_problem(p, c, 0.25, nc));
  TEST_OK(ctx, fcm_integrator_create(ctx, p->space, &mat, &o, &I));
  return I;
}

static int distance(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = make_integrator(ctx, &p, 2);
  const double lo[3] = {-0.3, -0.2, -0.1}, hi[3] = {0.4, 0.5, 0.3}, sc[3] = {0.1, 0.2, 0.3};
  double xyz[24];
  fcm_index tri[36];
  fcm_motion m = fcm_motion_default();
  const double ax[3] = {1, 2, 2};
  for (int i = 0; i < 3; i++) {
    m.velocity[i] = 0.1 * (i + 1);
    m.center[i] = 0.05 * i;
    m.axis[i] = ax[i];
  }
  m.angular_speed = 0.8;
  cube_surface(lo, hi, xyz, tri);
  TEST_OK(ctx, fcm_integrator_add_contact_sphere(I, sc, 0.3, &m, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_box(I, lo, hi, &m, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_surface(I, 8, xyz, 12, tri, &m, NULL, NULL));
  const double t = 0.7;
  /* frame points near a face, an edge, a corner, and inside; moved to the world at t */
  const double fr[5][3] = {
      {0.05, 0.1, 0.42}, {0.55, 0.1, 0.45}, {0.6, 0.7, -0.3}, {-0.45, 0.62, 0.1}, {0.0, 0.1, 0.1}};
  double uc[3], csph[3];
  fcm_motion_eval(&m, sc, t, uc, NULL);
  for (int i = 0; i < 3; i++)
    csph[i] = sc[i] + uc[i];
  for (int k = 0; k < 5; k++) {
    double x[3], u[3], d[3], g[3][3], H[3][9];
    fcm_motion_eval(&m, fr[k], t, u, NULL);
    for (int i = 0; i < 3; i++)
      x[i] = fr[k][i] + u[i];
    for (int id = 0; id < 3; id++) {
      obst_user ou = {I, id, t};
      TEST_OK(ctx, fcm_integrator_contact_distance(I, id, x, t, &d[id], g[id], H[id]));
      if (k == 4) continue; /* inside: only the signed distance is compared */
      const double err = fd_error(obst_fn, &ou, x, g[id], H[id]);
      if (!(err <= 1e-6))
        TEST_FAIL_("distance: obstacle %d, point %d: derivative error %.3g", id, k, err);
    }
    double r = 0.0;
    for (int i = 0; i < 3; i++)
      r += (x[i] - csph[i]) * (x[i] - csph[i]);
    TEST_NEAR(d[0], sqrt(r) - 0.3, 1e-12, 1e-13);
    TEST_NEAR(d[2], d[1], 1e-12, 1e-13); /* the box and its surface */
    if (k == 4) TEST_TRUE(d[1] < 0.0);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* Obstacle `kind` (0 sphere, 1 box, 2 surface: a cube tilted by 45 degrees about y, an edge
 * up) below a ball of radius 0.25 at (0.5, 0.5, 0.5), its top `gap` below the ball, moving at
 * `vel` (NULL: static). */
static void add_obstacle_below(fcm_ctx *ctx, fcm_integrator *I, int kind, double gap,
                               const double *vel, const fcm_contact_options *co)
{
  const double top = 0.25 - gap;
  fcm_motion m = fcm_motion_default();
  if (vel) memcpy(m.velocity, vel, sizeof m.velocity);
  if (kind == 0) {
    const double c[3] = {0.55, 0.5, top - 0.2};
    TEST_OK(ctx, fcm_integrator_add_contact_sphere(I, c, 0.2, vel ? &m : NULL, co, NULL));
  } else if (kind == 1) {
    const double lo[3] = {0.1, 0.0, top - 0.3}, hi[3] = {0.6, 1.0, top};
    TEST_OK(ctx, fcm_integrator_add_contact_box(I, lo, hi, vel ? &m : NULL, co, NULL));
  } else {
    const double h = 0.2, lo[3] = {-h, -0.6, -h}, hi[3] = {h, 0.6, h};
    double xyz[24];
    fcm_index tri[36];
    cube_surface(lo, hi, xyz, tri);
    const double cs = sqrt(0.5);
    for (int v = 0; v < 8; v++) {
      const double x = xyz[3 * v], z = xyz[3 * v + 2];
      xyz[3 * v] = 0.45 + cs * (x + z);
      xyz[3 * v + 1] += 0.5;
      xyz[3 * v + 2] = top - h * sqrt(2.0) + cs * (z - x);
    }
    TEST_OK(ctx, fcm_integrator_add_contact_surface(I, 8, xyz, 12, tri, vel ? &m : NULL, co, NULL));
  }
}

static int force(fcm_ctx *ctx, int kind)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = make_integrator(ctx, &p, 4);
  fcm_csr *T = NULL;
  fcm_contact_options co = fcm_contact_options_default();
  co.distance = 0.05;
  add_obstacle_below(ctx, I, kind, 0.015, NULL, &co);
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *u = calloc((size_t)n, sizeof *u), *d = calloc((size_t)n, sizeof *d);
  double *f0 = calloc((size_t)n, sizeof *f0), *Td = calloc((size_t)n, sizeof *Td);
  srand(11);
  for (fcm_index i = 0; i < n; i++) {
    u[i] = 0.002 * rnd();
    d[i] = rnd();
  }
  TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
  double e0 = 0.0, asym = 1.0, dTd = 0.0, err_e = 1.0, err_t = 0.0;
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e0, f0, T));
  TEST_TRUE(e0 > 0.0);
  /* the force is exact; the Newton matrix is the PSD part of the exact Hessian */
  contact_fd(ctx, I, n, u, d, 0.0, 1e-7, f0, NULL, &err_e, &err_t);
  if (!(err_e <= 1e-6))
    TEST_FAIL_("force %d: relative error %.3g against the energy's", kind, err_e);
  TEST_OK(ctx, fcm_csr_asymmetry(T, &asym));
  if (!(asym == 0.0)) TEST_FAIL_("force: Newton matrix asymmetry %.3g", asym);
  for (int r = 0; r < 5; r++) {
    for (fcm_index i = 0; i < n; i++)
      d[i] = rnd();
    TEST_OK(ctx, fcm_csr_apply(T, 1.0, d, 0.0, Td));
    dTd = 0.0;
    for (fcm_index i = 0; i < n; i++)
      dTd += d[i] * Td[i];
    if (!(dTd >= 0.0)) TEST_FAIL_("force: d^T T d = %.3g < 0", dTd);
  }
  {
    char what[32];
    snprintf(what, sizeof what, "force %d", kind);
    contact_eval_cost(ctx, I, &p, u, 0.0, f0, T, what);
  }
  free(u), free(d), free(f0), free(Td);
  fcm_csr_destroy(&T);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* The centre-of-mass velocity's z component. */
static double com_vz(const fcm_integrator *I, fcm_index n)
{
  const fcm_csr *M = fcm_integrator_mass(I);
  double *ez = calloc((size_t)n, sizeof *ez), *w = calloc((size_t)n, sizeof *w), m = 0.0, p = 0.0;
  for (fcm_index i = 0; i < n; i++)
    ez[i] = i % 3 == 2 ? 1.0 : 0.0;
  fcm_csr_apply(M, 1.0, ez, 0.0, w);
  for (fcm_index i = 0; i < n; i++) {
    m += ez[i] * w[i];
    p += fcm_integrator_velocity(I)[i] * w[i];
  }
  free(ez), free(w);
  return p / m;
}

static int drop_or_push(fcm_ctx *ctx, int kind, int push)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = make_integrator(ctx, &p, 6);
  const double g[3] = {0, 0, -9.81}, V[3] = {0, 0, 0.2};
  if (!push) TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  add_obstacle_below(ctx, I, kind, push ? 0.01 : 0.03, push ? V : NULL, NULL);
  TEST_OK(ctx, fcm_integrator_setup(I));
  const fcm_index n = fcm_space_num_dofs(p.space);
  double dmin_all = HUGE_VAL, F[3] = {0, 0, 0}, fmax_z = 0.0;
  const int steps = push ? 60 : 40;
  for (int s = 0; s < steps; s++) {
    fcm_step_info info;
    double dmin = 0.0;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, F, &dmin, NULL, NULL));
    dmin_all = fmin(dmin_all, dmin);
    fmax_z = fmax(fmax_z, F[2]);
  }
  long long filtered = 0, pullbacks = 0;
  TEST_OK(ctx, fcm_integrator_contact_counters(I, &filtered, &pullbacks));
  const double vz = com_vz(I, n);
  printf("%s %d: min distance %.4g m, largest upward force %.4g N, final vz %.4g m/s, %lld steps "
         "shortened, %lld guesses pulled back\n",
         push ? "push" : "drop", kind, dmin_all, fmax_z, vz, filtered, pullbacks);
  if (!(dmin_all > 0.0)) TEST_FAIL_("a surface point reached distance %.3g", dmin_all);
  if (!(fmax_z > 0.0)) TEST_FAIL_("the ball never touched the obstacle");
  if (push) {
    if (!(vz >= 0.95 * V[2] && vz <= 2.05 * V[2]))
      TEST_FAIL_("push: centre-of-mass velocity %.3g m/s outside [V, 2 V], V = %g", vz, V[2]);
  } else {
    TEST_TRUE(filtered + pullbacks > 0);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

static int errors(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = make_integrator(ctx, &p, 4);
  const double c[3] = {0.5, 0.5, 0.5}, lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0.1};
  const double bad_hi[3] = {1, -1, 1};
  fcm_contact_options co = fcm_contact_options_default();
  fcm_motion m = fcm_motion_default();
  double xyz[24];
  fcm_index tri[36];
  TEST_ERR(ctx, fcm_integrator_add_contact_sphere(I, c, -1.0, NULL, NULL, NULL), FCM_ERR_ARG,
           "radius = -1");
  TEST_ERR(ctx, fcm_integrator_add_contact_box(I, lo, bad_hi, NULL, NULL, NULL), FCM_ERR_ARG,
           "min[1] = 0 must be finite and below max[1] = -1");
  co.distance = -1.0;
  TEST_ERR(ctx, fcm_integrator_add_contact_sphere(I, c, 0.1, NULL, &co, NULL), FCM_ERR_ARG,
           "contact sphere 0: distance = -1");
  co.distance = 0.0;
  co.stiffness = -3.0;
  TEST_ERR(ctx, fcm_integrator_add_contact_box(I, lo, hi, NULL, &co, NULL), FCM_ERR_ARG,
           "contact box 0: stiffness = -3");
  m.start = 2.0;
  m.end = 1.0;
  TEST_ERR(ctx, fcm_integrator_add_contact_box(I, lo, hi, &m, NULL, NULL), FCM_ERR_ARG,
           "end = 1 before start = 2");
  cube_surface(lo, hi, xyz, tri);
  TEST_ERR(ctx, fcm_integrator_add_contact_surface(I, 8, xyz, 11, tri, NULL, NULL, NULL),
           FCM_ERR_ARG, "contact surface 0: not closed: 3 edges belong to one triangle only");
  /* a body starting inside each kind: the obstacle's top 0.1 above the ball's lowest point */
  for (int kind = 0; kind < 3; kind++) {
    fcm_integrator_destroy(&I);
    problem_free(&p);
    p = (problem){ctx, NULL, NULL, NULL, NULL};
    I = make_integrator(ctx, &p, 4);
    add_obstacle_below(ctx, I, kind, -0.1, NULL, NULL);
    const char *want[3] = {"contact sphere 0: the body starts in penetration",
                           "contact box 0: the body starts in penetration",
                           "contact surface 0: the body starts in penetration"};
    TEST_ERR(ctx, fcm_integrator_setup(I), FCM_ERR_ARG, want[kind]);
  }
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  if (fcm_ctx_create(NULL, &ctx) != FCM_OK) return 1;
  const char *mode = argc > 1 ? argv[1] : "triangle";
  const char *kinds[3] = {"sphere", "box", "surface"};
  int kind = -1;
  for (int k = 0; k < 3 && argc > 2; k++)
    if (!strcmp(argv[2], kinds[k])) kind = k;
  if (!strcmp(mode, "triangle")) {
    triangle();
  } else if (!strcmp(mode, "distance")) {
    distance(ctx);
  } else if (!strcmp(mode, "errors")) {
    errors(ctx);
  } else if (kind >= 0 && !strcmp(mode, "force")) {
    force(ctx, kind);
  } else if (kind >= 0 && (!strcmp(mode, "drop") || !strcmp(mode, "push"))) {
    drop_or_push(ctx, kind, !strcmp(mode, "push"));
  } else {
    return 2;
  }
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
