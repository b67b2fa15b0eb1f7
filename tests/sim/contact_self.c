/* Self-contact of one body (fcm_contact_options.self_contact) on a C-shaped body: two arms
 * 0.8 m long and 0.2 m thick joined by a spine, 0.2 m apart, the lower arm clamped; by mode:
 *   fd       the upper arm's free end pushed to within the threshold of the lower arm with a
 *            random displacement: central differences of the barrier energy match its force
 *            (relative error <= 1e-6), the Newton matrix is symmetric and positive
 *            semidefinite along random directions, the pairs are of one body; a step pushing
 *            the arm through the other is cut short to a fraction that keeps every pair apart
 *            (the energy there finite), and a rigid translation of the body is not limited
 *   fold     a downward load on the upper arm's end folds it onto the lower arm (backward
 *            Euler): with self-contact no sample lies inside the body at any step (depth
 *            <= 1e-6 m) and the arms touch (self pairs within the threshold); without it the
 *            same run passes the upper arm into the lower one (depth > 0.01 m) while no self
 *            pair or exclusion test is ever made (counters zero)
 *   cost     not asserted (lib/docs/contact.md): the fold with and without self-contact, one
 *            evaluation of the contact per sample point in the folded state and the step time
 *   errors   self_contact on an obstacle or out of {0, 1} refused naming the field; the scene
 *            key "self" accepted with "bodies" only */
#include "sim_util.h"
#include "fcm/fcm.h"
#include "sim/sim_impl.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double rnd(void)
{
  return (double)rand() / RAND_MAX - 0.5;
}

/* The C: [0, 1] x [0, 0.2] x [0, 0.6] less the slot x > 0.2, 0.2 < z < 0.4 (tets of 0.2 m
 * cubes), on 11 x 3 x 7 Hex8 cells of 0.1 m offset by 0.05 m: the cell layer 0.25 < z < 0.35
 * of the slot is empty, so the arms share DOFs only through the spine. */
static fcm_status c_problem(problem *p)
{
  const double glo[3] = {0, 0, 0}, ghi[3] = {1, 0.2, 0.6}, n3[3] = {5, 1, 3};
  const double lo[3] = {-0.05, -0.05, -0.05}, hi[3] = {1.05, 0.25, 0.65};
  const fcm_index cells[3] = {11, 3, 7},
                  gn[3] = {(fcm_index)n3[0], (fcm_index)n3[1], (fcm_index)n3[2]};
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  fcm_geometry *box = NULL;
  fcm_status st = fcm_geometry_create_box(p->ctx, glo, ghi, gn, &box);
  if (st == FCM_OK) {
    const fcm_index nn = fcm_geometry_num_nodes(box), nc = fcm_geometry_num_cells(box);
    const double *x = fcm_geometry_coords(box);
    const fcm_index *c = fcm_geometry_cells(box);
    fcm_index *keep = malloc(sizeof(fcm_index) * 4 * (size_t)nc), m = 0;
    for (fcm_index k = 0; k < nc; k++) {
      double xc = 0.0, zc = 0.0;
      for (int a = 0; a < 4; a++)
        xc += x[3 * c[4 * k + a]] / 4.0, zc += x[3 * c[4 * k + a] + 2] / 4.0;
      if (xc > 0.2 && zc > 0.2 && zc < 0.4) continue;
      memcpy(keep + 4 * m++, c + 4 * k, sizeof(fcm_index) * 4);
    }
    st = fcm_geometry_create(p->ctx, FCM_ELEMENT_TET4, nn, x, m, keep, &p->geom);
    free(keep);
  }
  fcm_geometry_destroy(&box);
  if (st == FCM_OK) st = fcm_mesh_create_box(p->ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p->mesh);
  ro.surface_strength = 2;
  ro.min_fraction = 1e-4;
  if (st == FCM_OK) st = fcm_cell_rules_create(p->ctx, p->mesh, p->geom, &ro, &p->rules);
  if (st == FCM_OK) st = fcm_space_create_embedded(p->ctx, p->mesh, p->rules, &p->space);
  return st;
}

/* The downward load density on the upper arm's end (x > 0.6, z > 0.4), ramped over 0.2 s. */
static void load(void *user, const double x[3], const double normal[3], double value[3])
{
  (void)normal;
  value[0] = value[1] = 0.0;
  value[2] = x[0] > 0.6 && x[2] > 0.4 ? -*(const double *)user : 0.0;
}

static double ramp(void *user, double t)
{
  (void)user;
  return t < 0.2 ? t / 0.2 : 1.0;
}

static double load_density = 3000.0;

/* The integrator on the C with the lower arm's bottom clamped (the mesh nodes at z < 0.1 with
 * x > 0.3) and the load; contact between bodies with self-contact on or off. */
