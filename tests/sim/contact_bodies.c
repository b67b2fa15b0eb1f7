/* Contact between bodies and between the pieces of a cut (fcm_integrator_add_contact_bodies()),
 * by mode:
 *   fd       two separate boxes (no cell holds both) pushed to within the threshold of each
 *            other with a random displacement: central differences of the barrier energy
 *            match its force (relative error <= 1e-6) along random directions, the Newton
 *            matrix is symmetric and positive semidefinite along them, and a step that would
 *            push one box through the other is cut short to a fraction that keeps every pair
 *            apart (the energy there finite); one box sunk 0.01 m into the other is measured
 *            0.01 m deep
 *   stack    the upper box falls under gravity onto the lower one, which rests on a floor
 *            (backward Euler): at every step no surface sample lies inside the other box
 *            (depth <= 1e-6 m) or reaches distance 0, the boxes touch, and the energy (kinetic
 *            + elastic + barrier - work of gravity) never grows by more than 1e-6 of the work
 *   dice <scenes>  apps/scenes/dice_on_floor.json (a cube cut into 36 sticks, spun and dropped
 *            onto a floor, contact between the pieces): at every step every surface point stays
 *            above the floor (also at the ends of the step's substeps: step_min_distance > 0)
 *            and no sample lies inside another stick by more than 1e-3 m, the
 *            sticks reach the floor (closer than half its threshold) and meet each other, and
 *            the energy never exceeds its start by more than 1e-3 of the work of gravity
 *   rest <scenes>  apps/scenes/cut_bar_resting.json (a bar cut along its length, dropped onto a
 *            floor: the upper half lands on the lower one): at every step the upper half lies
 *            at most 5e-3 m deep in the lower one and every point above the floor; at the end
 *            the bar rests (centre-of-mass velocity below 0.01 m/s), the energy never grew by
 *            more than 1e-3 of the work of gravity, and the force of the contact (barrier and
 *            the penalty of the halves that started in contact) matches differences of its
 *            energy (relative error <= 1e-6)
 *   cost <scenes>  not asserted (lib/docs/contact.md): the BVH's build and refit over random
 *            boxes; on dice_on_floor.json after the landing, one evaluation of the contact terms
 *            (energy, force, Newton matrix) per sample point, and the step time with and without
 *            the contact between the pieces
 *   errors   bad "bodies" input in a scene (false, negative friction) refused naming the field; a
 *            second call and a NULL geometry refused; a scene with obstacles only builds no
 *            search tree and evaluates no pair (counters zero) */
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

/* Box A = [0.1, 0.9]^2 x [0.05, 0.2] and B = [0.3, 0.7]^2 x [0.55, 0.8] on 4^3 Hex8 cells over
 * [0, 1]^3: the cell layer z in [0.25, 0.5] is empty, so they share no DOF. */
static fcm_status boxes_problem(problem *p)
{
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  const double alo[3] = {0.1, 0.1, 0.05}, ahi[3] = {0.9, 0.9, 0.2};
  const double blo[3] = {0.3, 0.3, 0.55}, bhi[3] = {0.7, 0.7, 0.8};
  const fcm_index cells[3] = {4, 4, 4};
  fcm_cell_rules_options ro = fcm_cell_rules_options_default();
  const fcm_index n[3] = {2, 2, 1};
  fcm_status st = merged_boxes(p->ctx, alo, ahi, blo, bhi, n, &p->geom);
  if (st == FCM_OK) st = fcm_mesh_create_box(p->ctx, FCM_ELEMENT_HEX8, lo, hi, cells, &p->mesh);
  ro.surface_strength = 2;
  ro.min_fraction = 1e-4;
  if (st == FCM_OK) st = fcm_cell_rules_create(p->ctx, p->mesh, p->geom, &ro, &p->rules);
  if (st == FCM_OK) st = fcm_space_create_embedded(p->ctx, p->mesh, p->rules, &p->space);
  return st;
}

