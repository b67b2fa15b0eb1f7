/* The effect table (one entry per effect type: name, parser/validator, scene rules,
 * printer), the parsers of the loads, constraints, initial velocity and damping, the
 * "effects" array reader, and the closed-form initial velocity. Regions, time windows and
 * rigid motions are read in effects_region.c; the cut and contact effects in
 * effects_contact.c. Motions are the library's fcm_motion, evaluated by fcm_motion_eval()
 * (fcm/sim.h), the evaluator the runner uses. */
#include "scene/scene_impl.h"

#include <stdlib.h>
#include <string.h>

#define COUNT(a) ((int)(sizeof(a) / sizeof *(a)))

/* ---------------------------------------------------------------- the effects */

static fcm_status parse_gravity(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"acceleration"};
  fcm_effect_gravity *g = &e->gravity;
  g->acceleration[0] = g->acceleration[1] = 0.0;
  g->acceleration[2] = -9.81;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "acceleration", 0, FCM__ANY, g->acceleration));
cleanup:
  return st;
}

static void view_gravity(const fcm_effect *e, FILE *f)
{
  const double *a = e->gravity.acceleration;
  fprintf(f, "acceleration (%g, %g, %g) m/s^2", a[0], a[1], a[2]);
}

/* Where a fixed or motion effect acts: "region" (background nodes) or "boundary" (the
 * embedded-boundary points in a box or half-space region, or "all"), exactly one; with
 * "boundary" the method keys "method", "penalty", "nitsche_safety". */
static fcm_status read_target(fcm__scene_parser *p, const fcm__json *o, fcm_region *region,
                              int *boundary, fcm_boundary_options *bo)
{
  fcm_status st = FCM_OK;
  static const char *const methods[] = {"nitsche", "penalty"};
  const fcm__json *b = fcm__json_member(o, "boundary");
  const int has_region = fcm__json_member(o, "region") != NULL;
  *bo = fcm_boundary_options_default();
  *boundary = b != NULL;
  SCENE_CHECK(!(b && has_region), p, FCM_ERR_ARG,
              "expected one of \"region\" (background nodes) or \"boundary\" (embedded-boundary "
              "points), got both");
  if (!b) {
    SCENE_CHECK(has_region, p, FCM_ERR_ARG,
                "missing \"region\"; expected a \"region\" (background nodes) or a "
                "\"boundary\" (embedded-boundary points)");
    FCM_TRY(p->ctx, fcm__scene_read_region(p, o, "region", 1, 1, region));
    static const char *const bkeys[] = {"method", "penalty", "nitsche_safety"};
    for (int k = 0; k < 3; k++) {
      size_t old = fcm__scene_path_push_key(p, bkeys[k]);
      SCENE_CHECK(!fcm__json_member(o, bkeys[k]), p, FCM_ERR_ARG,
                  "allowed only with \"boundary\" (embedded-boundary points), not with "
                  "\"region\"");
      fcm__scene_path_pop(p, old);
    }
    return FCM_OK;
  }
  if (fcm__json_get_kind(b) == FCM__JSON_STRING) {
    size_t old = fcm__scene_path_push_key(p, "boundary");
    SCENE_CHECK(!strcmp(fcm__json_string(b), "all"), p, FCM_ERR_ARG,
                "expected \"all\" or a region object (box or half_space), got \"%.40s\"",
                fcm__json_string(b));
    fcm__scene_path_pop(p, old);
    memset(region, 0, sizeof *region);
    region->kind = FCM_REGION_ALL;
    region->tolerance = 1e-9;
  } else {
    FCM_TRY(p->ctx, fcm__scene_read_region(p, o, "boundary", 1, 0, region));
  }
  int m = 0;
  FCM_TRY(p->ctx, fcm__scene_read_choice(p, o, "method", 0, methods, 2, &m));
  bo->method = (fcm_boundary_method)m;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "penalty", 0, FCM__POSITIVE, &bo->penalty));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "nitsche_safety", 0,
                                         (fcm__range){1.0, HUGE_VAL, 1, 1}, &bo->nitsche_safety));
cleanup:
  return st;
}

static void view_target(const fcm_region *r, int boundary, const fcm_boundary_options *bo, FILE *f)
{
  if (boundary) {
    fprintf(f, "the embedded boundary (%s", fcm_boundary_method_name(bo->method));
    if (bo->method == FCM_BOUNDARY_NITSCHE)
      fprintf(f, ", safety %g) in ", bo->nitsche_safety);
    else
      fprintf(f, " %g E/h) in ", bo->penalty);
  }
  fcm__scene_region_view(r, f);
}

