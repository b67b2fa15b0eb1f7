/* The effect table (one entry per effect type: name, parser/validator, scene rules,
 * printer), region parsing, and the closed-form initial velocity. Motions are the library's
 * fcm_motion, evaluated by fcm_motion_eval() (fcm/sim.h), the evaluator the runner uses. */
#include "scene/scene_impl.h"

#include <stdlib.h>
#include <string.h>

#define COUNT(a) ((int)(sizeof(a) / sizeof *(a)))

/* Node ids are read as JSON numbers: integers up to 2^53 are exact. */
#define MAX_NODE_ID 9007199254740991LL

/* ---------------------------------------------------------------- regions */

int fcm_region_contains(const fcm_region *r, const double x[3])
{
  switch (r->kind) {
  case FCM_REGION_ALL:
    return 1;
  case FCM_REGION_BOX:
    for (int d = 0; d < 3; d++)
      if (!(x[d] >= r->min[d] - r->tolerance && x[d] <= r->max[d] + r->tolerance)) return 0;
    return 1;
  case FCM_REGION_HALF_SPACE: {
    double s = 0.0;
    for (int d = 0; d < 3; d++)
      s += (x[d] - r->point[d]) * r->normal[d];
    return s >= -r->tolerance;
  }
  default:
    return 0;
  }
}

int fcm_region_select(void *region, const double X[3], const double normal[3])
{
  (void)normal;
  return fcm_region_contains(region, X);
}

static int cmp_index(const void *a, const void *b)
{
  fcm_index x = *(const fcm_index *)a, y = *(const fcm_index *)b;
  return (x > y) - (x < y);
}

static fcm_status read_box(fcm__scene_parser *p, const fcm__json *box, fcm_region *r)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"min", "max", "tolerance"};
  FCM_TRY(p->ctx, fcm__scene_check_object(p, box, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, box, "min", 1, FCM__ANY, r->min));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, box, "max", 1, FCM__ANY, r->max));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, box, "tolerance", 0, FCM__NONNEGATIVE, &r->tolerance));
  for (int d = 0; d < 3; d++)
    SCENE_CHECK(r->min[d] <= r->max[d], p, FCM_ERR_ARG,
                "expected min[%d] <= max[%d], got min[%d] = %g > max[%d] = %g", d, d, d, r->min[d],
                d, r->max[d]);
  r->kind = FCM_REGION_BOX;
cleanup:
  return st;
}

static fcm_status read_half_space(fcm__scene_parser *p, const fcm__json *hs, fcm_region *r)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"point", "normal", "tolerance"};
  FCM_TRY(p->ctx, fcm__scene_check_object(p, hs, keys, COUNT(keys)));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, hs, "point", 1, FCM__ANY, r->point));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, hs, "normal", 1, FCM__ANY, r->normal));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, hs, "tolerance", 0, FCM__NONNEGATIVE, &r->tolerance));
  double n =
      sqrt(r->normal[0] * r->normal[0] + r->normal[1] * r->normal[1] + r->normal[2] * r->normal[2]);
  {
    size_t old = fcm__scene_path_push_key(p, "normal");
    SCENE_CHECK(n > 0.0 && isfinite(n), p, FCM_ERR_ARG,
                "expected a non-zero vector, got (%g, %g, %g)", r->normal[0], r->normal[1],
                r->normal[2]);
    fcm__scene_path_pop(p, old);
  }
  for (int d = 0; d < 3; d++)
    r->normal[d] /= n;
  r->kind = FCM_REGION_HALF_SPACE;
cleanup:
  return st;
}