/* u = shift on the DOFs of the elements in cells above z = 0.5 (box B), 0 elsewhere. */
static void shift_upper(const fcm_space *s, const fcm_mesh *mesh, const double shift[3], double *u)
{
  for (fcm_index e = 0; e < fcm_space_num_elements(s); e++) {
    double X[3 * 8], zc = 0.0;
    fcm_mesh_cell_coords(mesh, fcm_space_element_cell(s, e), X);
    for (int a = 0; a < 8; a++)
      zc += X[3 * a + 2] / 8.0;
    if (zc < 0.5) continue;
    const fcm_index *ed = fcm_space_element_dofs(s, e);
    for (int a = 0; a < 8; a++)
      for (int i = 0; i < 3; i++)
        u[ed[a] + i] = shift[i];
  }
}

static void mon(void *user, const fcm_newton_event *ev)
{
  (void)user;
  if (getenv("FCM_TEST_NEWTON"))
    printf("  t %.3f it %d r %.3e tol %.3e E %.9e alpha %.3e lin %d\n", ev->time, ev->iteration,
           ev->residual, ev->tolerance, ev->energy, ev->step_length, ev->linear_iterations);
}

static fcm_integrator *boxes_integrator(fcm_ctx *ctx, problem *p, double dt)
{
  fcm_integrator *I = NULL;
  fcm_material mat = {FCM_MATERIAL_STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0};
  fcm_integrator_options o = fcm_integrator_options_default();
  o.kind = FCM_INTEGRATOR_BACKWARD_EULER;
  o.dt = dt;
  o.monitor = mon;
  TEST_OK(ctx, boxes_problem(p));
  TEST_OK(ctx, fcm_integrator_create(ctx, p->space, &mat, &o, &I));
  return I;
}

static int fd(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = boxes_integrator(ctx, &p, 0.02);
  fcm_contact_options co = fcm_contact_options_default();
  co.distance = 0.03;
  TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p.geom, &co, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  TEST_TRUE(fcm_space_num_bodies(p.space) == 2);
  const fcm_index n = fcm_space_num_dofs(p.space);
  double *u = calloc((size_t)n, sizeof *u), *f = calloc((size_t)n, sizeof *f);
  double *d = calloc((size_t)n, sizeof *d), e = 0.0;
  fcm_csr *T = NULL;
  TEST_OK(ctx, fcm_space_matrix_create(p.space, &T));
  /* at rest, 0.35 m apart: nothing within the threshold, and no piece ignores another */
  TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, f, NULL));
  TEST_TRUE(e == 0.0);
  srand(7);
  int pairs_seen = 0;
  for (int trial = 0; trial < 4; trial++) {
    /* B 0.01-0.02 m above A, shifted sideways so that its edges and corners meet A's faces */
    const double shift[3] = {0.05 * trial, -0.03 * trial, -0.35 + 0.01 + 0.003 * trial};
    memset(u, 0, sizeof(double) * (size_t)n);
    shift_upper(p.space, p.mesh, shift, u);
    for (fcm_index i = 0; i < n; i++)
      u[i] += 1e-3 * rnd();
    memset(f, 0, sizeof(double) * (size_t)n);
    fcm_csr_set_zero(T);
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, f, T));
    fcm_contact_stats cs;
    TEST_OK(ctx, fcm_integrator_set_state(I, u, NULL, 0.0, 0));
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    pairs_seen += cs.body_pairs > 0;
    contact_fd_directions(ctx, I, n, u, f, T, e, trial, "pairs", cs.body_pairs, rnd);
  }
  TEST_TRUE(pairs_seen == 4);
  {
    /* B sunk 0.01 m into A: the depth measure sees it */
    const double sunk[3] = {0, 0, -0.36};
    fcm_contact_stats cs;
    memset(u, 0, sizeof(double) * (size_t)n);
    shift_upper(p.space, p.mesh, sunk, u);
    TEST_OK(ctx, fcm_integrator_set_state(I, u, NULL, 0.0, 0));
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    printf("sunk 0.01 m: depth %.6g m\n", cs.body_depth);
    TEST_NEAR(cs.body_depth, 0.01, 1e-9, 0.0);
  }
  {
    /* a step pushing B 0.1 m down through A from 0.01 m above it */
    const double s0[3] = {0, 0, -0.34}, ds[3] = {0, 0, -0.1};
    memset(u, 0, sizeof(double) * (size_t)n);
    memset(d, 0, sizeof(double) * (size_t)n);
    shift_upper(p.space, p.mesh, s0, u);
    shift_upper(p.space, p.mesh, ds, d);
    I->bc_time = 0.0;
    const double amax = fcm__sim_contact_step_bound(I, u, d);
    printf("step bound %.4g (exact first contact at 0.1)\n", amax);
    TEST_TRUE(amax > 0.0 && amax <= 0.1 + 1e-12);
    for (fcm_index i = 0; i < n; i++)
      u[i] += 0.9 * amax * d[i];
    e = 0.0;
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, 0.0, &e, NULL, NULL));
    TEST_TRUE(isfinite(e));
  }
  fcm_csr_destroy(&T);
  free(u), free(f), free(d);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