static fcm_status parse_fixed(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"region", "boundary", "components",
                                     "method", "penalty",  "nitsche_safety"};
  fcm_effect_fixed *x = &e->fixed;
  const char *comp = NULL;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, read_target(p, o, &x->region, &x->boundary, &x->boundary_options));
  FCM_TRY(p->ctx, fcm__scene_read_string(p, o, "components", 0, &comp));
  x->components[0] = x->components[1] = x->components[2] = 1;
  if (comp) {
    int seen[3] = {0, 0, 0}, ok = strlen(comp) <= 3;
    for (const char *c = comp; *c && ok; c++) {
      int d = *c == 'x' ? 0 : *c == 'y' ? 1 : *c == 'z' ? 2 : -1;
      ok = d >= 0 && !seen[d];
      if (ok) seen[d] = 1;
    }
    size_t old = fcm__scene_path_push_key(p, "components");
    SCENE_CHECK(ok, p, FCM_ERR_ARG,
                "expected distinct letters from \"xyz\" (e.g. \"xz\"), got \"%.40s\"", comp);
    fcm__scene_path_pop(p, old);
    for (int d = 0; d < 3; d++)
      x->components[d] = seen[d];
  }
cleanup:
  return st;
}

static void view_fixed(const fcm_effect *e, FILE *f)
{
  const int *c = e->fixed.components;
  fprintf(f, "components %s%s%s on ", c[0] ? "x" : "", c[1] ? "y" : "", c[2] ? "z" : "");
  view_target(&e->fixed.region, e->fixed.boundary, &e->fixed.boundary_options, f);
}

static fcm_status parse_motion(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"region", "boundary", "velocity", "rotation",       "start",
                                     "end",    "release",  "method",   "nitsche_safety", "penalty"};
  fcm_motion *m = &e->motion.motion;
  *m = fcm_motion_default();
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx,
          read_target(p, o, &e->motion.region, &e->motion.boundary, &e->motion.boundary_options));
  FCM_TRY(p->ctx, fcm__scene_read_rigid_motion(p, o, m));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "release", 0, &m->release));
  if (m->release) {
    size_t old = fcm__scene_path_push_key(p, "release");
    SCENE_CHECK(m->end < HUGE_VAL, p, FCM_ERR_ARG,
                "true needs an \"end\" time (the region is released after it)");
    fcm__scene_path_pop(p, old);
  }
cleanup:
  return st;
}

static void view_motion(const fcm_effect *e, FILE *f)
{
  const fcm_motion *m = &e->motion.motion;
  fprintf(f, "velocity (%g, %g, %g) m/s", m->velocity[0], m->velocity[1], m->velocity[2]);
  if (m->angular_speed != 0.0)
    fprintf(f, ", rotation %g rad/s about (%g, %g, %g) through (%g, %g, %g)", m->angular_speed,
            m->axis[0], m->axis[1], m->axis[2], m->center[0], m->center[1], m->center[2]);
  fcm__scene_view_window(m->start, m->end, f);
  if (m->end < HUGE_VAL) fprintf(f, ", then %s", m->release ? "released" : "held");
  fprintf(f, "; on ");
  view_target(&e->motion.region, e->motion.boundary, &e->motion.boundary_options, f);
}

static fcm_status parse_initial_velocity(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"region", "velocity", "angular_velocity", "center"};
  fcm_effect_initial_velocity *v = &e->initial_velocity;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_region(p, o, "region", 0, 1, &v->region));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "velocity", 0, FCM__ANY, v->velocity));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "angular_velocity", 0, FCM__ANY, v->angular_velocity));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, v->center));
  v->center_of_mass = fcm__json_member(o, "center") == NULL;
  if (v->center_of_mass) fcm__scene_forget(p, "center"); /* not the default [0, 0, 0] */
cleanup:
  return st;
}

static void view_initial_velocity(const fcm_effect *e, FILE *f)
{
  const fcm_effect_initial_velocity *v = &e->initial_velocity;
  fprintf(f, "velocity (%g, %g, %g) m/s, angular (%g, %g, %g) rad/s about ", v->velocity[0],
          v->velocity[1], v->velocity[2], v->angular_velocity[0], v->angular_velocity[1],
          v->angular_velocity[2]);
  if (v->center_of_mass)
    fprintf(f, "the centre of mass");
  else
    fprintf(f, "(%g, %g, %g)", v->center[0], v->center[1], v->center[2]);
  fprintf(f, "; on ");
  fcm__scene_region_view(&v->region, f);
}