static fcm_integrator *c_integrator(fcm_ctx *ctx, problem *p, int self, double dhat)
{
  fcm_integrator *I = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = 0.02;
  TEST_OK(ctx, c_problem(p));
  if (!p->space) return NULL;
  TEST_OK(ctx, fcm_integrator_create(ctx, p->space, &mat, &o, &I));
  if (!I) return NULL;
  {
    const fcm_index nn = fcm_mesh_num_nodes(p->mesh);
    const double *X = fcm_mesh_coords(p->mesh);
    fcm_index *nodes = malloc(sizeof(fcm_index) * (size_t)nn), m = 0;
    fcm_motion held = fcm_motion_default();
    for (fcm_index v = 0; v < nn; v++)
      if (X[3 * v + 2] < 0.1 && X[3 * v] > 0.3) nodes[m++] = v;
    TEST_OK(ctx, fcm_integrator_add_constraint(I, m, nodes, &held, NULL));
    free(nodes);
  }
  TEST_OK(ctx, fcm_integrator_add_body_force(I, load, &load_density, ramp, NULL));
  co.distance = dhat;
  co.self_contact = self;
  TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p->geom, &co, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  return I;
}

/* u = shift on the DOFs of the elements whose cells lie in the upper arm's end (centre
 * x > 0.5, z > 0.3), 0 elsewhere. */
static void shift_end(const fcm_space *s, const fcm_mesh *mesh, const double shift[3], double *u)
{
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    double X[3 * 8], xc = 0.0, zc = 0.0;
    fcm_mesh_cell_coords(mesh, fcm_space_element_cell(s, e), X);
    for (int a = 0; a < 8; a++)
      xc += X[3 * a] / 8.0, zc += X[3 * a + 2] / 8.0;
    if (xc < 0.5 || zc < 0.3) continue;
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    for (int a = 0; a < 8; a++)
      for (int i = 0; i < 3; i++)
        u[ed[a] + i] = shift[i];
  }
}

static const sim_contact *bodies_of(const fcm_integrator *I)
{
  for (int c = 0; c < I->num_contacts; c++)
    if (I->contacts[c].kind == SIM_CONTACT_BODIES) return &I->contacts[c];
  return NULL;
}

static int fd(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = c_integrator(ctx, &p, 1, 0.03);
  if (!I) return 0;
  TEST_TRUE(fcm_space_num_bodies(p.space) == 1);
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *u = calloc((size_t)n, sizeof *u), *f = calloc((size_t)n, sizeof *f);
  double *d = calloc((size_t)n, sizeof *d), e = 0.0;
  fcm_csr *T = NULL;
  TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
  /* at rest: every self pair is excluded or beyond the threshold */
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, f, NULL));
  TEST_TRUE(e == 0.0);
  srand(5);
  for (int trial = 0; trial < 3; trial++) {
    /* the end 0.01-0.02 m above the lower arm, shifted sideways */
    const double shift[3] = {-0.02 * trial, 0.0, -0.19 + 0.004 * trial};
    memset(u, 0, sizeof(double) * (size_t)n);
    shift_end(p.space, p.mesh, shift, u);
    for (fcm_index i = 0; i < n; i++)
      u[i] += 1e-3 * rnd();
    memset(f, 0, sizeof(double) * (size_t)n);
    fcm_csr_set_zero(T);
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, f, T));
    fcm_contact_stats cs;
    TEST_OK(ctx, fcm_integrator_set_state(I, u, NULL, 0.0, 0));
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    TEST_TRUE(cs.self_pairs > 0 && cs.self_pairs == cs.body_pairs);
    contact_fd_directions(ctx, I, n, u, f, T, e, trial, "self pairs", cs.self_pairs, rnd);
  }
  {
    /* a step pushing the end 0.1 m down from 0.01 m above the lower arm */
    const double s0[3] = {0, 0, -0.19}, ds[3] = {0, 0, -0.1};
    memset(u, 0, sizeof(double) * (size_t)n);
    memset(d, 0, sizeof(double) * (size_t)n);
    shift_end(p.space, p.mesh, s0, u);
    shift_end(p.space, p.mesh, ds, d);
    I->bc_time = 0.0;
    const double amax = fcm__sim_contact_step_bound(I, u, d);
    printf("step bound %.4g (the end's exact first contact at 0.1)\n", amax);
    TEST_TRUE(amax > 0.0 && amax <= 0.1 + 1e-12);
    for (fcm_index i = 0; i < n; i++)
      u[i] += 0.9 * amax * d[i];
    e = 0.0;
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, NULL, NULL));
    TEST_TRUE(isfinite(e));
    /* a rigid translation of the whole body: no limit */
    for (fcm_index i = 0; i < n; i++)
      d[i] = i % 3 == 2 ? -0.5 : 0.3;
    const double arig = fcm__sim_bodies_step_bound(I, (sim_contact *)bodies_of(I), u, d);
    printf("step bound of a rigid translation %.4g\n", arig);
    TEST_TRUE(arig > 2.0);
  }
  fcm_csr_destroy(&T);
  free(u), free(f), free(d);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* The fold: 30 steps of 0.02 s; the largest self depth (measured with or without the option),
 * the most self pairs, the exclusion tests, the wall time and the samples. */
