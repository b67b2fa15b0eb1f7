/* Parsing: a scene setting every key lands every value in its field; a minimal scene gets
 * the documented defaults; relative file names resolve against the scene's directory;
 * the motion, initial-velocity and region formulas satisfy their geometric identities. */
#include "scene_util.h"
#include "la/vec3.h"

#include <math.h>
#include <sys/stat.h>

static void check_vec(const double *got, double x, double y, double z)
{
  TEST_NEAR(got[0], x, 1e-15, 1e-15);
  TEST_NEAR(got[1], y, 1e-15, 1e-15);
  TEST_NEAR(got[2], z, 1e-15, 1e-15);
}

static void check_full(fcm_ctx *ctx)
{
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, full_scene_json, "full.json", &s));
  if (!s) return;
  TEST_TRUE(!strcmp(fcm_scene_name(s), "full-scene.v1"));
  TEST_TRUE(!strcmp(fcm_scene_description(s), "every key set"));
  TEST_TRUE(!strcmp(fcm_scene_source(s), "full.json"));
  check_normalized(ctx, s, "the scene of every key");

  const fcm_scene_background *b = fcm_scene_get_background(s);
  TEST_TRUE(b->kind == FCM_SCENE_BACKGROUND_GRID && b->element == FCM_ELEMENT_TET10);
  check_vec(b->min, -1, -2, -3);
  check_vec(b->max, 4, 5, 6);
  TEST_TRUE(b->cells[0] == 2 && b->cells[1] == 3 && b->cells[2] == 4 && b->mesh == NULL);

  const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
  TEST_TRUE(g->kind == FCM_SCENE_GEOMETRY_TUBE && g->axis == 0);
  check_vec(g->center, 0.5, 1.5, 2.5);
  TEST_TRUE(g->inner_radius == 0.25 && g->outer_radius == 0.75 && g->length == 3);
  TEST_TRUE(g->radial_cells == 3 && g->angular_cells == 12 && g->axial_cells == 7);
  TEST_TRUE(g->has_transform);
  /* A = R_z(pi/2) diag(1, 2, 3): columns e_y, -2 e_x, 3 e_z; A^T A = diag(1, 4, 9). */
  const double A_expect[9] = {0, -2, 0, 1, 0, 0, 0, 0, 3};
  for (int i = 0; i < 9; i++)
    TEST_NEAR(g->transform[i], A_expect[i], 0, 1e-15);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double ata = 0;
      for (int k = 0; k < 3; k++)
        ata += g->transform[3 * k + i] * g->transform[3 * k + j];
      TEST_NEAR(ata, i == j ? (i + 1.0) * (i + 1.0) : 0.0, 1e-15, 1e-15);
    }
  check_vec(g->offset, 7, 8, 9);

  const fcm_material *m = fcm_scene_get_material(s);
  TEST_TRUE(m->model == FCM_MATERIAL_STVK && m->young == 2.5e6 && m->poisson == 0.35 &&
            m->density == 1200);
  TEST_OK(ctx, fcm_material_validate(ctx, m));

  const fcm_cell_rules_options *q = &fcm_scene_get_quadrature(s)->rules;
  TEST_TRUE(q->strength[FCM_RULE_STIFFNESS] == 5 && q->strength[FCM_RULE_MASS] == 7 &&
            q->surface_strength == 6);
  TEST_TRUE(q->simplify == 0 && q->simplify_options.method == FCM_SIMPLIFY_RECOMBINE);
  TEST_TRUE(q->stabilization.mode == FCM_STABILIZATION_MASS && q->stabilization.alpha == 1e-8);
  TEST_TRUE(q->min_fraction == 0.001);

  const fcm_scene_solver *sv = fcm_scene_get_solver(s);
  const fcm_integrator_options *so = &sv->integrator;
  TEST_TRUE(so->linear_solver == FCM_LINEAR_MINRES && so->direct_method == FCM_DIRECT_UMFPACK);
  TEST_TRUE(so->preconditioner == FCM_PRECOND_BLOCK_JACOBI);
  TEST_TRUE(so->schwarz_theta == 0.25 && so->schwarz.epsilon == 1e-12 &&
            so->schwarz.clamp == FCM_SCHWARZ_PAPER);
  TEST_TRUE(so->krylov_rtol == 1e-6 && so->krylov_atol == 1e-12 &&
            so->krylov_max_iterations == 321);
  TEST_TRUE(so->krylov_stagnation_window == 37);
  TEST_TRUE(so->newton_tolerance == 1e-4 && so->newton_max_iterations == 17);
  TEST_TRUE(so->newton_fixed_iterations == 2 && so->multigrid_fixed_cycles == 0);
  TEST_TRUE(so->line_search == 0 && so->project_psd == 1);
  TEST_TRUE(so->rep_acceleration == 10 && sv->threads == 3);
  TEST_TRUE(sv->stop_on_inversion == 1);
  TEST_TRUE(so->tolerance_mode == FCM_NEWTON_TOL_RELATIVE);

  const fcm_scene_time *t = fcm_scene_get_time(s);
  TEST_TRUE(t->integrator == FCM_INTEGRATOR_BACKWARD_EULER);
  TEST_TRUE(t->dt == 0.02 && t->num_steps == 75 && t->load_steps == 1);
  TEST_NEAR(t->duration, 1.5, 1e-15, 0);

  const fcm_scene_output *o = fcm_scene_get_output(s);
  TEST_TRUE(!strcmp(o->directory, "out/full") && o->frame_interval == 4);
  TEST_TRUE(o->checkpoint_interval == 9);
  TEST_TRUE(o->write_background == 0 && o->write_surface == 0);

  TEST_TRUE(fcm_scene_num_effects(s) == 10);
  TEST_TRUE(fcm_scene_get_effect(s, 10) == NULL && fcm_scene_get_effect(s, -1) == NULL);
  const int expect_count[FCM_EFFECT_TYPE_COUNT] = {1, 1, 1, 2, 1, 1, 1, 1, 1};
  for (int k = 0; k < FCM_EFFECT_TYPE_COUNT; k++)
    TEST_TRUE(fcm_scene_count_effects(s, (fcm_effect_type)k) == expect_count[k]);
  for (int i = 0; i < 10; i++)
    TEST_TRUE(fcm_scene_get_effect(s, i)->index == i);

  const fcm_effect *e = fcm_scene_get_effect(s, 0);
  TEST_TRUE(e->type == FCM_EFFECT_GRAVITY);
  check_vec(e->gravity.acceleration, 0, -9.81, 0);

  e = fcm_scene_get_effect(s, 1);
  TEST_TRUE(e->type == FCM_EFFECT_FIXED && e->fixed.region.kind == FCM_REGION_NODES);
  TEST_TRUE(e->fixed.region.num_nodes == 3);
  if (e->fixed.region.num_nodes == 3)
    TEST_TRUE(e->fixed.region.nodes[0] == 3 && e->fixed.region.nodes[1] == 5 &&
              e->fixed.region.nodes[2] == 11);
  TEST_TRUE(e->fixed.components[0] == 1 && e->fixed.components[1] == 0 &&
            e->fixed.components[2] == 1);
  const double anywhere[3] = {0, 0, 0};
  TEST_TRUE(!fcm_region_contains(&e->fixed.region, anywhere));

  e = fcm_scene_get_effect(s, 2);
  TEST_TRUE(e->type == FCM_EFFECT_MOTION && e->motion.region.kind == FCM_REGION_BOX);
  TEST_TRUE(e->motion.region.tolerance == 0.01);
  check_vec(e->motion.motion.velocity, 0.1, 0.2, 0.3);
  check_vec(e->motion.motion.axis, 0, 1, 0);
  check_vec(e->motion.motion.center, 1, 0, 1);
  TEST_TRUE(e->motion.motion.angular_speed == -0.5 && e->motion.motion.start == 0.25 &&
            e->motion.motion.end == 1.25 && e->motion.motion.release == 1);
  const double in_tol[3] = {0, -2.005, 0}, out_tol[3] = {0, -2.02, 0};
  TEST_TRUE(fcm_region_contains(&e->motion.region, in_tol));
  TEST_TRUE(!fcm_region_contains(&e->motion.region, out_tol));

  e = fcm_scene_get_effect(s, 3);
  TEST_TRUE(e->type == FCM_EFFECT_INITIAL_VELOCITY);
  TEST_TRUE(e->initial_velocity.region.kind == FCM_REGION_HALF_SPACE);
  check_vec(e->initial_velocity.region.normal, 0, 0, -1);
  TEST_TRUE(e->initial_velocity.region.tolerance == 1e-9);
  const double below[3] = {5, 5, 0.5}, above[3] = {0, 0, 1.5}, on[3] = {3, -4, 1};
  TEST_TRUE(fcm_region_contains(&e->initial_velocity.region, below));
  TEST_TRUE(fcm_region_contains(&e->initial_velocity.region, on));
  TEST_TRUE(!fcm_region_contains(&e->initial_velocity.region, above));
  check_vec(e->initial_velocity.velocity, 1, 2, 3);
  check_vec(e->initial_velocity.angular_velocity, 0.5, -0.5, 2);
  check_vec(e->initial_velocity.center, 1, 1, 1);
  TEST_TRUE(e->initial_velocity.center_of_mass == 0);

  e = fcm_scene_get_effect(s, 4);
  TEST_TRUE(e->type == FCM_EFFECT_DAMPING && e->damping.mass == 0.1 &&
            e->damping.stiffness == 0.02);

  e = fcm_scene_get_effect(s, 5);
  TEST_TRUE(e->type == FCM_EFFECT_TRACTION && e->traction.region.kind == FCM_REGION_BOX);
  check_vec(e->traction.traction, 10, 20, 30);
  TEST_TRUE(e->traction.start == 0.5 && e->traction.end == HUGE_VAL);

  e = fcm_scene_get_effect(s, 6);
  TEST_TRUE(e->type == FCM_EFFECT_PRESSURE && e->pressure.pressure == -250);
  TEST_TRUE(e->pressure.start == 0 && e->pressure.end == 1);

  e = fcm_scene_get_effect(s, 7);
  TEST_TRUE(e->type == FCM_EFFECT_INITIAL_VELOCITY && e->initial_velocity.center_of_mass == 1);
  TEST_TRUE(e->initial_velocity.region.kind == FCM_REGION_ALL);
  TEST_TRUE(fcm_region_contains(&e->initial_velocity.region, above));

  e = fcm_scene_get_effect(s, 8);
  TEST_TRUE(e->type == FCM_EFFECT_CUT && e->cut.kind == FCM_CUT_RECTANGLE && e->cut.time == 0.5);
  check_vec(e->cut.point, 1, 2, 3);
  check_vec(e->cut.normal, 0, 0, 1);
  check_vec(e->cut.axis, sqrt(0.5), 0, sqrt(0.5));
  TEST_TRUE(e->cut.size[0] == 0.5 && e->cut.size[1] == 0.25 && e->cut.has_transform);
  check_vec(e->cut.offset, 0, 0, 1);

  e = fcm_scene_get_effect(s, 9);
  TEST_TRUE(e->type == FCM_EFFECT_CONTACT);
  check_vec(e->contact.point, 0, 0, -2);
  check_vec(e->contact.normal, 0, 0, 1);
  check_vec(e->contact.velocity, 0, 0, 0.5);
  TEST_TRUE(e->contact.options.distance == 0.01 && e->contact.options.stiffness == 2e6);

  /* The summary names every section and effect. */
  FILE *f = tmpfile();
  TEST_TRUE(f != NULL);
  if (f) {
    char text[8192];
    fcm_scene_view(s, f);
    rewind(f);
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    fclose(f);
    const char *words[] = {
        "full-scene.v1", "tet10",    "tube",     "stvk",        "minres",
        "block_jacobi",  "75 steps", "out/full", "effects: 10", "on inversion: stop"};
    for (size_t i = 0; i < sizeof words / sizeof *words; i++)
      TEST_TRUE(strstr(text, words[i]));
    for (int k = 0; k < FCM_EFFECT_TYPE_COUNT; k++)
      TEST_TRUE(strstr(text, fcm_effect_type_name((fcm_effect_type)k)));
  }
  fcm_scene_destroy(&s);
  TEST_TRUE(s == NULL);
}

