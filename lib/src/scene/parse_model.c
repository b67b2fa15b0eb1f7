/* Scene sections of what is simulated: "background" (a grid or a Gmsh mesh), "geometry" (shapes,
 * meshes, surfaces, voxels, level sets, transforms) and "material". */
#define _POSIX_C_SOURCE 200809L
#include "geom/geom_impl.h"
#include "scene/scene_impl.h"

#include <string.h>

static const char *const model_names[] = {
    "linear", "stvk", "corotated", "snh", "stable_neo_hookean", "corotated_linear"};
static const fcm_material_model model_values[] = {FCM_MATERIAL_LINEAR,
                                                  FCM_MATERIAL_STVK,
                                                  FCM_MATERIAL_COROTATED,
                                                  FCM_MATERIAL_STABLE_NEO_HOOKEAN,
                                                  FCM_MATERIAL_STABLE_NEO_HOOKEAN,
                                                  FCM_MATERIAL_COROTATED_LINEAR};
static const char *const shape_names[] = {"box", "ball", "hemisphere", "hollow_ball", "tube"};

/* ---------------------------------------------------------------- background */

/* The required "min" and "max" of obj, with min[d] < max[d] (checked at the current path). */
static fcm_status read_min_max(fcm__scene_parser *p, const fcm__json *obj, double min[3],
                               double max[3])
{
  fcm_status st = FCM_OK;
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, obj, "min", 1, FCM__ANY, min));
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, obj, "max", 1, FCM__ANY, max));
  for (int d = 0; d < 3; d++)
    SCENE_CHECK(min[d] < max[d], p, FCM_ERR_ARG,
                "expected min[%d] < max[%d], got min[%d] = %g >= max[%d] = %g", d, d, d, min[d], d,
                max[d]);
cleanup:
  return st;
}

/* "fit_background": {"cell_size": h, "margin": m}: a grid of cubes of edge h around the
 * geometry's bounding box grown by m on every side, placed when the simulation is built. */
static fcm_status read_fit_background(fcm__scene_parser *p, const fcm__json *o,
                                      fcm_scene_background *b)
{
  fcm_status st = FCM_OK;
  static const char *const fit_keys[] = {"cell_size", "margin"};
  static const char *const excluded[] = {"box", "cells", "mesh"};
  const fcm__json *fit = NULL;
  size_t old = p->path_len;
  for (int i = 0; i < SCENE_COUNT(excluded); i++) {
    if (!fcm__json_member(o, excluded[i])) continue;
    fcm__scene_path_push_key(p, excluded[i]);
    SCENE_CHECK(0, p, FCM_ERR_ARG,
                "not allowed with \"fit_background\" (which places the grid around the "
                "geometry: give either \"fit_background\" or \"box\" and \"cells\")");
  }
  b->kind = FCM_SCENE_BACKGROUND_GRID;
  b->fit = 1;
  SCENE_READ_CHOICE(p, o, "element", 1, fcm__scene_element_names, b->element);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "fit_background", 1, &fit));
  SCENE_ENTER(p, "fit_background");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, fit, fit_keys, SCENE_COUNT(fit_keys)));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, fit, "cell_size", 1, FCM__POSITIVE, &b->fit_cell_size));
  b->fit_margin = b->fit_cell_size;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, fit, "margin", 0, FCM__NONNEGATIVE, &b->fit_margin));
  b->cells[0] = b->cells[1] = b->cells[2] = 1;
  b->max[0] = b->max[1] = b->max[2] = 1.0;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "octree": {"boundary": {"level": L}, "region": {"min", "max", "level": L}, "cuts": {"level":
 * L, "when": "setup" | "cut"}}: the grid refined as an octree along the embedded boundary, in a
 * box and along the cut effects' surfaces (at set-up, or during the run when the first cut
 * applies). */