static fcm_status parse_damping(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"mass", "stiffness"};
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "mass", 0, FCM__NONNEGATIVE, &e->damping.mass));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "stiffness", 0, FCM__NONNEGATIVE, &e->damping.stiffness));
cleanup:
  return st;
}

static void view_damping(const fcm_effect *e, FILE *f)
{
  fprintf(f, "Rayleigh D = %g M + %g K", e->damping.mass, e->damping.stiffness);
}

static fcm_status parse_traction(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"region", "value", "start", "end"};
  fcm_effect_traction *t = &e->traction;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_region(p, o, "region", 1, 0, &t->region));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "value", 1, FCM__ANY, t->traction));
  FCM_TRY(p->ctx, fcm__scene_read_window(p, o, &t->start, &t->end));
cleanup:
  return st;
}

static void view_traction(const fcm_effect *e, FILE *f)
{
  const fcm_effect_traction *t = &e->traction;
  fprintf(f, "(%g, %g, %g) Pa", t->traction[0], t->traction[1], t->traction[2]);
  fcm__scene_view_window(t->start, t->end, f);
  fprintf(f, "; on the boundary in ");
  fcm__scene_region_view(&t->region, f);
}

static fcm_status parse_pressure(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"region", "value", "start", "end"};
  fcm_effect_pressure *q = &e->pressure;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_region(p, o, "region", 1, 0, &q->region));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "value", 1, FCM__ANY, &q->pressure));
  FCM_TRY(p->ctx, fcm__scene_read_window(p, o, &q->start, &q->end));
cleanup:
  return st;
}

static void view_pressure(const fcm_effect *e, FILE *f)
{
  const fcm_effect_pressure *q = &e->pressure;
  fprintf(f, "%g Pa", q->pressure);
  fcm__scene_view_window(q->start, q->end, f);
  fprintf(f, "; on the boundary in ");
  fcm__scene_region_view(&q->region, f);
}

/* The one table of effect modules. Order = enum fcm_effect_type. */
static const fcm__effect_type effect_types[FCM_EFFECT_TYPE_COUNT] = {
    {.type = FCM_EFFECT_GRAVITY,
     .name = "gravity",
     .summary = "uniform body force density rho g",
     .max_count = 1,
     .allowed_static = 1,
     .parse = parse_gravity,
     .view = view_gravity,
     .apply = fcm__effect_apply_gravity},
    {.type = FCM_EFFECT_FIXED,
     .name = "fixed",
     .summary = "zero displacement of a region",
     .allowed_static = 1,
     .parse = parse_fixed,
     .view = view_fixed,
     .apply = fcm__effect_apply_constraint},
    {.type = FCM_EFFECT_MOTION,
     .name = "motion",
     .summary = "prescribed translation and rotation of a region",
     .allowed_static = 1,
     .parse = parse_motion,
     .view = view_motion,
     .apply = fcm__effect_apply_constraint},
    {.type = FCM_EFFECT_INITIAL_VELOCITY,
     .name = "initial_velocity",
     .summary = "linear and angular initial velocity",
     .parse = parse_initial_velocity,
     .view = view_initial_velocity,
     .initialize = fcm__effect_initialize_velocity},
    {.type = FCM_EFFECT_DAMPING,
     .name = "damping",
     .summary = "Rayleigh damping",
     .max_count = 1,
     .parse = parse_damping,
     .view = view_damping,
     .configure = fcm__effect_configure_damping},
    {.type = FCM_EFFECT_TRACTION,
     .name = "traction",
     .summary = "traction on the embedded boundary",
     .allowed_static = 1,
     .parse = parse_traction,
     .view = view_traction,
     .needs = FCM__NEEDS_SURFACE_RULES,
     .apply = fcm__effect_apply_surface_load},
    {.type = FCM_EFFECT_PRESSURE,
     .name = "pressure",
     .summary = "pressure on the embedded boundary",
     .allowed_static = 1,
     .parse = parse_pressure,
     .view = view_pressure,
     .needs = FCM__NEEDS_SURFACE_RULES,
     .apply = fcm__effect_apply_surface_load},
    {.type = FCM_EFFECT_CUT,
     .name = "cut",
     .summary = "a cut surface inserted at a time (XFEM): the body separates along it",
     .allowed_static = 1,
     .parse = fcm__effect_parse_cut,
     .view = fcm__effect_view_cut},
    {.type = FCM_EFFECT_CONTACT,
     .name = "contact",
     .summary = "a rigid plane obstacle, static or moving (log barrier on the embedded surface)",
     .allowed_static = 1, /* the body must start within d^ of obstacles holding it */
     .parse = fcm__effect_parse_contact,
     .view = fcm__effect_view_contact,
     .needs = FCM__NEEDS_SURFACE_RULES,
     .apply = fcm__effect_apply_contact},
};