#define MIN_BG                                                                                     \
  "\"background\": {\"element\": \"hex8\", \"box\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]}, "    \
  "\"cells\": [1, 1, 1]}"
#define MIN_MAT "\"material\": {\"young\": 1e6, \"poisson\": 0.3}"

static void check_defaults(fcm_ctx *ctx)
{
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, "{" MIN_BG ", " MIN_MAT "}",
                                            "some/dir/min_scene.json", &s));
  if (!s) return;
  TEST_TRUE(!strcmp(fcm_scene_name(s), "min_scene"));
  TEST_TRUE(!strcmp(fcm_scene_description(s), ""));
  TEST_TRUE(fcm_scene_get_geometry(s)->kind == FCM_SCENE_GEOMETRY_NONE);
  TEST_TRUE(fcm_scene_get_geometry(s)->has_transform == 0);
  const fcm_material *m = fcm_scene_get_material(s);
  TEST_TRUE(m->model == FCM_MATERIAL_STABLE_NEO_HOOKEAN && m->density == 1000);
  const fcm_cell_rules_options *q = &fcm_scene_get_quadrature(s)->rules;
  TEST_TRUE(q->strength[FCM_RULE_STIFFNESS] == -1 && q->strength[FCM_RULE_MASS] == -1 &&
            q->surface_strength == -1);
  TEST_TRUE(q->simplify == 1 && q->simplify_options.method == FCM_SIMPLIFY_AUTO);
  TEST_TRUE(q->stabilization.mode == FCM_STABILIZATION_MASS_STIFFNESS);
  TEST_TRUE(q->stabilization.alpha == 1e-6 && q->min_fraction == 1e-4);
  const fcm_scene_solver *sv = fcm_scene_get_solver(s);
  const fcm_integrator_options *so = &sv->integrator;
  TEST_TRUE(so->linear_solver == FCM_LINEAR_DIRECT && so->direct_method == FCM_DIRECT_CHOLMOD);
  TEST_TRUE(so->preconditioner == FCM_PRECOND_SCHWARZ);
  TEST_TRUE(so->schwarz_theta == 0.5 && so->schwarz.epsilon == 1e-13 &&
            so->schwarz.clamp == FCM_SCHWARZ_CLAMP);
  TEST_TRUE(so->krylov_rtol == 1e-8 && so->krylov_atol == 0 && so->krylov_max_iterations == 1000);
  TEST_TRUE(so->krylov_stagnation_window == 50);
  TEST_TRUE(so->newton_tolerance == 1e-5 && so->newton_max_iterations == 100);
  TEST_TRUE(so->newton_fixed_iterations == 0 && so->multigrid_fixed_cycles == 0);
  TEST_TRUE(so->line_search == 1 && so->project_psd == 0);
  TEST_TRUE(so->rep_acceleration == 9.81 && sv->threads == FCM_DEFAULT);
  TEST_TRUE(sv->stop_on_inversion == 0); /* "warn" */
  TEST_TRUE(so->tolerance_mode == FCM_NEWTON_TOL_AUTO);
  const fcm_scene_time *t = fcm_scene_get_time(s);
  TEST_TRUE(t->integrator == FCM_INTEGRATOR_BACKWARD_EULER && t->dt == 1.0 / 60.0 &&
            t->num_steps == 60 && t->load_steps == 1);
  TEST_NEAR(t->duration, 1.0, 1e-15, 0);
  const fcm_scene_output *o = fcm_scene_get_output(s);
  TEST_TRUE(!strcmp(o->directory, "fcm-output") && o->frame_interval == 1);
  TEST_TRUE(o->checkpoint_interval == 0);
  TEST_TRUE(o->write_background == 1 && o->write_surface == 1);
  TEST_TRUE(fcm_scene_num_effects(s) == 0);
  for (int k = 0; k < FCM_EFFECT_TYPE_COUNT; k++)
    TEST_TRUE(fcm_scene_count_effects(s, (fcm_effect_type)k) == 0);
  fcm_scene_destroy(&s);

  /* Names: no source name -> "scene"; a stem that is no valid name -> "scene". */
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, "{" MIN_BG ", " MIN_MAT "}", NULL, &s));
  if (s) TEST_TRUE(!strcmp(fcm_scene_name(s), "scene") && !strcmp(fcm_scene_source(s), "<string>"));
  fcm_scene_destroy(&s);

  /* Static: one step of the default dt; defaults of effects. */
  TEST_OK(ctx, fcm_scene_create_from_string(
                   ctx,
                   "{" MIN_BG ", " MIN_MAT ", \"time\": {\"static\": true}, \"effects\": ["
                   "{\"gravity\": {}}, {\"fixed\": {\"region\": {\"box\": {\"min\": [0, 0, 0], "
                   "\"max\": [0, 1, 1]}}}}, {\"motion\": {\"region\": {\"nodes\": [0]}}}]}",
                   "s.json", &s));
  if (s) {
    const fcm_scene_time *ts = fcm_scene_get_time(s);
    TEST_TRUE(ts->integrator == FCM_INTEGRATOR_STATIC && ts->num_steps == 1 &&
              ts->dt == 1.0 / 60.0);
    check_vec(fcm_scene_get_effect(s, 0)->gravity.acceleration, 0, 0, -9.81);
    const fcm_effect_fixed *fx = &fcm_scene_get_effect(s, 1)->fixed;
    TEST_TRUE(fx->components[0] && fx->components[1] && fx->components[2]);
    TEST_TRUE(fx->region.tolerance == 1e-9);
    const fcm_motion *mo = &fcm_scene_get_effect(s, 2)->motion.motion;
    check_vec(mo->velocity, 0, 0, 0);
    check_vec(mo->axis, 0, 0, 1);
    TEST_TRUE(mo->angular_speed == 0 && mo->start == 0 && mo->end == HUGE_VAL && !mo->release);
    TEST_TRUE(mo->components[0] && mo->components[1] && mo->components[2]);
    /* A motion with no speeds holds its region in place at all times. */
    double u[3];
    const double X[3] = {0.3, -0.2, 0.9};
    fcm_motion_eval(mo, X, 5.0, u, NULL);
    check_vec(u, 0, 0, 0);
    TEST_TRUE(fcm_motion_active(mo, 1e9));
  }
  fcm_scene_destroy(&s);
}