static fcm_status read_octree(fcm__scene_parser *p, const fcm__json *o, fcm_scene_background *b)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"boundary", "region", "cuts"};
  static const char *const bkeys[] = {"level"};
  static const char *const rkeys[] = {"min", "max", "level"};
  static const char *const ckeys[] = {"level", "when"};
  static const char *const when[] = {"setup", "cut"};
  const fcm__json *oct = NULL, *bnd = NULL, *reg = NULL, *cuts = NULL;
  long long level = 0;
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "octree", 0, &oct));
  if (!oct) return FCM_OK;
  SCENE_ENTER(p, "octree");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, oct, keys, SCENE_COUNT(keys)));
  SCENE_CHECK(fcm__json_member(oct, "boundary") || fcm__json_member(oct, "region") ||
                  fcm__json_member(oct, "cuts"),
              p, FCM_ERR_ARG,
              "expected at least one refinement criterion: \"boundary\" ({\"level\": L}, "
              "along the embedded boundary), \"region\" ({\"min\", \"max\", \"level\"}) or "
              "\"cuts\" ({\"level\": L}, along the cut effects' surfaces)");
  b->octree = 1;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, oct, "boundary", 0, &bnd));
  if (bnd) {
    size_t o2 = SCENE_ENTER(p, "boundary");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, bnd, bkeys, SCENE_COUNT(bkeys)));
    FCM_TRY(p->ctx, fcm__scene_read_int(p, bnd, "level", 1, 1, FCM_OCTREE_MAX_LEVEL, &level));
    b->octree_boundary = (int)level;
    fcm__scene_path_pop(p, o2);
  }
  FCM_TRY(p->ctx, fcm__scene_read_object(p, oct, "region", 0, &reg));
  if (reg) {
    size_t o2 = SCENE_ENTER(p, "region");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, reg, rkeys, SCENE_COUNT(rkeys)));
    FCM_TRY(p->ctx, read_min_max(p, reg, b->octree_region_min, b->octree_region_max));
    FCM_TRY(p->ctx, fcm__scene_read_int(p, reg, "level", 1, 1, FCM_OCTREE_MAX_LEVEL, &level));
    b->octree_region = (int)level;
    fcm__scene_path_pop(p, o2);
  }
  FCM_TRY(p->ctx, fcm__scene_read_object(p, oct, "cuts", 0, &cuts));
  if (cuts) {
    size_t o2 = SCENE_ENTER(p, "cuts");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, cuts, ckeys, SCENE_COUNT(ckeys)));
    FCM_TRY(p->ctx, fcm__scene_read_int(p, cuts, "level", 1, 1, FCM_OCTREE_MAX_LEVEL, &level));
    b->octree_cuts = (int)level;
    b->octree_cuts_at_cut = 0;
    FCM_TRY(p->ctx, fcm__scene_read_choice(p, cuts, "when", 0, when, SCENE_COUNT(when),
                                           &b->octree_cuts_at_cut));
    fcm__scene_path_pop(p, o2);
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_background(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"element", "box", "cells", "mesh", "fit_background", "octree"};
  static const char *const box_keys[] = {"min", "max"};
  fcm_scene_background *b = &p->scene->background;
  const fcm__json *o = NULL, *box = NULL;
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "background", 1, &o));
  SCENE_ENTER(p, "background");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
  if (fcm__json_member(o, "fit_background")) {
    FCM_TRY(p->ctx, read_fit_background(p, o, b));
    FCM_TRY(p->ctx, read_octree(p, o, b));
    goto cleanup;
  }
  if (fcm__json_member(o, "mesh")) {
    for (int i = 0; i < 3; i++) {
      if (!fcm__json_member(o, keys[i])) continue;
      fcm__scene_path_push_key(p, keys[i]);
      SCENE_CHECK(0, p, FCM_ERR_ARG,
                  "not allowed with \"mesh\" (the mesh file sets the element type and cells)");
    }
    if (fcm__json_member(o, "octree")) {
      fcm__scene_path_push_key(p, "octree");
      SCENE_CHECK(0, p, FCM_ERR_ARG,
                  "not allowed with \"mesh\" (an octree refines a generated grid: give \"box\" "
                  "and \"cells\" or \"fit_background\")");
    }
    b->kind = FCM_SCENE_BACKGROUND_MESH;
    b->element = FCM_ELEMENT_COUNT;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "mesh", 1, NULL, &b->mesh));
    goto cleanup;
  }
  SCENE_CHECK(fcm__json_member(o, "box"), p, FCM_ERR_ARG,
              "expected either \"box\" (with \"element\" and \"cells\") for a generated grid, "
              "\"fit_background\" (with \"element\") for a grid around the geometry, "
              "or \"mesh\" (a Gmsh file)");
  b->kind = FCM_SCENE_BACKGROUND_GRID;
  SCENE_READ_CHOICE(p, o, "element", 1, fcm__scene_element_names, b->element);
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "box", 1, &box));
  {
    size_t o2 = SCENE_ENTER(p, "box");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, box, box_keys, SCENE_COUNT(box_keys)));
    FCM_TRY(p->ctx, read_min_max(p, box, b->min, b->max));
    fcm__scene_path_pop(p, o2);
  }
  FCM_TRY(p->ctx, fcm__scene_read_ivec3(p, o, "cells", 1, 1, 1000000, b->cells));
  {
    const size_t in_background = p->path_len;
    double total = (double)b->cells[0] * (double)b->cells[1] * (double)b->cells[2];
    fcm__scene_path_push_key(p, "cells");
    SCENE_CHECK(total <= 1e8, p, FCM_ERR_ARG, "expected at most 1e8 cells in total, got %.0f",
                total);
    fcm__scene_path_pop(p, in_background);
  }
  FCM_TRY(p->ctx, read_octree(p, o, b));
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- geometry */