const fcm__effect_type *fcm__scene_effect_type(fcm_effect_type type)
{
  if ((int)type < 0 || type >= FCM_EFFECT_TYPE_COUNT) return NULL;
  return &effect_types[type];
}

const fcm__effect_type *fcm__scene_effect_type_find(const char *name)
{
  for (int i = 0; i < FCM_EFFECT_TYPE_COUNT; i++)
    if (!strcmp(effect_types[i].name, name)) return &effect_types[i];
  return NULL;
}

const char *fcm_effect_type_name(fcm_effect_type type)
{
  const fcm__effect_type *t = fcm__scene_effect_type(type);
  return t ? t->name : NULL;
}

fcm_status fcm__scene_read_effects(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  fcm_scene *s = p->scene;
  const fcm__json *arr = NULL;
  char got[96], names[256];
  int counts[FCM_EFFECT_TYPE_COUNT] = {0}, first[FCM_EFFECT_TYPE_COUNT] = {0};
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_field(p, root, "effects", 0,
                                   "an array of effects (objects like {\"gravity\": {}})",
                                   FCM__JSON_ARRAY, -1, &arr));
  if (!arr) return FCM_OK;
  {
    size_t used = 0;
    for (int i = 0; i < FCM_EFFECT_TYPE_COUNT; i++)
      used += (size_t)snprintf(names + used, sizeof names - used, "%s\"%s\"", i ? ", " : "",
                               effect_types[i].name);
  }
  int n = fcm__json_size(arr);
  if (n == 0) goto cleanup;
  s->effects = fcm__scene_alloc(s, (size_t)n, sizeof *s->effects);
  if (!s->effects) {
    st = FCM_ERR_ALLOC;
    fcm__trace(p->ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  int i = 0;
  for (const fcm__json *c = fcm__json_child(arr); c; c = fcm__json_next(c), i++) {
    size_t o = fcm__scene_path_push_index(p, i);
    fcm__scene_describe(c, got, sizeof got);
    if (fcm__json_get_kind(c) == FCM__JSON_OBJECT)
      snprintf(got, sizeof got, "an object with %d keys", fcm__json_size(c));
    SCENE_CHECK(fcm__json_get_kind(c) == FCM__JSON_OBJECT && fcm__json_size(c) == 1, p, FCM_ERR_ARG,
                "expected an object with one key naming the effect (one of %s), got %s", names,
                got);
    const fcm__json *params = fcm__json_child(c);
    const char *name = fcm__json_key(params);
    const fcm__effect_type *type = fcm__scene_effect_type_find(name);
    fcm__scene_path_push_key(p, name);
    SCENE_CHECK(type, p, FCM_ERR_ARG, "unknown effect; allowed effects: %s", names);
    fcm__scene_describe(params, got, sizeof got);
    SCENE_CHECK(fcm__json_get_kind(params) == FCM__JSON_OBJECT, p, FCM_ERR_ARG,
                "expected an object of parameters ({} for the defaults), got %s", got);
    fcm_effect *e = &s->effects[i];
    e->type = type->type;
    e->index = i;
    FCM_TRY(p->ctx, type->parse(p, params, e));
    SCENE_CHECK(type->max_count == 0 || counts[type->type] < type->max_count, p, FCM_ERR_ARG,
                "at most %d %s effect per scene; effects[%d] is one already", type->max_count,
                type->name, first[type->type]);
    SCENE_CHECK(type->allowed_static || s->time.integrator != FCM_INTEGRATOR_STATIC, p, FCM_ERR_ARG,
                "not allowed in a static scene (time.static is true)");
    if (counts[type->type]++ == 0) first[type->type] = i;
    s->num_effects = i + 1;
    fcm__scene_path_pop(p, o);
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- evaluation */

void fcm_effect_initial_velocity_eval(const fcm_effect_initial_velocity *iv, const double X[3],
                                      const double com[3], double v[3])
{
  const double *c = iv->center_of_mass && com ? com : iv->center;
  const double *w = iv->angular_velocity;
  double r[3] = {X[0] - c[0], X[1] - c[1], X[2] - c[2]};
  v[0] = iv->velocity[0] + w[1] * r[2] - w[2] * r[1];
  v[1] = iv->velocity[1] + w[2] * r[0] - w[0] * r[2];
  v[2] = iv->velocity[2] + w[0] * r[1] - w[1] * r[0];
}