static fcm_status read_nodes(fcm__scene_parser *p, const fcm__json *arr, fcm_region *r)
{
  fcm_status st = FCM_OK;
  char got[96];
  fcm_index *ids = NULL;
  fcm__scene_describe(arr, got, sizeof got);
  int n = fcm__json_get_kind(arr) == FCM__JSON_ARRAY ? fcm__json_size(arr) : 0;
  SCENE_CHECK(n > 0, p, FCM_ERR_ARG,
              "expected a non-empty array of node ids (integers in [0, %lld]), got %s", MAX_NODE_ID,
              got);
  ids = fcm__scene_alloc(p->scene, (size_t)n, sizeof *ids);
  if (!ids) {
    st = FCM_ERR_ALLOC;
    fcm__trace(p->ctx, __FILE__, __LINE__, __func__);
    goto cleanup;
  }
  int i = 0;
  for (const fcm__json *c = fcm__json_child(arr); c; c = fcm__json_next(c), i++) {
    size_t old = fcm__scene_path_push_index(p, i);
    fcm__scene_describe(c, got, sizeof got);
    double x = fcm__json_get_kind(c) == FCM__JSON_NUMBER ? fcm__json_number(c) : -1.0;
    SCENE_CHECK(isfinite(x) && x >= 0 && x == floor(x) && x <= (double)MAX_NODE_ID, p, FCM_ERR_ARG,
                "expected a node id (an integer in [0, %lld]), got %s", MAX_NODE_ID, got);
    ids[i] = (fcm_index)x;
    fcm__scene_path_pop(p, old);
  }
  qsort(ids, (size_t)n, sizeof *ids, cmp_index);
  for (i = 1; i < n; i++)
    SCENE_CHECK(ids[i] != ids[i - 1], p, FCM_ERR_ARG,
                "expected distinct node ids, got %lld more than once", (long long)ids[i]);
  r->kind = FCM_REGION_NODES;
  r->num_nodes = n;
  r->nodes = ids;
cleanup:
  return st;
}

fcm_status fcm__scene_read_region(fcm__scene_parser *p, const fcm__json *obj, const char *key,
                                  int required, int allow_nodes, fcm_region *out)
{
  fcm_status st = FCM_OK;
  const fcm__json *v = NULL;
  static const char *const kinds[] = {"box", "half_space", "nodes"};
  size_t old = p->path_len;
  fcm_region r;
  memset(&r, 0, sizeof r);
  r.kind = FCM_REGION_ALL;
  r.tolerance = 1e-9;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, obj, key, required, &v));
  if (!v) {
    *out = r;
    return FCM_OK;
  }
  fcm__scene_path_push_key(p, key);
  FCM_TRY(p->ctx, fcm__scene_check_object(p, v, kinds, allow_nodes ? 3 : 2));
  SCENE_CHECK(fcm__json_size(v) == 1, p, FCM_ERR_ARG,
              "expected an object with exactly one of %s, got %d keys",
              allow_nodes ? "\"box\", \"half_space\", \"nodes\"" : "\"box\", \"half_space\"",
              fcm__json_size(v));
  const fcm__json *c = fcm__json_child(v);
  const char *kind = fcm__json_key(c);
  size_t o = fcm__scene_path_push_key(p, kind);
  if (!strcmp(kind, "box"))
    FCM_TRY(p->ctx, read_box(p, c, &r));
  else if (!strcmp(kind, "half_space"))
    FCM_TRY(p->ctx, read_half_space(p, c, &r));
  else
    FCM_TRY(p->ctx, read_nodes(p, c, &r));
  fcm__scene_path_pop(p, o);
  *out = r;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

void fcm__scene_region_view(const fcm_region *r, FILE *f)
{
  switch (r->kind) {
  case FCM_REGION_ALL:
    fprintf(f, "the whole body");
    break;
  case FCM_REGION_BOX:
    fprintf(f, "box [%g, %g] x [%g, %g] x [%g, %g] (tol %g)", r->min[0], r->max[0], r->min[1],
            r->max[1], r->min[2], r->max[2], r->tolerance);
    break;
  case FCM_REGION_HALF_SPACE:
    fprintf(f, "half-space (x - (%g, %g, %g)) . (%g, %g, %g) >= 0 (tol %g)", r->point[0],
            r->point[1], r->point[2], r->normal[0], r->normal[1], r->normal[2], r->tolerance);
    break;
  case FCM_REGION_NODES:
    fprintf(f, "%lld nodes (ids %lld..%lld)", (long long)r->num_nodes, (long long)r->nodes[0],
            (long long)r->nodes[r->num_nodes - 1]);
    break;
  }
}

/* ---------------------------------------------------------------- time windows */