fcm_status fcm__scene_read_transform(fcm__scene_parser *p, const fcm__json *o, double A[9],
                                     double b[3], int *has)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"scale", "rotation", "translation"};
  static const char *const rkeys[] = {"axis", "angle"};
  const fcm__json *t = NULL, *rot = NULL;
  double scale[3] = {1, 1, 1}, axis[3] = {0, 0, 1}, angle = 0.0, offset[3] = {0, 0, 0};
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, o, "transform", 0, &t));
  if (!t) return FCM_OK;
  SCENE_ENTER(p, "transform");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, t, keys, SCENE_COUNT(keys)));
  const fcm__json *sc = fcm__json_member(t, "scale");
  if (sc && fcm__json_get_kind(sc) == FCM__JSON_NUMBER) {
    FCM_TRY(p->ctx, fcm__scene_read_number(p, t, "scale", 1, FCM__POSITIVE, &scale[0]));
    scale[1] = scale[2] = scale[0];
  } else {
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, t, "scale", 0, FCM__POSITIVE, scale));
  }
  FCM_TRY(p->ctx, fcm__scene_read_object(p, t, "rotation", 0, &rot));
  if (rot) {
    size_t o2 = SCENE_ENTER(p, "rotation");
    FCM_TRY(p->ctx, fcm__scene_check_object(p, rot, rkeys, SCENE_COUNT(rkeys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, rot, "axis", 1, FCM__ANY, axis));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, rot, "angle", 1, FCM__ANY, &angle));
    double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    fcm__scene_path_push_key(p, "axis");
    SCENE_CHECK(n > 0.0 && isfinite(n), p, FCM_ERR_ARG,
                "expected a non-zero vector, got (%g, %g, %g)", axis[0], axis[1], axis[2]);
    for (int d = 0; d < 3; d++)
      axis[d] /= n;
    fcm__scene_path_pop(p, o2);
  }
  FCM_TRY(p->ctx, fcm__scene_read_vec3(p, t, "translation", 0, FCM__ANY, offset));
  /* A = R(axis, angle) diag(scale): Rodrigues' formula, column j scaled by scale[j]. */
  double c = cos(angle), s = sin(angle), *a = axis;
  double R[9] = {c + a[0] * a[0] * (1 - c),        a[0] * a[1] * (1 - c) - a[2] * s,
                 a[0] * a[2] * (1 - c) + a[1] * s, a[1] * a[0] * (1 - c) + a[2] * s,
                 c + a[1] * a[1] * (1 - c),        a[1] * a[2] * (1 - c) - a[0] * s,
                 a[2] * a[0] * (1 - c) - a[1] * s, a[2] * a[1] * (1 - c) + a[0] * s,
                 c + a[2] * a[2] * (1 - c)};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      A[3 * i + j] = R[3 * i + j] * scale[j];
  memcpy(b, offset, sizeof offset);
  *has = 1;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "surface": a triangle surface file tetrahedralized when the simulation is built. */