static void fold_run(fcm_ctx *ctx, int self, int verbose, double *depth, long long *pairs,
                     long long *tests, double *seconds, fcm_index *samples)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = c_integrator(ctx, &p, self, 0.0);
  *depth = 0.0, *pairs = 0, *tests = 0, *seconds = 0.0, *samples = 0;
  if (!I) return;
  const sim_contact *c = bodies_of(I);
  *samples = fcm__sim_bodies_samples(c, NULL);
  const double t0 = fcm_wtime();
  double measure = 0.0;
  for (int s = 0; s < 30; s++) {
    fcm_step_info info;
    fcm_contact_stats cs;
    long long sp = 0;
    double dep = 0.0, where[3] = {0, 0, 0};
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    if (fcm_ctx_error_status(ctx) != FCM_OK) break;
    const double t1 = fcm_wtime();
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    TEST_OK(ctx,
            fcm__sim_bodies_self_stats(I, c, fcm_integrator_displacement(I), &sp, &dep, where));
    measure += fcm_wtime() - t1;
    if (verbose)
      printf("step %d: %d Newton, %d halvings, self pairs %lld, depth %.3g m at (%.3g, %.3g, "
             "%.3g), smallest distance %.3g m\n",
             s, info.newton_iterations, info.halvings, cs.self_pairs, dep, where[0], where[1],
             where[2], cs.min_distance);
    *depth = fmax(*depth, dep);
    *pairs = cs.self_pairs > *pairs ? cs.self_pairs : *pairs;
    *tests = cs.self_tests;
    if (self && !(cs.self_depth == dep)) TEST_FAIL_("stats' self depth %.3g", cs.self_depth);
  }
  *seconds = fcm_wtime() - t0 - measure;
  fcm_integrator_destroy(&I);
  problem_free(&p);
}

static int fold(fcm_ctx *ctx)
{
  const int verbose = getenv("FCM_TEST_VERBOSE") != NULL;
  double depth[2], sec[2];
  long long pairs[2], tests[2];
  fcm_index ns = 0;
  for (int self = 1; self >= 0; self--) {
    fold_run(ctx, self, verbose, &depth[self], &pairs[self], &tests[self], &sec[self], &ns);
    printf("fold, self-contact %s: largest depth of a sample inside the body %.3g m, most self "
           "pairs %lld, %lld exclusion tests, %.3g s\n",
           self ? "on" : "off", depth[self], pairs[self], tests[self], sec[self]);
  }
  if (!(depth[1] <= 1e-6)) TEST_FAIL_("with self-contact a sample got %.3g m inside", depth[1]);
  if (!(pairs[1] > 0)) TEST_FAIL_("with self-contact the arms never met");
  if (!(depth[0] > 0.01)) TEST_FAIL_("without self-contact the arms did not pass: %.3g", depth[0]);
  TEST_TRUE(pairs[0] == 0 && tests[0] == 0);
  return 0;
}

static int cost(fcm_ctx *ctx)
{
  double depth[2], sec[2];
  long long pairs[2], tests[2];
  fcm_index ns = 0;
  const double full = load_density;
  for (int light = 1; light >= 0; light--) {
    /* a third of the load: the arms never come within the threshold, the difference is the
     * self-contact's search alone */
    load_density = light ? full / 3.0 : full;
    for (int self = 1; self >= 0; self--)
      fold_run(ctx, self, 0, &depth[self], &pairs[self], &tests[self], &sec[self], &ns);
    printf("fold, load %g N/m^3: %lld samples, most self pairs %lld; 30 steps %.3g s with "
           "self-contact, %.3g s without (%.3g ms per step, %.3g us per sample point and "
           "step); %lld exclusion tests\n",
           load_density, (long long)ns, pairs[1], sec[1], sec[0], 1e3 * (sec[1] - sec[0]) / 30,
           1e6 * (sec[1] - sec[0]) / 30 / (double)(ns > 0 ? ns : 1), tests[1]);
  }
  load_density = full;
  for (int self = 0; self < 2; self++) {
    /* one evaluation in the folded state of the fd mode, per sample point */
    problem p = {ctx, NULL, NULL, NULL, NULL};
    fcm_integrator *I = c_integrator(ctx, &p, self, 0.03);
    if (!I) return 0;
    const fcm_index n = fcm_space_num_dofs(p.space);
    const double shift[3] = {0, 0, -0.19};
    double *u = calloc((size_t)n, sizeof *u), *f = calloc((size_t)n, sizeof *f), e = 0.0;
    fcm_csr *T = NULL;
    TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
    shift_end(p.space, p.mesh, shift, u);
    const int reps = 50;
    const double t0 = fcm_wtime();
    for (int r = 0; r < reps; r++)
      TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, f, T));
    const double dt = (fcm_wtime() - t0) / reps;
    const fcm_index s = fcm__sim_bodies_samples(bodies_of(I), NULL);
    printf("one evaluation (energy, force, Newton matrix), self-contact %s: %.3g ms, %.3g us "
           "per sample point\n",
           self ? "on" : "off", 1e3 * dt, 1e6 * dt / (double)s);
    fcm_csr_destroy(&T);
    free(u), free(f);
    fcm_integrator_destroy(&I);
    problem_free(&p);
  }
  return 0;
}