/* "start" (>= 0, default 0) and "end" (> start, default HUGE_VAL). */
static fcm_status read_window(fcm__scene_parser *p, const fcm__json *obj, double *start,
                              double *end)
{
  fcm_status st = FCM_OK;
  *start = 0.0;
  *end = HUGE_VAL;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, obj, "start", 0, FCM__NONNEGATIVE, start));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, obj, "end", 0, (fcm__range){*start, HUGE_VAL, 1, 1}, end));
cleanup:
  return st;
}

static void view_window(double start, double end, FILE *f)
{
  if (end < HUGE_VAL)
    fprintf(f, ", t in [%g, %g] s", start, end);
  else if (start > 0.0)
    fprintf(f, ", from t = %g s", start);
}

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

/* A rigid motion's "velocity", "rotation" {"axis", "center", "speed"} and window ("start",
 * "end") into m (its other members untouched). */
static fcm_status read_rigid_motion(fcm__scene_parser *p, const fcm__json *o, fcm_motion *m)
{
  fcm_status st = FCM_OK;
  static const char *const rkeys[] = {"axis", "center", "speed"};
  const fcm__json *rot = NULL;
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "velocity", 0, FCM__ANY, m->velocity));
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "rotation", 0, &rot));
  if (rot) {
    size_t old = fcm__scene_path_push_key(p, "rotation");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, rot, rkeys, COUNT(rkeys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, rot, "axis", 0, FCM__ANY, m->axis));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, rot, "center", 0, FCM__ANY, m->center));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, rot, "speed", 1, FCM__ANY, &m->angular_speed));
    double n = sqrt(m->axis[0] * m->axis[0] + m->axis[1] * m->axis[1] + m->axis[2] * m->axis[2]);
    fcm__scene_path_push_key(p, "axis");
    SCENE_CHECK(n > 0.0 && isfinite(n), p, FCM_ERR_ARG,
                "expected a non-zero vector, got (%g, %g, %g)", m->axis[0], m->axis[1], m->axis[2]);
    for (int d = 0; d < 3; d++)
      m->axis[d] /= n;
    fcm__scene_path_pop(p, old);
  }
  FCM_TRY(p->ctx, read_window(p, o, &m->start, &m->end));
cleanup:
  return st;
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
  FCM_TRY(p->ctx, read_rigid_motion(p, o, m));
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
  view_window(m->start, m->end, f);
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
  FCM_TRY(p->ctx, read_window(p, o, &t->start, &t->end));
cleanup:
  return st;
}

static void view_traction(const fcm_effect *e, FILE *f)
{
  const fcm_effect_traction *t = &e->traction;
  fprintf(f, "(%g, %g, %g) Pa", t->traction[0], t->traction[1], t->traction[2]);
  view_window(t->start, t->end, f);
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
  FCM_TRY(p->ctx, read_window(p, o, &q->start, &q->end));
cleanup:
  return st;
}

static void view_pressure(const fcm_effect *e, FILE *f)
{
  const fcm_effect_pressure *q = &e->pressure;
  fprintf(f, "%g Pa", q->pressure);
  view_window(q->start, q->end, f);
  fprintf(f, "; on the boundary in ");
  fcm__scene_region_view(&q->region, f);
}

/* A unit vector at member `key` (required). */
static fcm_status read_unit(fcm__scene_parser *p, const fcm__json *o, const char *key, double v[3])
{
  fcm_status st = FCM_OK;
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, key, 1, FCM__ANY, v));
  const double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  size_t old = fcm__scene_path_push_key(p, key);
  SCENE_CHECK(n > 0.0 && isfinite(n), p, FCM_ERR_ARG,
              "expected a non-zero vector, got (%g, %g, %g)", v[0], v[1], v[2]);
  fcm__scene_path_pop(p, old);
  for (int d = 0; d < 3; d++)
    v[d] /= n;
cleanup:
  return st;
}