static int stack(fcm_ctx *ctx)
{
  problem p = {ctx, NULL, NULL, NULL, NULL};
  fcm_integrator *I = boxes_integrator(ctx, &p, 0.02);
  const double g[3] = {0, 0, -9.81}, q[3] = {0, 0, 0.0}, nz[3] = {0, 0, 1};
  TEST_OK(ctx, fcm_integrator_add_gravity(I, g, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_plane(I, q, nz, NULL, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p.geom, NULL, NULL));
  TEST_OK(ctx, fcm_integrator_setup(I));
  double e0 = 0.0, emax = -HUGE_VAL, wmax = 0.0, depth = 0.0, dfloor = HUGE_VAL, dbody = HUGE_VAL;
  long long touched = 0;
  const double t0 = fcm_wtime();
  for (int s = 0; s < 50; s++) {
    fcm_step_info info;
    fcm_contact_stats cs;
    double d0 = 0.0, d1 = 0.0;
    TEST_OK(ctx, fcm_integrator_step(I, &info));
    if (fcm_ctx_error_status(ctx) != FCM_OK) break;
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, NULL, &d0, NULL, NULL));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 1, NULL, &d1, NULL, NULL));
    if (getenv("FCM_TEST_VERBOSE"))
      printf("step %d: %d Newton, %d backtracks, %d halvings, %lld pairs, d %.3g %.3g\n", s,
             info.newton_iterations, info.line_search_backtracks, info.halvings, cs.body_pairs, d0,
             d1);
    const double E = info.total_energy + cs.barrier_energy;
    if (s == 0) e0 = E;
    emax = fmax(emax, E);
    wmax = fmax(wmax, fabs(info.load_work));
    depth = fmax(depth, cs.body_depth);
    dfloor = fmin(dfloor, d0);
    dbody = fmin(dbody, d1);
    touched += cs.body_pairs > 0;
  }
  const double dt = fcm_wtime() - t0;
  fcm_contact_stats cs;
  TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
  printf("stack: 50 steps in %.3g s; smallest distance to the floor %.4g m, between the boxes "
         "%.4g m; largest depth %.3g m; %lld steps in contact; energy growth %.3g J (work %.4g "
         "J); %lld tree builds and refits\n",
         dt, dfloor, dbody, depth, touched, emax - e0, wmax, cs.tree_builds);
  if (!(dfloor > 0.0 && dbody > 0.0)) TEST_FAIL_("distance reached %.3g, %.3g", dfloor, dbody);
  if (!(depth <= 1e-6)) TEST_FAIL_("a sample got %.3g m inside the other box", depth);
  TEST_TRUE(touched > 0);
  if (!(emax - e0 <= 1e-6 * wmax)) TEST_FAIL_("energy grew by %.3g J", emax - e0);
  fcm_integrator_destroy(&I);
  problem_free(&p);
  return 0;
}

/* DIR/NAME as a scene and its simulation; both NULL (the failure recorded) when either fails. */
static void open_scene(fcm_ctx *ctx, const char *dir, const char *name, fcm_scene **scene,
                       fcm_simulation **sim)
{
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  *scene = NULL, *sim = NULL;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, scene));
  if (*scene) TEST_OK(ctx, fcm_simulation_create(ctx, *scene, NULL, sim));
  if (!*sim) fcm_scene_destroy(scene);
}