/* The minimal scene with the given "time" section (NULL, reported, when it does not parse). */
static fcm_scene *time_scene(fcm_ctx *ctx, const char *time)
{
  char json[512];
  snprintf(json, sizeof json, "{" MIN_BG ", " MIN_MAT ", \"time\": %s}", time);
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "t.json", &s));
  return s;
}

/* A duration that is a whole number of steps up to rounding keeps that count; otherwise
 * the count rounds up. */
static void check_steps(fcm_ctx *ctx)
{
  const struct {
    const char *time;
    long long steps;
    double duration;
  } cases[] = {
      {"{\"dt\": 0.016666666666666666, \"duration\": 7}", 420, 7.0},
      {"{\"dt\": 0.1, \"duration\": 0.3}", 3, 0.3},
      {"{\"dt\": 0.02, \"duration\": 0.05}", 3, 0.06},
      {"{\"dt\": 0.5, \"steps\": 9}", 9, 4.5},
      {"{\"dt\": 2, \"duration\": 1}", 1, 2.0},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    fcm_scene *s = time_scene(ctx, cases[i].time);
    if (!s) continue;
    TEST_TRUE(fcm_scene_get_time(s)->num_steps == cases[i].steps);
    TEST_NEAR(fcm_scene_get_time(s)->duration, cases[i].duration, 1e-14, 0);
    fcm_scene_destroy(&s);
  }
}