static fcm_status parse_cut(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"time", "surface"};
  static const char *const forms[] = {"plane", "rectangle", "disc", "mesh"};
  static const char *const plane_keys[] = {"point", "normal", "transform"};
  static const char *const rect_keys[] = {"center", "normal", "axis", "size", "transform"};
  static const char *const disc_keys[] = {"center", "normal", "radius", "segments", "transform"};
  fcm_effect_cut *c = &e->cut;
  const fcm__json *sf = NULL, *f = NULL;
  const double duration = p->scene->time.duration;
  memset(c, 0, sizeof *c);
  for (int i = 0; i < 9; i++)
    c->transform[i] = (i % 4 == 0);
  c->segments = 64;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "time", 0, (fcm__range){0.0, duration, 0, 0}, &c->time));
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "surface", 1, &sf));
  size_t old = fcm__scene_path_push_key(p, "surface");
  SCENE_CHECK(fcm__json_size(sf) == 1, p, FCM_ERR_ARG,
              "expected an object with one key naming the form (\"plane\", \"rectangle\", "
              "\"disc\" or \"mesh\"), got %d keys",
              (int)fcm__json_size(sf));
  FCM_TRY(p->ctx, fcm__scene_check_object(p, sf, forms, COUNT(forms)));
  if (fcm__json_member(sf, "mesh")) {
    c->kind = FCM_CUT_MESH;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, sf, "mesh", 1, NULL, &c->mesh));
  } else {
    const char *name = fcm__json_member(sf, "plane")       ? "plane"
                       : fcm__json_member(sf, "rectangle") ? "rectangle"
                                                           : "disc";
    FCM_TRY(p->ctx, fcm__scene_read_object(p, sf, name, 1, &f));
    size_t o2 = fcm__scene_path_push_key(p, name);
    if (!strcmp(name, "plane")) {
      c->kind = FCM_CUT_PLANE;
      FCM_TRY(p->ctx, fcm__scene_check_object(p, f, plane_keys, COUNT(plane_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, f, "point", 1, FCM__ANY, c->point));
      FCM_TRY(p->ctx, read_unit(p, f, "normal", c->normal));
    } else if (!strcmp(name, "rectangle")) {
      c->kind = FCM_CUT_RECTANGLE;
      FCM_TRY(p->ctx, fcm__scene_check_object(p, f, rect_keys, COUNT(rect_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, f, "center", 1, FCM__ANY, c->point));
      FCM_TRY(p->ctx, read_unit(p, f, "normal", c->normal));
      FCM_TRY(p->ctx, read_unit(p, f, "axis", c->axis));
      const double dot =
          c->axis[0] * c->normal[0] + c->axis[1] * c->normal[1] + c->axis[2] * c->normal[2];
      size_t o3 = fcm__scene_path_push_key(p, "axis");
      SCENE_CHECK(fabs(dot) < 1.0 - 1e-9, p, FCM_ERR_ARG,
                  "expected a direction not parallel to the normal, got (%g, %g, %g)", c->axis[0],
                  c->axis[1], c->axis[2]);
      fcm__scene_path_pop(p, o3);
      const fcm__json *sz = NULL;
      FCM_TRY(p->ctx, fcm__scene_field(p, f, "size", 1, "an array of 2 numbers > 0 [a, b]",
                                       FCM__JSON_ARRAY, 2, &sz));
      const fcm__json *v = fcm__json_child(sz);
      for (int k = 0; k < 2; k++, v = fcm__json_next(v)) {
        c->size[k] = fcm__json_get_kind(v) == FCM__JSON_NUMBER ? fcm__json_number(v) : -1.0;
        SCENE_CHECK(isfinite(c->size[k]) && c->size[k] > 0.0, p, FCM_ERR_ARG,
                    "expected an array of 2 numbers > 0 [a, b]; entry %d is not", k);
      }
      fcm__scene_path_pop(p, o3);
    } else {
      long long seg = 64;
      c->kind = FCM_CUT_DISC;
      FCM_TRY(p->ctx, fcm__scene_check_object(p, f, disc_keys, COUNT(disc_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, f, "center", 1, FCM__ANY, c->point));
      FCM_TRY(p->ctx, read_unit(p, f, "normal", c->normal));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, f, "radius", 1, FCM__POSITIVE, &c->radius));
      FCM_TRY(p->ctx, fcm__scene_read_int(p, f, "segments", 0, 3, 256, &seg));
      c->segments = (int)seg;
    }
    FCM_TRY(p->ctx, fcm__scene_read_transform(p, f, c->transform, c->offset, &c->has_transform));
    fcm__scene_path_pop(p, o2);
  }
  fcm__scene_path_pop(p, old);
cleanup:
  return st;
}