static int dice(fcm_ctx *ctx, const char *dir)
{
  fcm_scene *scene;
  fcm_simulation *sim;
  open_scene(ctx, dir, "dice_on_floor.json", &scene, &sim);
  if (!sim) return 0;
  double e0 = 0.0, emax = -HUGE_VAL, wmax = 0.0, depth = 0.0, dfloor = HUGE_VAL, dstep = HUGE_VAL;
  long long pairs = 0;
  int steps = 0;
  const double t0 = fcm_wtime();
  while (!fcm_simulation_done(sim)) {
    fcm_step_info info;
    fcm_contact_stats cs;
    double d0 = 0.0;
    TEST_OK(ctx, fcm_simulation_step(sim, &info));
    if (fcm_ctx_error_status(ctx) != FCM_OK) break;
    fcm_integrator *I = fcm_simulation_integrator(sim);
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, NULL, &d0, NULL, NULL));
    const double E = info.total_energy + cs.barrier_energy;
    if (steps++ == 0) e0 = E;
    emax = fmax(emax, E);
    wmax = fmax(wmax, fabs(info.load_work));
    depth = fmax(depth, cs.body_depth);
    dfloor = fmin(dfloor, d0);
    dstep = fmin(dstep, cs.step_min_distance); /* every substep's state, floor and pieces */
    pairs = cs.body_pairs > pairs ? cs.body_pairs : pairs;
  }
  double dhat = 0.0;
  TEST_OK(ctx,
          fcm_integrator_contact_info(fcm_simulation_integrator(sim), 0, NULL, NULL, &dhat, NULL));
  fcm_simulation_counters c;
  fcm_simulation_get_counters(sim, &c);
  printf("dice: %d steps in %.3g s, %lld pieces; smallest distance to the floor %.4g m; largest "
         "depth inside another piece %.3g m; most pairs between pieces %lld; energy growth "
         "%.4g J (work of gravity up to %.4g J)\n",
         steps, fcm_wtime() - t0, (long long)c.pieces, dfloor, depth, pairs, emax - e0, wmax);
  TEST_TRUE(c.pieces == 36);
  if (!(dfloor > 0.0)) TEST_FAIL_("a surface point reached the floor: %.3g m", dfloor);
  if (!(dstep > 0.0 && dstep <= dfloor))
    TEST_FAIL_("the substeps' smallest distance %.3g m: not in (0, %.3g]", dstep, dfloor);
  if (!(dfloor < 0.5 * dhat)) TEST_FAIL_("the sticks never reached the floor (%.3g m)", dfloor);
  if (!(pairs > 0)) TEST_FAIL_("the sticks never met each other");
  if (!(depth <= 1e-3)) TEST_FAIL_("a sample got %.3g m inside another stick", depth);
  if (!(emax - e0 <= 1e-3 * wmax)) TEST_FAIL_("energy grew by %.3g J", emax - e0);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return 0;
}

/* apps/scenes/cut_bar_resting.json: the upper half of a cut bar lands on the lower one and
 * rests; the sides of the cut start in contact, so the penalty on the lagged gap holds it. */