/* The time schemes: "integrator" with its parameter, the defaults of the parameter, and the
 * normalized scene keeps them (round trip). */
static void check_schemes(fcm_ctx *ctx)
{
  const struct {
    const char *time;
    fcm_time_scheme scheme;
    double alpha, rho;
  } cases[] = {
      {"{\"integrator\": \"newmark\"}", FCM_SCHEME_NEWMARK, -0.05, 0.8},
      {"{\"integrator\": \"hht\", \"alpha\": -0.25}", FCM_SCHEME_HHT, -0.25, 0.8},
      {"{\"integrator\": \"hht\"}", FCM_SCHEME_HHT, -0.05, 0.8},
      {"{\"integrator\": \"generalized_alpha\", \"rho_inf\": 0}", FCM_SCHEME_GENERALIZED_ALPHA,
       -0.05, 0.0},
      {"{\"integrator\": \"backward_euler\"}", FCM_SCHEME_BACKWARD_EULER, -0.05, 0.8},
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    fcm_scene *s = time_scene(ctx, cases[i].time);
    if (!s) continue;
    const fcm_scene_time *t = fcm_scene_get_time(s);
    TEST_TRUE(t->integrator == FCM_INTEGRATOR_DYNAMIC && t->scheme == cases[i].scheme &&
              t->hht_alpha == cases[i].alpha && t->rho_inf == cases[i].rho);
    check_normalized(ctx, s, cases[i].time);
    fcm_scene_destroy(&s);
  }
}

