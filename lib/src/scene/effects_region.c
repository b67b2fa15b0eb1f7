/* Where and when an effect acts: regions (boxes, half-spaces, node sets) with their
 * parsing, membership test and printing; time windows ("start", "end"); and rigid motions
 * (velocity, rotation about an axis, window) shared by the motion effect and the moving
 * contact obstacles. These readers are the building blocks of the effect parsers in
 * effects.c and effects_contact.c, kept apart from the effect table itself. */
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
fcm_status fcm__scene_read_window(fcm__scene_parser *p, const fcm__json *obj, double *start,
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

void fcm__scene_view_window(double start, double end, FILE *f)
{
  if (end < HUGE_VAL)
    fprintf(f, ", t in [%g, %g] s", start, end);
  else if (start > 0.0)
    fprintf(f, ", from t = %g s", start);
}

/* A rigid motion's "velocity", "rotation" {"axis", "center", "speed"} and window ("start",
 * "end") into m (its other members untouched). */
fcm_status fcm__scene_read_rigid_motion(fcm__scene_parser *p, const fcm__json *o, fcm_motion *m)
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
  FCM_TRY(p->ctx, fcm__scene_read_window(p, o, &m->start, &m->end));
cleanup:
  return st;
}