static fcm_status read_surface_geometry(fcm__scene_parser *p, const fcm__json *o,
                                        fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {
      "surface",        "max_volume",         "size",      "quality",    "fill_holes",
      "max_hole_edges", "max_hole_perimeter", "transform", "volume_mesh"};
  static const char *const exts[] = {".obj", ".off", ".stl", ".ply"};
  size_t old = p->path_len;
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
  g->kind = FCM_SCENE_GEOMETRY_SURFACE;
  FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "surface", 1, NULL, &g->mesh));
  {
    size_t n = strlen(g->mesh);
    int known = 0;
    for (int i = 0; i < SCENE_COUNT(exts); i++) {
      size_t e = strlen(exts[i]);
      int eq = n >= e;
      for (size_t k = 0; eq && k < e; k++) {
        char c = g->mesh[n - e + k];
        eq = (c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c) == exts[i][k];
      }
      known |= eq;
    }
    fcm__scene_path_push_key(p, "surface");
    SCENE_CHECK(known, p, FCM_ERR_ARG,
                "expected a file ending in .obj, .off, .stl or .ply, got '%s'", g->mesh);
    fcm__scene_path_pop(p, old);
  }
  g->surface = fcm_surface_mesh_options_default();
  g->fill = fcm_surface_fill_options_default();
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "max_volume", 0, FCM__NONNEGATIVE, &g->surface.max_volume));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "size", 0, FCM__NONNEGATIVE, &g->surface.size));
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "quality", 0, (fcm__range){0.0, 1.0, 0, 0},
                                         &g->surface.quality));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "fill_holes", 0, &g->fill_holes));
  g->surface.volume_mesh = -1; /* "auto": only for a scene that cuts */
  FCM_TRY(p->ctx, fcm__scene_read_bool_or_word(p, o, "volume_mesh", 0, "auto", -1,
                                               &g->surface.volume_mesh));
  long long me = 0;
  FCM_TRY(p->ctx, fcm__scene_read_int(p, o, "max_hole_edges", 0, 0, 1000000000, &me));
  g->fill.max_edges = (fcm_index)me;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "max_hole_perimeter", 0, FCM__NONNEGATIVE,
                                         &g->fill.max_perimeter));
  if (!g->fill_holes) {
    static const char *const fill_keys[] = {"max_hole_edges", "max_hole_perimeter"};
    for (int i = 0; i < SCENE_COUNT(fill_keys); i++) {
      fcm__scene_forget(p, fill_keys[i]); /* the defaults apply to filling only */
      if (!fcm__json_member(o, fill_keys[i])) continue;
      fcm__scene_path_push_key(p, fill_keys[i]);
      SCENE_CHECK(0, p, FCM_ERR_ARG, "only used with \"fill_holes\": true");
    }
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* One implicit (an object with one member named by its kind) at the current path into
 * nodes[*n ...]; *root is the index of its node. CSG arrays of k >= 2 operands fold left:
 * ((a op b) op c) ... */
static fcm_status read_implicit(fcm__scene_parser *p, const fcm__json *node, double h,
                                fcm_implicit *nodes, int *n, int *root)
{
  fcm_status st = FCM_OK;
  static const char *const sphere_keys[] = {"center", "radius"};
  static const char *const torus_keys[] = {"center", "axis", "major_radius", "minor_radius"};
  static const char *const box_keys[] = {"min", "max"};
  static const char *const gyroid_keys[] = {"min", "max", "period", "thickness", "type"};
  static const char *const gyroid_types[] = {"sheet", "solid"};
  size_t old = p->path_len;
  SCENE_CHECK(fcm__json_get_kind(node) == FCM__JSON_OBJECT && fcm__json_size(node) == 1, p,
              FCM_ERR_ARG,
              "expected an object with exactly one member: sphere, torus, box, gyroid, union, "
              "intersection or difference");
  const fcm__json *m = fcm__json_child(node);
  const char *key = fcm__json_key(m);
  int kind = -1;
  for (int k = 0; k < SCENE_COUNT(fcm__scene_implicit_names); k++)
    if (strcmp(key, fcm__scene_implicit_names[k]) == 0) kind = k;
  SCENE_CHECK(kind >= 0, p, FCM_ERR_ARG,
              "unknown implicit \"%.64s\"; expected sphere, torus, box, gyroid, union, "
              "intersection or difference",
              key);
  SCENE_ENTER(p, key);
  fcm_implicit q;
  memset(&q, 0, sizeof q);
  q.kind = (fcm_implicit_kind)kind;
  if (q.kind >= FCM_IMPLICIT_UNION) {
    SCENE_CHECK(fcm__json_get_kind(m) == FCM__JSON_ARRAY && fcm__json_size(m) >= 2, p, FCM_ERR_ARG,
                "expected an array of at least 2 implicits");
    int r = -1, i = 0;
    for (const fcm__json *c = fcm__json_child(m); c; c = fcm__json_next(c), i++) {
      size_t o2 = fcm__scene_path_push_index(p, i);
      int ci = -1;
      FCM_TRY(p->ctx, read_implicit(p, c, h, nodes, n, &ci));
      fcm__scene_path_pop(p, o2);
      if (r < 0) {
        r = ci;
        continue;
      }
      SCENE_CHECK(*n < FCM_IMPLICIT_MAX_NODES, p, FCM_ERR_ARG,
                  "the implicit tree has more than %d nodes", FCM_IMPLICIT_MAX_NODES);
      q.a = r, q.b = ci;
      nodes[*n] = q;
      r = (*n)++;
    }
    *root = r;
  } else {
    SCENE_CHECK(fcm__json_get_kind(m) == FCM__JSON_OBJECT, p, FCM_ERR_ARG,
                "expected an object of parameters");
    SCENE_CHECK(*n < FCM_IMPLICIT_MAX_NODES, p, FCM_ERR_ARG,
                "the implicit tree has more than %d nodes", FCM_IMPLICIT_MAX_NODES);
    switch (q.kind) {
    case FCM_IMPLICIT_SPHERE:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, m, sphere_keys, SCENE_COUNT(sphere_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, m, "center", 0, FCM__ANY, q.center));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "radius", 1, FCM__POSITIVE, &q.radius));
      break;
    case FCM_IMPLICIT_TORUS:
      FCM_TRY(p->ctx, fcm__scene_check_object(p, m, torus_keys, SCENE_COUNT(torus_keys)));
      FCM_TRY(p->ctx, fcm__scene_read_vec3(p, m, "center", 0, FCM__ANY, q.center));
      q.axis = 2;
      SCENE_READ_CHOICE(p, m, "axis", 0, fcm__scene_axis_names, q.axis);
      FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "major_radius", 1, FCM__POSITIVE, &q.radius));
      FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "minor_radius", 1,
                                             (fcm__range){0.0, q.radius, 1, 0}, &q.minor_radius));
      break;
    case FCM_IMPLICIT_BOX:
    case FCM_IMPLICIT_GYROID:
      if (q.kind == FCM_IMPLICIT_BOX)
        FCM_TRY(p->ctx, fcm__scene_check_object(p, m, box_keys, SCENE_COUNT(box_keys)));
      else
        FCM_TRY(p->ctx, fcm__scene_check_object(p, m, gyroid_keys, SCENE_COUNT(gyroid_keys)));
      FCM_TRY(p->ctx, read_min_max(p, m, q.min, q.max));
      if (q.kind == FCM_IMPLICIT_GYROID) {
        int type = 0;
        SCENE_READ_CHOICE(p, m, "type", 0, gyroid_types, type);
        q.sheet = type == 0;
        FCM_TRY(p->ctx, fcm__scene_read_number(p, m, "period", 1, FCM__POSITIVE, &q.period));
        q.thickness = q.sheet ? 0.1 * q.period : 0.0;
        FCM_TRY(p->ctx,
                fcm__scene_read_number(p, m, "thickness", 0,
                                       q.sheet ? (fcm__range){0.0, q.period / 4, 1, 1}
                                               : (fcm__range){-q.period / 4, q.period / 4, 1, 1},
                                       &q.thickness));
      }
      break;
    default:
      break;
    }
    /* a feature below the sampling spacing only samples noise: refused before building */
    char why[512];
    const char *feature;
    if (!fcm__implicit_resolved(&q, h, &feature, why, sizeof why)) {
      if (feature) fcm__scene_path_push_key(p, feature);
      SCENE_CHECK(0, p, FCM_ERR_ARG, "%s", why);
    }
    nodes[*n] = q;
    *root = (*n)++;
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "voxels": the image and its selection. */
static fcm_status read_voxels(fcm__scene_parser *p, const fcm__json *o, fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  size_t old = p->path_len;
  const fcm__json *lab = NULL;
  FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "voxels", 1, NULL, &g->image));
  g->threshold = 0.5;
  g->merge = 1;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "threshold", 0, FCM__ANY, &g->threshold));
  FCM_TRY(p->ctx, fcm__scene_read_bool(p, o, "merge", 0, &g->merge));
  if (fcm__json_member(o, "labels")) fcm__scene_forget(p, "threshold"); /* one or the other */
  FCM_TRY(p->ctx, fcm__scene_field(p, o, "labels", 0, "an array of 1 to 256 numbers",
                                   FCM__JSON_ARRAY, -1, &lab));
  if (lab) {
    const int nl = fcm__json_size(lab);
    SCENE_CHECK(nl >= 1 && nl <= 256, p, FCM_ERR_ARG, "expected 1 to 256 labels, got %d", nl);
    SCENE_CHECK(!fcm__json_member(o, "threshold"), p, FCM_ERR_ARG,
                "give either \"labels\" or \"threshold\", not both");
    double *l = fcm__scene_alloc(p->scene, (size_t)nl, sizeof *l);
    FCM_CHECK(l, p->ctx, FCM_ERR_ALLOC, "scene: out of memory");
    int i = 0;
    for (const fcm__json *c = fcm__json_child(lab); c; c = fcm__json_next(c), i++) {
      SCENE_CHECK(fcm__json_get_kind(c) == FCM__JSON_NUMBER && isfinite(fcm__json_number(c)), p,
                  FCM_ERR_ARG, "labels[%d]: expected a finite number", i);
      l[i] = fcm__json_number(c);
    }
    g->labels = l;
    g->num_labels = nl;
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "level_set": the implicit tree, its sampling box (default: the background grid) and the
 * refinement. */
static fcm_status read_level_set(fcm__scene_parser *p, const fcm__json *o, fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  size_t old = p->path_len;
  fcm_implicit *nodes = fcm__scene_alloc(p->scene, FCM_IMPLICIT_MAX_NODES, sizeof *nodes);
  FCM_CHECK(nodes, p->ctx, FCM_ERR_ALLOC, "scene: out of memory");
  int n = 0, root = -1;
  g->refinement = 4;
  SCENE_READ_INT(p, o, "refinement", 0, 1, 64, g->refinement);
  long long max_subcells = FCM_LEVEL_SET_MAX_SUBCELLS;
  FCM_TRY(p->ctx,
          fcm__scene_read_int(p, o, "max_subcells", 0, 0, (long long)1 << 50, &max_subcells));
  g->max_subcells = (fcm_index)max_subcells;
  const int nbox =
      !!fcm__json_member(o, "min") + !!fcm__json_member(o, "max") + !!fcm__json_member(o, "cells");
  SCENE_CHECK(nbox == 0 || nbox == 3, p, FCM_ERR_ARG,
              "the sampling box of a level set needs all of \"min\", \"max\" and \"cells\" "
              "(or none: the background grid)");
  if (nbox == 3) {
    g->has_box = 1;
    FCM_TRY(p->ctx, read_min_max(p, o, g->min, g->max));
    FCM_TRY(p->ctx, fcm__scene_read_ivec3(p, o, "cells", 1, 1, 10000, g->cells));
  } else {
    const fcm_scene_background *b = &p->scene->background;
    SCENE_CHECK(b->kind == FCM_SCENE_BACKGROUND_GRID && !b->fit &&
                    !fcm__json_member(o, "transform"),
                p, FCM_ERR_ARG,
                "a level set is sampled on the background grid only when the background is a "
                "grid with its box given (not fit_background) and there is no transform; give "
                "\"min\", \"max\" and \"cells\"");
    memcpy(g->min, b->min, sizeof g->min);
    memcpy(g->max, b->max, sizeof g->max);
    memcpy(g->cells, b->cells, sizeof g->cells);
  }
  /* the sampling spacing (fcm_level_set_info.h) every feature of the tree must resolve */
  double h = 0.0;
  for (int d = 0; d < 3; d++)
    h = fmax(h, (g->max[d] - g->min[d]) / ((double)g->cells[d] * g->refinement));
  SCENE_ENTER(p, "level_set");
  FCM_TRY(p->ctx, read_implicit(p, fcm__json_member(o, "level_set"), h, nodes, &n, &root));
  fcm__scene_path_pop(p, old);
  g->implicit = nodes;
  g->num_implicit = n;
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* "shape": a procedural body (box, ball, hemisphere, hollow ball, tube) with its keys. */
static fcm_status read_shape(fcm__scene_parser *p, const fcm__json *o, fcm_scene_geometry *g)
{
  fcm_status st = FCM_OK;
  static const char *const box_keys[] = {"shape", "min", "max", "cells", "transform"};
  static const char *const ball_keys[] = {"shape", "center", "radius", "resolution", "transform"};
  static const char *const hollow_keys[] = {"shape",        "center",      "inner_radius",
                                            "outer_radius", "hole_radius", "resolution",
                                            "layers",       "transform"};
  static const char *const tube_keys[] = {
      "shape",  "center",       "axis",          "inner_radius", "outer_radius",
      "length", "radial_cells", "angular_cells", "axial_cells",  "transform"};
  size_t old = p->path_len;
  int shape = 0;
  FCM_TRY(p->ctx,
          fcm__scene_read_choice(p, o, "shape", 1, shape_names, SCENE_COUNT(shape_names), &shape));
  g->kind = (fcm_scene_geometry_kind)(FCM_SCENE_GEOMETRY_BOX + shape);
  switch (g->kind) {
  case FCM_SCENE_GEOMETRY_BOX:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, box_keys, SCENE_COUNT(box_keys)));
    FCM_TRY(p->ctx, read_min_max(p, o, g->min, g->max));
    g->cells[0] = g->cells[1] = g->cells[2] = 1;
    FCM_TRY(p->ctx, fcm__scene_read_ivec3(p, o, "cells", 0, 1, 10000, g->cells));
    break;
  case FCM_SCENE_GEOMETRY_BALL:
  case FCM_SCENE_GEOMETRY_HEMISPHERE:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, ball_keys, SCENE_COUNT(ball_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, g->center));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "radius", 1, FCM__POSITIVE, &g->radius));
    g->resolution = 4;
    SCENE_READ_INT(p, o, "resolution", 0, 1, 1000, g->resolution);
    break;
  case FCM_SCENE_GEOMETRY_HOLLOW_BALL:
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, hollow_keys, SCENE_COUNT(hollow_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, g->center));
    FCM_TRY(p->ctx,
            fcm__scene_read_number(p, o, "outer_radius", 1, FCM__POSITIVE, &g->outer_radius));
    FCM_TRY(p->ctx,
            fcm__scene_read_number(p, o, "inner_radius", 1,
                                   (fcm__range){0.0, g->outer_radius, 1, 1}, &g->inner_radius));
    FCM_TRY(p->ctx,
            fcm__scene_read_number(p, o, "hole_radius", 0, (fcm__range){0.0, g->outer_radius, 0, 1},
                                   &g->hole_radius));
    g->resolution = 8;
    g->layers = 2;
    SCENE_READ_INT(p, o, "resolution", 0, 1, 1000, g->resolution);
    SCENE_READ_INT(p, o, "layers", 0, 1, 1000, g->layers);
    break;
  default: /* tube */
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, tube_keys, SCENE_COUNT(tube_keys)));
    FCM_TRY(p->ctx, fcm__scene_read_vec3(p, o, "center", 0, FCM__ANY, g->center));
    g->axis = 2;
    SCENE_READ_CHOICE(p, o, "axis", 0, fcm__scene_axis_names, g->axis);
    FCM_TRY(p->ctx,
            fcm__scene_read_number(p, o, "outer_radius", 1, FCM__POSITIVE, &g->outer_radius));
    FCM_TRY(p->ctx,
            fcm__scene_read_number(p, o, "inner_radius", 1,
                                   (fcm__range){0.0, g->outer_radius, 1, 1}, &g->inner_radius));
    FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "length", 1, FCM__POSITIVE, &g->length));
    g->radial_cells = 2;
    g->angular_cells = 24;
    g->axial_cells = 16;
    SCENE_READ_INT(p, o, "radial_cells", 0, 1, 10000, g->radial_cells);
    SCENE_READ_INT(p, o, "angular_cells", 0, 6, 10000, g->angular_cells);
    SCENE_READ_INT(p, o, "axial_cells", 0, 1, 10000, g->axial_cells);
    break;
  }
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