static int rest(fcm_ctx *ctx, const char *dir)
{
  fcm_scene *scene;
  fcm_simulation *sim;
  open_scene(ctx, dir, "cut_bar_resting.json", &scene, &sim);
  if (!sim) return 0;
  double depth = 0.0, dfloor = HUGE_VAL, e0 = 0.0, emax = -HUGE_VAL, wmax = 0.0, vz = 0.0;
  int steps = 0;
  while (!fcm_simulation_done(sim)) {
    fcm_step_info info;
    fcm_contact_stats cs;
    double d0 = 0.0;
    TEST_OK(ctx, fcm_simulation_step(sim, &info));
    if (fcm_ctx_error_status(ctx) != FCM_OK) break;
    fcm_integrator *I = fcm_simulation_integrator(sim);
    TEST_OK(ctx, fcm_integrator_contact_stats(I, &cs));
    TEST_OK(ctx, fcm_integrator_contact_info(I, 0, NULL, &d0, NULL, NULL));
    const double E = info.total_energy + cs.barrier_energy;
    if (steps++ == 0) e0 = E;
    emax = fmax(emax, E);
    wmax = fmax(wmax, fabs(info.load_work));
    depth = fmax(depth, cs.body_depth);
    dfloor = fmin(dfloor, d0);
    if (getenv("FCM_TEST_VERBOSE"))
      printf("step %d: depth %.3g m, floor %.4g m, pairs %lld, barrier + penalty %.4g J\n", steps,
             cs.body_depth, d0, cs.body_pairs, cs.barrier_energy);
  }
  {
    /* the centre-of-mass velocity of the whole bar at the end */
    fcm_integrator *I = fcm_simulation_integrator(sim);
    const fcm_index n = fcm_integrator_num_dofs(I);
    const fcm_csr *M = fcm_integrator_mass(I);
    double *ez = calloc((size_t)n, sizeof *ez), *w = calloc((size_t)n, sizeof *w), m = 0.0;
    for (fcm_index i = 0; i < n; i++)
      ez[i] = i % 3 == 2 ? 1.0 : 0.0;
    TEST_OK(ctx, fcm_csr_apply(M, 1.0, ez, 0.0, w));
    for (fcm_index i = 0; i < n; i++) {
      m += ez[i] * w[i];
      vz += fcm_integrator_velocity(I)[i] * w[i];
    }
    vz /= m;
    /* the lagged penalty's force against differences of its energy */
    double *u = malloc(sizeof(double) * (size_t)n), *f = calloc((size_t)n, sizeof *f);
    double *d = malloc(sizeof(double) * (size_t)n), e = 0.0, ee = 0.0, et = 0.0;
    const double t = fcm_integrator_time(I);
    fcm_integrator_get_state(I, u, NULL, NULL, NULL);
    TEST_OK(ctx, fcm_integrator_contact_eval(I, u, t, &e, f, NULL));
    srand(11);
    for (fcm_index i = 0; i < n; i++)
      d[i] = (double)rand() / RAND_MAX - 0.5;
    contact_fd(ctx, I, n, u, d, t, 1e-8, f, NULL, &ee, &et);
    printf("rest: contact energy %.6g J at the end, force against differences %.3g\n", e, ee);
    if (!(ee <= 1e-6)) TEST_FAIL_("force against differences: relative error %.3g", ee);
    free(ez), free(w), free(u), free(f), free(d);
  }
  printf("rest: %d steps; largest depth of the upper half in the lower %.3g m; smallest distance "
         "to the floor %.4g m; final centre-of-mass velocity %.3g m/s; energy growth %.3g J\n",
         steps, depth, dfloor, vz, emax - e0);
  if (!(depth <= 5e-3)) TEST_FAIL_("the upper half sank %.3g m into the lower", depth);
  if (!(dfloor > 0.0)) TEST_FAIL_("a surface point reached the floor: %.3g m", dfloor);
  if (!(fabs(vz) < 0.01)) TEST_FAIL_("the bar does not rest: vz = %.3g m/s", vz);
  if (!(emax - e0 <= 1e-3 * wmax)) TEST_FAIL_("energy grew by %.3g J", emax - e0);
  fcm_simulation_destroy(&sim);
  fcm_scene_destroy(&scene);
  return 0;
}

/* The wall time of a run of `scene` (steps and set-up), its steps, and in *per_sample the time
 * of one contact evaluation per sample point at the end (with bodies only). */
static double run_time(fcm_ctx *ctx, fcm_scene *scene, int *steps, double *per_sample,
                       fcm_index *samples, fcm_index *tris)
{
  fcm_simulation *sim = NULL;
  double dt = 0.0;
  *steps = 0;
  TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
  if (!sim) return 0.0;
  const double t0 = fcm_wtime();
  while (!fcm_simulation_done(sim)) {
    fcm_step_info info;
    TEST_OK(ctx, fcm_simulation_step(sim, &info));
    if (fcm_ctx_error_status(ctx) != FCM_OK) break;
    (*steps)++;
  }
  dt = fcm_wtime() - t0;
  fcm_integrator *I = fcm_simulation_integrator(sim);
  *per_sample = 0.0;
  for (int c = 0; c < I->num_contacts; c++) {
    if (I->contacts[c].kind != SIM_CONTACT_BODIES) continue;
    const fcm_index n = fcm_space_num_dofs(fcm_simulation_space(sim));
    double *f = calloc((size_t)n, sizeof *f), e = 0.0;
    fcm_csr *T = NULL;
    TEST_OK(ctx, fcm_space_matrix_create(fcm_simulation_space(sim), &T));
    *samples = fcm__sim_bodies_samples(&I->contacts[c], tris);
    const int reps = 50;
    const double t1 = fcm_wtime();
    for (int k = 0; k < reps; k++) {
      int finite = 1;
      e = 0.0;
      fcm__sim_bodies_assemble(I, &I->contacts[c], I->u, &e, f, T, &finite);
    }
    *per_sample = (fcm_wtime() - t1) / reps / (double)*samples;
    fcm_csr_destroy(&T);
    free(f);
  }
  fcm_simulation_destroy(&sim);
  return dt;
}