/* fixed and motion on the embedded boundary: "boundary" with a region or "all",
 * the method keys and their defaults; the region selects points by position. */
static void check_boundary(fcm_ctx *ctx)
{
  const char *json =
      "{" MIN_BG ", " MIN_MAT ", \"effects\": ["
      "{\"fixed\": {\"boundary\": \"all\", \"components\": \"z\", \"method\": \"penalty\", "
      "\"penalty\": 50}},"
      "{\"motion\": {\"boundary\": {\"half_space\": {\"point\": [0, 0, 1], \"normal\": [0, 0, "
      "2]}}, \"velocity\": [1, 0, 0], \"nitsche_safety\": 3}},"
      "{\"fixed\": {\"region\": {\"nodes\": [0]}}}]}";
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "b.json", &s));
  if (!s) return;
  const fcm_effect *e = fcm_scene_get_effect(s, 0);
  TEST_TRUE(e->type == FCM_EFFECT_FIXED && e->fixed.boundary == 1);
  TEST_TRUE(e->fixed.region.kind == FCM_REGION_ALL);
  TEST_TRUE(e->fixed.components[0] == 0 && e->fixed.components[2] == 1);
  TEST_TRUE(e->fixed.boundary_options.method == FCM_BOUNDARY_PENALTY);
  TEST_TRUE(e->fixed.boundary_options.penalty == 50.0);
  TEST_TRUE(e->fixed.boundary_options.nitsche_safety == 2.0);
  e = fcm_scene_get_effect(s, 1);
  TEST_TRUE(e->type == FCM_EFFECT_MOTION && e->motion.boundary == 1);
  TEST_TRUE(e->motion.region.kind == FCM_REGION_HALF_SPACE);
  TEST_TRUE(e->motion.boundary_options.method == FCM_BOUNDARY_NITSCHE);
  TEST_TRUE(e->motion.boundary_options.nitsche_safety == 3.0);
  const double above[3] = {0, 0, 1.5}, below[3] = {0, 0, 0.5}, n[3] = {0, 0, 1};
  TEST_TRUE(fcm_region_select((void *)&e->motion.region, above, n) == 1);
  TEST_TRUE(fcm_region_select((void *)&e->motion.region, below, n) == 0);
  e = fcm_scene_get_effect(s, 2);
  TEST_TRUE(e->type == FCM_EFFECT_FIXED && e->fixed.boundary == 0);
  fcm_scene_destroy(&s);
}