static void view_cut(const fcm_effect *e, FILE *f)
{
  const fcm_effect_cut *c = &e->cut;
  const double *q = c->point, *n = c->normal;
  fprintf(f, "at t = %g s: ", c->time);
  switch (c->kind) {
  case FCM_CUT_PLANE:
    fprintf(f, "plane through (%g, %g, %g), normal (%g, %g, %g)", q[0], q[1], q[2], n[0], n[1],
            n[2]);
    break;
  case FCM_CUT_RECTANGLE:
    fprintf(f, "rectangle %g x %g at (%g, %g, %g), normal (%g, %g, %g), axis (%g, %g, %g)",
            c->size[0], c->size[1], q[0], q[1], q[2], n[0], n[1], n[2], c->axis[0], c->axis[1],
            c->axis[2]);
    break;
  case FCM_CUT_DISC:
    fprintf(f, "disc of radius %g (%d segments) at (%g, %g, %g), normal (%g, %g, %g)", c->radius,
            c->segments, q[0], q[1], q[2], n[0], n[1], n[2]);
    break;
  case FCM_CUT_MESH:
    fprintf(f, "mesh %s", c->mesh);
    break;
  }
  if (c->has_transform) fprintf(f, " (transformed)");
}

static fcm_status parse_contact(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {
      "plane",    "sphere",    "box",      "surface",           "bodies",
      "distance", "stiffness", "friction", "friction_velocity", "friction_updates",
      "self"};
  static const char *const plane_keys[] = {"point", "normal", "velocity"};
  static const char *const sphere_keys[] = {"center",   "radius", "velocity",
                                            "rotation", "start",  "end"};
  static const char *const box_keys[] = {"min", "max", "velocity", "rotation", "start", "end"};
  static const char *const surface_keys[] = {"mesh", "velocity", "rotation", "start", "end"};
  fcm_effect_contact *c = &e->contact;
  const fcm__json *ob = NULL;
  const char *kind = NULL;
  int count = 0;
  memset(c, 0, sizeof *c);
  c->options = fcm_contact_options_default();
  c->motion = fcm_motion_default();
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, COUNT(keys)));
  for (int k = 0; k < 5; k++)
    if (fcm__json_member(o, keys[k])) {
      count++;
      kind = keys[k];
      c->obstacle = (fcm_contact_obstacle)k;
    }
  SCENE_CHECK(count == 1, p, FCM_ERR_ARG,
              "expected exactly one obstacle of \"plane\", \"sphere\", \"box\", \"surface\", "
              "or \"bodies\", got %d",
              count);
  if (c->obstacle == FCM_CONTACT_BODIES) {
    int on = 0;
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "bodies", 1, &on));
    size_t old = fcm__scene_path_push_key(p, "bodies");
    SCENE_CHECK(on, p, FCM_ERR_ARG,
                "expected true (contact between the bodies and cut pieces; leave the effect out "
                "for none), got false");
    fcm__scene_path_pop(p, old);
    goto options;
  }
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, kind, 1, &ob));
  size_t old = fcm__scene_path_push_key(p, kind);
  switch (c->obstacle) {
  case FCM_CONTACT_PLANE:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, ob, plane_keys, COUNT(plane_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, ob, "point", 1, FCM__ANY, c->point));
    FCM_TRY(p->ctx, read_unit(p, ob, "normal", c->normal));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, ob, "velocity", 0, FCM__ANY, c->velocity));
    break;
  case FCM_CONTACT_SPHERE:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, ob, sphere_keys, COUNT(sphere_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, ob, "center", 1, FCM__ANY, c->center));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, ob, "radius", 1, FCM__POSITIVE, &c->radius));
    break;
  case FCM_CONTACT_BOX:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, ob, box_keys, COUNT(box_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, ob, "min", 1, FCM__ANY, c->min));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, ob, "max", 1, FCM__ANY, c->max));
    {
      size_t o2 = fcm__scene_path_push_key(p, "max");
      for (int i = 0; i < 3; i++)
        SCENE_CHECK(c->max[i] > c->min[i], p, FCM_ERR_ARG,
                    "expected each component above \"min\"'s, got %g <= %g in component %d",
                    c->max[i], c->min[i], i);
      fcm__scene_path_pop(p, o2);
    }
    break;
  default:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, ob, surface_keys, COUNT(surface_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_file(p, ob, "mesh", 1, NULL, &c->mesh));
    break;
  }
  if (c->obstacle != FCM_CONTACT_PLANE) FCM_TRY(p->ctx, read_rigid_motion(p, ob, &c->motion));
  fcm__scene_path_pop(p, old);