static int cost(fcm_ctx *ctx, const char *dir)
{
  char path[1024];
  fcm_scene *with = NULL, *without = NULL;
  for (int k = 0; k < 2; k++) { /* the BVH alone: build and refit over n random boxes */
    const fcm_index n = k ? 20000 : 1584;
    double *boxes = malloc(sizeof(double) * 6 * (size_t)n);
    fcm_index *group = calloc((size_t)n, sizeof *group);
    sim_bvh T;
    memset(&T, 0, sizeof T);
    srand(3);
    for (fcm_index i = 0; i < n; i++)
      for (int d = 0; d < 3; d++) {
        const double c = (double)rand() / RAND_MAX, w = 0.02 * (double)rand() / RAND_MAX;
        boxes[6 * i + d] = c - w;
        boxes[6 * i + 3 + d] = c + w;
      }
    const int reps = 200;
    double t0 = fcm_wtime();
    for (int r = 0; r < reps; r++)
      TEST_OK(ctx, fcm__sim_bvh_build(ctx, &T, n, group, 1, boxes));
    const double tb = (fcm_wtime() - t0) / reps;
    t0 = fcm_wtime();
    for (int r = 0; r < reps; r++)
      fcm__sim_bvh_refit(&T, boxes);
    const double tr = (fcm_wtime() - t0) / reps;
    printf("bvh over %lld boxes: build %.3g ms, refit %.3g ms\n", (long long)n, 1e3 * tb, 1e3 * tr);
    fcm__sim_bvh_free(ctx, &T);
    free(boxes), free(group);
  }
  snprintf(path, sizeof path, "%s/dice_on_floor.json", dir);
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, path, &with));
  {
    /* without: the same scene without its "bodies" effect */
    static const char key[] = "{\"contact\": {\"bodies\": true, \"distance\": 0.02}},";
    FILE *f = fopen(path, "rb");
    char *text = calloc(1 << 16, 1), *at = NULL;
    if (f) {
      size_t len = fread(text, 1, (1 << 16) - 1, f);
      text[len] = 0;
      fclose(f);
    }
    at = strstr(text, key);
    TEST_TRUE(at != NULL);
    if (at) memmove(at, at + strlen(key), strlen(at + strlen(key)) + 1);
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, text, path, &without));
    free(text);
  }
  if (with && without) {
    int s1 = 0, s0 = 0;
    fcm_index ns = 0, nt = 0, ns0 = 0, nt0 = 0;
    double ps = 0.0, ps0 = 0.0;
    const double t1 = run_time(ctx, with, &s1, &ps, &ns, &nt);
    const double t0 = run_time(ctx, without, &s0, &ps0, &ns0, &nt0);
    printf("dice_on_floor: %lld samples on %lld triangles; one evaluation of the contact "
           "between the pieces (energy, force, Newton matrix) %.3g us per sample point after "
           "the landing; %d steps %.3g s with it, %.3g s without (%.3g ms per step, %.3g us per "
           "sample point and step)\n",
           (long long)ns, (long long)nt, 1e6 * ps, s1, t1, t0, 1e3 * (t1 - t0) / s1,
           1e6 * (t1 - t0) / s1 / (double)(ns > 0 ? ns : 1));
  }
  fcm_scene_destroy(&with);
  fcm_scene_destroy(&without);
  return 0;
}

/* A scene of a box (cut in two at x = 0.5) with the given contact effects. */
static void cut_scene(char *out, size_t len, const char *contact)
{
  snprintf(out, len,
           "{\"version\": 1, \"name\": \"c\","
           " \"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0],"
           "   \"max\": [1, 1, 1]}, \"cells\": [2, 2, 2]},"
           " \"geometry\": {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [1, 1, 1],"
           "   \"cells\": [2, 2, 2]},"
           " \"material\": {\"model\": \"snh\", \"young\": 1e6, \"poisson\": 0.3},"
           " \"time\": {\"dt\": 0.01, \"duration\": 0.03},"
           " \"effects\": [{\"gravity\": {}}, %s"
           "   {\"cut\": {\"surface\": {\"plane\": {\"point\": [0.5, 0.5, 0.5],"
           "     \"normal\": [1, 0, 0]}}}}]}",
           contact);
}