/* Motion of the full scene's effect 2, evaluated by fcm_motion_eval() (what the runner
 * constrains): rotation about the unit axis a through c by omega tau plus translation
 * v tau, tau clamped to [0, end - start]; velocity v + omega a x (x - c) while moving. */
static void check_motion(fcm_ctx *ctx)
{
  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, full_scene_json, "full.json", &s));
  if (!s) return;
  const fcm_motion *m = &fcm_scene_get_effect(s, 2)->motion.motion;
  const double Xs[3][3] = {{2, 0.5, -1}, {-0.5, 3, 4}, {1, 7, 1}}; /* the last is on the axis */
  const double times[] = {0.0, 0.25, 0.6, 1.0, 1.25, 3.0};
  for (int i = 0; i < 3; i++) {
    const double *X = Xs[i];
    for (size_t k = 0; k < sizeof times / sizeof *times; k++) {
      double t = times[k], u[3], v[3], y[3], r0[3], r1[3];
      double tau = fmin(fmax(t - 0.25, 0.0), 1.0);
      fcm_motion_eval(m, X, t, u, v);
      for (int d = 0; d < 3; d++) {
        y[d] = X[d] + u[d] - m->velocity[d] * tau; /* undo the translation */
        r0[d] = X[d] - m->center[d];
        r1[d] = y[d] - m->center[d];
      }
      /* Distance to the centre and the axial component are preserved... */
      TEST_NEAR(fcm__vec3_dot(r1, r1), fcm__vec3_dot(r0, r0), 1e-13, 1e-14);
      TEST_NEAR(fcm__vec3_dot(r1, m->axis), fcm__vec3_dot(r0, m->axis), 1e-13, 1e-14);
      /* ...and the normal components turn by omega tau, right-handed about the axis. */
      double p0[3], p1[3], c[3];
      for (int d = 0; d < 3; d++) {
        p0[d] = r0[d] - fcm__vec3_dot(r0, m->axis) * m->axis[d];
        p1[d] = r1[d] - fcm__vec3_dot(r1, m->axis) * m->axis[d];
      }
      double rr = fcm__vec3_dot(p0, p0), phi = m->angular_speed * tau;
      fcm__vec3_cross(p0, p1, c);
      TEST_NEAR(fcm__vec3_dot(p0, p1), rr * cos(phi), 1e-13, 1e-13);
      TEST_NEAR(fcm__vec3_dot(c, m->axis), rr * sin(phi), 1e-13, 1e-13);
      if (t <= 0.25) TEST_TRUE(fabs(u[0]) + fabs(u[1]) + fabs(u[2]) == 0.0);
      /* Velocity: v + omega a x (x - c) while start <= t < end, else 0. */
      double w[3], ax[3];
      fcm__vec3_cross(m->axis, r1, ax);
      int moving = t >= 0.25 && t < 1.25;
      for (int d = 0; d < 3; d++)
        w[d] = moving ? m->velocity[d] + m->angular_speed * ax[d] : 0.0;
      for (int d = 0; d < 3; d++)
        TEST_NEAR(v[d], w[d], 1e-12, 1e-13);
    }
  }
  /* Released after end: constrained up to end only. */
  TEST_TRUE(fcm_motion_active(m, 0.0) && fcm_motion_active(m, 1.25));
  TEST_TRUE(!fcm_motion_active(m, 1.2500001));

  /* Initial velocity: v - v0 = omega x (X - c) is orthogonal to omega and to X - c, with
   * |omega x r|^2 = |omega|^2 |r|^2 - (omega . r)^2. */
  const fcm_effect_initial_velocity *iv = &fcm_scene_get_effect(s, 3)->initial_velocity;
  const double com[3] = {100, 100, 100}; /* ignored: the effect names its centre */
  for (int i = 0; i < 3; i++) {
    double v[3], w[3], r[3];
    fcm_effect_initial_velocity_eval(iv, Xs[i], com, v);
    for (int d = 0; d < 3; d++) {
      w[d] = v[d] - iv->velocity[d];
      r[d] = Xs[i][d] - iv->center[d];
    }
    const double *om = iv->angular_velocity;
    TEST_NEAR(fcm__vec3_dot(w, om), 0.0, 0, 1e-13);
    TEST_NEAR(fcm__vec3_dot(w, r), 0.0, 0, 1e-13);
    TEST_NEAR(fcm__vec3_dot(w, w),
              fcm__vec3_dot(om, om) * fcm__vec3_dot(r, r) -
                  fcm__vec3_dot(om, r) * fcm__vec3_dot(om, r),
              1e-13, 1e-13);
  }
  /* About the centre of mass: the velocity at the centre of mass is v0. */
  fcm_effect_initial_velocity spin = *iv;
  spin.center_of_mass = 1;
  double v[3];
  fcm_effect_initial_velocity_eval(&spin, com, com, v);
  check_vec(v, 1, 2, 3);
  fcm_scene_destroy(&s);
}