fcm_status fcm__scene_read_geometry(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const any_keys[] = {"shape",
                                         "mesh",
                                         "tetgen",
                                         "transform",
                                         "min",
                                         "max",
                                         "cells",
                                         "center",
                                         "radius",
                                         "resolution",
                                         "inner_radius",
                                         "outer_radius",
                                         "hole_radius",
                                         "layers",
                                         "axis",
                                         "length",
                                         "radial_cells",
                                         "angular_cells",
                                         "axial_cells",
                                         "surface",
                                         "max_volume",
                                         "size",
                                         "quality",
                                         "fill_holes",
                                         "max_hole_edges",
                                         "max_hole_perimeter",
                                         "volume_mesh",
                                         "voxels",
                                         "threshold",
                                         "labels",
                                         "merge",
                                         "level_set",
                                         "refinement",
                                         "max_subcells"};
  static const char *const voxel_keys[] = {"voxels", "threshold", "labels", "merge", "transform"};
  static const char *const level_set_keys[] = {"level_set", "refinement", "max_subcells", "min",
                                               "max",       "cells",      "transform"};
  static const char *const mesh_keys[] = {"mesh", "transform"};
  static const char *const tetgen_keys[] = {"tetgen", "transform"};
  fcm_scene_geometry *g = &p->scene->geometry;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  for (int i = 0; i < 9; i++)
    g->transform[i] = (i % 4 == 0);
  g->kind = FCM_SCENE_GEOMETRY_NONE;
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "geometry", 0, &o));
  if (!o) return FCM_OK;
  SCENE_ENTER(p, "geometry");
  /* Typos first (against every geometry key), then the keys of the chosen kind. */
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, any_keys, SCENE_COUNT(any_keys)));
  int nd = !!fcm__json_member(o, "shape") + !!fcm__json_member(o, "mesh") +
           !!fcm__json_member(o, "tetgen") + !!fcm__json_member(o, "surface") +
           !!fcm__json_member(o, "voxels") + !!fcm__json_member(o, "level_set");
  SCENE_CHECK(nd == 1, p, FCM_ERR_ARG,
              "expected exactly one of \"shape\" (a procedural shape), \"mesh\" (a Gmsh file), "
              "\"tetgen\" (a TetGen base name), \"surface\" (an .obj, .off, .stl or .ply "
              "triangle surface), \"voxels\" (an image file) or \"level_set\" (an implicit "
              "body), got %d of them",
              nd);
  if (fcm__json_member(o, "surface")) {
    FCM_TRY(p->ctx, read_surface_geometry(p, o, g));
  } else if (fcm__json_member(o, "voxels")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, voxel_keys, SCENE_COUNT(voxel_keys)));
    g->kind = FCM_SCENE_GEOMETRY_VOXELS;
    FCM_TRY(p->ctx, read_voxels(p, o, g));
  } else if (fcm__json_member(o, "level_set")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, level_set_keys, SCENE_COUNT(level_set_keys)));
    g->kind = FCM_SCENE_GEOMETRY_LEVEL_SET;
    FCM_TRY(p->ctx, read_level_set(p, o, g));
  } else if (fcm__json_member(o, "mesh")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, mesh_keys, SCENE_COUNT(mesh_keys)));
    g->kind = FCM_SCENE_GEOMETRY_GMSH;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "mesh", 1, NULL, &g->mesh));
  } else if (fcm__json_member(o, "tetgen")) {
    FCM_TRY(p->ctx, fcm__scene_check_object(p, o, tetgen_keys, SCENE_COUNT(tetgen_keys)));
    g->kind = FCM_SCENE_GEOMETRY_TETGEN;
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "tetgen", 1, ".node", &g->mesh));
    FCM_TRY(p->ctx, fcm__scene_read_file(p, o, "tetgen", 1, ".ele", &g->ele));
  } else {
    FCM_TRY(p->ctx, read_shape(p, o, g));
  }
  FCM_TRY(p->ctx, fcm__scene_read_transform(p, o, g->transform, g->offset, &g->has_transform));
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}