static int errors(fcm_ctx *ctx)
{
  char json[4096];
  fcm_scene *scene = NULL;
  fcm_simulation *sim = NULL;
  cut_scene(json, sizeof json, "{\"contact\": {\"bodies\": false}},");
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene), FCM_ERR_ARG, "bodies");
  fcm_scene_destroy(&scene);
  cut_scene(json, sizeof json, "{\"contact\": {\"bodies\": 1}},");
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene), FCM_ERR_ARG, "bodies");
  fcm_scene_destroy(&scene);
  cut_scene(json, sizeof json, "{\"contact\": {\"bodies\": true, \"friction\": -0.3}},");
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene), FCM_ERR_ARG, "friction");
  fcm_scene_destroy(&scene);
  cut_scene(json, sizeof json, "{\"contact\": {\"bodies\": true, \"distance\": -1}},");
  TEST_ERR(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene), FCM_ERR_ARG, "distance");
  fcm_scene_destroy(&scene);
  /* the library: NULL geometry, a second call, friction */
  {
    problem p = {ctx, NULL, NULL, NULL, NULL};
    fcm_integrator *I = boxes_integrator(ctx, &p, 0.02);
    fcm_contact_options co = fcm_contact_options_default();
    TEST_ERR(ctx, fcm_integrator_add_contact_bodies(I, NULL, NULL, NULL), FCM_ERR_ARG,
             "NULL geometry");
    co.friction = -0.2;
    TEST_ERR(ctx, fcm_integrator_add_contact_bodies(I, p.geom, &co, NULL), FCM_ERR_ARG, "friction");
    TEST_OK(ctx, fcm_integrator_add_contact_bodies(I, p.geom, NULL, NULL));
    TEST_ERR(ctx, fcm_integrator_add_contact_bodies(I, p.geom, NULL, NULL), FCM_ERR_ARG,
             "already on");
    fcm_integrator_destroy(&I);
    problem_free(&p);
  }
  /* the cut box on a floor without "bodies": no tree, no pair; with it: trees and pieces */
  for (int on = 0; on < 2; on++) {
    cut_scene(json, sizeof json,
              on ? "{\"contact\": {\"plane\": {\"point\": [0, 0, -0.1], \"normal\": [0, 0, 1]}}},"
                   " {\"contact\": {\"bodies\": true}},"
                 : "{\"contact\": {\"plane\": {\"point\": [0, 0, -0.1], \"normal\": [0, 0, 1]}}},");
    TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "c.json", &scene));
    if (scene) TEST_OK(ctx, fcm_simulation_create(ctx, scene, NULL, &sim));
    if (sim) {
      fcm_contact_stats cs;
      while (!fcm_simulation_done(sim)) {
        fcm_step_info info;
        TEST_OK(ctx, fcm_simulation_step(sim, &info));
        if (fcm_ctx_error_status(ctx) != FCM_OK) break;
      }
      TEST_OK(ctx, fcm_integrator_contact_stats(fcm_simulation_integrator(sim), &cs));
      printf("cut box, bodies %s: %lld tree builds and refits, %lld pairs\n", on ? "on" : "off",
             cs.tree_builds, cs.body_pairs);
      if (on)
        TEST_TRUE(cs.tree_builds > 0);
      else
        TEST_TRUE(cs.tree_builds == 0 && cs.body_pairs == 0 && cs.body_depth == 0.0);
    }
    fcm_simulation_destroy(&sim);
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
  if (!strcmp(argv[1], "fd"))
    fd(ctx);
  else if (!strcmp(argv[1], "stack"))
    stack(ctx);
  else if (!strcmp(argv[1], "dice") && argc > 2)
    dice(ctx, argv[2]);
  else if (!strcmp(argv[1], "rest") && argc > 2)
    rest(ctx, argv[2]);
  else if (!strcmp(argv[1], "cost") && argc > 2)
    cost(ctx, argv[2]);
  else if (!strcmp(argv[1], "errors"))
    errors(ctx);
  else
    TEST_FAIL_("unknown mode %s", argv[1]);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