options:
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "distance", 0, FCM__NONNEGATIVE, &c->options.distance));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "stiffness", 0, FCM__NONNEGATIVE, &c->options.stiffness));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "friction", 0, FCM__NONNEGATIVE, &c->options.friction));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "friction_velocity", 0, FCM__NONNEGATIVE,
                                         &c->options.friction_velocity));
  {
    long long updates = 0;
    FCM_TRY(p->ctx, fcm__scene_read_int(p, o, "friction_updates", 0, 0, 20, &updates));
    c->options.friction_updates = (int)updates;
  }
  {
    int self = 0;
    FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "self", 0, &self));
    size_t o4 = fcm__scene_path_push_key(p, "self");
    SCENE_CHECK(!self || c->obstacle == FCM_CONTACT_BODIES, p, FCM_ERR_ARG,
                "expected false or absent with \"%s\" (self-contact is an option of "
                "\"bodies\"), got true",
                kind);
    fcm__scene_path_pop(p, o4);
    c->options.self_contact = self;
  }
cleanup:
  return st;
}

static void view_contact(const fcm_effect *e, FILE *f)
{
  const fcm_effect_contact *c = &e->contact;
  const fcm_motion *m = &c->motion;
  switch (c->obstacle) {
  case FCM_CONTACT_PLANE: {
    const double *q = c->point, *n = c->normal, *v = c->velocity;
    fprintf(f, "plane through (%g, %g, %g), normal (%g, %g, %g), velocity (%g, %g, %g) m/s", q[0],
            q[1], q[2], n[0], n[1], n[2], v[0], v[1], v[2]);
    break;
  }
  case FCM_CONTACT_SPHERE:
    fprintf(f, "sphere at (%g, %g, %g), radius %g m", c->center[0], c->center[1], c->center[2],
            c->radius);
    break;
  case FCM_CONTACT_BOX:
    fprintf(f, "box (%g, %g, %g) to (%g, %g, %g)", c->min[0], c->min[1], c->min[2], c->max[0],
            c->max[1], c->max[2]);
    break;
  case FCM_CONTACT_BODIES:
    fprintf(f, "between the bodies and cut pieces");
    if (c->options.self_contact) fprintf(f, ", self-contact of each body");
    break;
  default:
    fprintf(f, "surface %s", c->mesh);
    break;
  }
  if (c->obstacle != FCM_CONTACT_PLANE && c->obstacle != FCM_CONTACT_BODIES) {
    fprintf(f, ", velocity (%g, %g, %g) m/s", m->velocity[0], m->velocity[1], m->velocity[2]);
    if (m->angular_speed != 0.0)
      fprintf(f, ", rotation %g rad/s about (%g, %g, %g) through (%g, %g, %g)", m->angular_speed,
              m->axis[0], m->axis[1], m->axis[2], m->center[0], m->center[1], m->center[2]);
    view_window(m->start, m->end, f);
  }
  if (c->options.distance > 0.0)
    fprintf(f, ", threshold %g m", c->options.distance);
  else
    fprintf(f, ", threshold 0.1 h");
  if (c->options.stiffness > 0.0)
    fprintf(f, ", stiffness %g Pa/m", c->options.stiffness);
  else
    fprintf(f, ", stiffness E / h");
  if (c->options.friction > 0.0)
    fprintf(f, ", friction %g (smoothed below %g m/s)", c->options.friction,
            c->options.friction_velocity > 0.0 ? c->options.friction_velocity : 1e-3);
  if (c->options.friction > 0.0 && c->options.friction_updates > 0)
    fprintf(f, ", up to %d friction updates per substep", c->options.friction_updates);
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
     .parse = parse_cut,
     .view = view_cut},
    {.type = FCM_EFFECT_CONTACT,
     .name = "contact",
     .summary = "a rigid plane obstacle, static or moving (log barrier on the embedded surface)",
     .allowed_static = 1, /* the body must start within d^ of obstacles holding it */
     .parse = parse_contact,
     .view = view_contact,
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