/* File names are resolved against the scene file's directory; absolute names are kept. */
static void count_warnings(void *user, fcm_log_level level, const char *msg)
{
  (void)msg;
  if (level == FCM_LOG_WARNING) ++*(int *)user;
}

static void check_files(fcm_ctx *ctx)
{
  char dir[64], path[256], sub[128], meshes[128], scene_path[256], json[1024];
  if (!make_temp_dir(dir, sizeof dir)) {
    TEST_TRUE(!"mkdtemp failed");
    return;
  }
  snprintf(sub, sizeof sub, "%s/sub", dir);
  snprintf(meshes, sizeof meshes, "%s/meshes", dir);
  TEST_TRUE(mkdir(sub, 0700) == 0 && mkdir(meshes, 0700) == 0);
  snprintf(path, sizeof path, "%s/bg.msh", meshes);
  TEST_TRUE(write_text(path, "not parsed by the scene reader\n") == 0);
  snprintf(path, sizeof path, "%s/body.1.node", sub);
  TEST_TRUE(write_text(path, "0 3 0 0\n") == 0);
  snprintf(path, sizeof path, "%s/body.1.ele", sub);
  TEST_TRUE(write_text(path, "0 4 0\n") == 0);
  snprintf(json, sizeof json,
           "{\"background\": {\"mesh\": \"../meshes/bg.msh\"}, \"geometry\": {\"tetgen\": "
           "\"body.1\"}, " MIN_MAT "}");
  snprintf(scene_path, sizeof scene_path, "%s/scene.json", sub);
  TEST_TRUE(write_text(scene_path, json) == 0);

  fcm_scene *s = NULL;
  TEST_OK(ctx, fcm_scene_create_from_file(ctx, scene_path, &s));
  if (s) {
    char expect[256];
    const fcm_scene_background *b = fcm_scene_get_background(s);
    TEST_TRUE(b->kind == FCM_SCENE_BACKGROUND_MESH && b->element == FCM_ELEMENT_COUNT);
    snprintf(expect, sizeof expect, "%s/../meshes/bg.msh", sub);
    TEST_TRUE(!strcmp(b->mesh, expect));
    const fcm_scene_geometry *g = fcm_scene_get_geometry(s);
    TEST_TRUE(g->kind == FCM_SCENE_GEOMETRY_TETGEN);
    snprintf(expect, sizeof expect, "%s/body.1.node", sub);
    TEST_TRUE(!strcmp(g->mesh, expect));
    snprintf(expect, sizeof expect, "%s/body.1.ele", sub);
    TEST_TRUE(!strcmp(g->ele, expect));
    TEST_TRUE(!strcmp(fcm_scene_name(s), "scene"));
  }
  fcm_scene_destroy(&s);

  /* The same text given as a string with the file's name resolves the same way. */
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, scene_path, &s));
  fcm_scene_destroy(&s);

  /* An absolute name is used as given. */
  snprintf(json, sizeof json, "{\"background\": {\"mesh\": \"%s/bg.msh\"}, " MIN_MAT "}", meshes);
  TEST_OK(ctx, fcm_scene_create_from_string(ctx, json, "elsewhere/x.json", &s));
  if (s) {
    snprintf(path, sizeof path, "%s/bg.msh", meshes);
    TEST_TRUE(!strcmp(fcm_scene_get_background(s)->mesh, path));
  }
  fcm_scene_destroy(&s);

  /* Without "name", a file name that is not a usable name gives a sanitized one and a
   * warning; a usable one is taken as it is. */
  {
    int warnings = 0;
    fcm_ctx_options co = fcm_ctx_options_default();
    co.log = count_warnings;
    co.log_user = &warnings;
    fcm_ctx *c2 = NULL;
    TEST_OK(c2, fcm_ctx_create(&co, &c2));
    TEST_OK(c2, fcm_scene_create_from_string(c2, json, "elsewhere/my scene#1.json", &s));
    TEST_TRUE(s && !strcmp(fcm_scene_name(s), "my_scene_1") && warnings == 1);
    fcm_scene_destroy(&s);
    TEST_OK(c2, fcm_scene_create_from_string(c2, json, "elsewhere/x-1.json", &s));
    TEST_TRUE(s && !strcmp(fcm_scene_name(s), "x-1") && warnings == 1);
    fcm_scene_destroy(&s);
    fcm_ctx_destroy(&c2);
  }

  /* Clean up. */
  const char *files[] = {
      "sub/scene.json", "sub/body.1.node", "sub/body.1.ele", "meshes/bg.msh", "sub", "meshes", ""};
  for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
    snprintf(path, sizeof path, "%s/%s", dir, files[i]);
    TEST_TRUE(remove(path) == 0);
  }
}

int main(void)
{
  fcm_ctx *ctx = NULL;
  TEST_OK(ctx, fcm_ctx_create(NULL, &ctx));
  if (!ctx) return TEST_RESULT();
  check_full(ctx);
  check_defaults(ctx);
  check_steps(ctx);
  check_schemes(ctx);
  check_motion(ctx);
  check_boundary(ctx);
  check_files(ctx);
  TEST_TRUE(fcm_ctx_live_allocations(ctx) == 0);
  fcm_ctx_destroy(&ctx);
  return TEST_RESULT();
}
