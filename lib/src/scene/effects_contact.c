/* The effects that add surfaces the body meets: the cut effect (a plane, rectangle, disc
 * or mesh inserted at a time, along which the body separates) and the contact effect (a
 * plane, sphere, box or surface obstacle, or contact between the bodies), with their
 * parsers/validators and one-line printers. They share the unit-vector reader and are the
 * largest parsers of the effect table, so they live apart from the loads and constraints
 * of effects.c, which lists them in the table. */
#include "scene/scene_impl.h"

#include <string.h>

#define COUNT(a) ((int)(sizeof(a) / sizeof *(a)))

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

fcm_status fcm__effect_parse_cut(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
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

void fcm__effect_view_cut(const fcm_effect *e, FILE *f)
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

fcm_status fcm__effect_parse_contact(fcm__scene_parser *p, const fcm__json *o, fcm_effect *e)
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
  if (c->obstacle != FCM_CONTACT_PLANE)
    FCM_TRY(p->ctx, fcm__scene_read_rigid_motion(p, ob, &c->motion));
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

void fcm__effect_view_contact(const fcm_effect *e, FILE *f)
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
    fcm__scene_view_window(m->start, m->end, f);
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