/* A scene of a box with the effects %s. */
#define SCENE                                                                                      \
  "{\"version\": 1, \"name\": \"s\", \"background\": {\"element\": \"hex8\", \"box\": "            \
  "{\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]}, \"geometry\": {\"shape\": "    \
  "\"box\", \"min\": [0.1, 0.1, 0.1], \"max\": [0.9, 0.9, 0.9], \"cells\": [2, 2, 2]}, "           \
  "\"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3}, \"time\": {\"dt\": "      \
  "0.01, \"duration\": 0.03}, \"effects\": [%s]}"

static int errors(fcm_ctx *ctx)
{
  fcm_integrator *I = NULL;
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  fcm_contact_options co = fcm_contact_options_default();
  const double q[3] = {0, 0, -0.1}, nz[3] = {0, 0, 1};
  TEST_OK(ctx, c_problem(&p));
  TEST_OK(ctx, fcm_integrator_create(ctx, p.space, &mat, &o, &I));
  if (!I) return 0;
  TEST_TRUE(co.self_contact == 0);
  co.self_contact = 1;
  TEST_ERR(ctx, fcm_integrator_add_contact_plane(I, q, nz, NULL, &co, NULL), FCM_ERR_ARG,
           "self_contact");
  co.self_contact = 2;
  TEST_ERR(ctx, fcm_integrator_add_contact_bodies(I, p.geom, &co, NULL), FCM_ERR_ARG,
           "self_contact");
  co.self_contact = 1;
  TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p.geom, &co, NULL));
  fcm_integrator_destroy(&I);
  problem_free(&p);
  /* the scene key: with "bodies" only, a boolean; kept by the normalized scene */
  {
    static const char *const bad[][2] = {
        {"{\"contact\": {\"plane\": {\"point\": [0, 0, -1], \"normal\": [0, 0, 1]}, "
         "\"self\": true}}",
         "self"},
        {"{\"contact\": {\"bodies\": true, \"self\": 1}}", "self"}};
    char json[2048];
    fcm_scene *scene = NULL, *again = NULL;
    for (int k = 0; k < 2; k++) {
      snprintf(json, sizeof json, SCENE, bad[k][0]);
      TEST_ERR(ctx, fcm_scene_create_from_string(ctx, json, "s.json", &scene), FCM_ERR_ARG,
               bad[k][1]);
      fcm_scene_destroy(&scene);
    }
    snprintf(json, sizeof json, SCENE, "{\"contact\": {\"bodies\": true, \"self\": true}}");
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "s.json", &scene));
    if (scene) {
      const char *norm = fcm_scene_json(scene);
      TEST_TRUE(strstr(norm, "\"self\"") != NULL);
      TEST_OK(ctx, fcm_scene_create_from_string(ctx, norm, "s.json", &again));
      if (again) TEST_TRUE(!strcmp(norm, fcm_scene_json(again)));
      TEST_TRUE(fcm_scene_num_effects(scene) == 1);
    }
    fcm_scene_destroy(&again);
    fcm_scene_destroy(&scene);
  }
  return 0;
}

int main(int argc, char **argv)
{
  fcm_ctx *ctx = NULL;
  TEST_TRUE(argc > 1);
  if (argc < 2) return TEST_RESULT();
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  if (argc > 2) load_density = atof(argv[2]);
  if (!strcmp(argv[1], "fd"))
    fd(ctx);
  else if (!strcmp(argv[1], "fold"))
    fold(ctx);
  else if (!strcmp(argv[1], "cost"))
    cost(ctx);
  else if (!strcmp(argv[1], "errors"))
    errors(ctx);
  else
    TEST_FAIL_("unknown mode %s", argv[1]);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