/* ---------------------------------------------------------------- material */

fcm_status fcm__scene_read_material(fcm__scene_parser *p, const fcm__json *root)
{
  fcm_status st = FCM_OK;
  static const char *const keys[] = {"model", "young", "poisson", "density"};
  fcm_material *m = &p->scene->material;
  const fcm__json *o = NULL;
  size_t old = p->path_len;
  int model = 3; /* "snh" */
  FCM_TRY(p->ctx, fcm__scene_read_object(p, root, "material", 1, &o));
  SCENE_ENTER(p, "material");
  FCM_TRY(p->ctx, fcm__scene_check_object(p, o, keys, SCENE_COUNT(keys)));
  FCM_TRY(p->ctx,
          fcm__scene_read_choice(p, o, "model", 0, model_names, SCENE_COUNT(model_names), &model));
  m->model = model_values[model];
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "young", 1, FCM__POSITIVE, &m->young));
  FCM_TRY(p->ctx,
          fcm__scene_read_number(p, o, "poisson", 1, (fcm__range){-1.0, 0.5, 1, 1}, &m->poisson));
  m->density = 1000.0;
  FCM_TRY(p->ctx, fcm__scene_read_number(p, o, "density", 0, FCM__NONNEGATIVE, &m->density));
  /* The material module's own rule must agree with the ranges above. */
  FCM_ASSERT(fcm_material_validate(NULL, m) == FCM_OK, p->ctx);
cleanup:
  fcm__scene_path_pop(p, old);
  return st;
}
